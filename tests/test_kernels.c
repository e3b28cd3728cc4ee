/* test_kernels.c — the kernels on the device they run on: struct layout as the device
 * compiles it, the grid against brute force, irradiance from spherical lights against
 * the closed form, and rays through the edges and vertices of a closed mesh. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "render.h"
#include "offset.h"
#include "fixture.h"
#include "testutil.h"

/* Closest hits of rays through the grid (scene_intersect_closest). */
static void trace_grid(Fixture *fx, cl_mem rays, int n, cl_mem hits, cl_mem counters)
{
    fixture_run_frame_kernel(fx, "scene_intersect_closest", rays, n, hits, counters);
}

/* The closest hits of n rays through the grid (hg) and by brute force (hb). */
static void trace_grid_and_brute(Fixture *fx, const VbRay *rays, int n, VbHit *hg, VbHit *hb)
{
    cl_mem mr = buffer(rays, sizeof *rays * (size_t)n);
    cl_mem mg = buffer(NULL, sizeof *hg * (size_t)n), mb = buffer(NULL, sizeof *hb * (size_t)n);
    cl_uint zero[VBCL_COUNTER_WORDS] = {0};
    cl_mem mc = buffer(zero, sizeof zero);
    trace_grid(fx, mr, n, mg, mc);
    cl_uint ntris = fx->s.mesh.ntris;
    const size_t sz[] = {sizeof(cl_mem), sizeof(cl_uint), sizeof(cl_mem), sizeof(int),
                         sizeof(cl_mem)};
    const void *v[] = {&fx->r.buf.tris, &ntris, &mr, &n, &mb};
    run_kernel(fx->r.probe, "probe_intersect_brute", (size_t)n, 5, sz, v);
    read_buffer(mg, hg, sizeof *hg * (size_t)n);
    read_buffer(mb, hb, sizeof *hb * (size_t)n);
    clReleaseMemObject(mr);
    clReleaseMemObject(mg);
    clReleaseMemObject(mb);
    clReleaseMemObject(mc);
}

static void test_kernel_struct_layout(void)
{
    Fixture fx;
    if (fixture_open(
            &fx,
            "{\"camera\": {\"eye\": [0,0,5], \"look_at\": [0,0,0]}, \"materials\": {\"m\": {}},"
            " \"objects\": [{\"shape\": \"box\", \"material\": \"m\"}]}"))
        return;
    enum { N = VBCL_LAYOUT_COUNT };
    cl_uint out[N] = {0};
    cl_mem m = buffer(NULL, sizeof out);
    const size_t sz[] = {sizeof(cl_mem)};
    const void *v[] = {&m};
    run_kernel(fx.r.probe, "probe_layout", 1, 1, sz, v);
    read_buffer(m, out, sizeof out);
#define HOST_LAYOUT_ITEM(e) (cl_uint)(e),
    const cl_uint want[N] = {VBCL_LAYOUT_ITEMS(HOST_LAYOUT_ITEM)};
#undef HOST_LAYOUT_ITEM
    for (int i = 0; i < N; i++)
        CHECK(out[i] == want[i], "layout item %d: device %u, host %u", i, out[i], want[i]);
    CHECK(N >= 38, "only %d layout items", N);
    clReleaseMemObject(m);
    fixture_close(&fx);
}

static float frand(unsigned *state)
{
    *state = *state * 1664525u + 1013904223u;
    return (float)(*state >> 8) * (1.0f / 16777216.0f);
}

/* Random rays: half from a sphere around the scene toward a random point inside its
 * bounds, half from inside the bounds in a random direction. */
static void random_rays(const Scene *s, VbRay *rays, int n, unsigned seed)
{
    vec3 lo, hi;
    mesh_bounds(&s->mesh, &lo, &hi);
    vec3 c = v3_scale(v3_add(lo, hi), 0.5f), ext = v3_sub(hi, lo);
    float rad = v3_len(ext);
    for (int i = 0; i < n; i++) {
        vec3 target = v3(lo.x + ext.x * frand(&seed), lo.y + ext.y * frand(&seed),
                         lo.z + ext.z * frand(&seed));
        vec3 org, dir;
        if (i & 1) {
            org = v3(lo.x + ext.x * frand(&seed), lo.y + ext.y * frand(&seed),
                     lo.z + ext.z * frand(&seed));
            dir = v3_norm(v3(frand(&seed) - 0.5f, frand(&seed) - 0.5f, frand(&seed) - 0.5f));
        } else {
            vec3 u = v3_norm(v3(frand(&seed) - 0.5f, frand(&seed) - 0.5f, frand(&seed) - 0.5f));
            org = v3_add(c, v3_scale(u, rad * 1.5f));
            dir = v3_norm(v3_sub(target, org));
        }
        VbRay *r = &rays[i];
        r->org[0] = org.x;
        r->org[1] = org.y;
        r->org[2] = org.z;
        r->dir[0] = dir.x;
        r->dir[1] = dir.y;
        r->dir[2] = dir.z;
        r->tmax = INFINITY;
        r->sample = (unsigned)i;
    }
}

/* Grid and brute force agree on the closest hit of n random rays for the scene. */
static void compare_grid_brute(const char *label, const char *json, const char *grid, int n)
{
    char text[4096];
    snprintf(text, sizeof text, json, grid);
    Fixture fx;
    if (fixture_open(&fx, text)) return;
    VbRay *rays = malloc(sizeof *rays * (size_t)n);
    VbHit *hg = malloc(sizeof *hg * (size_t)n), *hb = malloc(sizeof *hb * (size_t)n);
    random_rays(&fx.s, rays, n, 12345u);
    trace_grid_and_brute(&fx, rays, n, hg, hb);
    int hits = 0, ties = 0, bad = 0;
    for (int i = 0; i < n; i++) {
        hits += hb[i].tri >= 0;
        if (hg[i].tri == hb[i].tri) {
            if (hb[i].tri >= 0 && fabsf(hg[i].t - hb[i].t) > 1e-5f * fabsf(hb[i].t)) {
                bad++;
                CHECK(0, "%s grid %s ray %d: t %.9g vs brute %.9g", label, grid, i, hg[i].t,
                      hb[i].t);
            }
        } else if (hg[i].tri >= 0 && hb[i].tri >= 0 &&
                   fabsf(hg[i].t - hb[i].t) <= 1e-5f * fabsf(hb[i].t)) {
            ties++; /* two triangles at the same distance (a shared edge): either is right */
        } else {
            bad++;
            CHECK(0, "%s grid %s ray %d: triangle %d t %.9g vs brute %d t %.9g", label, grid, i,
                  hg[i].tri, hg[i].t, hb[i].tri, hb[i].t);
        }
    }
    fprintf(stderr,
            "    %s, grid %s (%dx%dx%d, %u sub-grids, %u leaves): %d rays, %d hit, %d ties at "
            "equal t, %d mismatches\n",
            label, grid, fx.r.cs->grid.n[0], fx.r.cs->grid.n[1], fx.r.cs->grid.n[2],
            fx.r.cs->grid.subgrids, fx.r.cs->grid.nleaves, n, hits, ties, bad);
    CHECK(hits > n / 10, "%s: enough rays hit (%d of %d)", label, hits, n);
    CHECK(ties < n / 1000 + 5, "%s: ties are rare (%d)", label, ties);
    free(rays);
    free(hg);
    free(hb);
    fixture_close(&fx);
}

#define CAM "\"camera\": {\"eye\": [0,0,9], \"look_at\": [0,0,0]}, "

/* Two spheres over a tilted slab: the rest of a scene after its camera or render entries. */
#define SPHERES_SCENE                                                                              \
    "\"materials\": {\"m\": {}}, \"objects\": ["                                                   \
    "{\"shape\": \"sphere\", \"level\": 4, \"radius\": 1.5, \"material\": \"m\"},"                 \
    "{\"shape\": \"sphere\", \"level\": 2, \"radius\": 0.4, \"centre\": [2, 1, 0], "               \
    "\"material\": \"m\"},"                                                                        \
    "{\"shape\": \"box\", \"size\": [6, 0.2, 6], \"material\": \"m\", \"transform\": "             \
    "{\"translate\": [0, -1.7, 0], \"rotate\": [10, 20, 0]}}]}"

/* Writes soup.obj: n random triangles in [-2, 2]^3, every eighth one large (up to the
 * scene's size, spanning many cells in front of and behind small ones), the rest small. */
static void write_triangle_soup(int n, unsigned seed)
{
    size_t cap = (size_t)n * 200 + 64, len = 0;
    char *text = malloc(cap);
    for (int i = 0; i < n; i++) {
        float c[3], size = (i % 8 == 0) ? 3.0f : 0.3f;
        for (int a = 0; a < 3; a++) c[a] = 4.0f * frand(&seed) - 2.0f;
        for (int v = 0; v < 3; v++) {
            float p[3];
            for (int a = 0; a < 3; a++) {
                p[a] = c[a] + size * (frand(&seed) - 0.5f);
                p[a] = p[a] < -2.0f ? -2.0f : p[a] > 2.0f ? 2.0f : p[a];
            }
            len += (size_t)snprintf(text + len, cap - len, "v %.6f %.6f %.6f\n", (double)p[0],
                                    (double)p[1], (double)p[2]);
        }
    }
    for (int i = 0; i < n; i++)
        len += (size_t)snprintf(text + len, cap - len, "f %d %d %d\n", 3 * i + 1, 3 * i + 2,
                                3 * i + 3);
    tu_write_file("soup.obj", text);
    free(text);
}

