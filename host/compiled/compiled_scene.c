/* compiled_scene.c — the scene into the kernels' layout, on the host: triangles with their
 * tags, smooth normals, the grid's leaves and the objects' ranges four triangles at a time,
 * materials, surface patterns (Fourier coefficients and projected images), dispersion band
 * tables, the environment's texels, camera tiles and frame constants. */
#include "compiled_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dispersion.h"
#include "kernel_features.h"
#include "objects.h"
#include "texgen.h"

/* Fills the camera of the frame from the scene's eye, look_at, up and fov. */
static void frame_camera(const Scene *s, VbCamera *c)
{
    vec3 fwd = v3_norm(v3_sub(s->look_at, s->eye));
    vec3 right = v3_norm(v3_cross(fwd, s->up));
    vec3 up = v3_cross(right, fwd);
    float th = tanf(s->fov * 0.5f * (float)(M_PI / 180.0));
    float aspect = (float)s->width / (float)s->height;
    right = v3_scale(right, th * aspect);
    up = v3_scale(up, th);
    float *dst[4] = {c->eye, c->forward, c->right, c->up};
    vec3 src[4] = {s->eye, fwd, right, up};
    for (int i = 0; i < 4; i++) {
        dst[i][0] = src[i].x;
        dst[i][1] = src[i].y;
        dst[i][2] = src[i].z;
        dst[i][3] = 0.0f;
    }
}

/* The host's packed top cells (grid.h) are the kernels' VbGridCell array. */
VBCL_STATIC_ASSERT(GRID_SUB_BITS == VBCL_GRID_SUB_BITS, grid_sub_bits);
VBCL_STATIC_ASSERT(sizeof(VbGridCell) == 2 * sizeof(uint32_t), grid_cell_words);

static void frame_grid(const Grid *g, VbGrid *out)
{
    memset(out, 0, sizeof *out);
    for (int i = 0; i < 3; i++) {
        out->lo[i] = g->lo[i];
        out->hi[i] = g->hi[i];
        out->cell[i] = g->cell[i];
        out->inv_cell[i] = 1.0f / g->cell[i];
        out->n[i] = g->n[i];
    }
}

/* Triangles as the kernels read them, the tag in the w of the first vertex. */
static VbTriangle *pack_triangles(const Scene *s)
{
    const Mesh *m = &s->mesh;
    VbTriangle *t = calloc(m->ntris, sizeof *t);
    if (!t) return NULL;
    for (uint32_t i = 0; i < m->ntris; i++) {
        float *dst[3] = {t[i].v0, t[i].v1, t[i].v2};
        for (int k = 0; k < 3; k++) {
            vec3 p = m->verts[m->tris[3 * i + k]];
            dst[k][0] = p.x;
            dst[k][1] = p.y;
            dst[k][2] = p.z;
        }
        memcpy(&t[i].v0[3], &s->tri_tag[i], sizeof(uint32_t));
    }
    return t;
}

/* Appends triangle t to the quads being packed: lane *lane of quad *k, or lane 0 of the
 * next quad (its lanes padded with tri -1) where that one is full. */
static void quad_put(VbLeafQuad *q, size_t *k, uint32_t *lane, const VbTriangle *tris, uint32_t t)
{
    if (*lane == 4) {
        *lane = 0;
        (*k)++;
    }
    if (*lane == 0)
        for (int j = 0; j < 4; j++) q[*k].tri[j] = -1;
    const float *v[3] = {tris[t].v0, tris[t].v1, tris[t].v2};
    for (int a = 0; a < 9; a++) q[*k].xyz[a][*lane] = v[a / 3][a % 3];
    q[*k].tri[(*lane)++] = (int)t;
}

/* Ends a run of quad_put: the quad in progress is done. */
static void quad_end(size_t *k, uint32_t *lane)
{
    if (*lane > 0) (*k)++;
    *lane = 0;
}

/* The quads of record o's own triangles (tex 0) or of its texture's (tex 1) for the shadow
 * cone test's sets: the ranges light_cone_objects may add to one (a record of at most
 * VBCL_OBJECT_SET_MAX_TRIS / 2 triangles; with its texture, where that has no parts, if
 * the two together fit in a set), else 0. */
