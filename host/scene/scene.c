/* scene.c — loads a JSON scene (cJSON) and turns it into world-space triangles,
 * checking every value and naming the JSON path of anything wrong. */
#include "scene.h"

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cJSON.h>

#include "cache.h"
#include "diag.h"
#include "grid.h"

#define PATH_MAX_LEN 256

/* What a loader needs to report an error: the file and the message buffer. */
typedef struct Ctx {
    const char *file;
    char *err;
    size_t errlen;
    int animated; /* the document has an animation (anim_apply) */
    int frame;    /* the frame being loaded; -1: the scene as written */
    int ntargets; /* tracks whose target was resolved into targets[] (anim_apply) */
    char (*targets)[PATH_MAX_LEN]; /* per track: the JSON path it sets, "objects[1].eta" */
} Ctx;

static int fail(Ctx *c, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* "animation.tracks[2] at frame 5: " when a track sets path or a value inside it, else
 * "at frame 5: ": a value that is wrong in one frame of an animation. */
static void frame_prefix(const Ctx *c, const char *path, char *out, size_t n)
{
    for (int t = 0; path && t < c->ntargets; t++) {
        size_t k = strlen(c->targets[t]);
        if (k && strncmp(path, c->targets[t], k) == 0 && strchr(".[", path[k] ? path[k] : '.')) {
            snprintf(out, n, "animation.tracks[%d] at frame %d: ", t, c->frame);
            return;
        }
    }
    snprintf(out, n, "at frame %d: ", c->frame);
}

static int fail(Ctx *c, const char *path, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    diag_vformat(msg, sizeof msg, fmt, ap);
    va_end(ap);
    char where[PATH_MAX_LEN + 64] = "";
    if (c->frame >= 0 && c->animated) frame_prefix(c, path, where, sizeof where);
    if (path && *path)
        diag_format(c->err, c->errlen, "%s: %s%s: %s", c->file, where, path, msg);
    else
        diag_format(c->err, c->errlen, "%s: %s", c->file, msg);
    return -1;
}

static void path_key(char *out, const char *parent, const char *key)
{
    if (parent && *parent)
        snprintf(out, PATH_MAX_LEN, "%s.%s", parent, key);
    else
        snprintf(out, PATH_MAX_LEN, "%s", key);
}

static void path_index(char *out, const char *parent, int i)
{
    snprintf(out, PATH_MAX_LEN, "%s[%d]", parent, i);
}

static const char *json_type_name(const cJSON *j)
{
    if (cJSON_IsNumber(j)) return "a number";
    if (cJSON_IsString(j)) return "a string";
    if (cJSON_IsBool(j)) return "a boolean";
    if (cJSON_IsNull(j)) return "null";
    if (cJSON_IsArray(j)) return "an array";
    if (cJSON_IsObject(j)) return "an object";
    return "an unknown value";
}

/* Rejects keys not in allowed (NULL-terminated) and keys given twice. */
static int check_keys(Ctx *c, const cJSON *obj, const char *path, const char *const *allowed)
{
    for (const cJSON *k = obj->child; k; k = k->next) {
        int ok = 0;
        for (const char *const *a = allowed; *a; a++)
            if (strcmp(k->string, *a) == 0) ok = 1;
        char p[PATH_MAX_LEN];
        path_key(p, path, k->string);
        if (!ok) {
            char list[256] = "";
            for (const char *const *a = allowed; *a; a++) {
                if (a != allowed) strncat(list, ", ", sizeof list - strlen(list) - 1);
                strncat(list, *a, sizeof list - strlen(list) - 1);
            }
            return fail(c, p, "unknown key (expected one of: %s)", list);
        }
        for (const cJSON *o = obj->child; o != k; o = o->next)
            if (strcmp(o->string, k->string) == 0) return fail(c, p, "key given twice");
    }
    return 0;
}

/* The range [lo, hi] as a message shows it: "[1, 16384]", "> 0", ">= 0"; FLT_MIN or
 * DBL_MIN as lo means an open interval at 0, FLT_MAX or DBL_MAX as hi no upper limit. */
static const char *range_text(double lo, double hi, char *buf, size_t n)
{
    int open = lo == FLT_MIN || lo == DBL_MIN, unbounded = hi == FLT_MAX || hi == DBL_MAX;
    if (open && unbounded)
        snprintf(buf, n, "> 0");
    else if (open)
        snprintf(buf, n, "> 0 and <= %s", diag_num(hi));
    else if (unbounded)
        snprintf(buf, n, ">= %s", diag_num(lo));
    else
        snprintf(buf, n, "[%s, %s]", diag_num(lo), diag_num(hi));
    return buf;
}

/* The error for a number v outside [lo, hi] at path p. */
static int fail_range(Ctx *c, const char *p, double v, double lo, double hi)
{
    char r[96];
    range_text(lo, hi, r, sizeof r);
    return fail(c, p, "%s is out of range%s%s", diag_num(v), r[0] == '[' ? " " : ": expected ", r);
}

static int expect_object(Ctx *c, const cJSON *j, const char *path)
{
    if (!cJSON_IsObject(j)) return fail(c, path, "expected an object, got %s", json_type_name(j));
    return 0;
}

/* Reads obj[key] as a finite number in [lo, hi]; absent: def, or an error if required. */
static int get_num(Ctx *c, const cJSON *obj, const char *path, const char *key, double lo,
                   double hi, double def, int required, double *out)
{
    char p[PATH_MAX_LEN];
    path_key(p, path, key);
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!j) {
        if (required) return fail(c, p, "missing (expected a number)");
        *out = def;
        return 0;
    }
    if (!cJSON_IsNumber(j)) return fail(c, p, "expected a number, got %s", json_type_name(j));
    double v = j->valuedouble;
    if (!isfinite(v)) return fail(c, p, "expected a finite number");
    if (v < lo || v > hi) return fail_range(c, p, v, lo, hi);
    *out = v;
    return 0;
}

static int get_float(Ctx *c, const cJSON *obj, const char *path, const char *key, double lo,
                     double hi, double def, int required, float *out)
{
    double v;
    if (get_num(c, obj, path, key, lo, hi, def, required, &v)) return -1;
    *out = (float)v;
    return 0;
}

static int get_int(Ctx *c, const cJSON *obj, const char *path, const char *key, int lo, int hi,
                   int def, int required, int *out)
{
    double v;
    if (get_num(c, obj, path, key, lo, hi, def, required, &v)) return -1;
    if (v != floor(v)) {
        char p[PATH_MAX_LEN];
        path_key(p, path, key);
        return fail(c, p, "expected a whole number, got %g", v);
    }
    *out = (int)v;
    return 0;
}

/* Reads an array of n finite numbers in [lo, hi] at j. */
static int read_vec(Ctx *c, const cJSON *j, const char *p, int n, double lo, double hi, float *out)
{
    if (!cJSON_IsArray(j) || cJSON_GetArraySize(j) != n)
        return fail(c, p, "expected an array of %d numbers, got %s", n,
                    cJSON_IsArray(j) ? "an array of another length" : json_type_name(j));
    int i = 0;
    for (const cJSON *e = j->child; e; e = e->next, i++) {
        char pi[PATH_MAX_LEN];
        path_index(pi, p, i);
        if (!cJSON_IsNumber(e)) return fail(c, pi, "expected a number, got %s", json_type_name(e));
        if (!isfinite(e->valuedouble)) return fail(c, pi, "expected a finite number");
        if (e->valuedouble < lo || e->valuedouble > hi)
            return fail_range(c, pi, e->valuedouble, lo, hi);
        out[i] = (float)e->valuedouble;
    }
    return 0;
}

static int get_vec(Ctx *c, const cJSON *obj, const char *path, const char *key, int n, double lo,
                   double hi, const float *def, float *out)
{
    char p[PATH_MAX_LEN];
    path_key(p, path, key);
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!j) {
        if (!def) return fail(c, p, "missing (expected an array of %d numbers)", n);
        memcpy(out, def, sizeof(float) * (size_t)n);
        return 0;
    }
    return read_vec(c, j, p, n, lo, hi, out);
}

static int get_vec3(Ctx *c, const cJSON *obj, const char *path, const char *key, const float *def,
                    vec3 *out)
{
    float v[3];
    if (get_vec(c, obj, path, key, 3, -FLT_MAX, FLT_MAX, def, v)) return -1;
    *out = v3(v[0], v[1], v[2]);
    return 0;
}

/* A colour: [r, g, b], each >= 0. */
static int get_rgb(Ctx *c, const cJSON *obj, const char *path, const char *key, const float *def,
                   float *out)
{
    return get_vec(c, obj, path, key, 3, 0.0, FLT_MAX, def, out);
}