/* The two-level grid against brute force, 10^6 rays in all: top levels 1, auto, 64^3 and
 * 7x3x19 with automatic sub-grids; given sub-grids (a 3x1x7 in every crowded cell, dense
 * ones); one level only (subgrid 1); boxes whose faces lie on top-cell and sub-cell faces;
 * a flat scene; a soup of large triangles spanning many cells among small ones. The %s of each
 * scene is the render object's grid entries. */
static void test_grid_matches_brute_force(void)
{
    static const char *spheres = "{" CAM "\"render\": {\"grid\": %s}, " SPHERES_SCENE;
    static const char *vase =
        "{" CAM "\"render\": {\"grid\": %s}, \"materials\": {\"m\": {}}, \"objects\": ["
        "{\"shape\": \"revolution\", \"segments\": 40, \"material\": \"m\","
        " \"profile\": [[0, 0], [0.5, 0], [0.8, 0.4], [0.9, 0.9], [0.6, 1.5], [0.3, 2], [0.45, "
        "2.2]]},"
        "{\"shape\": \"prism\", \"depth\": 3, \"material\": \"m\", \"transform\": {\"scale\": 2}},"
        "{\"shape\": \"quad\", \"size\": [8, 8], \"material\": \"m\"}]}";
    /* unit boxes tiling [-1, 1]^3 (faces at -1, 0, 1: top-cell faces of grids 2 and 4) and
     * half boxes with faces at +-0.5 (sub-cell faces of grid 2 with 2x2x2 sub-grids) */
    static const char *faces =
        "{" CAM "\"render\": {\"grid\": %s}, \"materials\": {\"m\": {}}, \"objects\": ["
        "{\"shape\": \"box\", \"material\": \"m\", \"transform\": {\"translate\": [0.5, 0.5, "
        "0.5]}},"
        "{\"shape\": \"box\", \"material\": \"m\", \"transform\": {\"translate\": [-0.5, 0.5, "
        "-0.5]}},"
        "{\"shape\": \"box\", \"material\": \"m\", \"transform\": {\"translate\": [-0.5, -0.5, "
        "0.5]}},"
        "{\"shape\": \"box\", \"material\": \"m\", \"transform\": {\"translate\": [0.5, -0.5, "
        "-0.5]}},"
        "{\"shape\": \"box\", \"size\": [0.5, 0.5, 0.5], \"material\": \"m\", \"transform\": "
        "{\"translate\": [0.25, -0.25, 0.75]}},"
        "{\"shape\": \"box\", \"size\": [0.5, 1, 0.5], \"material\": \"m\", \"transform\": "
        "{\"translate\": [-0.75, 0, 0.25]}}]}";
    /* one plane of quads and a disc of revolution in it: a flat scene */
    static const char *flat =
        "{" CAM "\"render\": {\"grid\": %s}, \"materials\": {\"m\": {}}, \"objects\": ["
        "{\"shape\": \"quad\", \"size\": [4, 4], \"material\": \"m\"},"
        "{\"shape\": \"quad\", \"size\": [1, 1], \"material\": \"m\", \"transform\": "
        "{\"translate\": [2.5, 0, 0.5]}},"
        "{\"shape\": \"revolution\", \"segments\": 64, \"material\": \"m\", \"transform\": "
        "{\"translate\": [-2.5, 0, -2]}, \"profile\": [[0, 0], [0.5, 0], [1, 0]]}]}";
    static const char *soup =
        "{" CAM "\"render\": {\"grid\": %s}, \"materials\": {\"m\": {}}, \"objects\": ["
        "{\"shape\": \"mesh\", \"file\": \"soup.obj\", \"material\": \"m\"}]}";
    write_triangle_soup(400, 99u);
    compare_grid_brute("triangle soup", soup, "3", 100000);
    compare_grid_brute("triangle soup", soup, "\"auto\"", 100000);
    static const char *grids[] = {"1", "\"auto\"", "64"};
    for (int g = 0; g < 3; g++) {
        compare_grid_brute("spheres and a slab", spheres, grids[g], 100000);
        compare_grid_brute("vase, prism and floor", vase, grids[g], 100000);
    }
    compare_grid_brute("spheres and a slab", spheres, "[7, 3, 19]", 100000);
    compare_grid_brute("spheres and a slab", spheres, "5, \"subgrid\": [3, 1, 7]", 100000);
    compare_grid_brute("vase, prism and floor", vase, "\"auto\", \"subgrid\": 1", 100000);
    compare_grid_brute("vase, prism and floor", vase, "2, \"subgrid_density\": 16", 100000);
    compare_grid_brute("boxes on cell faces", faces, "2, \"subgrid\": 2", 100000);
    compare_grid_brute("boxes on cell faces", faces, "4, \"subgrid\": [2, 4, 1]", 50000);
    compare_grid_brute("flat scene", flat, "\"auto\"", 50000);
    compare_grid_brute("flat scene", flat, "[4, 1, 4], \"subgrid\": [8, 1, 8]", 50000);
}

/* Camera rays through random points of the image, as camera_ray makes them from the frame's
 * camera; every eighth on a border of the image (pixel coordinate 0 or the width, 0 or the
 * height), where a tile's margin matters most. */
static void camera_rays(const VbCamera *c, VbRay *rays, int n, unsigned seed)
{
    for (int i = 0; i < n; i++) {
        float sx = 2.0f * frand(&seed) - 1.0f, sy = 1.0f - 2.0f * frand(&seed);
        if (i % 8 == 1) sx = (i & 16) ? 1.0f : -1.0f;
        if (i % 8 == 5) sy = (i & 16) ? 1.0f : -1.0f;
        vec3 d = v3_norm(v3(c->forward[0] + sx * c->right[0] + sy * c->up[0],
                            c->forward[1] + sx * c->right[1] + sy * c->up[1],
                            c->forward[2] + sx * c->right[2] + sy * c->up[2]));
        rays[i] = (VbRay){{c->eye[0], c->eye[1], c->eye[2]}, INFINITY, {d.x, d.y, d.z}, (cl_uint)i};
    }
}

/* Hits of n rays by probe_trace_closest: through the grid, or with camera set as camera
 * rays (camera_trace_closest). */
static void probe_hits(Fixture *fx, int camera, cl_mem rays, int n, VbHit *out)
{
    cl_mem m = buffer(NULL, sizeof *out * (size_t)n);
    const size_t sz[] = {sizeof(cl_mem), sizeof(int), sizeof(cl_mem), sizeof(int)};
    const void *v[] = {&rays, &n, &m, &camera};
    fixture_run_probe(fx, "probe_trace_closest", (size_t)n, 4, sz, v);
    read_buffer(m, out, sizeof *out * (size_t)n);
    clReleaseMemObject(m);
}

/* Camera tiles (camera_trace_closest) against the grid and brute force for the camera of
 * `json`: the same triangle and distance, bit for bit, as the grid on n rays, and the brute
 * force's (or a tie at equal distance) on the first nb of them. */
static void compare_camera_tiles(const char *label, const char *json, int n, int nb)
{
    Fixture fx;
    if (fixture_open(&fx, json)) return;
    const VbCamTiles *ct = &fx.r.frame_host.cam_tiles;
    CHECK(ct->nx > 0 && ct->ny > 0, "%s: the scene has camera tiles", label);
    VbRay *rays = malloc(sizeof *rays * (size_t)n);
    VbHit *hc = malloc(sizeof *hc * (size_t)n), *hg = malloc(sizeof *hg * (size_t)n);
    VbHit *hb = malloc(sizeof *hb * (size_t)nb);
    camera_rays(&fx.r.frame_host.camera, rays, n, 4242u);
    cl_mem mr = buffer(rays, sizeof *rays * (size_t)n);
    probe_hits(&fx, 1, mr, n, hc);
    probe_hits(&fx, 0, mr, n, hg);
    cl_uint ntris = fx.s.mesh.ntris;
    cl_mem mb = buffer(NULL, sizeof *hb * (size_t)nb);
    const size_t sz[] = {sizeof(cl_mem), sizeof(cl_uint), sizeof(cl_mem), sizeof(int),
                         sizeof(cl_mem)};
    const void *v[] = {&fx.r.buf.tris, &ntris, &mr, &nb, &mb};
    run_kernel(fx.r.probe, "probe_intersect_brute", (size_t)nb, 5, sz, v);
    read_buffer(mb, hb, sizeof *hb * (size_t)nb);
    int hits = 0, differ = 0, bad = 0, ties = 0;
    for (int i = 0; i < n; i++) {
        hits += hc[i].tri >= 0;
        if (hc[i].tri != hg[i].tri || memcmp(&hc[i].t, &hg[i].t, sizeof(float)) != 0) {
            if (differ++ < 5)
                CHECK(0, "%s ray %d: tiles triangle %d t %.9g, grid %d t %.9g", label, i, hc[i].tri,
                      hc[i].t, hg[i].tri, hg[i].t);
        }
        if (i >= nb || hc[i].tri == hb[i].tri) continue;
        if (hc[i].tri >= 0 && hb[i].tri >= 0 && fabsf(hc[i].t - hb[i].t) <= 1e-5f * hb[i].t)
            ties++;
        else if (bad++ < 5)
            CHECK(0, "%s ray %d: tiles triangle %d t %.9g, brute force %d t %.9g", label, i,
                  hc[i].tri, hc[i].t, hb[i].tri, hb[i].t);
    }
    fprintf(stderr,
            "    %s: %dx%d tiles; %d camera rays, %d hit, %d differ from the grid; "
            "%d against brute force: %d ties at equal t, %d mismatches\n",
            label, ct->nx, ct->ny, n, hits, differ, nb, ties, bad);
    CHECK(differ == 0 && bad == 0, "%s: %d differ from the grid, %d from brute force", label,
          differ, bad);
    CHECK(hits > n / 10, "%s: enough rays hit (%d of %d)", label, hits, n);
    clReleaseMemObject(mr);
    clReleaseMemObject(mb);
    free(rays);
    free(hc);
    free(hg);
    free(hb);
    fixture_close(&fx);
}