static uint32_t object_range_quads(const VbObject *o, int tex)
{
    int own = o->ntris <= VBCL_OBJECT_SET_MAX_TRIS / 2;
    int fits = tex ? own && o->nelems == 0u && o->ntris + o->ntex <= VBCL_OBJECT_SET_MAX_TRIS : own;
    return fits ? ((tex ? o->ntex : o->ntris) + 3u) / 4u : 0u;
}

/* How many quads the records' ranges take (object_range_quads). */
static size_t objects_quads(const VbObject *objs, size_t nobjs)
{
    size_t n = 0;
    for (size_t i = 0; i < nobjs; i++)
        n += object_range_quads(&objs[i], 0) + object_range_quads(&objs[i], 1);
    return n;
}

/* The triangles four at a time (VbLeafQuad, kernels/types.h). First the leaves': leaf l's
 * quads are quads[start[l] .. start[l + 1] - 1], first those of its scene triangles and
 * then those of its texture triangles, each in the order of g->leaf_tris, a kind's last quad
 * padded with tri -1, so that all real lanes of a quad share VBCL_TAG_TEXTURE. Then the
 * records' ranges (object_range_quads), each in the order of its triangles, whose first
 * quads go into the records (quad_tri, quad_tex; VBCL_NO_QUADS: none); a range is of one
 * kind (an object's own triangles, or texture ones), so its quads share the tag too (which
 * quads_any reads from lane 0). Returns the quads
 * (NULL: out of memory; *start too) and their number in *nquads. */
static VbLeafQuad *pack_quads(const Grid *g, const uint32_t *tri_tag, const VbTriangle *tris,
                              VbObject *objs, size_t nobjs, uint32_t **start, uint32_t *nquads)
{
    size_t n = grid_leaf_quads(g, tri_tag, VBCL_TAG_TEXTURE) + objects_quads(objs, nobjs);
    *nquads = (uint32_t)n;
    *start = malloc(sizeof **start * ((size_t)g->nleaves + 1));
    VbLeafQuad *q = calloc(n ? n : 1, sizeof *q);
    if (!q || !*start) {
        free(q);
        free(*start);
        *start = NULL;
        return NULL;
    }
    size_t k = 0;
    uint32_t lane = 0;
    for (uint32_t l = 0; l < g->nleaves; l++) {
        (*start)[l] = (uint32_t)k;
        for (int texture = 0; texture < 2; texture++) {
            for (uint32_t i = g->leaf_start[l]; i < g->leaf_start[l + 1]; i++) {
                uint32_t t = g->leaf_tris[i];
                if (((tri_tag[t] & VBCL_TAG_TEXTURE) != 0u) == texture)
                    quad_put(q, &k, &lane, tris, t);
            }
            quad_end(&k, &lane);
        }
    }
    (*start)[g->nleaves] = (uint32_t)k;
    for (size_t i = 0; i < nobjs; i++) {
        VbObject *o = &objs[i];
        for (int tex = 0; tex < 2; tex++) {
            uint32_t first = tex ? o->first_tex : o->first_tri, count = tex ? o->ntex : o->ntris;
            uint32_t *dst = tex ? &o->quad_tex : &o->quad_tri;
            *dst = VBCL_NO_QUADS;
            if (object_range_quads(o, tex) == 0u) continue;
            *dst = (uint32_t)k;
            for (uint32_t t = first; t < first + count; t++) quad_put(q, &k, &lane, tris, t);
            quad_end(&k, &lane);
        }
    }
    return q;
}

static VbTriNormals *pack_normals(const Scene *s)
{
    const Mesh *m = &s->mesh;
    VbTriNormals *t = calloc(m->ntris ? m->ntris : 1, sizeof *t);
    if (!t || !m->normals) return t;
    for (uint32_t i = 0; i < m->ntris; i++) {
        float *dst[3] = {t[i].n0, t[i].n1, t[i].n2};
        for (int k = 0; k < 3; k++) {
            vec3 n = m->normals[m->tris[3 * i + k]];
            dst[k][0] = n.x;
            dst[k][1] = n.y;
            dst[k][2] = n.z;
        }
    }
    return t;
}

/* The texels buffer under construction: projected images, the band tables, the environment. */
typedef struct Texels {
    float *v;
    size_t n; /* in texels of 4 floats */
} Texels;

