/* test_aa.c — anti-aliasing through the vbcl binary (host/frame/aa.c, kernels/aa.cl) on a scene of
 * hard edges and flat colours (tests/scenes/aa_edges.json, 64x64): the error against
 * uniform 16x16 supersampling falls with the threshold, flat regions are never refined,
 * the samples stay well below uniform 16x16, and refining a pixel changes no other pixel. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "aa.h"
#include "aa_tree.h"
#include "fixture.h"
#include "harness.h"
#include "image_io.h"
#include "testutil.h"

#define AA_SCENE "tests/scenes/aa_edges.json"

/* One render of the test scene: its image, level map (adaptive only) and samples. */
typedef struct AaRender {
    int w, h;
    float *px;
    int *levels;         /* NULL without --aa */
    int *leaves;         /* samples per pixel from --aa-samples-map; NULL without --aa */
    double samples_mean; /* from --stats */
    unsigned samples_max;
} AaRender;

/* Reads a heat map (EXR) of w x h into values: each pixel the n in lo..hi whose colour
 * (colour(n)) is nearest, which must be within 1e-6. The map is the image's top-left
 * w x h pixels, its legend to the right (aa_map.h): the image is wider. Returns 0 or -1. */
static int aa_read_map(const char *path, int w, int h, int lo, int hi,
                       void (*colour)(int, float[3]), int *values)
{
    char err[512];
    int mw, mh;
    float *m;
    if (image_read(path, &mw, &mh, &m, err, sizeof err)) {
        CHECK(0, "%s", err);
        return -1;
    }
    int fits = mw > w && mh >= h;
    CHECK(fits, "map %dx%d has no legend beside the %dx%d image", mw, mh, w, h);
    for (int i = 0; i < w * h && fits; i++) {
        const float *p = m + 4 * ((size_t)(i / w) * (size_t)mw + (size_t)(i % w));
        double best = 1e30;
        for (int n = lo; n <= hi; n++) {
            float c[3];
            colour(n, c);
            double d = 0;
            for (int k = 0; k < 3; k++) d += (p[k] - c[k]) * (p[k] - c[k]);
            if (d < best) {
                best = d;
                values[i] = n;
            }
        }
        CHECK(best < 1e-12, "%s: pixel %d is no palette colour", path, i);
    }
    free(m);
    return fits ? 0 : -1;
}

/* Renders the test scene with extra options (to EXR; with map set, also --aa-map and
 * --aa-samples-map, decoded into levels and leaves). Returns 0, or -1 after a failed
 * check. */
static int aa_render(const char *name, const char *extra, int map, AaRender *out)
{
    char img[512], mpath[512], spath[512], cmd[2048], log[16384], err[512];
    memset(out, 0, sizeof *out);
    snprintf(img, sizeof img, "%s/aa_%s.exr", tu_tmpdir(), name);
    snprintf(mpath, sizeof mpath, "%s/aa_%s_map.exr", tu_tmpdir(), name);
    snprintf(spath, sizeof spath, "%s/aa_%s_samples.exr", tu_tmpdir(), name);
    snprintf(cmd, sizeof cmd, "%s %s -q --stats -o %s %s %s%s %s%s", tu_vbcl, AA_SCENE, img, extra,
             map ? "--aa-map " : "", map ? mpath : "", map ? "--aa-samples-map " : "",
             map ? spath : "");
    int rc = tu_run(cmd, log, sizeof log);
    CHECK(rc == 0, "%s exited %d: %s", cmd, rc, log);
    if (rc) return -1;
    const char *at = strstr(log, "samples ");
    CHECK(at && sscanf(at, "samples %lf per pixel (mean), %u", &out->samples_mean,
                       &out->samples_max) == 2,
          "no samples line: %s", log);
    if (image_read(img, &out->w, &out->h, &out->px, err, sizeof err)) {
        CHECK(0, "%s", err);
        return -1;
    }
    if (!map) return 0;
    size_t npix = (size_t)out->w * (size_t)out->h;
    out->levels = malloc(sizeof(int) * npix);
    out->leaves = malloc(sizeof(int) * npix);
    if (!out->levels || !out->leaves) return -1;
    return aa_read_map(mpath, out->w, out->h, 0, VBCL_AA_MAX_LEVEL, aa_level_colour, out->levels) ||
                   aa_read_map(spath, out->w, out->h, 1, VBCL_AA_CELLS, aa_samples_colour,
                               out->leaves)
               ? -1
               : 0;
}

/* The two maps of an adaptive render agree with each other and with --stats: a pixel at
 * level 0 has one sample, one at level L at least 1 + 3L (a split per level) and at most
 * 4^L; the largest count is the samples line's max, the mean its mean (printed to 0.01). */
static void aa_check_maps(const AaRender *r, const char *what)
{
    int bad = 0, max = 0;
    double sum = 0;
    for (int i = 0; i < r->w * r->h; i++) {
        int l = r->levels[i], n = r->leaves[i];
        bad += l == 0 ? n != 1 : (n < 1 + 3 * l || n > 1 << (2 * l));
        max = n > max ? n : max;
        sum += n;
    }
    double mean = sum / (double)(r->w * r->h);
    CHECK(bad == 0 && (unsigned)max == r->samples_max && fabs(mean - r->samples_mean) <= 0.0051,
          "%s: %d pixels whose samples do not fit their level; max %d (stats %u), mean %.4f "
          "(stats %.2f)",
          what, bad, max, r->samples_max, mean, r->samples_mean);
}

