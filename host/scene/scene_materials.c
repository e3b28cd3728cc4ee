/* scene_materials.c — materials[]: the surface coefficients, surface patterns (Fourier,
 * projection) and dispersion models with their bands. */
#include "scene_parts.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diag.h"

/* materials.NAME.pattern: a Fourier or projection surface pattern (thesis 2.2.2.3). */
/* A checker's "colours" (two colours; light and dark grey by default) and "axes" (the axes
 * along which its cells alternate: "xz" by default, a floor's), refused on other patterns. */
static int load_checker(Ctx *c, const cJSON *j, const char *p, ScenePattern *pt)
{
    static const float grey[2][3] = {{0.9f, 0.9f, 0.9f}, {0.15f, 0.15f, 0.15f}};
    const cJSON *col = cJSON_GetObjectItemCaseSensitive(j, "colours");
    const cJSON *ax = cJSON_GetObjectItemCaseSensitive(j, "axes");
    char q[PATH_MAX_LEN], r[PATH_MAX_LEN];
    if (pt->kind != VBCL_PATTERN_CHECKER) {
        if (!col && !ax) return 0;
        json_path_key(q, p, col ? "colours" : "axes");
        return scene_fail(c, q, "only a checker pattern takes colours and axes");
    }
    memcpy(pt->colours, grey, sizeof grey);
    json_path_key(q, p, "colours");
    if (col && (!cJSON_IsArray(col) || cJSON_GetArraySize(col) != 2))
        return scene_fail(c, q, "expected two colours, [[r, g, b], [r, g, b]]");
    for (int k = 0; col && k < 2; k++) {
        json_path_index(r, q, k);
        if (json_read_vec(c, cJSON_GetArrayItem(col, k), r, 3, 0.0, FLT_MAX, pt->colours[k]))
            return -1;
    }
    pt->axes = 1u | 4u;
    json_path_key(q, p, "axes");
    if (ax) {
        const char *a = cJSON_IsString(ax) ? ax->valuestring : NULL;
        pt->axes = 0;
        for (const char *ch = a; ch && *ch; ch++) {
            unsigned bit = *ch == 'x' ? 1u : *ch == 'y' ? 2u : *ch == 'z' ? 4u : 8u;
            if (bit == 8u || (pt->axes & bit)) {
                pt->axes = 0;
                break;
            }
            pt->axes |= bit;
        }
        if (!pt->axes)
            return scene_fail(c, q,
                              "expected the axes the cells alternate along: \"x\", \"xz\", "
                              "\"xyz\" ... (each once)");
    }
    return 0;
}

/* A projection's "axis" ("x", "y" or "z", the default): the image lies across the other two
 * in cyclic order, u along the first and v along the second (x: y, z; y: z, x; z: x, y), and
 * is projected along it; kept in pt->axes as that axis's bit. Refused on other patterns. */
static int load_projection_axis(Ctx *c, const cJSON *j, const char *p, ScenePattern *pt)
{
    const cJSON *ax = cJSON_GetObjectItemCaseSensitive(j, "axis");
    char q[PATH_MAX_LEN];
    json_path_key(q, p, "axis");
    if (pt->kind != VBCL_PATTERN_PROJECTION)
        return ax ? scene_fail(c, q, "only a projection pattern takes an axis") : 0;
    pt->axes = 4u;
    if (!ax) return 0;
    const char *a = cJSON_IsString(ax) ? ax->valuestring : "";
    if (strlen(a) != 1 || !strchr("xyz", a[0]))
        return scene_fail(c, q, "expected the axis to project along: \"x\", \"y\" or \"z\"");
    pt->axes = 1u << (a[0] - 'x');
    return 0;
}