/* Makes room for more texels; returns the first new one, or NULL (out of memory). */
static float *texels_grow(Texels *t, size_t more)
{
    float *grown = realloc(t->v, sizeof(float) * 4 * (t->n + more));
    if (!grown) return NULL;
    t->v = grown;
    float *first = grown + 4 * t->n;
    t->n += more;
    return first;
}

/* Material i's surface pattern into pt (images appended to tx). Returns 0, or 2 (the
 * pattern cannot be made, the message naming the material) or 1 (out of memory). */
static int pattern_make(const Scene *s, int i, VbPattern *pt, Texels *tx, char *err, size_t errlen)
{
    const ScenePattern *sp = &s->materials[i].pattern;
    char perr[512];
    pt->kind = sp->kind;
    pt->axes = sp->axes; /* a checker's axes, a projection's axis */
    for (int k = 0; k < 3; k++) {
        pt->origin[k] = sp->origin[k];
        pt->inv_size[k] = 1.0f / sp->size[k];
    }
    if (sp->kind == VBCL_PATTERN_CHECKER) {
        for (int c = 0; c < 2; c++)
            for (int k = 0; k < 3; k++) pt->colours[c][k] = sp->colours[c][k];
        return 0;
    }
    if (sp->kind == VBCL_PATTERN_FOURIER) {
        if (!texgen_fourier_init(&pt->fourier, sp->terms, sp->contrast, sp->freq, sp->seed, perr,
                                 sizeof perr))
            return 0;
        snprintf(err, errlen, "%s: materials.%s.pattern: %s", s->path, s->materials[i].name, perr);
        return 2;
    }
    int w, h, rc = 0;
    float *img = NULL;
    if (texgen_projection_load(sp->image, &w, &h, &img, perr, sizeof perr)) {
        snprintf(err, errlen, "%s: materials.%s.pattern.image: %s", s->path, s->materials[i].name,
                 perr);
        return 2;
    }
    size_t first = tx->n;
    float *dst = texels_grow(tx, (size_t)w * (size_t)h);
    if (!dst) {
        rc = 1;
        snprintf(err, errlen, "out of memory for the image %s", sp->image);
    } else {
        memcpy(dst, img, sizeof(float) * 4 * (size_t)w * (size_t)h);
        pt->width = w;
        pt->height = h;
        pt->texel_offset = (unsigned)first;
    }
    free(img);
    return rc;
}

/* The side data after the images: the bands' rgb weights (their first float's index into
 * *band_weights), then per dispersive material its band table (eta, transmitted fraction)
 * at each band's centre, its index into mats[i].disp. Returns 0, or 1 (out of memory). */
static int band_tables_make(const Scene *s, VbMaterial *mats, Texels *tx, unsigned *band_weights,
                            char *err, size_t errlen)
{
    int nb = s->bands, ndisp = 0;
    for (int i = 0; i < s->nmaterials; i++) ndisp += mats[i].disp >= 0;
    size_t first = tx->n;
    float *t = texels_grow(tx, (size_t)nb * (size_t)(1 + ndisp));
    if (!t) {
        snprintf(err, errlen, "out of memory for the band tables");
        return 1;
    }
    DispBand band[DISP_MAX_BANDS];
    disp_layout_bands(s->band_layout, nb, band);
    *band_weights = (unsigned)(4 * first);
    for (int b = 0; b < nb; b++, t += 4) {
        memcpy(t, band[b].rgb, sizeof band[b].rgb);
        t[3] = (float)band[b].centre;
    }
    for (int i = 0; i < s->nmaterials; i++) {
        if (mats[i].disp < 0) continue;
        const DispModel *d = &s->materials[i].disp;
        mats[i].disp = (int)(t - tx->v);
        for (int b = 0; b < nb; b++, t += 4) {
            t[0] = (float)disp_eta(d, band[b].centre);
            t[1] = (float)disp_band_transmit(d, band[b].lo, band[b].hi);
            t[2] = t[3] = 0.0f;
        }
    }
    return 0;
}

/* The environment's texels (the image times its scale) appended to tx, and where they are
 * and how they turn into e. Returns 0, or 1 (out of memory). */
