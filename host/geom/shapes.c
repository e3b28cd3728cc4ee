/* shapes.c — tessellated primitives (sphere, box, prism, quad, surface of revolution) as
 * closed, outward-oriented triangle meshes. */
#include "mesh.h"

#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979323846f

/* Adds triangle (a, b, c), swapped to (a, c, b) when its normal points against `out`. */
static int add_tri_facing(Mesh *m, uint32_t a, uint32_t b, uint32_t c, vec3 out)
{
    vec3 n = v3_cross(v3_sub(m->verts[b], m->verts[a]), v3_sub(m->verts[c], m->verts[a]));
    return v3_dot(n, out) >= 0.0f ? mesh_add_triangle(m, a, b, c) : mesh_add_triangle(m, a, c, b);
}

/* Adds quad a-b-c-d (a cycle around its boundary) as two triangles facing `out`. */
static int add_quad_facing(Mesh *m, uint32_t a, uint32_t b, uint32_t c, uint32_t d, vec3 out)
{
    if (add_tri_facing(m, a, b, c, out) < 0) return -1;
    return add_tri_facing(m, a, c, d, out);
}

/* Appends the finished temporary mesh to m and frees it. */
static int finish(Mesh *m, Mesh *tmp, int rc)
{
    if (rc == 0) rc = mesh_append(m, tmp);
    mesh_free(tmp);
    return rc;
}

/* ---- sphere ---- */

/* Midpoint cache for one subdivision level: edge (min << 32 | max) + 1 -> vertex. */
typedef struct MidMap {
    uint64_t *keys;
    uint32_t *vals;
    size_t size;
} MidMap;

static uint32_t midpoint(Mesh *m, MidMap *mm, uint32_t a, uint32_t b)
{
    uint64_t key = (a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a) + 1;
    size_t h = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 20) & (mm->size - 1);
    while (mm->keys[h]) {
        if (mm->keys[h] == key) return mm->vals[h];
        h = (h + 1) & (mm->size - 1);
    }
    uint32_t v = mesh_add_vertex(m, v3_norm(v3_add(m->verts[a], m->verts[b])));
    if (v != UINT32_MAX) {
        mm->keys[h] = key;
        mm->vals[h] = v;
    }
    return v;
}

