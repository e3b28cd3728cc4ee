/* stats.c — the report of a render: the --stats text and the --stats-json document. Each
 * field is described once, as a row of one table (stats_fields: its JSON group and key, its
 * words in the text, where its value is read), and both writers walk that table; the
 * kernels' counters take their JSON group and key from VBCL_COUNTER_LIST (types.h). */
#include "stats.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "fileio.h"
#include "frame.h"
#include "kernel_features.h"

unsigned long long stats_rays_total(const RenderStats *st)
{
    return st->rays_primary + st->rays_refine + st->rays_shadow + st->reflected + st->transmitted;
}

double stats_kernel_ms(const RenderStats *st)
{
    return st->camera_ms + st->intersect_ms + st->shading_ms + st->tree_ms + st->dispersion_ms;
}

static double per(unsigned long long a, unsigned long long b)
{
    return b ? (double)a / (double)b : 0.0;
}

/* ---- the fields ---- */

/* When the text gives a line, or a part of one: every bit of a row's `when` must hold. The
 * JSON always has every field (zeros where a stage did not run). */
enum {
    W_ANIMATION = 1u << 0,    /* a frame of an animation */
    W_TRANSPARENCY = 1u << 1, /* dielectrics: the ray-tree lines */
    W_MEDIA = 1u << 2,        /* dielectrics or volume textures: the pass-through line */
    W_DISPERSION = 1u << 3,   /* dispersive dielectrics (VBCL_FEATURE_DISPERSION) */
    W_THESIS_BANDS = 1u << 4, /* bands in the thesis's layout */
    W_BY_WEIGHT = 1u << 5,    /* render.shadow_by_weight */
    W_PENUMBRA = 1u << 6,     /* points in a penumbra trace more feelers */
    W_UNIFORM = 1u << 7,      /* --ssaa */
    W_ADAPTIVE = 1u << 8,     /* --aa */
    W_CROP = 1u << 9,         /* --crop */
};

/* What a frame's fields are read from: its records, or StatsDerived. */
enum { SRC_STATS, SRC_SCENE, SRC_GRID, SRC_DEVICE, SRC_FRAME, SRC_DERIVED, SRC_WORK, SRC_COUNT };

/* A field's C type where it is read; from T_FRAME on, values that are not one number or name,
 * which each writer builds in its own code (json_special, print_special). */
enum {
    T_NONE, /* no value: the text's words alone */
    T_INT,
    T_UINT,
    T_ULL,
    T_DOUBLE,
    T_FLOAT, /* given in the JSON to float precision (fnum) */
    T_BOOL,
    T_STR,        /* a char pointer */
    T_CHARS,      /* a char array */
    T_FRAME,      /* the frame number; JSON null for a scene that is not animated */
    T_FEATURES,   /* the scene's features: JSON an array of names, the text a list */
    T_RESOLUTION, /* the grid's top cells per axis */
    T_BY_DEPTH,   /* rays by ray-tree depth */
    T_REFINED,    /* pixels refined per anti-aliasing level */
    T_REGION,     /* the pixels written (frame_region): x0, y0, x1, y1 */
    T_WINDOW,     /* the pixels rendered (frame_window): x0, y0, x1, y1 */
    T_COUNTERS,   /* the group's counters in VBCL_COUNTER_LIST: JSON only */
};

typedef struct StatsAt {
    unsigned char src, type; /* SRC_*, T_* */
    size_t off;              /* offsetof the field in its record */
} StatsAt;

/* One field of the report. The text gives the fields of a line one after the other, each
 * in its own words, so a line is the run of rows after a line marker. */
typedef struct StatsField {
    const char *group; /* the JSON object in the frame's (or device's) object, or NULL: that */
    const char *key;   /* the JSON key, or NULL: the text alone gives it */
    StatsAt at;        /* where the value is read */
    /* The field's words in the --stats text, NULL: the JSON alone gives it. A printf
     * format with at most one conversion of the value: %lld for an integer (which is passed
     * twice, so that a format may give it twice), %g or %.Nf for a real, %s for a name; a
     * format may also leave the value out. print_special reads the formats of T_FRAME on. */
    const char *text;
    unsigned when;   /* W_*: the text gives it (a line marker: the line) only then */
    StatsAt text_at; /* where the text reads it when it says it otherwise (a percentage,
                      * words for a flag or a name); type T_NONE: at `at` */
    bool line;       /* a line marker: a new text line starts */
} StatsField;

/* The numbers the report computes from the frame's records, and the names it gives them,
 * for the table to read as it reads the records' own fields (stats_derive). */
