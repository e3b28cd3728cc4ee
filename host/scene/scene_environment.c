/* scene_environment.c — image.environment: a latitude-longitude image that rays leaving the
 * scene see instead of the background colour, its file read and checked as the scene
 * loads (linear radiance, finite and >= 0), its rotation and scale. */
#include "scene_parts.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "diag.h"
#include "image_io.h"

/* environment.rotation as the environment-to-world rotation m: a number turns the
 * environment by that many degrees about the y axis (its up); [x, y, z] rotates about x,
 * then y, then z, as an object's transform.rotate. */
static int load_rotation(Ctx *c, const cJSON *j, const char *p, mat4 *m)
{
    static const float zero[3] = {0, 0, 0};
    const cJSON *r = cJSON_GetObjectItemCaseSensitive(j, "rotation");
    float rot[3] = {0, 0, 0};
    if (r && cJSON_IsNumber(r)) {
        if (json_get_float(c, j, p, "rotation", -1e6, 1e6, 0, 1, &rot[1])) return -1;
    } else if (r && !cJSON_IsArray(r)) {
        char q[PATH_MAX_LEN];
        json_path_key(q, p, "rotation");
        return scene_fail(c, q,
                          "expected degrees about the up axis (a number) or about x, y and z "
                          "([x, y, z]), got %s",
                          json_type_name(r));
    } else if (json_get_vec(c, j, p, "rotation", 3, -1e6, 1e6, zero, rot)) {
        return -1;
    }
    *m = mat4_identity();
    for (int a = 0; a < 3; a++) *m = mat4_mul(mat4_rotate_axis(a, rot[a]), *m);
    return 0;
}

/* Reads the image at full (environment.file's value joined with the scene's directory) into
 * e, every value checked: finite and >= 0, and so once scaled. q: the key's JSON path. */
static int load_image_file(Ctx *c, const char *q, const char *full, SceneEnvironment *e)
{
    struct stat st; /* a regular file: opening a pipe would wait for a writer */
    if (stat(full, &st)) return scene_fail(c, q, "%s: cannot open: %s", full, strerror(errno));
    if (!S_ISREG(st.st_mode))
        return scene_fail(c, q, "%s: not a regular file (an environment must be an image file)",
                          full);
    char err[1024];
    if (image_read_radiance(full, &e->width, &e->height, &e->texels, err, sizeof err))
        return scene_fail(c, q, "%s", err);
    size_t n = (size_t)e->width * (size_t)e->height;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            float v = e->texels[4 * i + k];
            if (!isfinite(v) || v < 0.0f)
                return scene_fail(
                    c, q, "%s: texel (%zu, %zu) %c is %s: expected finite radiance >= 0", full,
                    i % (size_t)e->width, i / (size_t)e->width, "RGB"[k], diag_num(v));
            if (!isfinite(v * e->scale))
                return scene_fail(c, q, "%s: texel (%zu, %zu) %c times scale %s overflows", full,
                                  i % (size_t)e->width, i / (size_t)e->width, "RGB"[k],
                                  diag_num(e->scale));
        }
    return 0;
}

int scene_load_environment(Ctx *c, const cJSON *img, Scene *s)
{
    static const char *const keys[] = {"file", "rotation", "scale", NULL};
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(img, "environment");
    if (!j) return 0;
    const char *p = "image.environment";
    if (cJSON_GetObjectItemCaseSensitive(img, "background"))
        return scene_fail(c, "image.background",
                          "an environment replaces the background colour: give one of them");
    if (json_expect_object(c, j, p) || json_check_keys(c, j, p, keys)) return -1;
    SceneEnvironment *e = &s->env;
    mat4 m;
    if (json_get_float(c, j, p, "scale", 0, FLT_MAX, 1, 0, &e->scale) || load_rotation(c, j, p, &m))
        return -1;
    for (int r = 0; r < 3; r++) /* world to environment: the transpose */
        for (int k = 0; k < 3; k++) e->to_env[r][k] = (float)m.m[k][r];
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(j, "file");
    char q[PATH_MAX_LEN];
    json_path_key(q, p, "file");
    if (!f) return scene_fail(c, q, "missing (expected the image file: EXR, HDR, PNG, ...)");
    if (!cJSON_IsString(f) || !f->valuestring[0])
        return scene_fail(c, q, "expected a file name, got %s", json_type_name(f));
    char full[4096];
    scene_join_path(full, sizeof full, s->dir, f->valuestring);
    if (!(e->file = scene_strdup(full))) return scene_fail(c, NULL, "out of memory");
    return load_image_file(c, q, full, e);
}
