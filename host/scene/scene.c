/* scene.c — loads a JSON scene document (cJSON): reads the text, the image, camera,
 * render and lights keys, and runs the other parts' loaders (scene_parts.h) in order,
 * checking every value and naming the JSON path of anything wrong. */
#include "scene.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "diag.h"
#include "grid.h"
#include "scene_parts.h"

/* Whether path names standard input ("-" or "/dev/stdin"): read from the stream already
 * open, with mesh paths relative to the current directory. */
static int is_stdin(const char *path)
{
    return strcmp(path, "-") == 0 || strcmp(path, "/dev/stdin") == 0;
}

/* Reads f whole, at most SCENE_MAX_FILE_BYTES and no NUL byte (a pipe or device may never
 * end: /dev/zero stops at its first byte). */
static int read_stream(Ctx *c, FILE *f, char **out)
{
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap + 1);
    if (!buf) return scene_fail(c, NULL, "out of memory");
    size_t got;
    while ((got = fread(buf + len, 1, cap - len, f)) > 0) {
        if (memchr(buf + len, 0, got)) {
            free(buf);
            return scene_fail(c, NULL, "file contains a NUL byte: not a JSON text file");
        }
        len += got;
        if (len == cap) {
            if (cap >= SCENE_MAX_FILE_BYTES) {
                free(buf);
                return scene_fail(c, NULL, "file larger than 1 GiB");
            }
            char *nb = realloc(buf, cap * 2 + 1);
            if (!nb) {
                free(buf);
                return scene_fail(c, NULL, "out of memory");
            }
            buf = nb;
            cap *= 2;
        }
    }
    if (ferror(f)) {
        free(buf);
        return scene_fail(c, NULL, "read error: %s", strerror(errno));
    }
    buf[len] = 0;
    *out = buf;
    return 0;
}

int scene_read_text(const char *path, char **text, char *err, size_t errlen)
{
    Ctx c = {.file = scene_display_name(path), .err = err, .errlen = errlen, .frame = -1};
    *text = NULL;
    if (is_stdin(path)) return read_stream(&c, stdin, text) ? 2 : 0;
    FILE *f = fopen(path, "rb");
    if (!f) return scene_fail(&c, NULL, "cannot open: %s", strerror(errno)), 2;
    int rc = read_stream(&c, f, text);
    fclose(f);
    return rc ? 2 : 0;
}

const char *scene_display_name(const char *path)
{
    return strcmp(path, "-") == 0 ? "<stdin>" : path;
}

/* Parses "auto", "N" or "NX,NY,NZ" (1..max_axis each, at most GRID_MAX_CELLS in all) from
 * text up to end. Returns 0 and sets res (all 0 for auto), or -1. */
static int parse_resolution(const char *text, const char *end, int max_axis, int res[3])
{
    if ((size_t)(end - text) == 4 && strncmp(text, "auto", 4) == 0) {
        res[0] = res[1] = res[2] = 0;
        return 0;
    }
    long v[3];
    const char *p = text;
    int n = 0;
    while (n < 3) {
        char *stop;
        errno = 0;
        v[n] = strtol(p, &stop, 10);
        if (stop == p || stop > end || errno || v[n] < 1 || v[n] > max_axis) return -1;
        n++;
        if (stop == end) break;
        if (*stop != ',') return -1;
        p = stop + 1;
    }
    if (n == 1)
        v[1] = v[2] = v[0];
    else if (n != 3)
        return -1;
    if ((uint64_t)v[0] * (uint64_t)v[1] * (uint64_t)v[2] > GRID_MAX_CELLS) return -1;
    for (int i = 0; i < 3; i++) res[i] = (int)v[i];
    return 0;
}

int scene_parse_grid(const char *text, int res[3])
{
    return parse_resolution(text, text + strlen(text), GRID_MAX_AXIS, res);
}

int scene_parse_grid_levels(const char *text, int res[3], int sub[3])
{
    const char *colon = strchr(text, ':');
    if (!colon) return scene_parse_grid(text, res);
    int r[3];
    if (parse_resolution(text, colon, GRID_MAX_AXIS, r) ||
        parse_resolution(colon + 1, colon + 1 + strlen(colon + 1), GRID_SUB_MAX_AXIS, sub))
        return -1;
    memcpy(res, r, sizeof r);
    return 0;
}

