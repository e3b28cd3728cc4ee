/* render.h — renders a loaded scene on an OpenCL device: builds the grid and the
 * program, uploads the scene, and runs the frame's kernels tile by tile. */
#ifndef VBCL_RENDER_H
#define VBCL_RENDER_H

#include "clu.h"
#include "grid.h"
#include "scene.h"

/* What a render did and how long each part took (--stats). */
typedef struct RenderStats {
    unsigned long long rays_primary;
    unsigned long long rays_refine; /* adaptive anti-aliasing samples beyond pass 0 */
    /* the kernels' work counters (VBCL_COUNTER_LIST in kernels/types.h): rays_shadow,
     * shadow_skipped, traversal_steps, tri_tests, reflected, transmitted, ... */
#define RENDER_STATS_COUNTER(name, index, field, group, key) unsigned long long field;
    VBCL_COUNTER_LIST(RENDER_STATS_COUNTER)
#undef RENDER_STATS_COUNTER
    unsigned long long by_depth[VBCL_COUNT_DEPTH_BINS]; /* [0]: primary rays */
    unsigned features;
    char options[512];
    double build_ms;
    int build_cached;
    double grid_ms, upload_ms;
    double camera_ms, intersect_ms, shading_ms, tree_ms, readback_ms; /* event profiling */
    double dispersion_ms; /* tree_trace_bands: the dispersive subtrees (event profiling) */
    double render_ms;     /* wall time of the tile loop */
    int tiles, tile_pixels;
    /* anti-aliasing (--aa: adaptive, --ssaa: uniform; host/aa.c) */
    int aa_rounds;                                          /* contrast passes that marked pixels */
    unsigned long long aa_refined[VBCL_AA_MAX_LEVEL + 1];   /* [L]: pixels refined to level L */
    unsigned long long samples;                             /* camera rays through the film */
    unsigned samples_max;                                   /* most samples of one pixel */
    double aa_contrast_ms, aa_refine_ms, aa_reconstruct_ms; /* event profiling */
} RenderStats;

/* A scene on a device, ready to render. */
typedef struct Renderer {
    VbDevice *dev;
    cl_program program;
    cl_kernel k_camera, k_intersect, k_shading, k_tree; /* k_tree: with transparency */
    cl_kernel k_bands;                                  /* tree_trace_bands: with dispersion */
    cl_mem tris, normals, cell_start, cell_tris, materials, objects, lights, patterns, texels;
    cl_mem frame;
    cl_mem rays, hits, media, radiance, counters;
    cl_mem splits; /* dispersion: one VbSplitSet per ray */
    /* anti-aliasing, created on first use (host/aa.c) */
    cl_kernel k_aa_generate, k_aa_contrast, k_aa_reconstruct;
    cl_mem aa_pass, film, levels, marks, mark_counts;
    int *aa_levels; /* after an adaptive render: each pixel's refinement level, else NULL */
    Grid grid;
    VbFrame frame_host;
    int tile_pixels;
    int ray_capacity;  /* rays the ray buffers hold: the tile, and at least one 16x16 pixel */
    size_t local_size; /* work-group size of the tracing and anti-aliasing kernels, or 0 for
                        * the driver's choice: fixed, so that PoCL compiles one work-group
                        * function per kernel however the batch sizes vary */
    unsigned features;
    unsigned band_weights; /* dispersion: first float of the band weights in texels */
} Renderer;

/* Prepares s for rendering on dev: grid, program (extra build options appended, may be
 * NULL), buffers. Returns 0, or 1 (device failure) / 2 (the scene cannot be rendered as
 * given, e.g. a grid too large) with a message in err. */
int renderer_init(Renderer *r, VbDevice *dev, const Scene *s, const char *extra_options,
                  RenderStats *st, char *err, size_t errlen);

/* Renders the whole image into rgba (width*height*4 floats, linear, row 0 at the top):
 * one ray through each pixel centre, then with s->aa_threshold > 0 adaptive refinement
 * (r->aa_levels holds the levels reached); with s->ssaa > 1 instead N x N samples in
 * every pixel. With progress set, reports progress on stderr once the render has taken a
 * second. Returns 0, or 1 with a message in err. */
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

/* Traces the n camera rays in r->rays (first interfaces, local shading, ray trees) into
 * r->radiance, adds their counts and kernel times to st and the tracing kernels' time to
 * *trace_ms (may be NULL), and waits for them. n <= r->ray_capacity. Returns 0, or -1
 * with the error recorded (clu_error). */
int renderer_trace_rays(Renderer *r, int n, RenderStats *st, double *trace_ms);

/* Lowers r->local_size to 0 unless kernel k runs work-groups of that size. Returns 0. */
int renderer_fit_local_size(Renderer *r, cl_kernel k);

/* The local size argument of clEnqueueNDRangeKernel for the global size `global`. */
const size_t *renderer_local(const Renderer *r, size_t global);

/* Releases everything renderer_init created. */
void renderer_release(Renderer *r);

/* The kernel sources, embedded at build time (build/kernel_source.c). */
extern const char vbcl_kernel_source[];

#endif
