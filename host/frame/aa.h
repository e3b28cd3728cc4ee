/* aa.h — anti-aliasing on the device (thesis 4.1.2): adaptive refinement as a quadtree of
 * subpixels whose leaves fail a contrast test against adjacent leaves, and uniform
 * supersampling; both trace their samples through the frame's tracing kernels. */
#ifndef VBCL_AA_H
#define VBCL_AA_H

#include "render.h"

/* Safety bound on contrast rounds (--stats reports the rounds run). Each round deepens some
 * leaves; splits spread from leaf to adjacent leaf while the contrast lasts, so a long
 * gradient can take many rounds. Measured: 5 – 20 rounds at 64² – 128², 28 for A.4 at 400². */
#define AA_MAX_ROUNDS 256

/* Anti-aliasing's own device state, created on first use: the film (the image being
 * refined), each pixel's tree slot, the trees (per refined pixel 256 bytes of levels and
 * 340 node values of 16 bytes, aa_tree.h; grown as pixels are refined), the list of marked
 * nodes and the counters. */
/* The launches and pass writes in flight at most before the host waits for them. */
#define AA_PENDING 32

typedef struct AaState {
    cl_mem pass, film, slots, info, counts;
    cl_mem split;                  /* two rounds' split blocks of each pixel (aa_contrast_mark) */
    cl_mem list, tags, list_count; /* the pixels a round tests (aa_dirty_list) */
    cl_mem levels, values, slot_pixels; /* tree_cap slots (slot_pixels slot_pixels_cap) */
    cl_mem marks;                       /* mark_cap entries of (pixel, node code) */
    size_t tree_cap, slot_pixels_cap, mark_cap;
    size_t npix;      /* the frame's pixels: the most tree slots it can need */
    int *levels_host; /* after an adaptive render: each pixel's deepest level, else NULL */
    int *leaves_host; /* after an adaptive render: each pixel's number of leaves, else NULL */
    /* launches not waited for (aa.c, aa_settle): their events and the times they add to, and
     * the passes written from here without waiting */
    cl_event pending[AA_PENDING];
    double *pending_ms[AA_PENDING][2];
    int npending;
    VbAaPass passes[AA_PENDING];
    int npasses;
} AaState;

/* Refines rgba (the pass-0 image of the frame's window, one ray per pixel centre) adaptively: each
 * round marks the leaves that fail the contrast test (threshold s->aa_threshold, floor s->aa_floor)
 * against an adjacent leaf at their level or deeper, and splits them in four (three new
 * samples each, traced by r's kernels), until nothing is marked; leaves at s->aa_max_level
 * never split. rgba becomes the mean of each refined pixel's finest cells, each the value of
 * the nearest sample (s->aa_reconstruct SCENE_AA_NEAREST) or of its leaf (SCENE_AA_LEAVES,
 * the area-weighted mean of the leaves); pixels never split keep their pass-0 value bit
 * for bit. Leaves each pixel's deepest level and leaf
 * count in aa, and the counts and times in st; with progress set, reports on stderr once
 * refinement has taken a second. Returns 0, or 1 (device) / 2 (the image or its trees do
 * not fit the device's buffers) with a message in err. */
int aa_refine(AaState *aa, Renderer *r, const Scene *s, float *rgba, RenderStats *st, int progress,
              char *err, size_t errlen);

/* How far beyond a pixel adaptive refinement of s reads, in pixels: each contrast round
 * reads the 8 neighbours of the pixels it tests, so after the AA_MAX_ROUNDS - min level
 * rounds there can be at most, a pixel's leaves depend on the pass-0 samples and trees of
 * the pixels that many pixels around it, and the nearest-sample reconstruction reads the
 * neighbours' trees once more (+1, whichever reconstruction). A region of the image rendered
 * with this many pixels around it (clipped to the image) is refined exactly as in the whole
 * image. 0 without adaptive anti-aliasing (pass 0 and --ssaa read each pixel's own samples
 * only). */
int aa_reach(const Scene *s);

/* Whether a frame of s fits r's device before anything is traced: with a minimum level
 * (s->aa_min_level) every pixel takes a tree slot. Returns 0, or 2 with a message in err
 * (as aa_refine would after pass 0). */
int aa_check_fits(const Renderer *r, const Scene *s, char *err, size_t errlen);

/* Renders rgba, the frame's window, with n x n samples at the subpixel centres of every
 * pixel (n in 1..16), box-filtered. Returns as aa_refine. */
int aa_supersample(AaState *aa, Renderer *r, const Scene *s, int n, float *rgba, RenderStats *st,
                   char *err, size_t errlen);

/* Releases what aa_refine and aa_supersample created. */
void aa_release(AaState *aa);

/* The heat-map colour of a refinement level (linear RGB; sRGB-encoded it is the palette of
 * docs/scene-format.md): level 0 dark blue-grey through blue, green, yellow to red. */
void aa_level_colour(int level, float rgb[3]);

/* The heat-map colour of a pixel's sample count n >= 1 (its quadtree's leaves) on the same
 * palette, at level log4(n) and blended between levels: 1 sample dark, 4 blue, 16 green,
 * 64 yellow, 256 red. */
void aa_samples_colour(int n, float rgb[3]);

#endif
