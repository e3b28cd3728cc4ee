/* test_aa_map.c — the --aa-map and --aa-samples-map images with their legends
 * (host/aa_map.c, host/util/font.c): the heat map stays the image's top-left pixels as it
 * was without a legend, the legend shows each level's colour of the map's own scale beside
 * its number, and the files vbcl writes (PNG, EXR, PFM, numbered frames) carry it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "aa.h"
#include "aa_map.h"
#include "font.h"
#include "harness.h"
#include "image_io.h"
#include "testutil.h"

#define AA_SCENE "tests/scenes/aa_edges.json"

/* The level palette in sRGB bytes, as docs/scene-format.md gives it. */
static const unsigned char palette_srgb[VBCL_AA_MAX_LEVEL + 1][3] = {
    {24, 24, 48}, {40, 90, 220}, {40, 190, 80}, {250, 210, 40}, {230, 40, 40}};

static int same_rgb(const float *p, const float c[3])
{
    return p[0] == c[0] && p[1] == c[1] && p[2] == c[2];
}

static const float *pixel(const float *img, int width, int x, int y)
{
    return img + 4 * ((size_t)y * (size_t)width + (size_t)x);
}

/* The colour of level j in a legend: the level's, or the samples map's at 4^j samples. */
static void legend_colour(int samples, int j, float c[3])
{
    if (samples)
        aa_samples_colour(1 << (2 * j), c);
    else
        aa_level_colour(j, c);
}

/* What pixel (x, y) of the strip must be, by the layout: 2 a swatch or bar pixel (any
 * colour, checked apart), 1 ink (a tick or a label's glyph), 0 white. */
static int legend_expect(const AaMapLegend *lg, int x, int y)
{
    int k = lg->scale;
    for (int j = 0; j <= lg->max_level; j++) {
        int c = lg->centre[j];
        if (x >= lg->bar_x && x < lg->bar_x + lg->bar_w &&
            (lg->samples ? y >= lg->centre[lg->max_level] - lg->half && y < lg->centre[0] + lg->half
                         : y >= c - lg->half && y < c + lg->half))
            return 2;
        if (lg->samples && x >= lg->tick_x && x < lg->tick_x + lg->tick_w && y >= c - k / 2 &&
            y < c - k / 2 + k)
            return 1;
        char label[8];
        aa_map_label(j, lg->samples, label, sizeof label);
        int top = c - FONT_GLYPH_H * k / 2, dx = x - lg->label_x;
        if (dx >= 0 && dx < font_text_width(label, k) && y >= top && y < top + FONT_GLYPH_H * k) {
            int g = dx / (FONT_ADVANCE * k), col = dx % (FONT_ADVANCE * k) / k;
            if (g < (int)strlen(label) && font_ink(label[g], col, (y - top) / k)) return 1;
        }
    }
    return 0;
}

