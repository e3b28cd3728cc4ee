#line 2 "aa.cl"
/* aa.cl — adaptive anti-aliasing on contrast masks (thesis 4.1.2, figures 4.2–4.4) and
 * uniform supersampling: the contrast test, subpixel positions, sample ids, and the box
 * window that reconstructs a pixel from its samples. The entry points are in render.cl. */
#ifndef VBCL_AA_CL
#define VBCL_AA_CL

#include "sample.cl"
#include "types.h"

/* A pixel's value for the contrast test: scaled by 2^exposure and clamped to [0, 1], so
 * that differences a display cannot show (above white) do not refine. */
VB_INLINE float3 aa_display(__constant const VbAaPass *aa, __global const float *film, int p)
{
    return clamp(vload4(p, film).xyz * aa->contrast_scale, 0.0f, 1.0f);
}

/* The thesis's contrast |a - b| / (a + b) > threshold, per channel; a + b = 0 never fails. */
VB_INLINE int aa_contrast_fails(float3 a, float3 b, float threshold)
{
    float3 d = fabs(a - b), s = a + b;
    return (s.x > 0.0f && d.x > threshold * s.x) || (s.y > 0.0f && d.y > threshold * s.y) ||
           (s.z > 0.0f && d.z > threshold * s.z);
}

/* Whether pixel p (at level lv) is to be refined: some 8-neighbour q fails the contrast
 * test with it and is not at a lower level. Of a failing pair the pixel at the lower
 * level is refined (thesis figure 4.2); on a tie both are (the thesis refines the centre
 * pixel first and then, comparing again in its while loop, the neighbour). */
VB_INLINE int aa_pixel_marked(__constant const VbAaPass *aa, __global const float *film,
                              __global const int *levels, int p, int lv)
{
    int x = p % aa->width, y = p / aa->width;
    float3 a = aa_display(aa, film, p);
    for (int dy = -1; dy <= 1; dy++) {
        int qy = y + dy;
        if (qy < 0 || qy >= aa->height) continue;
        for (int dx = -1; dx <= 1; dx++) {
            int qx = x + dx;
            if ((dx == 0 && dy == 0) || qx < 0 || qx >= aa->width) continue;
            int q = qy * aa->width + qx;
            if (levels[q] < lv) continue; /* the neighbour is refined, not p */
            if (aa_contrast_fails(a, aa_display(aa, film, q), aa->threshold)) return 1;
        }
    }
    return 0;
}

/* The id of subpixel sub (row-major, of side x side) of a pixel: the pixel index itself
 * for one sample per pixel (so that keys match the unrefined render), otherwise a hash
 * of the three, so every supersample has its own shading jitter. */
VB_INLINE uint aa_sample_id(uint pixel, int side, uint sub)
{
    if (side == 1) return pixel;
    return vb_hash(pixel ^ vb_hash(((uint)side << 16) ^ sub ^ 0x5bd1e995u));
}

#endif
