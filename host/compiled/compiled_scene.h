/* compiled_scene.h — a scene compiled into the kernels' layout, once per frame whatever the
 * number of devices: the grid, packed triangles and normals, the leaves' and objects'
 * quads, the object records (objects.h), materials with their patterns and band tables,
 * lights, camera tiles and the frame constants. Each device only uploads it
 * (device_scene.h). */
#ifndef VBCL_COMPILED_SCENE_H
#define VBCL_COMPILED_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "camera_tiles.h"
#include "grid.h"
#include "scene.h"

typedef struct CompiledScene {
    Grid grid;
    unsigned features;     /* VBCL_FEATURE_* the scene uses (kernel_features.h) */
    VbTriangle *tris;      /* the mesh's triangles, each with its tag */
    VbTriNormals *normals; /* per triangle, with smooth normals; else NULL */
    uint32_t ntris;
    uint32_t *leaf_start; /* leaf l's quads: quads[leaf_start[l] .. leaf_start[l + 1] - 1] */
    VbLeafQuad *quads;    /* the leaves', then the object records' ranges */
    uint32_t nquads;
    VbObject *objects; /* objects_make's records */
    size_t nobjects;
    VbMaterial *materials; /* the scene's, then the medium outside every host */
    int nmaterials;        /* the scene's + 1 */
    VbPattern *patterns;
    int npatterns;
    float *texels; /* 4 floats each: projected images, the band tables, the environment */
    size_t ntexels;
    CamTiles cam;  /* camera tiles (cam.nx 0: none) */
    VbFrame frame; /* the frame constants; the tile fields are 0 */
    /* What the geometry above (grid, objects, triangles, normals, quads) was made of, so
     * that the next frame of an animation can tell whether it may keep it */
    struct GeometryKey *key;
    VbCamera key_camera; /* and the camera tiles: the camera and image they were made for */
    int key_width, key_height;
    /* this frame: whether the geometry and the camera tiles were made (1) or kept (0) */
    int geometry_built, camera_tiles_built;
} CompiledScene;

/* Compiles s into cs for devices of which none takes an allocation above max_alloc bytes
 * (the camera tiles are bounded by it). Returns 0, or 1 (out of memory) / 2 (the scene
 * cannot be rendered as given: a grid or a pattern it cannot have) with a message in err;
 * cs holds what was made either way (compiled_scene_free frees it). */
int compiled_scene_build(CompiledScene *cs, const Scene *s, size_t max_alloc, char *err,
                         size_t errlen);

/* Compiles s, the next frame of an animation, into cs, which holds the frame before: where
 * s has the same geometry (mesh, triangle tags, grid settings, objects and the transparency
 * of their textures' materials) it keeps the grid, object records, triangles and quads, and
 * where the camera and image size are the same too, the camera tiles; it makes the
 * materials, patterns, band tables and frame constants again. An empty cs (zeroed, or after
 * compiled_scene_free) is compiled whole. Returns as compiled_scene_build. */
int compiled_scene_update(CompiledScene *cs, const Scene *s, size_t max_alloc, char *err,
                          size_t errlen);

/* Frees everything of cs and zeroes it. */
void compiled_scene_free(CompiledScene *cs);

#endif