static int environment_make(const Scene *s, Texels *tx, VbEnvironment *e, char *err, size_t errlen)
{
    const SceneEnvironment *se = &s->env;
    size_t n = (size_t)se->width * (size_t)se->height, first = tx->n;
    float *t = texels_grow(tx, n);
    if (!t) {
        snprintf(err, errlen, "out of memory for the environment %s", se->file);
        return 1;
    }
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 4; k++) t[4 * i + k] = se->texels[4 * i + k] * se->scale;
    memset(e, 0, sizeof *e);
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++) e->rot[r][k] = se->to_env[r][k];
    e->first = (unsigned)first;
    e->width = se->width;
    e->height = se->height;
    return 0;
}

/* The frame constants of s: camera, grid, background, lights, feelers, media, limits. */
static void frame_fill(const Scene *s, const Grid *g, unsigned band_weights, VbFrame *f)
{
    memset(f, 0, sizeof *f);
    frame_camera(s, &f->camera);
    frame_grid(g, &f->grid);
    memcpy(f->background, s->background, sizeof s->background);
    memcpy(f->ambient, s->ambient, sizeof s->ambient);
    f->width = s->width;
    f->height = s->height;
    f->window_width = s->width; /* the whole image, unless the frame driver crops it */
    f->window_height = s->height;
    f->nlights = (unsigned)s->nlights;
    f->ntris = s->mesh.ntris;
    unsigned strata = (unsigned)lround(sqrt((double)s->shadow_samples));
    f->shadow_strata = strata < 1 ? 1 : strata;
    f->seed = s->seed;
    /* n x n feelers with n a power of two are a scrambled (0, 2)-net (light_cap_uv); the
     * test is made here, since a popcount in the kernel is an LLVM intrinsic that some
     * OpenCL implementations (Oclgrind) do not provide */
    f->flags = !s->shadow_jitter                             ? VBCL_FRAME_FIXED_FEELERS
               : (f->shadow_strata & (f->shadow_strata - 1)) ? 0u
                                                             : VBCL_FRAME_NET_FEELERS;
    if (s->shadow_cone_test && s->nobjects <= VBCL_CONE_TEST_MAX_OBJECTS)
        f->flags |= VBCL_FRAME_CONE_TEST;
    if (s->shadow_by_weight) f->flags |= VBCL_FRAME_WEIGHTED_FEELERS;
    if (s->shadow_by_weight && s->sample_shares && s->aa_threshold > 0.0f)
        f->flags |= VBCL_FRAME_SAMPLE_SHARES;
    f->nobjects = (unsigned)s->nobjects;
    f->penumbra_factor = (unsigned)s->penumbra_feelers;
    scene_medium_at(s, s->eye, &f->camera_medium);
    f->air_material = (unsigned)s->nmaterials;
    f->min_weight = s->min_weight;
    f->max_depth = s->max_depth;
    f->bands = s->bands;
    f->band_weights = band_weights;
}

/* The materials' surface patterns, with dispersion the band tables, and the environment
 * into cs (materials' pattern and disp set; band_weights: the bands' first texel float; env:
 * the environment's place in the texels). Returns 0, 2 (a pattern the scene cannot have, the
 * message naming the material) or 1 (out of memory). */
static int patterns_make(CompiledScene *cs, const Scene *s, unsigned *band_weights,
                         VbEnvironment *env, char *err, size_t errlen)
{
    VbMaterial *mats = cs->materials;
    cs->patterns = calloc((size_t)s->nmaterials + 1, sizeof *cs->patterns);
    Texels tx = {NULL, 0};
    int rc = 0;
    if (!cs->patterns) {
        snprintf(err, errlen, "out of memory for the patterns");
        return 1;
    }
    for (int i = 0; i < s->nmaterials && !rc; i++) {
        if (!s->materials[i].pattern.kind) continue;
        rc = pattern_make(s, i, &cs->patterns[cs->npatterns], &tx, err, errlen);
        mats[i].pattern = cs->npatterns++;
    }
    if (!rc && (cs->features & VBCL_FEATURE_DISPERSION)) {
        rc = band_tables_make(s, mats, &tx, band_weights, err, errlen);
    } else {
        for (int i = 0; i < s->nmaterials; i++) mats[i].disp = -1;
    }
    if (!rc && s->env.file) rc = environment_make(s, &tx, env, err, errlen);
    cs->texels = tx.v;
    cs->ntexels = tx.n;
    return rc;
}

