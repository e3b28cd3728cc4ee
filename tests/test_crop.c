/* test_crop.c — --crop, a region of the image (issue 55): the region written is the whole
 * image's region bit for bit (floats of .pfm outputs) on an opaque, a glass, a dispersive and
 * a textured scene, with and without adaptive anti-aliasing, whose contrast test at the
 * region's edge reads the pixels around it; in pixels and as fractions of the image
 * (rounded up as pbrt's crop window); touching the image's edges; with --ssaa, the frames of
 * an animation, the anti-aliasing maps, --stats-json, two devices and two MPI ranks; only
 * the region's pixels traced; and bad values refused with exit 2, one line naming --crop,
 * the output untouched. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cJSON.h>

#include "dist.h"
#include "harness.h"
#include "testutil.h"

/* The image the renders crop. */
#define W 48
#define H 40

/* An image read back from a .pfm: rgb floats, row 0 at the top. */
typedef struct Img {
    int w, h;
    float *px;
} Img;

/* Reads the .pfm at path (as vbcl writes it: "PF", little-endian, bottom row first) into
 * *im. Returns 0, or -1 after a failed check. */
static int pfm_read(const char *path, Img *im)
{
    im->px = NULL;
    FILE *f = fopen(path, "rb");
    float scale = 0.0f;
    int ok = f && fscanf(f, "PF %d %d %f", &im->w, &im->h, &scale) == 3 && fgetc(f) == '\n' &&
             im->w > 0 && im->h > 0 && scale < 0.0f;
    size_t n = ok ? (size_t)im->w * (size_t)im->h * 3 : 0;
    if (ok && (im->px = malloc(sizeof(float) * n)))
        for (int y = im->h - 1; y >= 0 && ok; y--)
            ok = fread(im->px + (size_t)y * (size_t)im->w * 3, sizeof(float) * 3, (size_t)im->w,
                       f) == (size_t)im->w;
    if (f) fclose(f);
    CHECK(ok && im->px, "%s: not a .pfm vbcl wrote", path);
    if (ok && im->px) return 0;
    free(im->px);
    im->px = NULL;
    return -1;
}

/* Renders scene at W x H with 4 feelers and opts into TMP/name.pfm (read into *im), with its
 * --stats-json into TMP/name.json. env: variables or a launcher before vbcl. Returns 0, or -1
 * after a failed check. */
static int render_env(const char *env, const char *scene, const char *opts, const char *name,
                      Img *im)
{
    char cmd[4096], out[8192], path[1024];
    snprintf(path, sizeof path, "%s/%s.pfm", tu_tmpdir(), name);
    snprintf(cmd, sizeof cmd,
             "%stimeout 300 %s %s -q --width %d --height %d --shadow-samples 4 -o %s "
             "--stats-json %s/%s.json %s",
             env, tu_vbcl, scene, W, H, path, tu_tmpdir(), name, opts);
    int rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 0, "%s: exit %d: %s", cmd, rc, out);
    im->px = NULL;
    return rc == 0 ? pfm_read(path, im) : -1;
}

static int render(const char *scene, const char *opts, const char *name, Img *im)
{
    return render_env("", scene, opts, name, im);
}

/* The --stats-json document of render `name` (the caller deletes it), or NULL. */
static cJSON *stats_of(const char *name)
{
    static char text[1 << 17];
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.json", tu_tmpdir(), name);
    return cJSON_Parse(tu_read_file(path, text, sizeof text));
}

/* The number at doc.group.key, or -1. */
static double stat_num(const cJSON *doc, const char *group, const char *key)
{
    const cJSON *v =
        cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, group), key);
    return cJSON_IsNumber(v) ? v->valuedouble : -1.0;
}

/* The most refinement rounds of a frame of render `name` (--stats-json aa.rounds, of each
 * frame of an animation), or -1. */
