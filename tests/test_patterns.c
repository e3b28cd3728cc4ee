/* test_patterns.c — surface-colour solid textures in the kernel (thesis 2.2.2.3): Gardner's
 * Fourier synthesis equals the host's evaluation, an orthogonal projection returns the
 * image's own texels, through a probe and through a whole render, and a checker gives each
 * cell its colour by the parity of its indices. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fixture.h"
#include "harness.h"
#include "image_io.h"
#include "scene.h"
#include "texgen.h"
#include "testutil.h"

/* A 4 x 2 image with distinct texels, written as EXR (exact floats). */
static const float image[8][3] = {{0.1f, 0.2f, 0.3f}, {0.4f, 0.5f, 0.6f},   {0.7f, 0.8f, 0.9f},
                                  {1.0f, 0.0f, 0.5f}, {0.25f, 0.5f, 0.75f}, {0.9f, 0.1f, 0.2f},
                                  {0.3f, 0.6f, 0.0f}, {0.05f, 0.95f, 0.45f}};

static const char *write_image(void)
{
    static char path[512];
    float rgba[8 * 4];
    for (int i = 0; i < 8; i++) {
        for (int c = 0; c < 3; c++) rgba[4 * i + c] = image[i][c];
        rgba[4 * i + 3] = 1;
    }
    char err[256];
    snprintf(path, sizeof path, "%s/pattern.exr", tu_tmpdir());
    CHECK(image_write(path, 4, 2, rgba, 0, err, sizeof err) == 0, "%s", err);
    return path;
}

/* n points (xyz + 0) in [-half, half)^3 from a linear congruential sequence from seed. */
static void random_points(float *pts, int n, unsigned seed, float half)
{
    for (int i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++) {
            seed = seed * 1664525u + 1013904223u;
            pts[4 * i + k] = (float)(seed >> 8) / 16777216.0f * 2.0f * half - half;
        }
        pts[4 * i + 3] = 0;
    }
}

#define PATTERN_SCENE                                                                              \
    "{\"camera\": {\"eye\": [0.5, 0.5, 5], \"look_at\": [0.5, 0.5, 0], \"fov\": 12},"              \
    " \"image\": {\"width\": 40, \"height\": 20},"                                                 \
    " \"render\": {\"ambient\": [1, 1, 1]},"                                                       \
    " \"materials\": {\"plain\": {},"                                                              \
    "   \"g\": {\"pattern\": {\"type\": \"fourier\", \"terms\": 6, \"contrast\": 0.5,"             \
    "          \"frequency\": [2, 3, 4], \"seed\": 7, \"origin\": [1, 2, 3], \"size\": 2}},"       \
    "   \"img\": {\"diffuse\": [1, 1, 1], \"pattern\": {\"type\": \"projection\", \"image\": "     \
    "\"%1$s\"}},"                                                                                  \
    "   \"chk\": {\"pattern\": {\"type\": \"checker\", \"size\": 0.5, \"origin\": [0.1, 0, 0.2],"  \
    "          \"colours\": [[1, 0, 0], [0, 0, 1]]}},"                                             \
    "   \"chk3\": {\"pattern\": {\"type\": \"checker\", \"size\": [0.5, 0.25, 2], \"axes\": "      \
    "\"xyz\"}},"                                                                                   \
    "   \"imgx\": {\"pattern\": {\"type\": \"projection\", \"image\": \"%1$s\", \"axis\": "        \
    "\"x\"}},"                                                                                     \
    "   \"imgy\": {\"pattern\": {\"type\": \"projection\", \"image\": \"%1$s\", \"axis\": "        \
    "\"y\"}}},"                                                                                    \
    " \"objects\": [{\"shape\": \"quad\", \"size\": [2, 1], \"material\": \"img\","                \
    "   \"transform\": {\"rotate\": [90, 0, 0], \"translate\": [0.5, 0.5, 0]}}]}"

