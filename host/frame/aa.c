/* aa.c — anti-aliasing on the device (thesis 4.1.2, figures 4.2–4.4). Adaptive: each round
 * the contrast kernel marks the quadtree leaves that fail against an adjacent leaf and
 * compacts them into one list; the list is traced in full batches of three new samples
 * per marked node (aa_split_rays, the frame's tracing kernels, aa_split_store), and this
 * repeats until nothing is marked; aa_resolve then makes each refined pixel the mean of
 * its finest cells, each the value of the nearest sample, its own or a refined
 * neighbour's (or of its leaf). Uniform supersampling (--ssaa) traces N x N samples of
 * every pixel. */
#include "aa.h"

#include "aa_tree.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { AA_COUNTS = VBCL_AA_MAX_LEVEL + 2 }; /* marks, marks per level 0..3(4), tree slots */
#define AA_ALL UINT_MAX                     /* aa_mark: test every pixel, not a list */

/* The pixels of r's frame window (VbFrame.window_width ...): the film's, which anti-aliasing
 * refines; the whole image unless the frame is cropped. */
static size_t aa_pixels(const Renderer *r)
{
    return (size_t)r->frame_host.window_width * (size_t)r->frame_host.window_height;
}

int aa_reach(const Scene *s)
{
    if (s->ssaa > 1 || !(s->aa_threshold > 0.0f)) return 0;
    return AA_MAX_ROUNDS - s->aa_min_level + 1;
}

/* Creates the buffers every anti-aliasing mode needs (pass, film, slots, info, counts)
 * once. Returns 0, 1 (device) or 2 (too large for one allocation) with a message in err. */
static int aa_setup(AaState *aa, Renderer *r, char *err, size_t errlen)
{
    if (aa->pass) return 0;
    VbDevice *d = r->dev;
    size_t npix = aa_pixels(r);
    if (sizeof(float) * 4 * npix > d->max_alloc) {
        snprintf(err, errlen,
                 "%dx%d: anti-aliasing keeps the image on the device (%.0f MiB), more than one "
                 "allocation on %s allows (%.0f MiB)",
                 r->frame_host.window_width, r->frame_host.window_height,
                 (double)(sizeof(float) * 4 * npix) / 1048576.0, d->name,
                 (double)d->max_alloc / 1048576.0);
        return 2;
    }
    aa->pass = clu_buffer(d, NULL, sizeof(VbAaPass), CL_MEM_READ_WRITE);
    aa->film = clu_buffer(d, NULL, sizeof(float) * 4 * npix, CL_MEM_READ_WRITE);
    aa->slots = clu_buffer(d, NULL, sizeof(cl_int) * npix, CL_MEM_READ_WRITE);
    aa->info = clu_buffer(d, NULL, sizeof(cl_int) * npix, CL_MEM_READ_WRITE);
    aa->counts = clu_buffer(d, NULL, sizeof(cl_uint) * AA_COUNTS, CL_MEM_READ_WRITE);
    aa->split = clu_buffer(d, NULL, sizeof(cl_uint) * 2 * npix, CL_MEM_READ_WRITE);
    if (aa->pass && aa->film && aa->slots && aa->info && aa->counts && aa->split) return 0;
    snprintf(err, errlen, "%s: %s", d->name, clu_error());
    return 1;
}

/* The capacity a growing buffer of `elem`-byte elements gets when it must hold `need`:
 * twice the need, as far as one allocation on d allows. Returns 0, or 2 (not even the need
 * fits) with a message in err. */
static int aa_capacity(const VbDevice *d, size_t need, size_t elem, const char *what, size_t *want,
                       char *err, size_t errlen)
{
    *want = 2 * need;
    if (*want * elem > d->max_alloc) *want = d->max_alloc / elem;
    if (*want >= need) return 0;
    snprintf(err, errlen,
             "anti-aliasing needs %.0f MiB for its %s, more than one allocation on %s "
             "allows (%.0f MiB); raise the threshold, or lower --aa-max-level or --aa-min-level",
             (double)(need * elem) / 1048576.0, what, d->name, (double)d->max_alloc / 1048576.0);
    return 2;
}

int aa_check_fits(const Renderer *r, const Scene *s, char *err, size_t errlen)
{
    size_t want, npix = aa_pixels(r);
    if (s->ssaa > 1 || !(s->aa_threshold > 0.0f) || s->aa_min_level == 0) return 0;
    return aa_capacity(r->dev, npix, sizeof(float) * 4 * AA_TREE_NODES, "trees", &want, err,
                       errlen);
}

