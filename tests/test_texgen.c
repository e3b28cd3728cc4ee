/* test_texgen.c — the texture generator: closed, outward, disjoint elements; --no-overlap;
 * byte-identical output per seed; Fourier bound; projection texels; bad parameters. */
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "image_io.h"
#include "texgen.h"
#include "testutil.h"

static double signed_volume(const Mesh *m)
{
    double v = 0.0;
    for (uint32_t i = 0; i < m->ntris; i++) {
        vec3 a = m->verts[m->tris[3 * i]], b = m->verts[m->tris[3 * i + 1]],
             c = m->verts[m->tris[3 * i + 2]];
        v += v3_dot(a, v3_cross(b, c));
    }
    return v / 6.0;
}

/* Every element closed and outward (positive volume), and so the whole set. */
static void check_elements(const TexSet *t, const char *what)
{
    char err[512];
    Mesh all;
    mesh_init(&all);
    CHECK(t->count > 0, "%s: no elements", what);
    for (int e = 0; e < t->count; e++) {
        const Mesh *m = &t->elems[e];
        CHECK(mesh_check_closed(m, err, sizeof err) == 0, "%s element %d: %s", what, e + 1, err);
        CHECK(signed_volume(m) > 0, "%s element %d: volume %g, expected > 0 (outward)", what, e + 1,
              signed_volume(m));
        CHECK(mesh_append(&all, m) == 0, "append");
    }
    CHECK(mesh_check_closed(&all, err, sizeof err) == 0, "%s, whole set: %s", what, err);
    mesh_free(&all);
}

static void test_texgen_bomb_closed(void)
{
    static const int shapes[3] = {TEX_SPHERE, TEX_CYLINDER, TEX_CUBE};
    for (int s = 0; s < 3; s++) {
        BombParams p;
        bomb_defaults(&p);
        p.shape = shapes[s];
        p.count = 40;
        p.level = 1;
        p.segments = 12;
        TexSet t;
        char err[512];
        CHECK(texgen_bomb(&p, &t, err, sizeof err) == 0, "bomb shape %d: %s", s, err);
        CHECK(t.count == 40, "40 elements, got %d", t.count);
        check_elements(&t, s == 0 ? "spheres" : s == 1 ? "cylinders" : "cubes");
        for (int e = 0; e < t.count; e++) {
            const float *b = t.bound[e];
            CHECK(b[0] >= 0 && b[0] <= 128 && b[1] >= 0 && b[1] <= 128 && b[2] >= 0 && b[2] <= 128,
                  "centre inside the block");
            CHECK(b[3] >= 1.0f && b[3] <= 14.0f * 1.7321f + 1e-3f, "bounding radius %g", b[3]);
            /* every vertex within the bounding sphere */
            const Mesh *m = &t.elems[e];
            for (uint32_t i = 0; i < m->nverts; i++) {
                float d = v3_len(v3_sub(m->verts[i], v3(b[0], b[1], b[2])));
                if (d > b[3] * 1.0001f + 1e-4f) {
                    CHECK(0, "vertex %u at %g outside bounding radius %g", i, d, b[3]);
                    break;
                }
            }
        }
        texset_free(&t);
    }
}

static void test_texgen_no_overlap(void)
{
    BombParams p;
    bomb_defaults(&p);
    p.shape = TEX_CUBE;
    p.count = 120;
    p.size_min = 2;
    p.size_max = 8;
    p.no_overlap = 1;
    p.seed = 7;
    TexSet t;
    char err[512];
    CHECK(texgen_bomb(&p, &t, err, sizeof err) == 0, "no-overlap: %s", err);
    for (int i = 0; i < t.count; i++)
        for (int j = i + 1; j < t.count; j++) {
            const float *a = t.bound[i], *b = t.bound[j];
            float d = v3_len(v3_sub(v3(a[0], a[1], a[2]), v3(b[0], b[1], b[2])));
            CHECK(d > (a[3] + b[3]) * (1.0f - 1e-5f), "elements %d and %d overlap: %g < %g", i, j,
                  d, a[3] + b[3]);
        }
    /* and so the meshes themselves do not meet */
    CHECK(texset_check_disjoint(&t, err, sizeof err) == 0, "%s", err);
    texset_free(&t);
    /* a count that cannot fit fails with a message, not a hang */
    p.count = 400;
    p.size_min = p.size_max = 20;
    CHECK(texgen_bomb(&p, &t, err, sizeof err) == -1 && strstr(err, "--no-overlap"),
          "impossible --no-overlap fails: %s", err);
}