/* Camera tiles against the grid on 1.05 * 10^6 camera rays (and brute force on 140,000):
 * cameras outside the scene and inside it (triangles behind the eye and across the plane
 * through it, which go to every tile), an image whose sides are no multiple of the tile's,
 * a triangle soup, and a textured prism (textures in contact with their host). */
static void test_camera_tiles_match_grid(void)
{
    static const char *spheres =
        "{\"image\": {\"width\": 97, \"height\": 61}, \"camera\": %s, " SPHERES_SCENE;
    static const char *vase =
        "{\"image\": {\"width\": 120, \"height\": 90}, \"camera\": %s, \"materials\": "
        "{\"m\": {}}, \"objects\": ["
        "{\"shape\": \"revolution\", \"segments\": 40, \"material\": \"m\","
        " \"profile\": [[0, 0], [0.5, 0], [0.8, 0.4], [0.9, 0.9], [0.6, 1.5], [0.3, 2], [0.45, "
        "2.2]]},"
        "{\"shape\": \"prism\", \"depth\": 3, \"material\": \"m\", \"transform\": {\"scale\": 2}},"
        "{\"shape\": \"quad\", \"size\": [8, 8], \"material\": \"m\"}]}";
    static const char *soup =
        "{\"image\": {\"width\": 64, \"height\": 64}, \"camera\": %s, \"materials\": "
        "{\"m\": {}}, \"objects\": ["
        "{\"shape\": \"mesh\", \"file\": \"soup.obj\", \"material\": \"m\"}]}";
    static const char *textured =
        "{\"image\": {\"width\": 100, \"height\": 100}, \"camera\": %s, \"materials\": "
        "{\"glass\": {\"k_global\": 1, \"eta\": 1.5}, \"s\": {}, \"floor\": {}}, \"objects\": ["
        "{\"shape\": \"quad\", \"size\": [8, 8], \"material\": \"floor\"},"
        "{\"shape\": \"prism\", \"depth\": 1.6, \"material\": \"glass\", \"points\": [[-0.9, 0], "
        "[0.9, 0], [0, 1.5]], \"texture\": {\"generate\": \"bomb --shape sphere --count 30 "
        "--size 8:18 --seed 4 --level 2\", \"material\": \"s\"}}]}";
    const struct {
        const char *label, *json, *camera;
    } cases[] = {
        {"spheres, from outside", spheres, "{\"eye\": [0, 0, 9], \"look_at\": [0, 0, 0]}"},
        {"spheres, from inside the big one", spheres,
         "{\"eye\": [0.3, 0.2, 1], \"look_at\": [-2, -1, -3], \"fov\": 100}"},
        {"vase, from above", vase, "{\"eye\": [3, 5, 6], \"look_at\": [0, 0.8, 0]}"},
        {"vase, eye on the floor", vase,
         "{\"eye\": [-0.5, 0.05, 3.5], \"look_at\": [0, 0.5, 0], \"fov\": 80}"},
        {"triangle soup, eye inside", soup, "{\"eye\": [0.1, 0.2, 1.9], \"look_at\": [0, 0, 0]}"},
        {"textured prism", textured, "{\"eye\": [0.3, 2, 5], \"look_at\": [0, 0.7, 0]}"},
        {"textured prism, eye inside", textured,
         "{\"eye\": [0.1, 0.5, 0.3], \"look_at\": [-1, 0.3, -2], \"fov\": 90}"},
    };
    write_triangle_soup(400, 99u);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char text[4096];
        snprintf(text, sizeof text, cases[i].json, cases[i].camera);
        compare_camera_tiles(cases[i].label, text, 150000, 20000);
    }
    /* render.camera_tiles: false leaves camera rays to the grid; not a boolean: an error */
    Fixture fx;
    if (fixture_open(&fx, "{" CAM "\"render\": {\"camera_tiles\": false}, \"materials\": "
                          "{\"m\": {}}, \"objects\": [{\"shape\": \"box\", "
                          "\"material\": \"m\"}]}") == 0) {
        CHECK(fx.r.frame_host.cam_tiles.nx == 0, "camera_tiles false: %d tiles per row",
              fx.r.frame_host.cam_tiles.nx);
        fixture_close(&fx);
    }
    Scene sc;
    char err[512];
    const char *path =
        tu_write_file("cam_flag.json", "{" CAM "\"render\": {\"camera_tiles\": 1}, \"materials\": "
                                       "{\"m\": {}}, \"objects\": [{\"shape\": \"box\", "
                                       "\"material\": \"m\"}]}");
    CHECK(scene_load(path, &sc, err, sizeof err) != 0 && strstr(err, "render.camera_tiles") &&
              strstr(err, "expected true or false"),
          "camera_tiles 1: %s", err);
}

/* grid_cell_box_range: for random boxes in random top cells (mostly inside the cell, some
 * crossing its faces, some flat), the leaves it gives hold every triangle of the cell that
 * overlaps the box within the cell (exact test on the host), only triangles of the cell, and
 * fewer than the whole list where the cell has a sub-grid and the box is small. */
static void test_grid_cell_box_range(void)
{
    static const char *json =
        "{" CAM "\"render\": {\"grid\": 3}, \"materials\": {\"m\": {}}, \"objects\": ["
        "{\"shape\": \"sphere\", \"level\": 4, \"radius\": 1.5, \"material\": \"m\"},"
        "{\"shape\": \"box\", \"size\": [6, 0.2, 6], \"material\": \"m\", \"transform\": "
        "{\"translate\": [0, -1.7, 0], \"rotate\": [10, 20, 0]}}]}";
    Fixture fx;
    if (fixture_open(&fx, json)) return;
    const Grid *g = &fx.r.cs->grid;
    enum { NQ = 2000 };
    cl_uint ntris = fx.s.mesh.ntris, nq = NQ;
    float *q = calloc(12 * NQ, sizeof *q);
    unsigned char *mark = calloc((size_t)NQ * ntris, 1);
    unsigned seed = 4242u;
    for (int i = 0; i < NQ; i++) {
        float *p = q + 12 * i;
        for (int a = 0; a < 3; a++) {
            int c = (int)(frand(&seed) * g->n[a]);
            p[a] = (float)(c < g->n[a] ? c : g->n[a] - 1);
            float lo = g->lo[a] + p[a] * g->cell[a];
            float u = frand(&seed) * 1.2f - 0.1f, w = (i % 7 == 0) ? 0.0f : 0.3f * frand(&seed);
            p[4 + a] = lo + u * g->cell[a];
            p[8 + a] = lo + (u + w) * g->cell[a];
        }
    }
    cl_mem mf = buffer(&fx.r.frame_host, sizeof fx.r.frame_host), mq = buffer(q, 12 * NQ * 4);
    cl_mem mm = buffer(mark, (size_t)NQ * ntris);
    const size_t sz[] = {sizeof(cl_mem), sizeof(cl_mem),  sizeof(cl_mem),  sizeof(cl_mem),
                         sizeof(cl_mem), sizeof(cl_uint), sizeof(cl_uint), sizeof(cl_mem)};
    const void *v[] = {
        &mf, &fx.r.buf.grid_cells, &fx.r.buf.leaf_start, &fx.r.buf.leaf_quads, &mq, &nq, &ntris,
        &mm};
    run_kernel(fx.r.probe, "probe_grid_box_range", NQ, 8, sz, v);
    read_buffer(mm, mark, (size_t)NQ * ntris);
    int missing = 0, foreign = 0, restricted = 0, crowded = 0;
    for (int i = 0; i < NQ; i++) {
        const float *p = q + 12 * i;
        uint32_t c =
            (uint32_t)p[0] + (uint32_t)g->n[0] * ((uint32_t)p[1] + g->n[1] * (uint32_t)p[2]);
        float centre[3], half[3];
        int empty = 0;
        for (int a = 0; a < 3; a++) { /* the box within the cell */
            float lo = g->lo[a] + p[a] * g->cell[a], hi = lo + g->cell[a];
            float b0 = fmaxf(p[4 + a], lo), b1 = fminf(p[8 + a], hi);
            empty |= b0 > b1;
            centre[a] = 0.5f * (b0 + b1);
            half[a] = 0.5f * (b1 - b0);
        }
        uint32_t in_list = 0, marked = 0;
        for (uint32_t t = 0; t < ntris; t++) {
            int listed = 0;
            for (uint32_t k = g->cell_start[c]; k < g->cell_start[c + 1] && !listed; k++)
                listed = g->cell_tris[k] == t;
            in_list += listed;
            marked += mark[(size_t)i * ntris + t];
            foreign += mark[(size_t)i * ntris + t] && !listed;
            if (!listed || empty || mark[(size_t)i * ntris + t]) continue;
            float tri[3][3];
            for (int k = 0; k < 3; k++) {
                vec3 pt = fx.s.mesh.verts[fx.s.mesh.tris[3 * t + (uint32_t)k]];
                tri[k][0] = pt.x, tri[k][1] = pt.y, tri[k][2] = pt.z;
            }
            if (grid_tri_box_overlap(centre, half, tri) && ++missing <= 5)
                CHECK(0, "query %d: triangle %u overlaps the box in cell %u but was not visited", i,
                      t, c);
        }
        int n[3];
        grid_sub_unpack(g->cells[2 * c + 1], n);
        crowded += n[0] * n[1] * n[2] > 1;
        restricted += n[0] * n[1] * n[2] > 1 && marked < in_list;
    }
    fprintf(stderr,
            "    %d queries: %d in cells with a sub-grid, %d of them visiting part of the "
            "list; %d triangles missed, %d from other cells\n",
            NQ, crowded, restricted, missing, foreign);
    CHECK(missing == 0 && foreign == 0, "%d triangles missed, %d foreign", missing, foreign);
    CHECK(crowded > NQ / 10 && restricted > crowded / 2,
          "the boxes restrict too rarely: %d of %d queries in sub-grids", restricted, crowded);
    clReleaseMemObject(mf);
    clReleaseMemObject(mq);
    clReleaseMemObject(mm);
    free(q);
    free(mark);
    fixture_close(&fx);
}