static int load_pattern(Ctx *c, const cJSON *e, const char *path, const Scene *s, ScenePattern *pt)
{
    static const char *const keys[] = {"type",   "terms", "contrast", "frequency", "seed", "image",
                                       "origin", "size",  "colours",  "axes",      "axis", NULL};
    static const float zero[3] = {0, 0, 0};
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(e, "pattern");
    if (!j) return 0;
    char p[PATH_MAX_LEN], q[PATH_MAX_LEN];
    json_path_key(p, path, "pattern");
    if (json_expect_object(c, j, p) || json_check_keys(c, j, p, keys)) return -1;
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(j, "type");
    json_path_key(q, p, "type");
    if (t && cJSON_IsString(t) && strcmp(t->valuestring, "fourier") == 0)
        pt->kind = VBCL_PATTERN_FOURIER;
    else if (t && cJSON_IsString(t) && strcmp(t->valuestring, "projection") == 0)
        pt->kind = VBCL_PATTERN_PROJECTION;
    else if (t && cJSON_IsString(t) && strcmp(t->valuestring, "checker") == 0)
        pt->kind = VBCL_PATTERN_CHECKER;
    else
        return scene_fail(c, q, "expected \"fourier\", \"projection\" or \"checker\"");
    if (load_checker(c, j, p, pt)) return -1;
    double seed;
    if (json_get_int(c, j, p, "terms", 4, 7, 5, 0, &pt->terms) ||
        json_get_float(c, j, p, "contrast", 0, 100, 1, 0, &pt->contrast) ||
        json_get_scalar_or_vec3(c, j, p, "frequency", 1e-6, 1e6, 1, pt->freq) ||
        json_get_num(c, j, p, "seed", 0, 9007199254740992.0, 1, 0, &seed) ||
        json_get_vec(c, j, p, "origin", 3, -FLT_MAX, FLT_MAX, zero, pt->origin) ||
        json_get_scalar_or_vec3(c, j, p, "size", FLT_MIN, FLT_MAX, 1, pt->size))
        return -1;
    double od[3];
    json_numbers(cJSON_GetObjectItemCaseSensitive(j, "origin"),
                 v3(pt->origin[0], pt->origin[1], pt->origin[2]), od);
    vec3 origin = scene_frame_point(s, od);
    pt->origin[0] = origin.x; /* patterns lie in the scene's frame too */
    pt->origin[1] = origin.y;
    pt->origin[2] = origin.z;
    for (int k = 0; k < 3; k++) pt->size[k] *= s->frame_scale;
    pt->seed = (unsigned long long)seed;
    const cJSON *img = cJSON_GetObjectItemCaseSensitive(j, "image");
    json_path_key(q, p, "image");
    if (pt->kind == VBCL_PATTERN_PROJECTION) {
        if (!img || !cJSON_IsString(img) || !img->valuestring[0])
            return scene_fail(c, q, "expected the image file to project");
        char full[4096];
        scene_join_path(full, sizeof full, s->dir, img->valuestring);
        if (!(pt->image = scene_strdup(full))) return scene_fail(c, NULL, "out of memory");
    } else if (img) {
        return scene_fail(c, q, "only a projection pattern takes an image");
    }
    return load_projection_axis(c, j, p, pt);
}

/* The first wavelength where the model's index is not a finite number > 0, or 0: every
 * nanometre of [380, 780] and every band centre of every layout renders can sample. */
static double disp_bad_wavelength(const DispModel *d)
{
    for (int l = (int)DISP_LAMBDA_MIN; l <= (int)DISP_LAMBDA_MAX; l++) {
        double n = disp_eta(d, l);
        if (!isfinite(n) || !(n > 0)) return l;
    }
    DispBand bands[DISP_MAX_BANDS];
    for (int n = 1; n <= DISP_MAX_BANDS + 1; n++) {
        int k = n <= DISP_MAX_BANDS
                    ? disp_layout_bands(DISP_LAYOUT_UNIFORM, n, bands)
                    : disp_layout_bands(DISP_LAYOUT_THESIS, DISP_THESIS_BANDS, bands);
        for (int b = 0; b < k; b++) {
            double eta = disp_eta(d, bands[b].centre);
            if (!isfinite(eta) || !(eta > 0)) return bands[b].centre;
        }
    }
    return 0;
}