/* The materials (the scene's, then the medium outside every host: vacuum, eta 1), with
 * their patterns and band tables, and the environment. Returns as patterns_make. */
static int materials_make(CompiledScene *cs, const Scene *s, unsigned *band_weights,
                          VbEnvironment *env, char *err, size_t errlen)
{
    cs->materials = calloc((size_t)s->nmaterials + 1, sizeof *cs->materials);
    if (!cs->materials) {
        snprintf(err, errlen, "out of memory for the materials");
        return 1;
    }
    cs->nmaterials = s->nmaterials + 1;
    VbMaterial *air = &cs->materials[s->nmaterials];
    for (int i = 0; i < s->nmaterials; i++) cs->materials[i] = s->materials[i].gpu;
    air->eta = 1.0f;
    air->pattern = -1;
    air->disp = -1;
    int rc = patterns_make(cs, s, band_weights, env, err, errlen);
    air->k_global = 1.0f;
    return rc;
}

/* The camera tiles of s (camera_tiles.h) from the packed triangles into cs->cam and the
 * frame's cam_tiles, or none (cam.nx = 0) where s turns them off or they would take more
 * than 64 references per triangle and per tile, CAM_TILES_MAX_REFS in all (about 100 MB),
 * or one allocation of max_alloc bytes. Returns 0 or 1 (out of memory). */
#define CAM_TILES_MAX_REFS ((size_t)1 << 21)
static int camera_tiles_make(CompiledScene *cs, const Scene *s, size_t max_alloc, char *err,
                             size_t errlen)
{
    VbCamTiles *ct = &cs->frame.cam_tiles;
    const VbCamera *cam = &cs->frame.camera;
    memset(ct, 0, sizeof *ct);
    size_t ntiles = (size_t)((s->width + VBCL_CAM_TILE - 1) / VBCL_CAM_TILE) *
                    (size_t)((s->height + VBCL_CAM_TILE - 1) / VBCL_CAM_TILE);
    size_t cap = 64 * ((size_t)s->mesh.ntris + ntiles), fit = max_alloc / sizeof(VbLeafQuad);
    cap = cap < CAM_TILES_MAX_REFS ? cap : CAM_TILES_MAX_REFS;
    if (s->camera_tiles && camtiles_build(&cs->cam, cam, s->width, s->height, cs->tris,
                                          s->mesh.ntris, cap < fit ? cap : fit)) {
        snprintf(err, errlen, "out of memory sorting %u triangles into camera tiles",
                 s->mesh.ntris);
        return 1;
    }
    if (!cs->cam.nx) return 0;
    double r2 = 0.0, u2 = 0.0;
    for (int a = 0; a < 3; a++) {
        r2 += (double)cam->right[a] * cam->right[a];
        u2 += (double)cam->up[a] * cam->up[a];
    }
    for (int a = 0; a < 3; a++) {
        ct->right_n[a] = (float)(cam->right[a] / r2);
        ct->up_n[a] = (float)(cam->up[a] / u2);
    }
    ct->nx = cs->cam.nx;
    ct->ny = cs->cam.ny;
    return 0;
}

/* The grid of s into cs->grid. Returns 0, or 2 (a grid the scene cannot have). */
static int grid_make(CompiledScene *cs, const Scene *s, char *err, size_t errlen)
{
    char gerr[256];
    const int *res = (s->grid_res[0] > 0) ? s->grid_res : NULL;
    const int *sub = (s->subgrid_res[0] > 0) ? s->subgrid_res : NULL;
    if (!grid_build_levels(&cs->grid, &s->mesh, res, s->grid_density, sub, s->subgrid_density, gerr,
                           sizeof gerr))
        return 0;
    snprintf(err, errlen, "%s: grid: %s", s->path, gerr);
    return 2;
}

/* What an object's records depend on (objects_make): its triangles, its materials and
 * whether its texture's material lets light through. */
typedef struct KeyObject {
    uint32_t first_tri, ntris, first_tex, ntex;
    int is_host, tex_slot, material, tex_material, tex_clear;
} KeyObject;

/* The inputs of the geometry, copied: the mesh, its tags, the grid settings, the objects. */
typedef struct GeometryKey {
    uint32_t nverts, ntris;
    vec3 *verts, *normals; /* normals NULL without smooth normals */
    uint32_t *tris, *tags;
    int grid_res[3], subgrid_res[3];
    float grid_density, subgrid_density;
    int nobjects;
    KeyObject *objects;
} GeometryKey;