static void aa_free(AaRender *r)
{
    free(r->px);
    free(r->levels);
    free(r->leaves);
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
 * refines nothing (the contrast is at most 1); at 0.1 the samples are at most a twentieth
 * of uniform 16x16 (the quadtree refines only the subpixels along the edges); no pixel
 * takes more than 256 samples (a fully split pixel: its 256 leaves, each traced once). At
 * 0.1 and 0.02, --aa-pairs both (a failing pair of one level splits both leaves, not only
 * the first) traces more samples for no less error: on these flat colours the second leaf
 * of a pair that the edge does not cross gains nothing from its split. */
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
        aa_check_maps(&r[k], extra);
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
    CHECK(frac[2] <= 0.05, "threshold 0.1 takes %.4f of the samples of uniform 16x16", frac[2]);
    for (int k = 0; k < 4; k++)
        CHECK(r[k].samples_max <= 256, "threshold %g: %u samples in one pixel", thr[k],
              r[k].samples_max);
    for (int k = 2; k < 4; k++) {
        char extra[64], name[32];
        AaRender both;
        snprintf(extra, sizeof extra, "--aa %g --aa-pairs both", thr[k]);
        snprintf(name, sizeof name, "both%d", k);
        if (aa_render(name, extra, 0, &both)) break;
        double eb = rmse(&both, &ref);
        fprintf(stderr, "    %-27s RMSE %.3e  samples/pixel %7.2f\n", extra, eb, both.samples_mean);
        CHECK(r[k].samples_mean < both.samples_mean && e[k] <= 1.02 * eb,
              "threshold %g: pairs first %.3f samples/pixel, RMSE %.4e; both %.3f, %.4e", thr[k],
              r[k].samples_mean, e[k], both.samples_mean, eb);
        aa_free(&both);
    }
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

/* Pixels that no refinement touches (level 0) are bit-identical to the render without
 * anti-aliasing, in renders that refine different sets of subpixels (thresholds 0.4 and
 * 0.1, max level 2), and flat colour next to a refined edge stays exact. */
static void test_aa_untouched_pixels_unchanged(void)
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
        int zero = 0, zero_same = 0, refined = 0;
        for (int i = 0; i < n; i++)
            if (a[k].levels[i] == 0) {
                zero++;
                zero_same += same_pixel(&a[k], &plain, i);
            } else {
                refined++;
            }
        fprintf(stderr, "    %s: %d pixels untouched, %d refined\n", extra[k], zero, refined);
        CHECK(refined > 0 && zero > n / 2, "%s: %d untouched, %d refined", extra[k], zero, refined);
        CHECK(zero_same == zero, "%s: %d of %d unrefined pixels equal the plain render", extra[k],
              zero_same, zero);
    }
    aa_free(&plain);
    for (int k = 0; k < 3; k++) aa_free(&a[k]);
}

/* --ssaa 1 goes through the supersampling path and gives the plain render bit for bit;
 * render.aa (and aa_max_level, aa_min_level, aa_level_gain, aa_floor, aa_reconstruct, aa_pairs) in
 * the scene is the same as the options; the floor's default is 1, the reconstruction's nearest, the
 * pairs' first; option errors exit 2. */
static void test_aa_options(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    AaRender plain, one, cli, key, dflt, floor1, floor0, nearest, leaves, first, both;
    if (aa_render("opt_plain", "", 0, &plain) || aa_render("opt_ssaa1", "--ssaa 1", 0, &one) ||
        aa_render("opt_cli",
                  "--aa 0.1 --aa-max-level 3 --aa-min-level 1 --aa-level-gain 1.5 "
                  "--aa-floor 0.5 --aa-reconstruct leaves --aa-pairs both",
                  1, &cli) ||
        aa_render("opt_default", "--aa 0.4", 0, &dflt) ||
        aa_render("opt_floor1", "--aa 0.4 --aa-floor 1", 0, &floor1) ||
        aa_render("opt_floor0", "--aa 0.4 --aa-floor 0", 0, &floor0) ||
        aa_render("opt_nearest", "--aa 0.4 --aa-reconstruct nearest", 0, &nearest) ||
        aa_render("opt_leaves", "--aa 0.4 --aa-reconstruct leaves", 0, &leaves) ||
        aa_render("opt_first", "--aa 0.4 --aa-pairs first", 0, &first) ||
        aa_render("opt_both", "--aa 0.4 --aa-pairs both", 0, &both))
        return;
    CHECK(rmse(&plain, &one) == 0.0, "--ssaa 1 differs from the plain render: %g",
          rmse(&plain, &one));
    /* the floor's default is 1 (SCENE_AA_FLOOR), and on this scene's dark edges it matters */
    CHECK(rmse(&dflt, &floor1) == 0.0, "the default floor is not 1: %g", rmse(&dflt, &floor1));
    CHECK(rmse(&dflt, &floor0) > 0.0, "--aa-floor 0 changes nothing at --aa 0.4");
    /* the reconstruction's default is the nearest samples', and it is not the leaves' */
    CHECK(rmse(&dflt, &nearest) == 0.0, "the default reconstruction is not nearest: %g",
          rmse(&dflt, &nearest));
    CHECK(rmse(&dflt, &leaves) > 0.0, "--aa-reconstruct leaves changes nothing at --aa 0.4");
    /* the pairs' default is first, and both splits more */
    CHECK(rmse(&dflt, &first) == 0.0 && dflt.samples_mean == first.samples_mean,
          "the default pairs are not first: %g", rmse(&dflt, &first));
    CHECK(both.samples_mean > first.samples_mean,
          "--aa-pairs both traces no more samples than first at --aa 0.4: %.3f vs %.3f",
          both.samples_mean, first.samples_mean);
    /* the scene with render.aa set instead of the option */
    char cmd[2048], log[8192], out[512];
    snprintf(out, sizeof out, "%s/aa_key.exr", tu_tmpdir());
    snprintf(cmd, sizeof cmd,
             "sed 's/\"ambient\": \\[1, 1, 1\\]/\"ambient\": [1, 1, 1], \"aa\": 0.1, "
             "\"aa_max_level\": 3, \"aa_min_level\": 1, \"aa_level_gain\": 1.5, \"aa_floor\": 0.5, "
             "\"aa_reconstruct\": \"leaves\", \"aa_pairs\": \"both\"/' %s > "
             "%s/aa_key.json && "
             "%s %s/aa_key.json -q -o %s",
             AA_SCENE, tu_tmpdir(), tu_vbcl, tu_tmpdir(), out);
    int rc = tu_run(cmd, log, sizeof log);
    CHECK(rc == 0, "%s: exit %d: %s", cmd, rc, log);
    char err[512];
    if (rc == 0 && image_read(out, &key.w, &key.h, &key.px, err, sizeof err) == 0) {
        CHECK(rmse(&key, &cli) == 0.0, "render.aa differs from --aa: %g", rmse(&key, &cli));
        free(key.px);
    }
    const char *bad[] = {"--aa 1.5",
                         "--aa-max-level 5",
                         "--aa-min-level 5",
                         "--aa-min-level 1",
                         "--aa 0.1 --aa-max-level 2 --aa-min-level 3",
                         "--ssaa 17",
                         "--ssaa 0",
                         "--aa 0.1 --ssaa 4",
                         "--aa-map m.png",
                         "--aa-samples-map s.png",
                         "--aa 0.1 --aa-map m.bmp",
                         "--aa 0.1 --aa-floor 3",
                         "--aa 0.1 --aa-level-gain 0.5",
                         "--aa 0.1 --aa-reconstruct mean",
                         "--aa 0.1 --aa-pairs one"};
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
    aa_free(&dflt);
    aa_free(&floor1);
    aa_free(&floor0);
    aa_free(&nearest);
    aa_free(&leaves);
    aa_free(&first);
    aa_free(&both);
}