typedef struct StatsDerived {
    unsigned when; /* the W_* that hold for this frame */
    const char *program_name, *program_from, *program_how;
    bool program_cached;
    bool grid_auto;
    const char *grid_how, *subgrid_how; /* "given" or "auto" */
    double empty_percent;
    unsigned long long leaf_quads;
    unsigned feelers_per_light, penumbra_factor;
    unsigned long long rays_total;
    int tree_max_rays;
    const char *band_layout;
    double cells_per_ray, tris_per_ray;
    double samples_mean, samples_fraction;
    const char *aa_mode, *aa_reconstruct, *aa_pairs;
    int ssaa, aa_max_level, aa_min_level;
    float aa_threshold, aa_floor, aa_level_gain; /* 0 unless adaptive */
    double kernel_ms, mrays_per_s;
    bool cropped;             /* --crop */
    int region[4], window[4]; /* the pixels written and rendered, x0, y0, x1, y1 */
    int region_w, region_h;   /* the image written */
    int margin;               /* pixels rendered around the region, where the image has them */
    unsigned long long window_pixels;
} StatsDerived;

/* The T_* of a field, from its declaration: a char array and a char pointer decay alike,
 * so the type of the field's address tells them apart. */
#define STATS_TYPE(x)                                                                              \
    _Generic((x), int: T_INT, unsigned: T_UINT, unsigned long long: T_ULL, double: T_DOUBLE,       \
             float: T_FLOAT, bool: T_BOOL, const char *: T_STR,                                    \
             char *: _Generic(&(x), char **: T_STR, default: T_CHARS))

/* The table's words. clang-format would set each braced macro body on lines of its own. */
/* clang-format off */
#define STATS_AT(src, rec, f) {src, STATS_TYPE(((rec *)0)->f), offsetof(rec, f)}
#define RS(f)       STATS_AT(SRC_STATS, RenderStats, f)
#define SC(f)       STATS_AT(SRC_SCENE, Scene, f)
#define GR(f)       STATS_AT(SRC_GRID, Grid, f)
#define DV(f)       STATS_AT(SRC_DEVICE, VbDevice, f)
#define FR(f)       STATS_AT(SRC_FRAME, StatsFrame, f)
#define DR(f)       STATS_AT(SRC_DERIVED, StatsDerived, f)
#define WK(f)       STATS_AT(SRC_WORK, DeviceWork, f)
#define SPECIAL(t)  {SRC_COUNT, t, 0}
#define NO_VALUE    {SRC_COUNT, T_NONE, 0}
/* A row's first members: a field of both, of the JSON alone, of the text alone. */
#define FIELD(g, k, a, t) .group = (g), .key = (k), .at = a, .text = (t)
#define JSON(g, k, a)     .group = (g), .key = (k), .at = a
#define TEXT(a, t)        .at = a, .text = (t)
/* A line marker, and the place of a group's counters in the JSON. */
#define LINE(w)     {.line = true, .when = (w)}
#define COUNTERS(g) {.group = (g), .at = SPECIAL(T_COUNTERS)}
/* clang-format on */

/* Every field of a frame, in the order of the text. A JSON object's keys come in the order
 * of its rows, and the objects in the order of their first rows. A counter's text row
 * reads its RenderStats field and has no JSON key: the group's COUNTERS row gives them
 * all to the JSON. The text gives dispersion_ms twice (dispersion and time lines): its
 * second place is a text row. */
