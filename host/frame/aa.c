/* aa.c — anti-aliasing on the device (thesis 4.1.2, figures 4.2–4.4): the contrast kernel
 * marks pixels over the whole image and compacts them into per-level lists; the marked
 * pixels are resampled one level deeper in bounded batches (aa_generate_rays, then the
 * frame's own tracing kernels, then aa_reconstruct), and this repeats until nothing is
 * marked. Uniform supersampling (--ssaa) runs the same batches over every pixel. */
#include "aa.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Creates the anti-aliasing buffers (film, level map, mark list) once.
 * Returns 0, 1 (device) or 2 (too large for one allocation) with a message in err. */
static int aa_setup(AaState *aa, Renderer *r, const Scene *s, char *err, size_t errlen)
{
    if (aa->pass) return 0;
    VbDevice *d = r->dev;
    size_t npix = (size_t)s->width * (size_t)s->height;
    if (sizeof(float) * 4 * npix > d->max_alloc) {
        snprintf(err, errlen,
                 "%dx%d: anti-aliasing keeps the image on the device (%.0f MiB), more than one "
                 "allocation on %s allows (%.0f MiB)",
                 s->width, s->height, (double)(sizeof(float) * 4 * npix) / 1048576.0, d->name,
                 (double)d->max_alloc / 1048576.0);
        return 2;
    }
    aa->pass = clu_buffer(d, NULL, sizeof(VbAaPass), CL_MEM_READ_WRITE);
    aa->film = clu_buffer(d, NULL, sizeof(float) * 4 * npix, CL_MEM_READ_WRITE);
    aa->levels = clu_buffer(d, NULL, sizeof(cl_int) * npix, CL_MEM_READ_WRITE);
    aa->marks = clu_buffer(d, NULL, sizeof(cl_uint) * npix, CL_MEM_READ_WRITE);
    aa->mark_counts = clu_buffer(d, NULL, sizeof(cl_uint) * VBCL_AA_MAX_LEVEL, CL_MEM_READ_WRITE);
    if (aa->pass && aa->film && aa->levels && aa->marks && aa->mark_counts) return 0;
    snprintf(err, errlen, "%s: %s", d->name, clu_error());
    return 1;
}

/* Supersamples `count` pixels — list entries first.. of aa->marks, or pixels first.. with
 * pass->identity — with side x side samples each, in batches that fit the ray buffers;
 * each batch is generated, traced by the frame's kernels and reconstructed into the film.
 * Returns 0, or -1 with the error recorded. */
static int aa_run_batches(AaState *aa, Renderer *r, VbAaPass *pass, unsigned first, unsigned count,
                          int side, RenderStats *st)
{
    VbDevice *d = r->dev;
    unsigned nsub = (unsigned)(side * side);
    unsigned per = (unsigned)r->ray_capacity / nsub;
    if (per < 1) per = 1;
    pass->side = side;
    for (unsigned done = 0; done < count; done += per) {
        unsigned k = count - done < per ? count - done : per;
        int nrays = (int)(k * nsub);
        cl_event ev[2] = {0};
        size_t g_rays = ((size_t)nrays + 63) / 64 * 64, g_pix = ((size_t)k + 63) / 64 * 64;
        pass->first = first + done;
        pass->entries = k;
        CL_CHECK(
            clEnqueueWriteBuffer(d->queue, aa->pass, CL_TRUE, 0, sizeof *pass, pass, 0, NULL, NULL),
            fail);
        const cl_uint a = RENDER_FRAME_ARGS;
        if (renderer_set_frame_args(r, r->k_aa_generate, r->rays, nrays, r->hits, r->media,
                                    r->radiance, r->counters) ||
            clu_set_arg(r->k_aa_generate, a, sizeof(cl_mem), &aa->pass) ||
            clu_set_arg(r->k_aa_generate, a + 1, sizeof(cl_mem), &aa->marks))
            goto fail;
        CL_CHECK(clEnqueueNDRangeKernel(d->queue, r->k_aa_generate, 1, NULL, &g_rays,
                                        renderer_local(r, g_rays), 0, NULL, &ev[0]),
                 fail);
        double trace_ms = 0.0;
        if (renderer_trace_rays(r, nrays, st, &trace_ms)) goto fail;
        const cl_mem args[5] = {aa->pass, aa->marks, r->radiance, aa->film, aa->levels};
        for (cl_uint i = 0; i < 5; i++)
            if (clu_set_arg(r->k_aa_reconstruct, i, sizeof(cl_mem), &args[i])) goto fail;
        CL_CHECK(clEnqueueNDRangeKernel(d->queue, r->k_aa_reconstruct, 1, NULL, &g_pix,
                                        renderer_local(r, g_pix), 0, NULL, &ev[1]),
                 fail);
        CL_CHECK(clFinish(d->queue), fail);
        double gen_ms = clu_event_ms(ev[0]);
        st->camera_ms += gen_ms;
        st->aa_refine_ms += gen_ms + trace_ms;
        st->aa_reconstruct_ms += clu_event_ms(ev[1]);
        for (int i = 0; i < 2; i++) clReleaseEvent(ev[i]);
        continue;
    fail:
        for (int i = 0; i < 2; i++)
            if (ev[i]) clReleaseEvent(ev[i]);
        return -1;
    }
    return 0;
}