/* The message of a failed allocation of `bytes` for anti-aliasing's `what`: out of memory
 * named with what would take less, or the device's error. */
static void aa_alloc_failed(const VbDevice *d, const char *what, size_t bytes, char *err,
                            size_t errlen)
{
    if (clu_error_out_of_memory())
        snprintf(err, errlen,
                 "out of memory for anti-aliasing's %s (%.0f MiB more on %s); raise the "
                 "threshold, lower --aa-max-level or --aa-min-level, or render a smaller image",
                 what, (double)bytes / 1048576.0, d->name);
    else
        snprintf(err, errlen, "%s: %s", d->name, clu_error());
}

/* Makes *buf hold at least `need` elements of `elem` bytes (capacity *cap), keeping its
 * first `keep` elements: a new buffer (aa_capacity), the old contents copied. Returns 0, 1
 * (device) or 2 (more than one allocation allows) with a message in err. */
static int aa_reserve(Renderer *r, cl_mem *buf, size_t *cap, size_t need, size_t elem, size_t keep,
                      const char *what, char *err, size_t errlen)
{
    VbDevice *d = r->dev;
    size_t want;
    if (need <= *cap) return 0;
    if (aa_capacity(d, need, elem, what, &want, err, errlen)) return 2;
    cl_mem nb = clu_buffer(d, NULL, want * elem, CL_MEM_READ_WRITE);
    if (!nb) goto fail;
    if (keep)
        CL_CHECK(clEnqueueCopyBuffer(d->queue, *buf, nb, 0, 0, keep * elem, 0, NULL, NULL), fail);
    CL_CHECK(clFinish(d->queue), fail);
    if (*buf) CL_WARN(clReleaseMemObject(*buf));
    *buf = nb;
    *cap = want;
    return 0;
fail:
    if (nb) CL_WARN(clReleaseMemObject(nb));
    aa_alloc_failed(d, what, want * elem, err, errlen);
    return 1;
}

/* Makes the trees hold at least `need` slots, keeping the first `keep`: both buffers grow
 * to twice the need together (the values' levels begin at multiples of the capacity,
 * aa_tree.h), each level of the values copied to its new place. Returns as aa_reserve. */
static int aa_reserve_trees(AaState *aa, Renderer *r, size_t need, size_t keep, char *err,
                            size_t errlen)
{
    VbDevice *d = r->dev;
    size_t elem = sizeof(float) * 4 * AA_TREE_NODES, want;
    if (need <= aa->tree_cap) return 0;
    if (aa_capacity(d, need, elem, "trees", &want, err, errlen)) return 2;
    if (want > aa->npix && need <= aa->npix) want = aa->npix; /* a slot per pixel at most */
    cl_mem levels = clu_buffer(d, NULL, want * VBCL_AA_CELLS, CL_MEM_READ_WRITE);
    cl_mem values = levels ? clu_buffer(d, NULL, want * elem, CL_MEM_READ_WRITE) : NULL;
    if (!values) goto fail;
    if (keep) {
        CL_CHECK(clEnqueueCopyBuffer(d->queue, aa->levels, levels, 0, 0, keep * VBCL_AA_CELLS, 0,
                                     NULL, NULL),
                 fail);
        for (int l = 1; l <= VBCL_AA_MAX_LEVEL; l++) {
            size_t node = sizeof(float) * 4, per = (size_t)1 << (2 * l);
            size_t base = (size_t)aa_level_base(l);
            CL_CHECK(clEnqueueCopyBuffer(d->queue, aa->values, values, base * aa->tree_cap * node,
                                         base * want * node, keep * per * node, 0, NULL, NULL),
                     fail);
        }
    }
    CL_CHECK(clFinish(d->queue), fail);
    if (aa->levels) CL_WARN(clReleaseMemObject(aa->levels));
    if (aa->values) CL_WARN(clReleaseMemObject(aa->values));
    aa->levels = levels;
    aa->values = values;
    aa->tree_cap = want;
    return 0;
fail:
    if (levels) CL_WARN(clReleaseMemObject(levels));
    if (values) CL_WARN(clReleaseMemObject(values));
    aa_alloc_failed(d, "trees", want * (elem + VBCL_AA_CELLS), err, errlen);
    return 1;
}

