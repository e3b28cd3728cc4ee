/* bench_rays.c — vbcl's ray throughput against Embree's on the same world-space triangles and
 * the same rays, per ray kind, measured side by side in one run (`make bench` part "embree",
 * scripts/bench.py; docs/benchmarks.md "Against Embree").
 *
 * The scene is loaded and prepared as the renderer does it (scene_load, renderer_init: the
 * same grid for the same --grid), with the probe kernels of kernels/probe.cl, which call the
 * renderer's own device functions. The kinds:
 *   primary     camera rays through the pixel centres: camera_trace_closest (the camera
 *               tiles, as the renderer traces them) / rtcIntersect1
 *   shadow      feelers from primary hits on opaque surfaces whose feelers meet no
 *               dielectric: the renderer's light_shade_local at each point / rtcOccluded1
 *   shadow_glass  feelers from the other opaque primary hits (some feeler crosses glass):
 *               light_shade_local / as many rtcIntersect1 from crossing to crossing as the
 *               renderer's walk (medium_shadow_transmittance) makes
 *   secondary   reflected and transmitted rays from primary hits on dielectrics (tree_spawn):
 *               as the renderer's ray trees trace them, among the triangles each can meet
 *               (ray_objects, scene_trace_closest_in) / rtcIntersect1
 * Each repeat runs every kind on vbcl (OpenCL event time of the probe kernel) and then on
 * Embree (wall time of the tracing on --threads threads); the medians are compared. The two
 * sides must agree on hit/miss and the closest distance for 99.9% of the rays. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_embree.h"
#include "render.h"

#define MAX_REPEATS 64

typedef struct Options {
    const char *scene, *grid, *device, *json;
    int width, height, shadow_samples, repeats, threads, robust, no_cone_test;
    float subgrid_density; /* 0: the scene's */
} Options;

enum { KIND_PRIMARY, KIND_SHADOW, KIND_GLASS, KIND_SECONDARY, KIND_COUNT };
static const char *const kind_names[KIND_COUNT] = {"primary", "shadow", "shadow_glass",
                                                   "secondary"};

/* One ray kind: the rays both sides trace, and what they measured. */
typedef struct Kind {
    VbRay *rays;             /* what Embree traces (the feelers, for the shadow kinds) */
    size_t nrays;            /* rays of this kind */
    uint32_t *steps;         /* shadow_glass: the renderer's closest-hit calls per feeler */
    float *vbcl_out;         /* vbcl's answer per ray: distance (-1 miss), or 1/0 blocked */
    uint32_t *points;        /* shadow kinds: the primary rays whose hits vbcl shades */
    size_t npoints;          /* shadow kinds: how many */
    cl_mem in, out, aux;     /* vbcl: rays or points; hits or traced counts; radiance */
    cl_mem feelers, blocked; /* shadow: its feelers for probe_trace_any, and the answers */
    double vbcl_ms[MAX_REPEATS], embree_ms[MAX_REPEATS];
    double any_ms[MAX_REPEATS]; /* shadow: scene_trace_any alone on the same feelers */
    size_t agree, compared;
    unsigned long long calls; /* closest-hit calls of the shadow_glass walks */
} Kind;

typedef struct Bench {
    Options o;
    VbDevice dev;
    Scene s;
    Renderer r;
    RenderStats st;
    size_t npix;
    cl_mem rays, hits, media; /* the camera rays and their first interfaces */
    VbRay *h_rays;            /* the camera rays on the host */
    cl_kernel k_closest, k_any, k_surface, k_shade, k_feelers, k_walk, k_secondary;
    Kind kinds[KIND_COUNT];
    BenchEmbree *emb;
    double embree_build_ms;
    float tol_abs; /* distance tolerance: 1e-6 of the scene's size, plus 1e-4 relative */
} Bench;

static const char usage[] =
    "usage: vbcl-bench-rays SCENE.json [options]\n"
    "  vbcl's rays per second against Embree's on the same triangles and rays, per kind\n"
    "  (primary, shadow, shadow_glass, secondary), medians of interleaved repeats\n"
    "  --grid auto|N|X,Y,Z     the renderer's grid (default: the scene's own)\n"
    "  --subgrid-density D     sub-cells per triangle of a crowded top cell (default: the\n"
    "                          scene's, else 2; as vbcl's --subgrid-density)\n"
    "  --width N --height N    camera rays (default: the scene's image size)\n"
    "  --shadow-samples N      feelers per point and light (default: the scene's)\n"
    "  --no-cone-test          vbcl traces every feeler (by default, as in a render, the\n"
    "                          feelers whose cone to the light meets no object are not\n"
    "                          traced; the shadow kinds count them all the same)\n"
    "  --repeats N             timed repeats after one warm-up (default 5, at most 64)\n"
    "  --threads N             Embree's threads (default 2)\n"
    "  --embree-robust 0|1     RTC_SCENE_FLAG_ROBUST (default 1)\n"
    "  --device SPEC           OpenCL device (default: VBCL_DEVICE, else the first)\n"
    "  --json FILE             write the results as JSON\n"
    "Exit status: 0, 2 for bad input, 1 for a failure or when the two sides disagree on\n"
    "more than 0.1% of the rays of a kind.\n";

static int int_arg(const char *name, const char *v, int lo, int hi, int *out)
{
    char *end;
    long x = v ? strtol(v, &end, 10) : 0;
    if (!v || *end || x < lo || x > hi) {
        fprintf(stderr, "vbcl-bench-rays: %s: expected an integer in %d..%d\n", name, lo, hi);
        return 2;
    }
    *out = (int)x;
    return 0;
}

