/* tiles.c — pass 0 on several devices: one host thread per device, each taking the next
 * tile from the shared source under one lock, tracing it on its own renderer (its own
 * context, queue, program and buffers) and writing its pixels into the image. */
#include "tiles.h"

#include <pthread.h>
#include <time.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The state the device threads share, guarded by lock. */
typedef struct Schedule {
    pthread_mutex_t lock;
    pthread_cond_t progress; /* signalled after each tile */
    const TileSource *src;
    long next, npix, done_pix;
    int tile_pixels;
    long taken, fail_at; /* tiles taken; VBCL_FAIL_TILE: the one that fails on purpose */
    int running;         /* device threads not yet finished */
    int failed;          /* set by the first failure: the others stop at their next tile */
    char err[1024];
    float *rgba;
} Schedule;

/* One device's thread. */
typedef struct Worker {
    Schedule *sc;
    Renderer *r;
    RenderStats st; /* this device's counts, added to the frame's at the end */
    DeviceWork *work;
    pthread_t thread;
} Worker;

unsigned long long tiles_rays(const RenderStats *st)
{
    return st->rays_primary + st->rays_refine + st->rays_shadow + st->reflected + st->transmitted;
}

double tiles_kernel_ms(const RenderStats *st)
{
    return st->camera_ms + st->intersect_ms + st->shading_ms + st->tree_ms + st->dispersion_ms;
}

void tiles_stats_add(RenderStats *to, const RenderStats *from)
{
    to->rays_primary += from->rays_primary;
#define TILES_ADD_COUNTER(name, index, field, group, key) to->field += from->field;
    VBCL_COUNTER_LIST(TILES_ADD_COUNTER)
#undef TILES_ADD_COUNTER
    for (int k = 0; k < VBCL_COUNT_DEPTH_BINS; k++) to->by_depth[k] += from->by_depth[k];
    to->camera_ms += from->camera_ms;
    to->intersect_ms += from->intersect_ms;
    to->shading_ms += from->shading_ms;
    to->tree_ms += from->tree_ms;
    to->dispersion_ms += from->dispersion_ms;
    to->readback_ms += from->readback_ms;
    to->tiles += from->tiles;
}

/* The next tile, under sc->lock. Returns 1, 0 (none left) or -1 (sc->err set). */
static int schedule_next(Schedule *sc, long *first, int *n)
{
    if (sc->failed) return 0;
    if (sc->src && sc->src->next) {
        int rc = sc->src->next(sc->src->ctx, first, n, sc->err, sizeof sc->err);
        if (rc < 0) sc->failed = 1;
        return rc;
    }
    if (sc->next >= sc->npix) return 0;
    *first = sc->next;
    *n = (int)(sc->npix - sc->next < sc->tile_pixels ? sc->npix - sc->next : sc->tile_pixels);
    sc->next += *n;
    return 1;
}

/* Records the first failure (under sc->lock). */
static void schedule_fail(Schedule *sc, const char *fmt, const char *a, const char *b)
{
    if (!sc->failed) snprintf(sc->err, sizeof sc->err, fmt, a, b);
    sc->failed = 1;
}

static void *worker_run(void *arg)
{
    Worker *w = arg;
    Schedule *sc = w->sc;
    char name[300];
    snprintf(name, sizeof name, "device %d (%s)", w->r->dev->index, w->r->dev->name);
    clu_error_clear();
    for (;;) {
        long first;
        int n;
        pthread_mutex_lock(&sc->lock);
        int got = schedule_next(sc, &first, &n);
        int inject = got > 0 && ++sc->taken == sc->fail_at;
        if (inject) schedule_fail(sc, "%s: %s", name, "failed on purpose (VBCL_FAIL_TILE)");
        pthread_mutex_unlock(&sc->lock);
        if (got <= 0 || inject) break;
        if (n > w->r->tile_pixels) { /* a tile from rank 0 must fit this rank's buffers */
            pthread_mutex_lock(&sc->lock);
            schedule_fail(sc, "%s: %s", name, "a tile from rank 0 is larger than its buffers");
            pthread_mutex_unlock(&sc->lock);
            break;
        }
        double t0 = clu_now_ms();
        int rc = renderer_trace_tile(w->r, first, n, sc->rgba, &w->st);
        w->work->busy_ms += clu_now_ms() - t0;
        pthread_mutex_lock(&sc->lock);
        if (rc) {
            schedule_fail(sc, "%s: %s", name, clu_error());
        } else if (sc->src && sc->src->deliver &&
                   sc->src->deliver(sc->src->ctx, first, n, sc->rgba + 4 * first, sc->err,
                                    sizeof sc->err)) {
            sc->failed = 1;
        } else {
            w->work->tiles++;
            sc->done_pix += n;
        }
        pthread_cond_signal(&sc->progress);
        pthread_mutex_unlock(&sc->lock);
        if (rc) break;
    }
    pthread_mutex_lock(&sc->lock);
    sc->running--;
    pthread_cond_signal(&sc->progress);
    pthread_mutex_unlock(&sc->lock);
    return NULL;
}