/* One legend image checked against its values and layout. */
static void check_legend_image(const int *values, int w, int h, int samples, int max_level)
{
    AaMapLegend lg;
    float *img = aa_map_image(values, w, h, samples, max_level, &lg);
    CHECK(img != NULL, "aa_map_image %dx%d: no image", w, h);
    if (!img) return;
    const char *what = samples ? "samples map" : "level map";
    CHECK(lg.width > w && lg.height >= h && lg.map_w == w && lg.map_h == h,
          "%s %dx%d: image %dx%d leaves no strip", what, w, h, lg.width, lg.height);
    /* the map: each pixel its value's colour, alpha 1, as before the legend */
    int off = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float c[3];
            int v = values[y * w + x];
            if (samples)
                aa_samples_colour(v, c);
            else
                aa_level_colour(v, c);
            const float *p = pixel(img, lg.width, x, y);
            off += !same_rgb(p, c) || p[3] != 1.0f;
        }
    CHECK(off == 0, "%s %dx%d: %d map pixels are not their value's colour", what, w, h, off);
    /* each level's colour on its centre row, across the bar */
    for (int j = 0; j <= lg.max_level; j++) {
        float c[3];
        legend_colour(samples, j, c);
        int bad = 0;
        for (int x = lg.bar_x; x < lg.bar_x + lg.bar_w; x++)
            bad += !same_rgb(pixel(img, lg.width, x, lg.centre[j]), c);
        CHECK(bad == 0, "%s %dx%d: level %d's row in the legend is not its colour", what, w, h, j);
        if (j > 0)
            CHECK(lg.centre[j] < lg.centre[j - 1] - 2 * lg.half + 1,
                  "%s: level %d is not above level %d", what, j, j - 1);
    }
    /* the level map's swatches are one colour each; every row of the samples bar is the
     * colour of a count the map can show, counts rising upwards */
    int bad = 0, prev = 1 << 30;
    for (int j = 0; j <= lg.max_level && !samples; j++) {
        float c[3];
        aa_level_colour(j, c);
        for (int y = lg.centre[j] - lg.half; y < lg.centre[j] + lg.half; y++)
            for (int x = lg.bar_x; x < lg.bar_x + lg.bar_w; x++)
                bad += !same_rgb(pixel(img, lg.width, x, y), c);
    }
    for (int y = lg.centre[lg.max_level] - lg.half; y < lg.centre[0] + lg.half && samples; y++) {
        const float *p = pixel(img, lg.width, lg.bar_x, y);
        int found = 0;
        for (int n = 1; n <= 1 << (2 * lg.max_level) && !found; n++) {
            float c[3];
            aa_samples_colour(n, c);
            if (same_rgb(p, c)) found = n;
        }
        bad += !found || found > prev;
        prev = found ? found : prev;
    }
    CHECK(bad == 0,
          "%s %dx%d: %d pixels of the swatches or rows of the bar are not their "
          "level's or a count's colour, or the counts do not rise upwards",
          what, w, h, bad);
    /* the rest of the strip, and the rows under the map: white, ink where a tick or a
     * digit is */
    int wrong = 0;
    for (int y = 0; y < lg.height; y++)
        for (int x = y < h ? w : 0; x < lg.width; x++) {
            int want = x >= w ? legend_expect(&lg, x, y) : 0;
            if (want == 2) continue;
            const float *p = pixel(img, lg.width, x, y);
            float c = want ? 0.0f : 1.0f;
            wrong += p[0] != c || p[1] != c || p[2] != c || p[3] != 1.0f;
        }
    CHECK(wrong == 0, "%s %dx%d: %d legend pixels not as laid out (white, black ink)", what, w, h,
          wrong);
    /* every label has ink, and labels read 0..max or 1..4^max */
    for (int j = 0; j <= lg.max_level; j++) {
        char label[8];
        aa_map_label(j, samples, label, sizeof label);
        char want[8];
        snprintf(want, sizeof want, "%d", samples ? 1 << (2 * j) : j);
        CHECK(strcmp(label, want) == 0, "%s: level %d labelled %s", what, j, label);
        int ink = 0;
        int top = lg.centre[j] - FONT_GLYPH_H * lg.scale / 2;
        for (int y = top; y < top + FONT_GLYPH_H * lg.scale; y++)
            for (int x = lg.label_x; x < lg.width; x++) ink += pixel(img, lg.width, x, y)[0] == 0;
        CHECK(ink > 0, "%s: level %d has no label", what, j);
    }
    free(img);
}

/* The legend of maps of several sizes and deepest levels: the map pixels are the values'
 * colours, the strip holds each level's colour (the samples map's at 4^level) beside the
 * level's number, and the rest is white; a map shorter than the legend gets white rows
 * below it. The digits are ten distinct glyphs. */
static void test_aa_map_legend(void)
{
    for (int a = 0; a < 10; a++) {
        unsigned ga = 0, gb;
        for (int r = 0; r < FONT_GLYPH_H; r++)
            for (int c = 0; c < FONT_GLYPH_W; c++) ga = ga << 1 | (unsigned)font_ink('0' + a, c, r);
        CHECK(ga != 0, "digit %d has no ink", a);
        for (int b = 0; b < a; b++) {
            gb = 0;
            for (int r = 0; r < FONT_GLYPH_H; r++)
                for (int c = 0; c < FONT_GLYPH_W; c++)
                    gb = gb << 1 | (unsigned)font_ink('0' + b, c, r);
            CHECK(ga != gb, "digits %d and %d look alike", a, b);
        }
    }
    CHECK(font_text_width("256", 2) == 22 && font_text_width("", 3) == 0 &&
              font_ink('x', 0, 0) == 0,
          "font metrics: \"256\" at scale 2 is %d pixels wide", font_text_width("256", 2));
    static const int sizes[][3] = {{64, 64, 4}, {400, 400, 4}, {7, 3, 4}, {100, 40, 2}, {1, 1, 1}};
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
        int w = sizes[s][0], h = sizes[s][1], max = sizes[s][2];
        int *levels = malloc(sizeof(int) * (size_t)(w * h));
        int *counts = malloc(sizeof(int) * (size_t)(w * h));
        if (!levels || !counts) {
            CHECK(0, "out of memory");
            free(levels);
            free(counts);
            return;
        }
        for (int i = 0; i < w * h; i++) {
            levels[i] = (i * 7 + i / w) % (max + 1);
            counts[i] = 1 + (i * 37) % (1 << (2 * max));
        }
        check_legend_image(levels, w, h, 0, max);
        check_legend_image(counts, w, h, 1, max);
        free(levels);
        free(counts);
    }
    AaMapLegend big, small;
    aa_map_legend(400, 400, 0, 4, &big);
    aa_map_legend(64, 64, 0, 4, &small);
    CHECK(big.scale > small.scale, "a 400-row map's legend is no larger than a 64-row one's");
}

