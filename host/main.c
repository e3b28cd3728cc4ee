/* main.c — the vbcl command line: parse options, load the scene, render, write the
 * image, report. Only this file exits. */
#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <sys/resource.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "aa.h"
#include "aa_map.h"
#include "frame.h"
#include "clu.h"
#include "diag.h"
#include "dist.h"
#include "kernel_features.h"
#include "image_io.h"
#include "fileio.h"
#include "render.h"
#include "scene.h"
#include "stats.h"
#include "texgen.h"
#include "warm.h"

#define VBCL_VERSION "0.1.0"

/* The prefix of every message: "vbcl", or "vbcl: rank N" on the other ranks of an MPI run. */
static const char *prog = "vbcl";
static int mpi_rank = -1; /* this process's rank in an MPI run of several, else -1 */

static const char usage_text[] =
    "usage: vbcl SCENE.json [options]\n"
    "       vbcl --list-devices\n"
    "       vbcl --warm-cache [--device ...]\n"
    "       vbcl texgen METHOD [options] -o FILE   (3D textures: vbcl texgen --help)\n"
    "\n"
    "Renders a volume-textured scene with OpenCL and writes the image; the format follows\n"
    "the extension: .png .jpg .tif (8-bit sRGB), .exr or .pfm (linear float; vbcl writes\n"
    ".pfm itself, without OpenImageIO). SCENE.json may be a pipe; - reads it from standard\n"
    "input (mesh paths then start at the current directory).\n"
    "\n"
    "options (each overrides the scene's own setting; --option=value works too):\n"
    "  -o, --output FILE        image to write (default: image.output, else SCENE.png);\n"
    "                           frames of an animation are numbered: a run of # in FILE\n"
    "                           becomes the frame number, else FILE_0007.png\n"
    "      --frames A:B         render frames A to B of an animated scene (or one: N);\n"
    "                           default: all of them\n"
    "      --width N            image width in pixels (1..16384)\n"
    "      --height N           image height in pixels (1..16384)\n"
    "      --crop X0,Y0,X1,Y1   render and write only this region of the image, its pixels\n"
    "                           the whole image's bit for bit: whole pixels (X0,Y0 its top-\n"
    "                           left pixel, 0,0 the image's; X1,Y1 one past its right column\n"
    "                           and bottom row), or fractions of the image from 0 to 1 with\n"
    "                           a decimal point, each bound rounded up to a pixel as pbrt's\n"
    "                           crop window (0.25,0.25,0.75,0.5; pbrt's --cropwindow lists\n"
    "                           them as X0,X1,Y0,Y1)\n"
    "      --crop-margin N      with --aa, the pixels rendered around the region for its\n"
    "                           contrast test (default: the refinement's whole reach, 257\n"
    "                           less --aa-min-level); a smaller margin is faster, and the\n"
    "                           region stays the whole image's while both refine in fewer\n"
    "                           than N rounds (--stats)\n"
    "      --grid TOP[:SUB]     two-level grid: TOP, the top level, is auto, N or X,Y,Z\n"
    "                           (1..1024 per axis, at most 134217728 cells in all; default\n"
    "                           auto); SUB, the sub-grid in each crowded top cell, is auto\n"
    "                           (default: sized by the cell's triangles) or N or X,Y,Z\n"
    "                           (1..64) in every cell with 2 or more; :1 = one level only\n"
    "      --grid-density D     cells per triangle for --grid auto\n"
    "      --subgrid-density D  sub-cells per triangle of a crowded top cell (default 2)\n"
    "      --no-camera-tiles    camera rays walk the grid instead of testing the triangles\n"
    "                           of their image tile nearest first (same image, slower)\n"
    "      --shadow-samples N   shadow feelers per light per point (nearest square)\n"
    "      --seed N             seed of the feelers' jitter (0..2147483647; default 1)\n"
    "      --no-cone-test       trace every feeler, also where the cone from the point to\n"
    "                           the light meets no object's bounds, and every ray of a ray\n"
    "                           tree through the grid (same image, slower)\n"
    "      --all-feelers        every point of a ray tree gets all its feelers (default: a\n"
    "                           point whose share of its sample is w <= 1/4 gets about\n"
    "                           w x N of the N, at least one)\n"
    "      --no-sample-shares   with --aa, a ray-tree point of a quadtree sample at level\n"
    "                           L gets the feelers of its weight w, not of w x 2^-L\n"
    "      --penumbra-feelers K  a point whose first feelers toward a light disagree (a\n"
    "                           penumbra) traces K times as many (1, 2, 4, 8, 16; default\n"
    "                           4; 1 off; feelers of a power-of-two side only)\n"
    "      --depth N            maximum depth of the ray tree (1..64)\n"
    "      --min-weight W       prune ray-tree branches weighing less than W (0..1)\n"
    "      --fresnel exact|thesis  energy split at interfaces: Fresnel, or thesis eq. 9\n"
    "      --exposure STOPS     scale the image by 2^STOPS before writing\n"
    "      --aa THRESHOLD       adaptive anti-aliasing: split pixels and subpixels whose\n"
    "                           contrast |a-b|/max(a+b,F) with an adjacent one exceeds\n"
    "                           THRESHOLD (0..1; 0 off; F: --aa-floor)\n"
    "      --aa-max-level L     deepest refinement, 2^L x 2^L subpixels per pixel (1..4)\n"
    "      --aa-min-level L     split every pixel down to 2^L x 2^L subpixels before the\n"
    "                           contrast test (0..max level; default 0): a floor under\n"
    "                           adaptivity for features pass 0's one ray misses; equal to\n"
    "                           --aa-max-level, uniform 4^L samples through the quadtree\n"
    "      --aa-floor F         contrast of dark pairs: a+b counts as at least F (0..2;\n"
    "                           default 1: below it the test is |a-b| > THRESHOLD; 0:\n"
    "                           the thesis's plain ratio)\n"
    "      --aa-level-gain G    the threshold of a subpixel at level L is THRESHOLD*G^L\n"
    "                           (1..4; default 2; 1: the thesis's, alike at every level)\n"
    "      --aa-reconstruct nearest|leaves  a refined pixel is the mean of its 16x16 finest\n"
    "                           cells, each the value of the sample nearest to it\n"
    "                           (default) or of the leaf covering it (the thesis's)\n"
    "      --aa-pairs first|both  of two adjacent subpixels of one level that fail, split\n"
    "                           the first in raster order, the other only if it still\n"
    "                           fails against the first's children (default, the\n"
    "                           thesis's figure 4.2), or both at once\n"
    "      --bands N|thesis     wavelength bands of a dispersive refraction (1..64), or the\n"
    "                           thesis's per-channel rays (1 red, 2 green, 3 blue)\n"
    "      --ssaa N             uniform N x N supersampling of every pixel (1..16)\n"
    "      --aa-map FILE        write each pixel's deepest refinement level as a heat map\n"
    "                           (dark 0, blue 1, green 2, yellow 3, red 4), a legend of\n"
    "                           the levels' colours and numbers to its right (the map\n"
    "                           stays the image's top-left WIDTH x HEIGHT pixels); frames\n"
    "                           are numbered as with -o\n"
    "      --aa-samples-map FILE  write each pixel's number of samples as a heat map on the\n"
    "                           same colours (dark 1, blue 4, green 16, yellow 64, red\n"
    "                           256), its legend a colour bar marked 1, 4, 16, 64, 256\n"
    "      --device INDEX|NAME|all|LIST  OpenCL device (also VBCL_DEVICE; default: device 0);\n"
    "                           all, or a list such as 0,2 or pocl,intel, shares pass 0's\n"
    "                           tiles among several (refinement runs on the first)\n"
    "      --list-devices       list OpenCL platforms and devices with their indices\n"
    "      --warm-cache         compile every kernel program for the chosen devices, all\n"
    "                           cores at once, and exit: later renders compile nothing\n"
    "                           (make run does it first; 2 - 2.5 minutes on 2 cores)\n"
    "      --stats              print rays by kind, time per stage and grid statistics\n"
    "      --stats-json FILE    write the same statistics as JSON (fields: docs/stats.md);\n"
    "                           an animation's frames go into one array, \"frames\"\n"
    "  -q, --quiet              print nothing but errors\n"
    "  -h, --help               show this help\n"
    "      --version            show the version\n"
    "\n"
    "environment: VBCL_DEVICE (as --device), VBCL_CACHE_DIR (vbcl's cache: kernel\n"
    "binaries, the stamps of programs compiled, textures; \"off\" disables it; default\n"
    "~/.cache/vbcl), VBCL_CACHE_MAX_MB (its binaries' size, default 256),\n"
    "VBCL_CACHE_BINARIES (1: store binaries on every driver, 0: on none; default: not on\n"
    "PoCL, which keeps compiled kernels in its own cache, POCL_CACHE_DIR, default\n"
    "~/.cache/pocl/kcache), VBCL_KERNEL_PROGRAMS (classes, the default; scene: a program\n"
    "of each scene's exact features, for comparison), VBCL_IMAGE_HELPER (0: load\n"
    "OpenImageIO in vbcl itself rather than in a helper process that encodes the PNG,\n"
    "JPEG, TIFF or EXR), VBCL_IMAGE_HELPER_TIMEOUT (seconds the helper may take for a step,\n"
    "default 120; then vbcl ends it and encodes the image itself); to clear the compiled\n"
    "kernels remove both cache folders\n"
    "mpirun -np N vbcl SCENE.json ...: the ranks share a still image's tiles, and an\n"
    "animation's frames (frame by frame in tiles with --stats-json); docs/scaling.md\n"
    "exit status: 0 success, 2 bad input or usage, 1 device or render failure\n"
    "scene format: docs/scene-format.md\n";

