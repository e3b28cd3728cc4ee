/* scene_animation.c — animation: tracks that set numbers of the scene document for a
 * frame, interpolated between their keys, before the document is read. */
#include "scene_parts.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diag.h"

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
        return scene_fail(c, path, "expected a number or an array of 1 to 16 numbers, got %s",
                          json_type_name(j));
    out->n = n;
    for (int i = 0; i < n; i++) {
        const cJSON *e = cJSON_GetArrayItem(j, i);
        if (!cJSON_IsNumber(e)) return scene_fail(c, path, "element %d is not a number", i);
        out->v[i] = e->valuedouble;
    }
    return 0;
}

/* A track's target path: 1 to PATH_MAX_LEN - 1 characters, no empty component
 * ("camera..fov" is not "camera.fov"). */
static int check_target(Ctx *c, const char *target, const char *path)
{
    if (strlen(target) >= PATH_MAX_LEN || !*target)
        return scene_fail(c, path, "expected a path such as \"materials.NAME.eta\"");
    if (target[0] == '.' || target[strlen(target) - 1] == '.' || strstr(target, ".."))
        return scene_fail(c, path, "\"%s\": an empty component (expected names between the dots)",
                          diag_value(target));
    return 0;
}

/* The element of the array node that seg names: by index, else by its "name"; -1 if none. */
static int anim_element(const cJSON *node, const char *seg)
{
    char *end;
    long i = strtol(seg, &end, 10);
    int n = cJSON_GetArraySize(node);
    if (*end == 0 && end != seg && i >= 0 && i < n) return (int)i;
    for (int k = 0; k < n; k++) {
        const cJSON *nm = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(node, k), "name");
        if (cJSON_IsString(nm) && strcmp(nm->valuestring, seg) == 0) return k;
    }
    return -1;
}

/* Puts *val in place of the last member seg of node (its element index, or -1 for an
 * object's member next, NULL when missing); *val becomes NULL once the tree holds it. */
static int anim_put(Ctx *c, cJSON *node, const char *seg, int index, const cJSON *next,
                    const char *target, const char *path, cJSON **val)
{
    if (next && !cJSON_IsNumber(next) && !cJSON_IsArray(next))
        return scene_fail(c, path, "\"%s\" is a %s: only numbers and arrays of numbers animate",
                          diag_value(target), json_type_name(next));
    if (!*val) return 0;
    cJSON_bool ok = index >= 0 ? cJSON_ReplaceItemInArray(node, index, *val)
                    : next     ? cJSON_ReplaceItemInObjectCaseSensitive(node, seg, *val)
                               : cJSON_AddItemToObject(node, seg, *val);
    if (!ok) return scene_fail(c, NULL, "out of memory");
    *val = NULL;
    return 0;
}

/* anim_set's walk along the target's components; *val as in anim_put. */
static int anim_walk(Ctx *c, cJSON *root, const char *target, const char *path, cJSON **val,
                     char *canon)
{
    char buf[PATH_MAX_LEN];
    strcpy(buf, target);
    cJSON *node = root;
    char *save = NULL;
    int in_element = 0; /* below an element of an array (an object, a light) */
    for (char *seg = strtok_r(buf, ".", &save); seg; seg = strtok_r(NULL, ".", &save)) {
        int last = *save == 0, index = -1;
        if (node == root && (strcmp(seg, "animation") == 0 || last))
            return scene_fail(c, path,
                              "\"%s\": expected a value inside image, camera, render, lights, "
                              "materials or objects",
                              diag_value(target));
        cJSON *next = NULL;
        size_t k = strlen(canon);
        if (cJSON_IsArray(node)) {
            if ((index = anim_element(node, seg)) < 0)
                return scene_fail(c, path, "\"%s\": no element \"%s\" (an index or a name)",
                                  diag_value(target), diag_value(seg));
            next = cJSON_GetArrayItem(node, index);
            in_element = 1;
            snprintf(canon + k, PATH_MAX_LEN - k, "[%d]", index);
        } else if (cJSON_IsObject(node)) {
            next = cJSON_GetObjectItemCaseSensitive(node, seg);
            snprintf(canon + k, PATH_MAX_LEN - k, "%s%s", k ? "." : "", seg);
        } else {
            return scene_fail(c, path, "\"%s\": \"%s\" is inside a %s, not an object or array",
                              diag_value(target), diag_value(seg), json_type_name(node));
        }
        if (last) return anim_put(c, node, seg, index, next, target, path, val);
        if (!next && !in_element)
            return scene_fail(c, path, "\"%s\": no member \"%s\"", diag_value(target),
                              diag_value(seg));
        if (!next) { /* a missing object on the way, inside an element (its transform) */
            if (!*val) return 0; /* checking only: it would be created */
            next = cJSON_CreateObject();
            if (!next || !cJSON_AddItemToObject(node, seg, next)) {
                cJSON_Delete(next);
                return scene_fail(c, NULL, "out of memory");
            }
        }
        node = next;
    }
    return scene_fail(c, path, "expected a path such as \"materials.NAME.eta\"");
}

