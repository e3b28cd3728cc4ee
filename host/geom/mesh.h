/* mesh.h — indexed triangle meshes on the host: storage, transforms, loaders, checks,
 * and the tessellated primitive shapes (the thesis's objects are all triangles). */
#ifndef VBCL_MESH_H
#define VBCL_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "vecmath.h"

typedef struct Mesh {
    vec3 *verts;    /* positions */
    vec3 *normals;  /* per-vertex shading normals, or NULL (flat shading) */
    uint32_t *tris; /* 3 vertex indices per triangle, counter-clockwise seen from outside */
    uint32_t nverts, ntris;
    uint32_t cap_verts, cap_tris;
} Mesh;

/* Sets an empty mesh. */
void mesh_init(Mesh *m);
/* Frees the arrays and leaves an empty mesh. */
void mesh_free(Mesh *m);
/* Appends a vertex (and, when the mesh has normals, a normal); returns its index,
 * or UINT32_MAX when out of memory. */
uint32_t mesh_add_vertex(Mesh *m, vec3 p);
/* Appends a triangle; returns 0, or -1 when out of memory. */
int mesh_add_triangle(Mesh *m, uint32_t a, uint32_t b, uint32_t c);
/* Gives the mesh a normal array (zeroed) if it has none; returns 0 or -1 (memory). */
int mesh_enable_normals(Mesh *m);
/* Appends all of src to dst (indices shifted); returns 0 or -1 (memory). */
int mesh_append(Mesh *dst, const Mesh *src);
/* Transforms positions (and normals, by the inverse transpose); a transform with a
 * negative determinant flips the triangle winding so normals stay outward. */
void mesh_transform(Mesh *m, const mat4 *xf);
/* Axis-aligned bounds of the vertices; an empty mesh gives lo > hi. */
void mesh_bounds(const Mesh *m, vec3 *lo, vec3 *hi);

#define MESH_MAX_FILE_BYTES ((uint64_t)1 << 30) /* as scene files: at most 1 GiB */

/* Loads a Wavefront OBJ or PLY (ASCII, binary little or big endian) file, chosen by
 * extension; polygons are fan-triangulated. The file must be a regular file (not a pipe
 * or device) of at most MESH_MAX_FILE_BYTES. Returns 0, or -1 with a one-line message in
 * err naming the file, the line (OBJ, ASCII PLY) or element, and what was expected. */
int mesh_load(const char *path, Mesh *out, char *err, size_t errlen);

/* mesh_load that also copies the file's first headlen - 1 bytes (its header, for the
 * comments texgen writes) into head, NUL-terminated: the file is read once. */
int mesh_load_head(const char *path, Mesh *out, char *head, size_t headlen, char *err,
                   size_t errlen);

/* Checks that the mesh bounds a volume: every edge is shared by exactly two triangles
 * that use it in opposite directions, and no triangle is degenerate in its indices.
 * Returns 0, or -1 with a message naming one offending edge (its two vertex positions). */
int mesh_check_closed(const Mesh *m, char *err, size_t errlen);

/* The first corner of triangle t of m, and in n its normal (edge 1 x edge 2, unnormalised,
 * in double precision from the float edges). */
vec3 mesh_tri_normal_d(const Mesh *m, uint32_t t, double n[3]);

/* qsort's comparison of two uint32_t. */
int mesh_cmp_u32(const void *a, const void *b);

/* Whether triangles first .. first + n - 1 of m bound a convex volume, tested edge by edge
 * in O(n log n): they form one closed surface of genus 0 (every edge, between vertex
 * indices, used by exactly two of them in opposite directions; connected; V - E + F = 2),
 * and at every edge the far corner of each triangle lies behind the other's plane by more
 * than tol (strictly convex edges, in double precision). A closed connected immersed
 * surface that is locally convex everywhere bounds a convex body (Hadamard), so every
 * vertex then lies behind every triangle's plane; convex edges make a vertex's cone convex
 * where its faces go round it once, which is assumed, not tested (docs/architecture.md,
 * "The shadow cone test"). Meshes with repeated vertex positions under other indices, flat edges
 * (coplanar neighbours) or degenerate triangles count as not convex. Returns 1 or 0 (also
 * when out of memory). */
int mesh_part_convex(const Mesh *m, uint32_t first, uint32_t n, double tol);

/* Triangles [first, first + ntris) of mesh: one object, or one element of a texture. */
typedef struct MeshPart {
    const Mesh *mesh;
    uint32_t first, ntris;
} MeshPart;

/* Whether the surfaces of two different parts meet, touching included (exact orientation
 * tests in double precision, coplanar triangles included; triangle bounding boxes swept
 * along z first). Returns 1 and the parts *pa < *pb with one triangle of each (*ta of
 * part *pa, *tb of *pb, counted within the part), 0 when they are disjoint, -1 when out
 * of memory. */
int mesh_parts_meet(const MeshPart *parts, int nparts, int *pa, int *pb, uint32_t *ta,
                    uint32_t *tb);

/* Tessellated primitives, centred at the origin, outward-oriented, appended to m.
 * Each returns 0, or -1 when out of memory. */
/* Unit-radius sphere: an icosahedron subdivided `level` times (0..7), smooth normals. */
int shape_sphere(Mesh *m, int level);
/* Box with edge lengths size (closed, 12 triangles, flat). */
int shape_box(Mesh *m, vec3 size);
/* Triangular prism: the triangle pts (x, y) extruded from z = -depth/2 to depth/2. */
int shape_prism(Mesh *m, const float pts[3][2], float depth);
/* Quad in the XZ plane of the given size, facing +Y (open: two triangles). */
int shape_quad(Mesh *m, float sx, float sz);
/* Surface of revolution about the Y axis of the profile (r_i, y_i), i < n, r >= 0, swept
 * in `segments` steps with smooth normals. Profile ends with r > 0 are closed by flat
 * caps when caps is non-zero, which makes the solid closed. */
int shape_revolution(Mesh *m, const float (*profile)[2], int n, int segments, int caps);

#endif