/* Waits for every launch and pass write in flight (clFinish) and adds each launch's device
 * time to its fields. The host waits only where it needs a result (a count it decides on,
 * the image), or where AA_PENDING are in flight: an in-order queue runs each command after
 * the one before, so a launch needs no wait before the next is enqueued. Returns 0 or -1. */
static int aa_settle(AaState *aa, Renderer *r)
{
    cl_int done = CL_SUCCESS;
    if (aa->npending || aa->npasses) done = clFinish(r->dev->queue);
    for (int i = 0; i < aa->npending; i++) {
        double ms = done == CL_SUCCESS ? clu_event_ms(aa->pending[i]) : 0.0;
        for (int k = 0; k < 2; k++)
            if (aa->pending_ms[i][k]) *aa->pending_ms[i][k] += ms;
        clReleaseEvent(aa->pending[i]);
    }
    aa->npending = aa->npasses = 0;
    return done == CL_SUCCESS ? 0 : clu_fail(done, "clFinish", __FILE__, __LINE__);
}

/* Enqueues kernel k over `global` work items with the given buffers as its arguments
 * (from argument `first` on), without waiting; its device time is added to *ms and *ms2
 * (may be NULL) when the host next waits (aa_settle). Returns 0 or -1. */
static int aa_launch(AaState *aa, Renderer *r, cl_kernel k, cl_uint first, const cl_mem *args,
                     int nargs, size_t items, double *ms, double *ms2)
{
    cl_event ev = NULL;
    size_t global = (items + 63) / 64 * 64;
    if (aa->npending == AA_PENDING && aa_settle(aa, r)) return -1;
    for (int i = 0; i < nargs; i++)
        if (clu_set_arg(k, first + (cl_uint)i, sizeof(cl_mem), &args[i])) return -1;
    CL_CHECK(clEnqueueNDRangeKernel(r->dev->queue, k, 1, NULL, &global, renderer_local(r, global),
                                    0, NULL, &ev),
             fail);
    aa->pending[aa->npending] = ev;
    aa->pending_ms[aa->npending][0] = ms;
    aa->pending_ms[aa->npending++][1] = ms2;
    return 0;
fail:
    return -1;
}

/* Writes pass into aa->pass without waiting, from a copy that stays until the host next
 * waits (aa_settle). Returns 0 or -1. */
static int aa_write_pass(AaState *aa, Renderer *r, VbAaPass *pass)
{
    pass->tree_cap = (unsigned)aa->tree_cap;
    if (aa->npasses == AA_PENDING && aa_settle(aa, r)) return -1;
    VbAaPass *copy = &aa->passes[aa->npasses++];
    *copy = *pass;
    CL_CHECK(clEnqueueWriteBuffer(r->dev->queue, aa->pass, CL_FALSE, 0, sizeof *copy, copy, 0, NULL,
                                  NULL),
             fail);
    return 0;
fail:
    return -1;
}

/* Traces `nrays` rays that kernel gen (a frame kernel taking the pass, and the mark list
 * when marks is set) generates for the batch in pass, into r->radiance. Returns 0 or -1. */
static int aa_trace_batch(AaState *aa, Renderer *r, cl_kernel gen, VbAaPass *pass, int with_marks,
                          int nrays, RenderStats *st)
{
    const cl_uint a = RENDER_FRAME_ARGS;
    double trace_ms = 0.0;
    if (aa_write_pass(aa, r, pass) || renderer_set_frame_args(r, gen, r->rays, nrays, r->hits,
                                                              r->media, r->radiance, r->counters))
        return -1;
    const cl_mem args[2] = {aa->pass, aa->marks};
    if (aa_launch(aa, r, gen, a, args, with_marks ? 2 : 1, (size_t)nrays, &st->camera_ms,
                  &st->aa_refine_ms) ||
        renderer_trace_rays(r, nrays, st, &trace_ms))
        return -1;
    st->aa_refine_ms += trace_ms;
    return 0;
}

/* Clears round `round`'s half of aa->split (two rounds' split blocks per pixel), for the
 * round's splits to OR into. Returns 0 or -1. */
static int aa_clear_split(AaState *aa, Renderer *r, int round, size_t npix)
{
    cl_uint zero = 0;
    CL_CHECK(clEnqueueFillBuffer(r->dev->queue, aa->split, &zero, sizeof zero,
                                 (size_t)(round % 2) * sizeof(cl_uint) * npix,
                                 sizeof(cl_uint) * npix, 0, NULL, NULL),
             fail);
    return 0;
fail:
    return -1;
}