/* A minimum level (--aa-min-level): every pixel is split down to it before the contrast
 * test. With the minimum at the deepest level (2) the quadtree traces 16 samples in every
 * pixel, one per 4 x 4 stratum, and its error against --ssaa 16 is below half of uniform
 * 2 x 2's and within 1.6 times uniform 4 x 4's (measured 0.38 and 1.42: a node's sample is
 * where its parent's lay, not at the stratum's centre, which on these hard edges costs some
 * accuracy against centred strata). Above a threshold's own refinement, a minimum of 1
 * leaves no pixel at level 0, adds samples and removes error; a minimum of 0 is the
 * default bit for bit. */
static void test_aa_min_level(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    AaRender ref, u2, u4, full, adapt, min0, min1;
    if (aa_render("min_ref", "--ssaa 16", 0, &ref) || aa_render("min_u2", "--ssaa 2", 0, &u2) ||
        aa_render("min_u4", "--ssaa 4", 0, &u4) ||
        aa_render("min_full", "--aa 1 --aa-min-level 2 --aa-max-level 2", 1, &full) ||
        aa_render("min_adapt", "--aa 0.1", 1, &adapt) ||
        aa_render("min_0", "--aa 0.1 --aa-min-level 0", 0, &min0) ||
        aa_render("min_1", "--aa 0.1 --aa-min-level 1", 1, &min1))
        return;
    double e2 = rmse(&u2, &ref), e4 = rmse(&u4, &ref), ef = rmse(&full, &ref);
    double ea = rmse(&adapt, &ref), e1 = rmse(&min1, &ref);
    fprintf(stderr,
            "    RMSE: --ssaa 2 %.3e, --ssaa 4 %.3e, minimum = deepest = 2 %.3e; --aa 0.1 %.3e "
            "(%.2f samples/pixel), with minimum 1 %.3e (%.2f)\n",
            e2, e4, ef, ea, adapt.samples_mean, e1, min1.samples_mean);
    int off = 0, below = 0;
    for (int i = 0; i < full.w * full.h; i++) {
        off += full.levels[i] != 2 || full.leaves[i] != 16;
        below += min1.levels[i] < 1;
    }
    aa_check_maps(&full, "minimum 2, deepest 2");
    aa_check_maps(&min1, "--aa 0.1, minimum 1");
    CHECK(off == 0 && full.samples_mean == 16.0 && full.samples_max == 16,
          "minimum = deepest = 2: %d pixels not at level 2 with 16 samples; %.2f per pixel "
          "(max %u)",
          off, full.samples_mean, full.samples_max);
    CHECK(ef <= 1.6 * e4 && ef < 0.5 * e2,
          "minimum = deepest = 2: RMSE %.4e against 4x4's %.4e, 2x2's %.4e", ef, e4, e2);
    CHECK(below == 0, "minimum 1: %d pixels at level 0", below);
    CHECK(min1.samples_mean >= 4.0 && min1.samples_mean > adapt.samples_mean && e1 < ea,
          "minimum 1: %.2f samples per pixel, RMSE %.4e; without: %.2f, %.4e", min1.samples_mean,
          e1, adapt.samples_mean, ea);
    CHECK(rmse(&min0, &adapt) == 0.0 && min0.samples_mean == adapt.samples_mean,
          "a minimum of 0 differs from the default: %g", rmse(&min0, &adapt));
    /* a slot per pixel that no device holds (16384^2 x 5,440 bytes): refused, naming the
     * option, writing nothing (aa_check_fits refuses it before pass 0, which would take
     * minutes here) */
    char cmd[1024], log[4096], big[512];
    snprintf(big, sizeof big, "%s/aa_min_big.png", tu_tmpdir());
    snprintf(cmd, sizeof cmd,
             "%s %s --width 16384 --height 16384 --aa 0.1 --aa-min-level 1 -q -o %s", tu_vbcl,
             AA_SCENE, big);
    int rc = tu_run(cmd, log, sizeof log);
    FILE *f = fopen(big, "rb");
    CHECK(rc != 0 && strstr(log, "--aa-min-level") && !f,
          "16384^2 with a minimum level: exit %d, %s: %s", rc, f ? "an image written" : "no image",
          log);
    if (f) fclose(f);
    AaRender *all[] = {&ref, &u2, &u4, &full, &adapt, &min0, &min1};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++) aa_free(all[i]);
}

/* Splits leaves[i] of a list of *n quadtree leaves: its three new children are appended and
 * the child that keeps its sample takes its place. */
static void split_leaf(unsigned *leaves, int *n, int i)
{
    unsigned node = leaves[i];
    int lv = aa_node_level(node);
    int keep = aa_node_sample_cell(lv, aa_node_x(node), aa_node_y(node));
    for (int j = 0; j < 3; j++) leaves[(*n)++] = aa_new_child(node, j);
    for (int c = 0; c < 4; c++) {
        unsigned ch =
            aa_node_code(lv + 1, 2 * aa_node_x(node) + (c & 1), 2 * aa_node_y(node) + (c >> 1));
        if (aa_node_sample_cell(lv + 1, aa_node_x(ch), aa_node_y(ch)) == keep) leaves[i] = ch;
    }
}

/* The nested sample positions (kernels/aa_tree.h), checked over every node: a node's
 * sample cell lies inside it; of its four children exactly one holds the node's sample,
 * the one aa_kept_index names, the three new children (aa_new_child) are the other three,
 * each with its sample (aa_new_child_cell: the cell the walk finds) inside
 * it; the pixel centre's cell is never a new sample. Then random refinements of a pixel:
 * the samples traced (the centre, then three per split) never repeat, and they are exactly
 * the samples of the leaves. */