/* PATTERN_SCENE prepared on the test device (fixture_open's result). */
static int open_pattern_scene(Fixture *fx)
{
    char json[4096];
    snprintf(json, sizeof json, PATTERN_SCENE, write_image());
    return fixture_open(fx, json);
}

/* Material mat's surface pattern at n points (xyz of each 4 floats) into out (rgb of each
 * 4), through the probe kernel probe_pattern. */
static void pattern_at(Fixture *fx, int mat, const float *pts, int n, float *out)
{
    size_t bytes = sizeof(float) * 4 * (size_t)n;
    cl_mem mp = buffer(pts, bytes), mo = buffer(NULL, bytes);
    const size_t sz[] = {sizeof(int), sizeof(cl_mem), sizeof(int), sizeof(cl_mem)};
    const void *v[] = {&mat, &mp, &n, &mo};
    fixture_run_probe(fx, "probe_pattern", (size_t)n, 4, sz, v);
    read_buffer(mo, out, bytes);
    clReleaseMemObject(mp);
    clReleaseMemObject(mo);
}

/* In the kernel, G (clamped at 0) matches the host's solidtex_fourier_eval at texture
 * coordinates (p - origin) / size; the projection returns each texel at its centre and 0
 * outside the unit square. */
static void test_patterns_probe_matches_host(void)
{
    Fixture fx;
    if (open_pattern_scene(&fx)) return;
    enum { N = 64 };
    float pts[N * 4], out[N * 4];
    random_points(pts, N, 5, 3.0f);
    pattern_at(&fx, 1, pts, N, out); /* "g" */
    VbFourier four;
    char err[256];
    const float freq[3] = {2, 3, 4};
    CHECK(texgen_fourier_init(&four, 6, 0.5f, freq, 7, err, sizeof err) == 0, "%s", err);
    double worst = 0, lo = 1, hi = 0;
    for (int i = 0; i < N; i++) {
        float q[3] = {(pts[4 * i] - 1) / 2, (pts[4 * i + 1] - 2) / 2, (pts[4 * i + 2] - 3) / 2};
        double want = fmax(0.0, solidtex_fourier_eval(&four, q[0], q[1], q[2]));
        worst = fmax(worst, fabs(out[4 * i] - want));
        lo = fmin(lo, out[4 * i]);
        hi = fmax(hi, out[4 * i]);
        CHECK(out[4 * i] == out[4 * i + 1] && out[4 * i] == out[4 * i + 2], "grey");
    }
    fprintf(stderr, "    Fourier: worst |kernel - host| %.2e over %d points, range %.3f..%.3f\n",
            worst, N, lo, hi);
    CHECK(worst < 1e-5, "kernel G equals the host's within 1e-5 (%.3g)", worst);
    CHECK(hi > lo + 0.05, "the pattern varies (%.3f..%.3f)", lo, hi);
    /* projection: texel centres of a 4 x 2 image over the unit square, and two points outside */
    float tp[14 * 4];
    for (int t = 0; t < 8; t++) {
        int col = t % 4, row = t / 4;
        tp[4 * t] = (col + 0.5f) / 4, tp[4 * t + 1] = 1 - (row + 0.5f) / 2, tp[4 * t + 2] = 0.3f;
    }
    tp[32] = 1.2f, tp[33] = 0.5f, tp[36] = 0.5f, tp[37] = -0.1f;
    /* rounding either side of the square's edges: the edge texels (a box face on the
     * square's boundary is not speckled with zeros) */
    tp[40] = -1e-6f, tp[41] = 0.9f, tp[44] = 1.0f + 1e-6f, tp[45] = 0.1f;
    tp[48] = 0.1f, tp[49] = 1.0f + 1e-6f, tp[52] = 0.9f, tp[53] = -1e-6f;
    float got[14 * 4];
    pattern_at(&fx, 2, tp, 14, got); /* "img" */
    for (int t = 0; t < 8; t++)
        for (int c = 0; c < 3; c++)
            CHECK(got[4 * t + c] == image[t][c], "texel %d channel %d: %g, image %g", t, c,
                  got[4 * t + c], image[t][c]);
    CHECK(got[32] == 0 && got[36] == 0, "zero outside the unit square (%g, %g)", got[32], got[36]);
    static const int edge_texel[4] = {0, 7, 0, 7};
    for (int k = 0; k < 4; k++)
        CHECK(got[40 + 4 * k] == image[edge_texel[k]][0], "1e-6 beyond edge %d: texel %d (%g, %g)",
              k, edge_texel[k], got[40 + 4 * k], image[edge_texel[k]][0]);
    /* along x and y: the same texel centres, with (u, v) on (y, z) and (z, x), the projection
     * axis's own coordinate anything */
    for (int axis = 0; axis < 2; axis++) {
        float ap[8 * 4];
        for (int t = 0; t < 8; t++) {
            float u = (t % 4 + 0.5f) / 4, v = 1 - (t / 4 + 0.5f) / 2, *q = ap + 4 * t;
            q[axis] = 7.0f * (float)t - 20.0f;
            q[(axis + 1) % 3] = u;
            q[(axis + 2) % 3] = v;
            q[3] = 0;
        }
        float ag[8 * 4];
        pattern_at(&fx, 5 + axis, ap, 8, ag); /* "imgx", "imgy" */
        for (int t = 0; t < 8; t++)
            for (int c = 0; c < 3; c++)
                CHECK(ag[4 * t + c] == image[t][c], "along %c, texel %d channel %d: %g, image %g",
                      'x' + axis, t, c, ag[4 * t + c], image[t][c]);
    }
    fixture_close(&fx);
}