/* The contrast pass: marks the leaves to split into aa->marks; counts[0] receives how many,
 * counts[1 + l] how many at level l, counts[AA_COUNTS - 1] the tree slots in use. Tests
 * every pixel (aa_contrast_mark) when `listed` is AA_ALL, else the `listed` pixels in
 * aa->list (at least one; aa_contrast_list), after clearing this round's half of
 * aa->split. Returns 0 or -1. */
static int aa_mark(AaState *aa, Renderer *r, VbAaPass *pass, unsigned listed,
                   cl_uint counts[AA_COUNTS], RenderStats *st)
{
    VbDevice *d = r->dev;
    size_t npix = aa_pixels(r);
    cl_uint zero[AA_COUNTS - 1] = {0};
    pass->entries = listed;
    if (aa_write_pass(aa, r, pass)) return -1;
    CL_CHECK(
        clEnqueueWriteBuffer(d->queue, aa->counts, CL_TRUE, 0, sizeof zero, zero, 0, NULL, NULL),
        fail);
    const cl_mem args[9] = {aa->pass,  aa->film,   aa->slots, aa->levels, aa->values,
                            aa->marks, aa->counts, aa->split, aa->list};
    if (listed == AA_ALL
            ? aa_launch(aa, r, r->k_aa_contrast, 0, args, 8, npix, &st->aa_contrast_ms, NULL)
            : aa_clear_split(aa, r, pass->round, npix) ||
                  aa_launch(aa, r, r->k_aa_contrast_list, 0, args, 9, listed, &st->aa_contrast_ms,
                            NULL))
        return -1;
    CL_CHECK(clEnqueueReadBuffer(d->queue, aa->counts, CL_TRUE, 0, sizeof(cl_uint) * AA_COUNTS,
                                 counts, 0, NULL, NULL),
             fail);
    return aa_settle(aa, r);
fail:
    return -1;
}

/* Progress of refinement on stderr (like pass 0's): the round, the deepest level it
 * reaches, samples so far and the time left in the round at its rate so far. */
typedef struct AaProgress {
    int on, shown;
    double t_start, t_round;
} AaProgress;

static void aa_progress(AaProgress *pg, int round, int level, unsigned long long samples,
                        unsigned long long npix, double done, double total)
{
    double now = clu_now_ms(), el = now - pg->t_start, rel = now - pg->t_round;
    if (!pg->on || (el < 1000.0 && !pg->shown)) return;
    double eta = done > 0 ? rel * (total - done) / done : 0.0;
    fprintf(stderr,
            "\rvbcl: anti-aliasing round %d, level %d: %3.0f%%, %llu samples (%.1f/pixel), "
            "%.1f s, round done in about %.1f s ",
            round + 1, level, 100.0 * done / total, samples, (double)samples / (double)npix,
            el / 1000.0, eta / 1000.0);
    pg->shown = 1;
}

/* Splits the k nodes listed in aa->marks from entry `first` on (at most a third of the ray
 * buffers): their three new samples each are traced and stored into the trees. Returns 0
 * or -1. */
static int aa_split_batch(AaState *aa, Renderer *r, VbAaPass *pass, unsigned first, unsigned k,
                          RenderStats *st)
{
    pass->first = first;
    pass->entries = k;
    if (aa_trace_batch(aa, r, r->k_aa_split_rays, pass, 1, (int)(3 * k), st)) return -1;
    const cl_mem args[10] = {aa->pass,        aa->marks,  r->radiance, aa->film,   aa->slots,
                             aa->slot_pixels, aa->levels, aa->values,  aa->counts, aa->split};
    if (aa_launch(aa, r, r->k_aa_split_store, 0, args, 10, k, &st->aa_reconstruct_ms, NULL))
        return -1;
    st->samples += 3ull * k;
    return 0;
}

/* Splits the `marked` nodes listed in aa->marks: batches of whole nodes (three rays each)
 * as wide as the ray buffers, each traced and stored into the trees. Returns 0 or -1. */
static int aa_split(AaState *aa, Renderer *r, VbAaPass *pass, unsigned marked, RenderStats *st,
                    AaProgress *pg, int round, int level, unsigned long long npix)
{
    unsigned per = (unsigned)r->ray_capacity / 3;
    for (unsigned done = 0; done < marked; done += per) {
        unsigned k = marked - done < per ? marked - done : per;
        if (aa_split_batch(aa, r, pass, done, k, st)) return -1;
        aa_progress(pg, round, level, st->samples, npix, done + k, marked);
    }
    return 0;
}

