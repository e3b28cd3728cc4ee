/* types.h — data shared by the host (C) and the kernels (OpenCL C): one definition,
 * compiled by both sides. Only 4-byte scalars and float[4] arrays, padded by hand; the
 * sizes and offsets are checked at compile time on both sides (end of this file). */
#ifndef VBCL_TYPES_H
#define VBCL_TYPES_H

#include "compat.h"
#include "solidtex.h"

/* Feature bits: which code a scene needs. The host turns them into -D options
 * (features_build_options in host/device/kernel_features.c); kernels test the macros. */
#define VBCL_FEATURE_AREA_LIGHTS    (1u << 0) /* some light has a radius > 0 */
#define VBCL_FEATURE_SMOOTH_NORMALS (1u << 1) /* some triangle has vertex normals */
#define VBCL_FEATURE_SPECULAR       (1u << 2) /* some material has a specular colour */
#define VBCL_FEATURE_TRANSPARENCY   (1u << 3) /* some object is a dielectric (k_global > 0) */
#define VBCL_FEATURE_TEXTURES       (1u << 4) /* some object carries a volume texture */
#define VBCL_FEATURE_ABSORPTION     (1u << 5) /* some dielectric absorbs (extinction > 0) */
#define VBCL_FEATURE_FRESNEL_THESIS (1u << 6) /* split by thesis eq. 9, not Fresnel */
#define VBCL_FEATURE_PATTERNS       (1u << 7) /* some material has a surface pattern */
#define VBCL_FEATURE_DISPERSION     (1u << 8) /* some dielectric's eta depends on wavelength */
#define VBCL_FEATURE_ENVIRONMENT    (1u << 9) /* rays that leave the scene see image.environment */
#define VBCL_FEATURE_COUNT          10

/* VbPattern.kind: the solid textures that colour surfaces (thesis 2.2.2.3). */
#define VBCL_PATTERN_FOURIER    1 /* Gardner's Fourier synthesis G(X, Y, Z) */
#define VBCL_PATTERN_PROJECTION 2 /* orthogonal projection of an image along one axis */
#define VBCL_PATTERN_CHECKER    3 /* cells of two colours, constant along the axes not in axes */

/* Volume textures: at most this many objects per scene carry one; the medium state keeps
 * an 8-bit count of elements per textured object. */
#define VBCL_MAX_TEXTURED 4

/* The tag in a triangle's v0[3]: the object index, with VBCL_TAG_TEXTURE set for triangles
 * of the object's volume texture and VBCL_TAG_OPAQUE for triangles of an object that bounds
 * no tracked volume (an opaque surface: the closest-hit search prefers it where it touches
 * a medium boundary, geometry.cl hit_before). */
#define VBCL_TAG_TEXTURE 0x80000000u
#define VBCL_TAG_OPAQUE  0x40000000u
#define VBCL_TAG_FLAGS   (VBCL_TAG_TEXTURE | VBCL_TAG_OPAQUE)

/* VbObject.flags */
#define VBCL_OBJECT_HOST   1u /* a closed volume whose inside the medium state tracks */
#define VBCL_OBJECT_PLANAR 2u /* every triangle of the object lies in VbObject.plane */
#define VBCL_OBJECT_CONVEX 4u /* every vertex lies behind (or on) every triangle's plane */
#define VBCL_OBJECT_HULL                                                                           \
    16u /* its own triangles bound a convex volume (its texture aside): a feeler's stretch         \
         * inside it is the segment clipped by their planes */
#define VBCL_OBJECT_INNER                                                                          \
    32u /* a host of more than VBCL_OBJECT_SET_MAX_TRIS / 2 own triangles that bound a convex      \
         * volume: VbObject.inside holds a sphere behind every plane of them (its inner sphere),   \
         * so a ray inside it meets them only where it has left that sphere (ray_objects) */
#define VBCL_OBJECT_SOLID                                                                          \
    8u /* a texture part that is convex, of an opaque material, strictly inside its convex         \
        * host and apart from the texture's other parts, or an opaque object (not a host) of       \
        * more than VBCL_OBJECT_SET_MAX_TRIS / 2 triangles that close a convex surface:            \
        * VbObject.inside holds a sphere inside it (its core), and a feeler from outside its       \
        * bounds that passes through the core is stopped by it, whatever it meets on the way */

/* The work counters the kernels keep (at most one atomic add per work item, not per ray, into
 * its work group's copy: VBCL_COUNTER_SLOTS): one list,
 * X(NAME, index, RenderStats field, stats group, key), from which come the indices
 * VBCL_COUNT_NAME into the counters buffer, the RenderStats fields (host/device/render.h), their
 * accumulation after each batch (renderer_trace_rays) and their place in --stats-json: the
 * object `group`, the key `key` (host/stats.c; docs/stats.md). Index 0 (VBCL_COUNT_PRIMARY)
 * is reserved: the host counts primary rays itself. */
