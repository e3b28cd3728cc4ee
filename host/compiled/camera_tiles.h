/* camera_tiles.h — the triangles each square of the image can see first: camera rays all
 * start at the eye, so the triangles one ray can hit are those whose projection meets its
 * pixel. The image is cut into tiles of VBCL_CAM_TILE x VBCL_CAM_TILE pixels; each tile lists
 * the triangles whose projection (widened by a margin) meets it, nearest first, four at a
 * time (VbLeafQuad), and a camera ray tests its tile's list until the next quad lies beyond
 * its best hit (camera_trace_closest, kernels/scene.cl). docs/architecture.md, "Camera
 * tiles". */
#ifndef VBCL_CAMERA_TILES_H
#define VBCL_CAMERA_TILES_H

#include <stddef.h>
#include <stdint.h>

#include "types.h"

typedef struct CamTiles {
    int nx, ny;        /* tiles per row and per column; 0: none (camera rays walk the grid) */
    uint32_t *start;   /* tile t's quads are quads[start[t] .. start[t + 1] - 1] */
    VbLeafQuad *quads; /* each tile's triangles, nearest first, four at a time */
    float *near;       /* per quad: no point of its triangles lies nearer to the eye */
    uint32_t nquads;
    size_t refs; /* triangle references in all tiles */
} CamTiles;

/* Builds the tiles of a width x height image seen by cam for the ntris triangles tris.
 * A scene whose lists would exceed max_refs references gets none (ct->nx = 0), and so does
 * one without triangles. Returns 0, or -1 when out of memory. */
int camtiles_build(CamTiles *ct, const VbCamera *cam, int width, int height, const VbTriangle *tris,
                   uint32_t ntris, size_t max_refs);
void camtiles_free(CamTiles *ct);

#endif