/* Lists in aa->list the pixels the round after `pass->round` tests (aa_dirty_list): those
 * in or next to a pixel of the `marked` nodes in aa->marks, which that round split; *listed
 * receives how many. Returns 0 or -1. */
static int aa_list_dirty(AaState *aa, Renderer *r, VbAaPass *pass, unsigned marked,
                         unsigned *listed, RenderStats *st)
{
    cl_uint zero = 0;
    pass->first = 0;
    pass->entries = marked;
    if (aa_write_pass(aa, r, pass)) return -1;
    CL_CHECK(clEnqueueWriteBuffer(r->dev->queue, aa->list_count, CL_TRUE, 0, sizeof zero, &zero, 0,
                                  NULL, NULL),
             fail);
    const cl_mem args[5] = {aa->pass, aa->marks, aa->tags, aa->list, aa->list_count};
    if (aa_launch(aa, r, r->k_aa_dirty_list, 0, args, 5, marked, &st->aa_contrast_ms, NULL))
        return -1;
    CL_CHECK(clEnqueueReadBuffer(r->dev->queue, aa->list_count, CL_TRUE, 0, sizeof(cl_uint), listed,
                                 0, NULL, NULL),
             fail);
    return aa_settle(aa, r);
fail:
    return -1;
}

/* Round `level` of the rounds below s->aa_min_level, which split every node of every pixel
 * at that level without a contrast test: the host lists the nodes `per` at a time, in pixel
 * order (into marks, then aa->marks, each holding per entries), clears this round's half of
 * aa->split (aa_contrast_mark's work in a tested round) and splits them as aa_split does.
 * Returns 0 or -1. */
static int aa_split_all(AaState *aa, Renderer *r, VbAaPass *pass, int level, cl_uint *marks,
                        unsigned per, RenderStats *st, AaProgress *pg, unsigned long long npix)
{
    VbDevice *d = r->dev;
    unsigned side = 1u << level, nodes = side * side;
    unsigned long long total = npix * nodes;
    if (aa_clear_split(aa, r, level, (size_t)npix)) return -1;
    pass->round = level;
    for (unsigned long long done = 0; done < total; done += per) {
        unsigned k = total - done < per ? (unsigned)(total - done) : per;
        for (unsigned i = 0; i < k; i++) {
            unsigned long long e = done + i;
            unsigned node = (unsigned)(e % nodes);
            marks[2 * i] = (cl_uint)(e / nodes);
            marks[2 * i + 1] = aa_node_code(level, (int)(node % side), (int)(node / side));
        }
        CL_CHECK(clEnqueueWriteBuffer(d->queue, aa->marks, CL_TRUE, 0, sizeof(cl_uint) * 2 * k,
                                      marks, 0, NULL, NULL),
                 fail);
        if (aa_split_batch(aa, r, pass, 0, k, st)) goto fail;
        aa_progress(pg, level, level + 1, st->samples, npix, (double)(done + k), (double)total);
    }
    return 0;
fail:
    return -1;
}

/* The rounds below the minimum level `forced` (aa_split_all, one per level), with room made
 * for every pixel's tree slot and a batch of host-listed nodes. Returns 0, or 1 (device) / 2
 * (too large) with a message in err. */
static int aa_split_levels(AaState *aa, Renderer *r, VbAaPass *pass, int forced, RenderStats *st,
                           AaProgress *pg, unsigned long long npix, char *err, size_t errlen)
{
    unsigned long long most = npix << (2 * (forced - 1)); /* the last round's nodes */
    unsigned per = (unsigned)r->ray_capacity / 3;
    if (most < per) per = (unsigned)most;
    cl_uint *marks = malloc(sizeof(cl_uint) * 2 * per);
    if (!marks) {
        snprintf(err, errlen, "out of memory");
        return 1;
    }
    int rc = aa_reserve(r, &aa->marks, &aa->mark_cap, per, sizeof(cl_uint) * 2, 0, "mark list", err,
                        errlen);
    if (!rc) rc = aa_reserve_trees(aa, r, npix, 0, err, errlen);
    if (!rc)
        rc = aa_reserve(r, &aa->slot_pixels, &aa->slot_pixels_cap, npix, sizeof(cl_int), 0, "trees",
                        err, errlen);
    pg->t_round = clu_now_ms();
    for (int level = 0; !rc && level < forced; level++) {
        if (aa_split_all(aa, r, pass, level, marks, per, st, pg, npix)) {
            snprintf(err, errlen, "%s: %s", r->dev->name, clu_error());
            rc = 1;
        } else {
            st->aa_rounds++;
        }
    }
    free(marks);
    return rc;
}