static const StatsField stats_fields[] = {
    LINE(W_ANIMATION),
    {FIELD(NULL, "frame", SPECIAL(T_FRAME), "frame       %lld")},
    {TEXT(SC(frames), " of %lld")},
    LINE(0),
    {FIELD("scene", "path", SC(path), "scene       %s")},
    {FIELD("scene", "objects", SC(nobjects), ": %lld objects")},
    {FIELD("scene", "triangles", SC(mesh.ntris), ", %lld triangles")},
    {FIELD("scene", "materials", SC(nmaterials), ", %lld materials")},
    {FIELD("scene", "lights", SC(nlights), ", %lld lights")},
    {JSON("scene", "width", SC(width))},
    {JSON("scene", "height", SC(height))},
    LINE(W_CROP),
    {JSON("crop", "cropped", DR(cropped))},
    {FIELD("crop", "region", SPECIAL(T_REGION), "crop        region %lld,%lld to %lld,%lld")},
    {FIELD("crop", "width", DR(region_w), " (%lldx")},
    {FIELD("crop", "height", DR(region_h), "%lld of")},
    {TEXT(SC(width), " %lldx")},
    {TEXT(SC(height), "%lld)")},
    {FIELD("crop", "margin", DR(margin), ", margin %lld")},
    {FIELD("crop", "window", SPECIAL(T_WINDOW), ": rendered %lld,%lld to %lld,%lld")},
    {FIELD("crop", "window_pixels", DR(window_pixels), " (%lld pixels)")},
    LINE(0),
    {FIELD("device", "name", DV(name), "device      %s")},
    {FIELD("device", "version", DV(version), " (%s)")},
    {JSON("device", "driver", DV(driver))},
    LINE(0),
    {FIELD(NULL, "features", SPECIAL(T_FEATURES), "features    %s")},
    LINE(0),
    {FIELD("program", "name", DR(program_name), "program     %s")},
    {FIELD("program", "build_ms", RS(build_ms), ", %.1f ms")},
    {JSON("program", "cached", DR(program_cached))},
    {FIELD("program", "from", DR(program_from), " (%s"), .text_at = DR(program_how)},
    {FIELD("program", "first_launch_ms", RS(first_launch_ms), "; first launches %.1f ms)")},
    {FIELD("program", "options", RS(options), ", options: %s")},
    LINE(0),
    {FIELD("grid", "resolution", SPECIAL(T_RESOLUTION), "grid        %lldx%lldx%lld")},
    {FIELD("grid", "cells", GR(ncells), " = %lld cells")},
    {FIELD("grid", "auto", DR(grid_auto), " (%s)"), .text_at = DR(grid_how)},
    {FIELD("grid", "build_ms", RS(grid_ms), ", build %.1f ms")},
    {JSON("compile", "scenes", RS(scene_compiles))},
    {JSON("compile", "geometry_built", RS(geometry_builds))},
    {JSON("grid", "triangle_refs", GR(nrefs))},
    {FIELD("grid", "tris_per_cell_mean", GR(tris_per_cell_mean), ", triangles per cell mean %.2f")},
    {FIELD("grid", "tris_per_cell_max", GR(tris_per_cell_max), " max %lld")},
    {FIELD("grid", "empty_fraction", GR(empty_fraction), ", empty %.1f%%"),
     .text_at = DR(empty_percent)},
    {FIELD("grid", "tris_per_nonempty_cell_mean", GR(tris_per_nonempty_mean),
           ", per non-empty cell %.2f")},
    {FIELD("grid", "refinements", GR(refinements), ", refined %lld times")},
    LINE(0),
    {FIELD("grid", "subgrids", GR(subgrids), "sub-grids   %lld of the top cells")},
    {TEXT(DR(subgrid_how), " (%s)")},
    {FIELD("grid", "leaves", GR(nleaves), ", %lld leaves (sub-cells and lists)")},
    {FIELD("grid", "leaf_refs", GR(nleaf_refs), ", %lld triangle references")},
    {FIELD("grid", "leaf_quads", DR(leaf_quads), " (%lld quads)")},
    {FIELD("grid", "tris_per_leaf_max", GR(tris_per_leaf_max), ", at most %lld in one leaf")},
    {FIELD("grid", "leaves_build_ms", GR(leaves_ms), ", build %.1f ms")},
    LINE(0),
    {FIELD("rays", "primary", RS(rays_primary), "rays        primary %lld")},
    {FIELD("rays", "refinement", RS(rays_refine), ", refinement %lld")},
    COUNTERS("rays"),
    {TEXT(RS(rays_shadow), ", shadow %lld")},
    {FIELD("rays", "shadow_feelers_per_light", DR(feelers_per_light),
           " (%lld per light per point")},
    {TEXT(NO_VALUE, ", fewer at ray-tree points weighing 1/4 or less"),
     .when = W_TRANSPARENCY | W_BY_WEIGHT},
    {FIELD("rays", "penumbra_factor", DR(penumbra_factor), ", %lld times as many"),
     .when = W_PENUMBRA},
    {TEXT(RS(shadow_penumbra), " at %lld points in a penumbra (their first feelers disagree)"),
     .when = W_PENUMBRA},
    {TEXT(RS(shadow_skipped), "; %lld skipped: light behind the surface")},
    {TEXT(RS(shadow_clear), "; %lld clear: not traced, their cone meets no object")},
    {TEXT(RS(shadow_blocked),
          "; %lld blocked: not traced, they pass through the core of an opaque part or object")},
    {TEXT(RS(shadow_unneeded), "; %lld unneeded: no BRDF response)")},
    {FIELD("rays", "total", DR(rays_total), ", total %lld")},
    LINE(W_TRANSPARENCY),
    COUNTERS("ray_tree"),
    {TEXT(RS(reflected), "ray tree    reflected %lld")},
    {TEXT(RS(transmitted), ", transmitted %lld")},
    {TEXT(RS(tir), ", total internal reflections %lld")},
    {TEXT(RS(pruned), "; not traced: %lld pruned")},
    {FIELD("ray_tree", "min_weight", SC(min_weight), " (weight < %g)")},
    {TEXT(RS(depth_cut), ", %lld deeper than max depth")},
    {FIELD("ray_tree", "max_depth", SC(max_depth), " %lld")},
    {TEXT(RS(tree_cut), ", %lld left when a tree reached")},
    {TEXT(DR(tree_max_rays), " %lld rays")},
    LINE(W_TRANSPARENCY),
    {TEXT(RS(interfaces), "energy      %lld interfaces split")},
    {TEXT(RS(energy_errors), ", %lld with |R + T - 1| > 1e-5")},
    LINE(W_TRANSPARENCY | W_DISPERSION),
    {TEXT(RS(splits), "dispersion  %lld rays split")},
    {FIELD("ray_tree", "bands", SC(bands), " into %lld bands")},
    {FIELD("ray_tree", "band_layout", DR(band_layout), " (thesis: 1 red, 2 green, 3 blue)"),
     .when = W_THESIS_BANDS},
    {TEXT(RS(band_rays), ", %lld band rays traced")},
    {TEXT(RS(dispersion_ms), ", %.1f ms in dispersive subtrees (device)")},
    LINE(W_TRANSPARENCY),
    {FIELD("rays", "by_depth", SPECIAL(T_BY_DEPTH), "by depth   ")},
    LINE(W_MEDIA),
    {TEXT(RS(pass_through), "media       %lld crossings passed through (no change of material)")},
    LINE(0),
    COUNTERS("work"),
    {FIELD("work", "cells_visited_per_ray", DR(cells_per_ray), "work        %.2f cells visited")},
    {FIELD("work", "triangles_tested_per_ray", DR(tris_per_ray),
           " and %.2f triangles tested per ray")},
    LINE(0),
    {JSON("samples", "total", RS(samples))},
    {FIELD("samples", "per_pixel_mean", DR(samples_mean), "samples     %.2f per pixel (mean)")},
    {FIELD("samples", "per_pixel_max", RS(samples_max), ", %lld (max)")},
    {FIELD("samples", "fraction_of_16x16", DR(samples_fraction), ", %.4f of uniform 16x16")},
    LINE(W_UNIFORM),
    {JSON("aa", "mode", DR(aa_mode))},
    {FIELD("aa", "ssaa", DR(ssaa), "anti-alias  uniform %lldx%lld supersampling, box window")},
    LINE(W_ADAPTIVE),
    {FIELD("aa", "threshold", DR(aa_threshold), "anti-alias  adaptive quadtree, threshold %g")},
    {FIELD("aa", "level_gain", DR(aa_level_gain), " (x %g per level)")},
    {FIELD("aa", "floor", DR(aa_floor), ", floor %g")},
    {FIELD("aa", "max_level", DR(aa_max_level), ", max level %lld")},
    {FIELD("aa", "min_level", DR(aa_min_level), ", min level %lld")},
    {FIELD("aa", "reconstruct", DR(aa_reconstruct), ", reconstruct %s")},
    {FIELD("aa", "pairs", DR(aa_pairs), ", pairs %s")},
    {FIELD("aa", "rounds", RS(aa_rounds), ", %lld rounds")},
    {FIELD("aa", "refined_per_level", SPECIAL(T_REFINED), "; pixels refined to level")},
    LINE(W_ADAPTIVE),
    {FIELD("aa", "contrast_ms", RS(aa_contrast_ms), "aa time     contrast %.1f ms")},
    {FIELD("aa", "refine_ms", RS(aa_refine_ms),
           ", refine %.1f ms (sample generation and tracing, included in the stages below)")},
    {FIELD("aa", "reconstruct_ms", RS(aa_reconstruct_ms), ", reconstruct %.1f ms (device)")},
    LINE(0),
    {FIELD("time_ms", "upload", RS(upload_ms), "time        upload %.1f ms")},
    {FIELD("time_ms", "camera", RS(camera_ms), " | camera %.1f ms")},
    {FIELD("time_ms", "intersect", RS(intersect_ms), ", intersect %.1f ms")},
    {FIELD("time_ms", "shading", RS(shading_ms), ", shading+shadows %.1f ms")},
    {FIELD("time_ms", "ray_trees", RS(tree_ms), ", ray trees %.1f ms")},
    {FIELD("time_ms", "dispersive_subtrees", RS(dispersion_ms), ", dispersive subtrees %.1f ms")},
    {FIELD("time_ms", "readback", RS(readback_ms), ", readback %.1f ms (device)")},
    {JSON("time_ms", "kernels", DR(kernel_ms))},
    {FIELD("time_ms", "image_wait", FR(image_wait_ms), " | image library %.1f ms")},
    {FIELD("time_ms", "render", RS(render_ms), ", render %.1f ms")},
    {FIELD("time_ms", "write", FR(write_ms), ", write %.1f ms")},
    {FIELD("time_ms", "total", FR(total_ms), ", total %.1f ms (wall)")},
    LINE(0),
    {FIELD(NULL, "mrays_per_s", DR(mrays_per_s), "throughput  %.2f Mrays/s over kernel time")},
    {FIELD("tiles", "count", RS(tiles), " (%lld tiles")},
    {FIELD("tiles", "max_pixels", RS(tile_pixels), " of up to %lld pixels)")},
};

