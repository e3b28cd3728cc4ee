/* scene_shapes.c — an object's shape tessellated in object space (mesh file, sphere, box,
 * prism, quad, revolution), its transform, and the triangle count known before building. */
#include "scene_parts.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diag.h"

/* Builds the object-to-world transform: scale, then rotate about x, y, z, then translate. */
int scene_load_transform(Ctx *c, const cJSON *obj, const char *path, mat4 *xf)
{
    static const char *const keys[] = {"translate", "rotate", "scale", NULL};
    static const float zero[3] = {0, 0, 0}, one[3] = {1, 1, 1};
    *xf = mat4_identity();
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(obj, "transform");
    if (!t) return 0;
    char p[PATH_MAX_LEN];
    json_path_key(p, path, "transform");
    if (json_expect_object(c, t, p) || json_check_keys(c, t, p, keys)) return -1;
    float tr[3], rot[3], sc[3];
    if (json_get_vec(c, t, p, "translate", 3, -FLT_MAX, FLT_MAX, zero, tr) ||
        json_get_vec(c, t, p, "rotate", 3, -1e6, 1e6, zero, rot))
        return -1;
    const cJSON *s = cJSON_GetObjectItemCaseSensitive(t, "scale");
    if (s && cJSON_IsNumber(s)) {
        float k;
        if (json_get_float(c, t, p, "scale", -FLT_MAX, FLT_MAX, 1, 1, &k)) return -1;
        sc[0] = sc[1] = sc[2] = k;
    } else if (json_get_vec(c, t, p, "scale", 3, -FLT_MAX, FLT_MAX, one, sc)) {
        return -1;
    }
    if (sc[0] == 0 || sc[1] == 0 || sc[2] == 0) {
        char ps[PATH_MAX_LEN];
        json_path_key(ps, p, "scale");
        return scene_fail(c, ps, "a scale factor of 0 flattens the object");
    }
    mat4 m = mat4_scale(v3(sc[0], sc[1], sc[2]));
    for (int a = 0; a < 3; a++) m = mat4_mul(mat4_rotate_axis(a, rot[a]), m);
    *xf = mat4_mul(mat4_translate(v3(tr[0], tr[1], tr[2])), m);
    return 0;
}

void scene_sphere_transform(const cJSON *o, const Scene *s, mat4 *xf)
{
    if (scene_frame_is_identity(s)) return; /* load_sphere placed it */
    double ctr[3];
    json_numbers(cJSON_GetObjectItemCaseSensitive(o, "centre"), v3(0.0f, 0.0f, 0.0f), ctr);
    const cJSON *r = cJSON_GetObjectItemCaseSensitive(o, "radius");
    float radius = cJSON_IsNumber(r) ? (float)r->valuedouble : 1.0f; /* checked: > 0 */
    mat4 place = mat4_scale(v3(radius, radius, radius));
    for (int k = 0; k < 3; k++) place.m[k][3] = ctr[k];
    *xf = mat4_mul(*xf, place);
}

int scene_load_transform_framed(Ctx *c, const cJSON *obj, const char *path, const Scene *s,
                                mat4 *xf)
{
    if (scene_load_transform(c, obj, path, xf)) return -1;
    if (scene_frame_is_identity(s)) return 0;
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(obj, "transform");
    vec3 parsed = v3(xf->m[0][3], xf->m[1][3], xf->m[2][3]);
    double tr[3];
    json_numbers(t ? cJSON_GetObjectItemCaseSensitive(t, "translate") : NULL, parsed, tr);
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) xf->m[i][j] *= s->frame_scale;   /* a power of two: exact */
        xf->m[i][3] = (tr[i] - s->frame_origin[i]) * s->frame_scale; /* double, as written */
    }
    return 0;
}

/* objects[i] with "shape": "revolution": a profile swept about the y axis (its triangle
 * count was checked before any shape was built: scene_count_triangles). */
