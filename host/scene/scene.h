/* scene.h — a scene as the renderer needs it, loaded from JSON (docs/scene-format.md):
 * image, camera and render settings, lights, materials, and every object tessellated
 * and transformed into one world-space mesh with a material per triangle. */
#ifndef VBCL_SCENE_H
#define VBCL_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "dispersion.h"
#include "mesh.h"
#include "types.h"

#define SCENE_MAX_IMAGE      16384
#define SCENE_MAX_TRIANGLES  50000000u
#define SCENE_NAME_MAX       64
#define SCENE_MAX_FILE_BYTES ((size_t)1 << 30) /* scene and mesh files: at most 1 GiB */

/* A material's surface pattern as the scene gives it; the renderer turns it into a
 * VbPattern (Fourier coefficients, image texels). */
typedef struct ScenePattern {
    int kind;            /* 0 none, VBCL_PATTERN_FOURIER, _PROJECTION or _CHECKER */
    float colours[2][3]; /* checker: the two colours */
    unsigned axes;       /* checker: bit k, cells alternate along axis k; projection: its axis */
    int terms;
    float contrast, freq[3];
    unsigned long long seed;
    char *image; /* projection: path, already joined with the scene's directory */
    float origin[3], size[3];
} ScenePattern;

/* image.environment: a latitude-longitude image seen by rays that leave the scene
 * (docs/scene-format.md; the kernels' VbEnvironment). file NULL: none. */
typedef struct SceneEnvironment {
    char *file;         /* the image, joined with the scene's directory */
    int width, height;  /* texels */
    float *texels;      /* linear rgba (a = 1), row 0 the top (the zenith); finite, >= 0 */
    float scale;        /* the radiance multiplier, >= 0 */
    float to_env[3][3]; /* rows of the world-to-environment rotation */
} SceneEnvironment;

typedef struct SceneMaterial {
    char name[SCENE_NAME_MAX];
    VbMaterial gpu;
    ScenePattern pattern;
    DispModel disp; /* materials.NAME.dispersion; model DISP_NONE: constant eta */
} SceneMaterial;

typedef struct SceneObject {
    char name[SCENE_NAME_MAX]; /* the JSON path ("objects[2]") when not named */
    int named;                 /* the scene gave "name" (unique among the objects) */
    int material;
    int is_host;      /* a closed volume tracked by the medium state (dielectric or textured) */
    int tex_slot;     /* -1: no volume texture */
    int tex_material; /* the texture's material when tex_slot >= 0 */
    uint32_t first_tri, ntris;         /* the object's own triangles */
    uint32_t first_tex_tri, ntex_tris; /* its texture's triangles */
} SceneObject;

/* How energy splits at an interface (render.fresnel). */
enum { SCENE_FRESNEL_EXACT = 0, SCENE_FRESNEL_THESIS = 1 };

/* How a refined pixel is made of its samples (render.aa_reconstruct): each finest cell the
 * value of the nearest sample, or of the leaf covering it (the thesis's area-weighted mean
 * of the leaves). The values are VbAaPass.reconstruct's. */
enum { SCENE_AA_NEAREST = 0, SCENE_AA_LEAVES = 1 };

/* Which node of a failing pair of adjacent leaves at the same level splits (render.aa_pairs):
 * the first in raster order, the other only if the pair still fails against the first's
 * children (the thesis's figure 4.2, one pixel at a time), or both at once. The values are
 * VbAaPass.pairs'. */
enum { SCENE_AA_PAIRS_FIRST = 0, SCENE_AA_PAIRS_BOTH = 1 };

/* render.aa_floor's default: the least a + b of the contrast test (display units). */
#define SCENE_AA_FLOOR 1.0f
/* render.aa_level_gain's default: the threshold grows by this factor per level. */
#define SCENE_AA_LEVEL_GAIN 2.0f
/* render.penumbra_feelers's default and largest value: a power of two, so that the extra
 * feelers continue the first ones' scrambled net into a larger net (light_penumbra). */
#define SCENE_PENUMBRA_FEELERS     4
#define SCENE_PENUMBRA_FEELERS_MAX 16
#define SCENE_PENUMBRA_FEELERS_SET "1, 2, 4, 8 or 16" /* the values that are ok */
static inline int scene_penumbra_feelers_ok(int k)
{
    return k >= 1 && k <= SCENE_PENUMBRA_FEELERS_MAX && (k & (k - 1)) == 0;
}

