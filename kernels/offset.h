/* offset.h — ray origins moved off the surface they start on by the rounding error of the
 * point's own computation (Pharr, Jakob & Humphreys, pbrt-v4, Interaction::OffsetRayOrigin),
 * in scalar arithmetic that compiles both as OpenCL C (kernels/geometry.cl) and as host C
 * (tests/watertight.c and the Embree benchmark follow the kernels with it), so that both
 * sides compute the same origin bit for bit.
 *
 * A hit point is interpolated on its triangle, p = w0 a + u b + v c in float (tri_point),
 * with w0 = 1 - u - v. Its distance from the triangle's plane is at most
 * err = gamma_7 (|n| . (|w0 a| + |u b| + |v c|)) (pbrt-v4, Triangle::InteractionFromIntersection:
 * the products and sums round each term by at most 3 units in the last place, and w0's own
 * rounding, at most 2 units of 1, moves the point off the plane by at most 2 units of the
 * plane's distance from the origin, which that sum bounds). Moving p by 16 times that along
 * the unit normal n, then one float further in each coordinate that moved, puts the origin
 * strictly on n's side of the plane; the intersection test does not take hits closer than
 * its own error bound as they are (geometry.cl, tri_finish), so a ray from there cannot find
 * its own triangle again. Why 16 times (VB_OFFSET_MARGIN), not pbrt-v4's once: the float
 * triangle test's error in the start triangle's distance is up to about 12 times the point's
 * bound for a triangle as large as its coordinates, and within it a hit goes to double
 * (tri_close_double); with the bound alone that was a large share of all rays leaving a
 * surface (prism_dispersion's kernels 6 - 10% slower), with 16 times it needs a triangle
 * larger than its coordinates (a floor under the origin). Both bounds come from the
 * magnitudes that produced the numbers, not from a length in scene units: the same scene at
 * any scale and position gets the same relative offsets, and at a power-of-two scale the
 * same offsets bit for bit. */
#ifndef VBCL_OFFSET_H
#define VBCL_OFFSET_H

#include "compat.h"

#ifdef VBCL_DEVICE
#define OFFSET_FN       inline
#define OFFSET_ABS(x)   fabs(x)
#define OFFSET_BITS(x)  as_int(x)
#define OFFSET_FLOAT(x) as_float(x)
#else
#include <math.h>
#include <stdint.h>
#include <string.h>
#define OFFSET_FN       static inline
#define OFFSET_ABS(x)   fabsf(x) /* in float, as on the device */
#define OFFSET_BITS(x)  vb_offset_bits(x)
#define OFFSET_FLOAT(x) vb_offset_float(x)
static inline int32_t vb_offset_bits(float f)
{
    int32_t i;
    memcpy(&i, &f, sizeof i);
    return i;
}
static inline float vb_offset_float(int32_t i)
{
    float f;
    memcpy(&f, &i, sizeof f);
    return f;
}
#endif

/* gamma_7 = 7u / (1 - 7u), u = 2^-24: the bound of seven roundings (pbrt's gamma(7)). */
#define VB_OFFSET_GAMMA (7.0f * 5.9604645e-8f / (1.0f - 7.0f * 5.9604645e-8f))

/* The offset in bounds of the point's error (a power of two: exact at any scale). */
#define VB_OFFSET_MARGIN 16.0f

/* One coordinate's share of the bound: |w0 a| + |u b| + |v c|. */
OFFSET_FN float vb_offset_sum(float w0, float u, float v, float a, float b, float c)
{
    return OFFSET_ABS(w0 * a) + OFFSET_ABS(u * b) + OFFSET_ABS(v * c);
}

/* The offset along the unit normal (nx, ny, nz) from the three coordinates' shares:
 * VB_OFFSET_MARGIN times the bound of the point's distance from its plane. */
OFFSET_FN float vb_offset_error(float nx, float ny, float nz, float sx, float sy, float sz)
{
    return (VB_OFFSET_MARGIN * VB_OFFSET_GAMMA) *
           (OFFSET_ABS(nx) * sx + OFFSET_ABS(ny) * sy + OFFSET_ABS(nz) * sz);
}

/* The float next to q on d's side (d not 0), nextafter(q, d * infinity) in integer steps:
 * the bits one unit away from zero where q and d have the same sign, toward it where not;
 * from a zero, the smallest float of d's sign. (nextafter itself, a call on PoCL, made an
 * opaque scene's shading about 3% slower.) */
OFFSET_FN float vb_offset_step(float q, float d)
{
    int bq = OFFSET_BITS(q), bd = OFFSET_BITS(d);
    if ((bq & 0x7fffffff) == 0) return OFFSET_FLOAT((bd & (int)0x80000000) | 1);
    return OFFSET_FLOAT(bq + ((bq ^ bd) < 0 ? -1 : 1));
}

/* Coordinate p of a point moved by err along the unit normal, whose coordinate is n: then
 * one float further the way it moved (so that rounding the sum cannot leave it short). */
OFFSET_FN float vb_offset_coord(float p, float n, float err)
{
    float d = err * n;
    float q = p + d;
    return d != 0.0f ? vb_offset_step(q, d) : q;
}

#endif
