/* dist.c — tiles and frames over MPI ranks (dist.h). Rank 0 runs a server thread that
 * answers the other ranks (tile and frame requests, pixels, reports) while its own devices
 * render; MPI is called by one thread at a time (MPI_THREAD_SERIALIZED): on rank 0 only by
 * the server while it runs, elsewhere by the device threads under the tile scheduler's
 * lock. Messages carry host structs as bytes: every rank runs the same binary. */
#include "dist.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* One rank: frames first..last in order (d->next_frame starts at 0: the first call
 * begins at first). */
static int next_in_order(Dist *d, int first, int last, int *frame)
{
    if (d->next_frame < first) d->next_frame = first;
    if (d->next_frame > last) return 0;
    *frame = d->next_frame++;
    return 1;
}

#ifdef VBCL_MPI
#include <mpi.h>

enum {
    TAG_TILE_ASK = 1, /* -> 0: int, a request for a tile */
    TAG_TILE,         /* 0 -> : long[2] first, n (n = 0: none left) */
    TAG_PIX_HEAD,     /* -> 0: long[2] first, n of the pixels that follow */
    TAG_PIX,          /* -> 0: float[4 n] */
    TAG_TILES_DONE,   /* -> 0: TilesReport */
    TAG_FRAME_ASK,    /* -> 0: int */
    TAG_FRAME,        /* 0 -> : int frame, or -1 */
    TAG_FRAME_FAIL,   /* -> 0: int, this rank failed a frame */
    TAG_FRAMES_DONE   /* -> 0: int, this rank takes no more frames */
};

/* What another rank sends rank 0 after its pass 0. */
typedef struct TilesReport {
    int rc;
    char msg[1024];
    RenderStats st;
    int nwork;
    DeviceWork work[CLU_MAX_DEVICES];
} TilesReport;

typedef struct DistServer {
    pthread_t thread;
    int running;
    pthread_mutex_t lock;
    /* tiles of a still image */
    float *rgba;
    long npix, next;
    int tile_pixels;
    int failed;
    char err[1200];
    TilesReport *reports; /* [rank] */
    /* frames of an animation */
    int frame_next, frame_last, frames_started, frames_stop;
} DistServer;

int dist_available(void)
{
    return 1;
}

/* Waits for the next message from any rank without spinning: MPI implementations poll in
 * a blocking receive and would take a core from this rank's own devices for as long as
 * the server waits (which is the whole render). */
static void wait_message(MPI_Status *stt)
{
    for (;;) {
        int flag = 0;
        MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, stt);
        if (flag) return;
        struct timespec pause = {0, 200 * 1000}; /* 0.2 ms: small against a tile */
        nanosleep(&pause, NULL);
    }
}

int dist_init(Dist *d, int *argc, char ***argv, char *err, size_t errlen)
{
    memset(d, 0, sizeof *d);
    d->size = 1;
    if (!getenv("OMPI_COMM_WORLD_SIZE") && !getenv("PMIX_RANK") && !getenv("PMI_RANK")) return 0;
    int provided = 0;
    if (MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS) {
        snprintf(err, errlen, "MPI_Init_thread failed");
        return 1;
    }
    d->mpi = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &d->rank);
    MPI_Comm_size(MPI_COMM_WORLD, &d->size);
    if (provided < MPI_THREAD_SERIALIZED && d->size > 1) {
        snprintf(err, errlen, "MPI gives thread level %d, vbcl needs MPI_THREAD_SERIALIZED",
                 provided);
        return 1;
    }
    d->server = calloc(1, sizeof *d->server);
    if (!d->server) {
        snprintf(err, errlen, "out of memory");
        return 1;
    }
    pthread_mutex_init(&d->server->lock, NULL);
    return 0;
}