static int load_revolution(Ctx *c, const cJSON *o, const char *p, Mesh *m)
{
    char q[PATH_MAX_LEN];
    static const char *const keys[] = {"shape",   "material", "name", "transform", "texture",
                                       "profile", "segments", "caps", NULL};
    int segments;
    if (json_check_keys(c, o, p, keys) ||
        json_get_int(c, o, p, "segments", 3, 4096, 32, 0, &segments))
        return -1;
    const cJSON *caps = cJSON_GetObjectItemCaseSensitive(o, "caps");
    json_path_key(q, p, "caps");
    if (caps && !cJSON_IsBool(caps))
        return scene_fail(c, q, "expected true or false, got %s", json_type_name(caps));
    json_path_key(q, p, "profile");
    const cJSON *pj = cJSON_GetObjectItemCaseSensitive(o, "profile");
    if (!pj) return scene_fail(c, q, "missing (expected an array of [r, y] points)");
    int n = cJSON_IsArray(pj) ? cJSON_GetArraySize(pj) : 0;
    if (n < 2 || n > 100000)
        return scene_fail(c, q, "expected an array of 2 to 100000 [r, y] points");
    float(*prof)[2] = malloc(sizeof(float[2]) * (size_t)n);
    if (!prof) return scene_fail(c, NULL, "out of memory");
    int i = 0;
    for (const cJSON *e = pj->child; e; e = e->next, i++) {
        char qi[PATH_MAX_LEN];
        json_path_index(qi, q, i);
        if (json_read_vec(c, e, qi, 2, -FLT_MAX, FLT_MAX, prof[i])) {
            free(prof);
            return -1;
        }
        if (prof[i][0] < 0) {
            free(prof);
            return scene_fail(c, qi, "the radius r must be >= 0");
        }
        if (i > 0 && prof[i][0] == prof[i - 1][0] && prof[i][1] == prof[i - 1][1]) {
            free(prof);
            return scene_fail(c, qi, "repeats the previous point");
        }
    }
    int rc =
        shape_revolution(m, (const float(*)[2])prof, n, segments, caps ? cJSON_IsTrue(caps) : 1);
    free(prof);
    if (rc) return scene_fail(c, p, "could not tessellate the shape (out of memory)");
    return 0;
}

/* objects[i] with "shape": "mesh": a mesh file, relative to the scene's directory. */
static int load_mesh_file(Ctx *c, const cJSON *o, const char *p, const Scene *s, Mesh *m)
{
    static const char *const keys[] = {"shape",   "material", "name", "transform",
                                       "texture", "file",     NULL};
    char q[PATH_MAX_LEN];
    if (json_check_keys(c, o, p, keys)) return -1;
    json_path_key(q, p, "file");
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(o, "file");
    if (!f) return scene_fail(c, q, "missing (expected a mesh file name)");
    if (!cJSON_IsString(f) || !f->valuestring[0])
        return scene_fail(c, q, "expected a file name, got %s", json_type_name(f));
    char full[4096], merr[512];
    scene_join_path(full, sizeof full, s->dir, f->valuestring);
    if (mesh_load(full, m, merr, sizeof merr)) return scene_fail(c, q, "%s", merr);
    return 0;
}

/* objects[i] with "shape": "sphere": a subdivided icosahedron of radius and centre. In a
 * scene whose frame is not the file's own the unit icosahedron is left as it is, and the
 * object's transform places it (scene_sphere_transform), in double. */
static int load_sphere(Ctx *c, const cJSON *o, const char *p, const Scene *s, Mesh *m)
{
    static const char *const keys[] = {"shape",  "material", "name",  "transform", "texture",
                                       "radius", "centre",   "level", NULL};
    static const float zero[3] = {0, 0, 0};
    float radius, centre[3];
    int level;
    if (json_check_keys(c, o, p, keys) ||
        json_get_float(c, o, p, "radius", FLT_MIN, FLT_MAX, 1, 0, &radius) ||
        json_get_vec(c, o, p, "centre", 3, -FLT_MAX, FLT_MAX, zero, centre) ||
        json_get_int(c, o, p, "level", 0, 7, 3, 0, &level))
        return -1;
    if (shape_sphere(m, level)) return 1;
    if (!scene_frame_is_identity(s)) return 0;
    mat4 xf = mat4_mul(mat4_translate(v3(centre[0], centre[1], centre[2])),
                       mat4_scale(v3(radius, radius, radius)));
    mesh_transform(m, &xf);
    return 0;
}