static int rounds_of(const char *name)
{
    cJSON *doc = stats_of(name), *frames = cJSON_GetObjectItemCaseSensitive(doc, "frames"), *f;
    int r = (int)stat_num(doc, "aa", "rounds");
    cJSON_ArrayForEach(f, frames) if (stat_num(f, "aa", "rounds") > r) r =
        (int)stat_num(f, "aa", "rounds");
    cJSON_Delete(doc);
    return r;
}

/* The margin of the anti-aliased crops that render less than the image. The crop is the
 * whole image's region when both renders refine in fewer rounds than the margin
 * (frame_margin, docs/architecture.md "A region of the image"): checked for each pair of
 * renders (margin_holds), so that a scene refined longer fails here, not as a difference.
 * (A window can refine longer than the whole image, near its own edges: with a margin of 12
 * the quickstart's region 30,25,48,40 takes 23 rounds against the image's 7, and its pixels
 * are still the image's; the test's regions are ones whose windows take fewer.) */
#define SMALL_MARGIN 12

static void margin_holds(const char *whole, const char *crop)
{
    int a = rounds_of(whole), b = rounds_of(crop);
    CHECK(a > 0 && a < SMALL_MARGIN && b >= 0 && b < SMALL_MARGIN,
          "%s, %s: refinement in fewer rounds than the margin %d (%d, %d), which makes the "
          "cropped refinement exact: raise SMALL_MARGIN",
          whole, crop, SMALL_MARGIN, a, b);
}

/* How many pixels of region reg (x0, y0, x1, y1) of full differ from crop's (any bit of any
 * channel); -1 when crop is not the region's size. */
/* The pixels of crop's top-left region-sized corner that differ from the region reg of full,
 * or -1 when crop is smaller than the region (or, with exact set, not its size). */
static long corner_differs(const Img *full, const int reg[4], const Img *crop, int exact)
{
    int w = reg[2] - reg[0], h = reg[3] - reg[1];
    if (!full->px || !crop->px || crop->w < w || crop->h < h ||
        (exact && (crop->w != w || crop->h != h)))
        return -1;
    long n = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            n += memcmp(crop->px + 3 * ((size_t)y * (size_t)crop->w + (size_t)x),
                        full->px +
                            3 * ((size_t)(y + reg[1]) * (size_t)full->w + (size_t)(x + reg[0])),
                        sizeof(float) * 3) != 0;
    return n;
}

/* The pixels of crop, an image of the region reg's size, that differ from the region of
 * full, or -1 when the sizes do not fit. */
static long region_differs(const Img *full, const int reg[4], const Img *crop)
{
    return corner_differs(full, reg, crop, 1);
}

/* Renders scene cropped to reg with opts as TMP/name.pfm and checks it against the region of
 * full. */
static void crop_matches(const char *scene, const char *opts, const int reg[4], const Img *full,
                         const char *name)
{
    char args[1024];
    Img crop;
    snprintf(args, sizeof args, "%s --crop %d,%d,%d,%d", opts, reg[0], reg[1], reg[2], reg[3]);
    if (render(scene, args, name, &crop)) return;
    long d = region_differs(full, reg, &crop);
    CHECK(d == 0, "%s: %s %s: %ld pixels differ from the whole image's (-1: its size, %dx%d)", name,
          scene, args, d, crop.w, crop.h);
    free(crop.px);
}

/* The scenes of test_crop_scenes, with short names. */
static const struct {
    const char *name, *path;
} scenes[] = {
    {"opaque", "scenes/quickstart.json"},
    {"glass", "scenes/glass_bombed_sphere.json"},
    {"dispersive", "scenes/prism_dispersion.json"},
    {"textured", "scenes/checker_glass.json"},
};

/* An inner region on four scenes, plain and with --aa 0.1: the crop is the whole image's
 * region bit for bit; with --aa at a margin of SMALL_MARGIN pixels, which refines a window
 * smaller than the image (the rounds checked below the margin), and on the first scene at the
 * default margin (the refinement's whole reach: here the whole image). */