/* A whole render: a quad facing the camera carries the projected image; lit only by an
 * ambient light of 1, each pixel's colour is its texel's. */
static void test_patterns_render_projection(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    char json[4096], out[512], cmd[2048], log[4096], err[256];
    snprintf(json, sizeof json, PATTERN_SCENE, write_image());
    const char *scene = tu_write_file("pattern_scene.json", json);
    snprintf(out, sizeof out, "%s/pattern_render.exr", tu_tmpdir());
    snprintf(cmd, sizeof cmd, "%s %s -q -o %s", tu_vbcl, scene, out);
    int rc = tu_run(cmd, log, sizeof log);
    CHECK(rc == 0, "renders: %s", log);
    int w, h;
    float *px;
    if (rc || image_read(out, &w, &h, &px, err, sizeof err)) return;
    /* the quad spans x in [-0.5, 1.5], y in [0, 1]; sample the pixel over each texel centre */
    double half = 5 * tan(6 * M_PI / 180), aspect = (double)w / h;
    int ok = 0;
    for (int t = 0; t < 8; t++) {
        double x = (t % 4 + 0.5) / 4, y = 1 - (t / 4 + 0.5) / 2;
        int col = (int)((((x - 0.5) / (half * aspect)) + 1) / 2 * w),
            row = (int)((1 - (y - 0.5) / half) / 2 * h);
        const float *c = px + 4 * ((size_t)row * w + col);
        int match = fabsf(c[0] - image[t][0]) < 1e-5f && fabsf(c[1] - image[t][1]) < 1e-5f &&
                    fabsf(c[2] - image[t][2]) < 1e-5f;
        ok += match;
        CHECK(match, "texel %d at pixel (%d, %d): %g %g %g, image %g %g %g", t, col, row, c[0],
              c[1], c[2], image[t][0], image[t][1], image[t][2]);
    }
    fprintf(stderr, "    projection render: %d of 8 texel centres exact\n", ok);
    free(px);
}

