/* test_mesh.c — tests of the mesh module: shapes, the closed-surface check, transforms and
 * the OBJ and PLY loaders (including their error messages). */
#include "harness.h"
#include "mesh.h"

#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

void suite_mesh(void);

#define PI 3.14159265358979323846

/* ---- helpers ---- */

static double signed_volume(const Mesh *m)
{
    double v = 0.0;
    for (uint32_t i = 0; i < m->ntris; i++) {
        const uint32_t *t = m->tris + (size_t)i * 3;
        vec3 a = m->verts[t[0]], b = m->verts[t[1]], c = m->verts[t[2]];
        v += (double)v3_dot(a, v3_cross(b, c));
    }
    return v / 6.0;
}

static vec3 face_normal(const Mesh *m, uint32_t i)
{
    const uint32_t *t = m->tris + (size_t)i * 3;
    vec3 a = m->verts[t[0]], b = m->verts[t[1]], c = m->verts[t[2]];
    return v3_norm(v3_cross(v3_sub(b, a), v3_sub(c, a)));
}

/* Counts faces of a convex mesh whose normal points towards `centre`, and vertex normals
 * (when present) that disagree with their face's normal or are not unit length. */
static int count_inward(const Mesh *m, vec3 centre)
{
    int bad = 0;
    for (uint32_t i = 0; i < m->ntris; i++) {
        const uint32_t *t = m->tris + (size_t)i * 3;
        vec3 n = face_normal(m, i);
        vec3 g = v3_scale(v3_add(v3_add(m->verts[t[0]], m->verts[t[1]]), m->verts[t[2]]), 1.0f / 3);
        if (v3_dot(n, v3_sub(g, centre)) <= 0.0f) bad++;
        if (m->normals)
            for (int k = 0; k < 3; k++) {
                vec3 vn = m->normals[t[k]];
                if (v3_dot(vn, n) <= 0.0f || fabsf(v3_len(vn) - 1.0f) > 1e-4f) bad++;
            }
    }
    return bad;
}

static int closed(const Mesh *m, char *err, size_t len)
{
    return mesh_check_closed(m, err, len);
}

static char tmpdir[64];

/* Writes len bytes to a file NAME in the test directory; returns its path (static). */
static const char *write_file(const char *name, const void *data, size_t len)
{
    static char path[256];
    if (!tmpdir[0]) {
        strcpy(tmpdir, "/tmp/vbcl_test_mesh_XXXXXX");
        if (!mkdtemp(tmpdir)) {
            tmpdir[0] = 0;
            return "/nonexistent/dir/x";
        }
    }
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    FILE *f = fopen(path, "wb");
    if (f) {
        fwrite(data, 1, len, f);
        fclose(f);
    }
    return path;
}

static const char *write_text(const char *name, const char *text)
{
    return write_file(name, text, strlen(text));
}

/* Loads text as the file NAME; returns mesh_load's result, the mesh in m, message in err. */
static int load_text(const char *name, const char *text, Mesh *m, char *err, size_t len)
{
    mesh_init(m);
    err[0] = 0;
    return mesh_load(write_text(name, text), m, err, len);
}

/* Expects loading text as NAME to fail with a message containing each of the given words
 * (a NULL-terminated list). */
static void expect_load_error(const char *name, const char *text, size_t textlen,
                              const char *const *words)
{
    Mesh m;
    mesh_init(&m);
    char err[512] = "";
    int rc = mesh_load(write_file(name, text, textlen), &m, err, sizeof err);
    CHECK(rc == -1, "%s: loaded, expected an error", name);
    CHECK(m.nverts == 0 && m.ntris == 0, "%s: failed load left %u verts", name, m.nverts);
    for (int i = 0; words[i]; i++)
        CHECK(strstr(err, words[i]) != NULL, "%s: message '%s' lacks '%s'", name, err, words[i]);
    mesh_free(&m);
}

#define EXPECT_ERROR(name, text, ...)                                                              \
    do {                                                                                           \
        const char *const w_[] = {__VA_ARGS__, NULL};                                              \
        expect_load_error(name, text, strlen(text), w_);                                           \
    } while (0)

static int same_mesh(const Mesh *a, const Mesh *b)
{
    if (a->nverts != b->nverts || a->ntris != b->ntris || !a->normals != !b->normals) return 0;
    if (memcmp(a->verts, b->verts, (size_t)a->nverts * sizeof(vec3)) != 0) return 0;
    if (a->normals && memcmp(a->normals, b->normals, (size_t)a->nverts * sizeof(vec3)) != 0)
        return 0;
    return memcmp(a->tris, b->tris, (size_t)a->ntris * 3 * sizeof(uint32_t)) == 0;
}

/* ---- shapes ---- */