static int load_image(Ctx *c, const cJSON *j, Scene *s)
{
    static const char *const keys[] = {"width",      "height",      "output", "exposure",
                                       "background", "environment", NULL};
    static const float black[3] = {0, 0, 0};
    if (json_expect_object(c, j, "image") || json_check_keys(c, j, "image", keys)) return -1;
    if (json_get_int(c, j, "image", "width", 1, SCENE_MAX_IMAGE, 400, 0, &s->width) ||
        json_get_int(c, j, "image", "height", 1, SCENE_MAX_IMAGE, 400, 0, &s->height) ||
        json_get_float(c, j, "image", "exposure", -30, 30, 0, 0, &s->exposure) ||
        json_get_rgb(c, j, "image", "background", black, s->background))
        return -1;
    const cJSON *o = cJSON_GetObjectItemCaseSensitive(j, "output");
    if (o) {
        if (!cJSON_IsString(o) || !o->valuestring[0])
            return scene_fail(c, "image.output", "expected a file name, got %s", json_type_name(o));
        if (!(s->output = scene_strdup(o->valuestring)))
            return scene_fail(c, NULL, "out of memory");
    }
    return scene_load_environment(c, j, s);
}

static int load_camera(Ctx *c, const cJSON *j, Scene *s)
{
    static const char *const keys[] = {"eye", "look_at", "up", "fov", NULL};
    static const float up[3] = {0, 1, 0};
    if (json_expect_object(c, j, "camera") || json_check_keys(c, j, "camera", keys)) return -1;
    if (json_get_vec3(c, j, "camera", "eye", NULL, &s->eye) ||
        json_get_vec3(c, j, "camera", "look_at", NULL, &s->look_at) ||
        json_get_vec3(c, j, "camera", "up", up, &s->up) ||
        json_get_float(c, j, "camera", "fov", 0.01, 179, 45, 0, &s->fov))
        return -1;
    vec3 fwd = v3_sub(s->look_at, s->eye);
    if (v3_len(fwd) <= 0.0f) return scene_fail(c, "camera.look_at", "must differ from camera.eye");
    if (v3_len(v3_cross(fwd, s->up)) <= 1e-6f * v3_len(fwd) * v3_len(s->up))
        return scene_fail(c, "camera.up", "must not be parallel to the viewing direction");
    double eye[3], look[3];
    json_numbers(cJSON_GetObjectItemCaseSensitive(j, "eye"), s->eye, eye);
    json_numbers(cJSON_GetObjectItemCaseSensitive(j, "look_at"), s->look_at, look);
    scene_frame_pick(s, eye, look);
    return 0;
}

void scene_frame_pick(Scene *s, const double eye[3], const double look_at[3])
{
    double d = 0.0, far = 0.0;
    for (int k = 0; k < 3; k++) {
        d += (look_at[k] - eye[k]) * (look_at[k] - eye[k]);
        far += look_at[k] * look_at[k];
    }
    d = sqrt(d);
    far = sqrt(far);
    s->frame_scale = 1.0f;
    if (d < SCENE_FRAME_MIN_VIEW || d > SCENE_FRAME_MAX_VIEW) /* 2^-64 .. 2^64: finite */
        s->frame_scale = (float)exp2(fmin(fmax(-round(log2(d)), -64.0), 64.0));
    double step = exp2(ceil(log2(d))); /* d > 0: look_at differs from eye */
    for (int k = 0; k < 3; k++)
        s->frame_origin[k] = far > SCENE_FRAME_FAR_VIEWS * d ? step * round(look_at[k] / step) : 0;
    s->eye = scene_frame_point(s, eye);
    s->look_at = scene_frame_point(s, look_at);
}

vec3 scene_frame_point(const Scene *s, const double p[3])
{
    double k = s->frame_scale;
    return v3((float)((p[0] - s->frame_origin[0]) * k), (float)((p[1] - s->frame_origin[1]) * k),
              (float)((p[2] - s->frame_origin[2]) * k));
}

int scene_frame_is_identity(const Scene *s)
{
    return s->frame_scale == 1.0f && s->frame_origin[0] == 0.0 && s->frame_origin[1] == 0.0 &&
           s->frame_origin[2] == 0.0;
}