int shape_sphere(Mesh *m, int level)
{
    if (level < 0 || level > 7) return -1;
    static const float ico_v[12][3] = {
        {-1, 1.6180339887f, 0},  {1, 1.6180339887f, 0},   {-1, -1.6180339887f, 0},
        {1, -1.6180339887f, 0},  {0, -1, 1.6180339887f},  {0, 1, 1.6180339887f},
        {0, -1, -1.6180339887f}, {0, 1, -1.6180339887f},  {1.6180339887f, 0, -1},
        {1.6180339887f, 0, 1},   {-1.6180339887f, 0, -1}, {-1.6180339887f, 0, 1}};
    static const uint8_t ico_t[20][3] = {
        {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    Mesh cur, next;
    mesh_init(&cur);
    mesh_init(&next);
    int rc = 0;
    for (int i = 0; i < 12 && rc == 0; i++)
        if (mesh_add_vertex(&cur, v3_norm(v3(ico_v[i][0], ico_v[i][1], ico_v[i][2]))) == UINT32_MAX)
            rc = -1;
    for (int i = 0; i < 20 && rc == 0; i++)
        rc = mesh_add_triangle(&cur, ico_t[i][0], ico_t[i][1], ico_t[i][2]);
    for (int l = 0; l < level && rc == 0; l++) {
        /* vertices are kept; each triangle becomes four */
        MidMap mm = {NULL, NULL, 1};
        while (mm.size < (size_t)cur.ntris * 3) mm.size *= 2;
        mm.keys = calloc(mm.size, sizeof *mm.keys);
        mm.vals = malloc(mm.size * sizeof *mm.vals);
        mesh_init(&next);
        if (!mm.keys || !mm.vals || mesh_append(&next, &cur) < 0) rc = -1;
        next.ntris = 0;
        for (uint32_t t = 0; t < cur.ntris && rc == 0; t++) {
            const uint32_t *v = cur.tris + (size_t)t * 3;
            uint32_t ab = midpoint(&next, &mm, v[0], v[1]);
            uint32_t bc = midpoint(&next, &mm, v[1], v[2]);
            uint32_t ca = midpoint(&next, &mm, v[2], v[0]);
            if (ab == UINT32_MAX || bc == UINT32_MAX || ca == UINT32_MAX ||
                mesh_add_triangle(&next, v[0], ab, ca) < 0 ||
                mesh_add_triangle(&next, ab, v[1], bc) < 0 ||
                mesh_add_triangle(&next, ca, bc, v[2]) < 0 ||
                mesh_add_triangle(&next, ab, bc, ca) < 0)
                rc = -1;
        }
        free(mm.keys);
        free(mm.vals);
        mesh_free(&cur);
        cur = next;
        mesh_init(&next);
    }
    if (rc == 0) rc = mesh_enable_normals(&cur);
    if (rc == 0)
        for (uint32_t i = 0; i < cur.nverts; i++) cur.normals[i] = cur.verts[i];
    return finish(m, &cur, rc);
}

/* ---- box, prism, quad ---- */

int shape_box(Mesh *m, vec3 size)
{
    Mesh t;
    mesh_init(&t);
    vec3 h = v3_scale(size, 0.5f);
    int rc = 0;
    /* vertex i has x = bit 0, y = bit 1, z = bit 2 */
    for (int i = 0; i < 8 && rc == 0; i++)
        if (mesh_add_vertex(&t, v3(i & 1 ? h.x : -h.x, i & 2 ? h.y : -h.y, i & 4 ? h.z : -h.z)) ==
            UINT32_MAX)
            rc = -1;
    static const uint8_t faces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                        {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
    for (int f = 0; f < 6 && rc == 0; f++) {
        int axis = f / 2;
        float s = f % 2 ? 1.0f : -1.0f;
        vec3 out = v3(axis == 0 ? s : 0, axis == 1 ? s : 0, axis == 2 ? s : 0);
        rc = add_quad_facing(&t, faces[f][0], faces[f][1], faces[f][2], faces[f][3], out);
    }
    return finish(m, &t, rc);
}

int shape_prism(Mesh *m, const float pts[3][2], float depth)
{
    Mesh t;
    mesh_init(&t);
    float hz = depth * 0.5f;
    int rc = 0;
    for (int i = 0; i < 6 && rc == 0; i++)
        if (mesh_add_vertex(&t, v3(pts[i % 3][0], pts[i % 3][1], i < 3 ? -hz : hz)) == UINT32_MAX)
            rc = -1;
    /* the triangle's own orientation decides the cap winding */
    float area = (pts[1][0] - pts[0][0]) * (pts[2][1] - pts[0][1]) -
                 (pts[2][0] - pts[0][0]) * (pts[1][1] - pts[0][1]);
    uint32_t b = area >= 0.0f ? 1 : 2, c = 3 - b; /* (0, b, c) counter-clockwise from +z */
    if (rc == 0) rc = mesh_add_triangle(&t, 3, 3 + b, 3 + c);
    if (rc == 0) rc = mesh_add_triangle(&t, 0, c, b);
    /* sides: the quad over edge i -> j of the counter-clockwise triangle */
    uint32_t ccw[3] = {0, b, c};
    for (int k = 0; k < 3 && rc == 0; k++) {
        uint32_t i = ccw[k], j = ccw[(k + 1) % 3];
        rc = mesh_add_triangle(&t, i, j, j + 3);
        if (rc == 0) rc = mesh_add_triangle(&t, i, j + 3, i + 3);
    }
    return finish(m, &t, rc);
}

int shape_quad(Mesh *m, float sx, float sz)
{
    Mesh t;
    mesh_init(&t);
    float hx = sx * 0.5f, hz = sz * 0.5f;
    int rc = 0;
    for (int i = 0; i < 4 && rc == 0; i++)
        if (mesh_add_vertex(&t, v3(i == 1 || i == 2 ? hx : -hx, 0, i >= 2 ? hz : -hz)) ==
            UINT32_MAX)
            rc = -1;
    /* corners go round: (-,-), (+,-), (+,+), (-,+); (0, 2, 1) faces +y */
    if (rc == 0) rc = mesh_add_triangle(&t, 0, 2, 1);
    if (rc == 0) rc = mesh_add_triangle(&t, 0, 3, 2);
    return finish(m, &t, rc);
}

/* ---- surface of revolution ---- */

/* A ring of `segments` vertices around the axis at one profile point, or a single pole
 * vertex when r == 0. */
typedef struct Ring {
    uint32_t base;
    int pole;
} Ring;

static int ring_add(Mesh *m, float r, float y, vec3 n2, int segments, Ring *ring)
{
    /* n2 holds the 2D profile normal as (nr, ny, unused) */
    ring->pole = r == 0.0f;
    ring->base = m->nverts;
    int count = ring->pole ? 1 : segments;
    for (int s = 0; s < count; s++) {
        float phi = 2.0f * PI_F * (float)s / (float)segments, c = cosf(phi), sn = sinf(phi);
        if (s == 0) c = 1.0f, sn = 0.0f;
        vec3 p = v3(r * c, y, r * sn);
        vec3 n = ring->pole ? v3(0, n2.y >= 0.0f ? 1.0f : -1.0f, 0) : v3(n2.x * c, n2.y, n2.x * sn);
        uint32_t v = mesh_add_vertex(m, p);
        if (v == UINT32_MAX) return -1;
        m->normals[v] = v3_norm(n);
    }
    return 0;
}

/* Joins ring a (earlier along the closed profile polygon) to ring b; flip is set when the
 * polygon runs counter-clockwise in the (r, y) plane. */
static int ring_join(Mesh *m, Ring a, Ring b, int segments, int flip)
{
    if (a.pole && b.pole) return 0;
    for (int s = 0; s < segments; s++) {
        uint32_t s1 = (uint32_t)((s + 1) % segments), s0 = (uint32_t)s;
        uint32_t a0 = a.base + (a.pole ? 0 : s0), a1 = a.base + (a.pole ? 0 : s1);
        uint32_t b0 = b.base + (b.pole ? 0 : s0), b1 = b.base + (b.pole ? 0 : s1);
        /* unflipped, (a0, a1, b1) faces along (-dy, dr) of the profile step (dr, dy) */
        if (!a.pole && mesh_add_triangle(m, a0, flip ? b1 : a1, flip ? a1 : b1) < 0) return -1;
        if (!b.pole && mesh_add_triangle(m, a0, flip ? b0 : b1, flip ? b1 : b0) < 0) return -1;
    }
    return 0;
}

/* Outward 2D normal (as vec3 (nr, ny, 0)) of the profile step from (r0, y0) to (r1, y1);
 * zero for a step of zero length. */
static vec3 step_normal(float r0, float y0, float r1, float y1, float orient)
{
    return v3_norm(v3(orient * (y1 - y0), orient * (r0 - r1), 0));
}

/* Point k of the closed profile polygon: the n profile points, then (0, y_last) and
 * (0, y_first) on the axis. */
static void polygon_point(const float (*profile)[2], int n, int k, double *r, double *y)
{
    *r = k < n ? profile[k][0] : 0.0;
    *y = profile[k < n ? k : k == n ? n - 1 : 0][1];
}

int shape_revolution(Mesh *m, const float (*profile)[2], int n, int segments, int caps)
{
    if (n < 2 || segments < 3) return -1;
    for (int i = 0; i < n; i++)
        if (!(profile[i][0] >= 0.0f) || !isfinite(profile[i][0]) || !isfinite(profile[i][1]))
            return -1;
    /* orientation of the closed profile polygon: the points, then back along the axis */
    double area = 0.0;
    for (int k = 0; k < n + 2; k++) {
        double r0, y0, r1, y1;
        polygon_point(profile, n, k, &r0, &y0);
        polygon_point(profile, n, (k + 1) % (n + 2), &r1, &y1);
        area += r0 * y1 - r1 * y0;
    }
    float orient = area >= 0.0 ? 1.0f : -1.0f;
    int flip = area >= 0.0;

    /* normals of the profile steps; a step of zero length has a zero normal */
    vec3 *sn = malloc((size_t)n * sizeof *sn);
    Ring *in = malloc((size_t)n * sizeof *in), *out = malloc((size_t)n * sizeof *out);
    Mesh t;
    mesh_init(&t);
    int rc = sn && in && out ? mesh_enable_normals(&t) : -1;
    for (int i = 0; i + 1 < n && rc == 0; i++)
        sn[i] =
            step_normal(profile[i][0], profile[i][1], profile[i + 1][0], profile[i + 1][1], orient);
    /* rings at each point: shared when the surface is smooth there (normals within 60
     * degrees), else one per side so the crease stays sharp */
    for (int i = 0; i < n && rc == 0; i++) {
        float r = profile[i][0], y = profile[i][1];
        vec3 nin = i > 0 ? sn[i - 1] : v3(0, 0, 0), nout = i + 1 < n ? sn[i] : v3(0, 0, 0);
        int has_in = v3_dot(nin, nin) > 0.0f, has_out = v3_dot(nout, nout) > 0.0f;
        int smooth = has_in && has_out && v3_dot(nin, nout) >= 0.5f;
        if (r == 0.0f) smooth = has_in && has_out && (nin.y >= 0.0f) == (nout.y >= 0.0f);
        if (smooth) {
            rc = ring_add(&t, r, y, v3_norm(v3_add(nin, nout)), segments, &in[i]);
            out[i] = in[i];
        } else {
            if (has_in) rc = ring_add(&t, r, y, nin, segments, &in[i]);
            if (has_out && rc == 0) rc = ring_add(&t, r, y, nout, segments, &out[i]);
        }
    }
    for (int i = 0; i + 1 < n && rc == 0; i++)
        if (v3_dot(sn[i], sn[i]) > 0.0f) rc = ring_join(&t, out[i], in[i + 1], segments, flip);
    /* flat caps: the polygon's steps along the axis ends, with their own rings */
    for (int end = 0; end < 2 && caps && rc == 0; end++) {
        int i = end ? n - 1 : 0;
        float r = profile[i][0], y = profile[i][1];
        if (r == 0.0f) continue;
        vec3 cn = end ? step_normal(r, y, 0, y, orient) : step_normal(0, y, r, y, orient);
        Ring centre, rim;
        rc = ring_add(&t, 0, y, cn, segments, &centre);
        if (rc == 0) rc = ring_add(&t, r, y, cn, segments, &rim);
        if (rc == 0)
            rc = end ? ring_join(&t, rim, centre, segments, flip)
                     : ring_join(&t, centre, rim, segments, flip);
    }
    free(sn);
    free(in);
    free(out);
    return finish(m, &t, rc);
}
