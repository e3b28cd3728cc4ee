/* aa.h — anti-aliasing on the device (thesis 4.1.2): adaptive refinement of the pixels
 * that fail a contrast test against their neighbours, and uniform supersampling, both
 * through the same path (subpixel rays, the frame's tracing kernels, a box window). */
#ifndef VBCL_AA_H
#define VBCL_AA_H

#include "render.h"

/* Safety bound on contrast rounds; each round raises some pixel's level, and renders
 * measured so far end in at most max_level + 3. */
#define AA_MAX_ROUNDS 64

/* Anti-aliasing's own device state, created on first use: the film (the image being
 * refined), each pixel's level, the list of marked pixels and the pass constants. */
typedef struct AaState {
    cl_mem pass, film, levels, marks, mark_counts;
    int *levels_host; /* after an adaptive render: each pixel's refinement level, else NULL */
} AaState;

/* Refines rgba (the pass-0 image, one ray per pixel centre) adaptively: contrast marks
 * with threshold s->aa_threshold, marked pixels resampled one level deeper by r's tracing
 * kernels, until nothing is marked or every marked pixel is at s->aa_max_level. Leaves
 * each pixel's level in aa->levels_host and the counts and times in st. Returns 0, or 1
 * (device) / 2 (the image does not fit the device's buffers) with a message in err. */
int aa_refine(AaState *aa, Renderer *r, const Scene *s, float *rgba, RenderStats *st, char *err,
              size_t errlen);

/* Renders rgba with n x n samples at the subpixel centres of every pixel (n in 1..16),
 * box-filtered. Returns as aa_refine. */
int aa_supersample(AaState *aa, Renderer *r, const Scene *s, int n, float *rgba, RenderStats *st,
                   char *err, size_t errlen);

/* Releases what aa_refine and aa_supersample created. */
void aa_release(AaState *aa);

/* The heat-map colour of a refinement level (linear RGB; sRGB-encoded it is the palette of
 * docs/scene-format.md): level 0 dark blue-grey through blue, green, yellow to red. */
void aa_level_colour(int level, float rgb[3]);

#endif
