/* types.h — data shared by the host (C) and the kernels (OpenCL C): one definition,
 * compiled by both sides. Only 4-byte scalars and float[4] arrays, padded by hand; the
 * sizes and offsets are checked at compile time on both sides (end of this file). */
#ifndef VBCL_TYPES_H
#define VBCL_TYPES_H

#include "compat.h"

/* Feature bits: which code a scene needs. The host turns them into -D options
 * (features_build_options in host/kernel_features.c); kernels test the macros. */
#define VBCL_FEATURE_AREA_LIGHTS    (1u << 0) /* some light has a radius > 0 */
#define VBCL_FEATURE_SMOOTH_NORMALS (1u << 1) /* some triangle has vertex normals */
#define VBCL_FEATURE_SPECULAR       (1u << 2) /* some material has a specular colour */
#define VBCL_FEATURE_COUNT          3

/* Ray-kind counters kept by the kernels (one atomic add per work item, not per ray). */
#define VBCL_COUNT_PRIMARY         0
#define VBCL_COUNT_SHADOW          1
#define VBCL_COUNT_SHADOW_SKIPPED  2 /* feelers not traced: light behind the surface */
#define VBCL_COUNT_TRAVERSAL_STEPS 3
#define VBCL_COUNT_TRI_TESTS       4
#define VBCL_COUNTERS              8

/* A ray work item: from the camera, or a secondary ray. */
typedef struct VbRay {
    float org[3];
    float tmax;          /* farthest accepted hit distance (in units of |dir|) */
    float dir[3];        /* unit length */
    unsigned int sample; /* film sample this ray belongs to (index within the tile) */
} VbRay;

/* The closest hit of a ray. */
typedef struct VbHit {
    float t;
    int tri;    /* -1: the ray left the scene */
    float u, v; /* barycentric coordinates of the hit on the triangle (w = 1-u-v) */
} VbHit;

/* A triangle as the kernels read it: three vertices, with w of v[0] holding the
 * material index (as float bits, via as_uint) — one 48-byte record per triangle. */
typedef struct VbTriangle {
    float v0[4];
    float v1[4];
    float v2[4];
} VbTriangle;

/* Per-vertex shading normals of a triangle (w unused); present only with
 * VBCL_FEATURE_SMOOTH_NORMALS. A zero normal means "use the geometric normal". */
typedef struct VbTriNormals {
    float n0[4];
    float n1[4];
    float n2[4];
} VbTriNormals;

/* Surface and volume properties of one material (thesis 4.1.4). */
typedef struct VbMaterial {
    float ambient[4];    /* rgb reflectance for the ambient light */
    float diffuse[4];    /* rgb diffuse reflectance */
    float specular[4];   /* rgb specular reflectance */
    float extinction[4]; /* rgb absorption coefficient alpha, 1/scene unit (optics issue) */
    float exponent;      /* specular (Blinn-Phong) exponent */
    float k_local;       /* weight of local shading */
    float k_global;      /* weight of reflected + transmitted light (optics issue) */
    float eta;           /* refractive index (optics issue) */
} VbMaterial;

/* A spherical light: radiance is uniform over its surface. */
typedef struct VbLight {
    float centre[3];
    float radius;      /* 0: a point light */
    float radiance[3]; /* rgb radiance of the surface (for radius 0: intensity, W/sr) */
    float pad;
} VbLight;

/* Pinhole camera: pixel (x, y) looks along normalize(forward + sx*right + sy*up). */
typedef struct VbCamera {
    float eye[4];
    float forward[4]; /* unit */
    float right[4];   /* scaled by tan(fov/2) * aspect */
    float up[4];      /* scaled by tan(fov/2) */
} VbCamera;

/* The uniform grid: bounds, resolution, cell size. */
typedef struct VbGrid {
    float lo[4];
    float hi[4];
    float cell[4];     /* cell size per axis */
    float inv_cell[4]; /* 1 / cell size */
    int n[4];          /* cells per axis (w unused) */
} VbGrid;

/* Everything a frame's kernels read besides the big buffers. */
typedef struct VbFrame {
    VbCamera camera;
    VbGrid grid;
    float background[4]; /* rgb radiance of rays that leave the scene */
    float ambient[4];    /* rgb ambient light */
    int width, height;   /* full image size in pixels */
    int first_pixel;     /* index of the tile's first pixel in the image (row-major) */
    int tile_pixels;     /* pixels in this tile */
    unsigned int nlights;
    unsigned int ntris;
    unsigned int shadow_strata; /* feelers per light per point: shadow_strata^2 */
    unsigned int seed;
} VbFrame;

VBCL_STATIC_ASSERT(sizeof(VbRay) == 32, ray_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbRay, dir) == 16, ray_dir);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbRay, sample) == 28, ray_sample);
VBCL_STATIC_ASSERT(sizeof(VbHit) == 16, hit_size);
VBCL_STATIC_ASSERT(sizeof(VbTriangle) == 48, triangle_size);
VBCL_STATIC_ASSERT(sizeof(VbTriNormals) == 48, trinormals_size);
VBCL_STATIC_ASSERT(sizeof(VbMaterial) == 80, material_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbMaterial, exponent) == 64, material_exponent);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbMaterial, eta) == 76, material_eta);
VBCL_STATIC_ASSERT(sizeof(VbLight) == 32, light_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbLight, radiance) == 16, light_radiance);
VBCL_STATIC_ASSERT(sizeof(VbCamera) == 64, camera_size);
VBCL_STATIC_ASSERT(sizeof(VbGrid) == 80, grid_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbGrid, n) == 64, grid_n);
VBCL_STATIC_ASSERT(sizeof(VbFrame) == 144 + 32 + 32, frame_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, grid) == 64, frame_grid);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, background) == 144, frame_background);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, width) == 176, frame_width);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, seed) == 204, frame_seed);

#endif
