/* test_objects.c — the object analysis (host/compiled/objects.c) on small scenes, without an
 * OpenCL device: convexity and hulls, planes, bounds, texture parts, the parts' ahead bits,
 * solid parts' cores and hosts' inner spheres. Every expectation is computed here from the
 * scene's vertices, not taken from the records. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "objects.h"
#include "scene.h"
#include "testutil.h"

/* A camera 20 units from the origin (the scene's frame is the file's own), an opaque
 * material m, an opaque texture material stone used by no object, and two dielectrics. */
#define OBJECTS_SCENE_HEAD                                                                         \
    "{\"camera\": {\"eye\": [0, 0, 20], \"look_at\": [0, 0, 0]},\n"                                \
    " \"materials\": {\"m\": {}, \"stone\": {\"diffuse\": [0.5, 0.4, 0.3]},\n"                     \
    "  \"glass\": {\"k_global\": 0.9, \"eta\": 1.5}, \"clear\": {\"k_global\": 0.5, \"eta\": "     \
    "1.2}},\n"

/* A texture whose block [-1, 1]^3 maps onto a host box of [-1, 1]^3 unchanged. */
#define IDENTITY_BLOCK "\"block\": [-1, -1, -1, 1, 1, 1]"

/* ---- OBJ text built piece by piece ---- */

typedef struct Obj {
    char *text;
    size_t len, cap;
    int nv; /* vertices written so far: the next is nv + 1 */
} Obj;

static void obj_add(Obj *o, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void obj_add(Obj *o, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0) return;
    if (o->len + (size_t)n + 1 > o->cap) {
        size_t cap = 2 * (o->len + (size_t)n + 1);
        char *t = realloc(o->text, cap);
        if (!t) return;
        o->text = t;
        o->cap = cap;
    }
    va_start(ap, fmt);
    vsnprintf(o->text + o->len, o->cap - o->len, fmt, ap);
    va_end(ap);
    o->len += (size_t)n;
}

/* The six corners of an octahedron of centre c and radius r (c +- r along each axis); the
 * index of the first, +x (then -x, +y, -y, +z, -z). */
static int obj_octahedron_corners(Obj *o, double cx, double cy, double cz, double r)
{
    int b = o->nv + 1;
    obj_add(o, "v %.9g %.9g %.9g\nv %.9g %.9g %.9g\n", cx + r, cy, cz, cx - r, cy, cz);
    obj_add(o, "v %.9g %.9g %.9g\nv %.9g %.9g %.9g\n", cx, cy + r, cz, cx, cy - r, cz);
    obj_add(o, "v %.9g %.9g %.9g\nv %.9g %.9g %.9g\n", cx, cy, cz + r, cx, cy, cz - r);
    o->nv += 6;
    return b;
}

/* Face s (0 .. 7: bit k set, the minus side of axis k) of the octahedron whose corners
 * start at b, outward. */
static void obj_octahedron_face(Obj *o, int b, int s)
{
    int x = b + (s & 1), y = b + 2 + (s >> 1 & 1), z = b + 4 + (s >> 2 & 1);
    if ((s & 1) ^ (s >> 1 & 1) ^ (s >> 2 & 1)) /* an odd number of minus sides: mirrored */
        obj_add(o, "f %d %d %d\n", x, z, y);
    else
        obj_add(o, "f %d %d %d\n", x, y, z);
}

/* An octahedron of centre c and radius r, outward. */
static void obj_octahedron(Obj *o, double cx, double cy, double cz, double r)
{
    int b = obj_octahedron_corners(o, cx, cy, cz, r);
    for (int s = 0; s < 8; s++) obj_octahedron_face(o, b, s);
}

/* An axis-aligned box [lo, hi], outward, its faces as quads (two triangles each). */
static void obj_box(Obj *o, const double lo[3], const double hi[3])
{
    int b = o->nv + 1; /* corner (i, j, k) of x, y, z is b + i + 2j + 4k */
    for (int c = 0; c < 8; c++)
        obj_add(o, "v %.9g %.9g %.9g\n", c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1],
                c & 4 ? hi[2] : lo[2]);
    o->nv += 8;
    static const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                    {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (int f = 0; f < 6; f++)
        obj_add(o, "f %d %d %d %d\n", b + faces[f][0], b + faces[f][1], b + faces[f][2],
                b + faces[f][3]);
}

/* An L-shaped prism, outward: the polygon (0,0) (2,0) (2,1) (1,1) (1,2) (0,2) scaled by s,
 * from z = -s/4 to s/4, moved by (x, y, z). Not convex: (1,1) is a reflex corner. */
static void obj_ell(Obj *o, double x, double y, double z, double s)
{
    static const double poly[6][2] = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
    int b = o->nv + 1; /* corner i at the bottom is b + i, at the top b + 6 + i */
    for (int top = 0; top < 2; top++)
        for (int i = 0; i < 6; i++)
            obj_add(o, "v %.9g %.9g %.9g\n", x + s * poly[i][0], y + s * poly[i][1],
                    z + (top ? s : -s) / 4);
    o->nv += 12;
    /* the caps fanned from corner 0, which sees every other corner */
    obj_add(o, "f %d %d %d %d %d %d\n", b + 6, b + 7, b + 8, b + 9, b + 10, b + 11);
    obj_add(o, "f %d %d %d %d %d %d\n", b, b + 5, b + 4, b + 3, b + 2, b + 1);
    for (int i = 0; i < 6; i++) {
        int j = (i + 1) % 6;
        obj_add(o, "f %d %d %d %d\n", b + i, b + j, b + 6 + j, b + 6 + i);
    }
}

/* Writes o to the test directory as name and frees its text. */
static void obj_write(Obj *o, const char *name)
{
    tu_write_file(name, o->text ? o->text : "");
    free(o->text);
    memset(o, 0, sizeof *o);
}

/* ---- geometry, in double precision from the float vertices ---- */

static vec3 corner(const Mesh *m, uint32_t t, int k)
{
    return m->verts[m->tris[3 * t + k]];
}

/* The unit normal n and offset k (n.x = k) of triangle t's plane; 0 where it is degenerate. */
static int tri_plane(const Mesh *m, uint32_t t, double n[3], double *k)
{
    vec3 a = corner(m, t, 0), b = corner(m, t, 1), c = corner(m, t, 2);
    double e[3] = {(double)b.x - a.x, (double)b.y - a.y, (double)b.z - a.z};
    double f[3] = {(double)c.x - a.x, (double)c.y - a.y, (double)c.z - a.z};
    n[0] = e[1] * f[2] - e[2] * f[1];
    n[1] = e[2] * f[0] - e[0] * f[2];
    n[2] = e[0] * f[1] - e[1] * f[0];
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0.0)) return 0;
    for (int a2 = 0; a2 < 3; a2++) n[a2] /= len;
    *k = n[0] * a.x + n[1] * a.y + n[2] * a.z;
    return 1;
}