int dist_agree(Dist *d, int rc)
{
    int all = rc;
    if (!d->mpi) return rc;
    /* a rank that is done first waits here while the others render: without spinning */
    MPI_Request req;
    MPI_Ibarrier(MPI_COMM_WORLD, &req);
    for (int done = 0;;) {
        MPI_Test(&req, &done, MPI_STATUS_IGNORE);
        if (done) break;
        struct timespec pause = {0, 1000 * 1000};
        nanosleep(&pause, NULL);
    }
    MPI_Allreduce(&rc, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return all;
}

int dist_finish(Dist *d, int rc)
{
    if (!d->mpi) return rc;
    rc = dist_agree(d, rc);
    if (d->server) {
        pthread_mutex_destroy(&d->server->lock);
        free(d->server->reports);
        free(d->server);
        d->server = NULL;
    }
    MPI_Finalize();
    return rc;
}

void dist_abort(Dist *d, int rc)
{
    if (d && d->mpi && d->size > 1) MPI_Abort(MPI_COMM_WORLD, rc);
}

int dist_share_scene(Dist *d, char **text, int *rc, int *first, int *last)
{
    if (!d->mpi || d->size < 2) return 0;
    int head[3] = {*rc, *first, *last};
    MPI_Bcast(head, 3, MPI_INT, 0, MPI_COMM_WORLD);
    *rc = head[0];
    *first = head[1];
    *last = head[2];
    if (*rc) return 0;
    long len = d->rank == 0 ? (long)strlen(*text) : 0;
    MPI_Bcast(&len, 1, MPI_LONG, 0, MPI_COMM_WORLD);
    if (d->rank != 0) {
        *text = malloc((size_t)len + 1);
        if (!*text) return 1; /* MPI_Abort follows in main: the others wait in the Bcast */
        (*text)[len] = 0;
    }
    MPI_Bcast(*text, (int)len, MPI_CHAR, 0, MPI_COMM_WORLD);
    return 0;
}

/* ---- tiles of a still image ---- */

/* The next tile of the shared queue (rank 0, under sv->lock): 1, or 0 when none is left. */
static int take_tile(DistServer *sv, long *first, long *n)
{
    if (sv->failed || sv->next >= sv->npix) return 0;
    *first = sv->next;
    *n = sv->npix - sv->next < sv->tile_pixels ? sv->npix - sv->next : sv->tile_pixels;
    sv->next += *n;
    return 1;
}

static void server_fail(DistServer *sv, const char *fmt, int rank, const char *msg)
{
    pthread_mutex_lock(&sv->lock);
    if (!sv->failed) snprintf(sv->err, sizeof sv->err, fmt, rank, msg);
    sv->failed = 1;
    pthread_mutex_unlock(&sv->lock);
}

/* Rank 0's server: answers tile requests, stores pixels, until every rank has reported. */
static void *serve_tiles(void *arg)
{
    Dist *d = arg;
    DistServer *sv = d->server;
    for (int left = d->size - 1; left > 0;) {
        MPI_Status stt;
        wait_message(&stt);
        int src = stt.MPI_SOURCE, ask;
        long t[2] = {0, 0};
        if (stt.MPI_TAG == TAG_TILE_ASK) {
            MPI_Recv(&ask, 1, MPI_INT, src, TAG_TILE_ASK, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            pthread_mutex_lock(&sv->lock);
            if (!take_tile(sv, &t[0], &t[1])) t[1] = 0;
            pthread_mutex_unlock(&sv->lock);
            MPI_Send(t, 2, MPI_LONG, src, TAG_TILE, MPI_COMM_WORLD);
        } else if (stt.MPI_TAG == TAG_PIX_HEAD) {
            MPI_Recv(t, 2, MPI_LONG, src, TAG_PIX_HEAD, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            if (t[0] < 0 || t[1] < 1 || t[0] + t[1] > sv->npix) { /* cannot happen: same binary */
                MPI_Abort(MPI_COMM_WORLD, 1);
            }
            MPI_Recv(sv->rgba + 4 * t[0], (int)(4 * t[1]), MPI_FLOAT, src, TAG_PIX, MPI_COMM_WORLD,
                     MPI_STATUS_IGNORE);
        } else if (stt.MPI_TAG == TAG_TILES_DONE) {
            TilesReport *rep = &sv->reports[src];
            MPI_Recv(rep, (int)sizeof *rep, MPI_BYTE, src, TAG_TILES_DONE, MPI_COMM_WORLD,
                     MPI_STATUS_IGNORE);
            if (rep->rc) server_fail(sv, "rank %d: %s", src, rep->msg);
            left--;
        } else {
            MPI_Recv(&ask, 1, MPI_INT, src, stt.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            server_fail(sv, "rank %d: unexpected message (%s)", src, "a frame request");
        }
    }
    return NULL;
}

static int local_next(void *ctx, long *first, int *n, char *err, size_t errlen)
{
    DistServer *sv = ((Dist *)ctx)->server;
    long got_n = 0;
    (void)err;
    (void)errlen;
    pthread_mutex_lock(&sv->lock);
    int got = take_tile(sv, first, &got_n);
    pthread_mutex_unlock(&sv->lock);
    *n = (int)got_n;
    return got;
}

/* Rank 0, after its own devices are done: no more tiles if it failed, then waits for the
 * other ranks; fails with the first rank's error. */
static int local_finish(void *ctx, int failed, char *err, size_t errlen)
{
    Dist *d = ctx;
    DistServer *sv = d->server;
    pthread_mutex_lock(&sv->lock);
    if (failed) sv->failed = 1;
    pthread_mutex_unlock(&sv->lock);
    if (sv->running) pthread_join(sv->thread, NULL);
    sv->running = 0;
    if (!failed && sv->err[0]) {
        snprintf(err, errlen, "%s", sv->err);
        return -1;
    }
    return failed ? -1 : 0;
}

static int remote_next(void *ctx, long *first, int *n, char *err, size_t errlen)
{
    (void)ctx;
    int ask = 0;
    long t[2];
    if (MPI_Send(&ask, 1, MPI_INT, 0, TAG_TILE_ASK, MPI_COMM_WORLD) != MPI_SUCCESS ||
        MPI_Recv(t, 2, MPI_LONG, 0, TAG_TILE, MPI_COMM_WORLD, MPI_STATUS_IGNORE) != MPI_SUCCESS) {
        snprintf(err, errlen, "no answer from rank 0");
        return -1;
    }
    *first = t[0];
    *n = (int)t[1];
    return t[1] > 0;
}

static int remote_deliver(void *ctx, long first, int n, const float *rgba, char *err, size_t errlen)
{
    (void)ctx;
    long t[2] = {first, n};
    if (MPI_Send(t, 2, MPI_LONG, 0, TAG_PIX_HEAD, MPI_COMM_WORLD) != MPI_SUCCESS ||
        MPI_Send(rgba, 4 * n, MPI_FLOAT, 0, TAG_PIX, MPI_COMM_WORLD) != MPI_SUCCESS) {
        snprintf(err, errlen, "cannot send pixels to rank 0");
        return -1;
    }
    return 0;
}

int dist_tiles_begin(Dist *d, float *rgba, long npix, int tile_pixels, TileSource *src, char *err,
                     size_t errlen)
{
    memset(src, 0, sizeof *src);
    src->ctx = d;
    if (d->rank != 0) {
        src->next = remote_next;
        src->deliver = remote_deliver;
        return 0;
    }
    DistServer *sv = d->server;
    free(sv->reports);
    sv->reports = calloc((size_t)d->size, sizeof *sv->reports);
    if (!sv->reports) {
        snprintf(err, errlen, "out of memory");
        return 1;
    }
    sv->rgba = rgba;
    sv->npix = npix;
    sv->next = 0;
    sv->tile_pixels = tile_pixels;
    sv->failed = 0;
    sv->err[0] = 0;
    src->next = local_next;
    src->finish = local_finish;
    if (pthread_create(&sv->thread, NULL, serve_tiles, d)) {
        snprintf(err, errlen, "cannot start the thread that serves the other ranks");
        return 1;
    }
    sv->running = 1;
    return 0;
}

int dist_tiles_report(Dist *d, int rc, const char *msg, const RenderStats *st,
                      const DeviceWork *work, int nwork)
{
    TilesReport *rep = calloc(1, sizeof *rep);
    if (!rep) return 1;
    rep->rc = rc;
    snprintf(rep->msg, sizeof rep->msg, "%s", msg ? msg : "");
    rep->st = *st;
    rep->nwork = nwork < CLU_MAX_DEVICES ? nwork : CLU_MAX_DEVICES;
    for (int i = 0; i < rep->nwork; i++) {
        rep->work[i] = work[i];
        rep->work[i].rank = d->rank;
    }
    int bad = MPI_Send(rep, (int)sizeof *rep, MPI_BYTE, 0, TAG_TILES_DONE, MPI_COMM_WORLD);
    free(rep);
    return bad != MPI_SUCCESS;
}

int dist_tiles_gather(Dist *d, RenderStats *st, DeviceWork *work, int nwork, int max)
{
    if (!d->mpi || d->rank != 0 || !d->server->reports) return nwork;
    for (int r = 1; r < d->size; r++) {
        const TilesReport *rep = &d->server->reports[r];
        tiles_stats_add(st, &rep->st);
        for (int i = 0; i < rep->nwork && nwork < max; i++) work[nwork++] = rep->work[i];
    }
    return nwork;
}

void dist_tiles_end(Dist *d)
{
    if (!d->mpi || d->rank != 0 || !d->server->running) return;
    local_finish(d, 1, NULL, 0);
}

/* ---- frames of an animation ---- */

static void *serve_frames(void *arg)
{
    Dist *d = arg;
    DistServer *sv = d->server;
    for (int left = d->size - 1; left > 0;) {
        MPI_Status stt;
        int msg, f = -1;
        wait_message(&stt);
        MPI_Recv(&msg, 1, MPI_INT, stt.MPI_SOURCE, stt.MPI_TAG, MPI_COMM_WORLD, &stt);
        pthread_mutex_lock(&sv->lock);
        if (stt.MPI_TAG == TAG_FRAME_ASK && !sv->frames_stop && sv->frame_next <= sv->frame_last)
            f = sv->frame_next++;
        if (stt.MPI_TAG == TAG_FRAME_FAIL) sv->frames_stop = 1;
        pthread_mutex_unlock(&sv->lock);
        if (stt.MPI_TAG == TAG_FRAME_ASK)
            MPI_Send(&f, 1, MPI_INT, stt.MPI_SOURCE, TAG_FRAME, MPI_COMM_WORLD);
        if (stt.MPI_TAG == TAG_FRAMES_DONE) left--;
    }
    return NULL;
}

int dist_frames_next(Dist *d, int first, int last, int *frame)
{
    if (!d->mpi || d->size < 2) return next_in_order(d, first, last, frame);
    DistServer *sv = d->server;
    if (d->rank != 0) {
        int ask = 0, f = -1;
        MPI_Send(&ask, 1, MPI_INT, 0, TAG_FRAME_ASK, MPI_COMM_WORLD);
        MPI_Recv(&f, 1, MPI_INT, 0, TAG_FRAME, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        *frame = f;
        return f >= 0;
    }
    if (!sv->frames_started) {
        sv->frames_started = 1;
        sv->frame_next = first;
        sv->frame_last = last;
        if (pthread_create(&sv->thread, NULL, serve_frames, d) == 0)
            sv->running = 1;
        else
            sv->frames_stop = 1; /* the others get nothing; dist_frames_end still waits */
    }
    pthread_mutex_lock(&sv->lock);
    int got = !sv->frames_stop && sv->frame_next <= sv->frame_last;
    if (got) *frame = sv->frame_next++;
    pthread_mutex_unlock(&sv->lock);
    return got;
}

void dist_frames_fail(Dist *d)
{
    if (!d->mpi || d->size < 2) return;
    if (d->rank != 0) {
        int one = 1;
        MPI_Send(&one, 1, MPI_INT, 0, TAG_FRAME_FAIL, MPI_COMM_WORLD);
        return;
    }
    pthread_mutex_lock(&d->server->lock);
    d->server->frames_stop = 1;
    pthread_mutex_unlock(&d->server->lock);
}

void dist_frames_end(Dist *d)
{
    if (!d->mpi || d->size < 2) return;
    if (d->rank != 0) {
        int one = 1;
        MPI_Send(&one, 1, MPI_INT, 0, TAG_FRAMES_DONE, MPI_COMM_WORLD);
        return;
    }
    DistServer *sv = d->server;
    if (!sv->frames_started) { /* rank 0 had nothing to do: still serve the others */
        int f;
        dist_frames_next(d, 1, 0, &f);
    }
    if (sv->running) pthread_join(sv->thread, NULL);
    sv->running = 0;
}

#else /* a build without MPI: one rank */

int dist_available(void)
{
    return 0;
}

int dist_init(Dist *d, int *argc, char ***argv, char *err, size_t errlen)
{
    (void)argc;
    (void)argv;
    memset(d, 0, sizeof *d);
    d->size = 1;
    /* under mpirun, every process would render the whole image and write the same file */
    const char *ranks = getenv("OMPI_COMM_WORLD_SIZE");
    if (ranks && atoi(ranks) > 1) {
        snprintf(err, errlen,
                 "started by mpirun with %s ranks, but this vbcl was built without MPI "
                 "(install libopenmpi-dev: make deps; then make clean; make)",
                 ranks);
        return 1;
    }
    return 0;
}

int dist_finish(Dist *d, int rc)
{
    (void)d;
    return rc;
}

int dist_agree(Dist *d, int rc)
{
    (void)d;
    return rc;
}

int dist_share_scene(Dist *d, char **text, int *rc, int *first, int *last)
{
    (void)d;
    (void)text;
    (void)rc;
    (void)first;
    (void)last;
    return 0;
}

void dist_abort(Dist *d, int rc)
{
    (void)d;
    (void)rc;
}

int dist_tiles_begin(Dist *d, float *rgba, long npix, int tile_pixels, TileSource *src, char *err,
                     size_t errlen)
{
    (void)d;
    (void)rgba;
    (void)npix;
    (void)tile_pixels;
    (void)err;
    (void)errlen;
    memset(src, 0, sizeof *src);
    return 0;
}

int dist_tiles_report(Dist *d, int rc, const char *msg, const RenderStats *st,
                      const DeviceWork *work, int nwork)
{
    (void)d;
    (void)msg;
    (void)st;
    (void)work;
    (void)nwork;
    return rc;
}

int dist_tiles_gather(Dist *d, RenderStats *st, DeviceWork *work, int nwork, int max)
{
    (void)d;
    (void)st;
    (void)work;
    (void)max;
    return nwork;
}

void dist_tiles_end(Dist *d)
{
    (void)d;
}

int dist_frames_next(Dist *d, int first, int last, int *frame)
{
    return next_in_order(d, first, last, frame);
}

void dist_frames_fail(Dist *d)
{
    (void)d;
}

void dist_frames_end(Dist *d)
{
    (void)d;
}

#endif