static void test_sphere_closed_outward(void)
{
    char err[256];
    for (int level = 0; level <= 5; level++) {
        Mesh m;
        mesh_init(&m);
        CHECK(shape_sphere(&m, level) == 0, "level %d", level);
        uint32_t nt = 20u << (2 * level), nv = 10u * (1u << (2 * level)) + 2;
        CHECK(m.ntris == nt && m.nverts == nv, "level %d: %u tris %u verts", level, m.ntris,
              m.nverts);
        CHECK(closed(&m, err, sizeof err) == 0, "level %d: %s", level, err);
        CHECK(count_inward(&m, v3(0, 0, 0)) == 0, "level %d: inward faces or bad normals", level);
        if (level == 5) {
            double v = signed_volume(&m), want = 4.0 / 3.0 * PI;
            CHECK(fabs(v - want) < 0.01 * want, "volume %g, want %g", v, want);
        }
        mesh_free(&m);
    }
    Mesh m;
    mesh_init(&m);
    CHECK(shape_sphere(&m, 8) == -1 && shape_sphere(&m, -1) == -1, "bad levels accepted");
    mesh_free(&m);
}

/* The largest distance by which a vertex of m lies in front of a triangle's plane. */
static double worst_vertex_in_front(const Mesh *m)
{
    double worst = -INFINITY;
    for (uint32_t t = 0; t < m->ntris; t++) {
        vec3 a = m->verts[m->tris[3 * t]], b = m->verts[m->tris[3 * t + 1]],
             c = m->verts[m->tris[3 * t + 2]];
        vec3 n = v3_norm(v3_cross(v3_sub(b, a), v3_sub(c, a)));
        for (uint32_t v = 0; v < m->nverts; v++)
            worst = fmax(worst, v3_dot(n, v3_sub(m->verts[v], a)));
    }
    return worst;
}

/* mesh_part_convex against the vertex-by-plane definition: tessellated spheres are convex
 * (up to level 3 also by the definition); a level-3 sphere with one vertex pushed in or
 * pulled out by 1% of the radius (a dent; a spike, whose foot is concave) is not, and the
 * definition agrees; nor an open sphere, two disjoint ones in one range (each alone is),
 * or a box, whose faces' two triangles are coplanar (flat edges are refused). */
static void test_part_convex(void)
{
    for (int level = 0; level <= 6; level++) {
        Mesh m;
        mesh_init(&m);
        CHECK(shape_sphere(&m, level) == 0, "level %d", level);
        CHECK(mesh_part_convex(&m, 0, m.ntris, 1e-9) == 1, "sphere level %d: not convex", level);
        if (level <= 3) {
            double w = worst_vertex_in_front(&m);
            CHECK(w < 1e-6, "level %d: a vertex %g in front of a plane", level, w);
        }
        if (level == 3) {
            vec3 keep = m.verts[7];
            for (int k = 0; k < 2; k++) {
                m.verts[7] = v3_scale(keep, k ? 1.01f : 0.99f);
                double w = worst_vertex_in_front(&m);
                CHECK(mesh_part_convex(&m, 0, m.ntris, 1e-9) == 0 && w > 1e-4,
                      "%s: convex by edges, %g in front", k ? "a spike" : "a dent", w);
            }
            m.verts[7] = keep;
            CHECK(mesh_part_convex(&m, 1, m.ntris - 1, 1e-9) == 0, "an open sphere passes");
            uint32_t n = m.ntris;
            Mesh two;
            mesh_init(&two);
            CHECK(shape_sphere(&two, 3) == 0, "second sphere");
            mat4 xf = mat4_translate(v3(3, 0, 0));
            mesh_transform(&two, &xf);
            CHECK(mesh_append(&m, &two) == 0, "append");
            CHECK(mesh_part_convex(&m, 0, m.ntris, 1e-9) == 0, "two spheres pass as one");
            CHECK(mesh_part_convex(&m, n, n, 1e-9) == 1, "the second sphere alone");
            mesh_free(&two);
        }
        mesh_free(&m);
    }
    Mesh box;
    mesh_init(&box);
    CHECK(shape_box(&box, v3(1, 2, 3)) == 0, "box");
    CHECK(mesh_part_convex(&box, 0, box.ntris, 1e-9) == 0, "a box's flat edges pass");
    mesh_free(&box);
}

static void test_box_exact(void)
{
    char err[256];
    Mesh m;
    mesh_init(&m);
    CHECK(shape_box(&m, v3(2, 3, 4)) == 0, "box");
    CHECK(m.nverts == 8 && m.ntris == 12 && !m.normals, "%u verts %u tris", m.nverts, m.ntris);
    CHECK(closed(&m, err, sizeof err) == 0, "%s", err);
    CHECK(signed_volume(&m) == 24.0, "volume %g", signed_volume(&m));
    CHECK(count_inward(&m, v3(0, 0, 0)) == 0, "inward faces");
    vec3 lo, hi;
    mesh_bounds(&m, &lo, &hi);
    CHECK(lo.x == -1 && lo.y == -1.5f && lo.z == -2 && hi.x == 1 && hi.y == 1.5f && hi.z == 2,
          "bounds");
    mesh_free(&m);
}