typedef struct Scene {
    char *path; /* the scene file as given */
    char *dir;  /* its directory, for relative mesh paths */
    /* image */
    int width, height;
    char *output;   /* image.output, or NULL */
    float exposure; /* stops */
    float background[3];
    SceneEnvironment env; /* image.environment; env.file NULL: none */
    /* camera */
    vec3 eye, look_at, up;
    float fov; /* vertical, degrees */
    /* The frame everything is stored and rendered in (scene_frame_pick): a point p of the
     * scene file is (p - frame_origin) * frame_scale here, lengths scale by frame_scale
     * (a power of two, so exactly) and extinctions by its inverse. The identity for a view
     * of ordinary size near the origin; a scene far smaller or larger than a unit, or far
     * from the origin, is brought to one, so that every float and every epsilon of the
     * renderer sees it as it sees a unit scene (docs/architecture.md, "Scale"). */
    double frame_origin[3];
    float frame_scale;
    /* render */
    int max_depth;
    int grid_res[3];    /* all 0: auto */
    float grid_density; /* cells per triangle of `auto`; 0: the default (grid_build_levels) */
    int subgrid_res[3]; /* the second level's resolution in every crowded cell; all 0: auto */
    float subgrid_density;
    int shadow_samples; /* as given; the kernels use the nearest square */
    float ambient[3];
    unsigned seed;
    int shadow_jitter;    /* render.shadow_jitter: 1 jittered feelers, 0 at stratum centres */
    int shadow_cone_test; /* render.shadow_cone_test: 0 traces every feeler (light_cone_objects) */
    int camera_tiles;     /* render.camera_tiles: 0 camera rays walk the grid (camera_tiles.h) */
    int shadow_by_weight; /* render.shadow_by_weight: feelers of ray-tree nodes by their weight
                           * (light_node_strata); 0: all shadow_samples at every node */
    int sample_shares;    /* render.sample_shares: with shadow_by_weight and adaptive
                           * anti-aliasing, a quadtree sample's ray-tree points count 2^-level
                           * of their weight (sample_share); 0: 1 */
    int penumbra_feelers; /* render.penumbra_feelers: a point whose first feelers toward a light
                           * disagree traces this many times as many (light_penumbra); 1: never */
    int fresnel;          /* SCENE_FRESNEL_* */
    float min_weight;     /* ray-tree pruning threshold */
    float aa_threshold;   /* adaptive anti-aliasing contrast threshold; 0: off */
    int aa_max_level;     /* deepest refinement level: 2^level x 2^level samples (1..4) */
    int aa_min_level;     /* every pixel is split down to this level untested (0..aa_max_level) */
    float aa_floor;       /* the contrast's a + b counts as at least this (SCENE_AA_FLOOR) */
    float aa_level_gain;  /* a leaf at level L fails at aa_threshold * gain^L (1: the thesis) */
    int aa_reconstruct;   /* SCENE_AA_NEAREST or SCENE_AA_LEAVES */
    int aa_pairs;         /* SCENE_AA_PAIRS_FIRST or SCENE_AA_PAIRS_BOTH */
    int ssaa;             /* uniform N x N supersampling (command line only); 1: off */
    int crop[4];          /* --crop (command line only): the region written, x0, y0, x1, y1 in
                           * pixels (x1, y1 one past its last column and row); all 0: none,
                           * the whole image */
    int crop_margin;      /* --crop-margin (command line only): pixels rendered around the
                           * region for adaptive anti-aliasing's contrast test; -1: its whole
                           * reach (frame_window) */
    int bands;            /* render.bands: wavelength bands of a dispersive split */
    int band_layout;      /* DISP_LAYOUT_*: "bands": "thesis", or by default when every
                           * dispersive material uses the thesis model */
    int frames;           /* animation.frames, or 1 */
    int animated;         /* the scene has an "animation" */
    int frame;            /* the frame loaded (0 for a scene as written) */
    /* contents */
    int nlights;
    VbLight *lights;
    int nmaterials;
    SceneMaterial *materials;
    int nobjects;
    SceneObject *objects;
    int ntextured;
    Mesh mesh;         /* all objects and textures, world space */
    uint32_t *tri_tag; /* per triangle: object index | VBCL_TAG_TEXTURE (texture triangles) |
                          VBCL_TAG_OPAQUE (an object that is not a host) */
    char warning[512]; /* the first thing the scene loads but will not render as meant
                        * ("FILE: json.path: what and why"), or "" */
} Scene;

