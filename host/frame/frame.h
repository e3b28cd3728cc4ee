/* frame.h — the frame driver: one image of a scene on a device, from pass 0 (one ray
 * through each pixel centre, tile by tile) through adaptive refinement or uniform
 * supersampling (aa.h) to the reconstructed image, with progress on stderr. */
#ifndef VBCL_FRAME_H
#define VBCL_FRAME_H

#include "aa.h"
#include "render.h"
#include "tiles.h"

/* A scene prepared for rendering on one or more devices, and the anti-aliasing state it
 * grows. Pass 0 runs on every device (tiles.h); refinement and supersampling run on the
 * first device's renderer r. */
typedef struct Frame {
    CompiledScene cs; /* the scene compiled once for every device */
    Renderer r;
    AaState aa;
    Renderer *more; /* the other devices' renderers (nmore of them) */
    int nmore;
    const TileSource *tiles;          /* where pass 0's tiles come from: NULL, this process */
    DeviceWork work[CLU_MAX_DEVICES]; /* [0]: r's device, then more[]'s */
} Frame;

/* The region of s's image a frame writes, x0, y0, x1, y1 in pixels (x1, y1 one past its
 * last column and row): s->crop, or the whole image. */
void frame_region(const Scene *s, int reg[4]);

/* The pixels a frame of s renders around its region where the image has them: with --crop
 * and adaptive anti-aliasing s->crop_margin, or (-1) the refinement's whole reach
 * (aa_reach: then the region is refined exactly as in the whole image); else 0. */
int frame_margin(const Scene *s);

/* The window: the part of s's image a frame renders, as frame_region gives its region: the
 * region widened on every side by frame_margin and clipped to the image. The whole image
 * without --crop. */
void frame_window(const Scene *s, int win[4]);

/* Prepares s on devs[0..ndev): compiles it (compiled_scene_update: grid, object analysis,
 * packed arrays, once for every device, the geometry kept from fr's last frame where it is
 * the same), then builds the program and uploads the buffers on each device
 * (renderer_init_compiled; st gets the first device's build), for its window (frame_window:
 * the frame constants' window_x ...). fr is zeroed before its first
 * frame and released (frame_release) after its last. Returns as renderer_init_compiled. */
int frame_init(Frame *fr, VbDevice *devs, int ndev, const Scene *s, RenderStats *st, char *err,
               size_t errlen);

/* Pass 0 alone: one ray through the centre of each pixel of the window, tile by tile on
 * every device (tiles from fr->tiles), into rgba (the window's pixels, row by row). Returns
 * 0, or 1 with a message in err. */
int frame_pixel_centres(Frame *fr, float *rgba, RenderStats *st, int progress, char *err,
                        size_t errlen);

/* Renderer i of the frame (0: r, the first device's), and how many there are. */
Renderer *frame_renderer(Frame *fr, int i);
int frame_devices(const Frame *fr);

/* Renders the frame's window (frame_window) in rgba, room for its pixels (4 floats each,
 * linear): one ray through each pixel centre, then with s->aa_threshold > 0 adaptive
 * refinement (frame_levels tells the levels reached); with s->ssaa > 1 instead N x N
 * samples in every pixel. Then leaves the region's pixels (frame_region) at the start of
 * rgba, row 0 at the top, and so the levels and leaves. With progress set, reports
 * progress on stderr once the render has taken a second. Returns 0, or 1 (device) / 2 (too
 * large for the device's buffers) with a message in err. */
int frame_render(Frame *fr, const Scene *s, float *rgba, RenderStats *st, int progress, char *err,
                 size_t errlen);

/* Each pixel's refinement level after an adaptive render (the region's pixels), else
 * NULL. */
const int *frame_levels(const Frame *fr);

/* Each pixel's number of samples (its quadtree's leaves) after an adaptive render (the
 * region's pixels), else NULL. */
const int *frame_leaves(const Frame *fr);

/* Releases everything frame_init and frame_render created, the compiled scene included. */
void frame_release(Frame *fr);

#endif
