/* scene.h — a scene as the renderer needs it, loaded from JSON (docs/scene-format.md):
 * image, camera and render settings, lights, materials, and every object tessellated
 * and transformed into one world-space mesh with a material per triangle. */
#ifndef VBCL_SCENE_H
#define VBCL_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "types.h"

#define SCENE_MAX_IMAGE     16384
#define SCENE_MAX_TRIANGLES 50000000u
#define SCENE_NAME_MAX      64

typedef struct SceneMaterial {
    char name[SCENE_NAME_MAX];
    VbMaterial gpu;
} SceneMaterial;

typedef struct SceneObject {
    char name[SCENE_NAME_MAX]; /* the JSON path ("objects[2]") when not named */
    int material;
    uint32_t first_tri, ntris;
} SceneObject;

typedef struct Scene {
    char *path; /* the scene file as given */
    char *dir;  /* its directory, for relative mesh paths */
    /* image */
    int width, height;
    char *output;   /* image.output, or NULL */
    float exposure; /* stops */
    float background[3];
    /* camera */
    vec3 eye, look_at, up;
    float fov; /* vertical, degrees */
    /* render */
    int max_depth;
    int grid_res[3]; /* all 0: auto */
    float grid_density;
    int shadow_samples; /* as given; the kernels use the nearest square */
    float ambient[3];
    unsigned seed;
    /* contents */
    int nlights;
    VbLight *lights;
    int nmaterials;
    SceneMaterial *materials;
    int nobjects;
    SceneObject *objects;
    Mesh mesh;              /* all objects, world space */
    uint32_t *tri_material; /* material index per triangle of mesh */
} Scene;

/* Reads and checks a scene file. Returns 0, or 2 (bad input) with a one-line message in
 * err: "FILE:LINE:COL: ..." for JSON syntax, "FILE: json.path: what was expected" for
 * meaning, and the mesh file's own message for a bad mesh. On error *s is freed. */
int scene_load(const char *path, Scene *s, char *err, size_t errlen);

/* Frees everything scene_load allocated. */
void scene_free(Scene *s);

/* Parses a grid resolution as written on the command line: "auto", "N" or "NX,NY,NZ".
 * Returns 0 and sets res (all 0 for auto), or -1. */
int scene_parse_grid(const char *text, int res[3]);

#endif