/* clang-format off */
#define VBCL_COUNTER_LIST(X)                                                                       \
    X(SHADOW,          1,  rays_shadow,     rays,     "shadow")           /* feelers traced */     \
    X(SHADOW_SKIPPED,  2,  shadow_skipped,  rays,     "shadow_skipped")   /* light behind */       \
    X(TRAVERSAL_STEPS, 3,  traversal_steps, work,     "cells_visited")    /* grid cells */         \
    X(TRI_TESTS,       4,  tri_tests,       work,     "triangles_tested") /* ray/triangle */       \
    X(REFLECTED,       5,  reflected,       ray_tree, "reflected")        /* secondary rays */     \
    X(TRANSMITTED,     6,  transmitted,     ray_tree, "transmitted")      /* secondary rays */     \
    X(PRUNED,          7,  pruned,          ray_tree, "pruned")           /* w < min_weight */     \
    X(DEPTH_CUT,       8,  depth_cut,       ray_tree, "depth_cut")        /* > max_depth */        \
    X(TIR,             9,  tir,             ray_tree, "tir")              /* total int. refl. */   \
    X(PASS_THROUGH,    10, pass_through,    ray_tree, "pass_through")     /* no material change */ \
    X(INTERFACES,      11, interfaces,      ray_tree, "interfaces")       /* energy splits */      \
    X(ENERGY_ERRORS,   12, energy_errors,   ray_tree, "energy_errors")    /* |R+T-1| > 1e-5 */     \
    X(SPLITS,          13, splits,          ray_tree, "splits")           /* white -> bands */     \
    X(BAND_RAYS,       14, band_rays,       ray_tree, "band_rays")        /* one-band rays */     \
    X(SHADOW_UNNEEDED, 15, shadow_unneeded, rays,     "shadow_unneeded")  /* BRDF gives 0 */  \
    X(SHADOW_CLEAR,    16, shadow_clear,    rays,     "shadow_clear")     /* cone meets nothing */ \
    X(SHADOW_BLOCKED,  17, shadow_blocked,  rays,     "shadow_blocked")   /* solid core */        \
    X(SHADOW_PENUMBRA, 18, shadow_penumbra, rays,     "shadow_penumbra")  /* more in penumbra */ \
    X(TREE_CUT,        19, tree_cut,        ray_tree, "tree_cut")         /* over TREE_MAX_RAYS */
/* clang-format on */
#define VBCL_COUNTER_INDEX(name, index, field, group, key) VBCL_COUNT_##name = (index),
enum { VBCL_COUNT_PRIMARY = 0, VBCL_COUNTER_LIST(VBCL_COUNTER_INDEX) };
#define VBCL_COUNT_DEPTH0     20 /* rays traced at depth d: counter DEPTH0 + min(d, 15) */
#define VBCL_COUNT_DEPTH_BINS 16
#define VBCL_COUNTERS         36
/* The counters buffer holds VBCL_COUNTER_SLOTS copies of the counters, VBCL_COUNTER_STRIDE
 * words (a multiple of 64 bytes) apart: work group g adds into copy g % VBCL_COUNTER_SLOTS,
 * so that groups running at once on different cores seldom add to the same cache line,
 * and the host sums the copies once per batch (renderer_trace_rays). */
#define VBCL_COUNTER_SLOTS  16
#define VBCL_COUNTER_STRIDE 48
#define VBCL_COUNTER_WORDS  (VBCL_COUNTER_SLOTS * VBCL_COUNTER_STRIDE)
/* The most rays one sample's ray tree traces (tree_run): a tree that reaches it leaves its
 * pending branches untraced, counted as tree_cut. Deep trees without pruning between
 * several dielectrics can hold 2^max_depth rays; every example scene's trees stay far
 * below this. */
#define VBCL_TREE_MAX_RAYS 4096

/* A ray work item: from the camera, or a secondary ray. */
typedef struct VbRay {
    float org[3];
    float tmax;          /* farthest accepted hit distance (in units of |dir|) */
    float dir[3];        /* unit length */
    unsigned int sample; /* the film sample's id, the key of its shading jitter: the pixel's
                          * index in the image for a ray through its centre, a hash of (pixel,
                          * samples per axis, subpixel) for a supersample (aa_sample_id) */
} VbRay;

/* The closest hit of a ray. */
typedef struct VbHit {
    float t;
    int tri;    /* -1: the ray left the scene */
    float u, v; /* barycentric coordinates of the hit on the triangle (w = 1-u-v) */
} VbHit;