/* Command-line settings; a negative or NULL value means "not given". */
typedef struct Options {
    const char *scene, *output, *device, *grid, *fresnel, *aa_reconstruct, *aa_pairs, *aa_map,
        *aa_samples_map, *stats_json;
    int frame_first, frame_last; /* --frames; -1: not given */
    const char *crop;            /* --crop as given, or NULL */
    double crop_v[4];            /* its four numbers */
    int crop_fraction;           /* 1: fractions of the image, 0: pixels */
    int crop_margin;             /* --crop-margin; -1: not given */
    int width, height, shadow_samples, depth, aa_max_level, aa_min_level, ssaa, bands, seed;
    double grid_density, subgrid_density, exposure, min_weight, aa, aa_floor, aa_level_gain;
    int have_exposure;
    int list_devices, warm_cache, stats, quiet, no_cone_test, no_camera_tiles, all_feelers,
        penumbra_feelers;
    int no_sample_shares;
} Options;

static int usage_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

static int usage_error(const char *fmt, ...)
{
    char msg[2048];
    va_list ap;
    va_start(ap, fmt);
    diag_vformat(msg, sizeof msg, fmt, ap);
    va_end(ap);
    diag_print(prog, "%s (see vbcl --help)", msg);
    return 2;
}

static int parse_int(const char *opt, const char *s, int lo, int hi, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (end == s || *end || errno || v < lo || v > hi) {
        diag_print(prog, "%s %s: expected a whole number from %d to %d", opt, diag_value(s), lo,
                   hi);
        return -1;
    }
    *out = (int)v;
    return 0;
}

static int parse_double(const char *opt, const char *s, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || *end || errno || !isfinite(v) || v < lo || v > hi) {
        diag_print(prog, "%s %s: expected a number from %s to %s", opt, diag_value(s), diag_num(lo),
                   diag_num(hi));
        return -1;
    }
    *out = v;
    return 0;
}

/* The options that only store their value (or set a flag), with their ranges. */
enum { OPT_STRING, OPT_INT, OPT_DOUBLE, OPT_FLAG };
typedef struct OptionSpec {
    const char *name, *alias;
    int kind;
    size_t field; /* offset in Options */
    double lo, hi;
} OptionSpec;

