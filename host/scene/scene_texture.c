/* scene_texture.c — an object's volume texture: a mesh file of closed elements or one
 * generated inline, mapped from its texture block onto the host object's box. */
#include "scene_parts.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cache.h"
#include "diag.h"
#include "texgen.h"

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

int scene_texgen_enabled = 1;

/* A mesh file of texture elements at path into tex, and the block its header declares
 * (*has_declared 0 when none). */
static int load_texture_file(Ctx *c, const char *q, const char *path, Mesh *tex, float declared[6],
                             int *has_declared)
{
    char head[8192], merr[512];
    if (mesh_load_head(path, tex, head, sizeof head, merr, sizeof merr))
        return scene_fail(c, q, "%s", merr);
    *has_declared = read_block_comment(head, declared);
    return 0;
}

/* The generated set's elements as one mesh, exactly as writing it to PLY and reading it
 * back gives it: elements in order, normals only when every element has them (unit
 * length, as the reader makes them), the block when it is valid. */
static int texset_to_mesh(Ctx *c, const char *q, const TexSet *t, Mesh *tex, float declared[6],
                          int *has_declared)
{
    int normals = t->count > 0;
    for (int e = 0; e < t->count; e++) {
        if (mesh_append(tex, &t->elems[e])) return scene_fail(c, NULL, "out of memory");
        normals = normals && t->elems[e].normals;
    }
    if (!normals) {
        free(tex->normals);
        tex->normals = NULL;
    }
    for (uint32_t v = 0; normals && v < tex->nverts; v++)
        tex->normals[v] = v3_norm(tex->normals[v]);
    if (tex->ntris == 0) return scene_fail(c, q, "the generated texture has no faces");
    *has_declared = 1;
    for (int i = 0; i < 3; i++) {
        declared[i] = t->block_lo[i];
        declared[i + 3] = t->block_hi[i];
        *has_declared = *has_declared && isfinite(declared[i]) && isfinite(declared[i + 3]) &&
                        declared[i + 3] > declared[i];
    }
    return 0;
}

/* Splits the arguments of objects[i].texture.generate into argv (argv[0] the method),
 * in buf. */
static int split_args(Ctx *c, const char *q, const char *args, char *buf, size_t n, char **argv,
                      int *argc)
{
    *argc = 0;
    if (strlen(args) >= n - 1) return scene_fail(c, q, "too long");
    snprintf(buf, n, "%s", args);
    char *save = NULL;
    for (char *tok = strtok_r(buf, " \t\n", &save); tok; tok = strtok_r(NULL, " \t\n", &save)) {
        if (*argc == 61) return scene_fail(c, q, "too many arguments");
        if (!strcmp(tok, "-o") || !strcmp(tok, "--output"))
            return scene_fail(c, q,
                              "give the texgen arguments without -o: the scene chooses the file");
        argv[(*argc)++] = tok;
    }
    argv[*argc] = NULL;
    return 0;
}

/* Parses argv (bomb or deform) as `vbcl texgen` does and runs the generator into t. */
static int run_texgen(Ctx *c, const char *q, int argc, char **argv, TexSet *t)
{
    char err[1024];
    TexgenOpts o;
    BombParams bp;
    DeformParams dp;
    int bomb = !strcmp(argv[0], "bomb");
    int rc = bomb ? texgen_bomb_args(argc, argv, &bp, &o, err, sizeof err)
                  : texgen_deform_args(argc, argv, &dp, &o, err, sizeof err);
    if (!rc && o.help)
        return scene_fail(c, q, "expected the options of vbcl texgen %s, not %s (docs/texgen.md)",
                          argv[0], "--help");
    if (!rc && !scene_texgen_enabled)
        return scene_fail(c, q, "this program cannot generate textures");
    if (!rc)
        rc = bomb ? texgen_bomb(&bp, t, err, sizeof err) : texgen_deform(&dp, t, err, sizeof err);
    if (rc) return scene_fail(c, q, "vbcl texgen %s: %s", argv[0], err);
    return 0;
}