/* A triangle as the kernels read it: three vertices, with w of v[0] holding its tag
 * (object index | VBCL_TAG_TEXTURE, as bits) — one 48-byte record per triangle. */
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
    float k_global;      /* weight of reflected + transmitted light */
    float eta;           /* refractive index */
    int pattern;         /* index into the patterns, or -1 */
    int disp;            /* dispersion: first float of its band table in the side data
                          * (texels): per band (eta, transmitted fraction, 0, 0); -1: none */
    int pad[2];
} VbMaterial;

/* A material's surface pattern: at a hit point p, texture coordinates
 * q = (p - origin) * inv_size, and the diffuse and ambient colours are scaled by
 * max(G(q), 0) (Fourier) or by the image's texel at (q.x, q.y) (projection, 0 outside
 * the unit square, as the thesis's R). */
typedef struct VbPattern {
    int kind;                  /* VBCL_PATTERN_* */
    int width, height;         /* projection: image size */
    unsigned int texel_offset; /* projection: first texel (4 floats each) in the texels */
    float origin[4];
    float inv_size[4];
    VbFourier fourier;   /* VBCL_PATTERN_FOURIER */
    float colours[2][4]; /* VBCL_PATTERN_CHECKER: the cell of (0, 0, 0) and its neighbours' */
    unsigned int axes;   /* CHECKER: bit k set: the cells alternate along axis k; PROJECTION:
                          * the bit of the axis it projects along */
    unsigned int pad[3];
} VbPattern;

/* An object as the kernels see it: its material, for a host its volume texture, and
 * where its triangles (texture included) lie, for the shadow cone test (light.cl). */
typedef struct VbObject {
    unsigned int material;     /* the object's own volume and surface */
    unsigned int tex_material; /* its volume texture's material (when tex_slot >= 0) */
    int tex_slot;              /* which count of VbMedium.tex_counts, or -1: no texture */
    unsigned int flags;        /* VBCL_OBJECT_* */
    float bound[4];            /* a sphere holding every triangle: centre, radius (margins
                                * included; radius < 0: no triangles) */
    float lo[3];               /* the triangles' bounding box, widened by the same margin */
    float plane_eps;           /* the vertices' largest distance from the plane, plus a margin */
    float hi[3];
    unsigned int host;      /* a texture part's record: the object whose texture it is */
    float plane[4];         /* VBCL_OBJECT_PLANAR: unit normal n and offset k (n.x = k on
                             * the plane); w: k. Each vertex lies within plane_eps of it */
    unsigned int first_tri; /* its own triangles: first_tri .. first_tri + ntris - 1 */
    unsigned int ntris;
    unsigned int first_tex; /* its texture's triangles */
    unsigned int ntex;
    unsigned int first_elem; /* its texture's elements: records first_elem .. first_elem +
                              * nelems - 1 of the objects buffer, after the scene's objects,
                              * each holding the bounds (bound, lo, hi, VBCL_OBJECT_CONVEX)
                              * and the range (first_tri, ntris) of one part of the texture;
                              * nelems 0: the texture is bounded as a whole */
    unsigned int nelems;
    float own[4]; /* a sphere holding the object's own triangles alone, its texture left out
                   * (as bound: centre, radius with margins; radius < 0: none); a part's and a
                   * textureless object's is bound */
    unsigned int quad_tri; /* the first of the quads (VbLeafQuad, after the leaves' in
                            * leaf_quads) that hold its own triangles four at a time, in the
                            * order of their indices, for the shadow cone test's sets
                            * (light_cone_objects); VBCL_NO_QUADS where it has more than
                            * VBCL_OBJECT_SET_MAX_TRIS / 2 (a set never holds them) */
    unsigned int quad_tex; /* the same for its texture's triangles, where it has no parts
                            * (nelems 0) and they and its own fit in a set together */
    unsigned int ahead;    /* a texture part's record: bit j set where the part may reach ahead
                            * of the plane of its host's own triangle host.first_tri + j (host
                            * of at most VBCL_AHEAD_BITS own triangles; of more, all bits set,
                            * or none where it lies within the host's inner sphere); clear only
                            * where it lies behind that plane by a margin, so that a ray or
                            * feeler leaving the host through the front of that triangle cannot
                            * meet it (part_ahead_bit). All set for a host that is not
                            * VBCL_OBJECT_HULL */
    unsigned int pad[3];
    float inside[4]; /* a sphere inside the object, centre and radius: VBCL_OBJECT_SOLID, its
                      * core; VBCL_OBJECT_INNER (a host), its inner sphere */
} VbObject;

/* The own triangles a host may have for a bit of VbObject.ahead each: the bits of an unsigned
 * int (the host's parts_ahead and the kernels' part_ahead_bit). */
#define VBCL_AHEAD_BITS 32