static char *dup_string(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

/* Converts the byte offset of a syntax error into line and column (1-based). */
static void text_position(const char *text, const char *at, int *line, int *col)
{
    *line = 1;
    *col = 1;
    for (const char *p = text; p < at && *p; p++) {
        if (*p == '\n') {
            (*line)++;
            *col = 1;
        } else {
            (*col)++;
        }
    }
}

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
    if (!buf) return fail(c, NULL, "out of memory");
    size_t got;
    while ((got = fread(buf + len, 1, cap - len, f)) > 0) {
        if (memchr(buf + len, 0, got)) {
            free(buf);
            return fail(c, NULL, "file contains a NUL byte: not a JSON text file");
        }
        len += got;
        if (len == cap) {
            if (cap >= SCENE_MAX_FILE_BYTES) {
                free(buf);
                return fail(c, NULL, "file larger than 1 GiB");
            }
            char *nb = realloc(buf, cap * 2 + 1);
            if (!nb) {
                free(buf);
                return fail(c, NULL, "out of memory");
            }
            buf = nb;
            cap *= 2;
        }
    }
    if (ferror(f)) {
        free(buf);
        return fail(c, NULL, "read error: %s", strerror(errno));
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
    if (!f) return fail(&c, NULL, "cannot open: %s", strerror(errno)), 2;
    int rc = read_stream(&c, f, text);
    fclose(f);
    return rc ? 2 : 0;
}

const char *scene_display_name(const char *path)
{
    return strcmp(path, "-") == 0 ? "<stdin>" : path;
}

int scene_parse_grid(const char *text, int res[3])
{
    if (strcmp(text, "auto") == 0) {
        res[0] = res[1] = res[2] = 0;
        return 0;
    }
    long v[3];
    const char *p = text;
    int n = 0;
    while (n < 3) {
        char *end;
        errno = 0;
        v[n] = strtol(p, &end, 10);
        if (end == p || errno || v[n] < 1 || v[n] > GRID_MAX_AXIS) return -1;
        n++;
        if (*end == 0) break;
        if (*end != ',') return -1;
        p = end + 1;
    }
    if (n == 1)
        v[1] = v[2] = v[0];
    else if (n != 3)
        return -1;
    if ((uint64_t)v[0] * (uint64_t)v[1] * (uint64_t)v[2] > GRID_MAX_CELLS) return -1;
    for (int i = 0; i < 3; i++) res[i] = (int)v[i];
    return 0;
}

static int load_image(Ctx *c, const cJSON *j, Scene *s)
{
    static const char *const keys[] = {"width", "height", "output", "exposure", "background", NULL};
    static const float black[3] = {0, 0, 0};
    if (expect_object(c, j, "image") || check_keys(c, j, "image", keys)) return -1;
    if (get_int(c, j, "image", "width", 1, SCENE_MAX_IMAGE, 400, 0, &s->width) ||
        get_int(c, j, "image", "height", 1, SCENE_MAX_IMAGE, 400, 0, &s->height) ||
        get_float(c, j, "image", "exposure", -30, 30, 0, 0, &s->exposure) ||
        get_rgb(c, j, "image", "background", black, s->background))
        return -1;
    const cJSON *o = cJSON_GetObjectItemCaseSensitive(j, "output");
    if (o) {
        if (!cJSON_IsString(o) || !o->valuestring[0])
            return fail(c, "image.output", "expected a file name, got %s", json_type_name(o));
        if (!(s->output = dup_string(o->valuestring))) return fail(c, NULL, "out of memory");
    }
    return 0;
}

static int load_camera(Ctx *c, const cJSON *j, Scene *s)
{
    static const char *const keys[] = {"eye", "look_at", "up", "fov", NULL};
    static const float up[3] = {0, 1, 0};
    if (expect_object(c, j, "camera") || check_keys(c, j, "camera", keys)) return -1;
    if (get_vec3(c, j, "camera", "eye", NULL, &s->eye) ||
        get_vec3(c, j, "camera", "look_at", NULL, &s->look_at) ||
        get_vec3(c, j, "camera", "up", up, &s->up) ||
        get_float(c, j, "camera", "fov", 0.01, 179, 45, 0, &s->fov))
        return -1;
    vec3 fwd = v3_sub(s->look_at, s->eye);
    if (v3_len(fwd) <= 0.0f) return fail(c, "camera.look_at", "must differ from camera.eye");
    if (v3_len(v3_cross(fwd, s->up)) <= 1e-6f * v3_len(fwd) * v3_len(s->up))
        return fail(c, "camera.up", "must not be parallel to the viewing direction");
    return 0;
}

/* render.bands: 1..64, or "thesis" (the per-channel 1/2/3 scheme, DISP_THESIS_BANDS rays). */
static int get_bands(Ctx *c, const cJSON *j, Scene *s)
{
    const cJSON *b = cJSON_GetObjectItemCaseSensitive(j, "bands");
    if (cJSON_IsString(b)) {
        if (strcmp(b->valuestring, "thesis") != 0)
            return fail(c, "render.bands", "expected an integer 1..%d or \"thesis\", got \"%s\"",
                        DISP_MAX_BANDS, diag_value(b->valuestring));
        s->bands = DISP_THESIS_BANDS;
        s->band_layout = DISP_LAYOUT_THESIS;
        return 0;
    }
    return get_int(c, j, "render", "bands", 1, DISP_MAX_BANDS, 8, 0, &s->bands);
}

static int load_render(Ctx *c, const cJSON *j, Scene *s)
{
    static const char *const keys[] = {
        "max_depth",  "grid", "grid_density", "shadow_samples", "ambient",       "seed", "fresnel",
        "min_weight", "aa",   "aa_max_level", "bands",          "shadow_jitter", NULL};
    static const float amb[3] = {0.1f, 0.1f, 0.1f};
    s->max_depth = 6;
    s->grid_density = GRID_DEFAULT_DENSITY;
    s->shadow_samples = 16;
    memcpy(s->ambient, amb, sizeof amb);
    s->seed = 1;
    s->fresnel = SCENE_FRESNEL_EXACT;
    s->min_weight = 1e-3f;
    s->aa_threshold = 0.0f;
    s->aa_max_level = VBCL_AA_MAX_LEVEL;
    s->ssaa = 1;
    s->bands = 8;
    s->band_layout = DISP_LAYOUT_UNIFORM;
    s->shadow_jitter = 1;
    if (!j) return 0; /* absent: all defaults */
    if (expect_object(c, j, "render") || check_keys(c, j, "render", keys)) return -1;
    int seed;
    if (get_int(c, j, "render", "max_depth", 1, 64, 6, 0, &s->max_depth) ||
        get_float(c, j, "render", "grid_density", 0.01, 64, GRID_DEFAULT_DENSITY, 0,
                  &s->grid_density) ||
        get_int(c, j, "render", "shadow_samples", 1, 1024, 16, 0, &s->shadow_samples) ||
        get_rgb(c, j, "render", "ambient", amb, s->ambient) ||
        get_int(c, j, "render", "seed", 0, 0x7fffffff, 1, 0, &seed) ||
        get_float(c, j, "render", "min_weight", 0, 1, 1e-3, 0, &s->min_weight) ||
        get_float(c, j, "render", "aa", 0, 1, 0, 0, &s->aa_threshold) ||
        get_int(c, j, "render", "aa_max_level", 1, VBCL_AA_MAX_LEVEL, VBCL_AA_MAX_LEVEL, 0,
                &s->aa_max_level) ||
        get_bands(c, j, s))
        return -1;
    s->seed = (unsigned)seed;
    const cJSON *jit = cJSON_GetObjectItemCaseSensitive(j, "shadow_jitter");
    if (jit) {
        if (!cJSON_IsBool(jit))
            return fail(c, "render.shadow_jitter", "expected true or false, got %s",
                        json_type_name(jit));
        s->shadow_jitter = cJSON_IsTrue(jit);
    }
    const cJSON *fr = cJSON_GetObjectItemCaseSensitive(j, "fresnel");
    if (fr) {
        if (cJSON_IsString(fr) && strcmp(fr->valuestring, "exact") == 0)
            s->fresnel = SCENE_FRESNEL_EXACT;
        else if (cJSON_IsString(fr) && strcmp(fr->valuestring, "thesis") == 0)
            s->fresnel = SCENE_FRESNEL_THESIS;
        else
            return fail(c, "render.fresnel", "expected \"exact\" or \"thesis\"");
    }
    const cJSON *g = cJSON_GetObjectItemCaseSensitive(j, "grid");
    if (g) {
        if (cJSON_IsString(g)) {
            if (strcmp(g->valuestring, "auto") != 0)
                return fail(c, "render.grid", "expected \"auto\", a number or [nx, ny, nz]");
        } else if (cJSON_IsNumber(g)) {
            int n;
            if (get_int(c, j, "render", "grid", 1, GRID_MAX_AXIS, 0, 1, &n)) return -1;
            s->grid_res[0] = s->grid_res[1] = s->grid_res[2] = n;
        } else {
            float v[3];
            if (read_vec(c, g, "render.grid", 3, 1, GRID_MAX_AXIS, v)) return -1;
            for (int i = 0; i < 3; i++) {
                if (v[i] != floorf(v[i]))
                    return fail(c, "render.grid", "expected whole numbers of cells");
                s->grid_res[i] = (int)v[i];
            }
        }
        uint64_t cells = (uint64_t)s->grid_res[0] * s->grid_res[1] * s->grid_res[2];
        if (cells > GRID_MAX_CELLS)
            return fail(c, "render.grid",
                        "%dx%dx%d is %llu cells, more than the limit of %u (2^27) in all: use "
                        "\"auto\" or fewer cells",
                        s->grid_res[0], s->grid_res[1], s->grid_res[2], (unsigned long long)cells,
                        GRID_MAX_CELLS);
    }
    return 0;
}

static int load_lights(Ctx *c, const cJSON *j, Scene *s)
{
    static const char *const keys[] = {"centre", "radius", "flux", "intensity", "colour", NULL};
    static const float white[3] = {1, 1, 1};
    if (!j) return 0;
    if (!cJSON_IsArray(j)) return fail(c, "lights", "expected an array, got %s", json_type_name(j));
    int n = cJSON_GetArraySize(j);
    if (n > 256) return fail(c, "lights", "%d lights: at most 256", n);
    s->lights = calloc((size_t)(n ? n : 1), sizeof *s->lights);
    if (!s->lights) return fail(c, NULL, "out of memory");
    int i = 0;
    for (const cJSON *e = j->child; e; e = e->next, i++) {
        char p[PATH_MAX_LEN];
        path_index(p, "lights", i);
        if (expect_object(c, e, p) || check_keys(c, e, p, keys)) return -1;
        vec3 centre;
        float radius, colour[3];
        double flux, intensity;
        if (get_vec3(c, e, p, "centre", NULL, &centre) ||
            get_float(c, e, p, "radius", 0, FLT_MAX, 0, 0, &radius) ||
            get_num(c, e, p, "flux", DBL_MIN, FLT_MAX, -1, 0, &flux) ||
            get_num(c, e, p, "intensity", DBL_MIN, FLT_MAX, -1, 0, &intensity) ||
            get_rgb(c, e, p, "colour", white, colour))
            return -1;
        if ((flux < 0) == (intensity < 0))
            return fail(c, p, "give exactly one of \"flux\" and \"intensity\"");
        /* intensity I = flux / 4 pi; a sphere of uniform radiance L has I = L pi r^2 */
        double I = intensity > 0 ? intensity : flux / (4.0 * M_PI);
        double scale = radius > 0 ? I / (M_PI * (double)radius * radius) : I;
        VbLight *l = &s->lights[i];
        l->centre[0] = centre.x;
        l->centre[1] = centre.y;
        l->centre[2] = centre.z;
        l->radius = radius;
        for (int k = 0; k < 3; k++) l->radiance[k] = (float)(scale * colour[k]);
        if (!isfinite(l->radiance[0] + l->radiance[1] + l->radiance[2]))
            return fail(c, p, "radiance overflows: the light is too bright for its size");
    }
    s->nlights = n;
    return 0;
}

static void join_path(char *out, size_t n, const char *dir, const char *file)
{
    if (file[0] == '/' || !dir || !dir[0])
        snprintf(out, n, "%s", file);
    else
        snprintf(out, n, "%s/%s", dir, file);
}

/* Reads obj[key] as a number (used for all three components) or as [x, y, z]. */
static int get_scalar_or_vec3(Ctx *c, const cJSON *obj, const char *path, const char *key,
                              double lo, double hi, float def, float out[3])
{
    const cJSON *x = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!x || cJSON_IsNumber(x)) {
        float a;
        if (get_float(c, obj, path, key, lo, hi, def, 0, &a)) return -1;
        out[0] = out[1] = out[2] = a;
        return 0;
    }
    const float d[3] = {def, def, def};
    return get_vec(c, obj, path, key, 3, lo, hi, d, out);
}