/* The disjointness check itself: it must see crossing, touching and coplanar overlaps. */
static void test_texgen_disjoint_detects(void)
{
    TexSet t;
    texset_init(&t);
    float b[4] = {0, 0, 0, 1};
    char err[256];
    Mesh m;
    mesh_init(&m);
    shape_box(&m, v3(2, 2, 2));
    texset_add(&t, &m, b);
    shape_box(&m, v3(2, 2, 2));
    mat4 xf = mat4_translate(v3(1.5f, 0.5f, 0.25f));
    mesh_transform(&m, &xf);
    texset_add(&t, &m, b);
    CHECK(texset_check_disjoint(&t, err, sizeof err) == -1, "crossing boxes found");
    xf = mat4_translate(v3(0.5f, 0, 0)); /* now at x offset 2: faces touch at x = 1 */
    mesh_transform(&t.elems[1], &xf);
    CHECK(texset_check_disjoint(&t, err, sizeof err) == -1, "touching (coplanar) faces found");
    xf = mat4_translate(v3(0.01f, 0, 0));
    mesh_transform(&t.elems[1], &xf);
    CHECK(texset_check_disjoint(&t, err, sizeof err) == 0, "apart boxes pass: %s", err);
    /* a small box strictly inside a big one: surfaces disjoint */
    texset_free(&t);
    shape_box(&m, v3(4, 4, 4));
    texset_add(&t, &m, b);
    shape_box(&m, v3(1, 1, 1));
    texset_add(&t, &m, b);
    CHECK(texset_check_disjoint(&t, err, sizeof err) == 0, "nested boxes pass: %s", err);
    texset_free(&t);
}

static void deform_case(const char *what, DeformParams *p, int expect_elems)
{
    TexSet t;
    char err[1024];
    int rc = texgen_deform(p, &t, err, sizeof err);
    CHECK(rc == 0, "%s: %s", what, err);
    if (rc) return;
    if (expect_elems) CHECK(t.count == expect_elems, "%s: %d elements", what, t.count);
    check_elements(&t, what);
    CHECK(texset_check_disjoint(&t, err, sizeof err) == 0, "%s: %s", what, err);
    texset_free(&t);
}

static void test_texgen_deform_closed_disjoint(void)
{
    DeformParams p;
    deform_defaults(&p);
    deform_case("figure 2.2", &p, 2);

    deform_defaults(&p);
    p.count = 5;
    p.ntaper = 0;
    p.taper_random = 1;
    p.segments = 24;
    deform_case("5 circles, random taper (core + 2 bands)", &p, 3);

    deform_defaults(&p);
    p.rect = 1;
    deform_case("rectangles, figure 2.2 tapers", &p, 2);

    deform_defaults(&p);
    p.rect = 1;
    p.ntaper = 0;
    p.twist_random = 1;
    p.twist_max = 20;
    deform_case("rectangles, twisted", &p, 2);

    deform_defaults(&p);
    p.rect = 1;
    p.count = 3;
    p.ntaper = 0;
    p.taper_random = 1;
    p.taper_max = 0.02f;
    static const float tw[3] = {15, -25, 40};
    memcpy(p.twist, tw, sizeof tw);
    p.ntwist = 3;
    deform_case("rectangles, tapered and twisted", &p, 2);

    deform_defaults(&p);
    p.count = 4;
    p.twist_random = 1;
    p.twist_max = 10;
    p.spacing = 2.5f;
    deform_case("circles, tapered and twisted", &p, 2);

    CHECK(deform_preset(&p, "wood") == 0, "wood preset");
    TexSet t;
    char err[512];
    CHECK(texgen_deform(&p, &t, err, sizeof err) == 0, "wood: %s", err);
    uint32_t n = 0;
    for (int e = 0; e < t.count; e++) n += t.elems[e].ntris;
    CHECK(n >= 2000 && n <= 3000, "wood: %u triangles, expected about 2500 (thesis A.3)", n);
    texset_free(&t);
    deform_case("wood", &p, 8);

    CHECK(deform_preset(&p, "marble") == 0, "marble preset");
    deform_case("marble", &p, 6);
    CHECK(deform_preset(&p, "plastic") == -1, "unknown preset refused");
}

/* Nested profiles: every band's outer wall lies strictly inside the next band's inner
 * wall, checked on the vertices of each ring as distances from the axis (circles,
 * untwisted, so rings are concentric similar polygons). */