/* objects[i].texture.generate, the arguments of `vbcl texgen bomb|deform`, into tex and the
 * block it declares. Generated textures are cached ($VBCL_CACHE_DIR/textures/HASH.ply, see
 * cache.h): generating wood or marble (deform, with its exact disjointness check) takes
 * about 0.5 s, reading the file back a few milliseconds, so a cache hit reads the file; a
 * miss generates in memory, uses that, and writes the file for the next time (a cache that
 * cannot be written only makes the next load slower). */
static int generate_texture(Ctx *c, const char *q, const char *args, Mesh *tex, float declared[6],
                            int *has_declared)
{
    char dir[4096], path[4200], buf[1024], *argv[64], err[512];
    int argc;
    size_t w0 = strspn(args, " \t\n"), w1 = strcspn(args + w0, " \t\n");
    if ((w1 == 7 && !strncmp(args + w0, "fourier", 7)) ||
        (w1 == 7 && !strncmp(args + w0, "project", 7)))
        return scene_fail(c, q,
                          "texgen %.7s makes an image, a surface pattern, not a volume texture: "
                          "give the material a \"pattern\" {\"type\": \"%s\"} "
                          "(docs/scene-format.md)",
                          args + w0, args[w0] == 'f' ? "fourier" : "projection");
    if (!(w1 == 4 && !strncmp(args + w0, "bomb", 4)) &&
        !(w1 == 6 && !strncmp(args + w0, "deform", 6)))
        return scene_fail(c, q,
                          "\"%s\": expected \"bomb ...\" or \"deform ...\" (the texgen methods "
                          "that make volume textures)",
                          diag_value(args));
    if (split_args(c, q, args, buf, sizeof buf, argv, &argc)) return -1;
    uint64_t h = cache_hash(cache_hash(CACHE_HASH_SEED, "vbcl texgen 1: "), args);
    int cached = cache_dir("textures", dir, sizeof dir) != NULL;
    if (cached) snprintf(path, sizeof path, "%s/%016llx.ply", dir, (unsigned long long)h);
    if (cached && access(path, R_OK) == 0) { /* generated before: used if whole */
        char why[128];
        if (cache_check_seal(path, why, sizeof why) == 0)
            return load_texture_file(c, q, path, tex, declared, has_declared);
        diag_print("vbcl", "%s: the cached texture is damaged (%s): generating it again", path,
                   why);
        cache_remove(path);
    }
    TexSet t;
    if (run_texgen(c, q, argc, argv, &t)) return -1;
    int rc = texset_to_mesh(c, q, &t, tex, declared, has_declared);
    if (!rc && cached && texset_write(&t, path, err, sizeof err) == 0)
        cache_seal(path, err, sizeof err);
    texset_free(&t);
    return rc;
}

