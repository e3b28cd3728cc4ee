/* scene_json.h — internal to host/scene/: the parse context of a scene load, its error
 * reporting (the JSON path of anything wrong), typed getters that check every value, and
 * the checks on the raw text that cJSON would let through. Not included outside host/scene/. */
#ifndef VBCL_SCENE_JSON_H
#define VBCL_SCENE_JSON_H

#include <stddef.h>

#include <cJSON.h>

#include "vecmath.h"

#define PATH_MAX_LEN 256

/* What a loader needs to report an error: the file and the message buffer. */
typedef struct Ctx {
    const char *file;
    char *err;
    size_t errlen;
    int animated; /* the document has an animation (scene_anim_apply) */
    int frame;    /* the frame being loaded; -1: the scene as written */
    int ntargets; /* tracks whose target was resolved into targets[] (scene_anim_apply) */
    char (*targets)[PATH_MAX_LEN]; /* per track: the JSON path it sets, "objects[1].eta" */
} Ctx;

/* Writes "FILE: [frame prefix]PATH: message" (or "FILE: message" without a path) into
 * c->err and returns -1. */
int scene_fail(Ctx *c, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* The error for a number v outside [lo, hi] at path p. */
int scene_fail_range(Ctx *c, const char *p, double v, double lo, double hi);

/* out = "parent.key" (or "key" at the root) and "parent[i]"; PATH_MAX_LEN bytes. */
void json_path_key(char *out, const char *parent, const char *key);
void json_path_index(char *out, const char *parent, int i);
/* "a number", "an array", ... for messages. */
const char *json_type_name(const cJSON *j);

/* Rejects keys not in allowed (NULL-terminated) and keys given twice. */
int json_check_keys(Ctx *c, const cJSON *obj, const char *path, const char *const *allowed);
int json_expect_object(Ctx *c, const cJSON *j, const char *path);

/* Typed getters of obj[key] at path: a finite number in [lo, hi] (absent: def, or an error
 * if required), a whole one, an array of n numbers (absent: def, or an error if def is
 * NULL), [x, y, z], a colour (each >= 0), and a number or [x, y, z]. Return 0 or -1. */
int json_get_num(Ctx *c, const cJSON *obj, const char *path, const char *key, double lo, double hi,
                 double def, int required, double *out);
int json_get_float(Ctx *c, const cJSON *obj, const char *path, const char *key, double lo,
                   double hi, double def, int required, float *out);
int json_get_int(Ctx *c, const cJSON *obj, const char *path, const char *key, int lo, int hi,
                 int def, int required, int *out);
int json_read_vec(Ctx *c, const cJSON *j, const char *p, int n, double lo, double hi, float *out);
int json_get_vec(Ctx *c, const cJSON *obj, const char *path, const char *key, int n, double lo,
                 double hi, const float *def, float *out);
/* The three numbers of arr as written (double), where arr is an array of three numbers;
 * else parsed's (json_numbers is for values already checked). */
void json_numbers(const cJSON *arr, vec3 parsed, double out[3]);
int json_get_vec3(Ctx *c, const cJSON *obj, const char *path, const char *key, const float *def,
                  vec3 *out);
int json_get_rgb(Ctx *c, const cJSON *obj, const char *path, const char *key, const float *def,
                 float *out);
int json_get_scalar_or_vec3(Ctx *c, const cJSON *obj, const char *path, const char *key, double lo,
                            double hi, float def, float out[3]);

/* A malloc'ed copy of s, or NULL. */
char *scene_strdup(const char *s);
/* file relative to dir (absolute file names and an empty dir kept as they are). */
void scene_join_path(char *out, size_t n, const char *dir, const char *file);

/* Refuses what cJSON accepts but JSON does not (leading zeros, \u0000 in strings), with
 * "FILE:LINE:COL: ..." in c->err. Returns 0 or -1. */
int scene_check_raw_text(const Ctx *c, const char *text);
/* Parses text into *root, or writes "FILE:LINE:COL: JSON syntax error ..." into c->err. */
int scene_parse_json(const Ctx *c, const char *text, cJSON **root);

#endif
