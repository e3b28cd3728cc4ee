/* device_scene.h — a compiled scene on one device: one buffer per entry of
 * VBCL_SCENE_BUFFERS (packed triangles and normals, the grid's cells, materials with their
 * pattern and band-table offsets, objects, lights, surface patterns and texels), and the
 * frame constants' buffer. */
#ifndef VBCL_DEVICE_SCENE_H
#define VBCL_DEVICE_SCENE_H

#include "clu.h"
#include "compiled_scene.h"

/* The scene's buffers on one device: frame, tris, ..., texels (types.h). */
typedef struct SceneBuffers {
#define SCENE_BUFFER_MEM(space, type, name, field) cl_mem field;
    VBCL_SCENE_BUFFERS(SCENE_BUFFER_MEM)
#undef SCENE_BUFFER_MEM
} SceneBuffers;

/* How many scene arguments every frame kernel (and every scene probe) starts with. */
#define SCENE_BUFFER_COUNT(space, type, name, field) +1
#define SCENE_BUFFER_ARGS                            (0 VBCL_SCENE_BUFFERS(SCENE_BUFFER_COUNT))

/* Uploads the compiled scene cs (of scene s, whose lights it takes) into b; b->frame is
 * created for cs->frame and written by whoever runs a tile. Returns 0, or 1 (device
 * failure) / 2 (a buffer larger than one allocation on dev) with a message in err; b holds
 * what was created either way (scene_buffers_release frees it). */
int scene_buffers_upload(SceneBuffers *b, VbDevice *dev, const CompiledScene *cs, const Scene *s,
                         char *err, size_t errlen);

/* Sets b as arguments 0 .. SCENE_BUFFER_ARGS - 1 of kernel k. Returns 0, or -1 with the
 * error recorded (clu_error). */
int scene_buffers_set_args(const SceneBuffers *b, cl_kernel k);

/* Releases every buffer of b and zeroes it. */
void scene_buffers_release(SceneBuffers *b);

#endif