/* Whether objects[i].texture.generate runs the texture generators (texgen_bomb,
 * texgen_deform): 1 unless a program turns it off. The scene fuzzer does, so that an input
 * asking for a million elements cannot make a run slow: the arguments are still parsed and
 * checked, and a valid "generate" is then an error. */
extern int scene_texgen_enabled;

/* Reads and checks a scene file. Returns 0, or 2 (bad input) with a one-line message in
 * err: "FILE:LINE:COL: ..." for JSON syntax, "FILE: json.path: what was expected" for
 * meaning, and the mesh file's own message for a bad mesh. On error *s is freed. */
int scene_load(const char *path, Scene *s, char *err, size_t errlen);

/* The same for frame `frame` of an animated scene (docs/scene-format.md, "animation"): the
 * tracks set their targets for that frame before the scene is read. frame -1: the scene as
 * written, tracks only checked. s->frames tells how many frames the scene has (1 if it is
 * not animated); a frame beyond them is an error. */
int scene_load_frame(const char *path, int frame, Scene *s, char *err, size_t errlen);

/* Reads a scene file whole, exactly once (a named pipe or standard input cannot be read
 * twice): "-" and "/dev/stdin" read standard input. At most SCENE_MAX_FILE_BYTES, no NUL
 * byte. Returns 0 with *text malloc'ed, or 2 with a message. */
int scene_read_text(const char *path, char **text, char *err, size_t errlen);

/* scene_load_frame on text already read from path: path names the scene in messages
 * ("-" as "<stdin>") and its directory is where relative mesh paths start (the current
 * directory for "-" and "/dev/stdin"). */
int scene_load_text(const char *path, const char *text, int frame, Scene *s, char *err,
                    size_t errlen);

/* The name messages give the scene file at path: "<stdin>" for "-". */
const char *scene_display_name(const char *path);

/* Picks s->frame_origin and frame_scale from the camera as written (eye and look_at, in
 * double): the scale 2^-round(log2 d) of the viewing distance d when d <
 * SCENE_FRAME_MIN_VIEW or d > SCENE_FRAME_MAX_VIEW, else 1; the origin look_at, each
 * coordinate rounded to a multiple of 2^ceil(log2 d), when look_at lies more than
 * SCENE_FRAME_FAR_VIEWS viewing distances from (0, 0, 0), else (0, 0, 0). (The rounding
 * keeps the frame's coordinates within a viewing distance of look_at, and makes a scene
 * moved by a multiple of that power of two the same scene in the frame, bit for bit.) Then
 * puts the camera in that frame. */
#define SCENE_FRAME_MIN_VIEW  (1.0 / 16.0)
#define SCENE_FRAME_MAX_VIEW  1024.0
#define SCENE_FRAME_FAR_VIEWS 2.0
void scene_frame_pick(Scene *s, const double eye[3], const double look_at[3]);

/* Point p of the scene file (in double, as written) in s's frame. */
vec3 scene_frame_point(const Scene *s, const double p[3]);

/* Whether s's frame is the scene file's own (origin 0, scale 1). */
int scene_frame_is_identity(const Scene *s);

/* Frees everything scene_load allocated. */
void scene_free(Scene *s);

/* Where the point p is: the host containing it (hosts must not overlap) and how many
 * elements of each textured object's texture contain it, by counting signed crossings
 * of a ray from p in double precision. */
void scene_medium_at(const Scene *s, vec3 p, VbMedium *m);

/* Parses a grid resolution as written on the command line: "auto", "N" or "NX,NY,NZ"
 * (1..GRID_MAX_AXIS each, at most GRID_MAX_CELLS in all).
 * Returns 0 and sets res (all 0 for auto), or -1. */
int scene_parse_grid(const char *text, int res[3]);

/* Parses both levels of a grid as written on the command line: TOP or TOP:SUB, each "auto",
 * "N" or "NX,NY,NZ" (TOP as scene_parse_grid; SUB 1..GRID_SUB_MAX_AXIS each). Returns 0 and
 * sets res, and sub when SUB is given (all 0 for auto), or -1 (res and sub untouched). */
int scene_parse_grid_levels(const char *text, int res[3], int sub[3]);

#endif