/* A glass box standing on an opaque floor: its bottom face lies in the floor's plane.
 * Rays from inside the glass toward the bottom meet both at the same distance up to
 * rounding; the floor, the surface in contact with the glass, must win every time, in the
 * grid and in brute force (before the contact rule about half of them found the glass face,
 * and the next ray's offset origin then skipped the floor: a per-pixel speckle). */
static void test_contact_opaque_surface_first(void)
{
    static const char *json =
        "{" CAM "\"render\": {\"grid\": %s}, \"materials\": {\"floor\": {}, \"glass\": "
        "{\"k_global\": 1, \"eta\": 1.5}}, \"objects\": ["
        "{\"shape\": \"quad\", \"size\": [4, 4], \"material\": \"floor\"},"
        "{\"shape\": \"box\", \"material\": \"glass\", \"transform\": {\"rotate\": [0, 15, "
        "0], \"translate\": [0.3, 0.5, -0.2]}}]}";
    static const char *grids[] = {"1", "\"auto\"", "[7, 5, 3]"};
    enum { N = 20000 };
    for (int g = 0; g < 3; g++) {
        char text[2048];
        snprintf(text, sizeof text, json, grids[g]);
        Fixture fx;
        if (fixture_open(&fx, text)) return;
        VbRay *rays = calloc(N, sizeof *rays);
        VbHit *hg = calloc(N, sizeof *hg), *hb = calloc(N, sizeof *hb);
        unsigned seed = 777u + (unsigned)g;
        for (int i = 0; i < N; i++) { /* from inside the box, down to its bottom face */
            float x = 0.3f + 0.4f * (frand(&seed) - 0.5f), z = -0.2f + 0.4f * (frand(&seed) - 0.5f);
            vec3 d = v3_norm(v3(0.5f * (frand(&seed) - 0.5f), -1.0f, 0.5f * (frand(&seed) - 0.5f)));
            rays[i] =
                (VbRay){{x, 0.1f + 0.8f * frand(&seed), z}, INFINITY, {d.x, d.y, d.z}, (cl_uint)i};
        }
        trace_grid_and_brute(&fx, rays, N, hg, hb);
        int floor_g = 0, floor_b = 0;
        for (int i = 0; i < N; i++) {
            floor_g += hg[i].tri >= 0 && (fx.s.tri_tag[hg[i].tri] & ~VBCL_TAG_FLAGS) == 0;
            floor_b += hb[i].tri >= 0 && (fx.s.tri_tag[hb[i].tri] & ~VBCL_TAG_FLAGS) == 0;
        }
        fprintf(stderr,
                "    grid %s: %d of %d rays from inside the glass hit the floor (brute "
                "force %d)\n",
                grids[g], floor_g, N, floor_b);
        CHECK(floor_g == N && floor_b == N,
              "grid %s: the floor in contact must come first: grid %d, brute force %d of %d",
              grids[g], floor_g, floor_b, N);
        free(rays);
        free(hg);
        free(hb);
        fixture_close(&fx);
    }
}

/* Local shading at points under a spherical light, diffuse reflectance 1, no ambient:
 * outgoing radiance = E / pi with E = pi L sin^2(alpha) cos(beta) whenever the whole cap
 * is above the horizon (alpha: the cap's half angle, beta: the tilt of the normal). Three
 * times: a purely diffuse surface, which light_cap_closed_form shades by that closed form (to
 * 1e-6, where the feelers' estimate is off by up to 2e-5); the same with a specular term of
 * 1e-7 and exponent 1, which the feelers estimate (1024 of them, to 1e-3); and with a specular
 * term of 1 and exponent 200, whose lobe (about the normal: the viewer looks along it) misses
 * the caps tilted by 40 and 60 degrees, so those are the closed form again (to 1e-6), and the
 * other cases are not checked (their highlight is not in the formula). */
static void test_light_irradiance_closed_form(void)
{
    static const char *const materials[3] = {
        "{\"diffuse\": [1, 1, 1]}",
        "{\"diffuse\": [1, 1, 1], \"specular\": [1e-7, 1e-7, 1e-7], \"exponent\": 1}",
        "{\"diffuse\": [1, 1, 1], \"specular\": [1, 1, 1], \"exponent\": 200}"};
    const double exponent[3] = {0, 1, 200};
    for (int mi = 0; mi < 3; mi++) {
        Fixture fx;
        char json[1024];
        /* the only geometry is a small box far behind the light, so nothing occludes */
        snprintf(json, sizeof json,
                 "{" CAM "\"render\": {\"shadow_samples\": 1024, \"ambient\": [0, 0, 0]},"
                 " \"lights\": [{\"centre\": [0, 0, 0], \"radius\": 1, \"flux\": 1000},"
                 "              {\"centre\": [0, 0, 0], \"radius\": 0, \"intensity\": 0.001}],"
                 " \"materials\": {\"m\": %s},"
                 " \"objects\": [{\"shape\": \"box\", \"material\": \"m\", \"transform\": "
                 "{\"translate\": [0, 0, -100]}}]}",
                 materials[mi]);
        if (fixture_open(&fx, json)) return;
        const double tol = mi == 1 ? 1e-3 : 1e-6;
        fprintf(stderr, "    %s:\n", materials[mi]);
        const double flux = 1000.0, R = 1.0, I_point = 0.001;
        const double L = flux / (4.0 * M_PI * M_PI * R * R);
        enum { N = 6 };
        /* distance d, tilt beta (degrees), in the plane of x and y */
        const double cases[N][2] = {{5, 0}, {1.05, 0}, {20, 40}, {3, 60}, {1.5, 30}, {2, 25}};
        float pts[N * 4], nrm[N * 4], out[N * 4];
        for (int i = 0; i < N; i++) {
            double d = cases[i][0], b = cases[i][1] * M_PI / 180.0;
            /* point on +x at distance d; the normal points back at the light, tilted by beta */
            pts[4 * i] = (float)d, pts[4 * i + 1] = 0, pts[4 * i + 2] = 0, pts[4 * i + 3] = 0;
            nrm[4 * i] = (float)-cos(b), nrm[4 * i + 1] = (float)sin(b), nrm[4 * i + 2] = 0,
                    nrm[4 * i + 3] = 0;
        }
        if (fixture_shade_points(&fx, pts, nrm, N, out)) {
            fixture_close(&fx);
            return;
        }
        for (int i = 0; i < N; i++) {
            double d = cases[i][0], b = cases[i][1] * M_PI / 180.0, s2 = R * R / (d * d);
            double alpha = asin(R / d);
            CHECK(b + alpha < M_PI / 2, "case %d: the cap must be above the horizon", i);
            double e_sphere = M_PI * L * s2 * cos(b);
            double e_point = I_point * cos(b) / (d * d);
            double want = (e_sphere + e_point) / M_PI;
            double got = out[4 * i];
            /* the lobe's reach about the mirror direction (the normal): 2 acos(nh_min) */
            double reach = mi == 2 ? 2.0 * acos(exp(-9.2103 / exponent[mi])) : 0.0;
            if (mi == 2 && b <= alpha + reach + 0.01) continue;
            fprintf(stderr,
                    "    d %.2f tilt %2.0f: radiance %.6g, closed form %.6g (rel. error %.2e)\n", d,
                    cases[i][1], got, want, fabs(got - want) / want);
            CHECK(fabs(got - want) <= tol * want, "%s case %d: radiance %.6g, closed form %.6g",
                  materials[mi], i, got, want);
        }
        /* facing away from both lights: no feelers, no light */
        nrm[0] = 1, nrm[1] = 0, nrm[2] = 0;
        if (fixture_shade_points(&fx, pts, nrm, 1, out) == 0)
            CHECK(out[0] == 0.0f && out[3] == 0.0f, "facing away: radiance %g, %g feelers traced",
                  out[0], out[3]);
        fixture_close(&fx);
    }
}

/* Random shading points for the cone probes, 16 floats each (probe_cone_brute's layout):
 * an object of the fixture's scene at random, one of its triangles (or of its texture's),
 * a point on it, either side; a light of random place and size; and in float 14 the host
 * whose inside the point's side lies in (-1: none): the object itself seen from inside,
 * or the host of a texture point seen from outside its part. */