/* materials.NAME.pattern: a Fourier or projection surface pattern (thesis 2.2.2.3). */
static int load_pattern(Ctx *c, const cJSON *e, const char *path, const Scene *s, ScenePattern *pt)
{
    static const char *const keys[] = {"type",  "terms",  "contrast", "frequency", "seed",
                                       "image", "origin", "size",     NULL};
    static const float zero[3] = {0, 0, 0};
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(e, "pattern");
    if (!j) return 0;
    char p[PATH_MAX_LEN], q[PATH_MAX_LEN];
    path_key(p, path, "pattern");
    if (expect_object(c, j, p) || check_keys(c, j, p, keys)) return -1;
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(j, "type");
    path_key(q, p, "type");
    if (t && cJSON_IsString(t) && strcmp(t->valuestring, "fourier") == 0)
        pt->kind = VBCL_PATTERN_FOURIER;
    else if (t && cJSON_IsString(t) && strcmp(t->valuestring, "projection") == 0)
        pt->kind = VBCL_PATTERN_PROJECTION;
    else
        return fail(c, q, "expected \"fourier\" or \"projection\"");
    double seed;
    if (get_int(c, j, p, "terms", 4, 7, 5, 0, &pt->terms) ||
        get_float(c, j, p, "contrast", 0, 100, 1, 0, &pt->contrast) ||
        get_scalar_or_vec3(c, j, p, "frequency", 1e-6, 1e6, 1, pt->freq) ||
        get_num(c, j, p, "seed", 0, 9007199254740992.0, 1, 0, &seed) ||
        get_vec(c, j, p, "origin", 3, -FLT_MAX, FLT_MAX, zero, pt->origin) ||
        get_scalar_or_vec3(c, j, p, "size", FLT_MIN, FLT_MAX, 1, pt->size))
        return -1;
    pt->seed = (unsigned long long)seed;
    const cJSON *img = cJSON_GetObjectItemCaseSensitive(j, "image");
    path_key(q, p, "image");
    if (pt->kind == VBCL_PATTERN_PROJECTION) {
        if (!img || !cJSON_IsString(img) || !img->valuestring[0])
            return fail(c, q, "expected the image file to project");
        char full[4096];
        join_path(full, sizeof full, s->dir, img->valuestring);
        if (!(pt->image = dup_string(full))) return fail(c, NULL, "out of memory");
    } else if (img) {
        return fail(c, q, "only a projection pattern takes an image");
    }
    return 0;
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
    path_key(p, path, "dispersion");
    if (expect_object(c, j, p) || check_keys(c, j, p, keys)) return -1;
    const cJSON *model = cJSON_GetObjectItemCaseSensitive(j, "model");
    path_key(q, p, "model");
    if (!cJSON_IsString(model))
        return fail(c, q, "expected \"thesis\", \"cauchy\" or \"sellmeier\"");
    if (strcmp(model->valuestring, "thesis") == 0) {
        double spread;
        if (get_num(c, j, p, "spread", 0, 1, 0.03, 0, &spread)) return -1;
        disp_thesis_model(d, eta, spread);
    } else if (strcmp(model->valuestring, "cauchy") == 0) {
        double abbe;
        if (get_num(c, j, p, "abbe", 1, 200, 0, 1, &abbe)) return -1;
        disp_cauchy_from_abbe(d, eta, abbe);
    } else if (strcmp(model->valuestring, "sellmeier") == 0) {
        const cJSON *pre = cJSON_GetObjectItemCaseSensitive(j, "preset");
        path_key(q, p, "preset");
        if (pre) {
            if (!cJSON_IsString(pre) || disp_sellmeier_preset(d, pre->valuestring))
                return fail(c, q, "expected \"BK7\" or \"F2\"");
        } else {
            float b[3], cc[3];
            if (get_vec(c, j, p, "B", 3, 0, 100, NULL, b) ||
                get_vec(c, j, p, "C", 3, 0, 1e4, NULL, cc))
                return -1;
            d->model = DISP_SELLMEIER;
            for (int i = 0; i < 3; i++) {
                d->sb[i] = b[i];
                d->sc[i] = cc[i];
            }
        }
    } else {
        return fail(c, q, "expected \"thesis\", \"cauchy\" or \"sellmeier\", got \"%s\"",
                    diag_value(model->valuestring));
    }
    if (cJSON_GetObjectItemCaseSensitive(j, "band")) {
        float band[2], jump;
        if (get_vec(c, j, p, "band", 2, DISP_LAMBDA_MIN, DISP_LAMBDA_MAX, NULL, band) ||
            get_float(c, j, p, "jump", -10, 10, 0, 0, &jump))
            return -1;
        path_key(q, p, "band");
        if (!(band[1] > band[0])) return fail(c, q, "expected [lo, hi] with lo < hi");
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
        return fail(c, p,
                    "eta at %g nm is %s: it must be finite and > 0 at every wavelength "
                    "from %g to %g nm",
                    bad, v, DISP_LAMBDA_MIN, DISP_LAMBDA_MAX);
    }
    return 0;
}

/* Without render.bands, a scene whose dispersive materials all use the thesis model
 * renders with the thesis's per-channel rays. */
static void default_band_layout(const cJSON *render, Scene *s)
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

static int load_materials(Ctx *c, const cJSON *j, Scene *s)
{
    static const char *const keys[] = {"ambient", "diffuse",    "specular", "exponent",
                                       "k_local", "k_global",   "eta",      "extinction",
                                       "pattern", "dispersion", NULL};
    static const float grey[3] = {0.8f, 0.8f, 0.8f}, black[3] = {0, 0, 0};
    if (!j) return fail(c, "materials", "missing (expected an object of named materials)");
    if (expect_object(c, j, "materials")) return -1;
    int n = cJSON_GetArraySize(j);
    if (n == 0) return fail(c, "materials", "expected at least one material");
    if (n > 65535) return fail(c, "materials", "%d materials: at most 65535", n);
    s->materials = calloc((size_t)n, sizeof *s->materials);
    if (!s->materials) return fail(c, NULL, "out of memory");
    int i = 0;
    for (const cJSON *e = j->child; e; e = e->next, i++) {
        char p[PATH_MAX_LEN];
        path_key(p, "materials", e->string);
        for (const cJSON *o = j->child; o != e; o = o->next)
            if (strcmp(o->string, e->string) == 0) return fail(c, p, "material defined twice");
        if (!e->string[0] || strlen(e->string) >= SCENE_NAME_MAX)
            return fail(c, p, "a material name must have 1 to %d characters", SCENE_NAME_MAX - 1);
        if (expect_object(c, e, p) || check_keys(c, e, p, keys)) return -1;
        SceneMaterial *m = &s->materials[i];
        VbMaterial *g = &m->gpu;
        snprintf(m->name, sizeof m->name, "%s", e->string);
        if (get_rgb(c, e, p, "diffuse", grey, g->diffuse) ||
            get_rgb(c, e, p, "ambient", g->diffuse, g->ambient) ||
            get_rgb(c, e, p, "specular", black, g->specular) ||
            get_float(c, e, p, "exponent", 0, 1e5, 32, 0, &g->exponent) ||
            get_float(c, e, p, "k_local", 0, 1, 1, 0, &g->k_local) ||
            get_float(c, e, p, "k_global", 0, 1, 0, 0, &g->k_global) ||
            get_float(c, e, p, "eta", 1e-3, 100, 1, 0, &g->eta))
            return -1;
        s->nmaterials = i + 1; /* from here on scene_free releases its pattern */
        g->pattern = -1;
        if (get_scalar_or_vec3(c, e, p, "extinction", 0, FLT_MAX, 0, g->extinction) ||
            load_pattern(c, e, p, s, &m->pattern) || load_dispersion(c, e, p, g->eta, &m->disp))
            return -1;
        if (m->pattern.kind) g->pattern = 0;           /* has one; the renderer assigns the index */
        g->disp = m->disp.model != DISP_NONE ? 0 : -1; /* likewise its band table's offset */
    }
    s->nmaterials = n;
    return 0;
}