static int float_arg(const char *name, const char *v, float lo, float hi, float *out)
{
    char *end;
    double x = v ? strtod(v, &end) : 0.0;
    if (!v || *end || !(x >= lo && x <= hi)) {
        fprintf(stderr, "vbcl-bench-rays: %s: expected a number in %g..%g\n", name, lo, hi);
        return 2;
    }
    *out = (float)x;
    return 0;
}

/* Returns -1 to go on, or an exit status. */
static int parse_args(int argc, char **argv, Options *o)
{
    memset(o, 0, sizeof *o);
    o->repeats = 5;
    o->threads = 2;
    o->robust = 1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int rc = 0;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage, stdout);
            return 0;
        } else if (!strcmp(a, "--grid") && v)
            o->grid = argv[++i];
        else if (!strcmp(a, "--device") && v)
            o->device = argv[++i];
        else if (!strcmp(a, "--subgrid-density"))
            rc = float_arg(a, argv[++i], 0.01f, 64.0f, &o->subgrid_density);
        else if (!strcmp(a, "--no-cone-test"))
            o->no_cone_test = 1;
        else if (!strcmp(a, "--json") && v)
            o->json = argv[++i];
        else if (!strcmp(a, "--width"))
            rc = int_arg(a, argv[++i], 1, SCENE_MAX_IMAGE, &o->width);
        else if (!strcmp(a, "--height"))
            rc = int_arg(a, argv[++i], 1, SCENE_MAX_IMAGE, &o->height);
        else if (!strcmp(a, "--shadow-samples"))
            rc = int_arg(a, argv[++i], 1, 4096, &o->shadow_samples);
        else if (!strcmp(a, "--repeats"))
            rc = int_arg(a, argv[++i], 1, MAX_REPEATS, &o->repeats);
        else if (!strcmp(a, "--threads"))
            rc = int_arg(a, argv[++i], 1, 64, &o->threads);
        else if (!strcmp(a, "--embree-robust"))
            rc = int_arg(a, argv[++i], 0, 1, &o->robust);
        else if (a[0] == '-' || o->scene) {
            fprintf(stderr, "vbcl-bench-rays: unexpected argument %s\n%s", a, usage);
            return 2;
        } else
            o->scene = a;
        if (rc) return rc;
    }
    if (!o->scene) {
        fprintf(stderr, "vbcl-bench-rays: no scene given\n%s", usage);
        return 2;
    }
    return -1;
}

/* ---- vbcl: the probe kernels ---- */

/* Sets the arguments of probe k after the scene's: n pairs of (size, pointer). */
static int probe_args(Bench *b, cl_kernel k, int n, const size_t *sizes, const void *const *vals)
{
    if (scene_buffers_set_args(&b->r.buf, k)) return -1;
    for (int i = 0; i < n; i++)
        if (clu_set_arg(k, (cl_uint)(SCENE_BUFFER_ARGS + i), sizes[i], vals[i])) return -1;
    return 0;
}

/* Runs k over n work items (work-groups of 64 where the kernel allows them, as the
 * renderer runs its kernels) and waits; *ms gets its event time. Returns 0 or -1. */
static int probe_run(Bench *b, cl_kernel k, size_t n, double *ms)
{
    size_t global = (n + 63) / 64 * 64, wg = 0, local = 64;
    if (n == 0) return 0;
    cl_event ev = NULL;
    int rc = -1;
    CL_CHECK(
        clGetKernelWorkGroupInfo(k, b->dev.device, CL_KERNEL_WORK_GROUP_SIZE, sizeof wg, &wg, NULL),
        done);
    CL_CHECK(clEnqueueNDRangeKernel(b->dev.queue, k, 1, NULL, &global, wg >= local ? &local : NULL,
                                    0, NULL, &ev),
             done);
    CL_CHECK(clWaitForEvents(1, &ev), done);
    if (ms) *ms = clu_event_ms(ev);
    rc = 0;
done:
    if (ev) clReleaseEvent(ev);
    return rc;
}

static int read_buf(Bench *b, cl_mem m, void *dst, size_t bytes)
{
    CL_CHECK(clEnqueueReadBuffer(b->dev.queue, m, CL_TRUE, 0, bytes, dst, 0, NULL, NULL), fail);
    return 0;
fail:
    return -1;
}

static int create_kernels(Bench *b)
{
    struct {
        cl_kernel *k;
        const char *name;
    } list[] = {{&b->k_closest, "probe_trace_closest"},   {&b->k_any, "probe_trace_any"},
                {&b->k_surface, "probe_hit_surface"},     {&b->k_shade, "probe_shade_feelers"},
                {&b->k_feelers, "probe_feeler_rays"},     {&b->k_walk, "probe_feeler_walk"},
                {&b->k_secondary, "probe_secondary_rays"}};
    for (size_t i = 0; i < sizeof list / sizeof list[0]; i++) {
        cl_int rc;
        if (list[i].k == &b->k_secondary && !(b->r.features & VBCL_FEATURE_TRANSPARENCY))
            continue; /* the scene has no ray trees */
        *list[i].k = clCreateKernel(b->r.probe, list[i].name, &rc);
        CL_CHECK_ERR(rc, list[i].name, fail);
    }
    return 0;
fail:
    return -1;
}

/* The camera rays of the whole image and their first interfaces (hits, media), by the
 * renderer's own camera_generate_rays and scene_intersect_closest. */