static void cone_cases(const Fixture *fx, float *cases, int ncases, unsigned seed)
{
    const Mesh *m = &fx->s.mesh;
    for (int i = 0; i < ncases; i++) {
        float *c = cases + 16 * i;
        /* an object at random, then one of its triangles (or of its texture's) */
        const SceneObject *ob =
            &fx->s.objects[(int)(frand(&seed) * (float)fx->s.nobjects) % fx->s.nobjects];
        int tex = ob->ntex_tris > 0 && frand(&seed) < 0.5f;
        uint32_t t = tex ? ob->first_tex_tri +
                               (uint32_t)(frand(&seed) * (float)ob->ntex_tris) % ob->ntex_tris
                         : ob->first_tri + (uint32_t)(frand(&seed) * (float)ob->ntris) % ob->ntris;
        vec3 a = m->verts[m->tris[3 * t]], b = m->verts[m->tris[3 * t + 1]],
             d = m->verts[m->tris[3 * t + 2]];
        float u = frand(&seed), v = frand(&seed);
        if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
        vec3 e1 = v3_sub(b, a), e2 = v3_sub(d, a);
        vec3 p = v3_add(a, v3_add(v3_scale(e1, u), v3_scale(e2, v)));
        float side = frand(&seed) < 0.5f ? 1.0f : -1.0f;
        vec3 n = v3_scale(v3_norm(v3_cross(e1, e2)), side);
        uint32_t tag = fx->s.tri_tag[t];
        /* the bound of p's distance from the plane (offset.h), as for a point interpolated
         * with weights (1, u, v) on a and the edges: 3 terms, each rounded */
        float err = vb_offset_error(n.x, n.y, n.z, vb_offset_sum(1.0f, u, v, a.x, e1.x, e2.x),
                                    vb_offset_sum(1.0f, u, v, a.y, e1.y, e2.y),
                                    vb_offset_sum(1.0f, u, v, a.z, e1.z, e2.z));
        float pv[16] = {
            p.x,
            p.y,
            p.z,
            (tag & VBCL_TAG_TEXTURE) ? -1.0f : (float)(tag & ~VBCL_TAG_FLAGS),
            n.x,
            n.y,
            n.z,
            side,
            16.0f * frand(&seed) - 8.0f,
            8.0f * frand(&seed) + 2.0f,
            16.0f * frand(&seed) - 8.0f,
            frand(&seed) * frand(&seed),
            err,
            (float)t,
            ob->is_host && (tex ? side > 0.0f : side < 0.0f) ? (float)(ob - fx->s.objects) : -1.0f,
            0};
        memcpy(c, pv, sizeof pv);
    }
}

/* Runs cone probe `kernel` (probe_cone_brute's arguments) on ncases random cases
 * (cone_cases with seed), nrays feelers each; returns its output per case (malloc'd; NULL,
 * a failed check, when out of memory) and the cases in *cases_out. */
static unsigned *run_cone_probe(Fixture *fx, const char *kernel, int ncases, int nrays,
                                unsigned seed, float **cases_out)
{
    float *cases = calloc((size_t)ncases * 16, sizeof(float));
    unsigned *out = calloc((size_t)ncases, sizeof(unsigned));
    *cases_out = cases;
    if (!cases || !out) {
        CHECK(0, "out of memory for %d cases", ncases);
        free(out);
        return NULL;
    }
    cone_cases(fx, cases, ncases, seed);
    cl_mem mc = buffer(cases, sizeof(float) * 16 * (size_t)ncases),
           mo = buffer(NULL, sizeof(unsigned) * (size_t)ncases);
    const size_t sz[] = {sizeof(cl_mem), sizeof(int), sizeof(int), sizeof(cl_mem)};
    const void *vals[] = {&mc, &ncases, &nrays, &mo};
    fixture_run_probe(fx, kernel, (size_t)ncases, 4, sz, vals);
    read_buffer(mo, out, sizeof(unsigned) * (size_t)ncases);
    clReleaseMemObject(mc);
    clReleaseMemObject(mo);
    return out;
}

/* The scene of the shadow cone test and of the ray trees' sets, the small sphere of material
 * SPHERE ("m": opaque; "g": a glass host): a floor and a tilted wall (planar), a box, a prism
 * and the sphere (convex), a vase (neither), a glass prism with a texture of bombed spheres,
 * some reaching out of it, and a glass ball of 320 triangles whose bombed spheres reach out
 * of it or lie wholly outside. */
#define CONE_SCENE(SPHERE)                                                                         \
    "{" CAM "\"materials\": {\"m\": {}, \"g\": {\"k_local\": 0.1, "                                \
    "\"k_global\": 0.9, \"eta\": 1.5}, \"e\": {\"diffuse\": [1, 0, 0]}},"                          \
    " \"objects\": ["                                                                              \
    "{\"shape\": \"quad\", \"size\": [10, 10], \"material\": \"m\"},"                              \
    "{\"shape\": \"quad\", \"size\": [6, 3], \"material\": \"m\","                                 \
    " \"transform\": {\"rotate\": [70, 20, 0], \"translate\": [0, 2, -3]}},"                       \
    "{\"shape\": \"box\", \"size\": [1, 2, 0.5], \"material\": \"m\","                             \
    " \"transform\": {\"rotate\": [10, 30, 5], \"translate\": [-2, 1, 0]}},"                       \
    "{\"shape\": \"prism\", \"material\": \"m\","                                                  \
    " \"transform\": {\"translate\": [2, 0.5, 1]}},"                                               \
    "{\"shape\": \"sphere\", \"level\": 1, \"radius\": 0.6, \"centre\": [0, 2.5, 1],"              \
    " \"material\": \"" SPHERE "\"},"                                                              \
    "{\"shape\": \"revolution\", \"segments\": 12, \"material\": \"m\","                           \
    " \"profile\": [[0.5, 0], [0.2, 0.6], [0.6, 1.2], [0.3, 1.6]],"                                \
    " \"transform\": {\"translate\": [0.5, 0, -1]}},"                                              \
    "{\"shape\": \"prism\", \"depth\": 1.6, \"points\": [[-0.9, 0], [0.9, 0], [0, 1.5]],"          \
    " \"material\": \"g\", \"transform\": {\"rotate\": [0, 25, 0], \"translate\": [-0.5, "         \
    "0.05, 2]},"                                                                                   \
    " \"texture\": {\"generate\": \"bomb --shape sphere --count 6 --size 20:30 --seed 3\","        \
    " \"material\": \"e\"}},"                                                                      \
    "{\"shape\": \"sphere\", \"level\": 2, \"radius\": 0.7, \"centre\": [2.5, 1.2, -2.5],"         \
    " \"material\": \"g\", \"texture\": {\"generate\": \"bomb --shape sphere --count 12 "          \
    "--size 14:24 --seed 8 --level 1\", \"material\": \"e\"}}]}"

/* Whether p lies behind the plane of every own triangle of object o (inside it, where o is
 * convex). */
static int inside_own_planes(const Mesh *m, const SceneObject *o, vec3 p)
{
    for (uint32_t t = o->first_tri; t < o->first_tri + o->ntris; t++) {
        vec3 a = m->verts[m->tris[3 * t]], b = m->verts[m->tris[3 * t + 1]],
             d = m->verts[m->tris[3 * t + 2]];
        if (v3_dot(v3_cross(v3_sub(b, a), v3_sub(d, a)), v3_sub(p, a)) > 0.0f) return 0;
    }
    return 1;
}

/* The object sets of ray-tree rays (light.cl, ray_objects) against the grid: from points on
 * every kind of surface of the shadow cone test's scene (planar, convex, neither, a textured
 * glass prism whose few own triangles are tested alone, a glass ball of 320 triangles with
 * a texture of bombed spheres reaching out of it, a glass sphere of 80 triangles without
 * one: both shells, VBCL_OBJECT_INNER), rays in every direction, each from the side it
 * leaves to, every fourth turned back, in the medium of that side. Each follows its way
 * through medium_trace twice, with its set and through the grid, and both must find the
 * same first interface at the same distance with the same medium state and pass-through
 * count, bit for bit, on over a million rays. The sets must be used, and every way of
 * theirs taken: shells, searches cut where a ray leaves its convex host, start objects left
 * behind, big records walked. Its teeth: with the inner sphere 3% too big 12,764 rays differ,
 * and with the cut at 0.97 of the way out of the host 8,677. */