static void test_aa_samples_nested_never_retraced(void)
{
    for (int lv = 0; lv <= VBCL_AA_MAX_LEVEL; lv++)
        for (int y = 0; y < (1 << lv); y++)
            for (int x = 0; x < (1 << lv); x++) {
                int s = AA_TREE_SIDE >> lv, cell = aa_node_sample_cell(lv, x, y);
                int fx = cell % AA_TREE_SIDE, fy = cell / AA_TREE_SIDE;
                CHECK(fx >= x * s && fx < (x + 1) * s && fy >= y * s && fy < (y + 1) * s,
                      "node (%d, %d, %d): sample cell %d outside it", lv, x, y, cell);
                if (lv == VBCL_AA_MAX_LEVEL) continue;
                unsigned code = aa_node_code(lv, x, y);
                int holders = 0, seen = 0;
                for (int c = 0; c < 4; c++)
                    holders +=
                        aa_node_sample_cell(lv + 1, 2 * x + (c & 1), 2 * y + (c >> 1)) == cell;
                unsigned kept = aa_kept_child(code);
                CHECK(aa_node_sample_cell(lv + 1, aa_node_x(kept), aa_node_y(kept)) == cell,
                      "node (%d, %d, %d): aa_kept_index %d does not hold its sample", lv, x, y,
                      aa_kept_index(code));
                for (int j = 0; j < 3; j++) {
                    unsigned ch = aa_new_child(code, j);
                    int cx = aa_node_x(ch), cy = aa_node_y(ch);
                    int cc = aa_node_sample_cell(lv + 1, cx, cy);
                    CHECK(aa_new_child_cell(ch) == cc,
                          "node (%d, %d, %d): new child %d's cell %d, walked %d", lv, x, y, j,
                          aa_new_child_cell(ch), cc);
                    CHECK(aa_node_level(ch) == lv + 1 && cx / 2 == x && cy / 2 == y,
                          "node (%d, %d, %d): new child %d is no child", lv, x, y, j);
                    CHECK(cc != cell && cc != AA_TREE_CENTRE_CELL,
                          "node (%d, %d, %d): new child %d reuses cell %d", lv, x, y, j, cc);
                    seen |= 1 << ((cy & 1) * 2 + (cx & 1));
                }
                CHECK(holders == 1 && seen != 15 && (seen | (seen >> 1)) != 0,
                      "node (%d, %d, %d): %d children hold its sample, new ones %x", lv, x, y,
                      holders, seen);
            }
    unsigned rng = 12345;
    for (int trial = 0; trial < 200; trial++) {
        unsigned leaves[256], traced[256];
        int nleaves = 1, ntraced = 1;
        leaves[0] = aa_node_code(0, 0, 0);
        traced[0] = AA_TREE_CENTRE_CELL;
        for (int step = 0; step < 40 + trial; step++) {
            rng = rng * 1103515245u + 12345u;
            int i = (int)((rng >> 8) % (unsigned)nleaves);
            unsigned n = leaves[i];
            if (aa_node_level(n) == VBCL_AA_MAX_LEVEL) continue;
            int before = nleaves;
            split_leaf(leaves, &nleaves, i);
            for (int j = before; j < nleaves; j++) /* the three new samples */
                traced[ntraced++] = (unsigned)aa_node_sample_cell(
                    aa_node_level(leaves[j]), aa_node_x(leaves[j]), aa_node_y(leaves[j]));
        }
        int dup = 0, unmatched = 0;
        for (int a = 0; a < ntraced; a++)
            for (int b = a + 1; b < ntraced; b++) dup += traced[a] == traced[b];
        for (int a = 0; a < nleaves; a++) {
            unsigned n = leaves[a];
            int cell = aa_node_sample_cell(aa_node_level(n), aa_node_x(n), aa_node_y(n)), found = 0;
            for (int b = 0; b < ntraced; b++) found += traced[b] == (unsigned)cell;
            unmatched += found != 1;
        }
        CHECK(ntraced == nleaves && dup == 0 && unmatched == 0,
              "trial %d: %d samples traced for %d leaves, %d repeated, %d leaves unmatched", trial,
              ntraced, nleaves, dup, unmatched);
        if (th_checks_failed) break;
    }
}

/* Runs kernel `name` of prog over n work items with the nargs buffers m as its arguments. */
static int run_buffers(cl_program prog, const char *name, size_t n, const cl_mem *m, int nargs)
{
    size_t sz[16];
    const void *v[16];
    for (int i = 0; i < nargs && i < 16; i++) {
        sz[i] = sizeof(cl_mem);
        v[i] = &m[i];
    }
    return nargs <= 16 ? run_kernel(prog, name, n, nargs, sz, v) : -1;
}

/* The kernels' storage of n trees (aa_tree.h) from trees written here as 256 finest cells
 * of 4 floats (the rgb of the leaf covering the cell, its level 1 .. 4): each cell's level
 * (levels: n x 256 bytes) and each leaf's value at its node (values: n x AA_TREE_NODES
 * float4, level by level, a capacity of n slots). */
static void trees_pack(const float *cells, int n, unsigned char *levels, float *values)
{
    for (int t = 0; t < n; t++)
        for (int k = 0; k < VBCL_AA_CELLS; k++) {
            const float *c = cells + ((size_t)t * VBCL_AA_CELLS + (size_t)k) * 4;
            int lv = (int)c[3], shift = VBCL_AA_MAX_LEVEL - lv;
            int x = k % AA_TREE_SIDE >> shift, y = k / AA_TREE_SIDE >> shift;
            size_t node = (size_t)n * (size_t)aa_level_base(lv) + ((size_t)t << (2 * lv)) +
                          (size_t)((y << lv) + x);
            levels[(size_t)t * VBCL_AA_CELLS + (size_t)k] = (unsigned char)lv;
            for (int i = 0; i < 3; i++) values[4 * node + (size_t)i] = c[i];
            values[4 * node + 3] = 0.0f;
        }
}

/* One two-pixel case of the contrast kernel: pixel 0 is a tree with every leaf at level
 * l0 and value v0, pixel 1 at level l1 and value v1, except pixel 1's leaves listed in
 * odd (codes) with value v_odd; want lists the marks expected as pixel << 16 | code. */
typedef struct TwoPixelCase {
    const char *what;
    int l0, l1;
    float v0, v1, v_odd;
    unsigned odd[4], nodd;
    unsigned want[12], nwant;
    float floor; /* the contrast's floor on a + b (0: the thesis's plain ratio) */
    float gain;  /* the threshold's growth per level (1: the thesis's) */
    int first;   /* 1: a failing pair of one level splits its first leaf in raster order
                  * (--aa-pairs first, the default); 0: both (--aa-pairs both) */
} TwoPixelCase;

static void two_pixel_fill(float *cells, int lv, float v, const unsigned *odd, unsigned nodd,
                           float v_odd)
{
    for (int k = 0; k < VBCL_AA_CELLS; k++) {
        int s = AA_TREE_SIDE >> lv, x = k % AA_TREE_SIDE / s, y = k / AA_TREE_SIDE / s;
        float val = v;
        for (unsigned i = 0; i < nodd; i++)
            if (odd[i] == aa_node_code(lv, x, y)) val = v_odd;
        for (int c = 0; c < 3; c++) cells[4 * k + c] = val;
        cells[4 * k + 3] = (float)lv;
    }
}