static int trace_primary(Bench *b)
{
    VbFrame *f = &b->r.frame_host;
    f->first_pixel = 0;
    f->tile_pixels = (int)b->npix;
    VbDevice *d = &b->dev;
    b->rays = clu_buffer(d, NULL, sizeof(VbRay) * b->npix, CL_MEM_READ_WRITE);
    b->hits = clu_buffer(d, NULL, sizeof(VbHit) * b->npix, CL_MEM_READ_WRITE);
    b->media = clu_buffer(d, NULL, sizeof(VbMedium) * b->npix, CL_MEM_READ_WRITE);
    cl_mem radiance = clu_buffer(d, NULL, sizeof(float) * 4 * b->npix, CL_MEM_READ_WRITE);
    cl_mem counters = clu_buffer(d, NULL, sizeof(cl_uint) * VBCL_COUNTER_WORDS, CL_MEM_READ_WRITE);
    b->h_rays = malloc(sizeof(VbRay) * b->npix);
    int rc = -1;
    if (!b->rays || !b->hits || !b->media || !radiance || !counters || !b->h_rays) goto done;
    CL_CHECK(
        clEnqueueWriteBuffer(d->queue, b->r.buf.frame, CL_TRUE, 0, sizeof *f, f, 0, NULL, NULL),
        done);
    cl_kernel ks[2] = {b->r.k_camera, b->r.k_intersect};
    for (int k = 0; k < 2; k++)
        if (renderer_set_frame_args(&b->r, ks[k], b->rays, (int)b->npix, b->hits, b->media,
                                    radiance, counters) ||
            probe_run(b, ks[k], b->npix, NULL))
            goto done;
    rc = read_buf(b, b->rays, b->h_rays, sizeof(VbRay) * b->npix);
done:
    if (radiance) clReleaseMemObject(radiance);
    if (counters) clReleaseMemObject(counters);
    return rc;
}

/* k_global of material m on the device (index nmaterials is the air: a dielectric). */
static float material_k_global(const Bench *b, int m)
{
    return m < b->s.nmaterials ? b->s.materials[m].gpu.k_global : 1.0f;
}

/* Appends v to a growing list. Returns 0 or -1 (memory). */
static int push_u32(uint32_t **list, size_t *n, size_t *cap, uint32_t v)
{
    if (*n == *cap) {
        size_t c = *cap ? 2 * *cap : 1024;
        uint32_t *p = realloc(*list, c * sizeof *p);
        if (!p) return -1;
        *list = p;
        *cap = c;
    }
    (*list)[(*n)++] = v;
    return 0;
}

/* The primary rays whose first interface is an opaque surface (k_global 0) and those whose
 * first interface is a dielectric, by the material light_sample_shading would shade. */
static int classify_points(Bench *b, uint32_t **opaque, size_t *nopaque, uint32_t **glass,
                           size_t *nglass)
{
    cl_mem surf = clu_buffer(&b->dev, NULL, sizeof(int) * b->npix, CL_MEM_READ_WRITE);
    int *h = malloc(sizeof(int) * b->npix), n = (int)b->npix, rc = -1;
    size_t cap_o = 0, cap_g = 0;
    const size_t sz[] = {sizeof(cl_mem), sizeof(cl_mem), sizeof(cl_mem), sizeof(int),
                         sizeof(cl_mem)};
    const void *vals[] = {&b->rays, &b->hits, &b->media, &n, &surf};
    if (!surf || !h || probe_args(b, b->k_surface, 5, sz, vals) ||
        probe_run(b, b->k_surface, b->npix, NULL) || read_buf(b, surf, h, sizeof(int) * b->npix))
        goto done;
    for (size_t i = 0; i < b->npix; i++) {
        if (h[i] < 0) continue;
        int glassy = material_k_global(b, h[i]) > 0.0f;
        if (glassy ? push_u32(glass, nglass, &cap_g, (uint32_t)i)
                   : push_u32(opaque, nopaque, &cap_o, (uint32_t)i))
            goto done;
    }
    rc = 0;
done:
    free(h);
    if (surf) clReleaseMemObject(surf);
    return rc;
}

/* Runs probe_shade_feelers over the points already in kind->in (kind->npoints of them):
 * into kind->out the feelers each traced; *total gets their sum. */
static int shade_points(Bench *b, Kind *kd, double *ms, unsigned long long *total)
{
    int n = (int)kd->npoints;
    const size_t sz[] = {sizeof(cl_mem), sizeof(cl_mem), sizeof(cl_mem), sizeof(cl_mem),
                         sizeof(int),    sizeof(cl_mem), sizeof(cl_mem)};
    const void *vals[] = {&b->rays, &b->hits, &b->media, &kd->in, &n, &kd->out, &kd->aux};
    if (probe_args(b, b->k_shade, 7, sz, vals) || probe_run(b, b->k_shade, kd->npoints, ms))
        return -1;
    uint32_t *traced = malloc(sizeof(uint32_t) * (kd->npoints + 1));
    if (!traced || read_buf(b, kd->out, traced, sizeof(uint32_t) * kd->npoints)) {
        free(traced);
        return -1;
    }
    *total = 0;
    for (size_t j = 0; j < kd->npoints; j++) *total += traced[j];
    free(traced);
    return 0;
}

/* Device buffers of a shadow kind for its point list (copied from points). */
static int shadow_kind_buffers(Bench *b, Kind *kd, const uint32_t *points, size_t n)
{
    size_t m = n ? n : 1;
    kd->npoints = n;
    kd->in = clu_buffer(&b->dev, n ? points : NULL, sizeof(uint32_t) * n, CL_MEM_READ_ONLY);
    kd->out = clu_buffer(&b->dev, NULL, sizeof(uint32_t) * m, CL_MEM_READ_WRITE);
    kd->aux = clu_buffer(&b->dev, NULL, sizeof(float) * 4 * m, CL_MEM_READ_WRITE);
    return kd->in && kd->out && kd->aux ? 0 : -1;
}

/* The feelers of all opaque points as the host sees them. */
typedef struct FeelerSet {
    size_t npoints, nrays;
    uint32_t *offsets; /* npoints + 1: point j's feelers are [offsets[j], offsets[j + 1]) */
    VbRay *rays;
    uint32_t *steps; /* closest-hit calls of the renderer's walk along each feeler */
    float *end;      /* where the walk ended: distance of its last hit, or -1 (the light) */
} FeelerSet;

