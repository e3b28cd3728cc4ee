/* scene_json.c — the parse context's error reporting (with the JSON path and, in an
 * animation, the frame and track), typed getters that check every value, and the checks
 * of the raw text before cJSON reads it. */
#include "scene_json.h"

#include <ctype.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diag.h"

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

int scene_fail(Ctx *c, const char *path, const char *fmt, ...)
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

void json_path_key(char *out, const char *parent, const char *key)
{
    if (parent && *parent)
        snprintf(out, PATH_MAX_LEN, "%s.%s", parent, key);
    else
        snprintf(out, PATH_MAX_LEN, "%s", key);
}

void json_path_index(char *out, const char *parent, int i)
{
    snprintf(out, PATH_MAX_LEN, "%s[%d]", parent, i);
}

const char *json_type_name(const cJSON *j)
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
int json_check_keys(Ctx *c, const cJSON *obj, const char *path, const char *const *allowed)
{
    for (const cJSON *k = obj->child; k; k = k->next) {
        int ok = 0;
        for (const char *const *a = allowed; *a; a++)
            if (strcmp(k->string, *a) == 0) ok = 1;
        char p[PATH_MAX_LEN];
        json_path_key(p, path, k->string);
        if (!ok) {
            char list[256] = "";
            for (const char *const *a = allowed; *a; a++) {
                if (a != allowed) strncat(list, ", ", sizeof list - strlen(list) - 1);
                strncat(list, *a, sizeof list - strlen(list) - 1);
            }
            const char *near = diag_suggest(k->string, allowed);
            if (near)
                return scene_fail(c, p, "unknown key: did you mean \"%s\"? (expected one of: %s)",
                                  near, list);
            return scene_fail(c, p, "unknown key (expected one of: %s)", list);
        }
        for (const cJSON *o = obj->child; o != k; o = o->next)
            if (strcmp(o->string, k->string) == 0) return scene_fail(c, p, "key given twice");
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
int scene_fail_range(Ctx *c, const char *p, double v, double lo, double hi)
{
    if ((hi == FLT_MAX || hi == DBL_MAX) && v > hi) /* "unbounded", but a float's limit */
        return scene_fail(c, p, "%s is out of range: expected at most %s (the largest %s)",
                          diag_num(v), diag_num(hi), hi == FLT_MAX ? "float" : "double");
    char r[96];
    range_text(lo, hi, r, sizeof r);
    return scene_fail(c, p, "%s is out of range%s%s", diag_num(v),
                      r[0] == '[' ? " " : ": expected ", r);
}

int json_expect_object(Ctx *c, const cJSON *j, const char *path)
{
    if (!cJSON_IsObject(j))
        return scene_fail(c, path, "expected an object, got %s", json_type_name(j));
    return 0;
}

/* Reads obj[key] as a finite number in [lo, hi]; absent: def, or an error if required. */
int json_get_num(Ctx *c, const cJSON *obj, const char *path, const char *key, double lo, double hi,
                 double def, int required, double *out)
{
    char p[PATH_MAX_LEN];
    json_path_key(p, path, key);
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!j) {
        if (required) return scene_fail(c, p, "missing (expected a number)");
        *out = def;
        return 0;
    }
    if (!cJSON_IsNumber(j)) return scene_fail(c, p, "expected a number, got %s", json_type_name(j));
    double v = j->valuedouble;
    if (!isfinite(v)) return scene_fail(c, p, "expected a finite number");
    if (v < lo || v > hi) return scene_fail_range(c, p, v, lo, hi);
    *out = v;
    return 0;
}

int json_get_float(Ctx *c, const cJSON *obj, const char *path, const char *key, double lo,
                   double hi, double def, int required, float *out)
{
    double v;
    if (json_get_num(c, obj, path, key, lo, hi, def, required, &v)) return -1;
    *out = (float)v;
    return 0;
}

int json_get_int(Ctx *c, const cJSON *obj, const char *path, const char *key, int lo, int hi,
                 int def, int required, int *out)
{
    double v;
    if (json_get_num(c, obj, path, key, lo, hi, def, required, &v)) return -1;
    if (v != floor(v)) {
        char p[PATH_MAX_LEN];
        json_path_key(p, path, key);
        return scene_fail(c, p, "expected a whole number, got %g", v);
    }
    *out = (int)v;
    return 0;
}

/* Reads an array of n finite numbers in [lo, hi] at j. */
int json_read_vec(Ctx *c, const cJSON *j, const char *p, int n, double lo, double hi, float *out)
{
    if (!cJSON_IsArray(j) || cJSON_GetArraySize(j) != n)
        return scene_fail(c, p, "expected an array of %d numbers, got %s", n,
                          cJSON_IsArray(j) ? "an array of another length" : json_type_name(j));
    int i = 0;
    for (const cJSON *e = j->child; e; e = e->next, i++) {
        char pi[PATH_MAX_LEN];
        json_path_index(pi, p, i);
        if (!cJSON_IsNumber(e))
            return scene_fail(c, pi, "expected a number, got %s", json_type_name(e));
        if (!isfinite(e->valuedouble)) return scene_fail(c, pi, "expected a finite number");
        if (e->valuedouble < lo || e->valuedouble > hi)
            return scene_fail_range(c, pi, e->valuedouble, lo, hi);
        out[i] = (float)e->valuedouble;
    }
    return 0;
}

int json_get_vec(Ctx *c, const cJSON *obj, const char *path, const char *key, int n, double lo,
                 double hi, const float *def, float *out)
{
    char p[PATH_MAX_LEN];
    json_path_key(p, path, key);
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!j) {
        if (!def) return scene_fail(c, p, "missing (expected an array of %d numbers)", n);
        memcpy(out, def, sizeof(float) * (size_t)n);
        return 0;
    }
    return json_read_vec(c, j, p, n, lo, hi, out);
}