static const OptionSpec option_specs[] = {
    {"--output", "-o", OPT_STRING, offsetof(Options, output), 0, 0},
    {"--width", NULL, OPT_INT, offsetof(Options, width), 1, SCENE_MAX_IMAGE},
    {"--height", NULL, OPT_INT, offsetof(Options, height), 1, SCENE_MAX_IMAGE},
    {"--grid", NULL, OPT_STRING, offsetof(Options, grid), 0, 0},
    {"--grid-density", NULL, OPT_DOUBLE, offsetof(Options, grid_density), 0.01, 64},
    {"--subgrid-density", NULL, OPT_DOUBLE, offsetof(Options, subgrid_density), 0.01, 64},
    {"--shadow-samples", NULL, OPT_INT, offsetof(Options, shadow_samples), 1, 1024},
    {"--seed", NULL, OPT_INT, offsetof(Options, seed), 0, 2147483647.0},
    {"--depth", NULL, OPT_INT, offsetof(Options, depth), 1, 64},
    {"--min-weight", NULL, OPT_DOUBLE, offsetof(Options, min_weight), 0, 1},
    {"--aa", NULL, OPT_DOUBLE, offsetof(Options, aa), 0, 1},
    {"--aa-max-level", NULL, OPT_INT, offsetof(Options, aa_max_level), 1, VBCL_AA_MAX_LEVEL},
    {"--aa-min-level", NULL, OPT_INT, offsetof(Options, aa_min_level), 0, VBCL_AA_MAX_LEVEL},
    {"--aa-floor", NULL, OPT_DOUBLE, offsetof(Options, aa_floor), 0, 2},
    {"--aa-level-gain", NULL, OPT_DOUBLE, offsetof(Options, aa_level_gain), 1, 4},
    {"--ssaa", NULL, OPT_INT, offsetof(Options, ssaa), 1, 16},
    {"--crop-margin", NULL, OPT_INT, offsetof(Options, crop_margin), 0, SCENE_MAX_IMAGE},
    {"--aa-map", NULL, OPT_STRING, offsetof(Options, aa_map), 0, 0},
    {"--aa-samples-map", NULL, OPT_STRING, offsetof(Options, aa_samples_map), 0, 0},
    {"--device", NULL, OPT_STRING, offsetof(Options, device), 0, 0},
    {"--stats-json", NULL, OPT_STRING, offsetof(Options, stats_json), 0, 0},
    {"--list-devices", NULL, OPT_FLAG, offsetof(Options, list_devices), 0, 0},
    {"--warm-cache", NULL, OPT_FLAG, offsetof(Options, warm_cache), 0, 0},
    {"--no-cone-test", NULL, OPT_FLAG, offsetof(Options, no_cone_test), 0, 0},
    {"--no-camera-tiles", NULL, OPT_FLAG, offsetof(Options, no_camera_tiles), 0, 0},
    {"--all-feelers", NULL, OPT_FLAG, offsetof(Options, all_feelers), 0, 0},
    {"--no-sample-shares", NULL, OPT_FLAG, offsetof(Options, no_sample_shares), 0, 0},
    {"--penumbra-feelers", NULL, OPT_INT, offsetof(Options, penumbra_feelers), 1,
     SCENE_PENUMBRA_FEELERS_MAX},
    {"--stats", NULL, OPT_FLAG, offsetof(Options, stats), 0, 0},
    {"--quiet", "-q", OPT_FLAG, offsetof(Options, quiet), 0, 0},
};

static const OptionSpec *option_find(const char *a)
{
    for (size_t k = 0; k < sizeof option_specs / sizeof option_specs[0]; k++)
        if (!strcmp(a, option_specs[k].name) ||
            (option_specs[k].alias && !strcmp(a, option_specs[k].alias)))
            return &option_specs[k];
    return NULL;
}

/* Stores option a's value val (NULL: none left) as spec says. Returns -1 (go on) or an
 * exit status after a usage error. */
static int option_store(Options *o, const OptionSpec *spec, const char *a, const char *val)
{
    char *field = (char *)o + spec->field;
    switch (spec->kind) {
    case OPT_FLAG:
        *(int *)field = 1;
        return -1;
    case OPT_STRING:
        *(const char **)field = val;
        return -1;
    case OPT_INT:
        return parse_int(a, val, (int)spec->lo, (int)spec->hi, (int *)field) ? 2 : -1;
    default:
        return parse_double(a, val, spec->lo, spec->hi, (double *)field) ? 2 : -1;
    }
}

/* --frames A:B or N. Returns -1 or 2. */
static int option_frames(Options *o, const char *val)
{
    char *end;
    errno = 0;
    long f0 = strtol(val, &end, 10), f1 = f0;
    if (end != val && *end == ':') {
        const char *b = end + 1;
        f1 = strtol(b, &end, 10);
        if (end == b) f1 = -1;
    }
    if (end == val || *end || errno || f0 < 0 || f1 < f0 || f1 > 100000)
        return usage_error("--frames %s: expected A:B or N, 0 <= A <= B", diag_value(val));
    o->frame_first = (int)f0;
    o->frame_last = (int)f1;
    return -1;
}

/* What --crop takes, for its messages. */
#define CROP_EXPECTED                                                                              \
    "expected X0,Y0,X1,Y1: four whole numbers of pixels (X0,Y0 the region's top-left pixel, "      \
    "X1,Y1 one past its right column and bottom row) or four fractions of the image from 0 to 1 "  \
    "with a decimal point (0.25,0.25,0.75,0.5)"

/* --crop X0,Y0,X1,Y1: four whole numbers (pixels) or four numbers with a decimal point
 * (fractions of the image), a non-empty region with X0 < X1 and Y0 < Y1; checked against
 * the image by crop_apply. Returns -1 or 2. */
static int option_crop(Options *o, const char *val)
{
    const char *p = val;
    int points = 0;
    for (int k = 0; k < 4; k++) {
        char *end;
        const char *dot = p + strcspn(p, ",");
        int fraction = memchr(p, '.', (size_t)(dot - p)) != NULL;
        errno = 0;
        double v = fraction ? (double)strtof(p, &end) : (double)strtol(p, &end, 10);
        if (end == p || end != dot || (k < 3) != (*end == ',') || errno || !isfinite(v) ||
            (k > 0 && fraction != points))
            return usage_error("--crop %s: " CROP_EXPECTED, diag_value(val));
        if (v < 0.0 || (fraction && v > 1.0))
            return usage_error("--crop %s: %s%d = %s lies outside the image (%s)", diag_value(val),
                               k % 2 ? "Y" : "X", k / 2, diag_num(v),
                               fraction ? "a fraction of it is from 0 to 1"
                                        : "pixels count from 0 at its top-left corner");
        points = fraction;
        o->crop_v[k] = v;
        p = end + (k < 3);
    }
    for (int k = 0; k < 2; k++)
        if (!(o->crop_v[k] < o->crop_v[k + 2]))
            return usage_error("--crop %s: an empty region: %s1 = %s must be greater than %s0 = %s",
                               diag_value(val), k ? "Y" : "X", diag_num(o->crop_v[k + 2]),
                               k ? "Y" : "X", diag_num(o->crop_v[k]));
    o->crop = val;
    o->crop_fraction = points;
    return -1;
}

/* The options with a value that need more than a range: --frames, --fresnel, --exposure,
 * --bands, --aa-reconstruct, --aa-pairs, --crop. Returns -1 (stored), 2 (usage error) or -2 (a
 * is none of them). */
static int option_special(Options *o, const char *a, const char *val)
{
    if (!strcmp(a, "--frames")) return option_frames(o, val);
    if (!strcmp(a, "--crop")) return option_crop(o, val);
    if (!strcmp(a, "--fresnel")) {
        if (strcmp(val, "exact") && strcmp(val, "thesis"))
            return usage_error("--fresnel %s: expected exact or thesis", diag_value(val));
        o->fresnel = val;
        return -1;
    }
    if (!strcmp(a, "--aa-reconstruct")) {
        if (strcmp(val, "nearest") && strcmp(val, "leaves"))
            return usage_error("--aa-reconstruct %s: expected nearest or leaves", diag_value(val));
        o->aa_reconstruct = val;
        return -1;
    }
    if (!strcmp(a, "--aa-pairs")) {
        if (strcmp(val, "first") && strcmp(val, "both"))
            return usage_error("--aa-pairs %s: expected first or both", diag_value(val));
        o->aa_pairs = val;
        return -1;
    }
    if (!strcmp(a, "--exposure")) {
        o->have_exposure = 1;
        return parse_double(a, val, -30, 30, &o->exposure) ? 2 : -1;
    }
    if (!strcmp(a, "--bands")) {
        if (!strcmp(val, "thesis")) {
            o->bands = 0; /* the thesis layout */
            return -1;
        }
        return parse_int(a, val, 1, DISP_MAX_BANDS, &o->bands) ? 2 : -1;
    }
    return -2;
}