static void feeler_set_free(FeelerSet *fs)
{
    free(fs->offsets);
    free(fs->rays);
    free(fs->steps);
    free(fs->end);
    memset(fs, 0, sizeof *fs);
}

/* Exports the feelers of the points in kd->in (probe_feeler_rays, at the offsets of the
 * counts light_shade_local reported in kd->out) and walks them (probe_feeler_walk). Fails,
 * saying so, when the exported feelers are not the ones the renderer traced. */
static int export_feelers(Bench *b, Kind *kd, FeelerSet *fs)
{
    unsigned long long total;
    int rc = -1, np = (int)kd->npoints, nr;
    cl_mem offsets = NULL, feelers = NULL, written = NULL, steps = NULL, end = NULL;
    uint32_t *counts = malloc(sizeof(uint32_t) * (kd->npoints + 1)), *got = NULL;
    fs->npoints = kd->npoints;
    fs->offsets = malloc(sizeof(uint32_t) * (kd->npoints + 1));
    if (!counts || !fs->offsets || shade_points(b, kd, NULL, &total)) goto done;
    if (total > 0x7fffffffULL) {
        fprintf(stderr, "vbcl-bench-rays: %llu feelers: too many, lower --width/--height\n", total);
        goto done;
    }
    if (read_buf(b, kd->out, counts, sizeof(uint32_t) * kd->npoints)) goto done;
    fs->offsets[0] = 0;
    for (size_t j = 0; j < kd->npoints; j++) fs->offsets[j + 1] = fs->offsets[j] + counts[j];
    fs->nrays = (size_t)total;
    nr = (int)total;
    offsets = clu_buffer(&b->dev, fs->offsets, sizeof(uint32_t) * (kd->npoints + 1), 0);
    feelers = clu_buffer(&b->dev, NULL, sizeof(VbRay) * fs->nrays, CL_MEM_READ_WRITE);
    written = clu_buffer(&b->dev, NULL, sizeof(uint32_t) * kd->npoints, CL_MEM_READ_WRITE);
    steps = clu_buffer(&b->dev, NULL, sizeof(uint32_t) * fs->nrays, CL_MEM_READ_WRITE);
    end = clu_buffer(&b->dev, NULL, sizeof(float) * fs->nrays, CL_MEM_READ_WRITE);
    fs->rays = malloc(sizeof(VbRay) * (fs->nrays + 1));
    fs->steps = malloc(sizeof(uint32_t) * (fs->nrays + 1));
    fs->end = malloc(sizeof(float) * (fs->nrays + 1));
    if (!offsets || !feelers || !written || !steps || !end || !fs->rays || !fs->steps || !fs->end)
        goto done;
    const size_t sz[] = {sizeof(cl_mem), sizeof(cl_mem), sizeof(cl_mem), sizeof(cl_mem),
                         sizeof(int),    sizeof(cl_mem), sizeof(cl_mem), sizeof(cl_mem)};
    const void *va[] = {&b->rays, &b->hits, &b->media, &kd->in, &np, &offsets, &feelers, &written};
    if (probe_args(b, b->k_feelers, 8, sz, va) || probe_run(b, b->k_feelers, kd->npoints, NULL))
        goto done;
    got = malloc(sizeof(uint32_t) * (kd->npoints + 1));
    if (!got || read_buf(b, written, got, sizeof(uint32_t) * kd->npoints)) goto done;
    for (size_t j = 0; j < kd->npoints; j++)
        if (got[j] != counts[j]) {
            fprintf(stderr,
                    "vbcl-bench-rays: point %zu: probe_feeler_rays made %u feelers where "
                    "light_shade_local traced %u: kernels/probe.cl no longer samples the feelers "
                    "as kernels/light.cl does\n",
                    j, got[j], counts[j]);
            goto done;
        }
    const size_t sw[] = {sizeof(cl_mem), sizeof(int), sizeof(cl_mem), sizeof(cl_mem),
                         sizeof(cl_mem)};
    const void *vw[] = {&feelers, &nr, &b->media, &steps, &end};
    if (probe_args(b, b->k_walk, 5, sw, vw) || probe_run(b, b->k_walk, fs->nrays, NULL) ||
        read_buf(b, feelers, fs->rays, sizeof(VbRay) * fs->nrays) ||
        read_buf(b, steps, fs->steps, sizeof(uint32_t) * fs->nrays) ||
        read_buf(b, end, fs->end, sizeof(float) * fs->nrays))
        goto done;
    rc = 0;
done:
    free(counts);
    free(got);
    cl_mem all[] = {offsets, feelers, written, steps, end};
    for (int i = 0; i < 5; i++)
        if (all[i]) clReleaseMemObject(all[i]);
    return rc;
}

/* Splits the opaque points into those whose feelers all end at their first closest hit
 * (the kind "shadow": an occlusion test answers them) and the others ("shadow_glass": some
 * feeler crosses an interface and goes on), each kind with its points and feelers. */
