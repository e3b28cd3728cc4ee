/* stats.c — the report of a render: the --stats text and the --stats-json document, from
 * the same RenderStats (the kernels' counters come from VBCL_COUNTER_LIST in types.h). */
#include "stats.h"

#include <stdlib.h>
#include <string.h>

#include "fileio.h"
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

/* ---- the --stats text ---- */

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

/* scene, device, features, program, grid */
static void print_setup(FILE *f, const StatsFrame *fr)
{
    const Scene *s = fr->scene;
    const RenderStats *st = fr->st;
    const Grid *g = &fr->r->cs->grid;
    char feat[128];
    features_describe(st->features, feat, sizeof feat);
    if (fr->frame >= 0) fprintf(f, "frame       %d of %d\n", fr->frame, s->frames);
    fprintf(f, "scene       %s: %d objects, %u triangles, %d materials, %d lights\n", s->path,
            s->nobjects, s->mesh.ntris, s->nmaterials, s->nlights);
    fprintf(f, "device      %s (%s)\n", fr->dev->name, fr->dev->version);
    fprintf(f, "features    %s\n", feat);
    fprintf(f, "program     %s, %.1f ms (%s; first launches %.1f ms), options: %s\n",
            features_program_name(st->program), st->build_ms, clu_build_how(st->build_cached),
            st->first_launch_ms, st->options);
    fprintf(f,
            "grid        %dx%dx%d = %u cells (%s), build %.1f ms, triangles per cell mean %.2f max "
            "%u, empty %.1f%%, per non-empty cell %.2f, refined %d times\n",
            g->n[0], g->n[1], g->n[2], g->ncells, s->grid_res[0] ? "given" : "auto", st->grid_ms,
            g->tris_per_cell_mean, g->tris_per_cell_max, 100.0 * g->empty_fraction,
            g->tris_per_nonempty_mean, g->refinements);
    fprintf(f,
            "sub-grids   %u of the top cells (%s), %u leaves (sub-cells and lists), %u triangle "
            "references (%zu quads), at most %u in one leaf, build %.1f ms\n",
            g->subgrids, s->subgrid_res[0] ? "given" : "auto", g->nleaves, g->nleaf_refs,
            grid_leaf_quads(g, s->tri_tag, VBCL_TAG_TEXTURE), g->tris_per_leaf_max, g->leaves_ms);
}