void json_numbers(const cJSON *arr, vec3 parsed, double out[3])
{
    out[0] = parsed.x;
    out[1] = parsed.y;
    out[2] = parsed.z;
    if (!cJSON_IsArray(arr) || cJSON_GetArraySize(arr) != 3) return;
    int k = 0;
    for (const cJSON *e = arr->child; e && k < 3; e = e->next, k++)
        if (cJSON_IsNumber(e)) out[k] = e->valuedouble;
}

int json_get_vec3(Ctx *c, const cJSON *obj, const char *path, const char *key, const float *def,
                  vec3 *out)
{
    float v[3];
    if (json_get_vec(c, obj, path, key, 3, -FLT_MAX, FLT_MAX, def, v)) return -1;
    *out = v3(v[0], v[1], v[2]);
    return 0;
}

/* A colour: [r, g, b], each >= 0. */
int json_get_rgb(Ctx *c, const cJSON *obj, const char *path, const char *key, const float *def,
                 float *out)
{
    return json_get_vec(c, obj, path, key, 3, 0.0, FLT_MAX, def, out);
}

char *scene_strdup(const char *s)
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

void scene_join_path(char *out, size_t n, const char *dir, const char *file)
{
    if (file[0] == '/' || !dir || !dir[0])
        snprintf(out, n, "%s", file);
    else
        snprintf(out, n, "%s/%s", dir, file);
}

/* Reads obj[key] as a number (used for all three components) or as [x, y, z]. */
int json_get_scalar_or_vec3(Ctx *c, const cJSON *obj, const char *path, const char *key, double lo,
                            double hi, float def, float out[3])
{
    const cJSON *x = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!x || cJSON_IsNumber(x)) {
        float a;
        if (json_get_float(c, obj, path, key, lo, hi, def, 0, &a)) return -1;
        out[0] = out[1] = out[2] = a;
        return 0;
    }
    const float d[3] = {def, def, def};
    return json_get_vec(c, obj, path, key, 3, lo, hi, d, out);
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
int scene_check_raw_text(const Ctx *c, const char *text)
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
int scene_parse_json(const Ctx *c, const char *text, cJSON **root)
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