static int split_feelers(Bench *b, const uint32_t *points, const FeelerSet *fs)
{
    Kind *sh = &b->kinds[KIND_SHADOW], *gl = &b->kinds[KIND_GLASS];
    uint32_t *psh = NULL, *pgl = NULL;
    size_t nsh = 0, ngl = 0, csh = 0, cgl = 0;
    int rc = -1;
    for (size_t j = 0; j < fs->npoints; j++) {
        int glassy = 0;
        for (uint32_t k = fs->offsets[j]; k < fs->offsets[j + 1]; k++) glassy |= fs->steps[k] > 1;
        size_t nr = fs->offsets[j + 1] - fs->offsets[j];
        Kind *kd = glassy ? gl : sh;
        kd->nrays += nr;
        if (glassy ? push_u32(&pgl, &ngl, &cgl, points[j]) : push_u32(&psh, &nsh, &csh, points[j]))
            goto done;
    }
    sh->rays = malloc(sizeof(VbRay) * (sh->nrays + 1));
    sh->vbcl_out = malloc(sizeof(float) * (sh->nrays + 1));
    gl->rays = malloc(sizeof(VbRay) * (gl->nrays + 1));
    gl->steps = malloc(sizeof(uint32_t) * (gl->nrays + 1));
    gl->vbcl_out = malloc(sizeof(float) * (gl->nrays + 1));
    if (!sh->rays || !sh->vbcl_out || !gl->rays || !gl->steps || !gl->vbcl_out) goto done;
    size_t ish = 0, igl = 0, jsh = 0;
    for (size_t j = 0; j < fs->npoints; j++) {
        int in_sh = jsh < nsh && psh[jsh] == points[j];
        jsh += in_sh;
        for (uint32_t k = fs->offsets[j]; k < fs->offsets[j + 1]; k++) {
            if (in_sh) {
                sh->vbcl_out[ish] = fs->end[k] >= 0.0f ? 1.0f : 0.0f; /* the walk's answer */
                sh->rays[ish++] = fs->rays[k];
                continue;
            }
            gl->rays[igl] = fs->rays[k];
            gl->steps[igl] = fs->steps[k];
            gl->vbcl_out[igl++] = fs->end[k];
            gl->calls += fs->steps[k];
        }
    }
    sh->feelers = clu_buffer(&b->dev, sh->nrays ? sh->rays : NULL, sizeof(VbRay) * sh->nrays,
                             CL_MEM_READ_ONLY);
    sh->blocked = clu_buffer(&b->dev, NULL, sh->nrays, CL_MEM_READ_WRITE);
    if (!sh->feelers || !sh->blocked) goto done;
    rc = shadow_kind_buffers(b, sh, psh, nsh) || shadow_kind_buffers(b, gl, pgl, ngl) ? -1 : 0;
done:
    free(psh);
    free(pgl);
    return rc;
}

/* The rays of kind kd into device buffers for probe_trace_closest: kd->in, kd->out (hits). */
static int closest_kind_buffers(Bench *b, Kind *kd)
{
    kd->in = clu_buffer(&b->dev, kd->nrays ? kd->rays : NULL, sizeof(VbRay) * kd->nrays,
                        CL_MEM_READ_ONLY);
    kd->out = clu_buffer(&b->dev, NULL, sizeof(VbHit) * kd->nrays, CL_MEM_READ_WRITE);
    kd->vbcl_out = malloc(sizeof(float) * (kd->nrays + 1));
    return kd->in && kd->out && kd->vbcl_out ? 0 : -1;
}

/* The reflected and transmitted rays tree_spawn makes at the dielectric points. */
static int prepare_secondary(Bench *b, const uint32_t *points, size_t n)
{
    Kind *kd = &b->kinds[KIND_SECONDARY];
    if (!b->k_secondary || n == 0) return 0;
    cl_mem pts = clu_buffer(&b->dev, points, sizeof(uint32_t) * n, CL_MEM_READ_ONLY);
    cl_mem out = clu_buffer(&b->dev, NULL, sizeof(VbRay) * 2 * n, CL_MEM_READ_WRITE);
    VbRay *all = malloc(sizeof(VbRay) * 2 * n);
    kd->rays = malloc(sizeof(VbRay) * 2 * n);
    int np = (int)n, rc = -1;
    const size_t sz[] = {sizeof(cl_mem), sizeof(cl_mem), sizeof(cl_mem),
                         sizeof(cl_mem), sizeof(int),    sizeof(cl_mem)};
    const void *vals[] = {&b->rays, &b->hits, &b->media, &pts, &np, &out};
    if (!pts || !out || !all || !kd->rays || probe_args(b, b->k_secondary, 6, sz, vals) ||
        probe_run(b, b->k_secondary, n, NULL) || read_buf(b, out, all, sizeof(VbRay) * 2 * n))
        goto done;
    for (size_t i = 0; i < 2 * n; i++)
        if (all[i].sample != 0xffffffffu) kd->rays[kd->nrays++] = all[i];
    rc = closest_kind_buffers(b, kd);
done:
    free(all);
    if (pts) clReleaseMemObject(pts);
    if (out) clReleaseMemObject(out);
    return rc;
}

/* Every kind's rays: the camera rays, the feelers of the opaque points split by what they
 * cross, and the secondary rays of the dielectric points. */
static int prepare_kinds(Bench *b)
{
    uint32_t *opaque = NULL, *glass = NULL;
    size_t nopaque = 0, nglass = 0;
    FeelerSet fs;
    memset(&fs, 0, sizeof fs);
    Kind all = {0};
    int rc = -1;
    if (trace_primary(b) || classify_points(b, &opaque, &nopaque, &glass, &nglass)) goto done;
    Kind *pk = &b->kinds[KIND_PRIMARY];
    pk->nrays = b->npix;
    pk->rays = malloc(sizeof(VbRay) * b->npix);
    if (!pk->rays) goto done;
    memcpy(pk->rays, b->h_rays, sizeof(VbRay) * b->npix);
    if (closest_kind_buffers(b, pk) || shadow_kind_buffers(b, &all, opaque, nopaque) ||
        export_feelers(b, &all, &fs) || split_feelers(b, opaque, &fs) ||
        prepare_secondary(b, glass, nglass))
        goto done;
    rc = 0;
done:
    feeler_set_free(&fs);
    cl_mem mems[] = {all.in, all.out, all.aux};
    for (int i = 0; i < 3; i++)
        if (mems[i]) clReleaseMemObject(mems[i]);
    free(opaque);
    free(glass);
    return rc;
}

