/* render.c — the tracing layer: builds the kernel program for a compiled scene, uploads
 * it (device_scene.c), and runs the tracing kernels on one batch of rays at a time. The frame
 * driver (frame.c) decides which batches make an image. */
#include "render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The kernels by name, with their program and the features each needs (render.h
 * RENDER_KERNELS). */
#define RENDER_KERNEL_ENTRY(id, name, prog, frame, needs)                                          \
    {name, offsetof(Renderer, k_##id), prog, frame, needs},
static const struct {
    const char *name;
    size_t field;
    int film;  /* in the film program */
    int frame; /* starts with the frame's arguments */
    unsigned needs;
} kernel_table[] = {RENDER_KERNELS(RENDER_KERNEL_ENTRY)};
#undef RENDER_KERNEL_ENTRY
enum { KERNEL_COUNT = sizeof kernel_table / sizeof kernel_table[0] };

static cl_kernel *kernel_slot(Renderer *r, int i)
{
    return (cl_kernel *)((char *)r + kernel_table[i].field);
}

int renderer_set_frame_args(const Renderer *r, cl_kernel k, cl_mem rays, int nrays, cl_mem hits,
                            cl_mem media, cl_mem radiance, cl_mem counters)
{
    const cl_uint a = SCENE_BUFFER_ARGS;
    if (scene_buffers_set_args(&r->buf, k) || clu_set_arg(k, a, sizeof(cl_mem), &rays) ||
        clu_set_arg(k, a + 1, sizeof(int), &nrays) ||
        clu_set_arg(k, a + 2, sizeof(cl_mem), &hits) ||
        clu_set_arg(k, a + 3, sizeof(cl_mem), &media) ||
        clu_set_arg(k, a + 4, sizeof(cl_mem), &radiance) ||
        clu_set_arg(k, a + 5, sizeof(cl_mem), &counters))
        return -1;
    return 0;
}

/* Lowers r->local_size to 0 unless kernel k runs work-groups of that size. */
static void renderer_fit_local_size(Renderer *r, cl_kernel k)
{
    size_t max = 0;
    if (clGetKernelWorkGroupInfo(k, r->dev->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof max, &max,
                                 NULL) != CL_SUCCESS ||
        max < r->local_size)
        r->local_size = 0;
}

const size_t *renderer_local(const Renderer *r, size_t global)
{
    return r->local_size && global % r->local_size == 0 ? &r->local_size : NULL;
}

static int build_notice_on;

void renderer_build_notice(int on)
{
    build_notice_on = on;
}

/* The film program's build options: it has no features. */
static const char film_options[] = "-cl-std=CL1.2";

/* Builds one program (clu_program_build) into *prog, adding its time to st->build_ms.
 * Returns 0 or 1. */
static int renderer_program(Renderer *r, const char *source, const char *options, cl_program *prog,
                            int *cached, RenderStats *st)
{
    double ms = 0.0;
    *prog = clu_program_build(r->dev, source, options, &ms, cached);
    st->build_ms += ms;
    return *prog ? 0 : 1;
}

/* The tracing program of the scene's class, the film program (and the probe program when
 * asked), and the kernels the scene runs. Returns 0 or 1 (device) with a message in err. */
static int renderer_build(Renderer *r, const Scene *s, const char *probe_source, RenderStats *st,
                          char *err, size_t errlen)
{
    r->features = r->cs->features;
    st->features = r->features;
    st->program = features_program(r->features);
    r->program_features = features_compiled(r->features);
    features_build_options(r->features, s, st->options, sizeof st->options);
    int fresh = !clu_program_seen(r->dev, vbcl_kernel_source, st->options) ||
                !clu_program_seen(r->dev, vbcl_film_source, film_options);
    if (fresh && build_notice_on) {
        char feat[160];
        features_describe(r->program_features &
                              ~(VBCL_FEATURE_FRESNEL_THESIS | VBCL_FEATURE_ENVIRONMENT),
                          feat, sizeof feat);
        fprintf(stderr,
                "vbcl: compiling the %s kernels (%s) for %s, first time only (vbcl --warm-cache "
                "compiles every program ahead)\n",
                features_program_name(st->program), feat, r->dev->name);
    }
    int film_cached;
    st->build_ms = 0.0;
    if (renderer_program(r, vbcl_film_source, film_options, &r->film, &film_cached, st) ||
        renderer_program(r, vbcl_kernel_source, st->options, &r->program, &st->build_cached, st))
        return 1;
    if (probe_source) {
        char popt[512];
        int pc;
        features_program_options(PROGRAM_DISPERSIVE, popt, sizeof popt);
        if (renderer_program(r, probe_source, popt, &r->probe, &pc, st)) return 1;
    }
    r->local_size = r->dev->max_wg >= 64 ? 64 : 0;
    for (int i = 0; i < KERNEL_COUNT; i++) {
        if ((r->features & kernel_table[i].needs) != kernel_table[i].needs) continue;
        cl_int rc;
        cl_kernel *k = kernel_slot(r, i);
        *k = clCreateKernel(kernel_table[i].film ? r->film : r->program, kernel_table[i].name, &rc);
        if (rc != CL_SUCCESS) {
            snprintf(err, errlen, "%s: clCreateKernel(%s): %s", r->dev->name, kernel_table[i].name,
                     clu_error_name(rc));
            return 1;
        }
        renderer_fit_local_size(r, *k);
    }
    return 0;
}

/* tree_trace_secondary's arguments after the frame's, in a program with dispersion: the
 * split records, and which of its two launches it is (0: the white trees, 1: the
 * dispersive subtrees they recorded). */
#define RENDER_TREE_BANDS_ARG (RENDER_FRAME_ARGS + 1)

static int renderer_tree_bands(cl_kernel k, cl_int bands)
{
    return clu_set_arg(k, RENDER_TREE_BANDS_ARG, sizeof bands, &bands);
}

/* The work items from which PoCL compiles a second work-group function of a kernel (its
 * "large grid" one; measured: 64,000 items use the small one, 65,536 the large). */
#define RENDER_LARGE_GRID 65536

/* One launch of every kernel the scene runs, on no work (a frame with no tile pixels, no
 * rays, a zeroed anti-aliasing pass: every kernel's bounds guard returns at once), with the
 * work-group size the render uses: a driver that compiles a kernel at its first launch
 * (PoCL, once for each work-group size) compiles it here. Sets st->first_launch_ms and adds
 * it to st->build_ms; marks the programs seen (clu_program_mark_seen). Returns 0 or -1. */
static int renderer_first_launch(Renderer *r, RenderStats *st)
{
    VbDevice *d = r->dev;
    double t0 = clu_now_ms();
    int rc = -1;
    static const unsigned char zeros[256];
    cl_mem zero = clu_buffer(d, zeros, sizeof zeros, CL_MEM_READ_WRITE);
    if (!zero) return -1;
    VbFrame f = r->frame_host;
    f.tile_pixels = 0;
    CL_CHECK(clEnqueueWriteBuffer(d->queue, r->buf.frame, CL_TRUE, 0, sizeof f, &f, 0, NULL, NULL),
             done);
    size_t global = r->local_size ? r->local_size : 64, whole = RENDER_LARGE_GRID;
    for (int i = 0; i < KERNEL_COUNT; i++) {
        cl_kernel k = *kernel_slot(r, i);
        if (!k) continue;
        cl_uint nargs = 0, first = 0;
        CL_CHECK(clGetKernelInfo(k, CL_KERNEL_NUM_ARGS, sizeof nargs, &nargs, NULL), done);
        if (kernel_table[i].frame) {
            if (renderer_set_frame_args(r, k, r->rays, 0, r->hits, r->media, r->radiance,
                                        r->counters))
                goto done;
            first = RENDER_FRAME_ARGS;
        }
        for (cl_uint a = first; a < nargs; a++) /* the pass, marks, lists, trees, splits */
            if (k == r->k_tree && a == RENDER_TREE_BANDS_ARG
                    ? renderer_tree_bands(k, 0)
                    : clu_set_arg(k, a, sizeof(cl_mem), &zero))
                goto done;
        CL_CHECK(clEnqueueNDRangeKernel(d->queue, k, 1, NULL, &global, renderer_local(r, global), 0,
                                        NULL, NULL),
                 done);
        /* the film kernels also run over a whole image, as large a grid as it is */
        if (kernel_table[i].film)
            CL_CHECK(clEnqueueNDRangeKernel(d->queue, k, 1, NULL, &whole, renderer_local(r, whole),
                                            0, NULL, NULL),
                     done);
    }
    CL_CHECK(clFinish(d->queue), done);
    clu_program_mark_seen(d, vbcl_kernel_source, st->options);
    clu_program_mark_seen(d, vbcl_film_source, film_options);
    rc = 0;
done:
    CL_WARN(clReleaseMemObject(zero));
    st->first_launch_ms = clu_now_ms() - t0;
    st->build_ms += st->first_launch_ms;
    return rc;
}

/* The most pixels of a tile, and so the most work items of a tracing launch: below
 * RENDER_LARGE_GRID, so that the first launches (renderer_first_launch) compile all a
 * render runs. */
#define RENDER_MAX_TILE (RENDER_LARGE_GRID - 64)

/* Tiles bounded so that 32-bit work counters of one tile cannot overflow, and the ray
 * buffers for a tile (at least one pixel's deepest supersamples). Returns 0 or 1. */
static int renderer_alloc_rays(Renderer *r, const Scene *s)
{
    const VbFrame *f = &r->frame_host;
    VbDevice *dev = r->dev;
    long npix = (long)s->width * s->height;
    long per_pixel = 1 + (long)s->nlights * (long)(f->shadow_strata * f->shadow_strata);
    long tile = RENDER_MAX_TILE;
    while (tile > 256 && tile * per_pixel > (1L << 24)) tile /= 2;
    if (tile > npix) tile = npix;
    r->tile_pixels = (int)tile;
    long cap = tile < RENDER_MIN_BATCH_RAYS ? RENDER_MIN_BATCH_RAYS : tile;
    r->ray_capacity = (int)cap;
    r->rays = clu_buffer(dev, NULL, sizeof(VbRay) * (size_t)cap, CL_MEM_READ_WRITE);
    r->hits = clu_buffer(dev, NULL, sizeof(VbHit) * (size_t)cap, CL_MEM_READ_WRITE);
    r->radiance = clu_buffer(dev, NULL, sizeof(float) * 4 * (size_t)cap, CL_MEM_READ_WRITE);
    r->media = clu_buffer(dev, NULL, sizeof(VbMedium) * (size_t)cap, CL_MEM_READ_WRITE);
    r->counters = clu_buffer(dev, NULL, sizeof(cl_uint) * VBCL_COUNTER_WORDS, CL_MEM_READ_WRITE);
    if (!r->rays || !r->hits || !r->radiance || !r->media || !r->counters) return 1;
    /* a program with dispersion takes the split records whether the scene disperses or not;
     * only a dispersive scene writes them */
    if (r->program_features & VBCL_FEATURE_DISPERSION)
        r->splits = clu_buffer(
            dev, NULL,
            (r->features & VBCL_FEATURE_DISPERSION) ? sizeof(VbSplitSet) * (size_t)cap : 0,
            CL_MEM_READ_WRITE);
    return (r->program_features & VBCL_FEATURE_DISPERSION) && !r->splits;
}

int renderer_init_compiled(Renderer *r, VbDevice *dev, const CompiledScene *cs, const Scene *s,
                           const char *probe_source, RenderStats *st, char *err, size_t errlen)
{
    memset(r, 0, sizeof *r);
    r->dev = dev;
    r->cs = cs;
    r->frame_host = cs->frame;
    clu_error_clear();
    err[0] = '\0';
    int rc = renderer_build(r, s, probe_source, st, err, errlen);
    double t0 = clu_now_ms();
    if (!rc) rc = scene_buffers_upload(&r->buf, dev, cs, s, err, errlen);
    if (!rc) rc = renderer_alloc_rays(r, s);
    double t1 = clu_now_ms();
    if (!rc && renderer_first_launch(r, st)) rc = 1;
    t0 += clu_now_ms() - t1; /* the first launches are build time, not upload */
    if (rc) {
        if (rc == 1 && !err[0])
            snprintf(err, errlen, "%s: %s", dev->name,
                     clu_error()[0] ? clu_error() : "out of memory");
        renderer_release(r);
        return rc;
    }
    st->upload_ms = clu_now_ms() - t0;
    st->tile_pixels = r->tile_pixels;
    return 0;
}

int renderer_init(Renderer *r, VbDevice *dev, const Scene *s, const char *probe_source,
                  RenderStats *st, char *err, size_t errlen)
{
    CompiledScene *cs = calloc(1, sizeof *cs);
    if (!cs) {
        memset(r, 0, sizeof *r);
        snprintf(err, errlen, "out of memory");
        return 1;
    }
    int rc = compiled_scene_build(cs, s, dev->max_alloc, err, errlen);
    st->grid_ms = cs->grid.build_ms;
    if (!rc) rc = renderer_init_compiled(r, dev, cs, s, probe_source, st, err, errlen);
    if (rc) {
        compiled_scene_free(cs);
        free(cs);
        return rc;
    }
    r->own_cs = cs;
    return 0;
}

int renderer_trace_rays(Renderer *r, int n, RenderStats *st, double *trace_ms)
{
    VbDevice *d = r->dev;
    cl_event ev[4] = {0};
    cl_uint zero = 0, slots[VBCL_COUNTER_WORDS], counts[VBCL_COUNTERS] = {0};
    size_t global = ((size_t)n + 63) / 64 * 64;
    int rc = -1;
    CL_CHECK(clEnqueueFillBuffer(d->queue, r->counters, &zero, sizeof zero, 0, sizeof slots, 0,
                                 NULL, NULL),
             done);
    /* first interfaces, local shading, with dielectrics the ray trees, and with dispersion
     * the dispersive subtrees the trees left in r->splits */
    cl_kernel stages[4] = {r->k_intersect, r->k_shading, r->k_tree,
                           (r->features & VBCL_FEATURE_DISPERSION) ? r->k_tree : NULL};
    for (int k = 0; k < 4; k++) {
        if (!stages[k]) continue;
        if (renderer_set_frame_args(r, stages[k], r->rays, n, r->hits, r->media, r->radiance,
                                    r->counters))
            goto done;
        /* the arguments are taken at each launch: the same kernel runs twice */
        if (k >= 2 && r->splits &&
            (clu_set_arg(stages[k], RENDER_FRAME_ARGS, sizeof(cl_mem), &r->splits) ||
             renderer_tree_bands(stages[k], k == 3)))
            goto done;
        CL_CHECK(clEnqueueNDRangeKernel(d->queue, stages[k], 1, NULL, &global,
                                        renderer_local(r, global), 0, NULL, &ev[k]),
                 done);
    }
    CL_CHECK(
        clEnqueueReadBuffer(d->queue, r->counters, CL_TRUE, 0, sizeof slots, slots, 0, NULL, NULL),
        done);
    for (int g = 0; g < VBCL_COUNTER_SLOTS; g++) /* the work groups' copies */
        for (int k = 0; k < VBCL_COUNTERS; k++) counts[k] += slots[g * VBCL_COUNTER_STRIDE + k];
    double ms[4];
    for (int k = 0; k < 4; k++) ms[k] = ev[k] ? clu_event_ms(ev[k]) : 0.0;
    st->intersect_ms += ms[0];
    st->shading_ms += ms[1];
    st->tree_ms += ms[2];
    st->dispersion_ms += ms[3];
    if (trace_ms) *trace_ms += ms[0] + ms[1] + ms[2] + ms[3];
    st->rays_primary += (unsigned long long)n;
#define RENDER_ADD_COUNTER(name, index, field, group, key) st->field += counts[VBCL_COUNT_##name];
    VBCL_COUNTER_LIST(RENDER_ADD_COUNTER)
#undef RENDER_ADD_COUNTER
    st->by_depth[0] += (unsigned long long)n;
    for (int k = 1; k < VBCL_COUNT_DEPTH_BINS; k++)
        st->by_depth[k] += counts[VBCL_COUNT_DEPTH0 + k];
    rc = 0;
done:
    for (int i = 0; i < 4; i++)
        if (ev[i]) clReleaseEvent(ev[i]);
    return rc;
}

int renderer_trace_tile(Renderer *r, long first, int n, float *rgba, RenderStats *st)
{
    VbDevice *d = r->dev;
    VbFrame *f = &r->frame_host;
    f->first_pixel = (int)first;
    f->tile_pixels = n;
    cl_event ev[2] = {0};
    size_t global = ((size_t)n + 63) / 64 * 64;
    int rc = -1;
    CL_CHECK(clEnqueueWriteBuffer(d->queue, r->buf.frame, CL_FALSE, 0, sizeof *f, f, 0, NULL, NULL),
             done);
    if (renderer_set_frame_args(r, r->k_camera, r->rays, n, r->hits, r->media, r->radiance,
                                r->counters))
        goto done;
    CL_CHECK(clEnqueueNDRangeKernel(d->queue, r->k_camera, 1, NULL, &global,
                                    renderer_local(r, global), 0, NULL, &ev[0]),
             done);
    if (renderer_trace_rays(r, n, st, NULL)) goto done;
    CL_CHECK(clEnqueueReadBuffer(d->queue, r->radiance, CL_TRUE, 0, sizeof(float) * 4 * (size_t)n,
                                 rgba + 4 * first, 0, NULL, &ev[1]),
             done);
    st->camera_ms += clu_event_ms(ev[0]);
    st->readback_ms += clu_event_ms(ev[1]);
    st->tiles++;
    rc = 0;
done:
    for (int i = 0; i < 2; i++)
        if (ev[i]) clReleaseEvent(ev[i]);
    return rc;
}

void renderer_release(Renderer *r)
{
    scene_buffers_release(&r->buf);
    cl_mem *mems[] = {&r->rays, &r->hits, &r->media, &r->radiance, &r->counters, &r->splits};
    for (size_t i = 0; i < sizeof mems / sizeof mems[0]; i++)
        if (*mems[i]) {
            CL_WARN(clReleaseMemObject(*mems[i]));
            *mems[i] = NULL;
        }
    for (int i = 0; i < KERNEL_COUNT; i++)
        if (*kernel_slot(r, i)) {
            CL_WARN(clReleaseKernel(*kernel_slot(r, i)));
            *kernel_slot(r, i) = NULL;
        }
    cl_program *progs[] = {&r->program, &r->film, &r->probe};
    for (size_t i = 0; i < sizeof progs / sizeof progs[0]; i++)
        if (*progs[i]) {
            CL_WARN(clReleaseProgram(*progs[i]));
            *progs[i] = NULL;
        }
    if (r->own_cs) {
        compiled_scene_free(r->own_cs);
        free(r->own_cs);
        r->own_cs = NULL;
    }
}