/* Runs the case's contrast pass in `round` (split last round: pixel 1's blocks `last`,
 * two rounds ago `older`) over the whole image (aa_contrast_mark), or with `listed` over
 * the list of both pixels (aa_contrast_list, after the host's clearing of this round's
 * half of split), and checks the marks. */
static void two_pixel_run(Fixture *fx, const TwoPixelCase *tc, int round, unsigned last,
                          unsigned older, int listed)
{
    static float tree[2 * VBCL_AA_CELLS * 4], values[2 * AA_TREE_NODES * 4];
    static unsigned char levels[2 * VBCL_AA_CELLS];
    float film[8] = {0};
    int slots[2] = {0, 1};
    cl_uint counts[VBCL_AA_MAX_LEVEL + 2] = {0}, marks[2 * 64] = {0};
    two_pixel_fill(tree, tc->l0, tc->v0, NULL, 0, 0.0f);
    two_pixel_fill(tree + VBCL_AA_CELLS * 4, tc->l1, tc->v1, tc->odd, tc->nodd, tc->v_odd);
    trees_pack(tree, 2, levels, values);
    VbAaPass pass;
    memset(&pass, 0, sizeof pass);
    pass.threshold = 0.1f;
    pass.floor = tc->floor;
    pass.level_gain = tc->gain;
    pass.contrast_scale = 1.0f;
    pass.max_level = VBCL_AA_MAX_LEVEL;
    pass.width = 2;
    pass.height = 1;
    pass.round = round;
    pass.tree_cap = 2;
    pass.pairs = tc->first ? SCENE_AA_PAIRS_FIRST : SCENE_AA_PAIRS_BOTH;
    pass.entries = 2; /* with listed: both pixels */
    /* two rounds' halves: pixel 1's blocks split last round, and two rounds ago (in the
     * half this round clears for its own splits) */
    cl_uint split[4] = {0}, list[2] = {0, 1};
    split[(round + 1) % 2 * 2 + 1] = last;
    split[round % 2 * 2 + 1] = listed ? 0u : older;
    cl_mem m[9] = {
        buffer(&pass, sizeof pass),    buffer(film, sizeof film),     buffer(slots, sizeof slots),
        buffer(levels, sizeof levels), buffer(values, sizeof values), buffer(marks, sizeof marks),
        buffer(counts, sizeof counts), buffer(split, sizeof split),   buffer(list, sizeof list)};
    if (run_buffers(fx->r.film, listed ? "aa_contrast_list" : "aa_contrast_mark", 2, m,
                    listed ? 9 : 8) == 0) {
        read_buffer(m[5], marks, sizeof marks);
        read_buffer(m[6], counts, sizeof counts);
        int missing = 0;
        for (unsigned w = 0; w < tc->nwant; w++) {
            int found = 0;
            for (unsigned k = 0; k < counts[0] && k < 64; k++)
                found += (marks[2 * k] << 16 | marks[2 * k + 1]) == tc->want[w];
            missing += found != 1;
        }
        CHECK(counts[0] == tc->nwant && missing == 0,
              "%s, round %d%s: %u marks, %u expected, %d missing", tc->what, round,
              listed ? " (listed)" : "", counts[0], tc->nwant, missing);
    }
    for (int i = 0; i < 9; i++) clReleaseMemObject(m[i]);
}

#define P0(l, x, y) (0u << 16 | ((l) << 8 | (y) << 4 | (x)))
#define P1(l, x, y) (1u << 16 | ((l) << 8 | (y) << 4 | (x)))

/* The quadtree's neighbour rule across levels and across the pixel border, on the
 * contrast kernel itself with two refined pixels side by side: a leaf is compared with
 * each adjacent leaf of its neighbour at the finer level of the two (8-neighbourhood, so
 * corners count), and of a failing pair the leaf at the lower level splits; on a tie both
 * with --aa-pairs both, and with first (the default) the one first in raster order (the
 * row above, or the left one in a row), which is not always the same pixel's on a diagonal.
 * After round 0 only leaves in or next to a block of cells split in the last round are
 * tested: the same cases in round 1 mark the same leaves when all of pixel 1 was split in
 * round 0, nothing when the last split was earlier, and nothing when round 0 split only
 * pixel 1's bottom-right block, which no leaf the cases mark lies in or next to. */
