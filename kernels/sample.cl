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

/* The bits of x in reverse order. */
VB_INLINE uint vb_reverse_bits(uint x)
{
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
}

/* Owen's nested scrambling of a coordinate in 32-bit fixed point, keyed by seed (Burley
 * 2020, "Practical hash-based Owen scrambling": the Laine-Karras permutation on the
 * reversed bits). Each digit is flipped by a hash of the digits above it, so a point set
 * that is a (0, m, 2)-net stays one, now randomised. */
VB_INLINE uint vb_owen_scramble(uint x, uint seed)
{
    x = vb_reverse_bits(x);
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return vb_reverse_bits(x);
}

/* Point k of the base-2 (0, 2)-sequence in 32-bit fixed point: van der Corput's radical
 * inverse and Sobol's second dimension. Its first 4^m points are a (0, 2m, 2)-net: one
 * point in each of the 4^m elementary rectangles of every shape (4^m x 1, ..., 1 x 4^m),
 * where n x n jittered strata fill only the n x n squares. */
VB_INLINE uint2 vb_sobol2(uint k)
{
    uint v = 1u << 31, y = 0u;
    for (uint i = k; i; i >>= 1, v ^= v >> 1)
        if (i & 1u) y ^= v;
    return (uint2)(vb_reverse_bits(k), y);
}

#endif