static void test_crop_scenes(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const int reg[4] = {13, 10, 31, 27};
    for (size_t k = 0; k < sizeof scenes / sizeof scenes[0]; k++) {
        char name[128];
        Img full, full_aa;
        snprintf(name, sizeof name, "%s_full", scenes[k].name);
        if (render(scenes[k].path, "", name, &full)) continue;
        snprintf(name, sizeof name, "%s_crop", scenes[k].name);
        crop_matches(scenes[k].path, "", reg, &full, name);
        snprintf(name, sizeof name, "%s_full_aa", scenes[k].name);
        if (render(scenes[k].path, "--aa 0.1", name, &full_aa)) {
            free(full.px);
            continue;
        }
        if (k == 0) { /* at 48 x 40 the default margin renders the whole image: one scene */
            snprintf(name, sizeof name, "%s_crop_aa", scenes[k].name);
            crop_matches(scenes[k].path, "--aa 0.1", reg, &full_aa, name);
        }
        snprintf(name, sizeof name, "%s_crop_aa_margin", scenes[k].name);
        char opts[128];
        snprintf(opts, sizeof opts, "--aa 0.1 --crop-margin %d", SMALL_MARGIN);
        crop_matches(scenes[k].path, opts, reg, &full_aa, name);
        char whole[128];
        snprintf(whole, sizeof whole, "%s_full_aa", scenes[k].name);
        margin_holds(whole, name);
        cJSON *doc = stats_of(name);
        const cJSON *win = cJSON_GetObjectItemCaseSensitive(
            cJSON_GetObjectItemCaseSensitive(doc, "crop"), "window");
        CHECK(cJSON_GetArraySize(win) == 4 && cJSON_GetArrayItem(win, 0)->valueint > 0 &&
                  cJSON_GetArrayItem(win, 2)->valueint < W,
              "%s: the window (the region and a margin of %d) is narrower than the image",
              scenes[k].name, SMALL_MARGIN);
        cJSON_Delete(doc);
        free(full.px);
        free(full_aa.px);
    }
}

/* The same bytes of two files. */
static int same_file(const char *a, const char *b)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "cmp -s %s/%s %s/%s", tu_tmpdir(), a, tu_tmpdir(), b);
    return tu_run(cmd, NULL, 0) == 0;
}

/* Fractions of the image are pbrt's crop window, rounded up: on 48 x 40 the fractions
 * 0.25,0.25,0.75,0.5 are pixels 12,10,36,20, the same file; on 40 x 40, 0.3 x 40 in single
 * precision is 12 (12.000000000000002 in double, whose ceiling would be 13), so
 * 0.3,0.3,0.7,0.7 are pixels 12,12,28,28. --stats-json records the region. */
static void test_crop_fractions(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const char *scene = "scenes/quickstart.json";
    Img a = {0, 0, NULL}, b = a, c = a, d = a;
    if (!render(scene, "--crop 0.25,0.25,0.75,0.5", "frac", &a) &&
        !render(scene, "--crop 12,10,36,20", "frac_px", &b)) {
        CHECK(a.w == 24 && a.h == 10, "0.25,0.25,0.75,0.5 of 48x40: %dx%d, want 24x10", a.w, a.h);
        CHECK(same_file("frac.pfm", "frac_px.pfm"), "fractions and pixels: the same file");
        cJSON *doc = stats_of("frac");
        const cJSON *r = cJSON_GetObjectItemCaseSensitive(
            cJSON_GetObjectItemCaseSensitive(doc, "crop"), "region");
        CHECK(cJSON_GetArraySize(r) == 4 && cJSON_GetArrayItem(r, 0)->valueint == 12 &&
                  cJSON_GetArrayItem(r, 1)->valueint == 10 &&
                  cJSON_GetArrayItem(r, 2)->valueint == 36 &&
                  cJSON_GetArrayItem(r, 3)->valueint == 20,
              "--stats-json crop.region is [12, 10, 36, 20]");
        cJSON_Delete(doc);
    }
    if (!render(scene, "--width 40 --crop 0.3,0.3,0.7,0.7", "frac40", &c) &&
        !render(scene, "--width 40 --crop 12,12,28,28", "frac40_px", &d)) {
        CHECK(c.w == 16 && c.h == 16, "0.3,0.3,0.7,0.7 of 40x40: %dx%d, want 16x16", c.w, c.h);
        CHECK(same_file("frac40.pfm", "frac40_px.pfm"), "0.3 of 40 is pixel 12, as in pbrt");
    }
    free(a.px);
    free(b.px);
    free(c.px);
    free(d.px);
}

