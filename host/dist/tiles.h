/* tiles.h — pass 0 on several devices at once: one host thread per device takes the next
 * tile from a shared source (the process's own queue, or rank 0 over MPI: mpi_dist.h)
 * whenever it is free, so a fast device and a slow one both stay busy. A tile's pixels
 * depend only on the pixels (jitter is keyed by pixel and sample), so the image is the
 * same whichever device traces which tile. */
#ifndef VBCL_TILES_H
#define VBCL_TILES_H

#include "render.h"

/* Where tiles come from, and where finished ones go. next and deliver are called under
 * the scheduler's lock, one call at a time. */
typedef struct TileSource {
    /* The next tile: 1 with its first pixel and size, 0 when none is left, or -1 after a
     * message in err. NULL: the local queue (tiles of r->tile_pixels in order). */
    int (*next)(void *ctx, long *first, int *n, char *err, size_t errlen);
    /* Hands on a finished tile (rgba holds its n pixels); NULL when the tile stays here.
     * Returns 0, or -1 after a message in err. */
    int (*deliver)(void *ctx, long first, int n, const float *rgba, char *err, size_t errlen);
    /* Called once after this process's devices are done (failed: whether one of them
     * failed): waits for work elsewhere. Returns 0, or -1 (with a message in err when
     * failed is 0). NULL: nothing to wait for. */
    int (*finish)(void *ctx, int failed, char *err, size_t errlen);
    void *ctx;
} TileSource;

/* What one device did for a frame (--stats "devices"). */
typedef struct DeviceWork {
    char name[256];           /* "platform / device" */
    int index;                /* its index in --list-devices */
    int rank;                 /* the MPI rank that drove it (0 without MPI) */
    char host[64];            /* the machine it is on (gethostname): ranks on one machine
                               * that name the same device index share that device */
    unsigned long long tiles; /* pass-0 tiles traced */
    unsigned long long rays;  /* every ray it traced, refinement included */
    double busy_ms;           /* wall time spent tracing (pass 0 and refinement) */
    double kernel_ms;         /* device time of its tracing kernels (event profiling) */
} DeviceWork;

/* Rays in st: primary + refinement + shadow + reflected + transmitted. */
unsigned long long tiles_rays(const RenderStats *st);

/* Device time of the tracing kernels in st (camera, intersect, shading, ray trees,
 * dispersive subtrees). */
double tiles_kernel_ms(const RenderStats *st);

/* Adds the counts and kernel times of one device's (or rank's) pass 0 to st. */
void tiles_stats_add(RenderStats *st, const RenderStats *from);

/* Tiles shared among devices are no smaller than this (each launch has a fixed cost). */
#define TILES_MIN_PIXELS 1024

/* The tile size for `workers` devices (or ranks) sharing npix pixels: tile_pixels, the
 * renderer's bound, for one; else small enough for 8 tiles per worker, so that a fast
 * device takes more of them, but at least TILES_MIN_PIXELS. Pixels are traced alike
 * whatever the tiling (their jitter is keyed by pixel), so this changes no pixel. */
int tiles_size(int tile_pixels, long npix, int workers);

/* Traces every tile of pass 0 (a ray through each pixel centre; npix pixels in all) on the
 * nr renderers *rs[i] (the same scene, one per device; nr >= 1) into rgba, tiles taken from
 * src (NULL: the local queue). Adds the counts and kernel times of all devices to st and
 * each device's share to work[i]. With progress set, reports on stderr once it has taken
 * a second. Returns 0, or 1 after a message in err naming the device that failed (then
 * the other devices stop at their next tile). */
int tiles_trace(Renderer *const *rs, int nr, const TileSource *src, long npix, float *rgba,
                RenderStats *st, DeviceWork *work, int progress, char *err, size_t errlen);

#endif
