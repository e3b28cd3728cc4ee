/* frame.h — the frame driver: one image of a scene on a device, from pass 0 (one ray
 * through each pixel centre, tile by tile) through adaptive refinement or uniform
 * supersampling (aa.h) to the reconstructed image, with progress on stderr. */
#ifndef VBCL_FRAME_H
#define VBCL_FRAME_H

#include "aa.h"
#include "render.h"

/* A scene prepared for rendering on one device, and the anti-aliasing state it grows. */
typedef struct Frame {
    Renderer r;
    AaState aa;
} Frame;

/* Prepares s on dev (grid, program, buffers: renderer_init). Returns as renderer_init. */
int frame_init(Frame *fr, VbDevice *dev, const Scene *s, RenderStats *st, char *err, size_t errlen);

/* Renders the whole image into rgba (width*height*4 floats, linear, row 0 at the top): one
 * ray through each pixel centre, then with s->aa_threshold > 0 adaptive refinement
 * (frame_levels tells the levels reached); with s->ssaa > 1 instead N x N samples in every
 * pixel. With progress set, reports progress on stderr once the render has taken a second.
 * Returns 0, or 1 (device) / 2 (too large for the device's buffers) with a message in
 * err. */
int frame_render(Frame *fr, const Scene *s, float *rgba, RenderStats *st, int progress, char *err,
                 size_t errlen);

/* Each pixel's refinement level after an adaptive render, else NULL. */
const int *frame_levels(const Frame *fr);

/* Releases everything frame_init and frame_render created. */
void frame_release(Frame *fr);

#endif