static void test_aa_neighbour_rule_across_levels(void)
{
    Fixture fx;
    if (fixture_open(&fx, "{\"camera\": {\"eye\": [0,0,9], \"look_at\": [0,0,0]}, "
                          "\"materials\": {\"m\": {\"diffuse\": [1, 1, 1]}}, "
                          "\"objects\": [{\"shape\": \"box\", \"material\": \"m\"}]}"))
        return;
    const TwoPixelCase cases[] = {
        /* pixel 1 finer and brighter everywhere: only pixel 0's two leaves along the
         * border split; pixel 1's leaves see a coarser neighbour and wait */
        {"finer neighbour",
         1,
         2,
         0.5f,
         1.0f,
         1.0f,
         {0},
         0,
         {P0(1, 1, 0), P0(1, 1, 1)},
         2,
         0.0f,
         1.0f,
         0},
        /* one bright level-2 leaf of pixel 1 at the bottom of the border: pixel 0's
         * lower-right leaf splits (pixel 1's other border leaves equal it), its
         * upper-right one does not; inside pixel 1 the bright leaf and its three
         * equal-level neighbours all split */
        {"one subpixel",
         1,
         2,
         0.5f,
         0.5f,
         1.0f,
         {P1(2, 0, 3) & 0xffff},
         1,
         {P0(1, 1, 1), P1(2, 0, 3), P1(2, 0, 2), P1(2, 1, 2), P1(2, 1, 3)},
         5,
         0.0f,
         1.0f,
         0},
        /* a bright leaf higher up, (0, 1) (cells y 4..7): pixel 0's upper-right leaf
         * (y 0..7) meets it along the border, the lower-right one (y 8..15) only through
         * its corner cell (16, 7): both split */
        {"corner",
         1,
         2,
         0.5f,
         0.5f,
         1.0f,
         {P1(2, 0, 1) & 0xffff},
         1,
         {P0(1, 1, 0), P0(1, 1, 1), P1(2, 0, 1), P1(2, 0, 0), P1(2, 1, 0), P1(2, 1, 1), P1(2, 1, 2),
          P1(2, 0, 2)},
         8,
         0.0f,
         1.0f,
         0},
        /* equal levels: both sides of the border split */
        {"tie",
         1,
         1,
         0.5f,
         1.0f,
         1.0f,
         {0},
         0,
         {P0(1, 1, 0), P0(1, 1, 1), P1(1, 0, 0), P1(1, 0, 1)},
         4,
         0.0f,
         1.0f,
         0},
        /* a dark pair: relative contrast 0.33 splits both sides; with a floor of 0.5 on
         * a + b the difference 0.01 is under 0.1 * 0.5 and nothing splits */
        {"dark pair",
         1,
         1,
         0.01f,
         0.02f,
         0.02f,
         {0},
         0,
         {P0(1, 1, 0), P0(1, 1, 1), P1(1, 0, 0), P1(1, 0, 1)},
         4,
         0.0f,
         1.0f,
         0},
        {"dark pair, floor", 1, 1, 0.01f, 0.02f, 0.02f, {0}, 0, {0}, 0, 0.5f, 1.0f, 0},
        /* the threshold grows by the gain per level: contrast 1/3 fails 0.1 * 2 at level
         * 1 (the tie above, now with gain 2: both sides split) but not 0.1 * 2^2 at level
         * 2, where with the thesis's gain 1 all eight border leaves split */
        {"gain 2, level 1",
         1,
         1,
         0.5f,
         1.0f,
         1.0f,
         {0},
         0,
         {P0(1, 1, 0), P0(1, 1, 1), P1(1, 0, 0), P1(1, 0, 1)},
         4,
         0.0f,
         2.0f,
         0},
        {"gain 2, level 2", 2, 2, 0.5f, 1.0f, 1.0f, {0}, 0, {0}, 0, 0.0f, 2.0f, 0},
        {"gain 1, level 2",
         2,
         2,
         0.5f,
         1.0f,
         1.0f,
         {0},
         0,
         {P0(2, 3, 0), P0(2, 3, 1), P0(2, 3, 2), P0(2, 3, 3), P1(2, 0, 0), P1(2, 0, 1), P1(2, 0, 2),
          P1(2, 0, 3)},
         8,
         0.0f,
         1.0f,
         0},
        /* below the threshold nothing splits */
        {"no contrast", 2, 1, 0.5f, 0.55f, 0.55f, {0}, 0, {0}, 0, 0.0f, 1.0f, 0},
        /* --aa-pairs first: of the tie's pairs across the border, pixel 0's upper leaf
         * (corner cell (8, 0)) comes before both of pixel 1's (16, 0) and (16, 8); its lower
         * one (8, 8) before (16, 8) but after (16, 0), which splits instead */
        {"tie, first",
         1,
         1,
         0.5f,
         1.0f,
         1.0f,
         {0},
         0,
         {P0(1, 1, 0), P0(1, 1, 1), P1(1, 0, 0)},
         3,
         0.0f,
         1.0f,
         1},
        /* inside pixel 1 the bright leaf (0, 3) splits before its right neighbour (1, 3),
         * and after (0, 2) and (1, 2) in the row above, which split instead; pixel 0's
         * coarser leaf splits as before */
        {"one subpixel, first",
         1,
         2,
         0.5f,
         0.5f,
         1.0f,
         {P1(2, 0, 3) & 0xffff},
         1,
         {P0(1, 1, 1), P1(2, 0, 3), P1(2, 0, 2), P1(2, 1, 2)},
         4,
         0.0f,
         1.0f,
         1},
        /* the bright leaf (0, 1): (0, 0) and (1, 0) above it split, and it splits before
         * (1, 1), (1, 2) and (0, 2), which wait */
        {"corner, first",
         1,
         2,
         0.5f,
         0.5f,
         1.0f,
         {P1(2, 0, 1) & 0xffff},
         1,
         {P0(1, 1, 0), P0(1, 1, 1), P1(2, 0, 1), P1(2, 0, 0), P1(2, 1, 0)},
         5,
         0.0f,
         1.0f,
         1},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        two_pixel_run(&fx, &cases[i], 0, 0u, 0u, 0);
        for (int listed = 0; listed < 2; listed++) { /* the whole image, or both listed */
            two_pixel_run(&fx, &cases[i], 1, 0xffffu, 0u, listed);
            TwoPixelCase none = cases[i];
            none.nwant = 0;
            two_pixel_run(&fx, &none, 2, 0u, 0xffffu, listed);
            /* split last round only in pixel 1's bottom-right 4 x 4 cells: no leaf of the
             * cases' marks (all within 8 cells of the border) lies in or next to them */
            two_pixel_run(&fx, &none, 1, 0x8000u, 0u, listed);
        }
    }
    fixture_close(&fx);
}

/* The pixels the round after a split tests (aa_dirty_list): on a 5 x 4 image, marks in
 * round 2 at two corners, an inner pixel, its right neighbour and the inner pixel again (a
 * second node of it) list each pixel in or next to them once, less one already listed this
 * round (its tag 3); the same marks again in that round list nothing, and in the next round
 * all of them again. */
static void test_aa_dirty_list(void)
{
    Fixture fx;
    if (fixture_open(&fx, "{\"camera\": {\"eye\": [0,0,9], \"look_at\": [0,0,0]}, "
                          "\"materials\": {\"m\": {\"diffuse\": [1, 1, 1]}}, "
                          "\"objects\": [{\"shape\": \"box\", \"material\": \"m\"}]}"))
        return;
    enum { W = 5, H = 4, N = W * H };
    const int marked[5] = {0, 1 * W + 2, 3 * W + 4, 1 * W + 3, 1 * W + 2};
    cl_uint marks[2 * 5], tags[N] = {0}, list[N] = {0}, count = 0;
    for (int j = 0; j < 5; j++) {
        marks[2 * j] = (cl_uint)marked[j];
        marks[2 * j + 1] = aa_node_code(j == 4, 0, 0);
    }
    tags[2 * W + 1] = 3; /* listed already in this round */
    int want[N] = {0}, nwant = 0;
    for (int j = 0; j < 5; j++)
        for (int q = 0; q < N; q++)
            if (abs(q % W - marked[j] % W) <= 1 && abs(q / W - marked[j] / W) <= 1)
                want[q] = q != 2 * W + 1;
    for (int q = 0; q < N; q++) nwant += want[q];
    for (int round = 2; round <= 3; round++)
        for (int again = 0; again < (round == 2 ? 2 : 1); again++) {
            VbAaPass pass;
            memset(&pass, 0, sizeof pass);
            pass.width = W;
            pass.height = H;
            pass.round = round;
            pass.entries = 5;
            count = 0;
            cl_mem m[5] = {buffer(&pass, sizeof pass), buffer(marks, sizeof marks),
                           buffer(tags, sizeof tags), buffer(list, sizeof list),
                           buffer(&count, sizeof count)};
            if (run_buffers(fx.r.film, "aa_dirty_list", 5, m, 5) == 0) {
                read_buffer(m[2], tags, sizeof tags);
                read_buffer(m[3], list, sizeof list);
                read_buffer(m[4], &count, sizeof count);
                int seen[N] = {0}, bad = 0;
                for (cl_uint k = 0; k < count && k < N; k++) bad += list[k] >= N || seen[list[k]]++;
                for (int q = 0; q < N; q++) bad += want[q] && tags[q] != (cl_uint)round + 1;
                int expect = again ? 0 : round == 2 ? nwant : nwant + 1;
                int listed_right = 1;
                for (int q = 0; q < N && !again; q++)
                    listed_right &= seen[q] == (round == 3 ? want[q] || q == 2 * W + 1 : want[q]);
                CHECK(count == (cl_uint)expect && bad == 0 && listed_right,
                      "round %d%s: %u pixels listed, %d expected, %d repeated or untagged, %s",
                      round, again ? " again" : "", count, expect, bad,
                      listed_right ? "the right ones" : "not the right ones");
            }
            for (int i = 0; i < 5; i++) clReleaseMemObject(m[i]);
        }
    fixture_close(&fx);
}