/* Ends refinement: each refined pixel becomes the mean of its cells (aa_resolve), the
 * film and each pixel's deepest level and leaf count come back, and st gets the samples
 * per pixel (max) and the pixels that reached each level. Returns 0 or -1. */
static int aa_finish(AaState *aa, Renderer *r, VbAaPass *pass, unsigned slots, float *rgba,
                     RenderStats *st)
{
    VbDevice *d = r->dev;
    size_t npix = aa_pixels(r);
    pass->entries = slots;
    const cl_mem args[7] = {aa->pass, aa->slot_pixels, aa->levels, aa->values,
                            aa->film, aa->info,        aa->slots};
    if (slots && (aa_write_pass(aa, r, pass) || aa_launch(aa, r, r->k_aa_resolve, 0, args, 7, slots,
                                                          &st->aa_reconstruct_ms, NULL)))
        return -1;
    CL_CHECK(clEnqueueReadBuffer(d->queue, aa->film, CL_TRUE, 0, sizeof(float) * 4 * npix, rgba, 0,
                                 NULL, NULL),
             fail);
    CL_CHECK(clEnqueueReadBuffer(d->queue, aa->info, CL_TRUE, 0, sizeof(int) * npix,
                                 aa->levels_host, 0, NULL, NULL),
             fail);
    if (aa_settle(aa, r)) goto fail;
    st->samples_max = 1;
    for (size_t i = 0; i < npix; i++) {
        int info = aa->levels_host[i];
        aa->levels_host[i] = info & 0xff;
        aa->leaves_host[i] = info ? info >> 8 : 1;
        if ((unsigned)aa->leaves_host[i] > st->samples_max)
            st->samples_max = (unsigned)aa->leaves_host[i];
        for (int l = 1; l <= aa->levels_host[i]; l++) st->aa_refined[l]++;
    }
    return 0;
fail:
    return -1;
}

/* Uploads the frame and pass 0's image, clears the slots, info and tree counter, and makes
 * room for the first tree slots. Returns 0, 1 or 2 as aa_reserve. */
static int aa_start(AaState *aa, Renderer *r, const float *rgba, char *err, size_t errlen)
{
    VbDevice *d = r->dev;
    size_t npix = aa_pixels(r);
    cl_int none = -1, zero = 0;
    cl_uint counts[AA_COUNTS] = {0};
    aa->npix = npix;
    aa->levels_host = malloc(sizeof(int) * npix); /* frame_render freed the last frame's */
    aa->leaves_host = malloc(sizeof(int) * npix);
    if (!aa->levels_host || !aa->leaves_host) {
        snprintf(err, errlen, "out of memory");
        return 1;
    }
    int rc = aa_reserve_trees(aa, r, 64, 0, err, errlen);
    if (!rc)
        rc = aa_reserve(r, &aa->slot_pixels, &aa->slot_pixels_cap, 64, sizeof(cl_int), 0, "trees",
                        err, errlen);
    if (!rc)
        rc = aa_reserve(r, &aa->marks, &aa->mark_cap, npix, sizeof(cl_uint) * 2, 0, "mark list",
                        err, errlen);
    if (rc) return rc;
    CL_CHECK(clEnqueueWriteBuffer(d->queue, r->buf.frame, CL_TRUE, 0, sizeof r->frame_host,
                                  &r->frame_host, 0, NULL, NULL),
             fail);
    CL_CHECK(clEnqueueWriteBuffer(d->queue, aa->film, CL_TRUE, 0, sizeof(float) * 4 * npix, rgba, 0,
                                  NULL, NULL),
             fail);
    CL_CHECK(clEnqueueFillBuffer(d->queue, aa->slots, &none, sizeof none, 0, sizeof(cl_int) * npix,
                                 0, NULL, NULL),
             fail);
    CL_CHECK(clEnqueueFillBuffer(d->queue, aa->info, &zero, sizeof zero, 0, sizeof(cl_int) * npix,
                                 0, NULL, NULL),
             fail);
    if (!aa->list) { /* adaptive only: the pixels each round tests (aa_list_dirty) */
        aa->list = clu_buffer(d, NULL, sizeof(cl_uint) * npix, CL_MEM_READ_WRITE);
        aa->tags = clu_buffer(d, NULL, sizeof(cl_uint) * npix, CL_MEM_READ_WRITE);
        aa->list_count = clu_buffer(d, NULL, sizeof(cl_uint), CL_MEM_READ_WRITE);
        if (!aa->list || !aa->tags || !aa->list_count) goto fail;
    }
    CL_CHECK(clEnqueueFillBuffer(d->queue, aa->tags, &zero, sizeof zero, 0, sizeof(cl_int) * npix,
                                 0, NULL, NULL),
             fail);
    CL_CHECK(clEnqueueWriteBuffer(d->queue, aa->counts, CL_TRUE, 0, sizeof counts, counts, 0, NULL,
                                  NULL),
             fail);
    return 0;
fail:
    snprintf(err, errlen, "%s: %s", d->name, clu_error());
    return 1;
}