/* The contrast pass: marks the pixels to refine into per-level segments of aa->marks.
 * counts[l] receives how many pixels at level l were marked. Returns 0 or -1. */
static int aa_mark(AaState *aa, Renderer *r, const Scene *s, VbAaPass *pass, cl_uint counts[],
                   RenderStats *st)
{
    VbDevice *d = r->dev;
    cl_event ev = NULL;
    cl_uint zero[VBCL_AA_MAX_LEVEL] = {0};
    size_t npix = (size_t)s->width * (size_t)s->height, global = (npix + 63) / 64 * 64;
    CL_CHECK(
        clEnqueueWriteBuffer(d->queue, aa->pass, CL_TRUE, 0, sizeof *pass, pass, 0, NULL, NULL),
        fail);
    CL_CHECK(clEnqueueWriteBuffer(d->queue, aa->mark_counts, CL_TRUE, 0, sizeof zero, zero, 0, NULL,
                                  NULL),
             fail);
    const cl_mem args[5] = {aa->pass, aa->film, aa->levels, aa->marks, aa->mark_counts};
    for (cl_uint i = 0; i < 5; i++)
        if (clu_set_arg(r->k_aa_contrast, i, sizeof(cl_mem), &args[i])) goto fail;
    CL_CHECK(clEnqueueNDRangeKernel(d->queue, r->k_aa_contrast, 1, NULL, &global,
                                    renderer_local(r, global), 0, NULL, &ev),
             fail);
    CL_CHECK(clEnqueueReadBuffer(d->queue, aa->mark_counts, CL_TRUE, 0,
                                 sizeof(cl_uint) * VBCL_AA_MAX_LEVEL, counts, 0, NULL, NULL),
             fail);
    st->aa_contrast_ms += clu_event_ms(ev);
    clReleaseEvent(ev);
    return 0;
fail:
    if (ev) clReleaseEvent(ev);
    return -1;
}

static void pass_init(VbAaPass *pass, const Scene *s)
{
    memset(pass, 0, sizeof *pass);
    pass->threshold = s->aa_threshold;
    pass->contrast_scale = exp2f(s->exposure);
    pass->max_level = s->aa_max_level;
    pass->width = s->width;
    pass->height = s->height;
}