/* ---- the measurement ---- */

/* One run of kind k on vbcl; *ms gets the probe kernel's event time. */
static int vbcl_time(Bench *b, int k, double *ms)
{
    Kind *kd = &b->kinds[k];
    if (k == KIND_SHADOW || k == KIND_GLASS) {
        unsigned long long total;
        if (shade_points(b, kd, ms, &total)) return -1;
        if (total != kd->nrays) {
            fprintf(stderr,
                    "vbcl-bench-rays: %s: light_shade_local traced %llu feelers, %zu "
                    "before\n",
                    kind_names[k], total, kd->nrays);
            return -1;
        }
        return 0;
    }
    /* as the renderer traces them: probe_trace_closest's modes 1 (camera) and 2 (ray tree) */
    int n = (int)kd->nrays, mode = k == KIND_PRIMARY ? 1 : 2;
    const size_t sz[] = {sizeof(cl_mem), sizeof(int), sizeof(cl_mem), sizeof(int)};
    const void *vals[] = {&kd->in, &n, &kd->out, &mode};
    return probe_args(b, b->k_closest, 4, sz, vals) || probe_run(b, b->k_closest, kd->nrays, ms)
               ? -1
               : 0;
}

static double embree_time(Bench *b, int k, float *out)
{
    Kind *kd = &b->kinds[k];
    EmbreeOp op = k == KIND_SHADOW  ? EMBREE_OCCLUDED
                  : k == KIND_GLASS ? EMBREE_WALK
                                    : EMBREE_CLOSEST;
    return bench_embree_trace(b->emb, op, kd->rays, kd->nrays, kd->steps, out, NULL, b->o.threads);
}

/* The shadow kind's feelers by scene_trace_any alone (probe_trace_any), into kd->blocked. */
static int vbcl_any_time(Bench *b, Kind *kd, double *ms)
{
    int n = (int)kd->nrays;
    const size_t sz[] = {sizeof(cl_mem), sizeof(int), sizeof(cl_mem)};
    const void *vals[] = {&kd->feelers, &n, &kd->blocked};
    return probe_args(b, b->k_any, 3, sz, vals) || probe_run(b, b->k_any, kd->nrays, ms) ? -1 : 0;
}

/* vbcl's answers for the agreement check, where the timed runs left them on the device: the
 * closest kinds' hits; for "shadow" the renderer's walk (export_feelers) where
 * probe_trace_any agrees with it, else 2, which agrees with nothing (shadow_glass: the walk). */
static int vbcl_answers(Bench *b, int k)
{
    Kind *kd = &b->kinds[k];
    if (k == KIND_GLASS) return 0;
    if (k == KIND_SHADOW) {
        unsigned char *h = malloc(kd->nrays + 1);
        int rc = h ? read_buf(b, kd->blocked, h, kd->nrays) : -1;
        for (size_t i = 0; !rc && i < kd->nrays; i++)
            if ((h[i] != 0) != (kd->vbcl_out[i] > 0.0f)) kd->vbcl_out[i] = 2.0f;
        free(h);
        return rc;
    }
    VbHit *h = malloc(sizeof(VbHit) * (kd->nrays + 1));
    int rc = h ? read_buf(b, kd->out, h, sizeof(VbHit) * kd->nrays) : -1;
    for (size_t i = 0; !rc && i < kd->nrays; i++) kd->vbcl_out[i] = h[i].tri < 0 ? -1.0f : h[i].t;
    free(h);
    return rc;
}

/* Whether two answers agree: both missed, or hit within 1e-4 of the distance plus tol_abs
 * (occlusion flags 0/1 compare exactly). */
static int answers_agree(const Bench *b, float v, float e)
{
    if (v < 0.0f || e < 0.0f) return (v < 0.0f) == (e < 0.0f);
    return fabsf(v - e) <= 1e-4f * fmaxf(v, e) + b->tol_abs;
}

/* A warm-up round, then o.repeats rounds of every kind on vbcl and then on Embree; then
 * the agreement of the last round's answers. */
static int measure(Bench *b)
{
    float *out[KIND_COUNT] = {0};
    int rc = -1;
    for (int k = 0; k < KIND_COUNT; k++)
        if (!(out[k] = malloc(sizeof(float) * (b->kinds[k].nrays + 1)))) goto done;
    for (int rep = -1; rep < b->o.repeats; rep++)
        for (int k = 0; k < KIND_COUNT; k++) {
            Kind *kd = &b->kinds[k];
            double ms = 0.0;
            if (kd->nrays == 0) continue;
            if (vbcl_time(b, k, &ms)) goto done;
            if (rep >= 0) kd->vbcl_ms[rep] = ms;
            if (k == KIND_SHADOW && vbcl_any_time(b, kd, &ms)) goto done;
            if (k == KIND_SHADOW && rep >= 0) kd->any_ms[rep] = ms;
            if (b->emb) ms = embree_time(b, k, out[k]);
            if (rep >= 0) kd->embree_ms[rep] = ms;
        }
    for (int k = 0; k < KIND_COUNT; k++) {
        Kind *kd = &b->kinds[k];
        if (kd->nrays == 0 || !b->emb) continue;
        if (vbcl_answers(b, k)) goto done;
        for (size_t i = 0; i < kd->nrays; i++)
            kd->agree += answers_agree(b, kd->vbcl_out[i], out[k][i]);
        kd->compared = kd->nrays;
    }
    rc = 0;
done:
    for (int k = 0; k < KIND_COUNT; k++) free(out[k]);
    return rc;
}