/* The options option_special reads. */
static const char *const special_options[] = {
    "--frames", "--fresnel", "--exposure", "--bands", "--aa-reconstruct", "--aa-pairs", "--crop"};

static int is_special_option(const char *a)
{
    for (size_t k = 0; k < sizeof special_options / sizeof special_options[0]; k++)
        if (!strcmp(a, special_options[k])) return 1;
    return 0;
}

/* "unknown option A", with the nearest option's name when one is near (diag_suggest). */
static int unknown_option(const char *a)
{
    enum { NSPEC = sizeof option_specs / sizeof option_specs[0] };
    enum { NSPECIAL = sizeof special_options / sizeof special_options[0] };
    const char *names[NSPEC + NSPECIAL + 3];
    size_t n = 0;
    for (size_t k = 0; k < NSPEC; k++) names[n++] = option_specs[k].name;
    for (size_t k = 0; k < NSPECIAL; k++) names[n++] = special_options[k];
    names[n++] = "--help";
    names[n++] = "--version";
    names[n] = NULL;
    const char *near = diag_suggest(a, names);
    if (near) return usage_error("unknown option %s: did you mean %s?", diag_value(a), near);
    return usage_error("unknown option %s", diag_value(a));
}

/* Reads the command line into o. Returns -1 to go on and render, or an exit status (0
 * after --help or --version, 2 after a usage error). */
static int parse_args(int argc, char **argv, Options *o)
{
    memset(o, 0, sizeof *o);
    o->width = o->height = o->shadow_samples = o->depth = -1;
    o->grid_density = o->subgrid_density = o->min_weight = o->aa = o->aa_floor = -1;
    o->aa_level_gain = -1;
    o->aa_max_level = o->aa_min_level = o->ssaa = o->bands = o->seed = -1;
    o->frame_first = o->frame_last = o->crop_margin = -1;
    static char named[64]; /* the option of an --option=value, without its value */
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *val = (i + 1 < argc) ? argv[i + 1] : NULL;
        const char *eq = !strncmp(a, "--", 2) ? strchr(a, '=') : NULL;
        if (eq && (size_t)(eq - a) < sizeof named) { /* --option=value */
            snprintf(named, sizeof named, "%.*s", (int)(eq - a), a);
            const OptionSpec *fs = option_find(named);
            if (fs && fs->kind == OPT_FLAG)
                return usage_error("%s takes no value (got %s)", named, diag_value(a));
            if (fs || is_special_option(named)) {
                int rc = fs ? option_store(o, fs, named, eq + 1) : option_special(o, named, eq + 1);
                if (rc >= 0) return rc;
                continue;
            }
            return unknown_option(named);
        }
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage_text, stdout);
            return 0;
        }
        if (!strcmp(a, "--version")) {
            printf("vbcl %s\n", VBCL_VERSION);
            return 0;
        }
        const OptionSpec *spec = option_find(a);
        if (spec || is_special_option(a)) {
            if (!(spec && spec->kind == OPT_FLAG)) {
                if (!val) return usage_error("%s needs a value", diag_value(a));
                i++;
            }
            int rc = spec ? option_store(o, spec, a, val) : option_special(o, a, val);
            if (rc >= 0) return rc;
        } else if (a[0] == '-' && a[1]) {
            return unknown_option(a);
        } else if (o->scene) {
            return usage_error("one scene at a time (also got %s)", diag_value(a));
        } else {
            o->scene = a;
        }
    }
    if (o->warm_cache && o->scene)
        return usage_error("--warm-cache takes no scene (got %s)", diag_value(o->scene));
    if (!o->scene && !o->list_devices && !o->warm_cache)
        return usage_error("%s", "no scene file given");
    if (o->penumbra_feelers && !scene_penumbra_feelers_ok(o->penumbra_feelers))
        return usage_error("--penumbra-feelers %d: expected " SCENE_PENUMBRA_FEELERS_SET,
                           o->penumbra_feelers);
    return -1;
}

/* The path of frame `frame` (-1: not an animation): a run of '#' in path becomes the frame
 * number, zero-padded to the run's length; without one, _NNNN goes before the extension. */
static char *frame_path(const char *path, int frame)
{
    if (frame < 0) return strdup(path);
    size_t n = strlen(path);
    char *out = malloc(n + 16);
    if (!out) return NULL;
    const char *hash = strchr(path, '#');
    const char *slash = strrchr(path, '/');
    if (hash && (!slash || hash > slash)) {
        size_t run = strspn(hash, "#");
        snprintf(out, n + 16, "%.*s%0*d%s", (int)(hash - path), path, (int)run, frame, hash + run);
    } else {
        const char *dot = strrchr(path, '.');
        if (!dot || (slash && dot < slash)) dot = path + n;
        snprintf(out, n + 16, "%.*s_%04d%s", (int)(dot - path), path, frame, dot);
    }
    return out;
}

/* The output path: -o, else image.output, else the scene's base name with .png; numbered
 * for the frames of an animation. */
static char *output_path(const Options *o, const Scene *s, int frame)
{
    if (o->output) return frame_path(o->output, frame);
    if (s->output) return frame_path(s->output, frame);
    const char *scene = strcmp(o->scene, "-") == 0 ? "stdin" : o->scene;
    const char *base = strrchr(scene, '/');
    base = base ? base + 1 : scene;
    size_t n = strlen(base);
    const char *dot = strrchr(base, '.');
    if (dot) n = (size_t)(dot - base);
    char *out = malloc(n + 5);
    if (out) {
        memcpy(out, base, n);
        memcpy(out + n, ".png", 5);
    }
    if (out && frame >= 0) {
        char *numbered = frame_path(out, frame);
        free(out);
        out = numbered;
    }
    return out;
}

/* Whether the images this run writes need OpenImageIO: not when each of them is a .pfm,
 * which vbcl writes itself (a scene's own image textures load it when they are read). s
 * is the still scene, or NULL for an animation, whose -o names its frames. */
static int needs_image_library(const Options *o, const Scene *s)
{
    const char *out = o->output ? o->output : s ? s->output : NULL;
    return !out || !image_is_native_format(out) ||
           (o->aa_map && !image_is_native_format(o->aa_map)) ||
           (o->aa_samples_map && !image_is_native_format(o->aa_samples_map));
}

/* The number of pixels in the rectangle r (x0, y0, x1, y1: frame_region, frame_window). */
static size_t rect_pixels(const int r[4])
{
    return (size_t)(r[2] - r[0]) * (size_t)(r[3] - r[1]);
}