static double height(const double n[3], double k, double x, double y, double z)
{
    return n[0] * x + n[1] * y + n[2] * z - k;
}

/* The greatest height of a vertex of triangles vf .. vf + vn - 1 above the plane of
 * triangle t (negative: every one lies behind it). */
static double max_height_one(const Mesh *m, uint32_t t, uint32_t vf, uint32_t vn)
{
    double n[3], k, worst = -INFINITY;
    if (!tri_plane(m, t, n, &k)) return INFINITY;
    for (uint32_t u = vf; u < vf + vn; u++)
        for (int j = 0; j < 3; j++) {
            vec3 v = corner(m, u, j);
            worst = fmax(worst, height(n, k, v.x, v.y, v.z));
        }
    return worst;
}

/* The same over the planes of triangles first .. first + n - 1: at most 0 (within rounding)
 * where every vertex lies behind or on every plane. */
static double max_height(const Mesh *m, uint32_t first, uint32_t n, uint32_t vf, uint32_t vn)
{
    double worst = -INFINITY;
    for (uint32_t t = first; t < first + n; t++) worst = fmax(worst, max_height_one(m, t, vf, vn));
    return worst;
}

/* The bounding box of the vertices of triangles first .. first + n - 1, grown into lo, hi. */
static void tri_box(const Mesh *m, uint32_t first, uint32_t n, double lo[3], double hi[3])
{
    for (uint32_t t = first; t < first + n; t++)
        for (int j = 0; j < 3; j++) {
            vec3 v = corner(m, t, j);
            const double c[3] = {v.x, v.y, v.z};
            for (int a = 0; a < 3; a++) {
                lo[a] = fmin(lo[a], c[a]);
                hi[a] = fmax(hi[a], c[a]);
            }
        }
}