int aa_refine(AaState *aa, Renderer *r, const Scene *s, float *rgba, RenderStats *st, char *err,
              size_t errlen)
{
    int rc = aa_setup(aa, r, s, err, errlen);
    if (rc) return rc;
    VbDevice *d = r->dev;
    size_t npix = (size_t)s->width * (size_t)s->height;
    cl_int zero = 0;
    unsigned long long at_level[VBCL_AA_MAX_LEVEL + 1] = {npix}; /* pixels at each level */
    VbAaPass pass;
    pass_init(&pass, s);
    pass.write_level = 1;
    aa->levels_host = malloc(sizeof(int) * npix); /* frame_render freed the last frame's */
    if (!aa->levels_host) {
        snprintf(err, errlen, "out of memory");
        return 1;
    }
    CL_CHECK(clEnqueueWriteBuffer(d->queue, r->buf.frame, CL_TRUE, 0, sizeof r->frame_host,
                                  &r->frame_host, 0, NULL, NULL),
             fail);
    CL_CHECK(clEnqueueWriteBuffer(d->queue, aa->film, CL_TRUE, 0, sizeof(float) * 4 * npix, rgba, 0,
                                  NULL, NULL),
             fail);
    CL_CHECK(clEnqueueFillBuffer(d->queue, aa->levels, &zero, sizeof zero, 0, sizeof(cl_int) * npix,
                                 0, NULL, NULL),
             fail);
    for (int round = 0; round < AA_MAX_ROUNDS; round++) {
        cl_uint counts[VBCL_AA_MAX_LEVEL] = {0};
        unsigned long long offset = 0, marked = 0;
        for (int l = 0; l < VBCL_AA_MAX_LEVEL; l++) {
            pass.seg_offset[l] = (unsigned)offset;
            offset += at_level[l];
        }
        if (aa_mark(aa, r, s, &pass, counts, st)) goto fail;
        for (int l = 0; l < VBCL_AA_MAX_LEVEL; l++) marked += counts[l];
        if (marked == 0) break;
        st->aa_rounds++;
        /* each marked pixel goes one level up: 2^(l+1) x 2^(l+1) new samples */
        for (int l = VBCL_AA_MAX_LEVEL - 1; l >= 0; l--) {
            if (!counts[l]) continue;
            pass.level = l + 1;
            if (aa_run_batches(aa, r, &pass, pass.seg_offset[l], counts[l], 1 << (l + 1), st))
                goto fail;
            st->aa_refined[l + 1] += counts[l];
            at_level[l] -= counts[l];
            at_level[l + 1] += counts[l];
        }
    }
    CL_CHECK(clEnqueueReadBuffer(d->queue, aa->film, CL_TRUE, 0, sizeof(float) * 4 * npix, rgba, 0,
                                 NULL, NULL),
             fail);
    CL_CHECK(clEnqueueReadBuffer(d->queue, aa->levels, CL_TRUE, 0, sizeof(int) * npix,
                                 aa->levels_host, 0, NULL, NULL),
             fail);
    /* samples of a pixel at level L: its centre, then 4 + 16 + ... + 4^L */
    st->samples = 0;
    st->samples_max = 1;
    for (size_t i = 0; i < npix; i++) {
        unsigned n = 1;
        for (int l = 1; l <= aa->levels_host[i]; l++) n += 1u << (2 * l);
        st->samples += n;
        if (n > st->samples_max) st->samples_max = n;
    }
    return 0;
fail:
    snprintf(err, errlen, "%s: %s", d->name, clu_error());
    return 1;
}

int aa_supersample(AaState *aa, Renderer *r, const Scene *s, int n, float *rgba, RenderStats *st,
                   char *err, size_t errlen)
{
    int rc = aa_setup(aa, r, s, err, errlen);
    if (rc) return rc;
    VbDevice *d = r->dev;
    size_t npix = (size_t)s->width * (size_t)s->height;
    VbAaPass pass;
    pass_init(&pass, s);
    pass.identity = 1;
    CL_CHECK(clEnqueueWriteBuffer(d->queue, r->buf.frame, CL_TRUE, 0, sizeof r->frame_host,
                                  &r->frame_host, 0, NULL, NULL),
             fail);
    if (aa_run_batches(aa, r, &pass, 0, (unsigned)npix, n, st)) goto fail;
    CL_CHECK(clEnqueueReadBuffer(d->queue, aa->film, CL_TRUE, 0, sizeof(float) * 4 * npix, rgba, 0,
                                 NULL, NULL),
             fail);
    st->samples = (unsigned long long)npix * (unsigned long long)(n * n);
    st->samples_max = (unsigned)(n * n);
    return 0;
fail:
    snprintf(err, errlen, "%s: %s", d->name, clu_error());
    return 1;
}

void aa_release(AaState *aa)
{
    cl_mem *mems[] = {&aa->pass, &aa->film, &aa->levels, &aa->marks, &aa->mark_counts};
    for (size_t i = 0; i < sizeof mems / sizeof mems[0]; i++)
        if (*mems[i]) CL_WARN(clReleaseMemObject(*mems[i]));
    free(aa->levels_host);
    memset(aa, 0, sizeof *aa);
}

void aa_level_colour(int level, float rgb[3])
{
    /* sRGB palette, dark to hot: 0 none, 1 2x2, 2 4x4, 3 8x8, 4 16x16 */
    static const unsigned char palette[VBCL_AA_MAX_LEVEL + 1][3] = {
        {24, 24, 48}, {40, 90, 220}, {40, 190, 80}, {250, 210, 40}, {230, 40, 40}};
    if (level < 0) level = 0;
    if (level > VBCL_AA_MAX_LEVEL) level = VBCL_AA_MAX_LEVEL;
    for (int c = 0; c < 3; c++) {
        float v = palette[level][c] / 255.0f;
        rgb[c] = v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
    }
}