/* Writes each pixel's refinement level or, with samples set, its number of samples of the
 * region reg as a heat map with its legend to the right (aa_map_image: the map stays the
 * image's top-left pixels, the region's size). */
static int write_aa_map(const char *path, const Scene *s, const int reg[4], const int *values,
                        int samples, char *err, size_t errlen)
{
    AaMapLegend lg;
    float *map =
        aa_map_image(values, reg[2] - reg[0], reg[3] - reg[1], samples, s->aa_max_level, &lg);
    if (!map) {
        snprintf(err, errlen, "out of memory for the anti-aliasing map");
        return -1;
    }
    int rc = image_write(path, lg.width, lg.height, map, 0.0f, err, errlen);
    free(map);
    return rc;
}

/* --crop on s's image, into s->crop: pixels as given, or fractions rounded as pbrt-v4 rounds
 * its crop window, each bound up to a whole pixel in single precision (x0 = ceilf(width *
 * X0), ...); and --crop-margin. Returns 0, or 2 after a usage error. */
static int crop_apply(const Options *o, Scene *s)
{
    if (o->crop_margin >= 0 && (!o->crop || aa_reach(s) == 0))
        return usage_error("--crop-margin %d: needs --crop and adaptive anti-aliasing (--aa or "
                           "render.aa), whose contrast test reads the pixels around the region",
                           o->crop_margin);
    if (!o->crop) return 0;
    int size[2] = {s->width, s->height};
    for (int k = 0; k < 4; k++) {
        double v = o->crop_fraction ? (double)ceilf((float)size[k % 2] * (float)o->crop_v[k])
                                    : o->crop_v[k];
        if (v > size[k % 2])
            return usage_error("--crop %s: %s%d = %s lies outside the %dx%d image (%s at most %d)",
                               diag_value(o->crop), k % 2 ? "Y" : "X", k / 2, diag_num(v), s->width,
                               s->height, k % 2 ? "Y" : "X", size[k % 2]);
        s->crop[k] = (int)v;
    }
    if (s->crop[0] >= s->crop[2] || s->crop[1] >= s->crop[3])
        return usage_error("--crop %s: rounds to no pixel of the %dx%d image (x %d to %d, y %d to "
                           "%d: width x fraction and height x fraction rounded up, as pbrt's crop "
                           "window)",
                           diag_value(o->crop), s->width, s->height, s->crop[0], s->crop[2],
                           s->crop[1], s->crop[3]);
    s->crop_margin = o->crop_margin;
    return 0;
}

/* The command line's settings over the scene's own. Returns 0, or 2 after a usage error. */
static int apply_options(const Options *o, Scene *s)
{
    if (o->width > 0) s->width = o->width;
    if (o->height > 0) s->height = o->height;
    if (o->shadow_samples > 0) s->shadow_samples = o->shadow_samples;
    if (o->seed >= 0) s->seed = (unsigned)o->seed;
    if (o->grid_density > 0) s->grid_density = (float)o->grid_density;
    if (o->subgrid_density > 0) s->subgrid_density = (float)o->subgrid_density;
    if (o->have_exposure) s->exposure = (float)o->exposure;
    if (o->depth > 0) s->max_depth = o->depth;
    if (o->min_weight >= 0) s->min_weight = (float)o->min_weight;
    if (o->aa >= 0) s->aa_threshold = (float)o->aa;
    if (o->aa_floor >= 0) s->aa_floor = (float)o->aa_floor;
    if (o->aa_level_gain > 0) s->aa_level_gain = (float)o->aa_level_gain;
    if (o->aa_reconstruct)
        s->aa_reconstruct =
            strcmp(o->aa_reconstruct, "leaves") == 0 ? SCENE_AA_LEAVES : SCENE_AA_NEAREST;
    if (o->aa_pairs)
        s->aa_pairs = strcmp(o->aa_pairs, "both") == 0 ? SCENE_AA_PAIRS_BOTH : SCENE_AA_PAIRS_FIRST;
    if (o->no_cone_test) s->shadow_cone_test = 0;
    if (o->no_camera_tiles) s->camera_tiles = 0;
    if (o->all_feelers) s->shadow_by_weight = 0;
    if (o->no_sample_shares) s->sample_shares = 0;
    if (o->penumbra_feelers > 0) s->penumbra_feelers = o->penumbra_feelers;
    if (o->aa_max_level > 0) s->aa_max_level = o->aa_max_level;
    if (o->aa_min_level >= 0) s->aa_min_level = o->aa_min_level;
    if (o->bands >= 0) {
        s->band_layout = o->bands ? DISP_LAYOUT_UNIFORM : DISP_LAYOUT_THESIS;
        s->bands = o->bands ? o->bands : DISP_THESIS_BANDS;
    }
    if (o->ssaa > 0) s->ssaa = o->ssaa;
    if (s->ssaa > 1 && s->aa_threshold > 0.0f) {
        if (o->aa > 0) return usage_error("%s", "--aa and --ssaa exclude each other");
        s->aa_threshold = 0.0f; /* --ssaa overrides the scene's render.aa */
    }
    if (s->aa_min_level > s->aa_max_level)
        return usage_error("the minimum refinement level (%d, --aa-min-level or "
                           "render.aa_min_level) exceeds the deepest (%d, --aa-max-level or "
                           "render.aa_max_level)",
                           s->aa_min_level, s->aa_max_level);
    if (o->aa_min_level > 0 && !(s->aa_threshold > 0.0f))
        return usage_error("%s", "--aa-min-level needs adaptive anti-aliasing (--aa or render.aa)");
    if ((o->aa_map || o->aa_samples_map) && !(s->aa_threshold > 0.0f))
        return usage_error("%s needs adaptive anti-aliasing (--aa or render.aa)",
                           o->aa_map ? "--aa-map" : "--aa-samples-map");
    if (o->fresnel)
        s->fresnel = strcmp(o->fresnel, "thesis") == 0 ? SCENE_FRESNEL_THESIS : SCENE_FRESNEL_EXACT;
    if (o->grid && scene_parse_grid_levels(o->grid, s->grid_res, s->subgrid_res))
        return usage_error("--grid %s: expected TOP or TOP:SUB, each auto, N or NX,NY,NZ (TOP "
                           "1..1024 each, at most 2^27 = 134217728 cells in all; SUB 1..64 each)",
                           diag_value(o->grid));
    return crop_apply(o, s);
}

/* Reports a frame written to out: --stats on stderr; with --stats-json its object added to
 * *json and the document written (again after each frame of an animation, so the file
 * always holds the frames done); the summary line on stdout unless -q. Returns an exit
 * status. */
/* How many devices did the work: entries of ranks on one machine that name the same device
 * index count once (two ranks may drive one device). */