static int find_material(const Scene *s, const char *name)
{
    for (int i = 0; i < s->nmaterials; i++)
        if (strcmp(s->materials[i].name, name) == 0) return i;
    return -1;
}

/* Builds the object-to-world transform: scale, then rotate about x, y, z, then translate. */
static int load_transform(Ctx *c, const cJSON *obj, const char *path, mat4 *xf)
{
    static const char *const keys[] = {"translate", "rotate", "scale", NULL};
    static const float zero[3] = {0, 0, 0}, one[3] = {1, 1, 1};
    *xf = mat4_identity();
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(obj, "transform");
    if (!t) return 0;
    char p[PATH_MAX_LEN];
    path_key(p, path, "transform");
    if (expect_object(c, t, p) || check_keys(c, t, p, keys)) return -1;
    float tr[3], rot[3], sc[3];
    if (get_vec(c, t, p, "translate", 3, -FLT_MAX, FLT_MAX, zero, tr) ||
        get_vec(c, t, p, "rotate", 3, -1e6, 1e6, zero, rot))
        return -1;
    const cJSON *s = cJSON_GetObjectItemCaseSensitive(t, "scale");
    if (s && cJSON_IsNumber(s)) {
        float k;
        if (get_float(c, t, p, "scale", -FLT_MAX, FLT_MAX, 1, 1, &k)) return -1;
        sc[0] = sc[1] = sc[2] = k;
    } else if (get_vec(c, t, p, "scale", 3, -FLT_MAX, FLT_MAX, one, sc)) {
        return -1;
    }
    if (sc[0] == 0 || sc[1] == 0 || sc[2] == 0) {
        char ps[PATH_MAX_LEN];
        path_key(ps, p, "scale");
        return fail(c, ps, "a scale factor of 0 flattens the object");
    }
    mat4 m = mat4_scale(v3(sc[0], sc[1], sc[2]));
    for (int a = 0; a < 3; a++) m = mat4_mul(mat4_rotate_axis(a, rot[a]), m);
    *xf = mat4_mul(mat4_translate(v3(tr[0], tr[1], tr[2])), m);
    return 0;
}

/* objects[i] with "shape": "revolution": a profile swept about the y axis (its triangle
 * count was checked before any shape was built: count_triangles_first). */
static int load_revolution(Ctx *c, const cJSON *o, const char *p, Mesh *m)
{
    char q[PATH_MAX_LEN];
    static const char *const keys[] = {"shape",   "material", "name", "transform", "texture",
                                       "profile", "segments", "caps", NULL};
    int segments;
    if (check_keys(c, o, p, keys) || get_int(c, o, p, "segments", 3, 4096, 32, 0, &segments))
        return -1;
    const cJSON *caps = cJSON_GetObjectItemCaseSensitive(o, "caps");
    path_key(q, p, "caps");
    if (caps && !cJSON_IsBool(caps))
        return fail(c, q, "expected true or false, got %s", json_type_name(caps));
    path_key(q, p, "profile");
    const cJSON *pj = cJSON_GetObjectItemCaseSensitive(o, "profile");
    if (!pj) return fail(c, q, "missing (expected an array of [r, y] points)");
    int n = cJSON_IsArray(pj) ? cJSON_GetArraySize(pj) : 0;
    if (n < 2 || n > 100000) return fail(c, q, "expected an array of 2 to 100000 [r, y] points");
    float(*prof)[2] = malloc(sizeof(float[2]) * (size_t)n);
    if (!prof) return fail(c, NULL, "out of memory");
    int i = 0;
    for (const cJSON *e = pj->child; e; e = e->next, i++) {
        char qi[PATH_MAX_LEN];
        path_index(qi, q, i);
        if (read_vec(c, e, qi, 2, -FLT_MAX, FLT_MAX, prof[i])) {
            free(prof);
            return -1;
        }
        if (prof[i][0] < 0) {
            free(prof);
            return fail(c, qi, "the radius r must be >= 0");
        }
        if (i > 0 && prof[i][0] == prof[i - 1][0] && prof[i][1] == prof[i - 1][1]) {
            free(prof);
            return fail(c, qi, "repeats the previous point");
        }
    }
    int rc =
        shape_revolution(m, (const float(*)[2])prof, n, segments, caps ? cJSON_IsTrue(caps) : 1);
    free(prof);
    if (rc) return fail(c, p, "could not tessellate the shape (out of memory)");
    return 0;
}

/* Tessellates one object's shape into m (object space). */
static int load_shape(Ctx *c, const cJSON *o, const char *p, const char *shape, const Scene *s,
                      Mesh *m)
{
    char q[PATH_MAX_LEN];
    int rc = 0;
    if (strcmp(shape, "mesh") == 0) {
        static const char *const keys[] = {"shape",   "material", "name", "transform",
                                           "texture", "file",     NULL};
        if (check_keys(c, o, p, keys)) return -1;
        path_key(q, p, "file");
        const cJSON *f = cJSON_GetObjectItemCaseSensitive(o, "file");
        if (!f) return fail(c, q, "missing (expected a mesh file name)");
        if (!cJSON_IsString(f) || !f->valuestring[0])
            return fail(c, q, "expected a file name, got %s", json_type_name(f));
        char full[4096], merr[512];
        join_path(full, sizeof full, s->dir, f->valuestring);
        if (mesh_load(full, m, merr, sizeof merr)) return fail(c, q, "%s", merr);
        return 0;
    }
    if (strcmp(shape, "sphere") == 0) {
        static const char *const keys[] = {"shape",  "material", "name",  "transform", "texture",
                                           "radius", "centre",   "level", NULL};
        static const float zero[3] = {0, 0, 0};
        float radius, centre[3];
        int level;
        if (check_keys(c, o, p, keys) ||
            get_float(c, o, p, "radius", FLT_MIN, FLT_MAX, 1, 0, &radius) ||
            get_vec(c, o, p, "centre", 3, -FLT_MAX, FLT_MAX, zero, centre) ||
            get_int(c, o, p, "level", 0, 7, 3, 0, &level))
            return -1;
        rc = shape_sphere(m, level);
        if (!rc) {
            mat4 xf = mat4_mul(mat4_translate(v3(centre[0], centre[1], centre[2])),
                               mat4_scale(v3(radius, radius, radius)));
            mesh_transform(m, &xf);
        }
    } else if (strcmp(shape, "box") == 0) {
        static const char *const keys[] = {"shape",   "material", "name", "transform",
                                           "texture", "size",     NULL};
        static const float one[3] = {1, 1, 1};
        float size[3];
        if (check_keys(c, o, p, keys) || get_vec(c, o, p, "size", 3, FLT_MIN, FLT_MAX, one, size))
            return -1;
        rc = shape_box(m, v3(size[0], size[1], size[2]));
    } else if (strcmp(shape, "prism") == 0) {
        static const char *const keys[] = {"shape",   "material", "name",  "transform",
                                           "texture", "points",   "depth", NULL};
        float pts[3][2] = {{-0.5f, -0.288675f}, {0.5f, -0.288675f}, {0.0f, 0.577350f}};
        float depth;
        if (check_keys(c, o, p, keys) ||
            get_float(c, o, p, "depth", FLT_MIN, FLT_MAX, 1, 0, &depth))
            return -1;
        const cJSON *pj = cJSON_GetObjectItemCaseSensitive(o, "points");
        path_key(q, p, "points");
        if (pj) {
            if (!cJSON_IsArray(pj) || cJSON_GetArraySize(pj) != 3)
                return fail(c, q, "expected 3 points [x, y]");
            int i = 0;
            for (const cJSON *e = pj->child; e; e = e->next, i++) {
                char qi[PATH_MAX_LEN];
                path_index(qi, q, i);
                if (read_vec(c, e, qi, 2, -FLT_MAX, FLT_MAX, pts[i])) return -1;
            }
        }
        double area = (pts[1][0] - pts[0][0]) * (pts[2][1] - pts[0][1]) -
                      (pts[2][0] - pts[0][0]) * (pts[1][1] - pts[0][1]);
        if (area == 0) return fail(c, q, "the three points are on one line");
        rc = shape_prism(m, (const float(*)[2])pts, depth);
    } else if (strcmp(shape, "quad") == 0) {
        static const char *const keys[] = {"shape",   "material", "name", "transform",
                                           "texture", "size",     NULL};
        static const float one[2] = {1, 1};
        float size[2];
        if (check_keys(c, o, p, keys) || get_vec(c, o, p, "size", 2, FLT_MIN, FLT_MAX, one, size))
            return -1;
        rc = shape_quad(m, size[0], size[1]);
    } else if (strcmp(shape, "revolution") == 0) {
        return load_revolution(c, o, p, m);
    } else {
        path_key(q, p, "shape");
        return fail(c, q,
                    "unknown shape \"%s\" (expected mesh, sphere, box, prism, quad or revolution)",
                    diag_value(shape));
    }
    if (rc) return fail(c, p, "could not tessellate the shape (out of memory)");
    return 0;
}

/* Maps the texture block [lo, hi] onto the box [host_lo, host_hi] through the unit cube
 * centred at the origin, where the texture's own transform applies. */
static mat4 texture_mapping(const float block[6], vec3 host_lo, vec3 host_hi, const mat4 *xf)
{
    vec3 bc = v3((block[0] + block[3]) * 0.5f, (block[1] + block[4]) * 0.5f,
                 (block[2] + block[5]) * 0.5f);
    vec3 inv = v3(1.0f / (block[3] - block[0]), 1.0f / (block[4] - block[1]),
                  1.0f / (block[5] - block[2]));
    mat4 to_unit = mat4_mul(mat4_scale(inv), mat4_translate(v3_scale(bc, -1.0f)));
    vec3 hc = v3_scale(v3_add(host_lo, host_hi), 0.5f), he = v3_sub(host_hi, host_lo);
    mat4 to_host = mat4_mul(mat4_translate(hc), mat4_scale(he));
    return mat4_mul(to_host, mat4_mul(*xf, to_unit));
}