int scene_get_point(Ctx *c, const cJSON *obj, const char *path, const char *key, const float *def,
                    const Scene *s, vec3 *out)
{
    vec3 v;
    if (json_get_vec3(c, obj, path, key, def, &v)) return -1;
    double d[3];
    json_numbers(cJSON_GetObjectItemCaseSensitive(obj, key), v, d);
    *out = scene_frame_point(s, d);
    return 0;
}

/* render.bands: 1..64, or "thesis" (the per-channel 1/2/3 scheme, DISP_THESIS_BANDS rays). */
static int get_bands(Ctx *c, const cJSON *j, Scene *s)
{
    const cJSON *b = cJSON_GetObjectItemCaseSensitive(j, "bands");
    if (cJSON_IsString(b)) {
        if (strcmp(b->valuestring, "thesis") != 0)
            return scene_fail(c, "render.bands",
                              "expected an integer 1..%d or \"thesis\", got \"%s\"", DISP_MAX_BANDS,
                              diag_value(b->valuestring));
        s->bands = DISP_THESIS_BANDS;
        s->band_layout = DISP_LAYOUT_THESIS;
        return 0;
    }
    return json_get_int(c, j, "render", "bands", 1, DISP_MAX_BANDS, 8, 0, &s->bands);
}

/* render.KEY: "auto" (res all 0), a number N or [nx, ny, nz] of 1 .. max_axis cells each,
 * at most GRID_MAX_CELLS in all. Absent: res untouched. Returns 0, or -1 after an error. */
static int get_resolution(Ctx *c, const cJSON *j, const char *key, int max_axis, int res[3])
{
    char path[32];
    snprintf(path, sizeof path, "render.%s", key);
    const cJSON *g = cJSON_GetObjectItemCaseSensitive(j, key);
    if (!g) return 0;
    if (cJSON_IsString(g)) {
        if (strcmp(g->valuestring, "auto") != 0)
            return scene_fail(c, path, "expected \"auto\", a number or [nx, ny, nz]");
        res[0] = res[1] = res[2] = 0;
    } else if (cJSON_IsNumber(g)) {
        int n;
        if (json_get_int(c, j, "render", key, 1, max_axis, 0, 1, &n)) return -1;
        res[0] = res[1] = res[2] = n;
    } else {
        float v[3];
        if (json_read_vec(c, g, path, 3, 1, max_axis, v)) return -1;
        for (int i = 0; i < 3; i++) {
            if (v[i] != floorf(v[i])) return scene_fail(c, path, "expected whole numbers of cells");
            res[i] = (int)v[i];
        }
    }
    uint64_t cells = (uint64_t)res[0] * res[1] * res[2];
    if (cells > GRID_MAX_CELLS)
        return scene_fail(c, path,
                          "%dx%dx%d is %llu cells, more than the limit of %u (2^27) in all: use "
                          "\"auto\" or fewer cells",
                          res[0], res[1], res[2], (unsigned long long)cells, GRID_MAX_CELLS);
    return 0;
}

/* render.<key>, when present: the string name0 (0) or name1 (1) into *v. */
static int get_choice(Ctx *c, const cJSON *j, const char *key, const char *name0, const char *name1,
                      int *v)
{
    const cJSON *b = cJSON_GetObjectItemCaseSensitive(j, key);
    if (!b) return 0;
    if (cJSON_IsString(b) && (!strcmp(b->valuestring, name0) || !strcmp(b->valuestring, name1))) {
        *v = strcmp(b->valuestring, name0) != 0;
        return 0;
    }
    char path[64];
    snprintf(path, sizeof path, "render.%s", key);
    return scene_fail(c, path, "expected \"%s\" or \"%s\"", name0, name1);
}

/* render.aa, render.aa_max_level, render.aa_min_level, render.aa_floor,
 * render.aa_level_gain, render.aa_reconstruct, render.aa_pairs: adaptive anti-aliasing. */
