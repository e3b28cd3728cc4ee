/* render.h — traces rays of a loaded scene on an OpenCL device: builds the grid and the
 * program, uploads the scene, and runs the tracing kernels on a batch of rays (a tile of
 * pass 0, or anti-aliasing's subpixels). The frame driver (frame.h) runs a whole image. */
#ifndef VBCL_RENDER_H
#define VBCL_RENDER_H

#include "clu.h"
#include "device_scene.h"
#include "grid.h"
#include "kernel_features.h"
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
    int build_cached; /* how the program came: CLU_BUILT, CLU_BINARY, CLU_BUILT_DRIVER_CACHE */
    double grid_ms, upload_ms;
    double camera_ms, intersect_ms, shading_ms, tree_ms, readback_ms; /* event profiling */
    double dispersion_ms; /* tree_trace_bands: the dispersive subtrees (event profiling) */
    double render_ms;     /* wall time of the tile loop */
    int tiles, tile_pixels;
    /* anti-aliasing (--aa: adaptive, --ssaa: uniform; host/frame/aa.c) */
    int aa_rounds;                                          /* contrast passes that marked pixels */
    unsigned long long aa_refined[VBCL_AA_MAX_LEVEL + 1];   /* [L]: pixels refined to level L */
    unsigned long long samples;                             /* camera rays through the film */
    unsigned samples_max;                                   /* most samples of one pixel */
    double aa_contrast_ms, aa_refine_ms, aa_reconstruct_ms; /* event profiling */
} RenderStats;

/* The kernels of the program, one list: X(Renderer field suffix, kernel name, the
 * VBCL_FEATURE_* bits without which the program has no such kernel). */
#define RENDER_KERNELS(X)                                                                          \
    X(camera, "camera_generate_rays", 0u)                                                          \
    X(intersect, "scene_intersect_closest", 0u)                                                    \
    X(shading, "light_sample_shading", 0u)                                                         \
    X(tree, "tree_trace_secondary", VBCL_FEATURE_TRANSPARENCY)                                     \
    X(bands, "tree_trace_bands", VBCL_FEATURE_TRANSPARENCY | VBCL_FEATURE_DISPERSION)              \
    X(aa_generate, "aa_generate_rays", 0u)                                                         \
    X(aa_contrast, "aa_contrast_mark", 0u)                                                         \
    X(aa_contrast_list, "aa_contrast_list", 0u)                                                    \
    X(aa_dirty_list, "aa_dirty_list", 0u)                                                          \
    X(aa_reconstruct, "aa_reconstruct", 0u)                                                        \
    X(aa_split_rays, "aa_split_rays", 0u)                                                          \
    X(aa_split_store, "aa_split_store", 0u)                                                        \
    X(aa_resolve, "aa_resolve", 0u)

/* A scene on a device, ready to trace: its buffers, the program and its kernels, and one
 * batch of rays (camera rays of a tile, or subpixel rays of anti-aliasing) at a time. */
typedef struct Renderer {
    VbDevice *dev;
    cl_program program;
#define RENDER_KERNEL_FIELD(id, name, needs) cl_kernel k_##id;
    RENDER_KERNELS(RENDER_KERNEL_FIELD) /* NULL where the features leave one out */
#undef RENDER_KERNEL_FIELD
    SceneBuffers buf;
    cl_mem rays, hits, media, radiance, counters;
    cl_mem splits; /* dispersion: one VbSplitSet per ray */
    Grid grid;
    VbFrame frame_host;
    int tile_pixels;
    int ray_capacity;  /* rays the ray buffers hold: the tile, and at least one 16x16 pixel */
    size_t local_size; /* work-group size of the tracing and anti-aliasing kernels, or 0 for
                        * the driver's choice: fixed, so that PoCL compiles one work-group
                        * function per kernel however the batch sizes vary */
    unsigned features;
} Renderer;

/* The ray buffers hold at least one pixel's samples at the deepest anti-aliasing level. */
#define RENDER_MIN_BATCH_RAYS (1 << (2 * VBCL_AA_MAX_LEVEL))

/* Prepares s for rendering on dev: grid, program (extra build options appended, may be
 * NULL), buffers. Returns 0, or 1 (device failure) / 2 (the scene cannot be rendered as
 * given, e.g. a grid too large) with a message in err. */
int renderer_init(Renderer *r, VbDevice *dev, const Scene *s, const char *extra_options,
                  RenderStats *st, char *err, size_t errlen);

/* Traces one tile of pass 0: a ray through the centre of each of the n pixels from
 * pixel `first` on, into rgba + 4 * first (n <= r->tile_pixels). Returns 0, or -1 with the
 * error recorded (clu_error). */
int renderer_trace_tile(Renderer *r, long first, int n, float *rgba, RenderStats *st);

/* The arguments a frame kernel starts with: the scene's (device_scene.h), then rays,
 * nrays, hits, media, radiance, counters. Kernels with more take them from here on. */
#define RENDER_FRAME_ARGS (SCENE_BUFFER_ARGS + 6)

/* Sets all arguments of a frame kernel: the scene's, then rays, nrays, hits, media,
 * radiance, counters. */
int renderer_set_frame_args(const Renderer *r, cl_kernel k, cl_mem rays, int nrays, cl_mem hits,
                            cl_mem media, cl_mem radiance, cl_mem counters);

/* Traces the n camera rays in r->rays (first interfaces, local shading, ray trees) into
 * r->radiance, adds their counts and kernel times to st and the tracing kernels' time to
 * *trace_ms (may be NULL), and waits for them. n <= r->ray_capacity. Returns 0, or -1
 * with the error recorded (clu_error). */
int renderer_trace_rays(Renderer *r, int n, RenderStats *st, double *trace_ms);

/* The local size argument of clEnqueueNDRangeKernel for the global size `global`. */
const size_t *renderer_local(const Renderer *r, size_t global);

/* Releases everything renderer_init created. */
void renderer_release(Renderer *r);

/* The kernel sources, embedded at build time (build/kernel_source.c). */
extern const char vbcl_kernel_source[];

#endif