/* objects[i] with "shape": "prism": a triangle [x, y] x 3 extruded by depth. */
static int load_prism(Ctx *c, const cJSON *o, const char *p, Mesh *m)
{
    static const char *const keys[] = {"shape",   "material", "name",  "transform",
                                       "texture", "points",   "depth", NULL};
    char q[PATH_MAX_LEN];
    float pts[3][2] = {{-0.5f, -0.288675f}, {0.5f, -0.288675f}, {0.0f, 0.577350f}};
    float depth;
    if (json_check_keys(c, o, p, keys) ||
        json_get_float(c, o, p, "depth", FLT_MIN, FLT_MAX, 1, 0, &depth))
        return -1;
    const cJSON *pj = cJSON_GetObjectItemCaseSensitive(o, "points");
    json_path_key(q, p, "points");
    if (pj) {
        if (!cJSON_IsArray(pj) || cJSON_GetArraySize(pj) != 3)
            return scene_fail(c, q, "expected 3 points [x, y]");
        int i = 0;
        for (const cJSON *e = pj->child; e; e = e->next, i++) {
            char qi[PATH_MAX_LEN];
            json_path_index(qi, q, i);
            if (json_read_vec(c, e, qi, 2, -FLT_MAX, FLT_MAX, pts[i])) return -1;
        }
    }
    double area = (pts[1][0] - pts[0][0]) * (pts[2][1] - pts[0][1]) -
                  (pts[2][0] - pts[0][0]) * (pts[1][1] - pts[0][1]);
    if (area == 0) return scene_fail(c, q, "the three points are on one line");
    return shape_prism(m, (const float(*)[2])pts, depth) ? 1 : 0;
}

/* objects[i] with "shape": "box" (3 sizes) or "quad" (2 sizes, in the xy plane). */
static int load_box_or_quad(Ctx *c, const cJSON *o, const char *p, int quad, Mesh *m)
{
    static const char *const keys[] = {"shape",   "material", "name", "transform",
                                       "texture", "size",     NULL};
    static const float one[3] = {1, 1, 1};
    float size[3];
    if (json_check_keys(c, o, p, keys) ||
        json_get_vec(c, o, p, "size", quad ? 2 : 3, FLT_MIN, FLT_MAX, one, size))
        return -1;
    int rc = quad ? shape_quad(m, size[0], size[1]) : shape_box(m, v3(size[0], size[1], size[2]));
    return rc ? 1 : 0;
}

/* Tessellates one object's shape into m (object space). */
int scene_load_shape(Ctx *c, const cJSON *o, const char *p, const char *shape, const Scene *s,
                     Mesh *m)
{
    int rc; /* -1 reported, 1 out of memory while tessellating */
    if (strcmp(shape, "mesh") == 0) return load_mesh_file(c, o, p, s, m);
    if (strcmp(shape, "revolution") == 0) return load_revolution(c, o, p, m);
    if (strcmp(shape, "sphere") == 0)
        rc = load_sphere(c, o, p, s, m);
    else if (strcmp(shape, "box") == 0 || strcmp(shape, "quad") == 0)
        rc = load_box_or_quad(c, o, p, shape[0] == 'q', m);
    else if (strcmp(shape, "prism") == 0)
        rc = load_prism(c, o, p, m);
    else {
        char q[PATH_MAX_LEN];
        json_path_key(q, p, "shape");
        return scene_fail(
            c, q, "unknown shape \"%s\" (expected mesh, sphere, box, prism, quad or revolution)",
            diag_value(shape));
    }
    if (rc > 0) return scene_fail(c, p, "could not tessellate the shape (out of memory)");
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
int scene_count_triangles(Ctx *c, const cJSON *j)
{
    uint64_t total = 0;
    int i = 0;
    for (const cJSON *o = j->child; o; o = o->next, i++) {
        char what[128], p[PATH_MAX_LEN];
        uint64_t n = shape_triangles(o, what, sizeof what);
        total += n;
        if (total <= SCENE_MAX_TRIANGLES) continue;
        json_path_index(p, "objects", i);
        return scene_fail(
            c, p,
            "%s %llu triangles, %llu with the objects before it, and a scene may have at "
            "most %u: use fewer segments, profile points or a lower level",
            what, (unsigned long long)n, (unsigned long long)total, SCENE_MAX_TRIANGLES);
    }
    return 0;
}