/* A leaf's sample in half-cells of its pixel (kernels/aa.cl, aa_leaf_list): a cell's centre
 * is odd, the pixel centre 16. */
static void resolve_sample_half(unsigned code, int *hx, int *hy)
{
    int cell = aa_node_sample_cell(aa_node_level(code), aa_node_x(code), aa_node_y(code));
    *hx = cell == AA_TREE_CENTRE_CELL ? AA_TREE_SIDE : 2 * (cell % AA_TREE_SIDE) + 1;
    *hy = cell == AA_TREE_CENTRE_CELL ? AA_TREE_SIDE : 2 * (cell / AA_TREE_SIDE) + 1;
}

/* The nearest-sample value of cell (cx, cy) (half-cells) of the pixel at (px, py) of the
 * resolve test's image: the mean of the values of the nearest samples among those of the
 * pixel's own tree and of its refined neighbours' lying in cells within 8 cells of the
 * pixel (a pixel's centre sample in its cell (8, 8)), computed in double. */
enum { RES_W = 12, RES_H = 11, RES_TREES = 100 };
static double resolve_cell_nearest(const int *tree_at, const unsigned (*leaves)[VBCL_AA_CELLS],
                                   const int *nleaves, const float (*value)[VBCL_AA_CELLS], int px,
                                   int py, int cx, int cy)
{
    double best = 1e30, sum = 0.0;
    int ties = 0;
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            int qx = px + dx, qy = py + dy;
            if (qx < 0 || qx >= RES_W || qy < 0 || qy >= RES_H) continue;
            int t = tree_at[qy * RES_W + qx];
            if (t < 0) continue;
            for (int i = 0; i < nleaves[t]; i++) {
                unsigned c = leaves[t][i];
                int cell = aa_node_sample_cell(aa_node_level(c), aa_node_x(c), aa_node_y(c));
                int sx = cell % AA_TREE_SIDE + AA_TREE_SIDE * dx;
                int sy = cell / AA_TREE_SIDE + AA_TREE_SIDE * dy;
                if (sx < -8 || sx >= AA_TREE_SIDE + 8 || sy < -8 || sy >= AA_TREE_SIDE + 8)
                    continue;
                int hx, hy;
                resolve_sample_half(c, &hx, &hy);
                hx += 2 * AA_TREE_SIDE * dx;
                hy += 2 * AA_TREE_SIDE * dy;
                double d = (double)(hx - cx) * (hx - cx) + (double)(hy - cy) * (hy - cy);
                if (d < best) {
                    best = d;
                    sum = 0.0;
                    ties = 0;
                }
                if (d == best) {
                    sum += value[t][i];
                    ties++;
                }
            }
        }
    return sum / ties;
}

/* The reconstruction (aa_resolve), run on trees made here: random refinements of the
 * pixels of a 12 x 11 image (as in the test above; a column and the last rows unrefined)
 * whose leaves get random values. With reconstruct 1 each pixel is the mean of its 256
 * finest cells, each the value of the leaf covering it (the leaves' area-weighted mean);
 * with 0 (the default) each cell takes the value of the sample nearest to its centre
 * among the pixel's own and its refined neighbours' within 8 cells of it, a cell equally
 * near to several the mean of theirs, computed here in double by a search of its own.
 * First a pixel split once, by hand, with no refined neighbour: its centre sample (kept
 * by the child at (1, 1)) is nearest to 82 of the 256 cells, the new samples of the
 * children (0, 0), (1, 0) and (0, 1) to 54, 60 and 60 (the leaves' weights would be 64
 * each). Then a row of pixels each split once, every leaf 1 but the centre samples 0: a
 * right neighbour's samples take 19 of the 82 cells of a pixel's centre sample (a left
 * one's none: the fresh samples either side of the border are as far from it), so the
 * centre sample weighs 63 cells, where the leaves would give it 64. info is the deepest
 * level | leaves << 8. */