/* ---- the report ---- */

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(const double *v, int n)
{
    double s[MAX_REPEATS];
    memcpy(s, v, sizeof(double) * (size_t)n);
    qsort(s, (size_t)n, sizeof s[0], cmp_double);
    return n % 2 ? s[n / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
}

/* Mrays/s of the median time, or 0 when there is nothing to say. */
static double mrays(const Kind *kd, const double *ms, int n)
{
    double m = median(ms, n);
    return kd->nrays && m > 0.0 ? (double)kd->nrays / (m * 1e3) : 0.0;
}

/* The grid as asked for: --grid's value, else "scene" (the scene's own) or "auto". */
static const char *grid_label(const Bench *b)
{
    return b->o.grid ? b->o.grid : b->s.grid_res[0] > 0 ? "scene" : "auto";
}

static void report_text(const Bench *b)
{
    const Grid *g = &b->r.cs->grid;
    printf("%s: %u triangles, grid %s (%dx%dx%d), %dx%d camera rays, %u feelers per point "
           "and spherical light; vbcl on %s; %s, %d threads%s; median of %d\n",
           b->s.path, b->s.mesh.ntris, grid_label(b), g->n[0], g->n[1], g->n[2], b->s.width,
           b->s.height, b->r.frame_host.shadow_strata * b->r.frame_host.shadow_strata, b->dev.name,
           bench_embree_describe(), b->o.threads,
           b->emb ? (b->o.robust ? ", robust" : ", not robust") : "", b->o.repeats);
    printf("%-13s %10s %12s %12s %9s %10s\n", "kind", "rays", "vbcl Mray/s", "Embree Mray/s",
           "vbcl/Emb", "agreement");
    for (int k = 0; k < KIND_COUNT; k++) {
        const Kind *kd = &b->kinds[k];
        double v = mrays(kd, kd->vbcl_ms, b->o.repeats), e = mrays(kd, kd->embree_ms, b->o.repeats);
        printf("%-13s %10zu %12.3f ", kind_names[k], kd->nrays, v);
        if (b->emb && kd->nrays)
            printf("%12.3f %9.3f %9.4f%%\n", e, e > 0 ? v / e : 0.0,
                   100.0 * (double)kd->agree / (double)kd->compared);
        else
            printf("%12s %9s %10s\n", "-", "-", "-");
    }
    const Kind *sh = &b->kinds[KIND_SHADOW];
    if (sh->nrays) {
        double a = mrays(sh, sh->any_ms, b->o.repeats), e = mrays(sh, sh->embree_ms, b->o.repeats);
        printf("shadow: scene_trace_any alone on the same feelers %.3f Mray/s", a);
        if (b->emb) printf(", %.3f of Embree", e > 0 ? a / e : 0.0);
        printf("\n");
    }
    if (b->kinds[KIND_GLASS].nrays)
        printf("shadow_glass: %.2f closest-hit calls per feeler\n",
               (double)b->kinds[KIND_GLASS].calls / (double)b->kinds[KIND_GLASS].nrays);
}

static void report_json_kinds(const Bench *b, FILE *f)
{
    for (int k = 0; k < KIND_COUNT; k++) {
        const Kind *kd = &b->kinds[k];
        double v = mrays(kd, kd->vbcl_ms, b->o.repeats), e = mrays(kd, kd->embree_ms, b->o.repeats);
        fprintf(f, "%s    {\"kind\": \"%s\", \"rays\": %zu, \"vbcl_mrays_s\": %.6g", k ? ",\n" : "",
                kind_names[k], kd->nrays, v);
        if (k == KIND_SHADOW || k == KIND_GLASS) fprintf(f, ", \"points\": %zu", kd->npoints);
        if (k == KIND_SHADOW)
            fprintf(f, ", \"vbcl_any_mrays_s\": %.6g", mrays(kd, kd->any_ms, b->o.repeats));
        if (k == KIND_GLASS && kd->nrays)
            fprintf(f, ", \"calls_per_ray\": %.4f", (double)kd->calls / (double)kd->nrays);
        if (b->emb && kd->nrays)
            fprintf(f, ", \"embree_mrays_s\": %.6g, \"ratio\": %.6g, \"agreement\": %.6f", e,
                    e > 0 ? v / e : 0.0, (double)kd->agree / (double)kd->compared);
        fprintf(f, "}");
    }
}

/* s as a JSON string: quoted, with quotes, backslashes and control characters escaped. */
static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

/* The results as one JSON object, written whole (a temporary file renamed into place). */
static int report_json(const Bench *b)
{
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp", b->o.json);
    FILE *f = fopen(tmp, "w");
    if (!f) {
        fprintf(stderr, "vbcl-bench-rays: %s: cannot write\n", b->o.json);
        return -1;
    }
    const Grid *g = &b->r.cs->grid;
    const char *keys[] = {"scene", "grid", "device", "embree"};
    const char *vals[] = {b->s.path, grid_label(b), b->dev.name, bench_embree_describe()};
    for (int i = 0; i < 4; i++) {
        fprintf(f, "%s\"%s\": ", i ? ", " : "{", keys[i]);
        json_string(f, vals[i]);
    }
    fprintf(f,
            ",\n \"cells\": \"%dx%dx%d\", \"triangles\": %u, \"width\": %d, \"height\": %d,\n"
            " \"feelers_per_light\": %u, \"repeats\": %d, \"embree_available\": %s,\n"
            " \"threads\": %d, \"robust\": %d, \"embree_build_ms\": %.3f,\n \"kinds\": [\n",
            g->n[0], g->n[1], g->n[2], b->s.mesh.ntris, b->s.width, b->s.height,
            b->r.frame_host.shadow_strata * b->r.frame_host.shadow_strata, b->o.repeats,
            b->emb ? "true" : "false", b->o.threads, b->o.robust, b->embree_build_ms);
    report_json_kinds(b, f);
    fprintf(f, "\n]}\n");
    int bad = ferror(f);
    if (fclose(f) || bad || rename(tmp, b->o.json)) {
        fprintf(stderr, "vbcl-bench-rays: %s: write failed\n", b->o.json);
        remove(tmp);
        return -1;
    }
    return 0;
}

/* 1 (with a message) when some kind's two sides disagree on more than 0.1% of its rays. */
static int disagreement(const Bench *b)
{
    int bad = 0;
    for (int k = 0; k < KIND_COUNT; k++) {
        const Kind *kd = &b->kinds[k];
        if (kd->compared && (double)kd->agree < 0.999 * (double)kd->compared) {
            fprintf(stderr, "vbcl-bench-rays: %s: vbcl and Embree agree on only %zu of %zu rays\n",
                    kind_names[k], kd->agree, kd->compared);
            bad = 1;
        }
    }
    return bad;
}

/* ---- set-up and main ---- */

/* Loads the scene with the options applied, opens the device and prepares the renderer with
 * the probe kernels. Returns 0 or an exit status after a message. */
static int bench_open(Bench *b)
{
    char err[1024];
    const Options *o = &b->o;
    if (o->json) { /* the output must be writable before any work */
        snprintf(err, sizeof err, "%s.tmp", o->json);
        FILE *f = fopen(err, "w");
        if (!f) {
            fprintf(stderr, "vbcl-bench-rays: --json %s: cannot write there\n", o->json);
            return 2;
        }
        fclose(f);
        remove(err);
    }
    if (scene_load(o->scene, &b->s, err, sizeof err)) {
        fprintf(stderr, "vbcl-bench-rays: %s\n", err);
        return 2;
    }
    if (o->width) b->s.width = o->width;
    if (o->height) b->s.height = o->height;
    if (o->shadow_samples) b->s.shadow_samples = o->shadow_samples;
    if (o->no_cone_test) b->s.shadow_cone_test = 0;
    /* the first feelers only: probe_feeler_rays exports them without tracing, so it cannot
     * know which points a penumbra gives more (light_penumbra) */
    b->s.penumbra_feelers = 1;
    if (o->subgrid_density > 0.0f) b->s.subgrid_density = o->subgrid_density;
    if (o->grid && scene_parse_grid(o->grid, b->s.grid_res)) {
        fprintf(stderr, "vbcl-bench-rays: --grid %s: expected auto, N or NX,NY,NZ\n", o->grid);
        scene_free(&b->s);
        return 2;
    }
    b->npix = (size_t)b->s.width * (size_t)b->s.height;
    int rc = clu_device_open(o->device, &b->dev, err, sizeof err);
    if (!rc) {
        rc = renderer_init(&b->r, &b->dev, &b->s, vbcl_probe_source, &b->st, err, sizeof err);
        if (rc) clu_device_close(&b->dev);
    }
    if (rc) {
        fprintf(stderr, "vbcl-bench-rays: %s\n", err[0] ? err : clu_error());
        scene_free(&b->s);
        return rc;
    }
    float diag = 0.0f;
    for (int k = 0; k < 3; k++)
        diag += (b->r.cs->grid.hi[k] - b->r.cs->grid.lo[k]) *
                (b->r.cs->grid.hi[k] - b->r.cs->grid.lo[k]);
    b->tol_abs = 1e-6f * sqrtf(diag);
    if (create_kernels(b)) {
        fprintf(stderr, "vbcl-bench-rays: %s\n", clu_error());
        return 1;
    }
    return 0;
}

static void bench_close(Bench *b)
{
    for (int k = 0; k < KIND_COUNT; k++) {
        Kind *kd = &b->kinds[k];
        free(kd->rays);
        free(kd->steps);
        free(kd->vbcl_out);
        cl_mem m[] = {kd->in, kd->out, kd->aux, kd->feelers, kd->blocked};
        for (int i = 0; i < 5; i++)
            if (m[i]) clReleaseMemObject(m[i]);
    }
    cl_kernel ks[] = {b->k_closest, b->k_any,  b->k_surface,  b->k_shade,
                      b->k_feelers, b->k_walk, b->k_secondary};
    for (size_t i = 0; i < sizeof ks / sizeof ks[0]; i++)
        if (ks[i]) clReleaseKernel(ks[i]);
    cl_mem ms[] = {b->rays, b->hits, b->media};
    for (int i = 0; i < 3; i++)
        if (ms[i]) clReleaseMemObject(ms[i]);
    free(b->h_rays);
    bench_embree_close(b->emb);
    renderer_release(&b->r);
    scene_free(&b->s);
    clu_device_close(&b->dev);
}

int main(int argc, char **argv)
{
    static Bench b;
    int rc = parse_args(argc, argv, &b.o);
    if (rc >= 0) return rc;
    if ((rc = bench_open(&b))) return rc;
    rc = 1;
    if (prepare_kinds(&b)) {
        fprintf(stderr, "vbcl-bench-rays: preparing the rays failed: %s\n",
                clu_error()[0] ? clu_error() : "out of memory");
        goto done;
    }
    char err[512] = "";
    if (bench_embree_available()) {
        b.emb = bench_embree_open(&b.s.mesh, b.o.robust, b.o.threads, &b.embree_build_ms, err,
                                  sizeof err);
        if (!b.emb) {
            fprintf(stderr, "vbcl-bench-rays: %s\n", err);
            goto done;
        }
    }
    if (measure(&b)) {
        fprintf(stderr, "vbcl-bench-rays: tracing failed: %s\n", clu_error());
        goto done;
    }
    report_text(&b);
    if (b.o.json && report_json(&b)) goto done;
    rc = disagreement(&b);
done:
    bench_close(&b);
    return rc;
}