static int distinct_devices(const DeviceWork *w, int n)
{
    int count = 0;
    for (int i = 0; i < n; i++) {
        int seen = 0;
        for (int j = 0; j < i && !seen; j++)
            seen = w[j].index == w[i].index && !strcmp(w[j].host, w[i].host);
        count += !seen;
    }
    return count;
}

static int report_frame(const Options *o, const StatsFrame *fr, const char *out, cJSON **json)
{
    const Scene *s = fr->scene;
    if (o->stats) stats_print(stderr, fr);
    if (o->stats_json) {
        char err[1024];
        if (stats_json_add_frame(json, fr)) {
            fprintf(stderr, "vbcl: out of memory for the statistics\n");
            return 1;
        }
        if (stats_json_write(o->stats_json, *json, err, sizeof err)) {
            fprintf(stderr, "vbcl: %s\n", err);
            return 1;
        }
    }
    if (!o->quiet && fr->st->tree_cut)
        fprintf(stderr,
                "vbcl: warning: %llu ray-tree branches were not traced: their samples' trees "
                "reached %d rays (render.max_depth %d, render.min_weight %g); raise min_weight or "
                "lower max_depth for an image without the cut (docs/stats.md, ray_tree.tree_cut)\n",
                fr->st->tree_cut, VBCL_TREE_MAX_RAYS, s->max_depth, (double)s->min_weight);
    if (!o->quiet) {
        unsigned long long rays = stats_rays_total(fr->st);
        double render_ms = fr->st->render_ms;
        char on[300];
        int ndevices = distinct_devices(fr->work, fr->nwork);
        if (ndevices > 1)
            snprintf(on, sizeof on, "%d devices (--stats: each one's share)", ndevices);
        else
            snprintf(on, sizeof on, "%s", fr->dev->name);
        if (fr->nwork > ndevices) /* ranks that share a device */
            snprintf(on + strlen(on), sizeof on - strlen(on), ", %d queues", fr->nwork);
        if (mpi_rank >= 0) snprintf(on + strlen(on), sizeof on - strlen(on), ", rank %d", mpi_rank);
        int reg[4];
        frame_region(s, reg);
        printf("vbcl: wrote %s (%dx%d) in %.2f s: %u triangles, %llu rays (%.2f Mrays/s) on %s\n",
               out, reg[2] - reg[0], reg[3] - reg[1], fr->total_ms / 1000.0, s->mesh.ntris, rays,
               render_ms > 0 ? (double)rays / (render_ms * 1e3) : 0.0, on);
        fflush(stdout);
    }
    return 0;
}

/* Loads frame `frame` of the scene (-1: a scene that is not animated; text: the scene
 * file, read once) with the command line applied. Returns 0 or an exit status after a
 * message; on 0 the caller frees *s. */
static int load_frame(const Options *o, const char *text, int frame, Scene *s)
{
    char err[1024] = "";
    if (scene_load_text(o->scene, text, frame, s, err, sizeof err)) {
        diag_print(prog, "%s", err);
        return 2;
    }
    static int warned; /* once, not once per frame of an animation */
    if (s->warning[0] && !o->quiet && !warned && mpi_rank <= 0) {
        diag_print(prog, "warning: %s", s->warning);
        warned = 1;
    }
    int rc = apply_options(o, s);
    if (rc) scene_free(s);
    return rc;
}

/* The frame's image on this process's devices into rgba, with the other MPI ranks' help
 * when d shares tiles (d->size > 1; this is rank 0: it serves pass 0's tiles and gathers
 * the ranks' pixels and work). Leaves every device's work in work[0..*nwork) (room for
 * max). Returns 0, or an exit status after a message. */
static int render_image(const Options *o, const Scene *s, VbDevice *devs, int ndev, Dist *d,
                        Frame *fr, float *rgba, RenderStats *st, DeviceWork *work, int *nwork,
                        int max, double *image_wait_ms)
{
    char err[1024] = "";
    int win[4];
    frame_window(s, win);
    long npix = (long)rect_pixels(win);
    int shared = d && d->size > 1;
    TileSource src;
    /* the image library first: without the helper process it loads on a thread of vbcl,
     * and the kernels' first launches (frame_init) would wait for its dynamic loads */
    double tl = clu_now_ms();
    image_preload_wait();
    *image_wait_ms = clu_now_ms() - tl;
    int rc = frame_init(fr, devs, ndev, s, st, err, sizeof err);
    if (shared) {
        int tile = rc ? TILES_MIN_PIXELS : tiles_size(fr->r.tile_pixels, npix, d->size * ndev);
        if (dist_tiles_begin(d, rgba, npix, tile, &src, err, sizeof err)) {
            diag_print(prog, "%s", err);
            dist_abort(d, 1);
        }
        fr->tiles = &src;
        st->tile_pixels = tile;
        if (s->ssaa > 1) dist_tiles_end(d); /* supersampling runs on rank 0 alone */
    }
    if (!rc) {
        int progress = !o->quiet && isatty(STDERR_FILENO);
        rc = frame_render(fr, s, rgba, st, progress, err, sizeof err) ? 1 : 0;
    }
    if (shared) dist_tiles_end(d);
    fr->tiles = NULL; /* src ends here */
    if (rc) {
        diag_print(prog, "%s", err);
        return rc;
    }
    for (int i = 0; i < ndev; i++) work[i] = fr->work[i];
    *nwork = shared ? dist_tiles_gather(d, st, work, ndev, max) : ndev;
    return 0;
}

/* Renders frame `frame` of the loaded scene *scene (its command line applied; freed here)
 * on devs through fr (which keeps the last frame's geometry for the next: frame_init),
 * with the other ranks' help when d shares tiles (render_image; else NULL), writes it and
 * reports it (report_frame; *json: the --stats-json document); t0 is when this frame's
 * work began. Returns an exit status. */