static double dist3(const double a[3], vec3 v)
{
    double d[3] = {v.x - a[0], v.y - a[1], v.z - a[2]};
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

/* ---- scenes ---- */

/* Writes json as name in the test directory, loads it and analyses it: 0 with *s loaded
 * and *rec (n records) allocated, -1 (a failed check) otherwise. */
static int load_objects(const char *name, const char *json, Scene *s, VbObject **rec, size_t *n)
{
    char err[1024] = "";
    int rc = scene_load(tu_write_file(name, json), s, err, sizeof err);
    CHECK(rc == 0, "%s loads: %s", name, err);
    if (rc) return -1;
    *rec = objects_make(s, n);
    CHECK(*rec != NULL, "objects_make gives records for %s", name);
    if (!*rec) {
        scene_free(s);
        return -1;
    }
    return 0;
}

static int has(const VbObject *g, unsigned flag)
{
    return (g->flags & flag) != 0;
}

/* The size of an object for tolerances: the largest coordinate of its box plus its half
 * diagonal, as both the own and the texture's triangles give it. */
static double object_size(const Mesh *m, const SceneObject *o)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    tri_box(m, o->first_tri, o->ntris, lo, hi);
    tri_box(m, o->first_tex_tri, o->ntex_tris, lo, hi);
    double mag = 0.0, d2 = 0.0;
    for (int a = 0; a < 3; a++) {
        mag = fmax(mag, fmax(fabs(lo[a]), fabs(hi[a])));
        d2 += (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    return mag + 0.5 * sqrt(d2);
}

/* ---- convexity and hulls ---- */

/* A textured glass box (its texture, two octahedra, inside it), a textured glass L-shaped
 * prism, an opaque box, an opaque L-shaped prism and a glass box whose texture reaches out
 * of it: VBCL_OBJECT_CONVEX exactly where every vertex of the object and its texture lies
 * behind (or within 1e-6 of the size of) every plane of its own triangles (the first and the
 * opaque box), VBCL_OBJECT_HULL exactly on the hosts with parts whose own triangles alone are
 * convex so (both textured boxes, not the L); the L host's parts keep every ahead bit. */
static void test_objects_hulls(void)
{
    Obj tex = {0}, out = {0}, ell = {0};
    obj_octahedron(&tex, -0.4, 0, 0, 0.3);
    obj_octahedron(&tex, 0.4, 0, 0, 0.3);
    obj_write(&tex, "hull_tex.obj");
    obj_octahedron(&out, 0.9, 0, 0, 0.3);
    obj_write(&out, "hull_out_tex.obj");
    obj_ell(&ell, 0, 0, 0, 1.0);
    obj_write(&ell, "ell.obj");
    const char *json = OBJECTS_SCENE_HEAD
        " \"objects\": [\n"
        "  {\"shape\": \"box\", \"size\": [2, 2, 2], \"material\": \"glass\",\n"
        "   \"transform\": {\"translate\": [-4, 0, 0]},\n"
        "   \"texture\": {\"file\": \"hull_tex.obj\", \"material\": \"stone\", " IDENTITY_BLOCK
        "}},\n"
        "  {\"shape\": \"mesh\", \"file\": \"ell.obj\", \"material\": \"glass\",\n"
        "   \"transform\": {\"translate\": [3, 0, 0]},\n"
        "   \"texture\": {\"file\": \"hull_tex.obj\", \"material\": \"stone\", " IDENTITY_BLOCK
        "}},\n"
        "  {\"shape\": \"box\", \"material\": \"m\", \"transform\": {\"translate\": [0, 4, 0]}},\n"
        "  {\"shape\": \"mesh\", \"file\": \"ell.obj\", \"material\": \"m\",\n"
        "   \"transform\": {\"translate\": [0, -5, 0]}},\n"
        "  {\"shape\": \"box\", \"size\": [2, 2, 2], \"material\": \"glass\",\n"
        "   \"transform\": {\"translate\": [0, 0, -6]},\n"
        "   \"texture\": {\"file\": \"hull_out_tex.obj\", \"material\": \"stone\", " IDENTITY_BLOCK
        "}}]}";
    Scene s;
    VbObject *rec;
    size_t n;
    if (load_objects("hulls.json", json, &s, &rec, &n)) return;
    const Mesh *m = &s.mesh;
    for (int i = 0; i < s.nobjects; i++) {
        const SceneObject *o = &s.objects[i];
        double eps = 1e-6 * object_size(m, o);
        double own = max_height(m, o->first_tri, o->ntris, o->first_tri, o->ntris);
        double all =
            fmax(own, max_height(m, o->first_tri, o->ntris, o->first_tex_tri, o->ntex_tris));
        int hull = o->is_host && rec[i].nelems > 0 && own <= eps;
        fprintf(stderr,
                "    %s: %u triangles, texture %u, highest vertex %.3g above an own plane\n",
                o->name, o->ntris, o->ntex_tris, all);
        CHECK(has(&rec[i], VBCL_OBJECT_CONVEX) == (all <= eps),
              "%s: CONVEX %d, a vertex %.3g above a plane", o->name,
              has(&rec[i], VBCL_OBJECT_CONVEX), all);
        CHECK(has(&rec[i], VBCL_OBJECT_HULL) == hull, "%s: HULL %d, expected %d", o->name,
              has(&rec[i], VBCL_OBJECT_HULL), hull);
    }
    /* the fixture itself: what the rules must say of these five */
    CHECK(has(&rec[0], VBCL_OBJECT_HULL) && has(&rec[0], VBCL_OBJECT_CONVEX),
          "the textured box is a hull and convex");
    CHECK(!has(&rec[1], VBCL_OBJECT_HULL) && !has(&rec[1], VBCL_OBJECT_CONVEX),
          "the textured L is neither a hull nor convex");
    CHECK(has(&rec[2], VBCL_OBJECT_CONVEX) && !has(&rec[3], VBCL_OBJECT_CONVEX),
          "the opaque box is convex, the opaque L not");
    CHECK(has(&rec[4], VBCL_OBJECT_HULL) && !has(&rec[4], VBCL_OBJECT_CONVEX),
          "the box whose texture reaches out is a hull, not convex");
    CHECK(rec[1].nelems == 2, "the L's texture has two parts (%u)", rec[1].nelems);
    for (unsigned e = 0; e < rec[1].nelems; e++)
        CHECK(rec[rec[1].first_elem + e].ahead == ~0u,
              "a part of a host that is no hull keeps every ahead bit (part %u: %#x)", e,
              rec[rec[1].first_elem + e].ahead);
    free(rec);
    scene_free(&s);
}

/* ---- planes ---- */

/* A quad of 2 x 3 turned by (30, 0, 20) degrees and moved to (1, 2, 3), and a box: the quad
 * is VBCL_OBJECT_PLANAR with a unit normal that is its triangles' (the rotated +y axis,
 * (-cos 30 sin 20, cos 30 cos 20, sin 30)) and the offset n.(1, 2, 3) of its centre, every
 * vertex within plane_eps of the plane and plane_eps at most 1e-4 of the quad's size; the
 * box is not planar. */
static void test_objects_planes(void)
{
    const char *json = OBJECTS_SCENE_HEAD
        " \"objects\": [\n"
        "  {\"shape\": \"quad\", \"size\": [2, 3], \"material\": \"m\",\n"
        "   \"transform\": {\"rotate\": [30, 0, 20], \"translate\": [1, 2, 3]}},\n"
        "  {\"shape\": \"box\", \"size\": [1, 2, 3], \"material\": \"m\",\n"
        "   \"transform\": {\"translate\": [-4, 0, 0]}}]}";
    Scene s;
    VbObject *rec;
    size_t n;
    if (load_objects("planes.json", json, &s, &rec, &n)) return;
    const Mesh *m = &s.mesh;
    const SceneObject *q = &s.objects[0];
    const VbObject *g = &rec[0];
    const double a = 30 * PI_D / 180, c = 20 * PI_D / 180;
    const double want[3] = {-cos(a) * sin(c), cos(a) * cos(c), sin(a)};
    const double want_k = want[0] * 1 + want[1] * 2 + want[2] * 3;
    double tn[3], tk, len = 0.0, dot = 0.0, dev = 0.0;
    CHECK(tri_plane(m, q->first_tri, tn, &tk), "the quad's first triangle has a plane");
    for (int k = 0; k < 3; k++) {
        len += (double)g->plane[k] * g->plane[k];
        dot += g->plane[k] * tn[k];
    }
    for (uint32_t t = q->first_tri; t < q->first_tri + q->ntris; t++)
        for (int j = 0; j < 3; j++) {
            vec3 v = corner(m, t, j);
            dev = fmax(dev, fabs(g->plane[0] * v.x + g->plane[1] * v.y + g->plane[2] * v.z -
                                 (double)g->plane[3]));
        }
    fprintf(stderr,
            "    quad: n (%.7f %.7f %.7f), k %.7f (expected %.7f), plane_eps %.3g, largest "
            "vertex distance %.3g\n",
            g->plane[0], g->plane[1], g->plane[2], g->plane[3], want_k, g->plane_eps, dev);
    CHECK(has(g, VBCL_OBJECT_PLANAR), "the quad is planar (flags %#x)", g->flags);
    CHECK(fabs(sqrt(len) - 1.0) < 1e-6, "the plane's normal is a unit vector (%.9f)", sqrt(len));
    CHECK(dot > 1.0 - 1e-6, "the normal is the triangles' (dot %.9f)", dot);
    for (int k = 0; k < 3; k++)
        CHECK(fabs(g->plane[k] - want[k]) < 1e-5, "normal[%d] %.7f, rotated +y %.7f", k,
              g->plane[k], want[k]);
    CHECK(fabs(g->plane[3] - want_k) < 1e-5 && fabs(g->plane[3] - tk) < 1e-5,
          "offset %.7f: n.(1, 2, 3) is %.7f, the triangle's %.7f", g->plane[3], want_k, tk);
    CHECK(dev <= g->plane_eps, "every vertex within plane_eps %.3g of the plane (%.3g)",
          g->plane_eps, dev);
    CHECK(g->plane_eps > 0.0f && g->plane_eps <= 1e-4 * 3.0, "plane_eps %.3g is small",
          g->plane_eps);
    CHECK(!has(&rec[1], VBCL_OBJECT_PLANAR), "the box is not planar (flags %#x)", rec[1].flags);
    free(rec);
    scene_free(&s);
}

/* ---- bounds ---- */

/* Checks that the sphere sph (and record box's lo, hi, where box is not NULL) holds every
 * vertex of triangles first .. first + n - 1 and of tf .. tf + tn - 1 and is tight: the
 * radius at most 1e-4 of the size above half the diagonal of their exact box, the box within
 * 1e-4 of the size of it. Returns the largest vertex distance from the sphere's centre. */
static double check_holds(const Mesh *m, const char *what, const float sph[4], const VbObject *box,
                          uint32_t first, uint32_t n, uint32_t tf, uint32_t tn)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    tri_box(m, first, n, lo, hi);
    tri_box(m, tf, tn, lo, hi);
    const double c[3] = {sph[0], sph[1], sph[2]};
    double far = 0.0, diag = 0.0, mag = 0.0;
    int out_box = 0;
    for (uint32_t t = 0; t < n + tn; t++)
        for (int j = 0; j < 3; j++) {
            vec3 v = corner(m, t < n ? first + t : tf + (t - n), j);
            far = fmax(far, dist3(c, v));
            if (box)
                out_box += v.x < box->lo[0] || v.y < box->lo[1] || v.z < box->lo[2] ||
                           v.x > box->hi[0] || v.y > box->hi[1] || v.z > box->hi[2];
        }
    for (int a = 0; a < 3; a++) {
        diag += (hi[a] - lo[a]) * (hi[a] - lo[a]);
        mag = fmax(mag, fmax(fabs(lo[a]), fabs(hi[a])));
    }
    double size = mag + 0.5 * sqrt(diag);
    CHECK(far <= sph[3], "%s: a vertex %.9g from the centre, radius %.9g", what, far, sph[3]);
    CHECK(sph[3] <= 0.5 * sqrt(diag) + 1e-4 * size, "%s: radius %.9g, half diagonal %.9g", what,
          sph[3], 0.5 * sqrt(diag));
    if (!box) return far;
    CHECK(out_box == 0, "%s: %d vertices outside the box", what, out_box);
    for (int a = 0; a < 3; a++)
        CHECK(lo[a] - box->lo[a] <= 1e-4 * size && box->hi[a] - hi[a] <= 1e-4 * size,
              "%s: box [%.9g, %.9g] along %d, the vertices' [%.9g, %.9g]", what, box->lo[a],
              box->hi[a], a, lo[a], hi[a]);
    return far;
}

/* A glass box [-1, 1]^3 whose texture holds an octahedron inside it and a box x in [1.5,
 * 1.9] beside it (a texture may reach out of its host), and an opaque sphere without a
 * texture: each record's bound sphere and box hold its own and its texture's vertices, and
 * so do each part's; the own sphere holds the box's own vertices and leaves the far texture
 * box out; the sphere's own sphere is its bound sphere. */
static void test_objects_bounds(void)
{
    Obj tex = {0};
    obj_octahedron(&tex, 0, 0, 0, 0.5);
    obj_box(&tex, (const double[3]){1.5, -0.2, -0.2}, (const double[3]){1.9, 0.2, 0.2});
    obj_write(&tex, "reach_tex.obj");
    const char *json = OBJECTS_SCENE_HEAD
        " \"objects\": [\n"
        "  {\"shape\": \"box\", \"size\": [2, 2, 2], \"material\": \"glass\",\n"
        "   \"texture\": {\"file\": \"reach_tex.obj\", \"material\": \"stone\", " IDENTITY_BLOCK
        "}},\n"
        "  {\"shape\": \"sphere\", \"level\": 1, \"radius\": 0.5, \"centre\": [0, 3, 0], "
        "\"material\": \"m\"}]}";
    Scene s;
    VbObject *rec;
    size_t n;
    if (load_objects("bounds.json", json, &s, &rec, &n)) return;
    const Mesh *m = &s.mesh;
    for (int i = 0; i < s.nobjects; i++) {
        const SceneObject *o = &s.objects[i];
        const VbObject *g = &rec[i];
        char what[96];
        snprintf(what, sizeof what, "%s bound", o->name);
        double far = check_holds(m, what, g->bound, g, o->first_tri, o->ntris, o->first_tex_tri,
                                 o->ntex_tris);
        snprintf(what, sizeof what, "%s own", o->name);
        double own = check_holds(m, what, g->own, NULL, o->first_tri, o->ntris, 0, 0);
        fprintf(stderr, "    %s: bound radius %.7f (farthest vertex %.7f), own %.7f (%.7f)\n",
                o->name, g->bound[3], far, g->own[3], own);
        for (unsigned e = 0; e < g->nelems; e++) {
            const VbObject *p = &rec[g->first_elem + e];
            snprintf(what, sizeof what, "%s part %u", o->name, e);
            check_holds(m, what, p->bound, p, p->first_tri, p->ntris, 0, 0);
        }
    }
    /* the texture's far box, x = 1.9, reaches beyond the host's own sphere */
    const double oc[3] = {rec[0].own[0], rec[0].own[1], rec[0].own[2]};
    CHECK(dist3(oc, v3(1.9f, 0.2f, 0.2f)) > rec[0].own[3],
          "the own sphere (radius %.7f) leaves out the texture reaching to x = 1.9", rec[0].own[3]);
    CHECK(rec[0].nelems == 2, "the texture has two parts (%u)", rec[0].nelems);
    CHECK(memcmp(rec[1].own, rec[1].bound, sizeof rec[1].own) == 0,
          "without a texture the own sphere is the bound sphere");
    free(rec);
    scene_free(&s);
}

/* ---- texture parts ---- */

/* The connected pieces of triangles first .. first + n - 1 (triangles that share a vertex
 * index): label[t - first] is the least vertex index of triangle t's piece. */
static void piece_labels(const Mesh *m, uint32_t first, uint32_t n, uint32_t *label)
{
    uint32_t *vl = malloc(sizeof *vl * (m->nverts ? m->nverts : 1));
    if (!vl) {
        memset(label, 0, sizeof *label * n);
        return;
    }
    for (uint32_t v = 0; v < m->nverts; v++) vl[v] = v;
    for (int changed = 1; changed;) { /* each triangle's corners take their least label */
        changed = 0;
        for (uint32_t t = first; t < first + n; t++) {
            const uint32_t *c = &m->tris[3 * t];
            uint32_t least = vl[c[0]] < vl[c[1]] ? vl[c[0]] : vl[c[1]];
            least = least < vl[c[2]] ? least : vl[c[2]];
            for (int j = 0; j < 3; j++) {
                changed |= vl[c[j]] != least;
                vl[c[j]] = least;
            }
        }
    }
    for (uint32_t t = 0; t < n; t++) label[t] = vl[m->tris[3 * (first + t)]];
    free(vl);
}

/* Checks textured object i's part records against the runs of its texture's pieces (a new
 * run wherever the next triangle is of another piece; none beyond
 * VBCL_CONE_TEST_MAX_ELEMENTS runs); returns the number of runs. */
static int check_parts(const Scene *s, const VbObject *rec, int i)
{
    const SceneObject *o = &s->objects[i];
    const VbObject *g = &rec[i];
    uint32_t *label = malloc(sizeof *label * (o->ntex_tris ? o->ntex_tris : 1));
    if (!label) return -1;
    piece_labels(&s->mesh, o->first_tex_tri, o->ntex_tris, label);
    int runs = 0;
    for (uint32_t t = 0; t < o->ntex_tris; t++) runs += t == 0 || label[t] != label[t - 1];
    unsigned want = runs <= VBCL_CONE_TEST_MAX_ELEMENTS ? (unsigned)runs : 0u;
    CHECK(g->nelems == want, "%s: %u parts, %d runs of pieces", o->name, g->nelems, runs);
    uint32_t next = o->first_tex_tri; /* where the next part must start */
    for (unsigned e = 0; e < g->nelems && e < want; e++) {
        const VbObject *p = &rec[g->first_elem + e];
        uint32_t a = p->first_tri - o->first_tex_tri, z = a + p->ntris; /* within the texture */
        CHECK(p->host == (unsigned)i, "%s part %u: host %u", o->name, e, p->host);
        CHECK(p->first_tri == next && p->ntris > 0 && z <= o->ntex_tris,
              "%s part %u: triangles %u + %u, expected from %u within %u + %u", o->name, e,
              p->first_tri, p->ntris, next, o->first_tex_tri, o->ntex_tris);
        if (p->first_tri != next || p->ntris == 0 || z > o->ntex_tris) break;
        for (uint32_t t = a + 1; t < z; t++)
            CHECK(label[t] == label[a], "%s part %u: triangle %u of another piece", o->name, e,
                  p->first_tri + (t - a));
        CHECK(z == o->ntex_tris || label[z] != label[z - 1],
              "%s part %u ends before a triangle of its own piece", o->name, e);
        next = p->first_tri + p->ntris;
    }
    if (want > 0)
        CHECK(next == o->first_tex_tri + o->ntex_tris, "%s: the parts cover the texture once",
              o->name);
    free(label);
    return runs;
}

/* Four glass hosts and an opaque box: a box with a texture of 5 octahedra, a sphere with 4
 * bombed spheres (`bomb --count 4 --no-overlap`), a box with two octahedra whose faces
 * alternate in the file (16 runs), and a box with 65 octahedra (more than
 * VBCL_CONE_TEST_MAX_ELEMENTS: bounded as a whole, no parts). Each part record belongs to
 * its host and holds one run of one piece, the runs in order; the parts of a texture cover
 * it exactly once; the records follow the scene's objects, texture after texture. */
static void test_objects_texture_parts(void)
{
    Obj five = {0}, mixed = {0}, many = {0};
    for (int k = 0; k < 5; k++) obj_octahedron(&five, -0.6 + 0.3 * k, 0, 0, 0.12);
    int a = obj_octahedron_corners(&mixed, -0.4, 0, 0, 0.3),
        b = obj_octahedron_corners(&mixed, 0.4, 0, 0, 0.3);
    for (int f = 0; f < 8; f++) {
        obj_octahedron_face(&mixed, a, f);
        obj_octahedron_face(&mixed, b, f);
    }
    for (int k = 0; k < VBCL_CONE_TEST_MAX_ELEMENTS + 1; k++)
        obj_octahedron(&many, -0.84 + 0.14 * (k % 13), -0.56 + 0.28 * (k / 13), 0, 0.05);
    obj_write(&five, "five_tex.obj");
    obj_write(&mixed, "mixed_tex.obj");
    obj_write(&many, "many_tex.obj");
    const char *json = OBJECTS_SCENE_HEAD
        " \"objects\": [\n"
        "  {\"shape\": \"box\", \"size\": [2, 2, 2], \"material\": \"glass\",\n"
        "   \"transform\": {\"translate\": [-6, 0, 0]},\n"
        "   \"texture\": {\"file\": \"five_tex.obj\", \"material\": \"stone\", " IDENTITY_BLOCK
        "}},\n"
        "  {\"shape\": \"sphere\", \"level\": 1, \"centre\": [-2, 0, 0], \"material\": \"glass\",\n"
        "   \"texture\": {\"generate\": \"bomb --shape sphere --count 4 --size 10:16 --seed 5 "
        "--level 1 --no-overlap\", \"material\": \"stone\"}},\n"
        "  {\"shape\": \"box\", \"material\": \"m\", \"transform\": {\"translate\": [0, 4, 0]}},\n"
        "  {\"shape\": \"box\", \"size\": [2, 2, 2], \"material\": \"glass\",\n"
        "   \"transform\": {\"translate\": [2, 0, 0]},\n"
        "   \"texture\": {\"file\": \"mixed_tex.obj\", \"material\": \"stone\", " IDENTITY_BLOCK
        "}},\n"
        "  {\"shape\": \"box\", \"size\": [2, 2, 2], \"material\": \"glass\",\n"
        "   \"transform\": {\"translate\": [6, 0, 0]},\n"
        "   \"texture\": {\"file\": \"many_tex.obj\", \"material\": \"stone\", " IDENTITY_BLOCK
        "}}]}";
    Scene s;
    VbObject *rec;
    size_t n;
    if (load_objects("parts.json", json, &s, &rec, &n)) return;
    const int want[5] = {5, 4, 0, 16, VBCL_CONE_TEST_MAX_ELEMENTS + 1};
    unsigned next = (unsigned)s.nobjects; /* the next texture's first part record */
    for (int i = 0; i < s.nobjects; i++) {
        int runs = check_parts(&s, rec, i);
        fprintf(stderr, "    %s: %u texture triangles, %d runs, %u part records from %u\n",
                s.objects[i].name, s.objects[i].ntex_tris, runs, rec[i].nelems, rec[i].first_elem);
        CHECK(runs == want[i], "%s: %d runs of pieces, expected %d", s.objects[i].name, runs,
              want[i]);
        if (rec[i].nelems == 0) continue;
        CHECK(rec[i].first_elem == next, "%s: parts from record %u, expected %u", s.objects[i].name,
              rec[i].first_elem, next);
        next = rec[i].first_elem + rec[i].nelems;
    }
    CHECK(n == next, "%zu records: the objects and their parts (%u)", n, next);
    CHECK(rec[4].nelems == 0, "a texture of %d pieces is bounded as a whole (%u parts)",
          VBCL_CONE_TEST_MAX_ELEMENTS + 1, rec[4].nelems);
    free(rec);
    scene_free(&s);
}

/* ---- parts behind a host's planes ---- */

/* Host i's part records' ahead bits, each against the test's own: bit j clear exactly where
 * every vertex of the part lies behind the plane of the host's own triangle j by at least
 * 1e-5 of the host's size (the margin). Returns the parts' masks in mask[] (at most 8). */
static void check_ahead(const Scene *s, const VbObject *rec, int i, unsigned mask[8])
{
    const SceneObject *o = &s->objects[i];
    const VbObject *g = &rec[i];
    double margin = 1e-5 * object_size(&s->mesh, o);
    for (unsigned e = 0; e < g->nelems && e < 8; e++) {
        const VbObject *p = &rec[g->first_elem + e];
        unsigned want = ~0u;
        for (uint32_t j = 0; j < o->ntris && j < VBCL_AHEAD_BITS; j++) {
            double h = max_height_one(&s->mesh, o->first_tri + j, p->first_tri, p->ntris);
            if (h <= -margin) want &= ~(1u << j);
        }
        fprintf(stderr, "    %s part %u: ahead %#x, expected %#x\n", o->name, e, p->ahead, want);
        CHECK(p->ahead == want, "%s part %u: ahead %#x, expected %#x (margin %.3g)", o->name, e,
              p->ahead, want, margin);
        mask[e] = want;
    }
}

/* The own triangles of object o whose unit normal is `sign` along axis `axis` (a face of a
 * box), as a mask of ahead bits. */
static unsigned face_bits(const Mesh *m, const SceneObject *o, int axis, double sign)
{
    unsigned bits = 0;
    for (uint32_t j = 0; j < o->ntris; j++) {
        double n[3], k;
        if (tri_plane(m, o->first_tri + j, n, &k) && fabs(n[axis] - sign) < 1e-9) bits |= 1u << j;
    }
    return bits;
}

/* A glass box [-1, 1]^3 (12 own triangles: a hull) with four parts: an octahedron at the
 * centre, behind every face by 0.5 or more; a box behind every face but reaching to
 * y = 1 - 2e-6, within the margin (about 3e-5) of the +y face; a box crossing the +x face;
 * and a box 1e-3 behind the -z face. The ahead bits are clear exactly where the part lies
 * behind the face triangle's plane by the margin: the first and last parts 0, the second
 * only the +y face's two triangles set, the third only the +x face's. */
static void test_objects_parts_ahead(void)
{
    Obj tex = {0};
    obj_octahedron(&tex, 0, 0, 0, 0.3);
    obj_box(&tex, (const double[3]){0.2, 0.5, -0.2}, (const double[3]){0.6, 1 - 2e-6, 0.2});
    obj_box(&tex, (const double[3]){0.8, -0.5, -0.2}, (const double[3]){1.3, -0.2, 0.2});
    obj_box(&tex, (const double[3]){-0.6, -0.6, -1 + 1e-3}, (const double[3]){-0.3, -0.3, -0.5});
    obj_write(&tex, "ahead_tex.obj");
    const char *json = OBJECTS_SCENE_HEAD
        " \"objects\": [\n"
        "  {\"shape\": \"box\", \"size\": [2, 2, 2], \"material\": \"glass\",\n"
        "   \"texture\": {\"file\": \"ahead_tex.obj\", \"material\": \"stone\", " IDENTITY_BLOCK
        "}}]}";
    Scene s;
    VbObject *rec;
    size_t n;
    if (load_objects("ahead.json", json, &s, &rec, &n)) return;
    unsigned mask[8] = {0};
    CHECK(has(&rec[0], VBCL_OBJECT_HULL) && rec[0].nelems == 4,
          "the box is a hull with four parts (flags %#x, %u parts)", rec[0].flags, rec[0].nelems);
    if (rec[0].nelems == 4) {
        check_ahead(&s, rec, 0, mask);
        unsigned top = face_bits(&s.mesh, &s.objects[0], 1, 1.0),
                 side = face_bits(&s.mesh, &s.objects[0], 0, 1.0);
        unsigned own = (1u << s.objects[0].ntris) - 1; /* the bits of its triangles */
        /* the fixture: what the rule must say of these four */
        CHECK((mask[0] & own) == 0 && (mask[3] & own) == 0,
              "the inner parts lie behind every face");
        CHECK(top != 0 && (mask[1] & own) == top, "the part near +y: %#x, the +y face's bits %#x",
              mask[1] & own, top);
        CHECK(side != 0 && (mask[2] & own) == side,
              "the part through +x: %#x, the +x face's bits %#x", mask[2] & own, side);
    }
    free(rec);
    scene_free(&s);
}

/* ---- solid parts, cores and inner spheres ---- */

/* How far the point c lies behind the nearest plane of triangles first .. first + n - 1
 * (negative: ahead of one of them). */
static double min_depth(const Mesh *m, uint32_t first, uint32_t n, const double c[3])
{
    double least = INFINITY, nrm[3], k;
    for (uint32_t t = first; t < first + n; t++) {
        if (!tri_plane(m, t, nrm, &k)) return -INFINITY;
        least = fmin(least, -height(nrm, k, c[0], c[1], c[2]));
    }
    return least;
}

/* The mean of the corners of triangles first .. first + n - 1. */
static void corner_mean(const Mesh *m, uint32_t first, uint32_t n, double c[3])
{
    c[0] = c[1] = c[2] = 0.0;
    for (uint32_t t = first; t < first + n; t++)
        for (int j = 0; j < 3; j++) {
            vec3 v = corner(m, t, j);
            c[0] += v.x / (3.0 * n);
            c[1] += v.y / (3.0 * n);
            c[2] += v.z / (3.0 * n);
        }
}

/* Whether every directed edge a -> b of triangles first .. first + n - 1 has its reverse
 * among them (a closed surface, by vertex indices). */
static int closed_by_edges(const Mesh *m, uint32_t first, uint32_t n)
{
    for (uint32_t t = first; t < first + n; t++)
        for (int j = 0; j < 3; j++) {
            uint32_t a = m->tris[3 * t + j], b = m->tris[3 * t + (j + 1) % 3];
            int found = 0;
            for (uint32_t u = first; u < first + n && !found; u++)
                for (int i = 0; i < 3 && !found; i++)
                    found = m->tris[3 * u + i] == b && m->tris[3 * u + (i + 1) % 3] == a;
            if (!found) return 0;
        }
    return 1;
}

/* Checks the sphere `core` (a record's VbObject.inside) against triangles first .. first +
 * n - 1 and, where hn > 0, a host's hf .. hf + hn - 1: behind every plane of both, and as
 * large as the lesser depth of c (the expected centre) behind them, less 1%. */
static void check_core(const Mesh *m, const char *what, const float core[4], const double c[3],
                       uint32_t first, uint32_t n, uint32_t hf, uint32_t hn)
{
    const double at[3] = {core[0], core[1], core[2]};
    double in_part = min_depth(m, first, n, at), in_host = hn ? min_depth(m, hf, hn, at) : INFINITY;
    double room = fmin(min_depth(m, first, n, c), hn ? min_depth(m, hf, hn, c) : INFINITY);
    fprintf(stderr,
            "    %s: sphere (%.5f %.5f %.5f) radius %.6f; its centre %.6f behind its planes", what,
            core[0], core[1], core[2], core[3], in_part);
    if (hn) fprintf(stderr, ", %.6f behind the host's", in_host);
    fprintf(stderr, "; room %.6f\n", room);
    CHECK(core[3] > 0.0f && core[3] <= in_part,
          "%s: the sphere (radius %.6f) lies behind every plane of its own (%.6f)", what, core[3],
          in_part);
    CHECK(core[3] <= in_host, "%s: the sphere (radius %.6f) lies inside the host (%.6f)", what,
          core[3], in_host);
    CHECK(core[3] >= 0.99 * room, "%s: the sphere (radius %.6f) fills the room about c (%.6f)",
          what, core[3], room);
    for (int a = 0; a < 3; a++)
        CHECK(fabs(core[a] - c[a]) < 1e-5, "%s: centre[%d] %.7f, expected %.7f", what, a, core[a],
              c[a]);
}

/* Whether part p of textured host o may be solid by the test's own reckoning: o's own
 * triangles convex, the texture material opaque and no object's own, the part convex,
 * closed, not planar, and the mean of its corners well inside it and inside o. */
static int solid_expected(const Scene *s, const SceneObject *o, const VbObject *p)
{
    const Mesh *m = &s->mesh;
    double eps = 1e-6 * object_size(m, o), c[3];
    int ok = max_height(m, o->first_tri, o->ntris, o->first_tri, o->ntris) <= eps &&
             !(s->materials[o->tex_material].gpu.k_global > 0.0f);
    for (int j = 0; j < s->nobjects; j++) ok &= s->objects[j].material != o->tex_material;
    corner_mean(m, p->first_tri, p->ntris, c);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    tri_box(m, p->first_tri, p->ntris, lo, hi);
    int flat = hi[0] - lo[0] < eps || hi[1] - lo[1] < eps || hi[2] - lo[2] < eps;
    return ok && !flat && max_height(m, p->first_tri, p->ntris, p->first_tri, p->ntris) <= eps &&
           closed_by_edges(m, p->first_tri, p->ntris) &&
           min_depth(m, p->first_tri, p->ntris, c) > 100 * eps &&
           min_depth(m, o->first_tri, o->ntris, c) > 100 * eps;
}

/* Checks the parts of textured object i: VBCL_OBJECT_SOLID where solid_expected says, with a
 * core (check_core) inside the part and inside the host; returns the parts found solid as
 * bits. */
static unsigned check_solid_parts(const Scene *s, const VbObject *rec, int i)
{
    const SceneObject *o = &s->objects[i];
    unsigned solid = 0;
    for (unsigned e = 0; e < rec[i].nelems && e < 32; e++) {
        const VbObject *p = &rec[rec[i].first_elem + e];
        int want = solid_expected(s, o, p);
        CHECK(has(p, VBCL_OBJECT_SOLID) == want, "%s part %u: SOLID %d, expected %d", o->name, e,
              has(p, VBCL_OBJECT_SOLID), want);
        if (!has(p, VBCL_OBJECT_SOLID)) continue;
        solid |= 1u << e;
        char what[96];
        double c[3];
        snprintf(what, sizeof what, "%s part %u", o->name, e);
        corner_mean(&s->mesh, p->first_tri, p->ntris, c);
        check_core(&s->mesh, what, p->inside, c, p->first_tri, p->ntris, o->first_tri, o->ntris);
    }
    return solid;
}

/* Solid parts: a glass box whose opaque texture (a material no object has) holds an
 * octahedron inside it, an octahedron reaching out through its +y face (its core shrunk to
 * lie inside the box), an L-shaped prism (not convex) and a box; the same texture in a glass
 * box with a transparent texture material, and in one whose texture material is an object's
 * own; an opaque sphere of 80 triangles, an opaque box of 12 and an opaque
 * hourglass. SOLID exactly where the rules say (the octahedra and the box part; the sphere),
 * each core behind every plane of its part (and host), centred on the mean of the corners and
 * at least 0.99 of the room there. */
static void test_objects_solid_parts(void)
{
    Obj tex = {0};
    obj_octahedron(&tex, -0.4, -0.3, 0, 0.4);
    obj_octahedron(&tex, 0, 0.8, 0, 0.5);
    obj_ell(&tex, 0.2, -0.9, 0, 0.3);
    obj_box(&tex, (const double[3]){0.4, -0.1, -0.3}, (const double[3]){0.8, 0.2, 0.3});
    obj_write(&tex, "solid_tex.obj");
    const char *json = OBJECTS_SCENE_HEAD
        " \"objects\": [\n"
        "  {\"shape\": \"box\", \"size\": [2, 2, 2], \"material\": \"glass\",\n"
        "   \"texture\": {\"file\": \"solid_tex.obj\", \"material\": \"stone\", " IDENTITY_BLOCK
        "}},\n"
        "  {\"shape\": \"box\", \"size\": [2, 2, 2], \"material\": \"glass\",\n"
        "   \"transform\": {\"translate\": [4, 0, 0]},\n"
        "   \"texture\": {\"file\": \"solid_tex.obj\", \"material\": \"clear\", " IDENTITY_BLOCK
        "}},\n"
        "  {\"shape\": \"box\", \"size\": [2, 2, 2], \"material\": \"glass\",\n"
        "   \"transform\": {\"translate\": [-4, 0, 0]},\n"
        "   \"texture\": {\"file\": \"solid_tex.obj\", \"material\": \"m\", " IDENTITY_BLOCK "}},\n"
        "  {\"shape\": \"sphere\", \"level\": 1, \"centre\": [0, 4, 0], \"material\": \"m\"},\n"
        "  {\"shape\": \"box\", \"material\": \"m\", \"transform\": {\"translate\": [4, 4, 0]}},\n"
        "  {\"shape\": \"revolution\", \"segments\": 12, \"material\": \"m\",\n"
        "   \"profile\": [[0.6, 0], [0.2, 0.5], [0.6, 1]], \"transform\": {\"translate\": [0, -5, "
        "0]}}]}";
    Scene s;
    VbObject *rec;
    size_t n;
    if (load_objects("solid.json", json, &s, &rec, &n)) return;
    unsigned solid[3];
    for (int i = 0; i < 3; i++) solid[i] = check_solid_parts(&s, rec, i);
    CHECK(rec[0].nelems == 4 && solid[0] == 0xb, "the two octahedra and the box are solid (%#x)",
          solid[0]);
    CHECK(solid[1] == 0 && solid[2] == 0,
          "no part of a transparent texture (%#x) nor of an object's material (%#x) is solid",
          solid[1], solid[2]);
    CHECK(has(&rec[rec[1].first_elem], VBCL_OBJECT_CONVEX),
          "the transparent texture's octahedron is convex all the same");
    for (int i = 3; i < s.nobjects; i++) {
        const SceneObject *o = &s.objects[i];
        double eps = 1e-6 * object_size(&s.mesh, o), c[3];
        int convex = max_height(&s.mesh, o->first_tri, o->ntris, o->first_tri, o->ntris) <= eps;
        int want = convex && o->ntris > VBCL_OBJECT_SET_MAX_TRIS / 2;
        CHECK(has(&rec[i], VBCL_OBJECT_SOLID) == want, "%s (%u triangles): SOLID %d, expected %d",
              o->name, o->ntris, has(&rec[i], VBCL_OBJECT_SOLID), want);
        if (!has(&rec[i], VBCL_OBJECT_SOLID)) continue;
        corner_mean(&s.mesh, o->first_tri, o->ntris, c);
        check_core(&s.mesh, o->name, rec[i].inside, c, o->first_tri, o->ntris, 0, 0);
    }
    CHECK(has(&rec[3], VBCL_OBJECT_SOLID) && !has(&rec[4], VBCL_OBJECT_SOLID) &&
              !has(&rec[5], VBCL_OBJECT_SOLID),
          "the sphere is solid, the small box and the hourglass not");
    free(rec);
    scene_free(&s);
}

/* Checks record i's inner sphere: VBCL_OBJECT_INNER exactly on a host of more than
 * VBCL_OBJECT_SET_MAX_TRIS / 2 own triangles that are convex, its sphere behind every plane of
 * them, centred on the middle of their box and filling at least 0.99 of the room there. */
static void check_inner(const Scene *s, const VbObject *rec, int i)
{
    const SceneObject *o = &s->objects[i];
    const Mesh *m = &s->mesh;
    double eps = 1e-6 * object_size(m, o), c[3];
    int want = o->is_host && o->ntris > VBCL_OBJECT_SET_MAX_TRIS / 2 &&
               max_height(m, o->first_tri, o->ntris, o->first_tri, o->ntris) <= eps;
    CHECK(has(&rec[i], VBCL_OBJECT_INNER) == want, "%s (%u triangles): INNER %d, expected %d",
          o->name, o->ntris, has(&rec[i], VBCL_OBJECT_INNER), want);
    if (!has(&rec[i], VBCL_OBJECT_INNER)) return;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    tri_box(m, o->first_tri, o->ntris, lo, hi);
    for (int a = 0; a < 3; a++) c[a] = 0.5 * (lo[a] + hi[a]);
    check_core(m, o->name, rec[i].inside, c, o->first_tri, o->ntris, 0, 0);
}

/* Inner spheres: a glass sphere of 320 triangles whose texture holds an octahedron at its
 * centre and one reaching out of it at x = 0.9, a glass sphere of 80 triangles without a
 * texture, and a glass box with the same texture (a hull of 12 triangles: too few). INNER on
 * both spheres, their inner spheres behind every own plane, about their own triangles'
 * centre (the texture reaching out moves the bound sphere, not this), at least 0.99 of the
 * room there; the box none. The big host's parts (320 own triangles, more than
 * VBCL_AHEAD_BITS): ahead 0 for the part within 0.9 of the inner sphere's radius, every bit
 * for the one reaching beyond it. */
static void test_objects_inner_spheres(void)
{
    Obj tex = {0};
    obj_octahedron(&tex, 0, 0, 0, 0.2);
    obj_octahedron(&tex, 0.9, 0, 0, 0.3);
    obj_write(&tex, "inner_tex.obj");
    const char *json = OBJECTS_SCENE_HEAD
        " \"objects\": [\n"
        "  {\"shape\": \"sphere\", \"level\": 2, \"material\": \"glass\",\n"
        "   \"texture\": {\"file\": \"inner_tex.obj\", \"material\": \"stone\", " IDENTITY_BLOCK
        "}},\n"
        "  {\"shape\": \"sphere\", \"level\": 1, \"centre\": [-4, 0, 0], \"material\": "
        "\"glass\"},\n"
        "  {\"shape\": \"box\", \"size\": [2, 2, 2], \"material\": \"glass\",\n"
        "   \"transform\": {\"translate\": [4, 0, 0]},\n"
        "   \"texture\": {\"file\": \"inner_tex.obj\", \"material\": \"stone\", " IDENTITY_BLOCK
        "}}]}";
    Scene s;
    VbObject *rec;
    size_t n;
    if (load_objects("inner.json", json, &s, &rec, &n)) return;
    for (int i = 0; i < s.nobjects; i++) check_inner(&s, rec, i);
    CHECK(has(&rec[0], VBCL_OBJECT_INNER) && has(&rec[1], VBCL_OBJECT_INNER) &&
              !has(&rec[2], VBCL_OBJECT_INNER),
          "both spheres have inner spheres, the box none");
    CHECK(rec[0].nelems == 2, "the big sphere's texture has two parts (%u)", rec[0].nelems);
    CHECK(rec[0].bound[0] > 0.05f, "the texture reaching out moves the bound sphere (x %.4f)",
          rec[0].bound[0]);
    const double ic[3] = {rec[0].inside[0], rec[0].inside[1], rec[0].inside[2]};
    for (unsigned e = 0; e < rec[0].nelems && has(&rec[0], VBCL_OBJECT_INNER); e++) {
        const VbObject *p = &rec[rec[0].first_elem + e];
        double far = 0.0;
        for (uint32_t t = p->first_tri; t < p->first_tri + p->ntris; t++)
            for (int j = 0; j < 3; j++) far = fmax(far, dist3(ic, corner(&s.mesh, t, j)));
        unsigned want = far <= 0.9 * rec[0].inside[3] ? 0u : ~0u;
        fprintf(stderr,
                "    part %u: reaches %.4f from the inner sphere's centre (radius %.4f), "
                "ahead %#x\n",
                e, far, rec[0].inside[3], p->ahead);
        CHECK(far <= 0.9 * rec[0].inside[3] || far > rec[0].inside[3],
              "the fixture: part %u is well within the inner sphere or beyond it", e);
        CHECK(p->ahead == want, "part %u: ahead %#x, expected %#x", e, p->ahead, want);
    }
    CHECK(rec[0].nelems < 2 || rec[rec[0].first_elem].ahead != rec[rec[0].first_elem + 1].ahead,
          "one part within the inner sphere, one beyond it");
    free(rec);
    scene_free(&s);
}

void suite_objects(void)
{
    RUN_TEST(test_objects_hulls);
    RUN_TEST(test_objects_planes);
    RUN_TEST(test_objects_bounds);
    RUN_TEST(test_objects_texture_parts);
    RUN_TEST(test_objects_parts_ahead);
    RUN_TEST(test_objects_solid_parts);
    RUN_TEST(test_objects_inner_spheres);
}