static void test_prism_both_windings(void)
{
    char err[256];
    const float ccw[3][2] = {{-1, -1}, {2, -1}, {0, 1}};
    const float cw[3][2] = {{-1, -1}, {0, 1}, {2, -1}};
    const float(*pts[2])[2] = {ccw, cw};
    for (int k = 0; k < 2; k++) {
        Mesh m;
        mesh_init(&m);
        CHECK(shape_prism(&m, pts[k], 0.5f) == 0, "prism");
        CHECK(m.nverts == 6 && m.ntris == 8, "%u verts %u tris", m.nverts, m.ntris);
        CHECK(closed(&m, err, sizeof err) == 0, "winding %d: %s", k, err);
        double v = signed_volume(&m); /* area 3, depth 0.5 */
        CHECK(fabs(v - 1.5) < 1e-6, "winding %d: volume %g", k, v);
        CHECK(count_inward(&m, v3(1.0f / 3, -1.0f / 3, 0)) == 0, "winding %d: inward", k);
        mesh_free(&m);
    }
}

static void test_quad_open(void)
{
    char err[256] = "";
    Mesh m;
    mesh_init(&m);
    CHECK(shape_quad(&m, 2, 3) == 0, "quad");
    CHECK(m.nverts == 4 && m.ntris == 2, "%u verts %u tris", m.nverts, m.ntris);
    for (uint32_t i = 0; i < m.ntris; i++) {
        vec3 n = face_normal(&m, i);
        CHECK(n.y > 0.999f, "triangle %u faces (%g %g %g)", i, n.x, n.y, n.z);
    }
    CHECK(closed(&m, err, sizeof err) == -1, "quad reported closed");
    CHECK(strstr(err, "open edge") && strstr(err, "used by 1 triangle"), "message: %s", err);
    mesh_free(&m);
}

static void test_revolution_cylinder(void)
{
    char err[256];
    const float up[2][2] = {{1, 0}, {1, 2}}, down[2][2] = {{1, 2}, {1, 0}};
    const float(*prof[2])[2] = {up, down};
    int segs = 64;
    double polygon = 0.5 * segs * sin(2 * PI / segs) * 2.0; /* inscribed polygon area * h */
    for (int k = 0; k < 2; k++) {
        Mesh m;
        mesh_init(&m);
        CHECK(shape_revolution(&m, prof[k], 2, segs, 1) == 0, "revolution");
        CHECK(closed(&m, err, sizeof err) == 0, "direction %d: %s", k, err);
        double v = signed_volume(&m);
        CHECK(fabs(v - polygon) < 1e-4 * polygon, "direction %d: volume %g want %g", k, v, polygon);
        CHECK(fabs(v - 2 * PI) < 0.01 * 2 * PI, "direction %d: volume %g", k, v);
        CHECK(count_inward(&m, v3(0, 1, 0)) == 0, "direction %d: inward", k);
        mesh_free(&m);
        /* without caps it is open */
        mesh_init(&m);
        CHECK(shape_revolution(&m, prof[k], 2, segs, 0) == 0, "revolution");
        CHECK(closed(&m, err, sizeof err) == -1 && strstr(err, "open edge"), "uncapped closed");
        mesh_free(&m);
    }
    /* the same cylinder with its caps in the profile: poles, creases at the rims */
    const float box[4][2] = {{0, 0}, {1, 0}, {1, 2}, {0, 2}};
    Mesh m;
    mesh_init(&m);
    CHECK(shape_revolution(&m, box, 4, segs, 1) == 0, "revolution");
    CHECK(closed(&m, err, sizeof err) == 0, "%s", err);
    CHECK(fabs(signed_volume(&m) - polygon) < 1e-4 * polygon, "volume %g", signed_volume(&m));
    CHECK(count_inward(&m, v3(0, 1, 0)) == 0, "inward");
    mesh_free(&m);
    CHECK(shape_revolution(&m, box, 1, segs, 1) == -1, "1-point profile accepted");
    CHECK(shape_revolution(&m, box, 4, 2, 1) == -1, "2 segments accepted");
}

static void test_revolution_poles(void)
{
    /* a sphere profile from pole to pole, listed upwards and downwards */
    char err[256];
    enum { N = 33 };
    float up[N][2], down[N][2];
    for (int i = 0; i < N; i++) {
        double a = -PI / 2 + PI * i / (N - 1);
        up[i][0] = i == 0 || i == N - 1 ? 0.0f : (float)cos(a);
        up[i][1] = (float)sin(a);
        down[N - 1 - i][0] = up[i][0];
        down[N - 1 - i][1] = up[i][1];
    }
    const float(*prof[2])[2] = {up, down};
    for (int k = 0; k < 2; k++) {
        Mesh m;
        mesh_init(&m);
        CHECK(shape_revolution(&m, prof[k], N, 64, 1) == 0, "revolution");
        CHECK(closed(&m, err, sizeof err) == 0, "direction %d: %s", k, err);
        double v = signed_volume(&m), want = 4.0 / 3.0 * PI;
        CHECK(fabs(v - want) < 0.01 * want, "direction %d: volume %g", k, v);
        CHECK(count_inward(&m, v3(0, 0, 0)) == 0, "direction %d: inward", k);
        /* one pole vertex at each end */
        int poles = 0;
        for (uint32_t i = 0; i < m.nverts; i++) poles += m.verts[i].x == 0 && m.verts[i].z == 0;
        CHECK(poles == 2, "direction %d: %d vertices on the axis", k, poles);
        mesh_free(&m);
    }
    /* a cone: pole at the tip, cap at the base */
    const float cone[2][2] = {{1, 0}, {0, 1}};
    Mesh m;
    mesh_init(&m);
    CHECK(shape_revolution(&m, cone, 2, 48, 1) == 0, "cone");
    CHECK(closed(&m, err, sizeof err) == 0, "cone: %s", err);
    double want = 48 * 0.5 * sin(2 * PI / 48) / 3.0;
    CHECK(fabs(signed_volume(&m) - want) < 1e-4, "cone volume %g want %g", signed_volume(&m), want);
    mesh_free(&m);
}