static int get_aa(Ctx *c, const cJSON *j, Scene *s)
{
    if (get_choice(c, j, "aa_reconstruct", "nearest", "leaves", &s->aa_reconstruct) ||
        get_choice(c, j, "aa_pairs", "first", "both", &s->aa_pairs) ||
        json_get_float(c, j, "render", "aa", 0, 1, 0, 0, &s->aa_threshold) ||
        json_get_int(c, j, "render", "aa_max_level", 1, VBCL_AA_MAX_LEVEL, VBCL_AA_MAX_LEVEL, 0,
                     &s->aa_max_level) ||
        json_get_int(c, j, "render", "aa_min_level", 0, VBCL_AA_MAX_LEVEL, 0, 0,
                     &s->aa_min_level) ||
        json_get_float(c, j, "render", "aa_floor", 0, 2, SCENE_AA_FLOOR, 0, &s->aa_floor) ||
        json_get_float(c, j, "render", "aa_level_gain", 1, 4, SCENE_AA_LEVEL_GAIN, 0,
                       &s->aa_level_gain))
        return -1;
    if (s->aa_min_level > s->aa_max_level)
        return scene_fail(c, "render.aa_min_level",
                          "expected at most render.aa_max_level (%d), got %d", s->aa_max_level,
                          s->aa_min_level);
    return 0;
}

/* render.<key>, when present: true or false into *v. */
static int get_bool(Ctx *c, const cJSON *j, const char *key, int *v)
{
    const cJSON *b = cJSON_GetObjectItemCaseSensitive(j, key);
    if (!b) return 0;
    if (!cJSON_IsBool(b)) {
        char path[64];
        snprintf(path, sizeof path, "render.%s", key);
        return scene_fail(c, path, "expected true or false, got %s", json_type_name(b));
    }
    *v = cJSON_IsTrue(b);
    return 0;
}

/* render.ambient's default. */
static const float render_ambient[3] = {0.1f, 0.1f, 0.1f};

/* render's defaults, every key absent. */
static void render_defaults(Scene *s)
{
    s->max_depth = 6;
    s->grid_density = 0.0f; /* the default of the grid's kind: grid_build_levels */
    s->subgrid_density = GRID_SUB_DEFAULT_DENSITY;
    s->shadow_samples = 16;
    memcpy(s->ambient, render_ambient, sizeof s->ambient);
    s->seed = 1;
    s->fresnel = SCENE_FRESNEL_EXACT;
    s->min_weight = 1e-3f;
    s->aa_threshold = 0.0f;
    s->aa_max_level = VBCL_AA_MAX_LEVEL;
    s->aa_min_level = 0;
    s->aa_floor = SCENE_AA_FLOOR;
    s->aa_level_gain = SCENE_AA_LEVEL_GAIN;
    s->aa_reconstruct = SCENE_AA_NEAREST;
    s->aa_pairs = SCENE_AA_PAIRS_FIRST;
    s->ssaa = 1;
    s->crop_margin = -1;
    s->bands = 8;
    s->band_layout = DISP_LAYOUT_UNIFORM;
    s->shadow_jitter = 1;
    s->shadow_cone_test = 1;
    s->camera_tiles = 1;
    s->shadow_by_weight = 1;
    s->sample_shares = 1;
    s->penumbra_feelers = SCENE_PENUMBRA_FEELERS;
}

