/* stats.h — what a render did, reported: the --stats text on stderr and the --stats-json
 * document (every field: docs/stats.md). */
#ifndef VBCL_STATS_H
#define VBCL_STATS_H

#include <stdio.h>

#include <cJSON.h>

#include "clu.h"
#include "render.h"
#include "scene.h"
#include "tiles.h"

/* One rendered frame and what it took. */
typedef struct StatsFrame {
    const Scene *scene;
    const VbDevice *dev;
    const Renderer *r;
    const RenderStats *st;
    int frame;              /* frame of an animation, or -1 */
    double image_wait_ms;   /* wall time the render waited for OpenImageIO to load */
    double write_ms;        /* wall time of writing the image (and --aa-map) */
    double total_ms;        /* wall time of the frame's work, from loading the scene on */
    const DeviceWork *work; /* what each device did (tiles.h), nwork of them */
    int nwork;
} StatsFrame;

/* Rays traced: primary + refinement + shadow + reflected + transmitted. */
unsigned long long stats_rays_total(const RenderStats *st);

/* Device time of the tracing kernels (camera, intersect, shading, ray trees, dispersive
 * subtrees), the denominator of Mrays/s. */
double stats_kernel_ms(const RenderStats *st);

/* Prints the --stats report of one frame to f. */
void stats_print(FILE *f, const StatsFrame *fr);

/* The --stats-json object of one frame (the same numbers as stats_print), or NULL when out
 * of memory. The caller owns it (cJSON_Delete). */
cJSON *stats_json(const StatsFrame *fr);

/* Adds frame fr's object (stats_json) to the document *doc: for a scene that is not
 * animated (fr->frame < 0) the document is that object; for an animation it is
 * {"scene": path, "frames_in_scene": N, "frames": [...]}, created on the first frame, with
 * one object per frame rendered, in order. Returns 0, or -1 when out of memory (*doc is
 * left as it was). */
int stats_json_add_frame(cJSON **doc, const StatsFrame *fr);

/* Writes doc to path, whole or not at all (file_write_whole). Returns 0, or -1 with a
 * message in err. */
int stats_json_write(const char *path, const cJSON *doc, char *err, size_t errlen);

#endif
