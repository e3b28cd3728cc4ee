/* test_aa.c — anti-aliasing through the vbcl binary (host/frame/aa.c, kernels/aa.cl) on a scene of
 * hard edges and flat colours (tests/scenes/aa_edges.json, 64x64): the error against
 * uniform 16x16 supersampling falls with the threshold, flat regions are never refined,
 * the samples stay well below uniform 16x16, and refining a pixel changes no other pixel. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "aa.h"
#include "harness.h"
#include "image_io.h"
#include "testutil.h"

#define AA_SCENE "tests/scenes/aa_edges.json"

/* One render of the test scene: its image, level map (adaptive only) and samples. */
typedef struct AaRender {
    int w, h;
    float *px;
    int *levels;         /* NULL without --aa */
    double samples_mean; /* from --stats */
} AaRender;

/* Renders the test scene with extra options (to EXR, with --aa-map when map is set).
 * Returns 0, or -1 after a failed check. */
static int aa_render(const char *name, const char *extra, int map, AaRender *out)
{
    char img[512], mpath[512], cmd[2048], log[16384], err[512];
    memset(out, 0, sizeof *out);
    snprintf(img, sizeof img, "%s/aa_%s.exr", tu_tmpdir(), name);
    snprintf(mpath, sizeof mpath, "%s/aa_%s_map.exr", tu_tmpdir(), name);
    snprintf(cmd, sizeof cmd, "%s %s -q --stats -o %s %s %s%s", tu_vbcl, AA_SCENE, img, extra,
             map ? "--aa-map " : "", map ? mpath : "");
    int rc = tu_run(cmd, log, sizeof log);
    CHECK(rc == 0, "%s exited %d: %s", cmd, rc, log);
    if (rc) return -1;
    const char *at = strstr(log, "samples ");
    CHECK(at && sscanf(at, "samples %lf", &out->samples_mean) == 1, "no samples line: %s", log);
    if (image_read(img, &out->w, &out->h, &out->px, err, sizeof err)) {
        CHECK(0, "%s", err);
        return -1;
    }
    if (!map) return 0;
    int mw, mh;
    float *m;
    if (image_read(mpath, &mw, &mh, &m, err, sizeof err)) {
        CHECK(0, "%s", err);
        return -1;
    }
    CHECK(mw == out->w && mh == out->h, "map %dx%d, image %dx%d", mw, mh, out->w, out->h);
    out->levels = malloc(sizeof(int) * (size_t)mw * (size_t)mh);
    for (int i = 0; i < mw * mh && out->levels; i++) {
        /* the nearest colour of the palette */
        double best = 1e30;
        for (int l = 0; l <= VBCL_AA_MAX_LEVEL; l++) {
            float c[3];
            aa_level_colour(l, c);
            double d = 0;
            for (int k = 0; k < 3; k++) d += (m[4 * i + k] - c[k]) * (m[4 * i + k] - c[k]);
            if (d < best) {
                best = d;
                out->levels[i] = l;
            }
        }
        CHECK(best < 1e-6, "map pixel %d is no palette colour", i);
    }
    free(m);
    return 0;
}

static void aa_free(AaRender *r)
{
    free(r->px);
    free(r->levels);
    memset(r, 0, sizeof *r);
}

static double rmse(const AaRender *a, const AaRender *b)
{
    double s = 0;
    int n = a->w * a->h;
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            double d = (double)a->px[4 * i + c] - (double)b->px[4 * i + c];
            s += d * d;
        }
    return sqrt(s / (3.0 * n));
}

static int same_pixel(const AaRender *a, const AaRender *b, int i)
{
    return memcmp(a->px + 4 * i, b->px + 4 * i, 3 * sizeof(float)) == 0;
}

/* RMSE against --ssaa 16 falls as the threshold falls (1.0, 0.4, 0.1, 0.02); threshold 1.0
 * refines nothing (the contrast is at most 1); at 0.1 the samples are at most a quarter of
 * uniform 16x16; pixels that reach level 4 equal the reference exactly (the same sample
 * positions and jitter keys). */