/* Regions touching the image's edges and corners, plain and anti-aliased with a margin
 * clipped by the image: each the whole image's region bit for bit; the whole image as a
 * region is the same file as no crop. */
static void test_crop_edges(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const char *scene = "scenes/quickstart.json";
    static const int regs[][4] = {
        {0, 0, 16, 12}, {32, 28, W, H}, {0, 14, W, 22}, {20, 0, 27, H}, {W - 1, 0, W, 1}};
    char opts[128];
    snprintf(opts, sizeof opts, "--aa 0.1 --crop-margin %d", SMALL_MARGIN);
    const char *const modes[2] = {"", "--aa 0.1"}, *const crops[2] = {"", opts};
    for (int m = 0; m < 2; m++) {
        char name[128];
        Img full;
        snprintf(name, sizeof name, "edges_full%d", m);
        if (render(scene, modes[m], name, &full)) continue;
        for (size_t k = 0; k < sizeof regs / sizeof regs[0]; k++) {
            snprintf(name, sizeof name, "edges%d_%zu", m, k);
            crop_matches(scene, crops[m], regs[k], &full, name);
            if (m) margin_holds("edges_full1", name);
        }
        free(full.px);
    }
    Img all;
    if (!render(scene, "--crop 0,0,48,40", "edges_whole", &all))
        CHECK(same_file("edges_whole.pfm", "edges_full0.pfm"),
              "--crop 0,0,48,40 is the image without --crop");
    free(all.px);
}

/* Uniform supersampling, the frames of an animation, the anti-aliasing maps and
 * --stats-json: the crop of each is the whole's region; --stats-json records the crop, and
 * without anti-aliasing traces only the region's camera rays. */