static void key_free(GeometryKey *k)
{
    if (!k) return;
    free(k->verts);
    free(k->normals);
    free(k->tris);
    free(k->tags);
    free(k->objects);
    free(k);
}

/* Object i of s as the key holds it. */
static KeyObject key_object(const Scene *s, int i)
{
    const SceneObject *o = &s->objects[i];
    KeyObject k;
    memset(&k, 0, sizeof k); /* compared with memcmp */
    k.first_tri = o->first_tri;
    k.ntris = o->ntris;
    k.first_tex = o->first_tex_tri;
    k.ntex = o->ntex_tris;
    k.is_host = o->is_host;
    k.tex_slot = o->tex_slot;
    k.material = o->material;
    k.tex_material = o->tex_material;
    k.tex_clear = o->tex_slot >= 0 && s->materials[o->tex_material].gpu.k_global > 0.0f;
    return k;
}

/* A copy of the inputs of s's geometry, or NULL (out of memory). */
static GeometryKey *key_make(const Scene *s)
{
    const Mesh *m = &s->mesh;
    GeometryKey *k = calloc(1, sizeof *k);
    if (!k) return NULL;
    size_t nv = m->nverts ? m->nverts : 1, nt = m->ntris ? m->ntris : 1;
    k->nverts = m->nverts;
    k->ntris = m->ntris;
    k->verts = malloc(sizeof *k->verts * nv);
    k->normals = m->normals ? malloc(sizeof *k->normals * nv) : NULL;
    k->tris = malloc(sizeof *k->tris * 3 * nt);
    k->tags = malloc(sizeof *k->tags * nt);
    k->objects = malloc(sizeof *k->objects * (size_t)(s->nobjects ? s->nobjects : 1));
    if (!k->verts || (m->normals && !k->normals) || !k->tris || !k->tags || !k->objects) {
        key_free(k);
        return NULL;
    }
    memcpy(k->verts, m->verts, sizeof *k->verts * m->nverts);
    if (m->normals) memcpy(k->normals, m->normals, sizeof *k->normals * m->nverts);
    memcpy(k->tris, m->tris, sizeof *k->tris * 3 * m->ntris);
    memcpy(k->tags, s->tri_tag, sizeof *k->tags * m->ntris);
    memcpy(k->grid_res, s->grid_res, sizeof k->grid_res);
    memcpy(k->subgrid_res, s->subgrid_res, sizeof k->subgrid_res);
    k->grid_density = s->grid_density;
    k->subgrid_density = s->subgrid_density;
    k->nobjects = s->nobjects;
    for (int i = 0; i < s->nobjects; i++) k->objects[i] = key_object(s, i);
    return k;
}

/* Whether s's geometry is made of exactly the inputs of k. */
static int key_equal(const GeometryKey *k, const Scene *s)
{
    const Mesh *m = &s->mesh;
    if (!k || k->nverts != m->nverts || k->ntris != m->ntris || !k->normals != !m->normals ||
        k->nobjects != s->nobjects || k->grid_density != s->grid_density ||
        k->subgrid_density != s->subgrid_density ||
        memcmp(k->grid_res, s->grid_res, sizeof k->grid_res) ||
        memcmp(k->subgrid_res, s->subgrid_res, sizeof k->subgrid_res) ||
        memcmp(k->verts, m->verts, sizeof *k->verts * m->nverts) ||
        (m->normals && memcmp(k->normals, m->normals, sizeof *k->normals * m->nverts)) ||
        memcmp(k->tris, m->tris, sizeof *k->tris * 3 * m->ntris) ||
        memcmp(k->tags, s->tri_tag, sizeof *k->tags * m->ntris))
        return 0;
    for (int i = 0; i < s->nobjects; i++) {
        KeyObject o = key_object(s, i);
        if (memcmp(&o, &k->objects[i], sizeof o)) return 0;
    }
    return 1;
}

/* The geometry: grid, object records, triangles, smooth normals and quads. Returns as
 * compiled_scene_build. */