/* ray trees, energy, dispersion, rays by depth (scenes with dielectrics) */
static void print_tree(FILE *f, const Scene *s, const RenderStats *st)
{
    fprintf(f,
            "ray tree    reflected %llu, transmitted %llu, total internal reflections %llu; not "
            "traced: %llu pruned (weight < %g), %llu deeper than max depth %d, %llu left when "
            "a tree reached %d rays\n",
            st->reflected, st->transmitted, st->tir, st->pruned, (double)s->min_weight,
            st->depth_cut, s->max_depth, st->tree_cut, VBCL_TREE_MAX_RAYS);
    fprintf(f, "energy      %llu interfaces split, %llu with |R + T - 1| > 1e-5\n", st->interfaces,
            st->energy_errors);
    if (st->features & VBCL_FEATURE_DISPERSION)
        fprintf(f,
                "dispersion  %llu rays split into %d bands%s, %llu band rays traced, %.1f ms in "
                "dispersive subtrees (device)\n",
                st->splits, s->bands,
                s->band_layout == DISP_LAYOUT_THESIS ? " (thesis: 1 red, 2 green, 3 blue)" : "",
                st->band_rays, st->dispersion_ms);
    fprintf(f, "by depth   ");
    for (int k = 0; k < VBCL_COUNT_DEPTH_BINS; k++)
        if (st->by_depth[k])
            fprintf(f, " %s%d: %llu", k == VBCL_COUNT_DEPTH_BINS - 1 ? ">=" : "", k,
                    st->by_depth[k]);
    fputc('\n', f);
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

/* samples per pixel and anti-aliasing */
static void print_samples(FILE *f, const Scene *s, const RenderStats *st)
{
    long npix = (long)s->width * s->height;
    fprintf(f, "samples     %.2f per pixel (mean), %u (max), %.4f of uniform 16x16\n",
            (double)st->samples / (double)npix, st->samples_max,
            (double)st->samples / (256.0 * (double)npix));
    if (s->ssaa > 1) {
        fprintf(f, "anti-alias  uniform %dx%d supersampling, box window\n", s->ssaa, s->ssaa);
        return;
    }
    if (!(s->aa_threshold > 0.0f)) return;
    fprintf(f,
            "anti-alias  adaptive quadtree, threshold %g (x %g per level), floor %g, max level %d, "
            "min level %d, reconstruct %s, pairs %s, %d rounds; pixels refined to level",
            (double)s->aa_threshold, (double)s->aa_level_gain, (double)s->aa_floor, s->aa_max_level,
            s->aa_min_level, aa_reconstruct_name(s), aa_pairs_name(s), st->aa_rounds);
    for (int l = 1; l <= s->aa_max_level; l++)
        fprintf(f, " %d (%dx%d): %llu%s", l, 1 << l, 1 << l, st->aa_refined[l],
                l < s->aa_max_level ? "," : "\n");
    fprintf(f,
            "aa time     contrast %.1f ms, refine %.1f ms (sample generation and tracing, "
            "included in the stages below), reconstruct %.1f ms (device)\n",
            st->aa_contrast_ms, st->aa_refine_ms, st->aa_reconstruct_ms);
}

/* How many times its first feelers a point in a penumbra traces (light_penumbra): the
 * frame's factor where the feelers are a net of at least 2 x 2, else 1. */
static unsigned penumbra_factor(const StatsFrame *fr)
{
    const VbFrame *f = &fr->r->frame_host;
    return (f->flags & VBCL_FRAME_NET_FEELERS) && f->shadow_strata >= 2u ? f->penumbra_factor : 1u;
}

void stats_print(FILE *f, const StatsFrame *fr)
{
    const Scene *s = fr->scene;
    const RenderStats *st = fr->st;
    unsigned long long rays = stats_rays_total(st);
    double kernel_ms = stats_kernel_ms(st);
    unsigned strata = fr->r->frame_host.shadow_strata;
    char penumbra[160] = "";
    if (penumbra_factor(fr) > 1u)
        snprintf(penumbra, sizeof penumbra,
                 ", %u times as many at %llu points in a penumbra (their first feelers disagree)",
                 penumbra_factor(fr), st->shadow_penumbra);
    print_setup(f, fr);
    fprintf(
        f,
        "rays        primary %llu, refinement %llu, shadow %llu (%u per light per point%s%s; %llu "
        "skipped: light behind the surface; %llu clear: not traced, their cone meets no "
        "object; %llu blocked: not traced, they pass through the core of an opaque part or "
        "object; %llu unneeded: no BRDF response), total %llu\n",
        st->rays_primary, st->rays_refine, st->rays_shadow, strata * strata,
        (st->features & VBCL_FEATURE_TRANSPARENCY) && s->shadow_by_weight
            ? ", fewer at ray-tree points weighing 1/4 or less"
            : "",
        penumbra, st->shadow_skipped, st->shadow_clear, st->shadow_blocked, st->shadow_unneeded,
        rays);
    if (st->features & VBCL_FEATURE_TRANSPARENCY) print_tree(f, s, st);
    if (st->features & (VBCL_FEATURE_TRANSPARENCY | VBCL_FEATURE_TEXTURES))
        fprintf(f, "media       %llu crossings passed through (no change of material)\n",
                st->pass_through);
    fprintf(f, "work        %.2f cells visited and %.2f triangles tested per ray\n",
            per(st->traversal_steps, rays), per(st->tri_tests, rays));
    print_samples(f, s, st);
    fprintf(f,
            "time        upload %.1f ms | camera %.1f ms, intersect %.1f ms, shading+shadows %.1f "
            "ms, ray trees %.1f ms, dispersive subtrees %.1f ms, readback %.1f ms (device) | "
            "image library %.1f ms, render %.1f ms, write %.1f ms, total %.1f ms (wall)\n",
            st->upload_ms, st->camera_ms, st->intersect_ms, st->shading_ms, st->tree_ms,
            st->dispersion_ms, st->readback_ms, fr->image_wait_ms, st->render_ms, fr->write_ms,
            fr->total_ms);
    fprintf(f, "throughput  %.2f Mrays/s over kernel time (%d tiles of up to %d pixels)\n",
            kernel_ms > 0 ? (double)rays / (kernel_ms * 1e3) : 0.0, st->tiles, st->tile_pixels);
    for (int i = 0; i < fr->nwork; i++) {
        const DeviceWork *w = &fr->work[i];
        fprintf(f,
                "device %-4d rank %d, %s: %llu tiles, %llu rays, busy %.1f ms (wall), kernels "
                "%.1f ms (device)\n",
                w->index, w->rank, w->name, w->tiles, w->rays, w->busy_ms, w->kernel_ms);
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

/* scene, device, features, program */
static void json_setup(cJSON *root, const StatsFrame *fr, int *ok)
{
    const Scene *s = fr->scene;
    const RenderStats *st = fr->st;
    cJSON *o = obj(root, "scene", ok);
    str(o, "path", s->path, ok);
    num(o, "objects", s->nobjects, ok);
    num(o, "triangles", s->mesh.ntris, ok);
    num(o, "materials", s->nmaterials, ok);
    num(o, "lights", s->nlights, ok);
    num(o, "width", s->width, ok);
    num(o, "height", s->height, ok);
    o = obj(root, "device", ok);
    str(o, "name", fr->dev->name, ok);
    str(o, "version", fr->dev->version, ok);
    str(o, "driver", fr->dev->driver, ok);
    char feat[256];
    features_describe(st->features, feat, sizeof feat);
    cJSON *a = arr(root, "features", ok);
    for (char *save = NULL, *w = strtok_r(feat, " ", &save); a && w; w = strtok_r(NULL, " ", &save))
        if (strcmp(w, "none")) push(a, cJSON_CreateString(w), ok);
    o = obj(root, "program", ok);
    str(o, "name", features_program_name(st->program), ok);
    num(o, "build_ms", st->build_ms, ok);
    num(o, "first_launch_ms", st->first_launch_ms, ok);
    flag(o, "cached", st->build_cached == CLU_BINARY, ok);
    str(o, "from", build_source_json(st->build_cached), ok);
    str(o, "options", st->options, ok);
}

static void json_grid(cJSON *root, const StatsFrame *fr, int *ok)
{
    const Grid *g = &fr->r->cs->grid;
    cJSON *o = obj(root, "grid", ok);
    cJSON *res = cJSON_CreateIntArray(g->n, 3);
    if (!res || !cJSON_AddItemToObject(o, "resolution", res)) {
        cJSON_Delete(res);
        *ok = 0;
    }
    num(o, "cells", g->ncells, ok);
    flag(o, "auto", !fr->scene->grid_res[0], ok);
    num(o, "build_ms", fr->st->grid_ms, ok);
    num(o, "triangle_refs", g->nrefs, ok);
    fnum(o, "tris_per_cell_mean", g->tris_per_cell_mean, ok);
    num(o, "tris_per_cell_max", g->tris_per_cell_max, ok);
    fnum(o, "empty_fraction", g->empty_fraction, ok);
    fnum(o, "tris_per_nonempty_cell_mean", g->tris_per_nonempty_mean, ok);
    num(o, "refinements", g->refinements, ok);
    num(o, "subgrids", g->subgrids, ok);
    num(o, "leaves", g->nleaves, ok);
    num(o, "leaf_refs", g->nleaf_refs, ok);
    num(o, "leaf_quads", (double)grid_leaf_quads(g, fr->scene->tri_tag, VBCL_TAG_TEXTURE), ok);
    num(o, "tris_per_leaf_max", g->tris_per_leaf_max, ok);
    num(o, "leaves_build_ms", g->leaves_ms, ok);
}

/* rays, ray_tree, work: the kernels' counters go to the group VBCL_COUNTER_LIST names */
static void json_rays(cJSON *root, const StatsFrame *fr, int *ok)
{
    const Scene *s = fr->scene;
    const RenderStats *st = fr->st;
    unsigned long long total = stats_rays_total(st);
    unsigned strata = fr->r->frame_host.shadow_strata;
    cJSON *rays = obj(root, "rays", ok), *ray_tree = obj(root, "ray_tree", ok);
    cJSON *work = obj(root, "work", ok);
    num(rays, "primary", (double)st->rays_primary, ok);
    num(rays, "refinement", (double)st->rays_refine, ok);
#define STATS_JSON_COUNTER(name, index, field, group, key) num(group, key, (double)st->field, ok);
    VBCL_COUNTER_LIST(STATS_JSON_COUNTER)
#undef STATS_JSON_COUNTER
    num(rays, "total", (double)total, ok);
    num(rays, "shadow_feelers_per_light", strata * strata, ok);
    num(rays, "penumbra_factor", penumbra_factor(fr), ok);
    cJSON *d = arr(rays, "by_depth", ok);
    for (int k = 0; d && k < VBCL_COUNT_DEPTH_BINS; k++)
        push(d, cJSON_CreateNumber((double)st->by_depth[k]), ok);
    num(ray_tree, "max_depth", s->max_depth, ok);
    fnum(ray_tree, "min_weight", s->min_weight, ok);
    num(ray_tree, "bands", s->bands, ok);
    str(ray_tree, "band_layout", s->band_layout == DISP_LAYOUT_THESIS ? "thesis" : "uniform", ok);
    num(work, "cells_visited_per_ray", per(st->traversal_steps, total), ok);
    num(work, "triangles_tested_per_ray", per(st->tri_tests, total), ok);
}

/* samples and anti-aliasing */
static void json_samples(cJSON *root, const Scene *s, const RenderStats *st, int *ok)
{
    double npix = (double)s->width * (double)s->height;
    cJSON *o = obj(root, "samples", ok);
    num(o, "total", (double)st->samples, ok);
    num(o, "per_pixel_mean", (double)st->samples / npix, ok);
    num(o, "per_pixel_max", st->samples_max, ok);
    num(o, "fraction_of_16x16", (double)st->samples / (256.0 * npix), ok);
    int adaptive = s->ssaa <= 1 && s->aa_threshold > 0.0f;
    o = obj(root, "aa", ok);
    str(o, "mode", s->ssaa > 1 ? "uniform" : adaptive ? "adaptive" : "off", ok);
    num(o, "ssaa", s->ssaa > 1 ? s->ssaa : 1, ok);
    fnum(o, "threshold", adaptive ? s->aa_threshold : 0.0f, ok);
    fnum(o, "floor", adaptive ? s->aa_floor : 0.0f, ok);
    fnum(o, "level_gain", adaptive ? s->aa_level_gain : 0.0f, ok);
    num(o, "max_level", adaptive ? s->aa_max_level : 0, ok);
    num(o, "min_level", adaptive ? s->aa_min_level : 0, ok);
    str(o, "reconstruct", adaptive ? aa_reconstruct_name(s) : "none", ok);
    str(o, "pairs", adaptive ? aa_pairs_name(s) : "none", ok);
    num(o, "rounds", st->aa_rounds, ok);
    cJSON *a = arr(o, "refined_per_level", ok);
    for (int l = 1; a && adaptive && l <= s->aa_max_level; l++)
        push(a, cJSON_CreateNumber((double)st->aa_refined[l]), ok);
    num(o, "contrast_ms", st->aa_contrast_ms, ok);
    num(o, "refine_ms", st->aa_refine_ms, ok);
    num(o, "reconstruct_ms", st->aa_reconstruct_ms, ok);
}

/* stage times, throughput, tiles */
static void json_times(cJSON *root, const StatsFrame *fr, int *ok)
{
    const RenderStats *st = fr->st;
    double kernel_ms = stats_kernel_ms(st);
    cJSON *o = obj(root, "time_ms", ok);
    num(o, "upload", st->upload_ms, ok);
    num(o, "camera", st->camera_ms, ok);
    num(o, "intersect", st->intersect_ms, ok);
    num(o, "shading", st->shading_ms, ok);
    num(o, "ray_trees", st->tree_ms, ok);
    num(o, "dispersive_subtrees", st->dispersion_ms, ok);
    num(o, "readback", st->readback_ms, ok);
    num(o, "kernels", kernel_ms, ok);
    num(o, "image_wait", fr->image_wait_ms, ok);
    num(o, "render", st->render_ms, ok);
    num(o, "write", fr->write_ms, ok);
    num(o, "total", fr->total_ms, ok);
    num(root, "mrays_per_s", kernel_ms > 0 ? (double)stats_rays_total(st) / (kernel_ms * 1e3) : 0.0,
        ok);
    o = obj(root, "tiles", ok);
    num(o, "count", st->tiles, ok);
    num(o, "max_pixels", st->tile_pixels, ok);
    cJSON *devs = arr(root, "devices", ok);
    for (int i = 0; i < fr->nwork && devs; i++) {
        const DeviceWork *w = &fr->work[i];
        cJSON *d = cJSON_CreateObject();
        num(d, "index", w->index, ok);
        num(d, "rank", w->rank, ok);
        str(d, "name", w->name, ok);
        str(d, "host", w->host, ok);
        num(d, "tiles", (double)w->tiles, ok);
        num(d, "rays", (double)w->rays, ok);
        num(d, "busy_ms", w->busy_ms, ok);
        num(d, "kernel_ms", w->kernel_ms, ok);
        push(devs, d, ok);
    }
}

cJSON *stats_json(const StatsFrame *fr)
{
    int ok = 1;
    cJSON *root = cJSON_CreateObject();
    if (!root) return NULL;
    if (fr->frame >= 0)
        num(root, "frame", fr->frame, &ok);
    else if (!cJSON_AddNullToObject(root, "frame"))
        ok = 0;
    json_setup(root, fr, &ok);
    json_grid(root, fr, &ok);
    json_rays(root, fr, &ok);
    json_samples(root, fr->scene, fr->st, &ok);
    json_times(root, fr, &ok);
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