SceneTexgenFn scene_texgen;

/* Reads the texture block a vbcl texgen file declares in its header ("# block x0 y0 z0 x1
 * y1 z1" in OBJ, "comment block ..." in PLY), from the file's first bytes `head`.
 * Returns 1 when found and valid. */
static int read_block_comment(const char *head, float block[6])
{
    int found = 0;
    for (int n = 0; n < 64 && !found && *head; n++) {
        char line[512];
        size_t k = strcspn(head, "\n");
        snprintf(line, sizeof line, "%.*s", (int)(k < sizeof line ? k : sizeof line - 1), head);
        head += k + (head[k] == '\n');
        const char *l = line;
        if (*l == '#')
            l++;
        else if (strncmp(l, "comment", 7) == 0)
            l += 7;
        else if (strncmp(l, "ply", 3) != 0 && strncmp(l, "format", 6) != 0)
            break; /* past the header */
        while (*l == ' ') l++;
        if (strncmp(l, "block ", 6) != 0) continue;
        found = sscanf(l + 6, "%f %f %f %f %f %f", &block[0], &block[1], &block[2], &block[3],
                       &block[4], &block[5]) == 6;
        for (int i = 0; i < 3 && found; i++)
            found = isfinite(block[i]) && isfinite(block[i + 3]) && block[i + 3] > block[i];
    }
    return found;
}

/* Runs `vbcl texgen ARGS` for objects[i].texture.generate into the cache (or a temporary
 * file when the cache is off), unless the cache already holds it; writes its path. */
static int generate_texture(Ctx *c, const char *q, const char *args, char *path, size_t n,
                            int *temporary)
{
    char dir[4096], err[768];
    size_t w0 = strspn(args, " \t\n"), w1 = strcspn(args + w0, " \t\n");
    if ((w1 == 7 && !strncmp(args + w0, "fourier", 7)) ||
        (w1 == 7 && !strncmp(args + w0, "project", 7)))
        return fail(c, q,
                    "texgen %.7s makes an image, a surface pattern, not a volume texture: give the "
                    "material a \"pattern\" {\"type\": \"%s\"} (docs/scene-format.md)",
                    args + w0, args[w0] == 'f' ? "fourier" : "projection");
    if (!(w1 == 4 && !strncmp(args + w0, "bomb", 4)) &&
        !(w1 == 6 && !strncmp(args + w0, "deform", 6)))
        return fail(c, q,
                    "expected \"bomb ...\" or \"deform ...\" (the texgen methods that make "
                    "volume textures)");
    uint64_t h = cache_hash(CACHE_HASH_SEED, "vbcl texgen 1: ");
    h = cache_hash(h, args);
    *temporary = 0;
    if (cache_dir("textures", dir, sizeof dir)) {
        snprintf(path, n, "%s/%016llx.ply", dir, (unsigned long long)h);
    } else {
        snprintf(path, n, "/tmp/vbcl-texture-%ld-%016llx.ply", (long)getpid(),
                 (unsigned long long)h);
        *temporary = 1;
    }
    if (!*temporary && access(path, R_OK) == 0) return 0; /* generated before */
    char buf[1024], *argv[66];
    int argc = 0;
    if (strlen(args) >= sizeof buf - 1) return fail(c, q, "too long");
    snprintf(buf, sizeof buf, "%s", args);
    argv[argc++] = (char *)"texgen";
    for (char *tok = strtok(buf, " \t\n"); tok; tok = strtok(NULL, " \t\n")) {
        if (argc == 62) return fail(c, q, "too many arguments");
        if (!strcmp(tok, "-o") || !strcmp(tok, "--output"))
            return fail(c, q, "give the texgen arguments without -o: the scene chooses the file");
        argv[argc++] = tok;
    }
    argv[argc++] = (char *)"-o";
    argv[argc++] = path;
    argv[argc] = NULL;
    if (!scene_texgen) return fail(c, q, "this program cannot generate textures");
    int rc = scene_texgen(argc, argv, err, sizeof err);
    if (rc) return fail(c, q, "vbcl texgen %s", err);
    return 0;
}

/* Loads objects[i].texture into tex, in the object's own space (before its transform). */
static int load_texture(Ctx *c, const cJSON *t, const char *p, const Scene *s, vec3 host_lo,
                        vec3 host_hi, Mesh *tex, int *material)
{
    static const char *const keys[] = {"file", "generate", "material", "block", "transform", NULL};
    char q[PATH_MAX_LEN];
    if (expect_object(c, t, p) || check_keys(c, t, p, keys)) return -1;
    const cJSON *mat = cJSON_GetObjectItemCaseSensitive(t, "material");
    path_key(q, p, "material");
    if (!mat) return fail(c, q, "missing (expected the name of the texture's material)");
    if (!cJSON_IsString(mat)) return fail(c, q, "expected a string, got %s", json_type_name(mat));
    *material = find_material(s, mat->valuestring);
    if (*material < 0) return fail(c, q, "unknown material \"%s\"", diag_value(mat->valuestring));
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(t, "file");
    const cJSON *g = cJSON_GetObjectItemCaseSensitive(t, "generate");
    char full[4096], merr[512];
    const char *shown;
    int temporary = 0;
    if (f && g) return fail(c, p, "give \"file\" or \"generate\", not both");
    if (g) {
        path_key(q, p, "generate");
        if (!cJSON_IsString(g) || !g->valuestring[0])
            return fail(c, q, "expected the arguments of vbcl texgen, such as \"bomb --count 30\"");
        if (generate_texture(c, q, g->valuestring, full, sizeof full, &temporary)) return -1;
        shown = "the generated texture";
    } else {
        path_key(q, p, "file");
        if (!f)
            return fail(
                c, q, "missing (expected a mesh file of closed texture elements, or \"generate\")");
        if (!cJSON_IsString(f) || !f->valuestring[0])
            return fail(c, q, "expected a file name, got %s", json_type_name(f));
        join_path(full, sizeof full, s->dir, f->valuestring);
        shown = f->valuestring;
    }
    char head[8192];
    int bad = mesh_load_head(full, tex, head, sizeof head, merr, sizeof merr);
    float declared[6];
    int has_declared = !bad && read_block_comment(head, declared);
    if (temporary) remove(full);
    if (bad) return fail(c, q, "%s", merr);
    if (mesh_check_closed(tex, merr, sizeof merr))
        return fail(c, q, "%s: texture elements must be closed and consistently oriented: %s",
                    shown, merr);
    float block[6];
    const cJSON *bj = cJSON_GetObjectItemCaseSensitive(t, "block");
    path_key(q, p, "block");
    if (bj) {
        if (read_vec(c, bj, q, 6, -FLT_MAX, FLT_MAX, block)) return -1;
        for (int k = 0; k < 3; k++)
            if (!(block[k + 3] > block[k]))
                return fail(c, q,
                            "expected [x0, y0, z0, x1, y1, z1] with x1 > x0, y1 > y0, z1 > z0");
    } else if (has_declared) {
        memcpy(block, declared, sizeof declared);
    } else {
        vec3 lo, hi;
        mesh_bounds(tex, &lo, &hi);
        float b[6] = {lo.x, lo.y, lo.z, hi.x, hi.y, hi.z};
        for (int k = 0; k < 3; k++)
            if (!(b[k + 3] > b[k])) b[k + 3] = b[k] + 1.0f; /* flat texture: any thickness */
        memcpy(block, b, sizeof b);
    }
    mat4 xf;
    if (load_transform(c, t, p, &xf)) return -1;
    mat4 map = texture_mapping(block, host_lo, host_hi, &xf);
    if (mat4_det3(&map) == 0.0) return fail(c, p, "the texture mapping is degenerate");
    mesh_transform(tex, &map);
    return 0;
}

/* Appends m to the scene mesh with every triangle tagged tag. */
static int scene_append(Ctx *c, Scene *s, const Mesh *m, uint32_t tag)
{
    uint32_t first = s->mesh.ntris;
    if (mesh_append(&s->mesh, m)) return fail(c, NULL, "out of memory");
    uint32_t *tt = realloc(s->tri_tag, sizeof(uint32_t) * (s->mesh.ntris ? s->mesh.ntris : 1));
    if (!tt) return fail(c, NULL, "out of memory");
    s->tri_tag = tt;
    for (uint32_t t = first; t < s->mesh.ntris; t++) tt[t] = tag;
    return 0;
}

static int check_finite(Ctx *c, const Mesh *m, const char *p)
{
    for (uint32_t v = 0; v < m->nverts; v++)
        if (!isfinite(m->verts[v].x + m->verts[v].y + m->verts[v].z))
            return fail(c, p, "vertex %u is not finite after the transform", v);
    return 0;
}