/* A checker in the kernel: at random points (negative coordinates among them), colour 0
 * where the cells' indices floor((p - origin) / size) along its axes sum to an even number,
 * colour 1 where odd; constant along the other axes ("xz", a floor's default), or cubes
 * ("xyz"); the default colours are 0.9 and 0.15 grey. */
static void test_patterns_checker(void)
{
    Fixture fx;
    if (open_pattern_scene(&fx)) return;
    enum { N = 256 };
    float pts[N * 4], out[N * 4];
    random_points(pts, N, 11, 4.0f);
    for (int mat = 3; mat <= 4; mat++) { /* "chk" (xz), "chk3" (xyz) */
        pattern_at(&fx, mat, pts, N, out);
        int bad = 0, odd = 0;
        for (int i = 0; i < N; i++) {
            const float *p = pts + 4 * i;
            long cells =
                mat == 3
                    ? (long)floor((p[0] - 0.1) / 0.5) + (long)floor((p[2] - 0.2) / 0.5)
                    : (long)floor(p[0] / 0.5) + (long)floor(p[1] / 0.25) + (long)floor(p[2] / 2);
            int par = (int)(cells & 1);
            odd += par;
            const float want[2][2][3] = {{{1, 0, 0}, {0, 0, 1}},
                                         {{0.9f, 0.9f, 0.9f}, {0.15f, 0.15f, 0.15f}}};
            const float *w = want[mat - 3][par];
            if (out[4 * i] != w[0] || out[4 * i + 1] != w[1] || out[4 * i + 2] != w[2]) bad++;
        }
        CHECK(bad == 0, "material %d: %d of %d points have the other cell's colour", mat, bad, N);
        CHECK(odd > N / 4 && odd < 3 * N / 4, "material %d: both colours appear (%d odd)", mat,
              odd);
    }
    fixture_close(&fx);
}

/* A pattern key on the wrong type, or a bad axis, is refused naming the key's JSON path. */
static void test_patterns_bad_keys(void)
{
    static const char *const cases[][2] = {
        {"{\"type\": \"projection\", \"image\": \"a.png\", \"axes\": \"xz\"}",
         "materials.m.pattern.axes: only a checker pattern takes colours and axes"},
        {"{\"type\": \"checker\", \"axis\": \"y\"}",
         "materials.m.pattern.axis: only a projection pattern takes an axis"},
        {"{\"type\": \"projection\", \"image\": \"a.png\", \"axis\": \"w\"}",
         "materials.m.pattern.axis: expected the axis to project along"},
        {"{\"type\": \"projection\", \"image\": \"a.png\", \"axis\": \"xy\"}",
         "materials.m.pattern.axis: expected the axis to project along"},
        {"{\"type\": \"checker\", \"axes\": \"xx\"}",
         "materials.m.pattern.axes: expected the axes the cells alternate along"},
        {"{\"type\": \"checker\", \"colours\": [[1, 0, 0]]}",
         "materials.m.pattern.colours: expected two colours"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char json[1024], err[1024] = "";
        snprintf(json, sizeof json,
                 "{\"camera\": {\"eye\": [0, 0, 4], \"look_at\": [0, 0, 0]}, \"materials\": "
                 "{\"m\": {\"pattern\": %s}}, \"objects\": [{\"shape\": \"sphere\", "
                 "\"material\": \"m\"}]}",
                 cases[i][0]);
        Scene sc;
        int rc = scene_load_text("p.json", json, -1, &sc, err, sizeof err);
        if (!rc) scene_free(&sc);
        CHECK(rc != 0 && strstr(err, cases[i][1]), "%s: expected \"%s\", got (%d) \"%s\"",
              cases[i][0], cases[i][1], rc, err);
    }
}

void suite_patterns(void)
{
    RUN_TEST(test_patterns_bad_keys);
    RUN_PROBE_TEST(test_patterns_probe_matches_host);
    RUN_TEST(test_patterns_render_projection);
    RUN_PROBE_TEST(test_patterns_checker);
}