/* The shadow cone test's sets of triangles (kernels/scene.cl, ObjectSet): at most this many
 * triangles in all; a record of more than half of it is tested by its bounds instead. */
#define VBCL_OBJECT_SET_MAX_TRIS 32
#define VBCL_NO_QUADS            0xffffffffu

/* Where a ray is: inside which host (or none), and inside how many elements of each
 * textured object's texture (8 bits per slot). The effective material follows. */
typedef struct VbMedium {
    int host;                /* object index, or -1: outside every host */
    unsigned int tex_counts; /* slot s in bits 8s..8s+7 */
} VbMedium;

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

/* Camera tiles (host/device/camera_tiles.h): the image in squares of VBCL_CAM_TILE pixels,
 * each with its triangles nearest first, which camera rays test instead of walking the grid.
 * nx = 0: none. right_n and up_n are the camera's right and up over their squared lengths,
 * so that a direction d falls on pixel x = (d.right_n / d.forward + 1) width / 2. */
#define VBCL_CAM_TILE 4
typedef struct VbCamTiles {
    float right_n[4];
    float up_n[4];
    int nx, ny; /* tiles per row and per column */
    int pad[2];
} VbCamTiles;

/* The top level of the two-level grid: bounds, resolution, cell size. */
typedef struct VbGrid {
    float lo[4];
    float hi[4];
    float cell[4];     /* cell size per axis */
    float inv_cell[4]; /* 1 / cell size */
    int n[4];          /* cells per axis (w unused) */
} VbGrid;

/* A top cell of the grid: a sub-grid of res = x | y << 10 | z << 20 sub-cells (each axis
 * 1 .. 1023), whose lists are leaves first .. first + x*y*z - 1 of the leaf offsets,
 * sub-cell (i, j, k) at first + i + x*(j + y*k); VBCL_GRID_LIST (1x1x1) is a plain list,
 * the one leaf `first`. Written by grid_build_leaves (host/accel/grid.c). */
typedef struct VbGridCell {
    unsigned int first;
    unsigned int res;
} VbGridCell;
/* Four triangles of one leaf, laid out for a test of all four in float4 lanes (grid.cl,
 * quad_candidates): xyz[3 k + a] holds coordinate a (x, y, z) of vertex k of the four
 * triangles, tri their indices. A leaf's scene triangles and its texture triangles fill
 * quads of their own (ceil(n / 4) each, in ascending triangle order), the last of each
 * padded with tri -1 (and zero vertices). After the leaves' come those of the records'
 * small ranges (VbObject.quad_tri, quad_tex), in the same way. Written by pack_quads
 * (host/device/device_scene.c); the leaves' counted by grid_leaf_quads (host/accel/grid.c). */
typedef struct VbLeafQuad {
    float xyz[9][4];
    int tri[4];
} VbLeafQuad;

#define VBCL_GRID_SUB_BITS 10
#define VBCL_GRID_SUB_MASK 1023u
#define VBCL_GRID_LIST     (1u | 1u << VBCL_GRID_SUB_BITS | 1u << (2 * VBCL_GRID_SUB_BITS))

/* Anti-aliasing (thesis 4.1.2): each pixel is the root of a quadtree of subpixels down to
 * level VBCL_AA_MAX_LEVEL (16x16); a leaf holds one sample (kernels/aa_tree.h), and the
 * pixel is the mean of its 16x16 finest cells, each the value of the nearest sample or of
 * its leaf (VbAaPass.reconstruct). Level 0 is the ray through the pixel's centre. */
#define VBCL_AA_MAX_LEVEL 4   /* 16x16 subpixels, the thesis's bound */
#define VBCL_AA_CELLS     256 /* finest cells per pixel: (2^VBCL_AA_MAX_LEVEL)^2 */

/* One step of the anti-aliasing passes (aa_* kernels in render.cl), uploaded before each
 * launch: the contrast test's parameters, or a batch of nodes or pixels to sample. */
typedef struct VbAaPass {
    float threshold;       /* a pair of neighbours fails when |a-b| / max(a+b, floor) > threshold */
    float contrast_scale;  /* values are scaled by 2^exposure and clamped to [0, 1] first */
    int max_level;         /* nodes at this level are never split */
    int width, height;     /* the film's size in pixels: the frame's window (VbFrame) */
    int side;              /* uniform batch: samples per pixel axis (N of --ssaa) */
    float floor;           /* contrast: a + b below this counts as this (dark noise) */
    unsigned int first;    /* batch: its first entry in the list of marked nodes (or pixels) */
    unsigned int entries;  /* batch: entries in it */
    int round;             /* adaptive: the round (0, 1, ...) of this contrast pass or batch */
    float level_gain;      /* a leaf at level L fails at threshold * level_gain^L */
    int reconstruct;       /* aa_resolve: 0 the nearest samples, 1 the leaves (SCENE_AA_*) */
    unsigned int tree_cap; /* adaptive: the tree slots the levels and values hold (aa_tree.h) */
    int pairs; /* aa_leaf_fails: a failing pair of leaves of one level splits its first leaf in
                * raster order (0, the thesis's) or both (1) (SCENE_AA_PAIRS_*) */
} VbAaPass;