static void test_ray_objects_brute(void)
{
    Fixture fx;
    if (fixture_open(&fx, CONE_SCENE("g"))) return;
    enum { CASES = 8192, RAYS = 128 };
    const Mesh *m = &fx.s.mesh;
    float *cases = calloc((size_t)CASES * 16, sizeof(float));
    unsigned *out = calloc(CASES, sizeof(unsigned));
    if (!cases || !out) {
        CHECK(0, "out of memory for %d cases", CASES);
        free(cases);
        free(out);
        fixture_close(&fx);
        return;
    }
    cone_cases(&fx, cases, CASES, 77);
    for (int i = 0; i < CASES; i++) { /* the hosts on either side of the point */
        float *c = cases + 16 * i;
        uint32_t tag = fx.s.tri_tag[(uint32_t)c[13]];
        const SceneObject *ob = &fx.s.objects[tag & ~VBCL_TAG_FLAGS];
        int obj = (int)(ob - fx.s.objects);
        if (!ob->is_host) {
            c[14] = c[15] = -1.0f;
        } else if (tag & VBCL_TAG_TEXTURE) { /* both sides in the host, or both out of it */
            c[14] = c[15] = inside_own_planes(m, ob, (vec3){c[0], c[1], c[2]}) ? (float)obj : -1.0f;
        } else { /* the inside lies against the outward normal */
            c[14] = c[7] < 0.0f ? (float)obj : -1.0f;
            c[15] = c[7] < 0.0f ? -1.0f : (float)obj;
        }
    }
    cl_mem mc = buffer(cases, sizeof(float) * 16 * CASES),
           mo = buffer(NULL, sizeof(unsigned) * CASES);
    int ncases = CASES, nrays = RAYS;
    const size_t sz[] = {sizeof(cl_mem), sizeof(int), sizeof(int), sizeof(cl_mem)};
    const void *vals[] = {&mc, &ncases, &nrays, &mo};
    fixture_run_probe(&fx, "probe_ray_objects", CASES, 4, sz, vals);
    read_buffer(mo, out, sizeof(unsigned) * CASES);
    clReleaseMemObject(mc);
    clReleaseMemObject(mo);
    long wrong = 0, used[7] = {0, 0, 0, 0, 0, 0, 0};
    for (int i = 0; i < CASES; i++) {
        unsigned nb = out[i] & 0xffffu;
        for (int b = 0; b < 7; b++) used[b] += (out[i] >> (16 + b)) & 1u;
        if (nb && wrong < 3) {
            const float *c = cases + 16 * i;
            fprintf(stderr,
                    "    rays differ: point (%g %g %g) on triangle %g (object %g), normal (%g %g "
                    "%g), hosts %g / %g: %u rays, the first ray %u\n",
                    c[0], c[1], c[2], c[13], c[3], c[4], c[5], c[6], c[14], c[15], nb,
                    (out[i] >> 23) - 1u);
        }
        wrong += nb;
    }
    fprintf(stderr,
            "    %u triangles, %d points, %ld rays: %ld points with sets (%ld with a shell, %ld "
            "with searches cut at the host's way out, %ld leaving their own object behind, %ld "
            "walking big records, %ld finding interfaces, %ld leaving a part of their host's "
            "texture behind its plane); %ld rays differ from the grid's\n",
            m->ntris, CASES, (long)CASES * RAYS, used[0], used[1], used[2], used[3], used[4],
            used[5], used[6], wrong);
    CHECK(wrong == 0, "%ld rays follow another way with their object set than through the grid",
          wrong);
    CHECK(used[0] > CASES / 2 && used[1] > CASES / 50 && used[2] > CASES / 50 &&
              used[3] > CASES / 10 && used[4] > CASES / 10 && used[5] > CASES / 10 &&
              used[6] > CASES / 100,
          "the sets' ways are not all taken: sets %ld, shells %ld, cut %ld, own %ld, big %ld, "
          "found %ld, parts behind %ld",
          used[0], used[1], used[2], used[3], used[4], used[5], used[6]);
    free(cases);
    free(out);
    fixture_close(&fx);
}

/* The shadow cone test (light_cone_objects) against brute force: points on every kind of
 * surface (a floor and a tilted wall: planar; a box, a prism, a sphere: convex; a vase:
 * neither; a glass prism with a texture of bombed spheres, some reaching out of it, each
 * sphere a part bounded on its own), on either side, under lights of random places and
 * sizes. Wherever the test says the cone is clear, none of 128 feelers per point over the
 * light's cap (its rim included), each tested against every triangle, may meet one; over
 * a million such feelers. The test must also find clear cones, planar and convex surfaces'
 * own included. Where it names a few triangles as the only ones in the way, the closest
 * hit among them is every feeler's closest hit of all, the big spheres' triangles aside,
 * which such a feeler may meet only outside the prism (where they change nothing), and a
 * feeler kept off the grid beside the sphere or the vase (objects of more than 16 triangles,
 * whose bounding spheres each feeler tests) must miss them, and one that meets their bounds,
 * traced through the set and the grid only where it lies in them (object_set_span), must get
 * the closest and the any hit of a walk of its whole way, bit for bit; such
 * sets must also come from points on the texture's spheres (the prism's triangles without
 * the spheres the cone misses). Feelers that pass through the core of a solid sphere,
 * which a render does not trace, must meet that sphere and, where the probe knows their
 * medium, be stopped by the walk through the grid. A glass ball of 320 triangles holds a
 * texture of bombed spheres, many of them reaching out of it or lying wholly outside: a
 * feeler from outside it that meets the bounds of the ball with its texture but not the
 * sphere of the ball's own triangles (VbObject.own) keeps off the grid, and must still get
 * every hit that matters (texture triangles met outside that sphere change nothing); over
 * 1% of the points have such feelers. Its teeth: with that sphere 3% too small, 71 clear
 * cones and 33 sets are wrong. */
static void test_light_cone_brute(void)
{
    Fixture fx;
    if (fixture_open(&fx, CONE_SCENE("m"))) return;
    enum { CASES = 16384, RAYS = 128 };
    const Mesh *m = &fx.s.mesh;
    float *cases;
    unsigned *out = run_cone_probe(&fx, "probe_cone_brute", CASES, RAYS, 99, &cases);
    if (!out) {
        free(cases);
        fixture_close(&fx);
        return;
    }
    long count[4] = {0, 0, 0, 0}, wrong[4] = {0, 0, 0, 0}, own_clear = 0, tex_sets = 0;
    long big_sets = 0, big_met = 0, blocked = 0, shell = 0;
    for (int i = 0; i < CASES; i++) {
        unsigned kind = out[i] & 3u, nb = (out[i] >> 6) & 1023u;
        big_sets += (out[i] & 4u) != 0;
        big_met += (out[i] & 8u) != 0;
        blocked += (out[i] & 16u) != 0;
        shell += kind != 0 && (out[i] & 32u) != 0;
        count[kind]++;
        wrong[kind] += nb != 0;
        int obj = (int)cases[16 * i + 3];
        own_clear += kind == 1 && obj >= 0 && obj <= 4; /* the planar and convex ones */
        tex_sets += kind == 2 && obj < 0; /* on a bombed sphere: the box without the others */
        if (nb && wrong[kind] <= 3) {
            const float *c = cases + 16 * i;
            fprintf(stderr,
                    "    %s cone wrong: point (%g %g %g) on object %g, normal (%g %g %g) side %g, "
                    "light (%g %g %g) r %g: %u feelers, one with triangle %u\n",
                    kind == 1 ? "clear" : "object set", c[0], c[1], c[2], c[3], c[4], c[5], c[6],
                    c[7], c[8], c[9], c[10], c[11], nb, out[i] >> 16);
        }
    }
    fprintf(stderr,
            "    %u triangles, %d points: %ld clear cones (%ld on planar or convex objects, "
            "their own surface left out), %ld a set of objects alone, %ld the grid, %ld inside "
            "a light (%ld sets from points on the texture's spheres; %ld with spheres whose "
            "bounds each feeler tests, %ld with feelers that meet them, %ld with feelers through "
            "a solid sphere's core, %ld with feelers beside a host that meet its texture's "
            "bounds); %ld feelers against brute force\n",
            m->ntris, CASES, count[1], own_clear, count[2], count[0], count[3], tex_sets, big_sets,
            big_met, blocked, shell, (count[1] + count[2]) * RAYS);
    CHECK(wrong[1] == 0, "%ld clear cones have feelers that meet a triangle", wrong[1]);
    CHECK(wrong[2] == 0, "%ld cones' object sets miss a feeler's closest hit", wrong[2]);
    CHECK((count[1] + count[2]) * RAYS >= 1000000 && own_clear > count[1] / 4 &&
              count[2] > CASES / 20 && tex_sets > CASES / 100 && big_sets > CASES / 100 &&
              big_met > 0 && big_met < big_sets && blocked > CASES / 200 && shell > CASES / 100,
          "too few cones to test: %ld clear (%ld on planar or convex objects), %ld sets (%ld from "
          "texture points, %ld with big parts, %ld with feelers meeting them, %ld through a core, "
          "%ld beside a host)",
          count[1], own_clear, count[2], tex_sets, big_sets, big_met, blocked, shell);
    free(cases);
    free(out);
    fixture_close(&fx);
}

/* A feeler that leaves the one convex host its cone meets (ObjectSet.sole) is done: the
 * rest of its way meets nothing that changes it. The render's feelers (light_feeler_decided)
 * against the same feelers with every crossing followed through the same triangles
 * (probe_transmittance_plain), on A.4's objects (the front prism's texture of spheres, some
 * cut by its faces, the back prism a glass host of its own) and a glass vase of zigzag
 * profile (a host that is not convex, which a feeler leaves and enters again): 16,384
 * points on every surface, either side, each in the medium its side lies in, under lights
 * of random places and sizes, 128 feelers each over the light's cap. Every feeler gets
 * exactly the same through both ways; some sets must have a sole host, and over 10,000
 * feelers start inside one and get light through. Its teeth: with the vase taken as a sole
 * host 14,035 feelers differ, and with a feeler in air taken as leaving a sole host 188. */