static void test_aa_error_falls_with_threshold(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const double thr[4] = {1.0, 0.4, 0.1, 0.02};
    AaRender ref, plain, r[4];
    if (aa_render("ssaa16", "--ssaa 16", 0, &ref) || aa_render("plain", "", 0, &plain)) return;
    double e[4], frac[4];
    for (int k = 0; k < 4; k++) {
        char extra[64], name[32];
        snprintf(extra, sizeof extra, "--aa %g", thr[k]);
        snprintf(name, sizeof name, "thr%d", k);
        if (aa_render(name, extra, 1, &r[k])) return;
        e[k] = rmse(&r[k], &ref);
        frac[k] = r[k].samples_mean / 256.0;
        fprintf(stderr, "    threshold %-5g RMSE %.3e  samples/pixel %7.2f (%.4f of 16x16)\n",
                thr[k], e[k], r[k].samples_mean, frac[k]);
    }
    double e_plain = rmse(&plain, &ref);
    fprintf(stderr, "    no anti-aliasing RMSE %.3e\n", e_plain);
    CHECK(e[0] == e_plain && r[0].samples_mean == 1.0, "threshold 1 refines nothing: %g vs %g",
          e[0], e_plain);
    for (int k = 1; k < 4; k++)
        CHECK(e[k] < e[k - 1], "RMSE falls: threshold %g %.5f, threshold %g %.5f", thr[k], e[k],
              thr[k - 1], e[k - 1]);
    CHECK(e[3] < 0.25 * e[0], "threshold 0.02 removes most of the error: %.5f vs %.5f", e[3], e[0]);
    CHECK(frac[2] <= 0.25, "threshold 0.1 takes %.4f of the samples of uniform 16x16", frac[2]);
    int top = 0, top_same = 0;
    for (int i = 0; i < ref.w * ref.h; i++)
        if (r[3].levels[i] == VBCL_AA_MAX_LEVEL) {
            top++;
            top_same += same_pixel(&r[3], &ref, i);
        }
    CHECK(top > 0 && top_same == top, "%d of %d level-4 pixels equal --ssaa 16", top_same, top);
    aa_free(&ref);
    aa_free(&plain);
    for (int k = 0; k < 4; k++) aa_free(&r[k]);
}

/* A pixel whose 5x5 neighbourhood is one colour in the reference (so it and its
 * neighbours are flat at every sampling rate) stays at level 0 even at threshold 0.02, and
 * so does the uniform background at the image corners. */
static void test_aa_flat_regions_never_refined(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    AaRender ref, a;
    if (aa_render("flat_ref", "--ssaa 16", 0, &ref) || aa_render("flat", "--aa 0.02", 1, &a))
        return;
    int w = a.w, h = a.h, flat = 0, flat_refined = 0, refined = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int i = y * w + x, uniform = 1;
            refined += a.levels[i] > 0;
            for (int dy = -2; dy <= 2 && uniform; dy++)
                for (int dx = -2; dx <= 2 && uniform; dx++) {
                    int qx = x + dx, qy = y + dy;
                    if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
                    uniform =
                        memcmp(ref.px + 4 * i, ref.px + 4 * (qy * w + qx), 3 * sizeof(float)) == 0;
                }
            if (!uniform) continue;
            flat++;
            flat_refined += a.levels[i] != 0;
        }
    int corners = 0;
    for (int y = 0; y < 6; y++)
        for (int x = 0; x < 6; x++) {
            int c[4] = {y * w + x, y * w + (w - 1 - x), (h - 1 - y) * w + x,
                        (h - 1 - y) * w + (w - 1 - x)};
            for (int k = 0; k < 4; k++) corners += a.levels[c[k]] != 0;
        }
    fprintf(stderr, "    %d flat pixels (%.0f%%), %d of them refined; %d pixels refined in all\n",
            flat, 100.0 * flat / (w * h), flat_refined, refined);
    CHECK(flat > w * h / 3, "the scene has flat regions: %d pixels", flat);
    CHECK(flat_refined == 0, "%d flat pixels refined", flat_refined);
    CHECK(corners == 0, "%d corner background pixels refined", corners);
    CHECK(refined > 0, "the edges are refined");
    aa_free(&ref);
    aa_free(&a);
}

/* A pixel's value depends only on its own level: every pixel at the same level in two
 * renders that refine different sets of pixels (thresholds 0.4 and 0.1, and max level 2)
 * is bit-identical, and every unrefined pixel equals the render without anti-aliasing —
 * so refining a pixel never changes a pixel outside its own box window. */