/* ---- closed check ---- */

static void test_check_closed_errors(void)
{
    char err[256] = "";
    Mesh m;
    mesh_init(&m);
    shape_box(&m, v3(1, 1, 1));
    uint32_t *t = m.tris + 3 * 5, s = t[1];
    t[1] = t[2];
    t[2] = s;
    CHECK(closed(&m, err, sizeof err) == -1, "flipped triangle accepted");
    CHECK(strstr(err, "same direction") && strstr(err, "inconsistent orientation"), "%s", err);
    t[2] = t[1];
    CHECK(closed(&m, err, sizeof err) == -1 && strstr(err, "repeats a vertex"), "%s", err);
    mesh_free(&m);

    /* duplicated seam vertices (same position, new index) are welded */
    shape_box(&m, v3(1, 1, 1));
    for (uint32_t i = 0; i < m.ntris; i += 2) {
        uint32_t *tri = m.tris + (size_t)i * 3;
        tri[0] = mesh_add_vertex(&m, m.verts[tri[0]]);
    }
    CHECK(closed(&m, err, sizeof err) == 0, "welded seams: %s", err);
    /* two boxes on top of each other: every edge used four times */
    Mesh two;
    mesh_init(&two);
    shape_box(&two, v3(1, 1, 1));
    shape_box(&two, v3(1, 1, 1));
    CHECK(closed(&two, err, sizeof err) == -1 && strstr(err, "non-manifold"), "%s", err);
    mesh_free(&two);
    mesh_free(&m);
    CHECK(closed(&m, err, sizeof err) == -1, "empty mesh closed");
}

static void test_transform_negative_scale(void)
{
    char err[256];
    Mesh m;
    mesh_init(&m);
    shape_sphere(&m, 2);
    double v0 = signed_volume(&m);
    mat4 xf = mat4_mul(mat4_rotate_axis(1, 30), mat4_scale(v3(-1, 2, 1)));
    mesh_transform(&m, &xf);
    CHECK(closed(&m, err, sizeof err) == 0, "%s", err);
    CHECK(fabs(signed_volume(&m) - 2 * v0) < 1e-4 * v0, "volume %g want %g", signed_volume(&m),
          2 * v0);
    CHECK(count_inward(&m, v3(0, 0, 0)) == 0, "inward after mirror");
    mat4 tr = mat4_translate(v3(5, -3, 2));
    mesh_transform(&m, &tr);
    CHECK(count_inward(&m, v3(5, -3, 2)) == 0, "inward after translation");
    mesh_free(&m);

    /* appending a mesh without normals to one with them gives zero normals */
    Mesh a, b;
    mesh_init(&a);
    mesh_init(&b);
    shape_sphere(&a, 0);
    shape_box(&b, v3(1, 1, 1));
    CHECK(mesh_append(&a, &b) == 0 && a.nverts == 20 && a.ntris == 32, "append");
    CHECK(a.normals && a.normals[19].x == 0 && a.normals[19].y == 0, "appended normals");
    CHECK(a.tris[3 * 20] >= 12, "indices shifted");
    mesh_free(&a);
    mesh_free(&b);
}

/* ---- OBJ ---- */

static void test_obj_face_forms(void)
{
    char err[512] = "";
    Mesh m;
    /* a unit cube; each face written in a different form, quads and triangles */
    const char *cube = "# cube\r\n"
                       "mtllib x.mtl\r\n"
                       "o cube\r\n"
                       "v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\n"
                       "v 0 0 1\r\nv 1 0 1\r\nv 1 1 1\r\nv 0 1 1 1.0\r\n"
                       "vt 0 0\nvt 1 0\nvt 1 1\n"
                       "vn 0 0 -1\n"
                       "g side\ns 1\nusemtl red\n"
                       "\n"
                       "f 1 4 3 2\n"           /* z = 0 */
                       "f 5/1 6/2 7/3 8/1\n"   /* z = 1 */
                       "f 1//1 2//1 6//1\n"    /* y = 0 */
                       "f 1/1/1 6/2/1 5/3/1\n" /* y = 0 */
                       "f -5 -1 -2 -6\n"       /* y = 1: 4 8 7 3 */
                       "f\t1  5\t8 4   \n"     /* x = 0 */
                       "f 2 3 7\nf 2 7 6\n"    /* x = 1 */
                       "l 1 2\nfoo bar\n";     /* unknown statements are ignored */
    CHECK(load_text("cube.obj", cube, &m, err, sizeof err) == 0, "%s", err);
    CHECK(m.nverts == 8 && m.ntris == 12, "%u verts %u tris", m.nverts, m.ntris);
    CHECK(!m.normals, "normals when only some face vertices give one");
    CHECK(closed(&m, err, sizeof err) == 0, "%s", err);
    CHECK(signed_volume(&m) == 1.0, "volume %g", signed_volume(&m));
    /* the quad 1 4 3 2 becomes fan triangles (1 4 3), (1 3 2) */
    CHECK(m.tris[0] == 0 && m.tris[1] == 3 && m.tris[2] == 2 && m.tris[3] == 0 && m.tris[4] == 2 &&
              m.tris[5] == 1,
          "fan triangulation");
    mesh_free(&m);

    /* upper-case extension, a long polygon on one line, no final newline */
    size_t n = 2000, cap = 64 + n * 40;
    char *big = malloc(cap), *p = big;
    for (size_t i = 0; i < n; i++) {
        double a = 2 * PI * (double)i / (double)n;
        p += sprintf(p, "v %.9f %.9f 0\n", cos(a), sin(a));
    }
    p += sprintf(p, "f");
    for (size_t i = 1; i <= n; i++) p += sprintf(p, " %zu", i);
    CHECK(load_text("disc.OBJ", big, &m, err, sizeof err) == 0, "%s", err);
    CHECK(m.ntris == n - 2, "%u triangles from a %zu-gon", m.ntris, n);
    mesh_free(&m);
    free(big);
}