static int load_object(Ctx *c, const cJSON *o, const char *p, int i, Scene *s)
{
    char q[PATH_MAX_LEN], merr[512];
    if (expect_object(c, o, p)) return -1;
    SceneObject *ob = &s->objects[i];
    ob->tex_slot = -1;
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(o, "name");
    path_key(q, p, "name");
    if (name && (!cJSON_IsString(name) || strlen(name->valuestring) >= SCENE_NAME_MAX))
        return fail(c, q, "expected a string of at most %d characters", SCENE_NAME_MAX - 1);
    snprintf(ob->name, sizeof ob->name, "%s", name ? name->valuestring : p);
    for (int k = 0; name && k < i; k++) /* an animation track finds objects by name */
        if (s->objects[k].named && strcmp(s->objects[k].name, ob->name) == 0)
            return fail(c, q, "\"%s\" is already used by objects[%d]", diag_value(ob->name), k);
    ob->named = name != NULL;
    const cJSON *shape = cJSON_GetObjectItemCaseSensitive(o, "shape");
    path_key(q, p, "shape");
    if (!shape)
        return fail(c, q, "missing (expected mesh, sphere, box, prism, quad or revolution)");
    if (!cJSON_IsString(shape))
        return fail(c, q, "expected a string, got %s", json_type_name(shape));
    const cJSON *mat = cJSON_GetObjectItemCaseSensitive(o, "material");
    path_key(q, p, "material");
    if (!mat) return fail(c, q, "missing (expected the name of a material)");
    if (!cJSON_IsString(mat)) return fail(c, q, "expected a string, got %s", json_type_name(mat));
    ob->material = find_material(s, mat->valuestring);
    if (ob->material < 0)
        return fail(c, q, "unknown material \"%s\"", diag_value(mat->valuestring));

    Mesh m, tex;
    mesh_init(&m);
    mesh_init(&tex);
    mat4 xf;
    int rc = -1;
    if (load_shape(c, o, p, shape->valuestring, s, &m) || load_transform(c, o, p, &xf)) goto done;
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(o, "texture");
    if (t) {
        path_key(q, p, "texture");
        if (s->ntextured == VBCL_MAX_TEXTURED) {
            fail(c, q, "at most %d objects per scene may carry a volume texture",
                 VBCL_MAX_TEXTURED);
            goto done;
        }
        vec3 lo, hi;
        mesh_bounds(&m, &lo, &hi);
        if (load_texture(c, t, q, s, lo, hi, &tex, &ob->tex_material)) goto done;
        ob->tex_slot = s->ntextured++;
    }
    ob->is_host = t != NULL || s->materials[ob->material].gpu.k_global > 0.0f;
    if (ob->is_host && mesh_check_closed(&m, merr, sizeof merr)) {
        fail(c, p, "%s object must be a closed, consistently oriented mesh: %s",
             t ? "a textured" : "a transparent (k_global > 0)", merr);
        goto done;
    }
    mesh_transform(&m, &xf);
    mesh_transform(&tex, &xf);
    if (check_finite(c, &m, p) || check_finite(c, &tex, p)) goto done;
    if ((uint64_t)s->mesh.ntris + m.ntris + tex.ntris > SCENE_MAX_TRIANGLES) {
        fail(c, p, "the scene has more than %u triangles", SCENE_MAX_TRIANGLES);
        goto done;
    }
    ob->first_tri = s->mesh.ntris;
    ob->ntris = m.ntris;
    if (scene_append(c, s, &m, (uint32_t)i | (ob->is_host ? 0u : VBCL_TAG_OPAQUE))) goto done;
    ob->first_tex_tri = s->mesh.ntris;
    ob->ntex_tris = tex.ntris;
    if (scene_append(c, s, &tex, (uint32_t)i | VBCL_TAG_TEXTURE)) goto done;
    rc = 0;
done:
    mesh_free(&m);
    mesh_free(&tex);
    return rc;
}

/* The triangles objects[i] will have, from its parameters alone (a mesh file's are known
 * only when read: 0 here), described in what; parameters that are wrong count 0 (the
 * object's own checks report them). */
static uint64_t shape_triangles(const cJSON *o, char *what, size_t n)
{
    const cJSON *shape = cJSON_GetObjectItemCaseSensitive(o, "shape");
    const char *sh = cJSON_IsString(shape) ? shape->valuestring : "";
    const cJSON *lv = cJSON_GetObjectItemCaseSensitive(o, "level");
    const cJSON *sg = cJSON_GetObjectItemCaseSensitive(o, "segments");
    const cJSON *pr = cJSON_GetObjectItemCaseSensitive(o, "profile");
    if (strcmp(sh, "sphere") == 0) {
        double level = lv ? (cJSON_IsNumber(lv) ? lv->valuedouble : -1) : 3;
        if (!(level >= 0 && level <= 7 && level == floor(level))) return 0;
        snprintf(what, n, "a sphere of level %d has", (int)level);
        return 20ull << (2 * (int)level);
    }
    if (strcmp(sh, "revolution") == 0) {
        double seg = sg ? (cJSON_IsNumber(sg) ? sg->valuedouble : -1) : 32;
        int points = cJSON_IsArray(pr) ? cJSON_GetArraySize(pr) : 0;
        if (!(seg >= 3 && seg <= 4096) || points < 2 || points > 100000) return 0;
        snprintf(what, n, "%d profile points x %d segments make up to", points, (int)seg);
        /* two triangles per segment per step and per cap ring */
        return 2ull * (uint64_t)seg * (uint64_t)(points + 1);
    }
    snprintf(what, n, "the shape has");
    return strcmp(sh, "box") == 0     ? 12
           : strcmp(sh, "prism") == 0 ? 8
           : strcmp(sh, "quad") == 0  ? 2
                                      : 0;
}

/* Refuses a scene whose shapes make more than SCENE_MAX_TRIANGLES before any is built. */
static int count_triangles_first(Ctx *c, const cJSON *j)
{
    uint64_t total = 0;
    int i = 0;
    for (const cJSON *o = j->child; o; o = o->next, i++) {
        char what[128], p[PATH_MAX_LEN];
        uint64_t n = shape_triangles(o, what, sizeof what);
        total += n;
        if (total <= SCENE_MAX_TRIANGLES) continue;
        path_index(p, "objects", i);
        return fail(c, p,
                    "%s %llu triangles, %llu with the objects before it, and a scene may have at "
                    "most %u: use fewer segments, profile points or a lower level",
                    what, (unsigned long long)n, (unsigned long long)total, SCENE_MAX_TRIANGLES);
    }
    return 0;
}

static int check_hosts_disjoint(Ctx *c, const Scene *s);

static int load_objects(Ctx *c, const cJSON *j, Scene *s)
{
    if (!j) return fail(c, "objects", "missing (expected an array of objects)");
    if (!cJSON_IsArray(j))
        return fail(c, "objects", "expected an array, got %s", json_type_name(j));
    int n = cJSON_GetArraySize(j);
    if (n == 0) return fail(c, "objects", "the scene is empty: expected at least one object");
    if (n > 0x7fffffff / 2) return fail(c, "objects", "too many objects");
    if (count_triangles_first(c, j)) return -1;
    s->objects = calloc((size_t)n, sizeof *s->objects);
    if (!s->objects) return fail(c, NULL, "out of memory");
    int i = 0;
    for (const cJSON *o = j->child; o; o = o->next, i++) {
        char p[PATH_MAX_LEN];
        path_index(p, "objects", i);
        if (load_object(c, o, p, i, s)) return -1;
        s->nobjects = i + 1;
    }
    if (s->mesh.ntris == 0) return fail(c, "objects", "no triangles to render");
    return check_hosts_disjoint(c, s);
}

/* Signed crossings of the ray p + t*d (t > 0) with triangles [first, first+n) of the
 * scene: +1 leaving through an outward face, -1 entering. Double precision. */
static int signed_crossings(const Scene *s, uint32_t first, uint32_t n, const double p[3],
                            const double d[3])
{
    int count = 0;
    for (uint32_t t = first; t < first + n; t++) {
        double v[3][3];
        for (int k = 0; k < 3; k++) {
            vec3 q = s->mesh.verts[s->mesh.tris[3 * t + k]];
            v[k][0] = q.x, v[k][1] = q.y, v[k][2] = q.z;
        }
        double e1[3], e2[3], pv[3], tv[3], qv[3];
        for (int k = 0; k < 3; k++) e1[k] = v[1][k] - v[0][k], e2[k] = v[2][k] - v[0][k];
        pv[0] = d[1] * e2[2] - d[2] * e2[1];
        pv[1] = d[2] * e2[0] - d[0] * e2[2];
        pv[2] = d[0] * e2[1] - d[1] * e2[0];
        double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
        if (det == 0.0) continue;
        for (int k = 0; k < 3; k++) tv[k] = p[k] - v[0][k];
        double u = (tv[0] * pv[0] + tv[1] * pv[1] + tv[2] * pv[2]) / det;
        if (u < 0.0 || u > 1.0) continue;
        qv[0] = tv[1] * e1[2] - tv[2] * e1[1];
        qv[1] = tv[2] * e1[0] - tv[0] * e1[2];
        qv[2] = tv[0] * e1[1] - tv[1] * e1[0];
        double w = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) / det;
        if (w < 0.0 || u + w > 1.0) continue;
        double tt = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) / det;
        if (tt <= 0.0) continue;
        /* the winding's normal e1 x e2 is outward: det < 0 means d points along it */
        count += det < 0.0 ? 1 : -1;
    }
    return count;
}

/* Whether object a has a vertex inside object b (both closed): a host nested in another. */
static int vertex_inside(const Scene *s, const SceneObject *a, const SceneObject *b)
{
    static const double d[3] = {0.5773502691896258 + 0.0131, 0.5773502691896258 - 0.0217,
                                0.5773502691896258 + 0.0071};
    vec3 v = s->mesh.verts[s->mesh.tris[3 * a->first_tri]];
    const double p[3] = {v.x, v.y, v.z};
    return signed_crossings(s, b->first_tri, b->ntris, p, d) > 0;
}

static void object_bounds(const Scene *s, const SceneObject *o, vec3 *lo, vec3 *hi)
{
    *lo = v3(FLT_MAX, FLT_MAX, FLT_MAX);
    *hi = v3(-FLT_MAX, -FLT_MAX, -FLT_MAX);
    for (uint32_t t = o->first_tri; t < o->first_tri + o->ntris; t++)
        for (int k = 0; k < 3; k++) {
            vec3 p = s->mesh.verts[s->mesh.tris[3 * t + k]];
            *lo = v3_min(*lo, p);
            *hi = v3_max(*hi, p);
        }
}