static void test_texgen_deform_nested_radii(void)
{
    DeformParams p;
    deform_preset(&p, "wood");
    TexSet t;
    char err[512];
    CHECK(texgen_deform(&p, &t, err, sizeof err) == 0, "wood: %s", err);
    /* the elements come from the outside in; compare their radial extents at z = 0 and
     * z = Max_Z: max radius of element e+1 < min radius of element e */
    for (int e = 0; e + 1 < t.count; e++)
        for (int end = 0; end < 2; end++) {
            float z = end ? p.length : 0.0f, rmin = 1e30f, rmax = 0;
            const Mesh *a = &t.elems[e], *b = &t.elems[e + 1];
            for (uint32_t i = 0; i < a->nverts; i++)
                if (a->verts[i].z == z) rmin = fminf(rmin, hypotf(a->verts[i].x, a->verts[i].y));
            for (uint32_t i = 0; i < b->nverts; i++)
                if (b->verts[i].z == z) rmax = fmaxf(rmax, hypotf(b->verts[i].x, b->verts[i].y));
            CHECK(rmax < rmin, "element %d (max r %g) inside element %d (min r %g) at z %g", e + 2,
                  rmax, e + 1, rmin, z);
        }
    texset_free(&t);
}

static int read_all(const char *path, char **buf, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    *buf = malloc((size_t)n + 1);
    *len = fread(*buf, 1, (size_t)n, f);
    fclose(f);
    return *len == (size_t)n ? 0 : -1;
}

static int same_file(const char *a, const char *b)
{
    char *x = NULL, *y = NULL;
    size_t nx = 0, ny = 0;
    int same =
        read_all(a, &x, &nx) == 0 && read_all(b, &y, &ny) == 0 && nx == ny && memcmp(x, y, nx) == 0;
    free(x);
    free(y);
    return same;
}

/* Runs texgen_main on a command line split at spaces, with stdout and stderr silenced. */
static int texgen(const char *cmdline)
{
    char buf[2048], *argv[64];
    int argc = 0;
    snprintf(buf, sizeof buf, "texgen %s", cmdline);
    for (char *tok = strtok(buf, " "); tok && argc < 63; tok = strtok(NULL, " "))
        argv[argc++] = tok;
    argv[argc] = NULL;
    fflush(stdout);
    fflush(stderr);
    int out = dup(1), err = dup(2), null = open("/dev/null", O_WRONLY);
    dup2(null, 1);
    dup2(null, 2);
    int rc = texgen_main(argc, argv);
    fflush(stdout);
    fflush(stderr);
    dup2(out, 1);
    dup2(err, 2);
    close(out);
    close(err);
    close(null);
    return rc;
}

static void test_texgen_same_seed_identical(void)
{
    const char *d = tu_tmpdir();
    static const char *cmds[] = {
        "bomb --shape cylinder --count 30 --seed 5 --segments 10",
        "bomb --shape cube --count 30 --seed 5 --no-overlap",
        "deform --preset marble --seed 3",
        "deform --profile rect --twist random --taper none --seed 9",
    };
    static const char *exts[] = {"obj", "ply"};
    for (int c = 0; c < 4; c++)
        for (int x = 0; x < 2; x++) {
            char cmd[1024], a[512], b[512];
            snprintf(a, sizeof a, "%s/same_a%d.%s", d, c, exts[x]);
            snprintf(b, sizeof b, "%s/same_b%d.%s", d, c, exts[x]);
            snprintf(cmd, sizeof cmd, "%s -o %s", cmds[c], a);
            CHECK(texgen(cmd) == 0, "%s", cmd);
            snprintf(cmd, sizeof cmd, "%s -o %s", cmds[c], b);
            CHECK(texgen(cmd) == 0, "%s", cmd);
            CHECK(same_file(a, b), "same seed, same bytes: %s", cmd);
            /* the renderer's loader reads it back closed, with every triangle */
            Mesh m;
            mesh_init(&m);
            char err[512];
            CHECK(mesh_load(a, &m, err, sizeof err) == 0, "%s: %s", a, err);
            CHECK(mesh_check_closed(&m, err, sizeof err) == 0, "%s loaded: %s", a, err);
            CHECK(m.ntris > 0 && signed_volume(&m) > 0, "%s: outward", a);
            mesh_free(&m);
        }
    char cmd[1024], a[512], b[512];
    snprintf(a, sizeof a, "%s/seed1.obj", d);
    snprintf(b, sizeof b, "%s/seed2.obj", d);
    snprintf(cmd, sizeof cmd, "bomb --count 10 --level 0 --seed 1 -o %s", a);
    CHECK(texgen(cmd) == 0, "%s", cmd);
    snprintf(cmd, sizeof cmd, "bomb --count 10 --level 0 --seed 2 -o %s", b);
    CHECK(texgen(cmd) == 0, "%s", cmd);
    CHECK(!same_file(a, b), "another seed, another texture");
}