static void test_obj_normals(void)
{
    char err[512] = "";
    Mesh m;
    /* two triangles sharing an edge; vertex 2 gets two different normals */
    const char *obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                      "vn 0 0 2\nvn 0 0.6 0.8\n"
                      "f 1//1 2//1 3//1\n"
                      "f 2/1/2 4//1 3//1\n";
    CHECK(load_text("n.obj", obj, &m, err, sizeof err) == 0, "%s", err);
    CHECK(m.normals != NULL, "no normals");
    /* distinct (position, normal) pairs: (1,1) (2,1) (3,1) (2,2) (4,1) */
    CHECK(m.nverts == 5 && m.ntris == 2, "%u verts %u tris", m.nverts, m.ntris);
    if (m.normals && m.nverts == 5) {
        CHECK(m.normals[0].z == 1.0f, "normal not normalised: %g", m.normals[0].z);
        CHECK(m.tris[2] == 2 && m.tris[5] == 2, "vertex 3 with normal 1 not shared");
        CHECK(m.tris[3] == 3 && m.normals[3].y == 0.6f, "second normal of vertex 2");
    }
    mesh_free(&m);
}

static void test_obj_errors(void)
{
    const char *cube8 = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";
    char buf[512];
    EXPECT_ERROR("a.obj", "v 0 0 0\nv 1 2\nf 1 1 1\n", "a.obj:2: expected 3 numbers after 'v'");
    EXPECT_ERROR("b.obj", "v 0 0 0\nv 1 2 x\n", "b.obj:2: expected 3 numbers after 'v'");
    snprintf(buf, sizeof buf, "%sf 1 2 3\nf 1 2 12\n", cube8);
    EXPECT_ERROR("c.obj", buf, "c.obj:10: face index 12 out of range (8 vertices)");
    snprintf(buf, sizeof buf, "%sf 1 2 -9\n", cube8);
    EXPECT_ERROR("d.obj", buf, "d.obj:9: face index -9 out of range (8 vertices)");
    snprintf(buf, sizeof buf, "%sf 0 1 2\n", cube8);
    EXPECT_ERROR("e.obj", buf, "e.obj:9: face index 0 out of range");
    EXPECT_ERROR("f.obj", "v nan 0 0\n", "f.obj:1:", "non-finite");
    EXPECT_ERROR("g.obj", "v 0 0 0\nv inf 0 0\n", "g.obj:2:", "non-finite");
    EXPECT_ERROR("h.obj", "v 0 0 1e999\n", "h.obj:1:", "non-finite");
    EXPECT_ERROR("i.obj", "v 0 0 1e39\n", "i.obj:1:", "non-finite");
    snprintf(buf, sizeof buf, "%sf 1 2\n", cube8);
    EXPECT_ERROR("j.obj", buf, "j.obj:9:", "face with 2 vertices");
    snprintf(buf, sizeof buf, "%sf 1 2 3x\n", cube8);
    EXPECT_ERROR("k.obj", buf, "k.obj:9:", "malformed");
    snprintf(buf, sizeof buf, "%svn 0 0 1\nf 1//1 2//2 3//1\n", cube8);
    EXPECT_ERROR("l.obj", buf, "l.obj:10:", "normal index 2 out of range (1 normals)");
    snprintf(buf, sizeof buf, "%sf 1 2 99999999999999999999\n", cube8);
    EXPECT_ERROR("m.obj", buf, "m.obj:9:", "out of range");
    EXPECT_ERROR("n.obj", cube8, "n.obj: no faces");
    EXPECT_ERROR("o.obj", "", "o.obj: no faces");
    EXPECT_ERROR("p.obj", "vn 1 0\n", "p.obj:1: expected 3 numbers after 'vn'");
    EXPECT_ERROR("model.stl", "solid\n", "model.stl", "'.stl'");

    Mesh m;
    mesh_init(&m);
    char err[256] = "";
    CHECK(mesh_load("/nonexistent/vbcl/x.obj", &m, err, sizeof err) == -1, "missing file");
    CHECK(strstr(err, "/nonexistent/vbcl/x.obj: cannot open: No such file or directory"), "%s",
          err);
}