/* materials.NAME.dispersion: {"model": "thesis", "spread": Δη} (eta at 670 nm, thesis 3.5),
 * {"model": "cauchy", "abbe": V_d} (n_d = the material's eta),
 * {"model": "sellmeier", "preset": "BK7" | "F2"} or {"model": "sellmeier", "B": [3], "C": [3]},
 * each with an optional absorption band "band": [lo, hi] (nm) and "jump" (Δη beyond it). */
static int load_dispersion(Ctx *c, const cJSON *mat, const char *path, float eta, DispModel *d)
{
    static const char *const keys[] = {"model", "abbe", "preset", "B", "C",
                                       "band",  "jump", "spread", NULL};
    memset(d, 0, sizeof *d);
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(mat, "dispersion");
    if (!j) return 0;
    char p[PATH_MAX_LEN], q[PATH_MAX_LEN];
    json_path_key(p, path, "dispersion");
    if (json_expect_object(c, j, p) || json_check_keys(c, j, p, keys)) return -1;
    const cJSON *model = cJSON_GetObjectItemCaseSensitive(j, "model");
    json_path_key(q, p, "model");
    if (!cJSON_IsString(model))
        return scene_fail(c, q, "expected \"thesis\", \"cauchy\" or \"sellmeier\"");
    if (strcmp(model->valuestring, "thesis") == 0) {
        double spread;
        if (json_get_num(c, j, p, "spread", 0, 1, 0.03, 0, &spread)) return -1;
        disp_thesis_model(d, eta, spread);
    } else if (strcmp(model->valuestring, "cauchy") == 0) {
        double abbe;
        if (json_get_num(c, j, p, "abbe", 1, 200, 0, 1, &abbe)) return -1;
        disp_cauchy_from_abbe(d, eta, abbe);
    } else if (strcmp(model->valuestring, "sellmeier") == 0) {
        const cJSON *pre = cJSON_GetObjectItemCaseSensitive(j, "preset");
        json_path_key(q, p, "preset");
        if (pre) {
            if (!cJSON_IsString(pre) || disp_sellmeier_preset(d, pre->valuestring))
                return scene_fail(c, q, "expected \"BK7\" or \"F2\"");
        } else {
            float b[3], cc[3];
            if (json_get_vec(c, j, p, "B", 3, 0, 100, NULL, b) ||
                json_get_vec(c, j, p, "C", 3, 0, 1e4, NULL, cc))
                return -1;
            d->model = DISP_SELLMEIER;
            for (int i = 0; i < 3; i++) {
                d->sb[i] = b[i];
                d->sc[i] = cc[i];
            }
        }
    } else {
        return scene_fail(c, q, "expected \"thesis\", \"cauchy\" or \"sellmeier\", got \"%s\"",
                          diag_value(model->valuestring));
    }
    if (cJSON_GetObjectItemCaseSensitive(j, "band")) {
        float band[2], jump;
        if (json_get_vec(c, j, p, "band", 2, DISP_LAMBDA_MIN, DISP_LAMBDA_MAX, NULL, band) ||
            json_get_float(c, j, p, "jump", -10, 10, 0, 0, &jump))
            return -1;
        json_path_key(q, p, "band");
        if (!(band[1] > band[0])) return scene_fail(c, q, "expected [lo, hi] with lo < hi");
        d->has_band = 1;
        d->band_lo = band[0];
        d->band_hi = band[1];
        d->jump = jump;
    }
    double bad = disp_bad_wavelength(d);
    if (bad > 0) {
        char v[32] = "not a number (eta squared < 0)";
        double n = disp_eta(d, bad);
        if (!isnan(n)) snprintf(v, sizeof v, "%g", n);
        return scene_fail(c, p,
                          "eta at %g nm is %s: it must be finite and > 0 at every wavelength "
                          "from %g to %g nm",
                          bad, v, DISP_LAMBDA_MIN, DISP_LAMBDA_MAX);
    }
    return 0;
}