/* Hosts (dielectric or textured objects) must not overlap: the medium the kernels track is
 * one host at a time. Refused: surfaces that meet or touch (mesh_parts_meet, the exact test
 * texgen uses for its elements) and one host inside another. Only hosts whose bounding box
 * overlaps another host's are tested. */
static int check_hosts_disjoint(Ctx *c, const Scene *s)
{
    int nh = 0, np = 0, *idx = malloc(sizeof(int) * 2 * (size_t)s->nobjects);
    MeshPart *parts = malloc(sizeof *parts * (size_t)s->nobjects);
    vec3 *box = malloc(sizeof *box * 2 * (size_t)s->nobjects);
    int rc = (!idx || !parts || !box) ? fail(c, NULL, "out of memory") : 0;
    int *pobj = idx ? idx + s->nobjects : NULL; /* per part: its object */
    for (int i = 0; !rc && i < s->nobjects; i++)
        if (s->objects[i].is_host) {
            object_bounds(s, &s->objects[i], &box[2 * nh], &box[2 * nh + 1]);
            idx[nh++] = i;
        }
    for (int i = 0; !rc && i < nh; i++) {
        int near = 0;
        for (int j = 0; !rc && j < nh; j++) {
            vec3 l0 = box[2 * i], h0 = box[2 * i + 1], l1 = box[2 * j], h1 = box[2 * j + 1];
            if (j == i || l0.x > h1.x || l1.x > h0.x || l0.y > h1.y || l1.y > h0.y || l0.z > h1.z ||
                l1.z > h0.z)
                continue;
            near = 1;
            const SceneObject *oi = &s->objects[idx[i]], *oj = &s->objects[idx[j]];
            if (vertex_inside(s, oi, oj))
                rc = fail(c, "objects",
                          "%s is inside %s: dielectric and textured objects must not overlap "
                          "(docs/scene-format.md)",
                          diag_value(oi->name), diag_value(oj->name));
        }
        if (near) {
            const SceneObject *o = &s->objects[idx[i]];
            pobj[np] = idx[i];
            parts[np++] = (MeshPart){&s->mesh, o->first_tri, o->ntris};
        }
    }
    int pa, pb;
    uint32_t ta, tb;
    int meet = rc || np < 2 ? 0 : mesh_parts_meet(parts, np, &pa, &pb, &ta, &tb);
    if (meet < 0) rc = fail(c, NULL, "out of memory");
    if (meet > 0)
        rc = fail(c, "objects",
                  "%s and %s overlap (triangle %u of one meets triangle %u of the other): "
                  "dielectric and textured objects must not overlap or touch "
                  "(docs/scene-format.md)",
                  diag_value(s->objects[pobj[pa]].name), diag_value(s->objects[pobj[pb]].name), ta,
                  tb);
    free(idx);
    free(parts);
    free(box);
    return rc;
}

void scene_medium_at(const Scene *s, vec3 p, VbMedium *m)
{
    /* a direction unlikely to graze edges of axis-aligned or symmetric meshes */
    const double d[3] = {0.5773502691896258 + 0.0131, 0.5773502691896258 - 0.0217,
                         0.5773502691896258 + 0.0071};
    const double q[3] = {p.x, p.y, p.z};
    m->host = -1;
    m->tex_counts = 0;
    for (int i = 0; i < s->nobjects; i++) {
        const SceneObject *o = &s->objects[i];
        if (o->is_host && m->host < 0 && signed_crossings(s, o->first_tri, o->ntris, q, d) > 0)
            m->host = i;
        if (o->tex_slot >= 0) {
            int k = signed_crossings(s, o->first_tex_tri, o->ntex_tris, q, d);
            k = k < 0 ? 0 : k > 255 ? 255 : k;
            m->tex_counts |= (unsigned)k << (8 * o->tex_slot);
        }
    }
}

/* ---- animation: tracks that set numbers of the scene document per frame ---- */

/* The value a track's key holds: a number, or an array of up to 16 numbers. */
typedef struct AnimValue {
    int n; /* 0: a number; else the array's length */
    double v[16];
} AnimValue;

static int anim_value(Ctx *c, const cJSON *j, const char *path, AnimValue *out)
{
    if (cJSON_IsNumber(j)) {
        out->n = 0;
        out->v[0] = j->valuedouble;
        return 0;
    }
    int n = cJSON_IsArray(j) ? cJSON_GetArraySize(j) : 0;
    if (n < 1 || n > 16)
        return fail(c, path, "expected a number or an array of 1 to 16 numbers, got %s",
                    json_type_name(j));
    out->n = n;
    for (int i = 0; i < n; i++) {
        const cJSON *e = cJSON_GetArrayItem(j, i);
        if (!cJSON_IsNumber(e)) return fail(c, path, "element %d is not a number", i);
        out->v[i] = e->valuedouble;
    }
    return 0;
}

/* A track's target path: 1 to PATH_MAX_LEN - 1 characters, no empty component
 * ("camera..fov" is not "camera.fov"). */
static int check_target(Ctx *c, const char *target, const char *path)
{
    if (strlen(target) >= PATH_MAX_LEN || !*target)
        return fail(c, path, "expected a path such as \"materials.NAME.eta\"");
    if (target[0] == '.' || target[strlen(target) - 1] == '.' || strstr(target, ".."))
        return fail(c, path, "\"%s\": an empty component (expected names between the dots)",
                    diag_value(target));
    return 0;
}

/* Sets the member a track's target names, "materials.glass.eta" or "objects.ball.transform.
 * rotate", to val (taken over; NULL only checks the path): object members by key, array
 * elements by index or by their "name". A missing last member is created (a setting left at
 * its default), and so are missing objects on the way inside an element of an array (an
 * object's transform); anything else must exist. */
static int anim_set(Ctx *c, cJSON *root, const char *target, const char *path, cJSON *val,
                    char *canon)
{
    char buf[PATH_MAX_LEN];
    canon[0] = 0;
    if (check_target(c, target, path)) {
        cJSON_Delete(val);
        return -1;
    }
    strcpy(buf, target);
    cJSON *node = root;
    char *save = NULL;
    int in_element = 0; /* below an element of an array (an object, a light) */
    for (char *seg = strtok_r(buf, ".", &save); seg; seg = strtok_r(NULL, ".", &save)) {
        int last = *save == 0;
        if (node == root && (strcmp(seg, "animation") == 0 || last)) {
            cJSON_Delete(val);
            return fail(c, path,
                        "\"%s\": expected a value inside image, camera, render, lights, "
                        "materials or objects",
                        diag_value(target));
        }
        int index = -1;
        cJSON *next = NULL;
        if (cJSON_IsArray(node)) {
            char *end;
            long i = strtol(seg, &end, 10);
            int n = cJSON_GetArraySize(node);
            if (*end == 0 && end != seg && i >= 0 && i < n) index = (int)i;
            for (int k = 0; index < 0 && k < n; k++) {
                const cJSON *nm =
                    cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(node, k), "name");
                if (cJSON_IsString(nm) && strcmp(nm->valuestring, seg) == 0) index = k;
            }
            if (index < 0) {
                cJSON_Delete(val);
                return fail(c, path, "\"%s\": no element \"%s\" (an index or a name)",
                            diag_value(target), diag_value(seg));
            }
            next = cJSON_GetArrayItem(node, index);
            in_element = 1;
            size_t k = strlen(canon);
            snprintf(canon + k, PATH_MAX_LEN - k, "[%d]", index);
        } else if (cJSON_IsObject(node)) {
            next = cJSON_GetObjectItemCaseSensitive(node, seg);
            size_t k = strlen(canon);
            snprintf(canon + k, PATH_MAX_LEN - k, "%s%s", k ? "." : "", seg);
            if (!next && node == root) {
                cJSON_Delete(val);
                return fail(c, path, "\"%s\": no member \"%s\"", diag_value(target),
                            diag_value(seg));
            }
        } else {
            cJSON_Delete(val);
            return fail(c, path, "\"%s\": \"%s\" is inside a %s, not an object or array",
                        diag_value(target), diag_value(seg), json_type_name(node));
        }
        if (last) {
            if (next && !cJSON_IsNumber(next) && !cJSON_IsArray(next)) {
                cJSON_Delete(val);
                return fail(c, path, "\"%s\" is a %s: only numbers and arrays of numbers animate",
                            diag_value(target), json_type_name(next));
            }
            if (!val) return 0;
            cJSON_bool ok = index >= 0 ? cJSON_ReplaceItemInArray(node, index, val)
                            : next     ? cJSON_ReplaceItemInObjectCaseSensitive(node, seg, val)
                                       : cJSON_AddItemToObject(node, seg, val);
            if (!ok) {
                cJSON_Delete(val);
                return fail(c, NULL, "out of memory");
            }
            return 0;
        }
        if (!next && !in_element) {
            cJSON_Delete(val);
            return fail(c, path, "\"%s\": no member \"%s\"", diag_value(target), diag_value(seg));
        }
        if (!next) {            /* a missing object on the way, inside an element (its transform) */
            if (!val) return 0; /* checking only: it would be created */
            next = cJSON_CreateObject();
            if (!next || !cJSON_AddItemToObject(node, seg, next)) {
                cJSON_Delete(next);
                cJSON_Delete(val);
                return fail(c, NULL, "out of memory");
            }
        }
        node = next;
    }
    cJSON_Delete(val);
    return fail(c, path, "expected a path such as \"materials.NAME.eta\"");
}

/* Applies root.animation for frame `frame`, linearly between the keys around it and holding
 * the first and last keys beyond them (-1: checks the tracks, changes nothing), and returns
 * the frame count in *frames (1 without an animation). */