/* Each device that worked on the frame (DeviceWork): an object of the JSON's "devices" and a
 * line of the text. */
static const StatsField device_fields[] = {
    LINE(0),
    {FIELD(NULL, "index", WK(index), "device %-4lld")},
    {FIELD(NULL, "rank", WK(rank), " rank %lld")},
    {FIELD(NULL, "name", WK(name), ", %s")},
    {JSON(NULL, "host", WK(host))},
    {FIELD(NULL, "tiles", WK(tiles), ": %lld tiles")},
    {FIELD(NULL, "rays", WK(rays), ", %lld rays")},
    {FIELD(NULL, "busy_ms", WK(busy_ms), ", busy %.1f ms (wall)")},
    {FIELD(NULL, "kernel_ms", WK(kernel_ms), ", kernels %.1f ms (device)")},
};

#define NFIELDS(t) (sizeof(t) / sizeof(t)[0])

/* How the program came (RenderStats.build_cached: CLU_BUILT ...) as --stats-json's
 * program.from; --stats says it in words (clu_build_how). */
static const char *build_source_json(int how)
{
    static const char *const json[] = {
        [CLU_BUILT] = "source",
        [CLU_BINARY] = "binary",
        [CLU_BUILT_DRIVER_CACHE] = "source_driver_cache",
        [CLU_KEPT] = "kept",
    };
    return json[how >= CLU_BUILT && how <= CLU_KEPT ? how : CLU_BUILT];
}