static void test_texgen_fourier_bound(void)
{
    TexRng rng;
    texrng_seed(&rng, 42);
    for (int n = 4; n <= 7; n++)
        for (int k = 0; k < 4; k++) {
            static const float a0s[4] = {0.0f, 0.5f, 1.0f, 2.0f};
            float freq[3] = {3.1f, 5.3f, 7.7f};
            VbFourier f;
            char err[256];
            CHECK(texgen_fourier_init(&f, n, a0s[k], freq, (uint64_t)(n * 10 + k), err,
                                      sizeof err) == 0,
                  "init: %s", err);
            float gmax = -2, gmin = 2;
            for (int i = 0; i < 100000; i++) {
                float x = (float)(10 * texrng_uniform(&rng)),
                      y = (float)(10 * texrng_uniform(&rng)),
                      z = (float)(10 * texrng_uniform(&rng));
                float g = solidtex_fourier_eval(&f, x, y, z);
                gmax = fmaxf(gmax, g);
                gmin = fminf(gmin, g);
            }
            CHECK(gmax <= 1.0f && gmin >= -1.0f, "n %d A0 %g: G in [%g, %g], expected |G| <= 1", n,
                  a0s[k], gmin, gmax);
            if (a0s[k] >= 1.0f) CHECK(gmin >= 0.0f, "n %d A0 %g: G >= 0 (%g)", n, a0s[k], gmin);
            if (a0s[k] == 1.0f)
                CHECK(gmax > 0.5f, "n %d: max G %g, expected > 0.5 (bound not loose)", n, gmax);
        }
    VbFourier f;
    char err[256];
    float freq[3] = {1, 1, 1};
    CHECK(texgen_fourier_init(&f, 3, 1, freq, 1, err, sizeof err) == -1, "n = 3 refused");
    CHECK(texgen_fourier_init(&f, 8, 1, freq, 1, err, sizeof err) == -1, "n = 8 refused");
    CHECK(texgen_fourier_init(&f, 5, -1, freq, 1, err, sizeof err) == -1, "A0 < 0 refused");
}

static void test_texgen_projection_texels(void)
{
    enum { W = 5, H = 3 };
    float img[W * H * 4];
    for (int i = 0; i < W * H * 4; i++) img[i] = (float)((i * 7) % 16) / 16.0f;
    for (int row = 0; row < H; row++)
        for (int col = 0; col < W; col++) {
            float x = (col + 0.5f) / W, y = (H - row - 0.5f) / H;
            for (int c = 0; c < 4; c++) {
                float v = solidtex_projection_eval(img, W, H, 4, c, x, y);
                CHECK(v == img[4 * (row * W + col) + c], "texel (%d, %d) channel %d", col, row, c);
            }
        }
    CHECK(solidtex_projection_eval(img, W, H, 4, 0, -0.01f, 0.5f) == 0.0f, "outside: 0");
    CHECK(solidtex_projection_eval(img, W, H, 4, 0, 0.5f, 1.01f) == 0.0f, "outside: 0");
    CHECK(solidtex_projection_texel(W, H, 1.0f, 1.0f) == W - 1, "corner (1, 1): top right");
    CHECK(solidtex_projection_texel(W, H, 0.0f, 0.0f) == (H - 1) * W, "corner (0, 0): bottom left");

    /* through a file: an EXR keeps the values, the loader returns them at texel centres */
    char path[512], err[512];
    snprintf(path, sizeof path, "%s/proj.exr", tu_tmpdir());
    CHECK(image_write(path, W, H, img, 0.0f, err, sizeof err) == 0, "%s", err);
    int w = 0, h = 0;
    float *px = NULL;
    CHECK(texgen_projection_load(path, &w, &h, &px, err, sizeof err) == 0, "%s", err);
    if (px) {
        CHECK(w == W && h == H, "size %d x %d", w, h);
        for (int row = 0; row < H; row++)
            for (int col = 0; col < W; col++)
                for (int c = 0; c < 3; c++) {
                    float v = solidtex_projection_eval(px, w, h, 4, c, (col + 0.5f) / W,
                                                       (H - row - 0.5f) / H);
                    CHECK(fabsf(v - img[4 * (row * W + col) + c]) < 1e-3f,
                          "file texel (%d, %d) channel %d: %g", col, row, c, v);
                }
        free(px);
    }
    CHECK(texgen_projection_load("/nonexistent/x.png", &w, &h, &px, err, sizeof err) == -1 &&
              strstr(err, "/nonexistent/x.png"),
          "unreadable image named: %s", err);
}