/* The pass's settings from s, its film r's frame window. */
static void pass_init(VbAaPass *pass, const Renderer *r, const Scene *s)
{
    memset(pass, 0, sizeof *pass);
    pass->threshold = s->aa_threshold;
    pass->floor = s->aa_floor;
    pass->level_gain = s->aa_level_gain;
    pass->reconstruct = s->aa_reconstruct;
    pass->pairs = s->aa_pairs;
    pass->contrast_scale = exp2f(s->exposure);
    pass->max_level = s->aa_max_level;
    pass->width = r->frame_host.window_width;
    pass->height = r->frame_host.window_height;
}

/* The deepest level the marked leaves of a round split into. */
static int aa_round_level(const cl_uint counts[AA_COUNTS])
{
    int deepest = 0;
    for (int l = 0; l < VBCL_AA_MAX_LEVEL; l++)
        if (counts[1 + l]) deepest = l + 1;
    return deepest;
}

int aa_refine(AaState *aa, Renderer *r, const Scene *s, float *rgba, RenderStats *st, int progress,
              char *err, size_t errlen)
{
    int rc = aa_setup(aa, r, err, errlen);
    if (!rc) rc = aa_start(aa, r, rgba, err, errlen);
    if (rc) return rc;
    unsigned long long npix = aa_pixels(r);
    unsigned long long leaves = npix;
    unsigned slots = 0;
    AaProgress pg = {progress, 0, clu_now_ms(), 0.0};
    VbAaPass pass;
    pass_init(&pass, r, s);
    st->samples = npix;
    /* below the minimum level every node splits, untested: every pixel takes a tree slot */
    int forced = s->aa_min_level;
    if (forced > 0) {
        rc = aa_split_levels(aa, r, &pass, forced, st, &pg, npix, err, errlen);
        if (rc) goto out;
        leaves = npix << (2 * forced);
        slots = (unsigned)npix;
    }
    unsigned listed = AA_ALL; /* the first tested round tests every pixel */
    for (int round = forced; round < AA_MAX_ROUNDS; round++) {
        cl_uint counts[AA_COUNTS];
        rc = aa_reserve(r, &aa->marks, &aa->mark_cap, leaves, sizeof(cl_uint) * 2, 0, "mark list",
                        err, errlen);
        if (rc) goto out;
        rc = 1;
        pass.round = round;
        if (aa_mark(aa, r, &pass, listed, counts, st)) goto fail;
        if (counts[0] == 0) break;
        st->aa_rounds++;
        /* pixels split for the first time take a tree slot each */
        size_t need = (size_t)slots + counts[1];
        rc = aa_reserve_trees(aa, r, need, slots, err, errlen);
        if (!rc)
            rc = aa_reserve(r, &aa->slot_pixels, &aa->slot_pixels_cap, need, sizeof(cl_int), slots,
                            "trees", err, errlen);
        if (rc) goto out;
        rc = 1;
        pg.t_round = clu_now_ms();
        if (aa_split(aa, r, &pass, counts[0], st, &pg, round, aa_round_level(counts), npix) ||
            aa_list_dirty(aa, r, &pass, counts[0], &listed, st))
            goto fail;
        slots += counts[1];
        leaves += 3ull * counts[0];
        if (listed == 0) break; /* (a split always lists its own pixel) */
    }
    rc = 1;
    if (aa_finish(aa, r, &pass, slots, rgba, st)) goto fail;
    rc = 0;
    goto out;
fail:
    snprintf(err, errlen, "%s: %s", r->dev->name, clu_error());
out:
    if (pg.shown)
        fprintf(stderr, "\rvbcl: anti-aliasing %d rounds, %.1f samples per pixel (%.1f s)%40s\n",
                st->aa_rounds, (double)st->samples / (double)npix,
                (clu_now_ms() - pg.t_start) / 1000.0, "");
    return rc;
}