/* The environment (image.environment, kernels/environment.cl): a latitude-longitude image in
 * the texels, seen by every ray that leaves the scene (VBCL_FRAME_ENVIRONMENT). A direction
 * d is looked up at e = rot d (rot's rows: the world-to-environment rotation), u =
 * atan2(e.x, -e.z) / 2pi in [0, 1) and v = acos(e.y) / pi, bilinearly between texel centres
 * along u (x = u width - 1/2, wrapping) and between rows along v (y = v (height - 1): row 0
 * the zenith, the last the nadir), as Mitsuba 3's envmap. */
typedef struct VbEnvironment {
    float rot[3][4];    /* rows of the world-to-environment rotation ([k][3] unused, 0) */
    unsigned int first; /* its first texel (4 floats each) in the texels, row 0 first */
    int width, height;  /* texels */
    unsigned int pad;
} VbEnvironment;

/* Everything a frame's kernels read besides the big buffers. */
typedef struct VbFrame {
    VbCamera camera;
    VbGrid grid;
    float background[4]; /* rgb radiance of rays that leave the scene */
    float ambient[4];    /* rgb ambient light */
    int width, height;   /* full image size in pixels */
    int first_pixel;     /* index of the tile's first pixel in the window (row-major) */
    int tile_pixels;     /* pixels in this tile */
    unsigned int nlights;
    unsigned int ntris;
    unsigned int shadow_strata; /* feelers per light per point: shadow_strata^2 */
    unsigned int seed;
    VbMedium camera_medium;       /* where the camera is, computed on the host */
    unsigned int air_material;    /* index of the material outside every host */
    float min_weight;             /* branches whose weight is below this in every channel stop */
    int max_depth;                /* deepest ray-tree level traced (primary rays: 0) */
    int bands;                    /* wavelength bands of a dispersive split */
    unsigned int band_weights;    /* first float of the bands' rgb weights (4 floats each) in the
                                   * side data (texels) */
    unsigned int flags;           /* VBCL_FRAME_* */
    unsigned int nobjects;        /* objects (VbObject), for the shadow cone test */
    unsigned int penumbra_factor; /* a point whose first feelers toward a light disagree traces
                                   * this many times as many (1: never; light_reflect_area) */
    unsigned int pad[2];
    VbCamTiles cam_tiles;
    /* The window: the part of the image the frame renders (host/frame/frame.h, frame_window:
     * a --crop region and the anti-aliasing's margin around it; the whole image without
     * --crop). Tiles, the film and the anti-aliasing's pixel indices count its pixels, row
     * by row (window_width a row); camera rays and sample ids use the pixel's place in the
     * whole image, so a pixel renders the same in any window. */
    int window_x, window_y; /* its top-left pixel in the image */
    int window_width, window_height;
    VbEnvironment env; /* with VBCL_FRAME_ENVIRONMENT: what rays leaving the scene see
                        * instead of background */
} VbFrame;

/* VbFrame.flags */
#define VBCL_FRAME_FIXED_FEELERS 1u /* shadow feelers at stratum centres, the same everywhere */
#define VBCL_FRAME_NET_FEELERS   2u /* jittered feelers of a power-of-two side: a scrambled net */
#define VBCL_FRAME_CONE_TEST                                                                       \
    4u /* a point's feelers toward a light whose cone meets no                                     \
        * object's bounds are not traced (light_cone_objects) */
#define VBCL_FRAME_WEIGHTED_FEELERS                                                                \
    8u /* a ray-tree node gets feelers in proportion to its weight (light_node_strata) */
#define VBCL_FRAME_SAMPLE_SHARES                                                                   \
    16u /* adaptive anti-aliasing with feelers by weight: a quadtree sample's id carries its       \
         * level, and its points count 2^-level of their weight (sample_share) */
/* What the scene uses, for programs compiled with more than it needs (kernel_features.c):
 * each of these is tested at run time wherever the program has the code for it. */
