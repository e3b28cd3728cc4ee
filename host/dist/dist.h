/* dist.h — several processes, over MPI (docs/scaling.md): `mpirun -np N ./vbcl scene.json`.
 * Rank 0 reads and checks the scene and shares it; a still image's pass-0 tiles are handed
 * out by rank 0 to whichever rank asks (each rank on all its devices: tiles.h) and its
 * pixels gathered there, where refinement runs and the image is written; an animation's
 * frames are handed out one at a time (a dynamic frame queue) and each rank renders and
 * writes whole frames. Without MPI (a build without it, or not started by mpirun) there is
 * one rank and every function here is trivial. */
#ifndef VBCL_DIST_H
#define VBCL_DIST_H

#include "tiles.h"

/* This process among the others. */
typedef struct Dist {
    int rank, size; /* 0 and 1 without MPI */
    int mpi;        /* MPI was initialised (started by mpirun or srun, in an MPI build) */
    struct DistServer *server; /* rank 0: the thread that serves the other ranks */
    int next_frame;            /* one rank: the next frame of dist_frames_next */
} Dist;

/* Whether this build can use MPI. */
int dist_available(void);

/* Starts MPI when the process was started by mpirun or srun (OMPI_COMM_WORLD_SIZE,
 * PMIX_RANK or PMI_RANK in the environment) in an MPI build. A build without MPI started
 * by mpirun with several ranks fails (each would render and write the whole image).
 * Returns 0, or 1 after a message in err. */
int dist_init(Dist *d, int *argc, char ***argv, char *err, size_t errlen);

/* The exit status every rank agrees on (the largest of all ranks' rc), after which MPI is
 * finalised. Collective: every rank calls it once. */
int dist_finish(Dist *d, int rc);

/* The largest rc over all ranks (collective). */
int dist_agree(Dist *d, int rc);

/* Shares rank 0's scene text, its *rc (0 to go on, else the exit status every rank
 * takes) and the frames to render with the other ranks, which receive the text in *text
 * (malloc'd). Collective. Returns 0, or 1 when out of memory. */
int dist_share_scene(Dist *d, char **text, int *rc, int *first, int *last);

/* Ends every rank at once with status rc (MPI_Abort) when other ranks wait on this one;
 * returns with one rank. */
void dist_abort(Dist *d, int rc);

/* A still image over ranks. Rank 0: serves tiles of npix pixels (tile_pixels each) from
 * one queue to its own devices and to the other ranks, whose pixels land in rgba; *src
 * is the queue its own frame_render takes tiles from (its finish waits for the other
 * ranks and fails with the first rank's error). Other ranks: *src asks rank 0 for each
 * tile and sends the pixels back. Returns 0, or 1 after a message in err. */
int dist_tiles_begin(Dist *d, float *rgba, long npix, int tile_pixels, TileSource *src, char *err,
                     size_t errlen);

/* Another rank, after its pass 0 (rc 0, or 1 with err naming its device): sends rank 0
 * its status, counts and per-device work. Returns 0, or 1 after a message in err. */
int dist_tiles_report(Dist *d, int rc, const char *msg, const RenderStats *st,
                      const DeviceWork *work, int nwork);

/* Rank 0, after its frame: adds the other ranks' counts to st and appends their devices'
 * work after its own nwork rows in work (room for max rows). Returns the rows in all. */
int dist_tiles_gather(Dist *d, RenderStats *st, DeviceWork *work, int nwork, int max);

/* Rank 0: stops serving tiles (after dist_tiles_begin, once the frame is done or failed). */
void dist_tiles_end(Dist *d);

/* An animation's frames first..last over ranks: the next frame for this rank to render,
 * 1 with *frame set, or 0 when none is left (or a rank has failed: dist_frames_fail). Rank
 * 0 serves the other ranks from a thread started on the first call. */
int dist_frames_next(Dist *d, int first, int last, int *frame);

/* This rank failed a frame: the others get no new frames. */
void dist_frames_fail(Dist *d);

/* After the last frame: rank 0 waits until every rank is done. Collective. */
void dist_frames_end(Dist *d);

#endif