static void test_aa_resolve_nearest_samples(void)
{
    Fixture fx;
    if (fixture_open(&fx, "{\"camera\": {\"eye\": [0,0,9], \"look_at\": [0,0,0]}, "
                          "\"materials\": {\"m\": {\"diffuse\": [1, 1, 1]}}, "
                          "\"objects\": [{\"shape\": \"box\", \"material\": \"m\"}]}"))
        return;
    enum { TREES = RES_TREES, NPIX = RES_W * RES_H };
    static float tree[TREES * VBCL_AA_CELLS * 4], values[TREES * AA_TREE_NODES * 4];
    static unsigned char levels[TREES * VBCL_AA_CELLS];
    static unsigned leaves[TREES][VBCL_AA_CELLS];
    static float value[TREES][VBCL_AA_CELLS];
    int nleaves[TREES], deepest[TREES], pixels[TREES], tree_at[NPIX], slots[NPIX];
    unsigned rng = 2024;
    /* tree 0 alone at (0, 10), trees 1 .. 4 in a row at (5 .. 8, 10), each split once; the
     * others over rows 0 .. 8, column 7 left unrefined */
    for (int p = 0; p < NPIX; p++) tree_at[p] = -1;
    for (int t = 0, p = 0; t < TREES; t++) {
        if (t == 0)
            pixels[t] = 10 * RES_W;
        else if (t <= 4)
            pixels[t] = 10 * RES_W + 4 + t;
        else {
            while (p % RES_W == 7) p++;
            pixels[t] = p++;
        }
        tree_at[pixels[t]] = t;
    }
    for (int p = 0; p < NPIX; p++) slots[p] = tree_at[p];
    for (int t = 0; t < TREES; t++) {
        int n = 1;
        leaves[t][0] = aa_node_code(0, 0, 0);
        int once = t <= 4, steps = once ? 1 : 1 + t % 60;
        for (int step = 0; step < steps; step++) {
            rng = rng * 1103515245u + 12345u;
            int i = once ? 0 : (int)((rng >> 8) % (unsigned)n);
            if (aa_node_level(leaves[t][i]) < VBCL_AA_MAX_LEVEL) split_leaf(leaves[t], &n, i);
        }
        nleaves[t] = n;
        deepest[t] = 0;
        for (int i = 0; i < n; i++) {
            unsigned c = leaves[t][i];
            rng = rng * 1103515245u + 12345u;
            value[t][i] = once ? (c == aa_node_code(1, 1, 1)) == (t == 0) ? 1.0f : 0.0f
                               : (float)((rng >> 8) % 1000u) / 250.0f; /* 0 .. 4 */
            int lv = aa_node_level(c), s = AA_TREE_SIDE >> lv;
            deepest[t] = lv > deepest[t] ? lv : deepest[t];
            for (int y = aa_node_y(c) * s; y < (aa_node_y(c) + 1) * s; y++)
                for (int x = aa_node_x(c) * s; x < (aa_node_x(c) + 1) * s; x++) {
                    float *cell =
                        tree + ((size_t)t * VBCL_AA_CELLS + (size_t)(y * AA_TREE_SIDE + x)) * 4;
                    cell[0] = value[t][i];
                    cell[1] = 0.5f * value[t][i];
                    cell[2] = 1.0f - value[t][i];
                    cell[3] = (float)lv;
                }
        }
    }
    trees_pack(tree, TREES, levels, values);
    for (int mode = 0; mode < 2; mode++) {
        float film[NPIX * 4];
        int info[NPIX];
        VbAaPass pass;
        memset(&pass, 0, sizeof pass);
        pass.entries = TREES;
        pass.reconstruct = mode;
        pass.width = RES_W;
        pass.height = RES_H;
        pass.tree_cap = TREES;
        memset(film, 0, sizeof film);
        memset(info, 0, sizeof info);
        cl_mem m[7] = {buffer(&pass, sizeof pass),    buffer(pixels, sizeof pixels),
                       buffer(levels, sizeof levels), buffer(values, sizeof values),
                       buffer(film, sizeof film),     buffer(info, sizeof info),
                       buffer(slots, sizeof slots)};
        if (run_buffers(fx.r.film, "aa_resolve", TREES, m, 7) == 0) {
            read_buffer(m[4], film, sizeof film);
            read_buffer(m[5], info, sizeof info);
            int bad = 0, bad_info = 0, differs = 0;
            double worst = 0.0;
            for (int t = 0; t < TREES; t++) {
                int px = pixels[t] % RES_W, py = pixels[t] / RES_W;
                double want = 0.0, own = 0.0;
                int lone[NPIX]; /* the pixel's tree alone: its own samples' reconstruction */
                for (int q = 0; q < NPIX; q++) lone[q] = q == pixels[t] ? t : -1;
                for (int k = 0; k < VBCL_AA_CELLS; k++) {
                    int cx = 2 * (k % AA_TREE_SIDE) + 1, cy = 2 * (k / AA_TREE_SIDE) + 1;
                    if (mode) {
                        for (int i = 0; i < nleaves[t]; i++) {
                            unsigned c = leaves[t][i];
                            int s = AA_TREE_SIDE >> aa_node_level(c);
                            if (k % AA_TREE_SIDE / s == aa_node_x(c) &&
                                k / AA_TREE_SIDE / s == aa_node_y(c))
                                want += value[t][i];
                        }
                    } else {
                        want +=
                            resolve_cell_nearest(tree_at, leaves, nleaves, value, px, py, cx, cy);
                        own += resolve_cell_nearest(lone, leaves, nleaves, value, px, py, cx, cy);
                    }
                }
                want /= VBCL_AA_CELLS;
                own /= VBCL_AA_CELLS;
                double err = fabs(film[4 * pixels[t]] - want);
                worst = err > worst ? err : worst;
                bad += err > 1e-5 * (1.0 + want);
                differs += !mode && fabs(own - want) > 1e-3;
                bad_info += info[pixels[t]] != (deepest[t] | nleaves[t] << 8);
            }
            CHECK(bad == 0 && bad_info == 0,
                  "reconstruct %d: %d of %d pixels off their cells' mean (worst %.3g), %d infos "
                  "wrong",
                  mode, bad, TREES, worst, bad_info);
            /* the test has teeth: the neighbours' samples change most pixels */
            CHECK(mode || differs > TREES / 2,
                  "only %d of %d pixels differ from their own samples' reconstruction", differs,
                  TREES);
            double split_once = mode ? 64.0 / 256.0 : 82.0 / 256.0;
            float *lone = film + 4 * pixels[0];
            CHECK(fabs(lone[0] - split_once) < 1e-6 && fabs(lone[2] - (1.0 - split_once)) < 1e-6,
                  "reconstruct %d, a pixel split once: the centre sample weighs %.6f, not %.6f",
                  mode, lone[0], split_once);
            for (int t = 1; t <= 4; t++) {
                double centre = mode ? 64.0 : t < 4 ? 63.0 : 82.0; /* the last: no right one */
                CHECK(fabs(film[4 * pixels[t]] - (1.0 - centre / 256.0)) < 1e-6,
                      "reconstruct %d, a row of pixels split once: pixel %d's centre sample "
                      "weighs %.2f cells, not %.0f",
                      mode, t, 256.0 * (1.0 - film[4 * pixels[t]]), centre);
            }
        }
        for (int i = 0; i < 7; i++) clReleaseMemObject(m[i]);
    }
    fixture_close(&fx);
}

void suite_aa(void)
{
    RUN_TEST(test_aa_error_falls_with_threshold);
    RUN_TEST(test_aa_flat_regions_never_refined);
    RUN_TEST(test_aa_untouched_pixels_unchanged);
    RUN_TEST(test_aa_options);
    RUN_TEST(test_aa_min_level);
    RUN_TEST(test_aa_samples_nested_never_retraced);
    RUN_PROBE_TEST(test_aa_neighbour_rule_across_levels);
    RUN_PROBE_TEST(test_aa_resolve_nearest_samples);
    RUN_PROBE_TEST(test_aa_dirty_list);
}