static void test_aa_refinement_is_local(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    AaRender plain, a[3];
    const char *extra[3] = {"--aa 0.4", "--aa 0.1", "--aa 0.1 --aa-max-level 2"};
    const char *names[3] = {"local_a", "local_b", "local_c"};
    if (aa_render("local_plain", "", 0, &plain)) return;
    for (int k = 0; k < 3; k++)
        if (aa_render(names[k], extra[k], 1, &a[k])) return;
    int n = plain.w * plain.h;
    for (int k = 0; k < 3; k++) {
        int zero = 0, zero_same = 0;
        for (int i = 0; i < n; i++)
            if (a[k].levels[i] == 0) {
                zero++;
                zero_same += same_pixel(&a[k], &plain, i);
            }
        CHECK(zero_same == zero, "%s: %d of %d unrefined pixels equal the plain render", extra[k],
              zero_same, zero);
        for (int j = k + 1; j < 3; j++) {
            int both = 0, both_same = 0, differ = 0;
            for (int i = 0; i < n; i++) {
                if (a[k].levels[i] != a[j].levels[i]) {
                    differ++;
                    continue;
                }
                both++;
                both_same += same_pixel(&a[k], &a[j], i);
            }
            fprintf(stderr,
                    "    %s / %s: %d pixels at different levels, %d of %d at equal levels "
                    "identical\n",
                    extra[k], extra[j], differ, both_same, both);
            CHECK(differ > 0, "%s and %s refine different pixels", extra[k], extra[j]);
            CHECK(both_same == both, "%s / %s: %d of %d pixels at equal levels identical", extra[k],
                  extra[j], both_same, both);
        }
    }
    aa_free(&plain);
    for (int k = 0; k < 3; k++) aa_free(&a[k]);
}

/* --ssaa 1 goes through the supersampling path and gives the plain render bit for bit;
 * render.aa in the scene is the same as --aa; option errors exit 2. */
static void test_aa_options(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    AaRender plain, one, cli, key;
    if (aa_render("opt_plain", "", 0, &plain) || aa_render("opt_ssaa1", "--ssaa 1", 0, &one) ||
        aa_render("opt_cli", "--aa 0.1 --aa-max-level 3", 1, &cli))
        return;
    CHECK(rmse(&plain, &one) == 0.0, "--ssaa 1 differs from the plain render: %g",
          rmse(&plain, &one));
    /* the scene with render.aa set instead of the option */
    char cmd[2048], log[8192], out[512];
    snprintf(out, sizeof out, "%s/aa_key.exr", tu_tmpdir());
    snprintf(cmd, sizeof cmd,
             "sed 's/\"ambient\": \\[1, 1, 1\\]/\"ambient\": [1, 1, 1], \"aa\": 0.1, "
             "\"aa_max_level\": 3/' %s > %s/aa_key.json && %s %s/aa_key.json -q -o %s",
             AA_SCENE, tu_tmpdir(), tu_vbcl, tu_tmpdir(), out);
    int rc = tu_run(cmd, log, sizeof log);
    CHECK(rc == 0, "%s: exit %d: %s", cmd, rc, log);
    char err[512];
    if (rc == 0 && image_read(out, &key.w, &key.h, &key.px, err, sizeof err) == 0) {
        CHECK(rmse(&key, &cli) == 0.0, "render.aa differs from --aa: %g", rmse(&key, &cli));
        free(key.px);
    }
    const char *bad[] = {
        "--aa 1.5",       "--aa-max-level 5",       "--ssaa 17", "--ssaa 0", "--aa 0.1 --ssaa 4",
        "--aa-map m.png", "--aa 0.1 --aa-map m.bmp"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        snprintf(cmd, sizeof cmd, "%s %s -q -o %s/never.png %s", tu_vbcl, AA_SCENE, tu_tmpdir(),
                 bad[i]);
        rc = tu_run(cmd, log, sizeof log);
        CHECK(rc == 2 && strchr(log, '\n') == strrchr(log, '\n'), "%s: exit %d, %s", bad[i], rc,
              log);
    }
    aa_free(&plain);
    aa_free(&one);
    aa_free(&cli);
}

void suite_aa(void)
{
    RUN_TEST(test_aa_error_falls_with_threshold);
    RUN_TEST(test_aa_flat_regions_never_refined);
    RUN_TEST(test_aa_refinement_is_local);
    RUN_TEST(test_aa_options);
}
