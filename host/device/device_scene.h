/* device_scene.h — the scene as the kernels read it: one device buffer per entry of
 * VBCL_SCENE_BUFFERS (packed triangles and normals, the grid's cells, materials with their
 * pattern and band-table offsets, objects, lights, surface patterns and texels), and the
 * frame constants (camera, grid, lights, ray-tree limits). */
#ifndef VBCL_DEVICE_SCENE_H
#define VBCL_DEVICE_SCENE_H

#include "clu.h"
#include "grid.h"
#include "scene.h"

/* The scene's buffers on one device: frame, tris, ..., texels (types.h). */
typedef struct SceneBuffers {
#define SCENE_BUFFER_MEM(space, type, name, field) cl_mem field;
    VBCL_SCENE_BUFFERS(SCENE_BUFFER_MEM)
#undef SCENE_BUFFER_MEM
} SceneBuffers;

/* How many scene arguments every frame kernel (and every scene probe) starts with. */
#define SCENE_BUFFER_COUNT(space, type, name, field) +1
#define SCENE_BUFFER_ARGS                            (0 VBCL_SCENE_BUFFERS(SCENE_BUFFER_COUNT))

/* Uploads s and its grid g into b for the kernels compiled with `features`
 * (VBCL_FEATURE_* bits), and fills *f with the frame constants (the tile fields left 0);
 * b->frame is created for f and written by whoever runs a tile. Returns 0, or 1 (device
 * failure, out of memory) / 2 (the scene cannot be rendered as given: a pattern it cannot
 * have, or too large for one allocation) with a message in err; b holds what was created
 * either way (scene_buffers_release frees it). */
int scene_buffers_upload(SceneBuffers *b, VbDevice *dev, const Scene *s, const Grid *g,
                         unsigned features, VbFrame *f, char *err, size_t errlen);

/* Sets b as arguments 0 .. SCENE_BUFFER_ARGS - 1 of kernel k. Returns 0, or -1 with the
 * error recorded (clu_error). */
int scene_buffers_set_args(const SceneBuffers *b, cl_kernel k);

/* Releases every buffer of b and zeroes it. */
void scene_buffers_release(SceneBuffers *b);

#endif