/* How many times its first feelers a point in a penumbra traces (light_penumbra): the
 * frame's factor where the feelers are a net of at least 2 x 2, else 1. */
static unsigned penumbra_factor(const StatsFrame *fr)
{
    const VbFrame *f = &fr->r->frame_host;
    return (f->flags & VBCL_FRAME_NET_FEELERS) && f->shadow_strata >= 2u ? f->penumbra_factor : 1u;
}

/* The names of the adaptive anti-aliasing's reconstruction and pair rule, as the options and
 * scene keys spell them (--aa-reconstruct, --aa-pairs). */
static const char *aa_reconstruct_name(const Scene *s)
{
    return s->aa_reconstruct == SCENE_AA_LEAVES ? "leaves" : "nearest";
}

static const char *aa_pairs_name(const Scene *s)
{
    return s->aa_pairs == SCENE_AA_PAIRS_BOTH ? "both" : "first";
}

/* The W_* that hold for frame fr. */
static unsigned stats_when(const StatsFrame *fr, int adaptive)
{
    const Scene *s = fr->scene;
    unsigned feat = fr->st->features, w = 0;
    if (fr->frame >= 0) w |= W_ANIMATION;
    if (feat & VBCL_FEATURE_TRANSPARENCY) w |= W_TRANSPARENCY;
    if (feat & (VBCL_FEATURE_TRANSPARENCY | VBCL_FEATURE_TEXTURES)) w |= W_MEDIA;
    if (feat & VBCL_FEATURE_DISPERSION) w |= W_DISPERSION;
    if (s->band_layout == DISP_LAYOUT_THESIS) w |= W_THESIS_BANDS;
    if (s->shadow_by_weight) w |= W_BY_WEIGHT;
    if (penumbra_factor(fr) > 1u) w |= W_PENUMBRA;
    if (s->ssaa > 1) w |= W_UNIFORM;
    if (adaptive) w |= W_ADAPTIVE;
    if (s->crop[2] > 0) w |= W_CROP;
    return w;
}

/* Fills *v for frame fr. The anti-aliasing's settings are 0 (names "none") unless it is
 * adaptive, where the text gives them. */