#define VBCL_FRAME_FRESNEL_THESIS  32u   /* the thesis's angle-independent split (eq. 9) */
#define VBCL_FRAME_SMOOTH_NORMALS  64u   /* the mesh has vertex normals (the normals buffer) */
#define VBCL_FRAME_TRANSPARENCY    128u  /* some surface has k_global > 0: rays cross media */
#define VBCL_FRAME_TEXTURES        256u  /* some object holds a volume texture */
#define VBCL_FRAME_DISPERSION      512u  /* some transparent material disperses: split records */
#define VBCL_FRAME_ABSORPTION      1024u /* some transparent material has an extinction > 0 */
#define VBCL_FRAME_ENVIRONMENT     2048u /* rays that leave the scene see env, not background */
#define VBCL_CONE_TEST_MAX_OBJECTS 64    /* scenes with more objects trace every feeler */
#define VBCL_CONE_TEST_MAX_ELEMENTS                                                                \
    64 /* a texture of more parts (connected pieces) than this is bounded as a whole */

/* Dispersion: a white ray's refraction into bands, recorded by tree_trace_secondary and
 * traced by its second launch (so that the time spent in dispersive subtrees is that
 * launch's time). Each ray has VBCL_SPLIT_SLOTS records; further splits of the same tree are
 * traced inline. Device data only: the host sizes the buffer. */
#define VBCL_SPLIT_SLOTS 2
typedef struct VbSplit {
    float p[4];      /* the shading point; [3]: its ray offset (tri_point_error) */
    float ng[4];     /* unit geometric normal on the incoming side */
    float ns[4];     /* unit shading normal, same side */
    float dir[4];    /* incoming direction */
    float weight[4]; /* weight arriving at the interface, times the surface's k_global */
    VbMedium after;  /* the medium beyond the interface */
    unsigned int mat_before, mat_after;
    int depth;
    unsigned int key; /* jitter key of the transmitted bands */
    int pad[2];
} VbSplit;

typedef struct VbSplitSet {
    VbSplit s[VBCL_SPLIT_SLOTS];
    int count;    /* records in use */
    float budget; /* pruning budget the first kernel left (see tree_push) */
    int pad[2];
} VbSplitSet;

/* Every size and offset the host relies on, as one list that the host and the device both
 * evaluate (probe_layout, test_kernel_struct_layout): the device compiler's layout must equal
 * the host's, whatever the static asserts below say about either. */
/* clang-format off */
#define VBCL_LAYOUT_ITEMS(X)                                                                       \
    X(sizeof(VbRay)) X(VBCL_OFFSETOF(VbRay, dir)) X(VBCL_OFFSETOF(VbRay, sample))                 \
    X(sizeof(VbHit)) X(sizeof(VbTriangle)) X(sizeof(VbTriNormals)) X(sizeof(VbMaterial))          \
    X(VBCL_OFFSETOF(VbMaterial, exponent)) X(VBCL_OFFSETOF(VbMaterial, eta))                       \
    X(VBCL_OFFSETOF(VbMaterial, pattern)) X(VBCL_OFFSETOF(VbMaterial, disp))                       \
    X(sizeof(VbPattern)) X(VBCL_OFFSETOF(VbPattern, fourier)) X(VBCL_OFFSETOF(VbPattern, colours)) X(VBCL_OFFSETOF(VbPattern, axes)) X(sizeof(VbObject)) \
    X(VBCL_OFFSETOF(VbObject, bound)) X(VBCL_OFFSETOF(VbObject, lo)) X(VBCL_OFFSETOF(VbObject, plane_eps)) X(VBCL_OFFSETOF(VbObject, hi)) X(VBCL_OFFSETOF(VbObject, plane)) X(VBCL_OFFSETOF(VbObject, first_tri)) X(VBCL_OFFSETOF(VbObject, ntex)) X(VBCL_OFFSETOF(VbObject, nelems)) X(VBCL_OFFSETOF(VbObject, own)) X(VBCL_OFFSETOF(VbObject, quad_tri)) X(VBCL_OFFSETOF(VbObject, quad_tex)) X(VBCL_OFFSETOF(VbObject, ahead)) X(VBCL_OFFSETOF(VbObject, inside)) \
    X(sizeof(VbMedium)) X(sizeof(VbLight)) X(VBCL_OFFSETOF(VbLight, radiance))                     \
    X(sizeof(VbCamera)) X(sizeof(VbGrid)) X(VBCL_OFFSETOF(VbGrid, n)) X(sizeof(VbFrame))           \
    X(sizeof(VbGridCell)) X(VBCL_OFFSETOF(VbGridCell, res))                                        \
    X(sizeof(VbLeafQuad)) X(VBCL_OFFSETOF(VbLeafQuad, tri))                                        \
    X(VBCL_OFFSETOF(VbFrame, grid)) X(VBCL_OFFSETOF(VbFrame, background))                          \
    X(VBCL_OFFSETOF(VbFrame, width)) X(VBCL_OFFSETOF(VbFrame, seed))                               \
    X(VBCL_OFFSETOF(VbFrame, camera_medium)) X(VBCL_OFFSETOF(VbFrame, min_weight))                 \
    X(VBCL_OFFSETOF(VbFrame, max_depth)) X(VBCL_OFFSETOF(VbFrame, bands))                          \
    X(VBCL_OFFSETOF(VbFrame, band_weights)) X(VBCL_OFFSETOF(VbFrame, flags)) X(VBCL_OFFSETOF(VbFrame, nobjects)) X(VBCL_OFFSETOF(VbFrame, penumbra_factor)) X(VBCL_OFFSETOF(VbFrame, cam_tiles)) X(VBCL_OFFSETOF(VbFrame, window_x)) X(VBCL_OFFSETOF(VbFrame, env)) X(sizeof(VbEnvironment)) X(VBCL_OFFSETOF(VbEnvironment, first)) X(sizeof(VbCamTiles)) X(VBCL_OFFSETOF(VbCamTiles, nx)) X(sizeof(VbAaPass)) X(VBCL_OFFSETOF(VbAaPass, side))   \
    X(VBCL_OFFSETOF(VbAaPass, first)) X(VBCL_OFFSETOF(VbAaPass, floor)) X(VBCL_OFFSETOF(VbAaPass, level_gain)) X(VBCL_OFFSETOF(VbAaPass, reconstruct)) X(VBCL_OFFSETOF(VbAaPass, tree_cap)) X(VBCL_OFFSETOF(VbAaPass, pairs)) X(sizeof(VbSplit))    \
    X(VBCL_OFFSETOF(VbSplit, after)) X(VBCL_OFFSETOF(VbSplit, key)) X(sizeof(VbSplitSet))          \
    X(VBCL_OFFSETOF(VbSplitSet, count))
