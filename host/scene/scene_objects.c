/* scene_objects.c — objects[]: each object's shape, material and texture into the scene
 * mesh, the check that hosts do not overlap, and the medium at a point. */
#include "scene_parts.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diag.h"

/* Appends m to the scene mesh with every triangle tagged tag. */
static int scene_append(Ctx *c, Scene *s, const Mesh *m, uint32_t tag)
{
    uint32_t first = s->mesh.ntris;
    if (mesh_append(&s->mesh, m)) return scene_fail(c, NULL, "out of memory");
    uint32_t *tt = realloc(s->tri_tag, sizeof(uint32_t) * (s->mesh.ntris ? s->mesh.ntris : 1));
    if (!tt) return scene_fail(c, NULL, "out of memory");
    s->tri_tag = tt;
    for (uint32_t t = first; t < s->mesh.ntris; t++) tt[t] = tag;
    return 0;
}

static int check_finite(Ctx *c, const Mesh *m, const char *p)
{
    for (uint32_t v = 0; v < m->nverts; v++)
        if (!isfinite(m->verts[v].x + m->verts[v].y + m->verts[v].z))
            return scene_fail(c, p, "vertex %u is not finite after the transform", v);
    return 0;
}

static int load_object(Ctx *c, const cJSON *o, const char *p, int i, Scene *s)
{
    char q[PATH_MAX_LEN], merr[512];
    if (json_expect_object(c, o, p)) return -1;
    SceneObject *ob = &s->objects[i];
    ob->tex_slot = -1;
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(o, "name");
    json_path_key(q, p, "name");
    if (name && (!cJSON_IsString(name) || strlen(name->valuestring) >= SCENE_NAME_MAX))
        return scene_fail(c, q, "expected a string of at most %d characters", SCENE_NAME_MAX - 1);
    snprintf(ob->name, sizeof ob->name, "%s", name ? name->valuestring : p);
    for (int k = 0; name && k < i; k++) /* an animation track finds objects by name */
        if (s->objects[k].named && strcmp(s->objects[k].name, ob->name) == 0)
            return scene_fail(c, q, "\"%s\" is already used by objects[%d]", diag_value(ob->name),
                              k);
    ob->named = name != NULL;
    const cJSON *shape = cJSON_GetObjectItemCaseSensitive(o, "shape");
    json_path_key(q, p, "shape");
    if (!shape)
        return scene_fail(c, q, "missing (expected mesh, sphere, box, prism, quad or revolution)");
    if (!cJSON_IsString(shape))
        return scene_fail(c, q, "expected a string, got %s", json_type_name(shape));
    const cJSON *mat = cJSON_GetObjectItemCaseSensitive(o, "material");
    json_path_key(q, p, "material");
    if (!mat) return scene_fail(c, q, "missing (expected the name of a material)");
    if (!cJSON_IsString(mat))
        return scene_fail(c, q, "expected a string, got %s", json_type_name(mat));
    ob->material = scene_find_material(s, mat->valuestring);
    if (ob->material < 0)
        return scene_fail(c, q, "unknown material \"%s\"", diag_value(mat->valuestring));

    Mesh m, tex;
    mesh_init(&m);
    mesh_init(&tex);
    mat4 xf;
    int rc = -1;
    if (scene_load_shape(c, o, p, shape->valuestring, s, &m) ||
        scene_load_transform_framed(c, o, p, s, &xf))
        goto done;
    if (strcmp(shape->valuestring, "sphere") == 0) scene_sphere_transform(o, s, &xf);
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(o, "texture");
    if (t) {
        json_path_key(q, p, "texture");
        if (s->ntextured == VBCL_MAX_TEXTURED) {
            scene_fail(c, q, "at most %d objects per scene may carry a volume texture",
                       VBCL_MAX_TEXTURED);
            goto done;
        }
        vec3 lo, hi;
        mesh_bounds(&m, &lo, &hi);
        if (scene_load_texture(c, t, q, s, lo, hi, &tex, &ob->tex_material)) goto done;
        scene_texture_check_faces(c, q, &m, &tex, s);
        ob->tex_slot = s->ntextured++;
    }
    ob->is_host = t != NULL || s->materials[ob->material].gpu.k_global > 0.0f;
    if (ob->is_host && mesh_check_closed(&m, merr, sizeof merr)) {
        scene_fail(c, p, "%s object must be a closed, consistently oriented mesh: %s",
                   t ? "a textured" : "a transparent (k_global > 0)", merr);
        goto done;
    }
    mesh_transform(&m, &xf);
    mesh_transform(&tex, &xf);
    if (check_finite(c, &m, p) || check_finite(c, &tex, p)) goto done;
    if ((uint64_t)s->mesh.ntris + m.ntris + tex.ntris > SCENE_MAX_TRIANGLES) {
        scene_fail(c, p, "the scene has more than %u triangles", SCENE_MAX_TRIANGLES);
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

static int check_hosts_disjoint(Ctx *c, const Scene *s);

int scene_load_objects(Ctx *c, const cJSON *j, Scene *s)
{
    if (!j) return scene_fail(c, "objects", "missing (expected an array of objects)");
    if (!cJSON_IsArray(j))
        return scene_fail(c, "objects", "expected an array, got %s", json_type_name(j));
    int n = cJSON_GetArraySize(j);
    if (n == 0) return scene_fail(c, "objects", "the scene is empty: expected at least one object");
    if (n > 0x7fffffff / 2) return scene_fail(c, "objects", "too many objects");
    if (scene_count_triangles(c, j)) return -1;
    s->objects = calloc((size_t)n, sizeof *s->objects);
    if (!s->objects) return scene_fail(c, NULL, "out of memory");
    int i = 0;
    for (const cJSON *o = j->child; o; o = o->next, i++) {
        char p[PATH_MAX_LEN];
        json_path_index(p, "objects", i);
        if (load_object(c, o, p, i, s)) return -1;
        s->nobjects = i + 1;
    }
    if (s->mesh.ntris == 0) return scene_fail(c, "objects", "no triangles to render");
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
 * one host at a time. Refused, each in its own words: surfaces that cross or touch
 * (mesh_parts_meet, the exact test texgen uses for its elements), and, where no surfaces
 * meet, one host nested inside another. Only hosts whose bounding box overlaps another
 * host's are tested. */
static int check_hosts_disjoint(Ctx *c, const Scene *s)
{
    int nh = 0, np = 0, *idx = malloc(sizeof(int) * 2 * (size_t)s->nobjects);
    MeshPart *parts = malloc(sizeof *parts * (size_t)s->nobjects);
    vec3 *box = malloc(sizeof *box * 2 * (size_t)s->nobjects);
    int rc = (!idx || !parts || !box) ? scene_fail(c, NULL, "out of memory") : 0;
    int *pobj = idx ? idx + s->nobjects : NULL; /* per part: its object */
    for (int i = 0; !rc && i < s->nobjects; i++)
        if (s->objects[i].is_host) {
            object_bounds(s, &s->objects[i], &box[2 * nh], &box[2 * nh + 1]);
            idx[nh++] = i;
        }
    int nest_in = -1, nest_out = -1; /* a host with a vertex inside another */
    for (int i = 0; !rc && i < nh; i++) {
        int near = 0;
        for (int j = 0; j < nh; j++) {
            vec3 l0 = box[2 * i], h0 = box[2 * i + 1], l1 = box[2 * j], h1 = box[2 * j + 1];
            if (j == i || l0.x > h1.x || l1.x > h0.x || l0.y > h1.y || l1.y > h0.y || l0.z > h1.z ||
                l1.z > h0.z)
                continue;
            near = 1;
            if (nest_in < 0 && vertex_inside(s, &s->objects[idx[i]], &s->objects[idx[j]])) {
                nest_in = idx[i];
                nest_out = idx[j];
            }
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
    if (meet < 0) rc = scene_fail(c, NULL, "out of memory");
    if (meet > 0)
        rc = scene_fail(c, "objects",
                        "%s and %s overlap or touch: their surfaces meet (triangle %u of one "
                        "meets triangle %u of the other); dielectric and textured objects must "
                        "be apart (docs/scene-format.md)",
                        diag_value(s->objects[pobj[pa]].name),
                        diag_value(s->objects[pobj[pb]].name), ta, tb);
    else if (!rc && nest_in >= 0)
        rc =
            scene_fail(c, "objects",
                       "%s lies wholly inside %s (nested); dielectric and textured objects must "
                       "be apart: put a volume inside another as a texture "
                       "(docs/scene-format.md)",
                       diag_value(s->objects[nest_in].name), diag_value(s->objects[nest_out].name));
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