int aa_supersample(AaState *aa, Renderer *r, const Scene *s, int n, float *rgba, RenderStats *st,
                   char *err, size_t errlen)
{
    int rc = aa_setup(aa, r, err, errlen);
    if (rc) return rc;
    VbDevice *d = r->dev;
    size_t npix = aa_pixels(r);
    unsigned per = (unsigned)r->ray_capacity / (unsigned)(n * n);
    VbAaPass pass;
    pass_init(&pass, r, s);
    pass.side = n;
    CL_CHECK(clEnqueueWriteBuffer(d->queue, r->buf.frame, CL_TRUE, 0, sizeof r->frame_host,
                                  &r->frame_host, 0, NULL, NULL),
             fail);
    for (size_t done = 0; done < npix; done += per) {
        unsigned k = npix - done < per ? (unsigned)(npix - done) : per;
        pass.first = (unsigned)done;
        pass.entries = k;
        const cl_mem args[3] = {aa->pass, r->radiance, aa->film};
        if (aa_trace_batch(aa, r, r->k_aa_generate, &pass, 0, (int)(k * (unsigned)(n * n)), st) ||
            aa_launch(aa, r, r->k_aa_reconstruct, 0, args, 3, k, &st->aa_reconstruct_ms, NULL))
            goto fail;
    }
    CL_CHECK(clEnqueueReadBuffer(d->queue, aa->film, CL_TRUE, 0, sizeof(float) * 4 * npix, rgba, 0,
                                 NULL, NULL),
             fail);
    if (aa_settle(aa, r)) goto fail;
    st->samples = (unsigned long long)npix * (unsigned long long)(n * n);
    st->samples_max = (unsigned)(n * n);
    return 0;
fail:
    snprintf(err, errlen, "%s: %s", d->name, clu_error());
    return 1;
}

void aa_release(AaState *aa)
{
    cl_mem *mems[] = {&aa->pass,   &aa->film,   &aa->slots,       &aa->info,  &aa->counts,
                      &aa->levels, &aa->values, &aa->slot_pixels, &aa->marks, &aa->split,
                      &aa->list,   &aa->tags,   &aa->list_count};
    for (int i = 0; i < aa->npending; i++) /* a failed frame's launches, never settled */
        CL_WARN(clReleaseEvent(aa->pending[i]));
    for (size_t i = 0; i < sizeof mems / sizeof mems[0]; i++)
        if (*mems[i]) CL_WARN(clReleaseMemObject(*mems[i]));
    free(aa->levels_host);
    free(aa->leaves_host);
    memset(aa, 0, sizeof *aa);
}

/* The palette at level position v in [0, VBCL_AA_MAX_LEVEL], blended in sRGB between the
 * levels either side, as linear RGB. */
static void aa_palette_at(float v, float rgb[3])
{
    /* sRGB palette, dark to hot: 0 none, 1 2x2, 2 4x4, 3 8x8, 4 16x16 */
    static const unsigned char palette[VBCL_AA_MAX_LEVEL + 1][3] = {
        {24, 24, 48}, {40, 90, 220}, {40, 190, 80}, {250, 210, 40}, {230, 40, 40}};
    v = fminf(fmaxf(v, 0.0f), (float)VBCL_AA_MAX_LEVEL);
    int lo = (int)v, hi = lo < VBCL_AA_MAX_LEVEL ? lo + 1 : lo;
    float f = v - (float)lo;
    for (int c = 0; c < 3; c++) {
        float e = (palette[lo][c] * (1.0f - f) + palette[hi][c] * f) / 255.0f;
        rgb[c] = e <= 0.04045f ? e / 12.92f : powf((e + 0.055f) / 1.055f, 2.4f);
    }
}

void aa_level_colour(int level, float rgb[3])
{
    aa_palette_at((float)level, rgb);
}

void aa_samples_colour(int n, float rgb[3])
{
    aa_palette_at(0.5f * log2f((float)(n > 1 ? n : 1)), rgb);
}