/* clang-format on */
#define VBCL_LAYOUT_COUNT_ONE(e) +1
#define VBCL_LAYOUT_COUNT        (0 VBCL_LAYOUT_ITEMS(VBCL_LAYOUT_COUNT_ONE))

VBCL_STATIC_ASSERT(sizeof(VbRay) == 32, ray_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbRay, dir) == 16, ray_dir);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbRay, sample) == 28, ray_sample);
VBCL_STATIC_ASSERT(sizeof(VbHit) == 16, hit_size);
VBCL_STATIC_ASSERT(sizeof(VbTriangle) == 48, triangle_size);
VBCL_STATIC_ASSERT(sizeof(VbTriNormals) == 48, trinormals_size);
VBCL_STATIC_ASSERT(sizeof(VbMaterial) == 96, material_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbMaterial, pattern) == 80, material_pattern);
VBCL_STATIC_ASSERT(sizeof(VbPattern) == 48 + 240 + 48, pattern_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbPattern, fourier) == 48, pattern_fourier);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbPattern, colours) == 48 + 240, pattern_colours);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbPattern, axes) == 48 + 240 + 32, pattern_axes);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbMaterial, exponent) == 64, material_exponent);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbMaterial, eta) == 76, material_eta);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbMaterial, disp) == 84, material_disp);
VBCL_STATIC_ASSERT(sizeof(VbLight) == 32, light_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbLight, radiance) == 16, light_radiance);
VBCL_STATIC_ASSERT(sizeof(VbCamera) == 64, camera_size);
VBCL_STATIC_ASSERT(sizeof(VbGrid) == 80, grid_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbGrid, n) == 64, grid_n);
VBCL_STATIC_ASSERT(sizeof(VbGridCell) == 8, gridcell_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbGridCell, res) == 4, gridcell_res);
VBCL_STATIC_ASSERT(sizeof(VbLeafQuad) == 160, leafquad_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbLeafQuad, tri) == 144, leafquad_tri);
VBCL_STATIC_ASSERT(sizeof(VbObject) == 160, object_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbObject, inside) == 144, object_inside);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbObject, ahead) == 128, object_ahead);
VBCL_STATIC_ASSERT(VBCL_AHEAD_BITS == 8 * sizeof(unsigned int), object_ahead_bits);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbObject, own) == 104, object_own);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbObject, quad_tri) == 120, object_quad_tri);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbObject, quad_tex) == 124, object_quad_tex);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbObject, nelems) == 100, object_nelems);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbObject, first_tri) == 80, object_first_tri);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbObject, ntex) == 92, object_ntex);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbObject, bound) == 16, object_bound);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbObject, lo) == 32, object_lo);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbObject, plane_eps) == 44, object_plane_eps);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbObject, hi) == 48, object_hi);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbObject, plane) == 64, object_plane);
VBCL_STATIC_ASSERT(sizeof(VbMedium) == 8, medium_size);
VBCL_STATIC_ASSERT(sizeof(VbFrame) == 384, frame_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, window_x) == 304, frame_window_x);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, cam_tiles) == 256, frame_cam_tiles);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, env) == 320, frame_env);
VBCL_STATIC_ASSERT(sizeof(VbEnvironment) == 64, environment_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbEnvironment, first) == 48, environment_first);
VBCL_STATIC_ASSERT(sizeof(VbCamTiles) == 48, cam_tiles_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbCamTiles, nx) == 32, cam_tiles_nx);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, flags) == 236, frame_flags);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, nobjects) == 240, frame_nobjects);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, penumbra_factor) == 244, frame_penumbra_factor);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, max_depth) == 224, frame_max_depth);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, camera_medium) == 208, frame_camera_medium);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, min_weight) == 220, frame_min_weight);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, bands) == 228, frame_bands);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, band_weights) == 232, frame_band_weights);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, grid) == 64, frame_grid);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, background) == 144, frame_background);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, width) == 176, frame_width);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFrame, seed) == 204, frame_seed);
VBCL_STATIC_ASSERT(sizeof(VbSplit) == 112, split_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbSplit, after) == 80, split_after);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbSplit, key) == 100, split_key);
VBCL_STATIC_ASSERT(sizeof(VbSplitSet) == 240, splitset_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbSplitSet, count) == 224, splitset_count);
VBCL_STATIC_ASSERT(sizeof(VbAaPass) == 56, aapass_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbAaPass, side) == 20, aapass_side);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbAaPass, floor) == 24, aapass_floor);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbAaPass, first) == 28, aapass_first);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbAaPass, level_gain) == 40, aapass_level_gain);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbAaPass, reconstruct) == 44, aapass_reconstruct);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbAaPass, tree_cap) == 48, aapass_tree_cap);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbAaPass, pairs) == 52, aapass_pairs);