/* Reads path into *img; returns 0, or -1 after a failed check. */
static int read_image(const char *path, int *w, int *h, float **img)
{
    char err[512];
    if (image_read(path, w, h, img, err, sizeof err)) {
        CHECK(0, "%s", err);
        return -1;
    }
    return 0;
}

/* Whether the strip of img (columns from map_w on) holds a pixel of colour c, within tol. */
static int strip_has(const float *img, int width, int height, int map_w, const float c[3],
                     double tol)
{
    for (int y = 0; y < height; y++)
        for (int x = map_w; x < width; x++) {
            const float *p = pixel(img, width, x, y);
            if (fabs(p[0] - c[0]) <= tol && fabs(p[1] - c[1]) <= tol && fabs(p[2] - c[2]) <= tol)
                return 1;
        }
    return 0;
}

/* The maps vbcl writes: an adaptive render of the 64x64 edges to EXR, PFM and PNG maps. Each
 * is wider than the image (the legend); the PFM is the EXR float for float; in the PNG the
 * map's pixels are the palette's sRGB bytes (docs/scene-format.md) of the EXR's levels,
 * exactly as vbcl wrote the map before the legend; each strip holds every level's colour
 * (the samples map's at 1, 4, 16, 64, 256 samples). Numbered frames (## in the names)
 * carry the legend too. */