static void test_crop_modes(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const int reg[4] = {9, 7, 29, 25};
    const char *scene = "scenes/quickstart.json";
    Img full, maps[4];
    if (!render(scene, "--ssaa 2", "ssaa_full", &full)) {
        crop_matches(scene, "--ssaa 2", reg, &full, "ssaa_crop");
        free(full.px);
    }
    /* the maps, as .pfm */
    char opts[1024], cropped[64];
    const char *tmp = tu_tmpdir();
    snprintf(cropped, sizeof cropped, " --crop 9,7,29,25 --crop-margin %d", SMALL_MARGIN);
    for (int c = 0; c < 2; c++) {
        snprintf(opts, sizeof opts, "--aa 0.1 --aa-map %s/lv%d.pfm --aa-samples-map %s/sp%d.pfm%s",
                 tmp, c, tmp, c, c ? cropped : "");
        Img im;
        if (render(scene, opts, c ? "maps_crop" : "maps_full", &im)) return;
        free(im.px);
        char path[1024];
        snprintf(path, sizeof path, "%s/lv%d.pfm", tmp, c);
        pfm_read(path, &maps[2 * c]);
        snprintf(path, sizeof path, "%s/sp%d.pfm", tmp, c);
        pfm_read(path, &maps[2 * c + 1]);
    }
    margin_holds("maps_full", "maps_crop");
    /* each map is its image's top-left corner, its legend to the right (aa_map.h) */
    CHECK(corner_differs(&maps[0], reg, &maps[2], 0) == 0, "--aa-map: the crop is the region");
    CHECK(corner_differs(&maps[1], reg, &maps[3], 0) == 0,
          "--aa-samples-map: the crop is the region");
    for (int k = 0; k < 4; k++) free(maps[k].px);
    /* an animation: the first two frames of the thesis's figure A.6 (eta falls from 3.7) */
    const char *anim = "scenes/thesis/a6_eta_animation.json";
    char cmd[4096], out[8192];
    for (int c = 0; c < 2; c++) {
        snprintf(cmd, sizeof cmd,
                 "timeout 300 %s %s -q --frames 0:1 --width %d --height %d --shadow-samples 4 "
                 "--aa 0.1 -o %s/anim%d_#.pfm%s --stats-json %s/anim%d.json",
                 tu_vbcl, anim, W, H, tmp, c, c ? cropped : "", tmp, c);
        int rc = tu_run(cmd, out, sizeof out);
        CHECK(rc == 0, "%s: exit %d: %s", cmd, rc, out);
    }
    margin_holds("anim0", "anim1");
    for (int f = 0; f < 2; f++) {
        char a[1024], b[1024];
        Img fa = {0, 0, NULL}, fb = {0, 0, NULL};
        snprintf(a, sizeof a, "%s/anim0_%d.pfm", tmp, f);
        snprintf(b, sizeof b, "%s/anim1_%d.pfm", tmp, f);
        if (!pfm_read(a, &fa) && !pfm_read(b, &fb))
            CHECK(region_differs(&fa, reg, &fb) == 0, "animation frame %d: the crop is the region",
                  f);
        free(fa.px);
        free(fb.px);
    }
    /* --stats-json: the crop recorded, only the region's camera rays traced */
    Img im;
    if (render(scene, "--crop 9,7,29,25", "stats_crop", &im)) return;
    free(im.px);
    cJSON *doc = stats_of("stats_crop");
    const cJSON *crop = cJSON_GetObjectItemCaseSensitive(doc, "crop");
    CHECK(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(crop, "cropped")) &&
              stat_num(doc, "crop", "width") == 20 && stat_num(doc, "crop", "height") == 18 &&
              stat_num(doc, "crop", "margin") == 0 && stat_num(doc, "crop", "window_pixels") == 360,
          "--stats-json crop: cropped, 20x18, margin 0, 360 pixels rendered");
    CHECK(stat_num(doc, "rays", "primary") == 360 && stat_num(doc, "samples", "total") == 360,
          "the region's camera rays only: %g (want 360)", stat_num(doc, "rays", "primary"));
    cJSON_Delete(doc);
    doc = stats_of("ssaa_full");
    CHECK(cJSON_IsFalse(cJSON_GetObjectItemCaseSensitive(
              cJSON_GetObjectItemCaseSensitive(doc, "crop"), "cropped")) &&
              stat_num(doc, "crop", "window_pixels") == W * H,
          "--stats-json without --crop: not cropped, the whole image rendered");
    cJSON_Delete(doc);
}

/* Two PoCL devices sharing the tiles and two MPI ranks give the one-device crop bit for bit,
 * plain and anti-aliased (refinement on the first device, or on rank 0). */
static void test_crop_devices(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const char *scene = "scenes/glass_bombed_sphere.json";
    char opts[256];
    snprintf(opts, sizeof opts, "--crop 5,4,41,33 --aa 0.1 --crop-margin %d", SMALL_MARGIN);
    const char *const cases[2] = {"--crop 5,4,41,33", opts};
    char out[4096], cmd[1024];
    snprintf(cmd, sizeof cmd, "POCL_DEVICES='pthread pthread' %s --list-devices", tu_vbcl);
    int two = tu_run(cmd, out, sizeof out) == 0 && strstr(out, "\n1: ");
    int mpi = dist_available() && tu_run("command -v mpirun", NULL, 0) == 0;
    for (int c = 0; c < 2; c++) {
        Img one, all, ranks;
        char name[64], more[512];
        snprintf(name, sizeof name, "dev_one%d", c);
        if (render(scene, cases[c], name, &one)) continue;
        int reg[4] = {0, 0, one.w, one.h};
        if (two) {
            snprintf(name, sizeof name, "dev_all%d", c);
            snprintf(more, sizeof more, "%s --device all", cases[c]);
            if (!render_env("POCL_DEVICES='pthread pthread' ", scene, more, name, &all)) {
                CHECK(region_differs(&one, reg, &all) == 0, "--device all: %s", cases[c]);
                free(all.px);
            }
        }
        if (mpi) {
            snprintf(name, sizeof name, "dev_mpi%d", c);
            snprintf(more, sizeof more,
                     "mpirun %s--oversubscribe --mca btl_vader_single_copy_mechanism none -x "
                     "LSAN_OPTIONS=detect_leaks=0 -np 2 ",
                     getuid() == 0 ? "--allow-run-as-root " : "");
            if (!render_env(more, scene, cases[c], name, &ranks)) {
                CHECK(region_differs(&one, reg, &ranks) == 0, "2 MPI ranks: %s", cases[c]);
                free(ranks.px);
            }
        }
        free(one.px);
    }
    if (!two) th_skip("PoCL does not list two devices under POCL_DEVICES='pthread pthread'");
    if (!mpi) th_skip("no MPI build or no mpirun");
}