/* ---- PLY ---- */

/* Little writer for binary PLY bodies. */
typedef struct Buf {
    unsigned char d[4096];
    size_t n;
    int big;
} Buf;

static void put(Buf *b, const void *v, size_t size)
{
    const unsigned char *p = v;
    for (size_t i = 0; i < size; i++) b->d[b->n++] = p[b->big ? size - 1 - i : i];
}
static void put_f32(Buf *b, float f)
{
    put(b, &f, 4);
}
static void put_f64(Buf *b, double f)
{
    put(b, &f, 8);
}
static void put_u8(Buf *b, uint8_t v)
{
    put(b, &v, 1);
}
static void put_i16(Buf *b, int16_t v)
{
    put(b, &v, 2);
}
static void put_i32(Buf *b, int32_t v)
{
    put(b, &v, 4);
}
static void put_text(Buf *b, const char *s)
{
    memcpy(b->d + b->n, s, strlen(s));
    b->n += strlen(s);
}

static const float cube_v[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                   {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
static const int cube_f[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                 {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};

static const char *ply_header_fmt = "ply\n"
                                    "format %s 1.0\n"
                                    "comment made by test_mesh\n"
                                    "obj_info nothing\n"
                                    "element vertex 8\n"
                                    "property float x\n"
                                    "property uchar flags\n"
                                    "property double y\n"
                                    "property list uchar int16 extra\n"
                                    "property float32 z\n"
                                    "property float nx\n"
                                    "property float ny\n"
                                    "property float nz\n"
                                    "element edge 2\n"
                                    "property list uint8 int pair\n"
                                    "property ushort weight\n"
                                    "element face 6\n"
                                    "property int8 material\n"
                                    "property list uchar int vertex_indices\n"
                                    "end_header\n";

/* A cube PLY (quads, extra properties and elements) in the given format. */
static void make_cube_ply(Buf *b, const char *format)
{
    b->n = 0;
    b->big = strcmp(format, "binary_big_endian") == 0;
    char head[1024];
    snprintf(head, sizeof head, ply_header_fmt, format);
    put_text(b, head);
    int ascii = strcmp(format, "ascii") == 0;
    char line[256];
    for (int i = 0; i < 8; i++) {
        const float *v = cube_v[i];
        vec3 n = v3_norm(v3(v[0] - 0.5f, v[1] - 0.5f, v[2] - 0.5f));
        if (ascii) {
            snprintf(line, sizeof line, "%g 7 %g 2 -5 300 %g %.9g %.9g %.9g\n", v[0], v[1], v[2],
                     n.x, n.y, n.z);
            put_text(b, line);
        } else {
            put_f32(b, v[0]);
            put_u8(b, 7);
            put_f64(b, v[1]);
            put_u8(b, 2);
            put_i16(b, -5);
            put_i16(b, 300);
            put_f32(b, v[2]);
            put_f32(b, n.x);
            put_f32(b, n.y);
            put_f32(b, n.z);
        }
    }
    for (int i = 0; i < 2; i++) {
        if (ascii) {
            put_text(b, "2 0 1 65535\n");
        } else {
            put_u8(b, 2);
            put_i32(b, 0);
            put_i32(b, 1);
            put_i16(b, -1); /* ushort 65535 */
        }
    }
    for (int i = 0; i < 6; i++) {
        const int *f = cube_f[i];
        if (ascii) {
            snprintf(line, sizeof line, "-1 4 %d %d %d %d\n", f[0], f[1], f[2], f[3]);
            put_text(b, line);
        } else {
            put_u8(b, 0xff);
            put_u8(b, 4);
            for (int k = 0; k < 4; k++) put_i32(b, f[k]);
        }
    }
}

static void test_ply_formats_agree(void)
{
    const char *formats[3] = {"ascii", "binary_little_endian", "binary_big_endian"};
    Mesh m[3];
    char err[512] = "", name[32];
    static Buf b;
    for (int k = 0; k < 3; k++) {
        make_cube_ply(&b, formats[k]);
        snprintf(name, sizeof name, "cube%d.PLY", k);
        mesh_init(&m[k]);
        CHECK(mesh_load(write_file(name, b.d, b.n), &m[k], err, sizeof err) == 0, "%s: %s",
              formats[k], err);
        CHECK(m[k].nverts == 8 && m[k].ntris == 12 && m[k].normals, "%s: %u verts %u tris",
              formats[k], m[k].nverts, m[k].ntris);
        CHECK(closed(&m[k], err, sizeof err) == 0, "%s: %s", formats[k], err);
        CHECK(signed_volume(&m[k]) == 1.0, "%s: volume %g", formats[k], signed_volume(&m[k]));
        CHECK(count_inward(&m[k], v3(0.5f, 0.5f, 0.5f)) == 0, "%s: inward", formats[k]);
    }
    CHECK(same_mesh(&m[0], &m[1]), "ascii and little-endian meshes differ");
    CHECK(same_mesh(&m[1], &m[2]), "little- and big-endian meshes differ");
    for (int k = 0; k < 3; k++) mesh_free(&m[k]);

    /* minimal file: vertex_index, CRLF header, no normals */
    Mesh t;
    const char *tri = "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty float x\r\n"
                      "property float y\r\nproperty float z\r\nelement face 1\r\n"
                      "property list uchar uint vertex_index\r\nend_header\r\n"
                      "0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n";
    CHECK(load_text("tri.ply", tri, &t, err, sizeof err) == 0, "%s", err);
    CHECK(t.nverts == 3 && t.ntris == 1 && !t.normals, "%u verts", t.nverts);
    mesh_free(&t);

    /* an element without properties holds no bytes, so any count of it is read at once
     * (the fuzzer's 2^31 empty items once took seconds, one at a time) */
    const char *empty = "ply\nformat binary_little_endian 1.0\nelement nothing 2147483647\n"
                        "element vertex 3\nproperty uchar x\nproperty uchar y\nproperty uchar z\n"
                        "element face 1\nproperty list uchar uchar vertex_indices\nend_header\n"
                        "\0\0\0\1\0\0\0\1\0\3\0\1\2";
    CHECK(mesh_load(write_file("empty.ply", empty, strlen(empty) + 13), &t, err, sizeof err) == 0,
          "%s", err);
    CHECK(t.nverts == 3 && t.ntris == 1, "%u verts %u tris", t.nverts, t.ntris);
    mesh_free(&t);
}

static const char *ply_tri_head = "ply\nformat %s 1.0\nelement vertex %s\nproperty float x\n"
                                  "property float y\nproperty float z\nelement face %s\n"
                                  "property list uchar int vertex_indices\nend_header\n";

static void test_ply_errors(void)
{
    char buf[2048];
    static Buf b;
    EXPECT_ERROR("a.ply",
                 "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                 "property flaot y\nend_header\n",
                 "a.ply: line 5 of header: unknown property type 'flaot'");
    EXPECT_ERROR("b.ply", "plx\nformat ascii 1.0\nend_header\n", "b.ply:", "not a PLY");
    EXPECT_ERROR("c.ply", "ply\nformat ascii 2.0\nend_header\n", "c.ply: line 2 of header");
    EXPECT_ERROR("d.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", "d.ply:", "end_header");
    EXPECT_ERROR("e.ply", "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
                 "e.ply: line 3 of header", "before any element");
    EXPECT_ERROR("f.ply",
                 "ply\nformat ascii 1.0\nelement face 1\nproperty list float int "
                 "vertex_indices\nend_header\n",
                 "f.ply: line 4 of header", "not an integer");

    /* face 10 (0-based) names vertex 99 of 8 */
    snprintf(buf, sizeof buf, ply_tri_head, "ascii", "8", "12");
    for (int i = 0; i < 8; i++) strcat(buf, "0 0 0\n");
    for (int i = 0; i < 12; i++) strcat(buf, i == 10 ? "3 0 1 99\n" : "3 0 1 2\n");
    EXPECT_ERROR("g.ply", buf, "g.ply:28: face 10: index 99 out of range (8 vertices)");
    /* the same in binary */
    b.n = 0;
    b.big = 0;
    snprintf(buf, sizeof buf, ply_tri_head, "binary_little_endian", "8", "12");
    put_text(&b, buf);
    for (int i = 0; i < 24; i++) put_f32(&b, 0.0f);
    for (int i = 0; i < 12; i++) {
        put_u8(&b, 3);
        put_i32(&b, 0);
        put_i32(&b, i == 10 ? 99 : 1);
        put_i32(&b, i == 10 ? -1 : 2);
    }
    {
        const char *const w[] = {"h.ply: face 10: index 99 out of range (8 vertices)", NULL};
        expect_load_error("h.ply", (const char *)b.d, b.n, w);
    }
    /* negative index */
    snprintf(buf, sizeof buf, ply_tri_head, "ascii", "3", "1");
    strcat(buf, "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n");
    EXPECT_ERROR("i.ply", buf, "i.ply:13: face 0: index -1 out of range (3 vertices)");
    /* truncated binary: the file ends inside vertex 3 */
    b.n = 0;
    snprintf(buf, sizeof buf, ply_tri_head, "binary_little_endian", "8", "1");
    put_text(&b, buf);
    for (int i = 0; i < 24; i++) put_f32(&b, 0.0f);
    put_u8(&b, 3);
    for (int i = 0; i < 3; i++) put_i32(&b, i);
    size_t full = b.n;
    {
        const char *const w[] = {"j.ply: unexpected end of file in vertex 3", NULL};
        expect_load_error("j.ply", (const char *)b.d, full - 13 - 12 * 4 - 6, w);
        /* inside the face's index list */
        const char *const w2[] = {"k.ply: unexpected end of file in face 0", NULL};
        expect_load_error("k.ply", (const char *)b.d, full - 2, w2);
    }
    /* ASCII ending early */
    snprintf(buf, sizeof buf, ply_tri_head, "ascii", "3", "1");
    strcat(buf, "0 0 0\n1 0 0\n0 1 0\n3 0 1\n");
    EXPECT_ERROR("l.ply", buf, "l.ply: unexpected end of file in face 0");
    snprintf(buf, sizeof buf, ply_tri_head, "ascii", "3", "1");
    strcat(buf, "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n");
    EXPECT_ERROR("m.ply", buf, "m.ply:11: vertex 1: bad number 'zero'");
    snprintf(buf, sizeof buf, ply_tri_head, "ascii", "3", "1");
    strcat(buf, "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n");
    EXPECT_ERROR("n.ply", buf, "n.ply:11: vertex 1:");
    snprintf(buf, sizeof buf, ply_tri_head, "ascii", "3", "1");
    strcat(buf, "0 0 0\n1 0 0\n0 1 0\n300 0 1 2\n");
    EXPECT_ERROR("o.ply", buf, "o.ply:13: face 0:", "does not fit");
    snprintf(buf, sizeof buf, ply_tri_head, "ascii", "3", "0");
    strcat(buf, "0 0 0\n1 0 0\n0 1 0\n");
    EXPECT_ERROR("p.ply", buf, "p.ply: no faces");

    /* absurd counts fail before anything is allocated for them */
    snprintf(buf, sizeof buf, ply_tri_head, "binary_little_endian", "2147483648", "1");
    EXPECT_ERROR("q.ply", buf, "q.ply: line 3 of header", "too large");
    snprintf(buf, sizeof buf, ply_tri_head, "binary_little_endian", "2147483647", "1");
    strcat(buf, "tiny");
    EXPECT_ERROR("r.ply", buf, "r.ply: unexpected end of file in vertex 0");
    snprintf(buf, sizeof buf, ply_tri_head, "ascii", "2147483647", "1");
    strcat(buf, "0 0 0\n");
    EXPECT_ERROR("s.ply", buf, "s.ply: unexpected end of file", "2147483647");
    snprintf(buf, sizeof buf, ply_tri_head, "binary_big_endian", "3", "99999999999999999999");
    EXPECT_ERROR("t.ply", buf, "t.ply: line 7 of header", "too large");
    /* a list length far beyond the file */
    b.n = 0;
    b.big = 1;
    snprintf(buf, sizeof buf,
             "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\n"
             "property float y\nproperty float z\nelement face 1\n"
             "property list uint int vertex_indices\nend_header\n");
    put_text(&b, buf);
    for (int i = 0; i < 9; i++) put_f32(&b, (float)i);
    put_i32(&b, 0x7fffffff);
    put_i32(&b, 0);
    {
        const char *const w[] = {"u.ply: unexpected end of file in face 0", NULL};
        expect_load_error("u.ply", (const char *)b.d, b.n, w);
    }
}

/* Loads every prefix of a valid file, and corrupted variants: must never crash. */
static void test_truncations_dont_crash(void)
{
    static Buf b;
    char err[512];
    const char *formats[3] = {"ascii", "binary_little_endian", "binary_big_endian"};
    for (int k = 0; k < 3; k++) {
        make_cube_ply(&b, formats[k]);
        int ok = 0;
        for (size_t len = 0; len < b.n; len++) {
            Mesh m;
            mesh_init(&m);
            ok += mesh_load(write_file("cut.ply", b.d, len), &m, err, sizeof err) == 0;
            mesh_free(&m);
        }
        /* ASCII may still parse when only the final newline is missing */
        CHECK(ok <= 1, "%s: %d truncated files loaded", formats[k], ok);
        unsigned seed = 12345;
        for (int trial = 0; trial < 300; trial++) {
            static Buf c;
            c = b;
            for (int f = 0; f < 4; f++) {
                seed = seed * 1103515245u + 12345u;
                c.d[(seed >> 8) % c.n] = (unsigned char)(seed >> 20);
            }
            Mesh m;
            mesh_init(&m);
            mesh_load(write_file("junk.ply", c.d, c.n), &m, err, sizeof err);
            mesh_free(&m);
            Mesh o;
            mesh_init(&o);
            mesh_load(write_file("junk.obj", c.d, c.n), &o, err, sizeof err);
            mesh_free(&o);
        }
    }
}

static void cleanup_tmpdir(void)
{
    if (!tmpdir[0]) return;
    DIR *d = opendir(tmpdir);
    struct dirent *e;
    char path[512];
    while (d && (e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        snprintf(path, sizeof path, "%s/%s", tmpdir, e->d_name);
        unlink(path);
    }
    if (d) closedir(d);
    rmdir(tmpdir);
    tmpdir[0] = 0;
}

void suite_mesh(void)
{
    RUN_TEST(test_sphere_closed_outward);
    RUN_TEST(test_part_convex);
    RUN_TEST(test_box_exact);
    RUN_TEST(test_prism_both_windings);
    RUN_TEST(test_quad_open);
    RUN_TEST(test_revolution_cylinder);
    RUN_TEST(test_revolution_poles);
    RUN_TEST(test_check_closed_errors);
    RUN_TEST(test_transform_negative_scale);
    RUN_TEST(test_obj_face_forms);
    RUN_TEST(test_obj_normals);
    RUN_TEST(test_obj_errors);
    RUN_TEST(test_ply_formats_agree);
    RUN_TEST(test_ply_errors);
    RUN_TEST(test_truncations_dont_crash);
    cleanup_tmpdir();
}