static void test_aa_map_files(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const char *dir = tu_tmpdir();
    const char *ext[] = {"exr", "pfm", "png"};
    float *lv[3] = {NULL, NULL, NULL}, *sp[3] = {NULL, NULL, NULL};
    int lw[3], lh[3], sw[3], sh[3];
    char cmd[2048], log[8192], lpath[512], spath[512];
    for (int f = 0; f < 3; f++) {
        snprintf(lpath, sizeof lpath, "%s/legend_lv.%s", dir, ext[f]);
        snprintf(spath, sizeof spath, "%s/legend_sp.%s", dir, ext[f]);
        snprintf(cmd, sizeof cmd,
                 "%s %s -q --aa 0.1 -o %s/legend.exr --aa-map %s --aa-samples-map %s", tu_vbcl,
                 AA_SCENE, dir, lpath, spath);
        int rc = tu_run(cmd, log, sizeof log);
        CHECK(rc == 0, "%s: exit %d: %s", cmd, rc, log);
        if (rc || read_image(lpath, &lw[f], &lh[f], &lv[f]) ||
            read_image(spath, &sw[f], &sh[f], &sp[f]))
            goto done;
        AaMapLegend lg, sg;
        aa_map_legend(64, 64, 0, VBCL_AA_MAX_LEVEL, &lg);
        aa_map_legend(64, 64, 1, VBCL_AA_MAX_LEVEL, &sg);
        CHECK(lw[f] == lg.width && lh[f] == lg.height && sw[f] == sg.width && sh[f] == sg.height,
              ".%s: maps %dx%d and %dx%d, not the 64x64 image with its legend (%dx%d, %dx%d)",
              ext[f], lw[f], lh[f], sw[f], sh[f], lg.width, lg.height, sg.width, sg.height);
        if (lw[f] != lg.width || lh[f] != lg.height || sw[f] != sg.width || sh[f] != sg.height)
            goto done;
        for (int j = 0; j <= VBCL_AA_MAX_LEVEL; j++) {
            float lc[3], scol[3];
            aa_level_colour(j, lc);
            aa_samples_colour(1 << (2 * j), scol);
            if (f == 2)
                for (int c = 0; c < 3; c++) {
                    lc[c] = palette_srgb[j][c] / 255.0f;
                    scol[c] = palette_srgb[j][c] / 255.0f; /* 4^j samples: level j's colour */
                }
            double tol = f == 2 ? 0.25 / 255 : 0.0;
            CHECK(strip_has(lv[f], lw[f], lh[f], 64, lc, tol),
                  ".%s: the level map's legend lacks level %d's colour", ext[f], j);
            CHECK(strip_has(sp[f], sw[f], sh[f], 64, scol, tol),
                  ".%s: the samples map's legend lacks the colour of %d samples", ext[f],
                  1 << (2 * j));
        }
    }
    CHECK(memcmp(lv[0], lv[1], sizeof(float) * 4 * (size_t)(lw[0] * lh[0])) == 0 &&
              memcmp(sp[0], sp[1], sizeof(float) * 4 * (size_t)(sw[0] * sh[0])) == 0,
          "the PFM maps are not the EXR maps");
    /* the PNG's map: the palette bytes of each pixel's level, read from the EXR */
    int off = 0, levels_seen = 0;
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            const float *e = pixel(lv[0], lw[0], x, y), *p = pixel(lv[2], lw[2], x, y);
            int level = -1;
            for (int j = 0; j <= VBCL_AA_MAX_LEVEL; j++) {
                float c[3];
                aa_level_colour(j, c);
                if (same_rgb(e, c)) level = j;
            }
            levels_seen |= level >= 0 ? 1 << level : 0;
            for (int c = 0; c < 3 && level >= 0; c++)
                off += lround(p[c] * 255.0f) != palette_srgb[level][c];
            off += level < 0;
        }
    CHECK(off == 0 && (levels_seen & 1) && levels_seen > 1,
          "PNG level map: %d channels off the palette bytes of the EXR's levels (levels seen %#x)",
          off, levels_seen);
    /* numbered frames of an animation */
    const char *scene = tu_write_file(
        "legend_anim.json",
        "{\"image\": {\"width\": 12, \"height\": 10, \"background\": [0.2, 0.2, 0.2]},"
        " \"camera\": {\"eye\": [0, 0, 5], \"look_at\": [0, 0, 0]},"
        " \"render\": {\"ambient\": [1, 1, 1], \"aa\": 0.1},"
        " \"materials\": {\"m\": {\"ambient\": [0.9, 0.9, 0.9], \"diffuse\": [0, 0, 0]}},"
        " \"objects\": [{\"shape\": \"box\", \"size\": [1, 1, 1], \"material\": \"m\"}],"
        " \"animation\": {\"frames\": 2, \"tracks\": [{\"target\": \"objects.0.size\","
        "   \"keys\": [[0, [1, 1, 1]], [1, [2, 1, 1]]]}]}}");
    snprintf(cmd, sizeof cmd,
             "%s %s -q -o %s/legend_f_##.png --aa-map %s/legend_fl_##.png "
             "--aa-samples-map %s/legend_fs_##.pfm",
             tu_vbcl, scene, dir, dir, dir);
    int rc = tu_run(cmd, log, sizeof log);
    CHECK(rc == 0, "%s: exit %d: %s", cmd, rc, log);
    for (int fr = 0; fr < 2 && rc == 0; fr++) {
        const char *names[2] = {"legend_fl_%02d.png", "legend_fs_%02d.pfm"};
        for (int m = 0; m < 2; m++) {
            char name[64], path[600];
            snprintf(name, sizeof name, names[m], fr);
            snprintf(path, sizeof path, "%s/%s", dir, name);
            int w, h;
            float *img = NULL;
            if (read_image(path, &w, &h, &img)) continue;
            AaMapLegend lg;
            aa_map_legend(12, 10, m, VBCL_AA_MAX_LEVEL, &lg);
            CHECK(w == lg.width && h == lg.height, "frame %d: %s is %dx%d, not %dx%d", fr, name, w,
                  h, lg.width, lg.height);
            float c[3];
            legend_colour(m, VBCL_AA_MAX_LEVEL, c);
            if (m == 0)
                for (int k = 0; k < 3; k++) c[k] = palette_srgb[VBCL_AA_MAX_LEVEL][k] / 255.0f;
            CHECK(w == lg.width && strip_has(img, w, h, 12, c, m == 0 ? 0.25 / 255 : 0.0),
                  "frame %d: %s has no legend", fr, name);
            free(img);
        }
    }
done:
    for (int f = 0; f < 3; f++) {
        free(lv[f]);
        free(sp[f]);
    }
}

void suite_aa_map(void)
{
    RUN_TEST(test_aa_map_legend);
    RUN_TEST(test_aa_map_files);
}