static int load_render(Ctx *c, const cJSON *j, Scene *s)
{
    static const char *const keys[] = {"max_depth",
                                       "grid",
                                       "grid_density",
                                       "shadow_samples",
                                       "ambient",
                                       "seed",
                                       "fresnel",
                                       "min_weight",
                                       "aa",
                                       "aa_max_level",
                                       "aa_min_level",
                                       "aa_floor",
                                       "aa_level_gain",
                                       "aa_reconstruct",
                                       "aa_pairs",
                                       "bands",
                                       "shadow_jitter",
                                       "subgrid",
                                       "subgrid_density",
                                       "shadow_cone_test",
                                       "camera_tiles",
                                       "shadow_by_weight",
                                       "sample_shares",
                                       "penumbra_feelers",
                                       NULL};
    render_defaults(s);
    if (!j) return 0; /* absent: all defaults */
    if (json_expect_object(c, j, "render") || json_check_keys(c, j, "render", keys)) return -1;
    int seed;
    if (json_get_int(c, j, "render", "max_depth", 1, 64, 6, 0, &s->max_depth) ||
        json_get_float(c, j, "render", "grid_density", 0.01, 64, 0.0, 0, &s->grid_density) ||
        json_get_float(c, j, "render", "subgrid_density", 0.01, 64, GRID_SUB_DEFAULT_DENSITY, 0,
                       &s->subgrid_density) ||
        json_get_int(c, j, "render", "shadow_samples", 1, 1024, 16, 0, &s->shadow_samples) ||
        json_get_rgb(c, j, "render", "ambient", render_ambient, s->ambient) ||
        json_get_int(c, j, "render", "seed", 0, 0x7fffffff, 1, 0, &seed) ||
        json_get_float(c, j, "render", "min_weight", 0, 1, 1e-3, 0, &s->min_weight) ||
        json_get_int(c, j, "render", "penumbra_feelers", 1, SCENE_PENUMBRA_FEELERS_MAX,
                     SCENE_PENUMBRA_FEELERS, 0, &s->penumbra_feelers) ||
        get_aa(c, j, s) || get_bands(c, j, s))
        return -1;
    if (!scene_penumbra_feelers_ok(s->penumbra_feelers))
        return scene_fail(c, "render.penumbra_feelers",
                          "expected " SCENE_PENUMBRA_FEELERS_SET ", got %d", s->penumbra_feelers);
    s->seed = (unsigned)seed;
    if (get_bool(c, j, "shadow_jitter", &s->shadow_jitter) ||
        get_bool(c, j, "shadow_cone_test", &s->shadow_cone_test) ||
        get_bool(c, j, "camera_tiles", &s->camera_tiles) ||
        get_bool(c, j, "shadow_by_weight", &s->shadow_by_weight) ||
        get_bool(c, j, "sample_shares", &s->sample_shares) ||
        get_choice(c, j, "fresnel", "exact", "thesis", &s->fresnel)) /* SCENE_FRESNEL_* */
        return -1;
    if (get_resolution(c, j, "grid", GRID_MAX_AXIS, s->grid_res) ||
        get_resolution(c, j, "subgrid", GRID_SUB_MAX_AXIS, s->subgrid_res))
        return -1;
    return 0;
}

static int load_lights(Ctx *c, const cJSON *j, Scene *s)
{
    static const char *const keys[] = {"centre", "radius", "flux", "intensity", "colour", NULL};
    static const float white[3] = {1, 1, 1};
    if (!j) return 0;
    if (!cJSON_IsArray(j))
        return scene_fail(c, "lights", "expected an array, got %s", json_type_name(j));
    int n = cJSON_GetArraySize(j);
    if (n > 256) return scene_fail(c, "lights", "%d lights: at most 256", n);
    s->lights = calloc((size_t)(n ? n : 1), sizeof *s->lights);
    if (!s->lights) return scene_fail(c, NULL, "out of memory");
    int i = 0;
    for (const cJSON *e = j->child; e; e = e->next, i++) {
        char p[PATH_MAX_LEN];
        json_path_index(p, "lights", i);
        if (json_expect_object(c, e, p) || json_check_keys(c, e, p, keys)) return -1;
        vec3 centre;
        float radius, colour[3];
        double flux, intensity;
        if (scene_get_point(c, e, p, "centre", NULL, s, &centre) ||
            json_get_float(c, e, p, "radius", 0, FLT_MAX, 0, 0, &radius) ||
            json_get_num(c, e, p, "flux", DBL_MIN, FLT_MAX, -1, 0, &flux) ||
            json_get_num(c, e, p, "intensity", DBL_MIN, FLT_MAX, -1, 0, &intensity) ||
            json_get_rgb(c, e, p, "colour", white, colour))
            return -1;
        if ((flux < 0) == (intensity < 0))
            return scene_fail(c, p, "give exactly one of \"flux\" and \"intensity\"");
        /* intensity I = flux / 4 pi; a sphere of uniform radiance L has I = L pi r^2 */
        double I = intensity > 0 ? intensity : flux / (4.0 * M_PI);
        /* a point light's intensity falls off as 1 / d^2 in the frame's lengths: scaled by
         * the frame's scale squared, it lights a point as it does in the file's units */
        double fs = s->frame_scale;
        double scale = radius > 0 ? I / (M_PI * (double)radius * radius) : I * fs * fs;
        if (!isfinite(centre.x + centre.y + centre.z) || !isfinite(radius * s->frame_scale))
            return scene_fail(c, p, "the light lies beyond a float's range in the camera's frame");
        VbLight *l = &s->lights[i];
        l->centre[0] = centre.x; /* in the frame; the radiance stays, as (r / d)^2 does */
        l->centre[1] = centre.y;
        l->centre[2] = centre.z;
        l->radius = radius * s->frame_scale;
        for (int k = 0; k < 3; k++) l->radiance[k] = (float)(scale * colour[k]);
        if (!isfinite(l->radiance[0] + l->radiance[1] + l->radiance[2]))
            return scene_fail(c, p, "radiance overflows: the light is too bright for its size");
    }
    s->nlights = n;
    return 0;
}

