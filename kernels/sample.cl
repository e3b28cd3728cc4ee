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

#endif
