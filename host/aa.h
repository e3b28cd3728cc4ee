/* aa.h — anti-aliasing on the device (thesis 4.1.2): adaptive refinement of the pixels
 * that fail a contrast test against their neighbours, and uniform supersampling, both
 * through the same path (subpixel rays, the frame's tracing kernels, a box window). */
#ifndef VBCL_AA_H
#define VBCL_AA_H

#include "render.h"

/* The ray buffers hold at least this many rays: one pixel at the top level, 16x16. */
#define AA_MIN_BATCH_RAYS (1 << (2 * VBCL_AA_MAX_LEVEL))

/* Safety bound on contrast rounds; each round raises some pixel's level, and renders
 * measured so far end in at most max_level + 3. */
#define AA_MAX_ROUNDS 64

/* Refines rgba (the pass-0 image, one ray per pixel centre) adaptively: contrast marks
 * with threshold s->aa_threshold, marked pixels resampled one level deeper, until nothing
 * is marked or every marked pixel is at s->aa_max_level. Leaves each pixel's level in
 * r->aa_levels and the counts and times in st. Returns 0, or 1 (device) / 2 (the image
 * does not fit the device's buffers) with a message in err. */
int aa_refine(Renderer *r, const Scene *s, float *rgba, RenderStats *st, char *err, size_t errlen);

/* Renders rgba with n x n samples at the subpixel centres of every pixel (n in 1..16),
 * box-filtered. Returns as aa_refine. */
int aa_supersample(Renderer *r, const Scene *s, int n, float *rgba, RenderStats *st, char *err,
                   size_t errlen);

/* The heat-map colour of a refinement level (linear RGB; sRGB-encoded it is the palette of
 * docs/scene-format.md): level 0 dark blue-grey through blue, green, yellow to red. */
void aa_level_colour(int level, float rgb[3]);

#endif