static void stats_derive(const StatsFrame *fr, StatsDerived *v)
{
    const Scene *s = fr->scene;
    const RenderStats *st = fr->st;
    const Grid *g = &fr->r->cs->grid;
    unsigned strata = fr->r->frame_host.shadow_strata;
    unsigned long long total = stats_rays_total(st);
    int reg[4], win[4];
    frame_region(s, reg);
    frame_window(s, win);
    unsigned long long window_pixels =
        (unsigned long long)(win[2] - win[0]) * (unsigned long long)(win[3] - win[1]);
    double npix = (double)window_pixels, kernel_ms = stats_kernel_ms(st);
    int adaptive = s->ssaa <= 1 && s->aa_threshold > 0.0f;
    *v = (StatsDerived){
        .when = stats_when(fr, adaptive),
        .program_name = features_program_name(st->program),
        .program_from = build_source_json(st->build_cached),
        .program_how = clu_build_how(st->build_cached),
        .program_cached = st->build_cached == CLU_BINARY,
        .grid_auto = !s->grid_res[0],
        .grid_how = s->grid_res[0] ? "given" : "auto",
        .subgrid_how = s->subgrid_res[0] ? "given" : "auto",
        .empty_percent = 100.0 * g->empty_fraction,
        .leaf_quads = grid_leaf_quads(g, s->tri_tag, VBCL_TAG_TEXTURE),
        .feelers_per_light = strata * strata,
        .penumbra_factor = penumbra_factor(fr),
        .rays_total = total,
        .tree_max_rays = VBCL_TREE_MAX_RAYS,
        .band_layout = s->band_layout == DISP_LAYOUT_THESIS ? "thesis" : "uniform",
        .cells_per_ray = per(st->traversal_steps, total),
        .tris_per_ray = per(st->tri_tests, total),
        .samples_mean = (double)st->samples / npix,
        .samples_fraction = (double)st->samples / (256.0 * npix),
        .aa_mode = s->ssaa > 1 ? "uniform"
                   : adaptive  ? "adaptive"
                               : "off",
        .aa_reconstruct = adaptive ? aa_reconstruct_name(s) : "none",
        .aa_pairs = adaptive ? aa_pairs_name(s) : "none",
        .ssaa = s->ssaa > 1 ? s->ssaa : 1,
        .aa_max_level = adaptive ? s->aa_max_level : 0,
        .aa_min_level = adaptive ? s->aa_min_level : 0,
        .aa_threshold = adaptive ? s->aa_threshold : 0.0f,
        .aa_floor = adaptive ? s->aa_floor : 0.0f,
        .aa_level_gain = adaptive ? s->aa_level_gain : 0.0f,
        .kernel_ms = kernel_ms,
        .mrays_per_s = kernel_ms > 0 ? (double)total / (kernel_ms * 1e3) : 0.0,
        .cropped = s->crop[2] > 0,
        .region = {reg[0], reg[1], reg[2], reg[3]},
        .window = {win[0], win[1], win[2], win[3]},
        .region_w = reg[2] - reg[0],
        .region_h = reg[3] - reg[1],
        .margin = frame_margin(s),
        .window_pixels = window_pixels,
    };
}

/* A frame's records, and its StatsDerived, where the rows read them (StatsAt.src). */
typedef struct StatsSources {
    const StatsFrame *fr;
    StatsDerived derived;
    const void *base[SRC_COUNT];
} StatsSources;

static void stats_sources(const StatsFrame *fr, StatsSources *c)
{
    c->fr = fr;
    stats_derive(fr, &c->derived);
    c->base[SRC_STATS] = fr->st;
    c->base[SRC_SCENE] = fr->scene;
    c->base[SRC_GRID] = &fr->r->cs->grid;
    c->base[SRC_DEVICE] = fr->dev;
    c->base[SRC_FRAME] = fr;
    c->base[SRC_DERIVED] = &c->derived;
    c->base[SRC_WORK] = NULL; /* set per device */
}

/* A field's value as the writers take it, by its T_*: an integer, a real or a name. */
typedef struct StatsValue {
    long long i;
    double d;
    const char *s;
} StatsValue;

/* Reads the field at `at`; all zero for T_NONE and from T_FRAME on. */
static StatsValue stats_read(const StatsSources *c, const StatsAt *at)
{
    StatsValue v = {0, 0.0, NULL};
    if (at->type == T_NONE || at->type >= T_FRAME) return v;
    const char *p = (const char *)c->base[at->src] + at->off;
    if (at->type == T_INT)
        v.i = *(const int *)p;
    else if (at->type == T_UINT)
        v.i = *(const unsigned *)p;
    else if (at->type == T_ULL)
        v.i = (long long)*(const unsigned long long *)p;
    else if (at->type == T_BOOL)
        v.i = *(const bool *)p;
    else if (at->type == T_DOUBLE)
        v.d = *(const double *)p;
    else if (at->type == T_FLOAT)
        v.d = *(const float *)p;
    else
        v.s = at->type == T_STR ? *(const char *const *)p : p;
    return v;
}

/* ---- the --stats text ---- */

/* The text of the fields that are not one number or name. The lists (by depth, refined per
 * level) are as long as the frame makes them, so their items' words are here, not in
 * the table. */
static void print_special(FILE *f, const StatsField *r, const StatsSources *c)
{
    const StatsFrame *fr = c->fr;
    const RenderStats *st = fr->st;
    const int *n = fr->r->cs->grid.n;
    const int *rect = r->at.type == T_REGION ? c->derived.region : c->derived.window;
    char feat[256];
    switch (r->at.type) {
    case T_FRAME:
        fprintf(f, r->text, (long long)fr->frame);
        break;
    case T_FEATURES:
        features_describe(st->features, feat, sizeof feat);
        fprintf(f, r->text, feat);
        break;
    case T_RESOLUTION:
        fprintf(f, r->text, (long long)n[0], (long long)n[1], (long long)n[2]);
        break;
    case T_BY_DEPTH:
        fputs(r->text, f);
        for (int k = 0; k < VBCL_COUNT_DEPTH_BINS; k++)
            if (st->by_depth[k])
                fprintf(f, " %s%d: %llu", k == VBCL_COUNT_DEPTH_BINS - 1 ? ">=" : "", k,
                        st->by_depth[k]);
        break;
    case T_REFINED:
        fputs(r->text, f);
        for (int l = 1; l <= fr->scene->aa_max_level; l++)
            fprintf(f, "%s %d (%dx%d): %llu", l > 1 ? "," : "", l, 1 << l, 1 << l,
                    st->aa_refined[l]);
        break;
    case T_REGION:
    case T_WINDOW:
        fprintf(f, r->text, (long long)rect[0], (long long)rect[1], (long long)rect[2],
                (long long)rect[3]);
        break;
    }
}