static void test_texgen_bad_parameters(void)
{
    const char *d = tu_tmpdir();
    char o[600], cmd[1024];
    snprintf(o, sizeof o, "-o %s/bad.obj", d);
    static const char *bad[] = {
        "bomb --count 0 %s",
        "bomb --size 5:2 %s",
        "bomb --size 0:2 %s",
        "bomb --shape torus %s",
        "bomb --count 3",
        "bomb --count 3 -o x.stl",
        "bomb --frobnicate 1 %s",
        "bomb --count %s",
        "deform --length 100 %s",
        "deform --profile rect --twist random --taper 0.06,0.06,0.06,0.06 --length 20 %s",
        "deform --count 6 %s",
        "deform --taper 0.1,0.2 %s",
        "deform --profile hexagon %s",
        "deform --preset oak %s",
        "deform --preset marble --tube-radius 0.5 --taper-max 0.01 %s",
        "deform",
        "fourier --terms 3 -o x.png",
        "fourier --contrast -1 -o x.png",
        "fourier --terms 5",
        "project --image /nonexistent/image.png",
        "project",
        "smudge %s",
        "",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        snprintf(cmd, sizeof cmd, bad[i], o);
        CHECK(texgen(cmd) == 2, "'%s': exit 2", cmd);
    }
    char path[512];
    snprintf(path, sizeof path, "%s/bad.obj", d);
    CHECK(access(path, F_OK) != 0, "nothing written for bad parameters");
    CHECK(texgen("--help") == 0 && texgen("bomb --help") == 0 && texgen("deform --help") == 0 &&
              texgen("fourier --help") == 0 && texgen("project --help") == 0,
          "--help exits 0");
    snprintf(cmd, sizeof cmd, "bomb --count 2 -o /nonexistent/dir/x.obj");
    CHECK(texgen(cmd) == 1, "unwritable output: exit 1");
}

static void test_texgen_binary(void)
{
    char cmd[1024], out[4096];
    const char *d = tu_tmpdir();
    snprintf(cmd, sizeof cmd, "%s texgen bomb --count 0 -o %s/cli.obj", tu_vbcl, d);
    CHECK(tu_run(cmd, out, sizeof out) == 2, "count 0: exit 2: %s", out);
    CHECK(strncmp(out, "vbcl texgen bomb: --count 0", 27) == 0 &&
              strchr(out, '\n') == out + strlen(out) - 1,
          "one line naming the option: %s", out);
    snprintf(cmd, sizeof cmd, "%s texgen deform --length 50 -o %s/cli.obj", tu_vbcl, d);
    CHECK(tu_run(cmd, out, sizeof out) == 2, "clearance: exit 2: %s", out);
    CHECK(strstr(out, "clearance") && strchr(out, '\n') == out + strlen(out) - 1,
          "one line about the clearance: %s", out);
    snprintf(cmd, sizeof cmd, "%s texgen deform --preset wood -o %s/cli.ply", tu_vbcl, d);
    CHECK(tu_run(cmd, out, sizeof out) == 0 && strstr(out, "8 elements"), "wood: %s", out);
    snprintf(cmd, sizeof cmd, "%s texgen --help", tu_vbcl);
    CHECK(tu_run(cmd, out, sizeof out) == 0 && strstr(out, "usage: vbcl texgen"), "help: %s", out);
}

void suite_texgen(void)
{
    RUN_TEST(test_texgen_bomb_closed);
    RUN_TEST(test_texgen_no_overlap);
    RUN_TEST(test_texgen_disjoint_detects);
    RUN_TEST(test_texgen_deform_closed_disjoint);
    RUN_TEST(test_texgen_deform_nested_radii);
    RUN_TEST(test_texgen_same_seed_identical);
    RUN_TEST(test_texgen_fourier_bound);
    RUN_TEST(test_texgen_projection_texels);
    RUN_TEST(test_texgen_bad_parameters);
    RUN_TEST(test_texgen_binary);
}