/* Waits for the workers, reporting progress on stderr once a second has passed. Called
 * with sc->lock held; returns with it held. */
static void schedule_wait(Schedule *sc, int progress)
{
    double t_start = clu_now_ms();
    int shown = 0;
    while (sc->running > 0) {
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        until.tv_nsec += 200 * 1000 * 1000;
        if (until.tv_nsec >= 1000000000L) {
            until.tv_sec++;
            until.tv_nsec -= 1000000000L;
        }
        pthread_cond_timedwait(&sc->progress, &sc->lock, &until);
        double el = clu_now_ms() - t_start;
        if (!progress || sc->src || (el < 1000.0 && !shown)) continue;
        double left = sc->done_pix > 0 ? el * (double)(sc->npix - sc->done_pix) / sc->done_pix : 0;
        fprintf(stderr, "\rvbcl: rendering %3.0f%%  (%.1f s elapsed, about %.1f s left) ",
                100.0 * (double)sc->done_pix / (double)sc->npix, el / 1000.0, left / 1000.0);
        shown = 1;
    }
    if (shown)
        fprintf(stderr, sc->failed ? "\n" : "\rvbcl: rendering 100%% (%.1f s)%30s\n",
                (clu_now_ms() - t_start) / 1000.0, "");
}

int tiles_size(int tile_pixels, long npix, int workers)
{
    if (workers < 2) return tile_pixels;
    long want = (npix + 8L * workers - 1) / (8L * workers);
    if (want < TILES_MIN_PIXELS) want = TILES_MIN_PIXELS;
    return want < tile_pixels ? (int)want : tile_pixels;
}

int tiles_trace(Renderer *const *rs, int nr, const TileSource *src, long npix, float *rgba,
                RenderStats *st, DeviceWork *work, int progress, char *err, size_t errlen)
{
    Schedule sc;
    memset(&sc, 0, sizeof sc);
    pthread_mutex_init(&sc.lock, NULL);
    pthread_cond_init(&sc.progress, NULL);
    sc.src = src;
    sc.npix = npix;
    sc.tile_pixels = tiles_size(rs[0]->tile_pixels, npix, nr);
    sc.rgba = rgba;
    /* a test of the failure path (docs/scaling.md): the process's Nth tile fails as a device
     * error would */
    const char *fail_at = getenv("VBCL_FAIL_TILE");
    sc.fail_at = fail_at ? atol(fail_at) : 0;
    Worker *ws = calloc((size_t)nr, sizeof *ws);
    if (!ws) {
        snprintf(err, errlen, "out of memory");
        return 1;
    }
    int started = 0;
    for (int i = 0; i < nr; i++) {
        ws[i].sc = &sc;
        ws[i].r = rs[i];
        ws[i].work = &work[i];
        pthread_mutex_lock(&sc.lock);
        sc.running++;
        pthread_mutex_unlock(&sc.lock);
        if (pthread_create(&ws[i].thread, NULL, worker_run, &ws[i])) {
            pthread_mutex_lock(&sc.lock);
            sc.running--;
            schedule_fail(&sc, "%s%s", "cannot start a host thread for device ", rs[i]->dev->name);
            pthread_mutex_unlock(&sc.lock);
            break;
        }
        started++;
    }
    pthread_mutex_lock(&sc.lock);
    schedule_wait(&sc, progress);
    pthread_mutex_unlock(&sc.lock);
    for (int i = 0; i < started; i++) pthread_join(ws[i].thread, NULL);
    for (int i = 0; i < started; i++) {
        tiles_stats_add(st, &ws[i].st);
        work[i].rays += tiles_rays(&ws[i].st);
        work[i].kernel_ms += tiles_kernel_ms(&ws[i].st);
    }
    free(ws);
    if (src && src->finish && src->finish(src->ctx, sc.failed, sc.err, sizeof sc.err))
        sc.failed = 1;
    if (!src || !src->next) st->tile_pixels = sc.tile_pixels; /* else the source's size */
    int failed = sc.failed;
    if (failed) snprintf(err, errlen, "%s", sc.err);
    pthread_cond_destroy(&sc.progress);
    pthread_mutex_destroy(&sc.lock);
    return failed ? 1 : 0;
}
