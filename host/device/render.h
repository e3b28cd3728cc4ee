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
    int build_cached;       /* how the tracing program came: CLU_BUILT, CLU_BINARY, ... (clu.h) */
    double first_launch_ms; /* the kernels' empty first launches (in build_ms): a driver
                             * that compiles each kernel at its first launch does it here */
    int program;            /* PROGRAM_* (kernel_features.h) */
    double grid_ms, upload_ms;
    int scene_compiles;  /* compilations of the scene (compiled_scene_update) for this frame */
    int geometry_builds; /* of them, those that made the geometry (the others kept it) */
    double camera_ms, intersect_ms, shading_ms, tree_ms, readback_ms; /* event profiling */
    double dispersion_ms; /* tree_trace_secondary's second launch: the dispersive subtrees
                           * (event profiling) */
    double render_ms;     /* wall time of the tile loop */
    int tiles, tile_pixels;
    /* anti-aliasing (--aa: adaptive, --ssaa: uniform; host/frame/aa.c) */
    int aa_rounds;                                          /* contrast passes that marked pixels */
    unsigned long long aa_refined[VBCL_AA_MAX_LEVEL + 1];   /* [L]: pixels refined to level L */
    unsigned long long samples;                             /* camera rays through the film */
    unsigned samples_max;                                   /* most samples of one pixel */
    double aa_contrast_ms, aa_refine_ms, aa_reconstruct_ms; /* event profiling */
} RenderStats;

/* The kernels, one list: X(Renderer field suffix, kernel name, program: 0 the tracing
 * program (render.cl), 1 the film program (film.cl), whether it starts with the frame's
 * arguments (FRAME_KERNEL_ARGS), the VBCL_FEATURE_* bits without which the scene does not
 * run it). */
#define RENDER_KERNELS(X)                                                                          \
    X(camera, "camera_generate_rays", 0, 1, 0u)                                                    \
    X(intersect, "scene_intersect_closest", 0, 1, 0u)                                              \
    X(shading, "light_sample_shading", 0, 1, 0u)                                                   \
    X(tree, "tree_trace_secondary", 0, 1, VBCL_FEATURE_TRANSPARENCY)                               \
    X(aa_generate, "aa_generate_rays", 0, 1, 0u)                                                   \
    X(aa_split_rays, "aa_split_rays", 0, 1, 0u)                                                    \
    X(aa_contrast, "aa_contrast_mark", 1, 0, 0u)                                                   \
    X(aa_contrast_list, "aa_contrast_list", 1, 0, 0u)                                              \
    X(aa_dirty_list, "aa_dirty_list", 1, 0, 0u)                                                    \
    X(aa_reconstruct, "aa_reconstruct", 1, 0, 0u)                                                  \
    X(aa_split_store, "aa_split_store", 1, 0, 0u)                                                  \
    X(aa_resolve, "aa_resolve", 1, 0, 0u)

/* A scene on a device, ready to trace: its buffers, the program and its kernels, and one
 * batch of rays (camera rays of a tile, or subpixel rays of anti-aliasing) at a time. */
typedef struct Renderer {
    VbDevice *dev;
    cl_program program; /* the tracing program of the scene's class (kernel_features.h) */
    cl_program film;    /* anti-aliasing's film kernels, the same for every scene */
    cl_program probe;   /* the tests' probe kernels (renderer_init's probe_source), or NULL */
#define RENDER_KERNEL_FIELD(id, name, prog, frame, needs) cl_kernel k_##id;
    RENDER_KERNELS(RENDER_KERNEL_FIELD) /* NULL where the scene's features leave one out */
#undef RENDER_KERNEL_FIELD
    SceneBuffers buf;
    cl_mem rays, hits, media, radiance, counters;
    cl_mem splits;           /* dispersion: one VbSplitSet per ray */
    const CompiledScene *cs; /* the scene as compiled for the kernels (its grid: cs->grid) */
    CompiledScene *own_cs;   /* cs where renderer_init compiled it itself, else NULL */
    VbFrame frame_host;
    int tile_pixels;
    int ray_capacity;  /* rays the ray buffers hold: the tile, and at least one 16x16 pixel */
    size_t local_size; /* work-group size of the tracing and anti-aliasing kernels, or 0 for
                        * the driver's choice: fixed, so that PoCL compiles one work-group
                        * function per kernel however the batch sizes vary */
    unsigned features; /* the scene's (VBCL_FEATURE_*) */
    unsigned program_features; /* those compiled into r->program, a superset */
} Renderer;

/* The ray buffers hold at least one pixel's samples at the deepest anti-aliasing level. */
#define RENDER_MIN_BATCH_RAYS (1 << (2 * VBCL_AA_MAX_LEVEL))

/* Prepares s, compiled into cs (compiled_scene.h; the same for every device of a frame),
 * for rendering on dev: programs (kept on dev for later frames: clu.h), buffers, and one
 * empty launch of each kernel the scene runs, so that a driver that compiles a kernel at
 * its first launch (PoCL) does so here, counted in st->build_ms and not in the render. cs
 * must outlive r. probe_source: the tests' probe program (built as the dispersive class,
 * into r->probe), or NULL. Returns 0, or 1 (device failure) / 2 (the scene cannot be
 * rendered as given, e.g. too large for the device) with a message in err. */
int renderer_init_compiled(Renderer *r, VbDevice *dev, const CompiledScene *cs, const Scene *s,
                           const char *probe_source, RenderStats *st, char *err, size_t errlen);

/* renderer_init_compiled on a compiled scene of its own (compiled_scene_build for dev; st
 * gets the grid's time), for one device alone. Returns as both. */
int renderer_init(Renderer *r, VbDevice *dev, const Scene *s, const char *probe_source,
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

/* Whether renderer_init says on stderr that it compiles a program for the first time on
 * the device (vbcl turns it on when stderr is a terminal and -q is not given). */
void renderer_build_notice(int on);

/* Releases everything renderer_init created. */
void renderer_release(Renderer *r);

/* The kernel sources, embedded at build time (build/kernel_source.c): the tracing program
 * (render.cl) and the film program (film.cl). The test binaries also embed probe.cl
 * (build/probe_source.c: vbcl_probe_source). */
extern const char vbcl_kernel_source[];
extern const char vbcl_film_source[];
extern const char vbcl_probe_source[]; /* linked into the test binaries only */

#endif