/* Loads objects[i].texture into tex, in the object's own space (before its transform). */
int scene_load_texture(Ctx *c, const cJSON *t, const char *p, const Scene *s, vec3 host_lo,
                       vec3 host_hi, Mesh *tex, int *material)
{
    static const char *const keys[] = {"file", "generate", "material", "block", "transform", NULL};
    char q[PATH_MAX_LEN];
    if (json_expect_object(c, t, p) || json_check_keys(c, t, p, keys)) return -1;
    const cJSON *mat = cJSON_GetObjectItemCaseSensitive(t, "material");
    json_path_key(q, p, "material");
    if (!mat) return scene_fail(c, q, "missing (expected the name of the texture's material)");
    if (!cJSON_IsString(mat))
        return scene_fail(c, q, "expected a string, got %s", json_type_name(mat));
    *material = scene_find_material(s, mat->valuestring);
    if (*material < 0)
        return scene_fail(c, q, "unknown material \"%s\"", diag_value(mat->valuestring));
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(t, "file");
    const cJSON *g = cJSON_GetObjectItemCaseSensitive(t, "generate");
    char full[4096], merr[512];
    const char *shown = "the generated texture";
    float declared[6];
    int has_declared = 0;
    if (f && g) return scene_fail(c, p, "give \"file\" or \"generate\", not both");
    if (g) {
        json_path_key(q, p, "generate");
        if (!cJSON_IsString(g) || !g->valuestring[0])
            return scene_fail(c, q,
                              "expected the arguments of vbcl texgen, such as \"bomb --count 30\"");
        if (generate_texture(c, q, g->valuestring, tex, declared, &has_declared)) return -1;
    } else {
        json_path_key(q, p, "file");
        if (!f)
            return scene_fail(
                c, q, "missing (expected a mesh file of closed texture elements, or \"generate\")");
        if (!cJSON_IsString(f) || !f->valuestring[0])
            return scene_fail(c, q, "expected a file name, got %s", json_type_name(f));
        scene_join_path(full, sizeof full, s->dir, f->valuestring);
        shown = f->valuestring;
        if (load_texture_file(c, q, full, tex, declared, &has_declared)) return -1;
    }
    if (mesh_check_closed(tex, merr, sizeof merr))
        return scene_fail(c, q, "%s: texture elements must be closed and consistently oriented: %s",
                          shown, merr);
    float block[6];
    const cJSON *bj = cJSON_GetObjectItemCaseSensitive(t, "block");
    json_path_key(q, p, "block");
    if (bj) {
        if (json_read_vec(c, bj, q, 6, -FLT_MAX, FLT_MAX, block)) return -1;
        for (int k = 0; k < 3; k++)
            if (!(block[k + 3] > block[k]))
                return scene_fail(
                    c, q, "expected [x0, y0, z0, x1, y1, z1] with x1 > x0, y1 > y0, z1 > z0");
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
    if (scene_load_transform(c, t, p, &xf)) return -1;
    mat4 map = texture_mapping(block, host_lo, host_hi, &xf);
    if (mat4_det3(&map) == 0.0) return scene_fail(c, p, "the texture mapping is degenerate");
    mesh_transform(tex, &map);
    return 0;
}

static float v3_comp(vec3 v, int k)
{
    return k == 0 ? v.x : (k == 1 ? v.y : v.z);
}

/* Triangles of m whose three vertices lie within eps of the plane (axis k) = w. */
static uint32_t tris_in_plane(const Mesh *m, int k, float w, float eps)
{
    uint32_t n = 0;
    for (uint32_t t = 0; t < m->ntris; t++) {
        int in = 1;
        for (int j = 0; j < 3 && in; j++)
            in = fabsf(v3_comp(m->verts[m->tris[3 * t + j]], k) - w) <= eps;
        n += (uint32_t)in;
    }
    return n;
}

void scene_texture_check_faces(Ctx *c, const char *p, const Mesh *host, const Mesh *tex, Scene *s)
{
    if (s->warning[0] || host->ntris == 0 || tex->ntris == 0) return;
    vec3 lo, hi;
    mesh_bounds(host, &lo, &hi);
    float size = fmaxf(hi.x - lo.x, fmaxf(hi.y - lo.y, hi.z - lo.z));
    for (int k = 0; k < 6; k++) {
        float w = v3_comp(k < 3 ? lo : hi, k % 3);
        float eps = 1e-5f * fmaxf(size, fabsf(w)); /* about 100 ulps: a float's mapping */
        if (tris_in_plane(host, k % 3, w, eps) == 0) continue;
        uint32_t n = tris_in_plane(tex, k % 3, w, eps);
        if (n == 0) continue;
        diag_format(s->warning, sizeof s->warning,
                    "%s: %s: %u triangles of the texture lie in a face of the object (its plane "
                    "%c = %s, in the object's own coordinates): a ray meets both surfaces at one "
                    "distance, and that face renders as speckle; give \"block\" a margin "
                    "(docs/scene-format.md)",
                    c->file, p, n, "xyz"[k % 3], diag_num(w));
        return;
    }
}