int scene_load(const char *path, Scene *s, char *err, size_t errlen)
{
    return scene_load_frame(path, -1, s, err, errlen);
}

int scene_load_frame(const char *path, int frame, Scene *s, char *err, size_t errlen)
{
    char *text = NULL;
    memset(s, 0, sizeof *s);
    if (scene_read_text(path, &text, err, errlen)) return 2;
    int rc = scene_load_text(path, text, frame, s, err, errlen);
    free(text);
    return rc;
}

/* Everything inside the document root, for the frame scene_anim_apply has set. */
static int load_document(Ctx *c, const cJSON *root, Scene *s)
{
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
    if (!cam) return scene_fail(c, "camera", "missing (expected an object with eye and look_at)");
    const cJSON *img = cJSON_GetObjectItemCaseSensitive(root, "image");
    const cJSON *desc = cJSON_GetObjectItemCaseSensitive(root, "description");
    if (desc && !cJSON_IsString(desc))
        return scene_fail(c, "description", "expected a string, got %s", json_type_name(desc));
    if (img) {
        if (load_image(c, img, s)) return -1;
    } else {
        s->width = s->height = 400;
    }
    if (load_camera(c, cam, s) ||
        load_render(c, cJSON_GetObjectItemCaseSensitive(root, "render"), s) ||
        load_lights(c, cJSON_GetObjectItemCaseSensitive(root, "lights"), s) ||
        scene_load_materials(c, cJSON_GetObjectItemCaseSensitive(root, "materials"), s) ||
        scene_load_objects(c, cJSON_GetObjectItemCaseSensitive(root, "objects"), s))
        return -1;
    scene_default_band_layout(cJSON_GetObjectItemCaseSensitive(root, "render"), s);
    return 0;
}

int scene_load_text(const char *path, const char *text, int frame, Scene *s, char *err,
                    size_t errlen)
{
    static const char *const keys[] = {"description", "image",   "camera",    "render", "lights",
                                       "materials",   "objects", "animation", NULL};
    Ctx c = {.file = scene_display_name(path), .err = err, .errlen = errlen, .frame = frame};
    memset(s, 0, sizeof *s);
    mesh_init(&s->mesh);
    cJSON *root = NULL;
    if (!(s->path = scene_strdup(path)) || !(s->dir = scene_strdup(is_stdin(path) ? "" : path)))
        goto oom;
    char *slash = strrchr(s->dir, '/');
    if (slash)
        *(slash == s->dir ? slash + 1 : slash) = 0;
    else
        s->dir[0] = 0;
    if (scene_check_raw_text(&c, text) || scene_parse_json(&c, text, &root)) goto fail;
    if (json_expect_object(&c, root, "") || json_check_keys(&c, root, "", keys) ||
        scene_anim_apply(&c, root, frame, &s->frames))
        goto fail;
    if (frame >= s->frames) {
        c.frame = -1;
        scene_fail(&c, "animation.frames", "frame %d asked for, the scene has %d", frame,
                   s->frames);
        goto fail;
    }
    s->frame = frame < 0 ? 0 : frame;
    s->animated = c.animated;
    if (load_document(&c, root, s)) goto fail;
    cJSON_Delete(root);
    free(c.targets);
    return 0;
oom:
    diag_format(err, errlen, "%s: out of memory", c.file);
fail:
    cJSON_Delete(root);
    free(c.targets);
    scene_free(s);
    return 2;
}

void scene_free(Scene *s)
{
    free(s->path);
    free(s->dir);
    free(s->output);
    free(s->lights);
    free(s->env.file);
    free(s->env.texels);
    for (int i = 0; s->materials && i < s->nmaterials; i++) free(s->materials[i].pattern.image);
    free(s->materials);
    free(s->objects);
    free(s->tri_tag);
    mesh_free(&s->mesh);
    memset(s, 0, sizeof *s);
}