/* Sets the member a track's target names, "materials.glass.eta" or "objects.ball.transform.
 * rotate", to val (taken over; NULL only checks the path): object members by key, array
 * elements by index or by their "name". A missing last member is created (a setting left at
 * its default), and so are missing objects on the way inside an element of an array (an
 * object's transform); anything else must exist. */
static int anim_set(Ctx *c, cJSON *root, const char *target, const char *path, cJSON *val,
                    char *canon)
{
    canon[0] = 0;
    int rc = check_target(c, target, path) ? -1 : anim_walk(c, root, target, path, &val, canon);
    cJSON_Delete(val);
    return rc;
}

/* Applies root.animation for frame `frame`, linearly between the keys around it and holding
 * the first and last keys beyond them (-1: checks the tracks, changes nothing), and returns
 * the frame count in *frames (1 without an animation). */
int scene_anim_apply(Ctx *c, cJSON *root, int frame, int *frames)
{
    static const char *const keys[] = {"frames", "tracks", NULL};
    static const char *const tkeys[] = {"target", "keys", NULL};
    *frames = 1;
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(root, "animation");
    if (!a) return 0;
    if (json_expect_object(c, a, "animation") || json_check_keys(c, a, "animation", keys))
        return -1;
    const cJSON *fr = cJSON_GetObjectItemCaseSensitive(a, "frames");
    if (!cJSON_IsNumber(fr) || fr->valuedouble != floor(fr->valuedouble) || fr->valuedouble < 1 ||
        fr->valuedouble > 100000)
        return scene_fail(c, "animation.frames", "expected an integer 1 .. 100000");
    *frames = (int)fr->valuedouble;
    c->animated = 1;
    const cJSON *tracks = cJSON_GetObjectItemCaseSensitive(a, "tracks");
    if (!cJSON_IsArray(tracks) || cJSON_GetArraySize(tracks) < 1)
        return scene_fail(c, "animation.tracks", "expected an array of {\"target\", \"keys\"}");
    c->targets = calloc((size_t)cJSON_GetArraySize(tracks), sizeof *c->targets);
    if (!c->targets) return scene_fail(c, NULL, "out of memory");
    for (int ti = 0; ti < cJSON_GetArraySize(tracks); ti++) {
        const cJSON *t = cJSON_GetArrayItem(tracks, ti);
        char p[PATH_MAX_LEN], q[PATH_MAX_LEN], kp[PATH_MAX_LEN];
        json_path_index(p, "animation.tracks", ti);
        if (json_expect_object(c, t, p) || json_check_keys(c, t, p, tkeys)) return -1;
        const cJSON *target = cJSON_GetObjectItemCaseSensitive(t, "target");
        const cJSON *ks = cJSON_GetObjectItemCaseSensitive(t, "keys");
        json_path_key(q, p, "target");
        if (!cJSON_IsString(target))
            return scene_fail(c, q, "expected a path such as \"materials.NAME.eta\"");
        json_path_key(kp, p, "keys");
        int nk = cJSON_IsArray(ks) ? cJSON_GetArraySize(ks) : 0;
        if (nk < 1)
            return scene_fail(c, kp, "expected [[frame, value], ...] with at least one key");
        /* every key: [frame, value], frames increasing, values of one shape; and the pair of
         * keys around the frame (lo, hi) */
        AnimValue lo = {0}, hi = {0}, v;
        double flo = 0, fhi = 0, prev = 0;
        int found = 0;
        for (int k = 0; k < nk; k++) {
            const cJSON *key = cJSON_GetArrayItem(ks, k);
            char ep[PATH_MAX_LEN];
            json_path_index(ep, kp, k);
            const cJSON *kf = cJSON_GetArrayItem(key, 0);
            if (!cJSON_IsArray(key) || cJSON_GetArraySize(key) != 2 || !cJSON_IsNumber(kf))
                return scene_fail(c, ep, "expected [frame, value]");
            if (anim_value(c, cJSON_GetArrayItem(key, 1), ep, &v)) return -1;
            double f = kf->valuedouble;
            if (k > 0 && v.n != lo.n)
                return scene_fail(c, ep, "the value has another shape than key 0's");
            if (k > 0 && !(f > prev))
                return scene_fail(c, ep, "frames must increase (%g after %g)", f, prev);
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
        if (!val) return scene_fail(c, NULL, "out of memory");
        if (anim_set(c, root, target->valuestring, q, val, c->targets[ti])) return -1;
        c->ntargets = ti + 1;
    }
    return 0;
}
