/* render.h — renders a loaded scene on an OpenCL device: builds the grid and the
 * program, uploads the scene, and runs the frame's kernels tile by tile. */
#ifndef VBCL_RENDER_H
#define VBCL_RENDER_H

#include "clu.h"
#include "grid.h"
#include "scene.h"

/* What a render did and how long each part took (--stats). */
typedef struct RenderStats {
    unsigned long long rays_primary, rays_shadow, shadow_skipped;
    unsigned long long traversal_steps, tri_tests;
    unsigned long long reflected, transmitted, pruned, depth_cut, tir, pass_through;
    unsigned long long interfaces, energy_errors;
    unsigned long long by_depth[VBCL_COUNT_DEPTH_BINS]; /* [0]: primary rays */
    unsigned features;
    char options[512];
    double build_ms;
    int build_cached;
    double grid_ms, upload_ms;
    double camera_ms, intersect_ms, shading_ms, tree_ms, readback_ms; /* event profiling */
    double render_ms; /* wall time of the tile loop */
    int tiles, tile_pixels;
} RenderStats;

/* A scene on a device, ready to render. */
typedef struct Renderer {
    VbDevice *dev;
    cl_program program;
    cl_kernel k_camera, k_intersect, k_shading, k_tree; /* k_tree: with transparency */
    cl_mem tris, normals, cell_start, cell_tris, materials, objects, lights, patterns, texels;
    cl_mem frame;
    cl_mem rays, hits, media, radiance, counters;
    Grid grid;
    VbFrame frame_host;
    int tile_pixels;
    unsigned features;
} Renderer;

/* Prepares s for rendering on dev: grid, program (extra build options appended, may be
 * NULL), buffers. Returns 0, or 1 (device failure) / 2 (the scene cannot be rendered as
 * given, e.g. a grid too large) with a message in err. */
int renderer_init(Renderer *r, VbDevice *dev, const Scene *s, const char *extra_options,
                  RenderStats *st, char *err, size_t errlen);

/* Renders the whole image into rgba (width*height*4 floats, linear, row 0 at the top).
 * With progress set, reports progress on stderr once the render has taken a second.
 * Returns 0, or 1 with a message in err. */
int renderer_render(Renderer *r, const Scene *s, float *rgba, RenderStats *st, int progress,
                    char *err, size_t errlen);

/* The scene arguments every frame kernel (and every shading probe) starts with: frame,
 * tris, normals, cell_start, cell_tris, materials, objects, lights, patterns, texels. */
#define RENDER_SCENE_ARGS 10
int renderer_set_scene_args(const Renderer *r, cl_kernel k);

/* Sets all arguments of a frame kernel: the scene's, then rays, nrays, hits, media,
 * radiance, counters. */
int renderer_set_frame_args(const Renderer *r, cl_kernel k, cl_mem rays, int nrays, cl_mem hits,
                            cl_mem media, cl_mem radiance, cl_mem counters);

/* Releases everything renderer_init created. */
void renderer_release(Renderer *r);

/* The kernel sources, embedded at build time (build/kernel_source.c). */
extern const char vbcl_kernel_source[];

#endif