static int anim_apply(Ctx *c, cJSON *root, int frame, int *frames)
{
    static const char *const keys[] = {"frames", "tracks", NULL};
    static const char *const tkeys[] = {"target", "keys", NULL};
    *frames = 1;
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(root, "animation");
    if (!a) return 0;
    if (expect_object(c, a, "animation") || check_keys(c, a, "animation", keys)) return -1;
    const cJSON *fr = cJSON_GetObjectItemCaseSensitive(a, "frames");
    if (!cJSON_IsNumber(fr) || fr->valuedouble != floor(fr->valuedouble) || fr->valuedouble < 1 ||
        fr->valuedouble > 100000)
        return fail(c, "animation.frames", "expected an integer 1 .. 100000");
    *frames = (int)fr->valuedouble;
    c->animated = 1;
    const cJSON *tracks = cJSON_GetObjectItemCaseSensitive(a, "tracks");
    if (!cJSON_IsArray(tracks) || cJSON_GetArraySize(tracks) < 1)
        return fail(c, "animation.tracks", "expected an array of {\"target\", \"keys\"}");
    c->targets = calloc((size_t)cJSON_GetArraySize(tracks), sizeof *c->targets);
    if (!c->targets) return fail(c, NULL, "out of memory");
    for (int ti = 0; ti < cJSON_GetArraySize(tracks); ti++) {
        const cJSON *t = cJSON_GetArrayItem(tracks, ti);
        char p[PATH_MAX_LEN], q[PATH_MAX_LEN], kp[PATH_MAX_LEN];
        path_index(p, "animation.tracks", ti);
        if (expect_object(c, t, p) || check_keys(c, t, p, tkeys)) return -1;
        const cJSON *target = cJSON_GetObjectItemCaseSensitive(t, "target");
        const cJSON *ks = cJSON_GetObjectItemCaseSensitive(t, "keys");
        path_key(q, p, "target");
        if (!cJSON_IsString(target))
            return fail(c, q, "expected a path such as \"materials.NAME.eta\"");
        path_key(kp, p, "keys");
        int nk = cJSON_IsArray(ks) ? cJSON_GetArraySize(ks) : 0;
        if (nk < 1) return fail(c, kp, "expected [[frame, value], ...] with at least one key");
        /* every key: [frame, value], frames increasing, values of one shape; and the pair of
         * keys around the frame (lo, hi) */
        AnimValue lo = {0}, hi = {0}, v;
        double flo = 0, fhi = 0, prev = 0;
        int found = 0;
        for (int k = 0; k < nk; k++) {
            const cJSON *key = cJSON_GetArrayItem(ks, k);
            char ep[PATH_MAX_LEN];
            path_index(ep, kp, k);
            const cJSON *kf = cJSON_GetArrayItem(key, 0);
            if (!cJSON_IsArray(key) || cJSON_GetArraySize(key) != 2 || !cJSON_IsNumber(kf))
                return fail(c, ep, "expected [frame, value]");
            if (anim_value(c, cJSON_GetArrayItem(key, 1), ep, &v)) return -1;
            double f = kf->valuedouble;
            if (k > 0 && v.n != lo.n)
                return fail(c, ep, "the value has another shape than key 0's");
            if (k > 0 && !(f > prev))
                return fail(c, ep, "frames must increase (%g after %g)", f, prev);
            prev = f;
            if (k == 0 || (!found && f <= frame)) lo = v, flo = f; /* the last key at or before */
            if (!found && (f >= frame || k == nk - 1)) {
                hi = v, fhi = f; /* the first key at or after (or the last) */
                found = 1;
            }
        }
        if (fhi < flo || frame <= flo) hi = lo, fhi = flo; /* before the first key: hold it */
        if (frame < 0) {
            if (anim_set(c, root, target->valuestring, q, NULL, c->targets[ti])) return -1;
            continue;
        }
        double w = fhi > flo ? (frame - flo) / (fhi - flo) : 0.0;
        w = w < 0 ? 0 : w > 1 ? 1 : w;
        double out[16];
        int n = lo.n ? lo.n : 1;
        for (int i = 0; i < n; i++) out[i] = lo.v[i] + w * (hi.v[i] - lo.v[i]);
        cJSON *val = lo.n ? cJSON_CreateDoubleArray(out, lo.n) : cJSON_CreateNumber(out[0]);
        if (!val) return fail(c, NULL, "out of memory");
        if (anim_set(c, root, target->valuestring, q, val, c->targets[ti])) return -1;
        c->ntargets = ti + 1;
    }
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

/* The error at the position `at` of text: "FILE:LINE:COL: message". */
static int fail_at(const Ctx *c, const char *text, const char *at, const char *msg)
{
    int line, col;
    text_position(text, at, &line, &col);
    diag_format(c->err, c->errlen, "%s:%d:%d: %s", c->file, line, col, msg);
    return -1;
}

/* A string at s (just past its opening quote) holding \u0000: cJSON would cut it there, so
 * "fov\u0000zoom" would read as "fov". Reported as an unknown key or a bad string. */
static int fail_nul_string(const Ctx *c, const char *text, const char *s)
{
    const char *e = s;
    while (*e && *e != '"') e += (*e == '\\' && e[1]) ? 2 : 1;
    const char *after = *e ? e + 1 : e;
    while (*after == ' ' || *after == '\t' || *after == '\r' || *after == '\n') after++;
    char raw[128], msg[512];
    snprintf(raw, sizeof raw, "%.*s", (int)(e - s < 100 ? e - s : 100), s);
    if (*after == ':')
        snprintf(msg, sizeof msg, "unknown key \"%s\" (a key cannot hold \\u0000)",
                 diag_value(raw));
    else
        snprintf(msg, sizeof msg, "JSON string \"%s\" holds \\u0000 (NUL), which is not allowed",
                 diag_value(raw));
    return fail_at(c, text, s - 1, msg);
}

/* What cJSON accepts but JSON does not, or reads otherwise than written: numbers with
 * leading zeros (040) and strings holding \u0000. Checked on the raw text, with line:col. */
static int check_raw_text(const Ctx *c, const char *text)
{
    char prev = ' ';
    for (const char *p = text; *p; p++) {
        if (*p == '"') { /* a whole string: escapes skipped, \u0000 refused */
            const char *q = p + 1;
            while (*q && *q != '"') {
                if (*q == '\\' && strncmp(q + 1, "u0000", 5) == 0)
                    return fail_nul_string(c, text, p + 1);
                q += (*q == '\\' && q[1]) ? 2 : 1;
            }
            if (!*q) return 0; /* unterminated: the parser reports it */
            p = q;
            prev = '"';
            continue;
        }
        int starts = (*p == '-' || isdigit((unsigned char)*p)) &&
                     !(isalnum((unsigned char)prev) || prev == '.' || prev == '+' || prev == '-');
        const char *d = *p == '-' ? p + 1 : p;
        if (starts && d[0] == '0' && isdigit((unsigned char)d[1]))
            return fail_at(c, text, d,
                           "JSON syntax error: a number cannot start with 0 (write 40, not 040)");
        prev = *p;
    }
    return 0;
}

/* Parses text into *root, or writes "FILE:LINE:COL: JSON syntax error ..." into err. */
static int parse_json(const Ctx *c, const char *text, cJSON **root)
{
    const char *end = NULL;
    *root = cJSON_ParseWithOpts(text, &end, 1);
    if (*root) return 0;
    const char *at = end ? end : cJSON_GetErrorPtr();
    int line, col;
    if (!at) at = text;
    text_position(text, at, &line, &col);
    char near[24] = "";
    size_t k = 0;
    for (const char *q = at; *q && *q != '\n' && k < 16; q++) near[k++] = *q;
    near[k] = 0;
    if (*at == 0)
        diag_format(c->err, c->errlen, "%s:%d:%d: JSON syntax error: unexpected end of file",
                    c->file, line, col);
    else
        diag_format(c->err, c->errlen, "%s:%d:%d: JSON syntax error near \"%s\"", c->file, line,
                    col, near);
    return -1;
}

/* Everything inside the document root, for the frame anim_apply has set. */
static int load_document(Ctx *c, const cJSON *root, Scene *s)
{
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
    if (!cam) return fail(c, "camera", "missing (expected an object with eye and look_at)");
    const cJSON *img = cJSON_GetObjectItemCaseSensitive(root, "image");
    const cJSON *desc = cJSON_GetObjectItemCaseSensitive(root, "description");
    if (desc && !cJSON_IsString(desc))
        return fail(c, "description", "expected a string, got %s", json_type_name(desc));
    if (img) {
        if (load_image(c, img, s)) return -1;
    } else {
        s->width = s->height = 400;
    }
    if (load_camera(c, cam, s) ||
        load_render(c, cJSON_GetObjectItemCaseSensitive(root, "render"), s) ||
        load_lights(c, cJSON_GetObjectItemCaseSensitive(root, "lights"), s) ||
        load_materials(c, cJSON_GetObjectItemCaseSensitive(root, "materials"), s) ||
        load_objects(c, cJSON_GetObjectItemCaseSensitive(root, "objects"), s))
        return -1;
    default_band_layout(cJSON_GetObjectItemCaseSensitive(root, "render"), s);
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
    if (!(s->path = dup_string(path)) || !(s->dir = dup_string(is_stdin(path) ? "" : path)))
        goto oom;
    char *slash = strrchr(s->dir, '/');
    if (slash)
        *(slash == s->dir ? slash + 1 : slash) = 0;
    else
        s->dir[0] = 0;
    if (check_raw_text(&c, text) || parse_json(&c, text, &root)) goto fail;
    if (expect_object(&c, root, "") || check_keys(&c, root, "", keys) ||
        anim_apply(&c, root, frame, &s->frames))
        goto fail;
    if (frame >= s->frames) {
        c.frame = -1;
        fail(&c, "animation.frames", "frame %d asked for, the scene has %d", frame, s->frames);
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
    for (int i = 0; s->materials && i < s->nmaterials; i++) free(s->materials[i].pattern.image);
    free(s->materials);
    free(s->objects);
    free(s->tri_tag);
    mesh_free(&s->mesh);
    memset(s, 0, sizeof *s);
}