static int render_frame(const Options *o, Scene *scene, int frame, VbDevice *devs, int ndev,
                        Dist *d, Frame *fr, double t0, cJSON **json)
{
    char err[1024] = "";
    Scene s = *scene;
    int rc = 0, nwork = 0, max = ndev + (d ? d->size - 1 : 0) * CLU_MAX_DEVICES;
    char *out = output_path(o, &s, frame);
    char *map = !o->aa_map ? NULL : frame_path(o->aa_map, frame);
    char *smap = !o->aa_samples_map ? NULL : frame_path(o->aa_samples_map, frame);
    int win[4], reg[4]; /* the pixels rendered, and those written */
    frame_window(&s, win);
    frame_region(&s, reg);
    float *rgba = malloc(sizeof(float) * 4 * rect_pixels(win));
    DeviceWork *work = calloc((size_t)max, sizeof *work);
    RenderStats st;
    memset(&st, 0, sizeof st);
    if (!out || (o->aa_map && !map) || (o->aa_samples_map && !smap) || !rgba || !work) {
        fprintf(stderr, "%s: out of memory for a %dx%d image\n", prog, win[2] - win[0],
                win[3] - win[1]);
        rc = 1;
        dist_abort(d, 1); /* with other ranks: they wait for tiles */
        goto done;
    }
    double image_wait_ms = 0.0;
    rc = render_image(o, &s, devs, ndev, d, fr, rgba, &st, work, &nwork, max, &image_wait_ms);
    if (rc) goto done;
    double tw = clu_now_ms();
    if (image_write(out, reg[2] - reg[0], reg[3] - reg[1], rgba, s.exposure, err, sizeof err) ||
        (map && frame_levels(fr) &&
         write_aa_map(map, &s, reg, frame_levels(fr), 0, err, sizeof err)) ||
        (smap && frame_leaves(fr) &&
         write_aa_map(smap, &s, reg, frame_leaves(fr), 1, err, sizeof err))) {
        diag_print(prog, "%s", err);
        rc = 1;
        goto done;
    }
    StatsFrame sf = {
        &s,   &devs[0], &fr->r, &st, frame, image_wait_ms, clu_now_ms() - tw, clu_now_ms() - t0,
        work, nwork};
    rc = report_frame(o, &sf, out, json);
done:
    free(rgba);
    free(work);
    free(out);
    free(map);
    free(smap);
    scene_free(&s);
    return rc;
}

/* Another rank's part of a frame shared by tiles (d->size > 1, rank > 0): pass 0's tiles
 * from rank 0, traced on this rank's devices, the pixels and the work sent back. *scene is
 * freed here. Returns 0, or 1 (rank 0 reports the failure). */
static int render_tiles_for_rank0(Dist *d, Scene *scene, VbDevice *devs, int ndev)
{
    char err[1024] = "";
    Scene s = *scene;
    int win[4]; /* the pixels rendered: rank 0's tiles count them */
    frame_window(&s, win);
    float *rgba = malloc(sizeof(float) * 4 * rect_pixels(win));
    Frame fr;
    memset(&fr, 0, sizeof fr);
    RenderStats st;
    memset(&st, 0, sizeof st);
    TileSource src;
    dist_tiles_begin(d, rgba, (long)rect_pixels(win), 0, &src, err, sizeof err);
    int rc = 1;
    if (!rgba)
        snprintf(err, sizeof err, "cannot allocate a %dx%d image", win[2] - win[0],
                 win[3] - win[1]);
    else
        rc = frame_init(&fr, devs, ndev, &s, &st, err, sizeof err);
    if (!rc) {
        fr.tiles = &src;
        rc = frame_pixel_centres(&fr, rgba, &st, 0, err, sizeof err);
    }
    if (dist_tiles_report(d, rc, err, &st, fr.work, frame_devices(&fr))) rc = 1;
    frame_release(&fr);
    free(rgba);
    scene_free(&s);
    return rc;
}

/* Checks that a file can be written at path before any work (its directory exists and is
 * writable). Returns 0, or 2 after a message naming the path. */
static int check_output_dir(const char *path)
{
    char err[1024];
    if (file_check_dir(path, err, sizeof err)) {
        diag_print(prog, "%s", err);
        return 2;
    }
    return 0;
}

/* Checks that path can be written before any work: a format vbcl writes, in a directory
 * that exists and is writable. Returns 0, or 2 after a message naming the path. */
static int check_output(const char *path)
{
    char err[1024];
    if (image_check_path(path, err, sizeof err)) {
        diag_print(prog, "%s", err);
        return 2;
    }
    return check_output_dir(path);
}

/* Every output of frames first..last (or of the still image, frame -1): the image, the
 * --aa-map and the --aa-samples-map, checked before anything renders. */
static int check_outputs(const Options *o, const Scene *s, int first, int last)
{
    for (int f = first; f <= last; f++) {
        char *out = output_path(o, s, f), *map = o->aa_map ? frame_path(o->aa_map, f) : NULL;
        char *smap = o->aa_samples_map ? frame_path(o->aa_samples_map, f) : NULL;
        int rc =
            (!out || (o->aa_map && !map) || (o->aa_samples_map && !smap)) ? 1 : check_output(out);
        if (!rc && map) rc = check_output(map);
        if (!rc && smap) rc = check_output(smap);
        free(out);
        free(map);
        free(smap);
        if (rc) return rc;
        if (f < 0) break;
    }
    return 0;
}

/* Loads every frame to be rendered with the command line applied, so that a value out
 * of range in frame 7 stops the run before frame 0 is written. */
static int check_frames(const Options *o, const char *text, int first, int last)
{
    for (int f = first; f <= last; f++) {
        Scene s;
        int rc = load_frame(o, text, f, &s);
        if (rc) return rc;
        scene_free(&s);
    }
    return 0;
}

/* The scene as written, then --frames against its frame count, every frame to render and
 * every output path. Sets the frames to render (first = last = -1: a still image). Returns
 * 0 or an exit status; on 0 with a still image, *still holds the checked scene, loaded
 * once for checking and rendering (the caller frees it). */
static int check_scene(const Options *o, const char *text, int *first, int *last, Scene *still)
{
    Scene s;
    int rc = load_frame(o, text, -1, &s);
    if (rc) return rc;
    int frames = s.frames, animated = s.animated;
    *first = animated ? 0 : -1;
    *last = animated ? frames - 1 : -1;
    if (!rc && o->frame_first >= 0) {
        if (!animated) {
            rc = usage_error("--frames: %s is not animated", diag_value(o->scene));
        } else {
            *first = o->frame_first;
            *last = o->frame_last < 0 ? frames - 1 : o->frame_last;
            if (*last >= frames)
                rc = usage_error("--frames %d:%d: %s has frames 0 to %d", *first, *last,
                                 diag_value(o->scene), frames - 1);
        }
    }
    if (!rc) rc = check_outputs(o, &s, *first, *last);
    if (!rc && o->stats_json) rc = check_output_dir(o->stats_json);
    if (!rc && !animated) {
        *still = s;
        return 0;
    }
    scene_free(&s);
    if (!rc) rc = check_frames(o, text, *first, *last);
    return rc;
}

/* Renders frames first..last (first = last = -1: the still image *still, freed here),
 * each one shared by tiles among the MPI ranks (with one rank: on this process's devices),
 * or, for an animation over several ranks without --stats-json, whole frames handed out
 * one at a time (each rank writes its own). Returns an exit status. */