/* A bad --crop or --crop-margin: exit 2, one line naming the option (and the value as given
 * for --crop), the output file as it was. */
static void expect_refused(const char *args, const char *needle)
{
    const char *scene = tu_write_file(
        "crop_bad.json", "{\"image\": {\"width\": 48, \"height\": 40},"
                         " \"camera\": {\"eye\": [0, 1, 5], \"look_at\": [0, 0, 0]},"
                         " \"lights\": [{\"centre\": [2, 4, 3], \"radius\": 0.5, \"flux\": 500}],"
                         " \"materials\": {\"m\": {}}, \"objects\": [{\"shape\": \"sphere\", "
                         "\"material\": \"m\"}]}");
    tu_expect_refused(scene, args, needle);
}

static void test_crop_refused(void)
{
    static const char *const cases[][2] = {
        {"--crop 10,10,10,20", "--crop 10,10,10,20: an empty region: X1 = 10 must be greater"},
        {"--crop 20,10,12,30", "--crop 20,10,12,30: an empty region"},
        {"--crop 5,30,40,8", "--crop 5,30,40,8: an empty region: Y1 = 8"},
        {"--crop 0,0,49,40", "--crop 0,0,49,40: X1 = 49 lies outside the 48x40 image"},
        {"--crop 0,0,48,41", "--crop 0,0,48,41: Y1 = 41 lies outside the 48x40 image"},
        {"--crop=-1,0,4,4", "--crop -1,0,4,4: X0 = -1 lies outside the image"},
        {"--crop 1,2,3", "--crop 1,2,3: expected X0,Y0,X1,Y1"},
        {"--crop 1,2,3,4,5", "--crop 1,2,3,4,5: expected X0,Y0,X1,Y1"},
        {"--crop a,b,c,d", "--crop a,b,c,d: expected X0,Y0,X1,Y1"},
        {"--crop 0.1,0,0.5,0.5", "--crop 0.1,0,0.5,0.5: expected X0,Y0,X1,Y1"},
        {"--crop 0.5,0.5,1.5,0.9", "--crop 0.5,0.5,1.5,0.9: X1 = 1.5 lies outside the image"},
        {"--crop 0.101,0.1,0.104,0.5", "--crop 0.101,0.1,0.104,0.5: rounds to no pixel"},
        {"--crop", "--crop needs a value"},
        {"--crop 0,0,8,8 --crop-margin 4", "--crop-margin 4: needs --crop and adaptive"},
        {"--aa 0.1 --crop-margin 4", "--crop-margin 4: needs --crop"},
        {"--aa 0.1 --crop 0,0,8,8 --crop-margin -1", "--crop-margin -1: expected a whole number"},
        {"--crop 0,0,8,8 --width 4", "--crop 0,0,8,8: X1 = 8 lies outside the 4x40 image"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++)
        expect_refused(cases[k][0], cases[k][1]);
}

void suite_crop(void)
{
    RUN_TEST(test_crop_refused);
    RUN_TEST(test_crop_fractions);
    RUN_TEST(test_crop_edges);
    RUN_TEST(test_crop_modes);
    RUN_TEST(test_crop_scenes);
    RUN_TEST(test_crop_devices);
}
