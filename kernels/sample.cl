#line 2 "sample.cl"
/* sample.cl — the integer hash behind every jitter (shadow feelers, anti-aliasing
 * subpixels), and unit floats from it. */
#ifndef VBCL_SAMPLE_CL
#define VBCL_SAMPLE_CL

#include "compat.h"

/* Integer hash (lowbias32): decorrelated jitter from a pixel, light and stratum. */
VB_INLINE uint vb_hash(uint x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

VB_INLINE float vb_unit_float(uint h)
{
    return (float)(h >> 8) * (1.0f / 16777216.0f);
}

/* Each byte with its bits in reverse order. */
#define VB_REV2(n) n, n + 2 * 64, n + 1 * 64, n + 3 * 64
#define VB_REV4(n) VB_REV2(n), VB_REV2(n + 2 * 16), VB_REV2(n + 1 * 16), VB_REV2(n + 3 * 16)
#define VB_REV6(n) VB_REV4(n), VB_REV4(n + 2 * 4), VB_REV4(n + 1 * 4), VB_REV4(n + 3 * 4)
__constant uchar vb_byte_reversed[256] = {VB_REV6(0), VB_REV6(2), VB_REV6(1), VB_REV6(3)};

/* The bits of x in reverse order, by bytes from a table: the shift-and-mask form compiles
 * to LLVM's bitreverse intrinsic, which not every OpenCL implementation provides
 * (Oclgrind does not). */
VB_INLINE uint vb_reverse_bits(uint x)
{
    return ((uint)vb_byte_reversed[x & 0xffu] << 24) |
           ((uint)vb_byte_reversed[(x >> 8) & 0xffu] << 16) |
           ((uint)vb_byte_reversed[(x >> 16) & 0xffu] << 8) | (uint)vb_byte_reversed[x >> 24];
}

/* Owen's nested scrambling of a coordinate in 32-bit fixed point, keyed by seed (Burley
 * 2020, "Practical hash-based Owen scrambling": the Laine-Karras permutation on the
 * reversed bits), the coordinate given with its bits already reversed (xr). Each digit is
 * flipped by a hash of the digits above it, so a point set that is a (0, m, 2)-net stays
 * one, now randomised. */
VB_INLINE uint vb_owen_scramble_reversed(uint xr, uint seed)
{
    uint x = xr + seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return vb_reverse_bits(x);
}

/* Point k of the base-2 (0, 2)-sequence in 32-bit fixed point, each coordinate with its
 * bits reversed (what vb_owen_scramble_reversed takes, so that no reversal is spent on it):
 * van der Corput's radical inverse, whose reversal is k itself, and Sobol's second
 * dimension, the XOR of the direction numbers v_i of k's set bits (v_0 = 2^31,
 * v_i+1 = v_i ^ v_i >> 1; reversed: r_0 = 1, r_i+1 = r_i ^ r_i << 1). Its first 4^m points
 * are a (0, 2m, 2)-net: one point in each of the 4^m elementary rectangles of every shape
 * (4^m x 1, ..., 1 x 4^m), where n x n jittered strata fill only the n x n squares. */
VB_INLINE uint2 vb_sobol2_reversed(uint k)
{
    uint r = 1u, y = 0u;
    for (uint i = k; i; i >>= 1, r ^= r << 1)
        if (i & 1u) y ^= r;
    return (uint2)(k, y);
}

#endif