/* The counter list's indices: distinct (their bits' sum equals their union), clear of the
 * reserved index 0 and below the by-depth counters. */
#define VBCL_COUNTER_BIT_OR(name, index, field, group, key)  | (1u << (index))
#define VBCL_COUNTER_BIT_SUM(name, index, field, group, key) +(1u << (index))
VBCL_STATIC_ASSERT((0u VBCL_COUNTER_LIST(VBCL_COUNTER_BIT_OR)) ==
                       (0u VBCL_COUNTER_LIST(VBCL_COUNTER_BIT_SUM)),
                   counters_distinct);
VBCL_STATIC_ASSERT(((0u VBCL_COUNTER_LIST(VBCL_COUNTER_BIT_OR)) & 1u) == 0 &&
                       (0u VBCL_COUNTER_LIST(VBCL_COUNTER_BIT_OR)) < (1u << VBCL_COUNT_DEPTH0),
                   counters_in_range);
VBCL_STATIC_ASSERT(VBCL_COUNT_DEPTH0 + VBCL_COUNT_DEPTH_BINS <= VBCL_COUNTERS, counters_depth);
VBCL_STATIC_ASSERT(VBCL_COUNTERS <= VBCL_COUNTER_STRIDE && VBCL_COUNTER_STRIDE % 16 == 0,
                   counter_slots_apart);

/* The scene's buffers, the one list behind every place that names them: the arguments
 * every frame kernel and scene probe starts with, in this order (render.cl
 * SCENE_KERNEL_ARGS), the device functions' DevScene (scene.cl), and the host's cl_mem
 * fields and clSetKernelArg calls (host/device/render.h, render.c). Each entry is
 * X(address space, element type, kernel argument name, Renderer field). */
#define VBCL_SCENE_BUFFERS(X)                                                                      \
    X(__constant, VbFrame, f, frame)                                                               \
    X(__global, VbTriangle, tris, tris)                                                            \
    X(__global, VbTriNormals, normals, normals)                                                    \
    X(__global, VbGridCell, grid_cells, grid_cells) /* one per top cell */                         \
    X(__global, uint, leaf_start, leaf_start)       /* offsets of the leaves' quads */             \
    X(__global, VbLeafQuad, leaf_quads, leaf_quads) /* their triangles, four at a time */          \
    X(__global, uint, cam_start, cam_start)         /* offsets of the camera tiles' quads */       \
    X(__global, VbLeafQuad, cam_quads, cam_quads)   /* their triangles, nearest first */           \
    X(__global, float, cam_near, cam_near)          /* per quad: its least distance to the eye */  \
    X(__global, VbMaterial, materials, materials)                                                  \
    X(__global, VbObject, objects, objects)                                                        \
    X(__global, VbLight, lights, lights)                                                           \
    X(__global, VbPattern, patterns, patterns)                                                     \
    X(__global, float, texels, texels) /* images, band tables, environment: 4 floats each */

#endif