/* Without render.bands, a scene whose dispersive materials all use the thesis model
 * renders with the thesis's per-channel rays. */
void scene_default_band_layout(const cJSON *render, Scene *s)
{
    if (render && cJSON_GetObjectItemCaseSensitive(render, "bands")) return;
    int thesis = 0, other = 0;
    for (int i = 0; i < s->nmaterials; i++) {
        int m = s->materials[i].disp.model;
        thesis += m == DISP_THESIS;
        other += m != DISP_THESIS && m != DISP_NONE;
    }
    if (thesis && !other) {
        s->bands = DISP_THESIS_BANDS;
        s->band_layout = DISP_LAYOUT_THESIS;
    }
}

int scene_load_materials(Ctx *c, const cJSON *j, Scene *s)
{
    static const char *const keys[] = {"ambient", "diffuse",    "specular", "exponent",
                                       "k_local", "k_global",   "eta",      "extinction",
                                       "pattern", "dispersion", NULL};
    static const float grey[3] = {0.8f, 0.8f, 0.8f}, black[3] = {0, 0, 0};
    if (!j) return scene_fail(c, "materials", "missing (expected an object of named materials)");
    if (json_expect_object(c, j, "materials")) return -1;
    int n = cJSON_GetArraySize(j);
    if (n == 0) return scene_fail(c, "materials", "expected at least one material");
    if (n > 65535) return scene_fail(c, "materials", "%d materials: at most 65535", n);
    s->materials = calloc((size_t)n, sizeof *s->materials);
    if (!s->materials) return scene_fail(c, NULL, "out of memory");
    int i = 0;
    for (const cJSON *e = j->child; e; e = e->next, i++) {
        char p[PATH_MAX_LEN];
        json_path_key(p, "materials", e->string);
        for (const cJSON *o = j->child; o != e; o = o->next)
            if (strcmp(o->string, e->string) == 0)
                return scene_fail(c, p, "material defined twice");
        if (!e->string[0] || strlen(e->string) >= SCENE_NAME_MAX)
            return scene_fail(c, p, "a material name must have 1 to %d characters",
                              SCENE_NAME_MAX - 1);
        if (json_expect_object(c, e, p) || json_check_keys(c, e, p, keys)) return -1;
        SceneMaterial *m = &s->materials[i];
        VbMaterial *g = &m->gpu;
        snprintf(m->name, sizeof m->name, "%s", e->string);
        if (json_get_rgb(c, e, p, "diffuse", grey, g->diffuse) ||
            json_get_rgb(c, e, p, "ambient", g->diffuse, g->ambient) ||
            json_get_rgb(c, e, p, "specular", black, g->specular) ||
            json_get_float(c, e, p, "exponent", 0, 1e5, 32, 0, &g->exponent) ||
            json_get_float(c, e, p, "k_local", 0, 1, 1, 0, &g->k_local) ||
            json_get_float(c, e, p, "k_global", 0, 1, 0, 0, &g->k_global) ||
            json_get_float(c, e, p, "eta", 1e-3, 100, 1, 0, &g->eta))
            return -1;
        s->nmaterials = i + 1; /* from here on scene_free releases its pattern */
        g->pattern = -1;
        if (json_get_scalar_or_vec3(c, e, p, "extinction", 0, FLT_MAX, 0, g->extinction) ||
            load_pattern(c, e, p, s, &m->pattern) || load_dispersion(c, e, p, g->eta, &m->disp))
            return -1;
        for (int k = 0; k < 3; k++) g->extinction[k] /= s->frame_scale; /* per frame length */
        if (m->pattern.kind) g->pattern = 0;           /* has one; the renderer assigns the index */
        g->disp = m->disp.model != DISP_NONE ? 0 : -1; /* likewise its band table's offset */
    }
    s->nmaterials = n;
    return 0;
}

int scene_find_material(const Scene *s, const char *name)
{
    for (int i = 0; i < s->nmaterials; i++)
        if (strcmp(s->materials[i].name, name) == 0) return i;
    return -1;
}