/* Prints field r in its words: its value read at text_at, or at `at`. */
static void print_field(FILE *f, const StatsField *r, const StatsSources *c)
{
    const StatsAt *at = r->text_at.type != T_NONE ? &r->text_at : &r->at;
    StatsValue v = stats_read(c, at);
    if (at->type >= T_FRAME)
        print_special(f, r, c);
    else if (at->type == T_NONE)
        fputs(r->text, f);
    else if (at->type == T_DOUBLE || at->type == T_FLOAT)
        fprintf(f, r->text, v.d);
    else if (at->type == T_STR || at->type == T_CHARS)
        fprintf(f, r->text, v.s);
    else
        fprintf(f, r->text, v.i, v.i);
}

/* Prints the text lines of rows[0..n): a line marker ends the line before it, if any of it
 * was printed, and starts one that is printed where its `when` holds. */
static void print_fields(FILE *f, const StatsField *rows, size_t n, const StatsSources *c)
{
    bool open = false, begun = false;
    for (size_t k = 0; k < n; k++) {
        const StatsField *r = &rows[k];
        bool holds = (r->when & ~c->derived.when) == 0;
        if (r->line) {
            if (begun) fputc('\n', f);
            open = holds;
            begun = false;
        } else if (open && holds && r->text) {
            print_field(f, r, c);
            begun = true;
        }
    }
    if (begun) fputc('\n', f);
}

void stats_print(FILE *f, const StatsFrame *fr)
{
    StatsSources c;
    stats_sources(fr, &c);
    print_fields(f, stats_fields, NFIELDS(stats_fields), &c);
    for (int i = 0; i < fr->nwork; i++) {
        c.base[SRC_WORK] = &fr->work[i];
        print_fields(f, device_fields, NFIELDS(device_fields), &c);
    }
}

/* ---- the --stats-json document ---- */

/* Adders that record a failure (out of memory) in *ok; a NULL object fails too. */
static void num(cJSON *o, const char *key, double v, int *ok)
{
    if (!cJSON_AddNumberToObject(o, key, v)) *ok = 0;
}

/* A float's value as its shortest decimal (0.001, not 0.0010000000474974513). */
static void fnum(cJSON *o, const char *key, float v, int *ok)
{
    char buf[32];
    snprintf(buf, sizeof buf, "%.7g", (double)v);
    num(o, key, strtod(buf, NULL), ok);
}

static void str(cJSON *o, const char *key, const char *v, int *ok)
{
    if (!cJSON_AddStringToObject(o, key, v)) *ok = 0;
}

static void flag(cJSON *o, const char *key, int v, int *ok)
{
    if (!cJSON_AddBoolToObject(o, key, v)) *ok = 0;
}

static cJSON *obj(cJSON *parent, const char *key, int *ok)
{
    cJSON *o = cJSON_AddObjectToObject(parent, key);
    if (!o) *ok = 0;
    return o;
}

static cJSON *arr(cJSON *parent, const char *key, int *ok)
{
    cJSON *a = cJSON_AddArrayToObject(parent, key);
    if (!a) *ok = 0;
    return a;
}

static void push(cJSON *a, cJSON *item, int *ok)
{
    if (!item || !cJSON_AddItemToArray(a, item)) {
        cJSON_Delete(item);
        *ok = 0;
    }
}