static void test_light_sole_host(void)
{
    Fixture fx;
    if (fixture_open(
            &fx,
            "{" CAM "\"materials\": {\"floor\": {\"diffuse\": [0.7, 0.68, 0.62]}, "
            "\"glass\": {\"diffuse\": [0, 0, 0], \"specular\": [1, 1, 1], \"exponent\": 300, "
            "\"k_local\": 0.05, \"k_global\": 0.95, \"eta\": 1.501, \"extinction\": [0.1, 0.2, "
            "0.3]}, \"spheres\": {\"diffuse\": [0.85, 0.3, 0.1]}, \"dense\": {\"diffuse\": [0.2, "
            "0.25, 0.35], \"k_local\": 0.2, \"k_global\": 0.8, \"eta\": 3.227}},"
            " \"objects\": ["
            "{\"shape\": \"quad\", \"size\": [14, 14], \"material\": \"floor\"},"
            "{\"shape\": \"prism\", \"depth\": 1.6, \"material\": \"glass\", \"points\": [[-0.9, "
            "0.0], [0.9, 0.0], [0.0, 1.5]], \"transform\": {\"rotate\": [0, 15, 0], "
            "\"translate\": [0.5, 0, 1.0]}, \"texture\": {\"generate\": \"bomb --shape sphere "
            "--count 30 --size 8:18 --seed 4 --no-overlap --level 1\", \"material\": "
            "\"spheres\"}},"
            "{\"shape\": \"prism\", \"depth\": 1.4, \"material\": \"dense\", \"points\": [[-0.8, "
            "0.0], [0.8, 0.0], [0.0, 1.4]], \"transform\": {\"rotate\": [0, -25, 0], "
            "\"translate\": [-1.3, 0, -1.0]}},"
            "{\"shape\": \"revolution\", \"segments\": 12, \"material\": \"glass\","
            " \"profile\": [[0.8, 0], [0.1, 0.4], [0.8, 0.8], [0.1, 1.2], [0.8, 1.6]],"
            " \"transform\": {\"translate\": [2.5, 0, -1.5]}}]}"))
        return;
    enum { CASES = 16384, RAYS = 128 };
    float *cases;
    unsigned *out = run_cone_probe(&fx, "probe_sole_exit", CASES, RAYS, 4242, &cases);
    if (!out) {
        free(cases);
        fixture_close(&fx);
        return;
    }
    long sole = 0, wrong = 0, exits = 0;
    for (int i = 0; i < CASES; i++) {
        unsigned nb = (out[i] >> 1) & 32767u;
        sole += out[i] & 1u;
        wrong += nb;
        exits += out[i] >> 16;
        if (nb && wrong == nb) {
            const float *c = cases + 16 * i;
            fprintf(stderr,
                    "    point (%g %g %g) on object %g in host %g, normal (%g %g %g), light "
                    "(%g %g %g) r %g: %u feelers differ\n",
                    c[0], c[1], c[2], c[3], c[14], c[4], c[5], c[6], c[8], c[9], c[10], c[11], nb);
        }
    }
    fprintf(stderr,
            "    %d points: %ld cones with a sole host, %ld feelers leaving it with light, %ld "
            "differ from following every crossing\n",
            CASES, sole, exits, wrong);
    CHECK(wrong == 0, "%ld feelers get another amount through with the sole host", wrong);
    CHECK(sole > CASES / 20 && exits > 10000, "too few cases: %ld sole hosts, %ld feelers leaving",
          sole, exits);
    free(cases);
    free(out);
    fixture_close(&fx);
}

/* The host sets the cone test (VBCL_FRAME_CONE_TEST) by default, not with
 * "shadow_cone_test": false, nor for a scene of more than VBCL_CONE_TEST_MAX_OBJECTS
 * objects; a bad value of the key is refused. */
static void test_light_cone_flag(void)
{
    static char json[16384];
    for (int k = 0; k < 3; k++) {
        int n = snprintf(json, sizeof json,
                         "{" CAM "\"render\": {%s}, \"materials\": {\"m\": {}}, "
                         "\"objects\": [",
                         k == 1 ? "\"shadow_cone_test\": false" : "");
        int nobj = k == 2 ? VBCL_CONE_TEST_MAX_OBJECTS + 1 : 2;
        for (int i = 0; i < nobj; i++)
            n += snprintf(json + n, sizeof json - (size_t)n,
                          "%s{\"shape\": \"box\", \"size\": [0.1, 0.1, 0.1], \"material\": \"m\", "
                          "\"transform\": {\"translate\": [%d, 0, 0]}}",
                          i ? ", " : "", i);
        snprintf(json + n, sizeof json - (size_t)n, "]}");
        Fixture fx;
        if (fixture_open(&fx, json)) return;
        unsigned want = k == 0 ? VBCL_FRAME_CONE_TEST : 0u;
        CHECK((fx.r.frame_host.flags & VBCL_FRAME_CONE_TEST) == want &&
                  fx.r.frame_host.nobjects == (unsigned)nobj,
              "case %d (%d objects): frame flags %u, %u objects", k, nobj, fx.r.frame_host.flags,
              fx.r.frame_host.nobjects);
        fixture_close(&fx);
    }
    Scene s;
    char err[512];
    const char *path = tu_write_file(
        "cone_flag.json", "{" CAM "\"render\": {\"shadow_cone_test\": 1}, "
                          "\"materials\": {\"m\": {}}, \"objects\": [{\"shape\": \"box\", "
                          "\"material\": \"m\"}]}");
    CHECK(scene_load(path, &s, err, sizeof err) != 0 && strstr(err, "render.shadow_cone_test") &&
              strstr(err, "expected true or false"),
          "shadow_cone_test 1: %s", err);
}

/* Runs probe_cap_uv (mode LIGHT_FEELERS_*: 0 fixed, 1 jittered, 2 net): nkeys x strata^2
 * (u1, u2) pairs into uv. Returns 0 or -1. */
static int cap_uv(Fixture *fx, unsigned strata, unsigned nkeys, int mode, float *uv)
{
    size_t n = (size_t)nkeys * strata * strata;
    cl_mem mo = buffer(NULL, sizeof(float) * 2 * n);
    unsigned key0 = 12345;
    const size_t sz[] = {sizeof(unsigned), sizeof(unsigned), sizeof(unsigned), sizeof(int),
                         sizeof(cl_mem)};
    const void *v[] = {&strata, &key0, &nkeys, &mode, &mo};
    int rc = run_kernel(fx->r.probe, "probe_cap_uv", nkeys, 5, sz, v);
    read_buffer(mo, uv, sizeof(float) * 2 * n);
    clReleaseMemObject(mo);
    return rc;
}

/* The feelers' positions on the cap's unit square (light_cap_uv), for 256 points' keys:
 * with a power-of-two strata (4, 16, 64 feelers) each point's set is a (0, 2m, 2)-net, one
 * feeler in each cell of every elementary grid 2^a x 2^b (a + b = 2m), and the sets differ
 * from key to key (the scramble); the mean of u1 and u2 over all is 1/2 within 0.01. With 9
 * feelers each lies in its own third x third square; without jitter at the squares'
 * centres. The host picks the net for 16 feelers (the default), not for 9, nor with
 * shadow_jitter false. */
static void test_light_feelers_net(void)
{
    Fixture fx;
    if (fixture_open(&fx, "{" CAM "\"materials\": {\"m\": {}}, \"objects\": "
                          "[{\"shape\": \"box\", \"material\": \"m\"}]}"))
        return;
    enum { KEYS = 256 };
    static float uv[KEYS * 64 * 2];
    const unsigned stratas[] = {2, 4, 8};
    for (size_t s = 0; s < sizeof stratas / sizeof stratas[0]; s++) {
        unsigned n = stratas[s] * stratas[s], m2 = 0;
        while ((1u << m2) < n) m2++;
        if (cap_uv(&fx, stratas[s], KEYS, 2, uv)) break;
        int bad = 0, distinct = 0;
        double mean[2] = {0, 0};
        for (int k = 0; k < KEYS; k++) {
            const float *p = uv + (size_t)k * n * 2;
            for (unsigned a = 0; a <= m2; a++) { /* grid 2^a x 2^(m2 - a) */
                int seen[64] = {0};
                for (unsigned q = 0; q < n; q++) {
                    int cx = (int)(p[2 * q] * (float)(1u << a));
                    int cy = (int)(p[2 * q + 1] * (float)(1u << (m2 - a)));
                    seen[cx * (1 << (m2 - a)) + cy]++;
                }
                for (unsigned c = 0; c < n; c++) bad += seen[c] != 1;
            }
            for (unsigned q = 0; q < n; q++) mean[0] += p[2 * q], mean[1] += p[2 * q + 1];
            distinct += k > 0 && p[0] != uv[0];
        }
        mean[0] /= (double)KEYS * n, mean[1] /= (double)KEYS * n;
        fprintf(stderr, "    %u feelers: %d cells not holding one point, mean (%.4f, %.4f)\n", n,
                bad, mean[0], mean[1]);
        CHECK(bad == 0 && fabs(mean[0] - 0.5) < 0.01 && fabs(mean[1] - 0.5) < 0.01 &&
                  distinct > KEYS - 4,
              "%u feelers: %d empty or doubled cells, mean (%g, %g), %d of %d keys move the "
              "first point",
              n, bad, mean[0], mean[1], distinct, KEYS - 1);
    }
    for (int jitter = 1; jitter >= 0; jitter--) {
        if (cap_uv(&fx, 3, KEYS, jitter, uv)) break;
        int bad = 0;
        for (int k = 0; k < KEYS; k++)
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) {
                    const float *p = uv + ((size_t)k * 9 + (size_t)(i * 3 + j)) * 2;
                    if (jitter)
                        bad += (int)(p[0] * 3.0f) != i || (int)(p[1] * 3.0f) != j;
                    else
                        bad += fabsf(p[0] - (i + 0.5f) / 3.0f) > 1e-6f ||
                               fabsf(p[1] - (j + 0.5f) / 3.0f) > 1e-6f;
                }
        CHECK(bad == 0, "9 feelers, jitter %d: %d outside their squares or off centre", jitter,
              bad);
    }
    const unsigned placement = VBCL_FRAME_NET_FEELERS | VBCL_FRAME_FIXED_FEELERS;
    CHECK((fx.r.frame_host.flags & placement) == VBCL_FRAME_NET_FEELERS,
          "16 feelers: frame flags %u", fx.r.frame_host.flags);
    fixture_close(&fx);
    const char *other[2] = {"\"shadow_samples\": 9", "\"shadow_jitter\": false"};
    const unsigned want[2] = {0u, VBCL_FRAME_FIXED_FEELERS};
    for (int k = 0; k < 2; k++) {
        char json[512];
        snprintf(json, sizeof json,
                 "{" CAM "\"render\": {%s}, \"materials\": {\"m\": {}}, "
                 "\"objects\": [{\"shape\": \"box\", \"material\": \"m\"}]}",
                 other[k]);
        if (fixture_open(&fx, json)) return;
        CHECK((fx.r.frame_host.flags & placement) == want[k], "%s: frame flags %u, want %u",
              other[k], fx.r.frame_host.flags, want[k]);
        fixture_close(&fx);
    }
}