static int geometry_make(CompiledScene *cs, const Scene *s, char *err, size_t errlen)
{
    int rc = grid_make(cs, s, err, errlen);
    if (rc) return rc;
    cs->objects = objects_make(s, &cs->nobjects);
    cs->ntris = s->mesh.ntris;
    cs->tris = pack_triangles(s);
    if (cs->features & VBCL_FEATURE_SMOOTH_NORMALS) cs->normals = pack_normals(s);
    if (cs->objects && cs->tris)
        cs->quads = pack_quads(&cs->grid, s->tri_tag, cs->tris, cs->objects, cs->nobjects,
                               &cs->leaf_start, &cs->nquads);
    if (cs->objects && cs->tris && cs->quads &&
        (cs->normals || !(cs->features & VBCL_FEATURE_SMOOTH_NORMALS)))
        return 0;
    snprintf(err, errlen, "out of memory packing %u triangles", s->mesh.ntris);
    return 1;
}

/* Frees the geometry of cs (what geometry_make made, and its key). */
static void geometry_free(CompiledScene *cs)
{
    grid_free(&cs->grid);
    free(cs->tris);
    free(cs->normals);
    free(cs->leaf_start);
    free(cs->quads);
    free(cs->objects);
    key_free(cs->key);
    cs->tris = NULL;
    cs->normals = NULL;
    cs->leaf_start = NULL;
    cs->quads = NULL;
    cs->objects = NULL;
    cs->key = NULL;
    cs->ntris = cs->nquads = 0;
    cs->nobjects = 0;
}

/* Frees what every frame makes again: materials, patterns, texels. */
static void shading_free(CompiledScene *cs)
{
    free(cs->materials);
    free(cs->patterns);
    free(cs->texels);
    cs->materials = NULL;
    cs->patterns = NULL;
    cs->texels = NULL;
    cs->nmaterials = cs->npatterns = 0;
    cs->ntexels = 0;
}

/* The camera tiles again where the geometry, the camera or the image size changed. Returns
 * as camera_tiles_make. */
static int camera_tiles_update(CompiledScene *cs, const Scene *s, VbCamTiles kept, size_t max_alloc,
                               char *err, size_t errlen)
{
    cs->camera_tiles_built = cs->geometry_built || s->width != cs->key_width ||
                             s->height != cs->key_height ||
                             memcmp(&cs->frame.camera, &cs->key_camera, sizeof cs->key_camera);
    if (!cs->camera_tiles_built) {
        cs->frame.cam_tiles = kept;
        return 0;
    }
    camtiles_free(&cs->cam);
    memset(&cs->cam, 0, sizeof cs->cam);
    cs->key_camera = cs->frame.camera;
    cs->key_width = s->width;
    cs->key_height = s->height;
    return camera_tiles_make(cs, s, max_alloc, err, errlen);
}

int compiled_scene_update(CompiledScene *cs, const Scene *s, size_t max_alloc, char *err,
                          size_t errlen)
{
    int rc = 0;
    cs->features = features_of_scene(s);
    cs->geometry_built = !key_equal(cs->key, s);
    if (cs->geometry_built) {
        geometry_free(cs);
        rc = geometry_make(cs, s, err, errlen);
        /* only an animation has a next frame to compare with: a still keeps no copy */
        if (!rc && s->animated && !(cs->key = key_make(s))) {
            snprintf(err, errlen, "out of memory");
            rc = 1;
        }
    }
    shading_free(cs);
    unsigned band_weights = 0;
    VbEnvironment env;
    memset(&env, 0, sizeof env);
    if (!rc) rc = materials_make(cs, s, &band_weights, &env, err, errlen);
    if (rc) return rc;
    VbCamTiles kept = cs->frame.cam_tiles;
    frame_fill(s, &cs->grid, band_weights, &cs->frame);
    cs->frame.env = env;
    cs->frame.flags |= features_frame_flags(cs->features);
    return camera_tiles_update(cs, s, kept, max_alloc, err, errlen);
}

int compiled_scene_build(CompiledScene *cs, const Scene *s, size_t max_alloc, char *err,
                         size_t errlen)
{
    memset(cs, 0, sizeof *cs);
    return compiled_scene_update(cs, s, max_alloc, err, errlen);
}

void compiled_scene_free(CompiledScene *cs)
{
    geometry_free(cs);
    shading_free(cs);
    camtiles_free(&cs->cam);
    memset(cs, 0, sizeof *cs);
}