static int render_all(const Options *o, Dist *d, const char *text, int first, int last,
                      Scene *still, VbDevice *devs, int ndev, double t0)
{
    cJSON *json = NULL; /* the --stats-json document */
    int rc = 0, f;
    Frame fr; /* kept from frame to frame: an animation's unchanged geometry is not rebuilt */
    memset(&fr, 0, sizeof fr);
    if (first >= 0 && d->size > 1 && !o->stats_json) {
        while (!rc && dist_frames_next(d, first, last, &f)) {
            Scene s;
            rc = load_frame(o, text, f, &s);
            if (!rc) rc = render_frame(o, &s, f, devs, ndev, NULL, &fr, t0, &json);
            t0 = clu_now_ms();
        }
        if (rc) dist_frames_fail(d);
        dist_frames_end(d);
        frame_release(&fr);
        return rc;
    }
    for (f = first; !rc && f <= last; f++) {
        Scene s;
        if (f < 0)
            s = *still;
        else if ((rc = load_frame(o, text, f, &s)))
            break;
        if (d->rank == 0)
            rc = render_frame(o, &s, f, devs, ndev, d, &fr, t0, &json);
        else
            rc = render_tiles_for_rank0(d, &s, devs, ndev);
        rc = dist_agree(d, rc);
        t0 = clu_now_ms();
    }
    frame_release(&fr);
    cJSON_Delete(json);
    return rc;
}

/* vbcl --warm-cache: every program on the chosen devices, as many at once as there are
 * cores. Returns the exit status. */
static int warm_main(const Options *o)
{
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    return warm_cache(o->device, cores > 0 ? (int)cores : 1, o->quiet);
}

/* The command line on this rank: the scene read and checked by rank 0 (once: it may be a
 * pipe), every frame and output path checked before any device is opened, then shared
 * with the other ranks; each rank opens its devices; then render_all. */
static int run(Dist *d, int argc, char **argv, double t0)
{
    Options o;
    int rc = parse_args(argc, argv, &o);
    if (rc >= 0) return rc;
    if (o.list_devices) return clu_list_devices(stdout) > 0 ? 0 : 1;
    if (o.warm_cache) return warm_main(&o);
    renderer_build_notice(!o.quiet && isatty(STDERR_FILENO) && d->rank <= 0);
    char err[1024] = "", *text = NULL;
    int first = -1, last = -2;
    Scene still;
    if (d->rank == 0) {
        rc = scene_read_text(o.scene, &text, err, sizeof err) ? 2 : 0;
        if (rc) diag_print(prog, "%s", err);
        if (!rc) rc = check_scene(&o, text, &first, &last, &still);
    }
    if (dist_share_scene(d, &text, &rc, &first, &last)) dist_abort(d, 1);
    if (!rc && d->rank != 0 && first < 0) rc = load_frame(&o, text, -1, &still);
    int have_still = !rc && first < 0; /* still is ours to render or free */
    VbDevice devs[CLU_MAX_DEVICES];
    int ndev = 0;
    int writes = !rc && (d->rank == 0 || first >= 0) /* the ranks that write images */
                 && needs_image_library(&o, have_still ? &still : NULL);
    if (writes) image_preload(0); /* the helper process, at once: a loader of its own */
    if (!rc) {
        rc = clu_devices_open(o.device, devs, CLU_MAX_DEVICES, &ndev, err, sizeof err);
        if (rc)
            diag_print(prog, "%s", err);
        else if (writes)
            image_preload(1);   /* without a helper, OpenImageIO loads on a thread from here */
        rc = dist_agree(d, rc); /* every rank has its devices, or all stop */
    }
    if (!rc) {
        have_still = 0; /* render_all frees it */
        rc = render_all(&o, d, text, first, last, &still, devs, ndev, t0);
    }
    if (have_still) scene_free(&still);
    clu_devices_close(devs, ndev);
    free(text);
    return rc;
}

/* The stack vbcl runs with: a kernel's work-group function keeps every work item's private
 * arrays (a ray tree's stack) on the stack of PoCL's thread, which glibc sizes by the stack
 * limit (ulimit -s), so a limit of 256 KiB overflows it (SIGSEGV), and at 96 KiB the main
 * thread overflows too. */
#define STACK_WANT ((rlim_t)8 << 20)
#define STACK_MIN  ((rlim_t)128 << 10) /* the main thread's need, with a margin */

/* Below STACK_WANT: gives the threads created from here on STACK_WANT, and raises the stack
 * limit toward it (up to the hard limit) and runs vbcl again under it (the main thread's
 * stack is sized when a program starts). Returns 0, or 1 after a message where the hard
 * limit is below STACK_MIN. */
static int stack_limit(char **argv)
{
    struct rlimit rl;
    if (getrlimit(RLIMIT_STACK, &rl) || rl.rlim_cur == RLIM_INFINITY || rl.rlim_cur >= STACK_WANT)
        return 0;
    pthread_attr_t a;
    if (!pthread_attr_init(&a)) {
        if (!pthread_attr_setstacksize(&a, (size_t)STACK_WANT)) pthread_setattr_default_np(&a);
        pthread_attr_destroy(&a);
    }
    if (getenv("VBCL_STACK_RAISED")) return 0; /* raised as far as it goes already */
    rlim_t want =
        rl.rlim_max == RLIM_INFINITY || rl.rlim_max > STACK_WANT ? STACK_WANT : rl.rlim_max;
    if (want < STACK_MIN) {
        fprintf(stderr,
                "%s: the stack limit (ulimit -s) is %llu KiB and cannot be raised above %llu "
                "KiB; vbcl needs %llu KiB or more (ulimit -s %llu)\n",
                prog, (unsigned long long)rl.rlim_cur / 1024,
                (unsigned long long)rl.rlim_max / 1024, (unsigned long long)STACK_MIN / 1024,
                (unsigned long long)STACK_WANT / 1024);
        return 1;
    }
    if (want <= rl.rlim_cur) return 0; /* as far as it goes: the threads' stacks suffice */
    rl.rlim_cur = want;
    if (setrlimit(RLIMIT_STACK, &rl) || setenv("VBCL_STACK_RAISED", "1", 1)) return 0;
    execv("/proc/self/exe", argv);
    return 0; /* not run again: go on with the threads' stacks raised */
}

int main(int argc, char **argv)
{
    if (stack_limit(argv)) return 1;
    /* A file-size limit (ulimit -f) then fails the write with "File too large", which
     * fileio.c reports with the file's name, instead of killing the process mid-write. */
    signal(SIGXFSZ, SIG_IGN);
    if (argc > 1 && strcmp(argv[1], "texgen") == 0) return texgen_main(argc - 1, argv + 1);
    if (argc == 2 && strcmp(argv[1], "--image-helper") == 0) return image_helper_main();
    double t0 = clu_now_ms();
    Dist d;
    char err[1024] = "";
    if (dist_init(&d, &argc, &argv, err, sizeof err)) {
        diag_print(prog, "%s", err);
        return 1;
    }
    static char rank_prog[64];
    if (d.size > 1) mpi_rank = d.rank;
    if (d.size > 1 && d.rank > 0) {
        snprintf(rank_prog, sizeof rank_prog, "vbcl: rank %d", d.rank);
        prog = rank_prog;
    }
    return dist_finish(&d, run(&d, argc, argv, t0));
}