/* The kernels' counters of row r's group, under the keys VBCL_COUNTER_LIST gives them. */
static void json_counters(cJSON *o, const StatsField *r, const RenderStats *st, int *ok)
{
#define STATS_JSON_COUNTER(name, index, field, g, key)                                             \
    if (!strcmp(#g, r->group)) num(o, key, (double)st->field, ok);
    VBCL_COUNTER_LIST(STATS_JSON_COUNTER)
#undef STATS_JSON_COUNTER
}

/* The JSON of the fields that are not one number or name. */
static void json_special(cJSON *o, const StatsField *r, const StatsSources *c, int *ok)
{
    const StatsFrame *fr = c->fr;
    const RenderStats *st = fr->st;
    char feat[256];
    cJSON *a = NULL;
    switch (r->at.type) {
    case T_FRAME:
        if (fr->frame >= 0)
            num(o, r->key, fr->frame, ok);
        else if (!cJSON_AddNullToObject(o, r->key))
            *ok = 0;
        break;
    case T_FEATURES:
        features_describe(st->features, feat, sizeof feat);
        a = arr(o, r->key, ok);
        for (char *save = NULL, *w = strtok_r(feat, " ", &save); a && w;
             w = strtok_r(NULL, " ", &save))
            if (strcmp(w, "none")) push(a, cJSON_CreateString(w), ok);
        break;
    case T_RESOLUTION:
        a = cJSON_CreateIntArray(fr->r->cs->grid.n, 3);
        if (!a || !cJSON_AddItemToObject(o, r->key, a)) {
            cJSON_Delete(a);
            *ok = 0;
        }
        break;
    case T_BY_DEPTH:
        a = arr(o, r->key, ok);
        for (int k = 0; a && k < VBCL_COUNT_DEPTH_BINS; k++)
            push(a, cJSON_CreateNumber((double)st->by_depth[k]), ok);
        break;
    case T_REFINED:
        a = arr(o, r->key, ok);
        for (int l = 1; a && (c->derived.when & W_ADAPTIVE) && l <= fr->scene->aa_max_level; l++)
            push(a, cJSON_CreateNumber((double)st->aa_refined[l]), ok);
        break;
    case T_REGION:
    case T_WINDOW:
        a = cJSON_CreateIntArray(r->at.type == T_REGION ? c->derived.region : c->derived.window, 4);
        if (!a || !cJSON_AddItemToObject(o, r->key, a)) {
            cJSON_Delete(a);
            *ok = 0;
        }
        break;
    case T_COUNTERS:
        json_counters(o, r, st, ok);
        break;
    }
}

/* Adds field r to object o under its key. */
static void json_field(cJSON *o, const StatsField *r, const StatsSources *c, int *ok)
{
    StatsValue v = stats_read(c, &r->at);
    if (r->at.type >= T_FRAME)
        json_special(o, r, c, ok);
    else if (r->at.type == T_DOUBLE)
        num(o, r->key, v.d, ok);
    else if (r->at.type == T_FLOAT)
        fnum(o, r->key, (float)v.d, ok);
    else if (r->at.type == T_BOOL)
        flag(o, r->key, (int)v.i, ok);
    else if (r->at.type == T_STR || r->at.type == T_CHARS)
        str(o, r->key, v.s, ok);
    else
        num(o, r->key, (double)v.i, ok);
}

/* Adds the fields of rows[0..n) that the JSON has to top: a row with a group to the object
 * of that name in top, which the group's first row adds. */
static void json_fields(cJSON *top, const StatsField *rows, size_t n, const StatsSources *c,
                        int *ok)
{
    for (size_t k = 0; k < n; k++) {
        const StatsField *r = &rows[k];
        if (r->line || (!r->key && r->at.type != T_COUNTERS)) continue;
        cJSON *o = top;
        if (r->group && !(o = cJSON_GetObjectItemCaseSensitive(top, r->group)))
            o = obj(top, r->group, ok);
        json_field(o, r, c, ok);
    }
}

cJSON *stats_json(const StatsFrame *fr)
{
    int ok = 1;
    cJSON *root = cJSON_CreateObject();
    if (!root) return NULL;
    StatsSources c;
    stats_sources(fr, &c);
    json_fields(root, stats_fields, NFIELDS(stats_fields), &c, &ok);
    cJSON *devs = arr(root, "devices", &ok);
    for (int i = 0; i < fr->nwork && devs; i++) {
        cJSON *d = cJSON_CreateObject();
        c.base[SRC_WORK] = &fr->work[i];
        if (d) json_fields(d, device_fields, NFIELDS(device_fields), &c, &ok);
        push(devs, d, &ok);
    }
    if (!ok) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}
int stats_json_add_frame(cJSON **doc, const StatsFrame *fr)
{
    cJSON *f = stats_json(fr);
    if (!f) return -1;
    if (fr->frame < 0) {
        cJSON_Delete(*doc);
        *doc = f;
        return 0;
    }
    if (!*doc) {
        int ok = 1;
        cJSON *d = cJSON_CreateObject();
        str(d, "scene", fr->scene->path, &ok);
        num(d, "frames_in_scene", fr->scene->frames, &ok);
        arr(d, "frames", &ok);
        if (!d || !ok) {
            cJSON_Delete(d);
            cJSON_Delete(f);
            return -1;
        }
        *doc = d;
    }
    cJSON *frames = cJSON_GetObjectItemCaseSensitive(*doc, "frames");
    if (!cJSON_AddItemToArray(frames, f)) {
        cJSON_Delete(f);
        return -1;
    }
    return 0;
}

int stats_json_write(const char *path, const cJSON *doc, char *err, size_t errlen)
{
    char *text = cJSON_Print(doc);
    if (!text) {
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    size_t n = strlen(text);
    text[n] = '\n'; /* the terminator becomes a final newline */
    int rc = file_write_whole(path, text, n + 1, err, errlen);
    cJSON_free(text);
    return rc;
}