/* Rays aimed exactly at every vertex and every edge midpoint of closed meshes, from
 * outside toward the centre, must all hit: none slips between two triangles. */
static void test_rays_at_edges_and_vertices_hit(void)
{
    Fixture fx;
    if (fixture_open(&fx, "{" CAM "\"materials\": {\"m\": {}}, \"objects\": ["
                          "{\"shape\": \"sphere\", \"level\": 3, \"material\": \"m\"},"
                          "{\"shape\": \"revolution\", \"segments\": 12, \"material\": \"m\","
                          " \"profile\": [[0, -1], [1, 0], [0, 1]], \"transform\": {\"translate\": "
                          "[5, 0, 0]}}]}"))
        return;
    const Mesh *m = &fx.s.mesh;
    int n = (int)(m->nverts + 3 * m->ntris);
    VbRay *rays = calloc((size_t)n, sizeof *rays);
    VbHit *hits = calloc((size_t)n, sizeof *hits);
    int k = 0;
    for (uint32_t t = 0; t < m->ntris; t++) {
        for (int e = 0; e < 4; e++) {
            vec3 p;
            if (e == 3) {
                if (t >= m->nverts) continue;
                p = m->verts[t];
            } else {
                vec3 a = m->verts[m->tris[3 * t + e]], b = m->verts[m->tris[3 * t + (e + 1) % 3]];
                p = v3_scale(v3_add(a, b), 0.5f);
            }
            vec3 c = p.x > 2.5f ? v3(5, 0, 0) : v3(0, 0, 0);
            vec3 dir = v3_norm(v3_sub(p, c));
            vec3 org = v3_add(c, v3_scale(dir, 4.0f));
            VbRay *r = &rays[k++];
            r->org[0] = org.x, r->org[1] = org.y, r->org[2] = org.z;
            r->dir[0] = -dir.x, r->dir[1] = -dir.y, r->dir[2] = -dir.z;
            r->tmax = INFINITY;
        }
    }
    n = k;
    cl_mem mr = buffer(rays, sizeof *rays * (size_t)n), mh = buffer(NULL, sizeof *hits * (size_t)n);
    cl_uint zero[VBCL_COUNTER_WORDS] = {0};
    cl_mem mc = buffer(zero, sizeof zero);
    trace_grid(&fx, mr, n, mh, mc);
    read_buffer(mh, hits, sizeof *hits * (size_t)n);
    int miss = 0;
    for (int i = 0; i < n; i++) miss += hits[i].tri < 0;
    fprintf(stderr, "    %d rays at edges and vertices, %d leaked\n", n, miss);
    CHECK(miss == 0, "%d of %d rays at edges and vertices passed through", miss, n);
    clReleaseMemObject(mr);
    clReleaseMemObject(mh);
    clReleaseMemObject(mc);
    free(rays);
    free(hits);
    fixture_close(&fx);
}

/* A kernel that does not compile: NULL, the error recorded, and the build log and the
 * options printed on stderr. */
static void test_failed_build_prints_log_and_options(void)
{
    VbDevice *d = tu_device();
    if (!d) {
        th_skip("no OpenCL device");
        return;
    }
    char path[512];
    snprintf(path, sizeof path, "%s/build-log.txt", tu_tmpdir());
    fflush(stderr);
    int saved = dup(2);
    FILE *f = fopen(path, "w");
    if (!f || saved < 0) {
        CHECK(0, "cannot redirect stderr");
        return;
    }
    dup2(fileno(f), 2);
    double ms;
    int cached;
    clu_error_clear();
    cl_program p = clu_program_build(d, "__kernel void broken(__global float *x) { x[0] = y; }\n",
                                     "-DVBCL_MARKER_OPTION", &ms, &cached);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    fclose(f);
    CHECK(p == NULL, "a broken kernel must not build");
    if (p) clReleaseProgram(p);
    CHECK(strstr(clu_error(), "CL_BUILD_PROGRAM_FAILURE") != NULL, "error recorded: %s",
          clu_error());
    char log[8192] = "";
    f = fopen(path, "r");
    if (f) {
        size_t n = fread(log, 1, sizeof log - 1, f);
        log[n] = 0;
        fclose(f);
    }
    CHECK(strstr(log, "-DVBCL_MARKER_OPTION") != NULL, "options printed: %s", log);
    CHECK(strstr(log, "build log") != NULL && strstr(log, "y") != NULL, "log printed: %s", log);
    clu_error_clear();
}

/* The lobe test (light_lobe_misses_cap) against brute force: for 20,000 random points
 * (normal, viewer, direction to the light's centre at 0 – 1.2 rad from the mirror
 * direction, cap half-angles of sin 0.002 – 0.4, exponents 20 to 2000), wherever the test
 * lets a point without a diffuse term skip its feelers, no direction of 65 x 64 spread over
 * the cap (its rim included) has N.H above nh_min; and the test is not idle: it skips at
 * least half of the points whose cap the brute force finds outside the lobe. Exponent 20
 * (a lobe wider than 45 degrees) is never skipped. */
static void test_light_lobe_cap(void)
{
    Fixture fx;
    if (fixture_open(&fx, "{" CAM "\"materials\": {\"m\": {\"diffuse\": [0, 0, 0], "
                          "\"specular\": [1, 1, 1], \"exponent\": 300}}, \"objects\": "
                          "[{\"shape\": \"box\", \"material\": \"m\"}]}"))
        return;
    enum { N = 20000 };
    static float cases[N * 12], out[N * 3];
    const float exponents[] = {20.0f, 50.0f, 300.0f, 2000.0f};
    unsigned seed = 777;
    for (int i = 0; i < N; i++) {
        float *c = cases + 12 * i;
        vec3 n = v3_norm(v3(frand(&seed) - 0.5f, frand(&seed) - 0.5f, frand(&seed) - 0.5f));
        vec3 wo = v3_norm(v3(frand(&seed) - 0.5f, frand(&seed) - 0.5f, frand(&seed) - 0.5f));
        if (v3_dot(n, wo) < 0.0f) wo = v3_scale(wo, -1.0f);
        vec3 m = v3_sub(v3_scale(n, 2.0f * v3_dot(n, wo)), wo);
        vec3 p =
            v3_norm(v3_cross(m, v3(frand(&seed) - 0.5f, frand(&seed) - 0.5f, frand(&seed) - 0.5f)));
        float phi = 1.2f * frand(&seed);
        vec3 wc = v3_add(v3_scale(m, cosf(phi)), v3_scale(p, sinf(phi)));
        const vec3 v[3] = {n, wo, wc};
        for (int k = 0; k < 3; k++) c[3 * k] = v[k].x, c[3 * k + 1] = v[k].y, c[3 * k + 2] = v[k].z;
        c[9] = 0.002f + 0.398f * frand(&seed);
        c[10] = exponents[i % 4];
        c[11] = 0.0f;
    }
    cl_mem mc = buffer(cases, sizeof cases), mo = buffer(NULL, sizeof out);
    int n = N;
    const size_t sz[] = {sizeof(cl_mem), sizeof(int), sizeof(cl_mem)};
    const void *args[] = {&mc, &n, &mo};
    int rc = run_kernel(fx.r.probe, "probe_lobe_cap", N, 3, sz, args);
    read_buffer(mo, out, sizeof out);
    clReleaseMemObject(mc);
    clReleaseMemObject(mo);
    fixture_close(&fx);
    if (rc) return;
    int wrong = 0, skipped = 0, outside = 0, found = 0, wide = 0;
    for (int i = 0; i < N; i++) {
        const float *o = out + 3 * i;
        int skip = o[0] != 0.0f, out_of_lobe = o[1] <= o[2];
        wrong += skip && !out_of_lobe;
        skipped += skip;
        outside += out_of_lobe;
        found += skip && out_of_lobe;
        wide += skip && i % 4 == 0;
    }
    fprintf(stderr,
            "    %d of %d caps skipped; brute force: %d outside the lobe, %d of them "
            "skipped; %d wrongly\n",
            skipped, N, outside, found, wrong);
    CHECK(wrong == 0 && wide == 0 && outside > N / 10 && 2 * found >= outside,
          "%d caps skipped that reach the lobe, %d of exponent 20; %d of %d outside the lobe "
          "skipped",
          wrong, wide, found, outside);
}

void suite_kernels(void)
{
    RUN_TEST(test_failed_build_prints_log_and_options);
    RUN_PROBE_TEST(test_kernel_struct_layout);
    RUN_PROBE_TEST(test_grid_matches_brute_force);
    RUN_PROBE_TEST(test_camera_tiles_match_grid);
    RUN_PROBE_TEST(test_grid_cell_box_range);
    RUN_PROBE_TEST(test_contact_opaque_surface_first);
    RUN_PROBE_TEST(test_light_irradiance_closed_form);
    RUN_PROBE_TEST(test_light_feelers_net);
    RUN_PROBE_TEST(test_light_lobe_cap);
    RUN_PROBE_TEST(test_light_cone_brute);
    RUN_PROBE_TEST(test_ray_objects_brute);
    RUN_PROBE_TEST(test_light_sole_host);
    RUN_PROBE_TEST(test_light_cone_flag);
    RUN_PROBE_TEST(test_rays_at_edges_and_vertices_hit);
}
