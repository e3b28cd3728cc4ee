/* device_scene.c — the scene into the kernels' layout and onto the device: triangles with
 * their tags, smooth normals, grid cells, materials, objects, lights, surface patterns
 * (Fourier coefficients and projected images), dispersion band tables, frame constants. */
#include "device_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera_tiles.h"
#include "dispersion.h"
#include "kernel_features.h"
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

/* The texels buffer under construction: projected images, then the band tables. */
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

/* Builds the materials' surface patterns and, with dispersion, the band tables, and
 * uploads them into b->patterns and b->texels; sets mats[i].pattern and mats[i].disp.
 * Returns 0, 2 (a pattern the scene cannot have, the message naming the material) or 1
 * (device, out of memory). */
static int upload_patterns(SceneBuffers *b, VbDevice *dev, const Scene *s, unsigned features,
                           VbMaterial *mats, unsigned *band_weights, char *err, size_t errlen)
{
    VbPattern *pats = calloc((size_t)s->nmaterials + 1, sizeof *pats);
    Texels tx = {NULL, 0};
    int npats = 0, rc = 0;
    if (!pats) return 1;
    for (int i = 0; i < s->nmaterials && !rc; i++) {
        if (!s->materials[i].pattern.kind) continue;
        rc = pattern_make(s, i, &pats[npats], &tx, err, errlen);
        mats[i].pattern = npats++;
    }
    if (!rc && (features & VBCL_FEATURE_DISPERSION)) {
        rc = band_tables_make(s, mats, &tx, band_weights, err, errlen);
    } else {
        for (int i = 0; i < s->nmaterials; i++) mats[i].disp = -1;
    }
    if (!rc) {
        b->patterns = clu_buffer(dev, pats, sizeof *pats * (size_t)npats, CL_MEM_READ_ONLY);
        b->texels = clu_buffer(dev, tx.v, sizeof(float) * 4 * tx.n, CL_MEM_READ_ONLY);
        if (!b->patterns || !b->texels) {
            snprintf(err, errlen, "%s: %s", dev->name, clu_error());
            rc = 1;
        }
    }
    free(pats);
    free(tx.v);
    return rc;
}

/* The camera tiles of s (camera_tiles.h), from its packed triangles, into b and ct, or none (ct->nx
 * = 0, buffers of one element) where s turns them off or they would take more than 64 references
 * per triangle and per tile, CAM_TILES_MAX_REFS in all (about 100 MB), or one allocation. Returns 0
 * or 1 (out of memory, device). */
#define CAM_TILES_MAX_REFS ((size_t)1 << 21)
static int upload_camera_tiles(SceneBuffers *b, VbDevice *dev, const Scene *s,
                               const VbTriangle *tris, VbCamTiles *ct, char *err, size_t errlen)
{
    CamTiles t;
    memset(&t, 0, sizeof t);
    memset(ct, 0, sizeof *ct);
    VbCamera cam;
    frame_camera(s, &cam);
    size_t ntiles = (size_t)((s->width + VBCL_CAM_TILE - 1) / VBCL_CAM_TILE) *
                    (size_t)((s->height + VBCL_CAM_TILE - 1) / VBCL_CAM_TILE);
    size_t cap = 64 * ((size_t)s->mesh.ntris + ntiles), fit = dev->max_alloc / sizeof(VbLeafQuad);
    cap = cap < CAM_TILES_MAX_REFS ? cap : CAM_TILES_MAX_REFS;
    if (s->camera_tiles &&
        camtiles_build(&t, &cam, s->width, s->height, tris, s->mesh.ntris, cap < fit ? cap : fit)) {
        snprintf(err, errlen, "out of memory sorting %u triangles into camera tiles",
                 s->mesh.ntris);
        return 1;
    }
    size_t nstart = t.nx ? (size_t)t.nx * (size_t)t.ny + 1 : 0;
    b->cam_start = clu_buffer(dev, t.start, sizeof(uint32_t) * nstart, CL_MEM_READ_ONLY);
    b->cam_quads = clu_buffer(dev, t.quads, sizeof(VbLeafQuad) * t.nquads, CL_MEM_READ_ONLY);
    b->cam_near = clu_buffer(dev, t.near, sizeof(float) * t.nquads, CL_MEM_READ_ONLY);
    if (t.nx) {
        double r2 = 0.0, u2 = 0.0;
        for (int a = 0; a < 3; a++) {
            r2 += (double)cam.right[a] * cam.right[a];
            u2 += (double)cam.up[a] * cam.up[a];
        }
        for (int a = 0; a < 3; a++) {
            ct->right_n[a] = (float)(cam.right[a] / r2);
            ct->up_n[a] = (float)(cam.up[a] / u2);
        }
        ct->nx = t.nx;
        ct->ny = t.ny;
    }
    camtiles_free(&t);
    if (b->cam_start && b->cam_quads && b->cam_near) return 0;
    snprintf(err, errlen, "%s: %s", dev->name, clu_error());
    return 1;
}

/* Triangles, smooth normals (with VBCL_FEATURE_SMOOTH_NORMALS), grid cells, the quads of
 * the leaves and of the records objs (whose quad_tri and quad_tex it sets: pack_quads) and
 * the camera tiles (into ct). Returns 0, 1 (out of memory, device) or 2 (larger than one
 * allocation). */
static int upload_geometry(SceneBuffers *b, VbDevice *dev, const Scene *s, const Grid *g,
                           VbObject *objs, size_t nobjs, unsigned features, VbCamTiles *ct,
                           char *err, size_t errlen)
{
    size_t nbytes_tris = sizeof(VbTriangle) * s->mesh.ntris;
    if (nbytes_tris > dev->max_alloc ||
        sizeof(VbLeafQuad) *
                (grid_leaf_quads(g, s->tri_tag, VBCL_TAG_TEXTURE) + objects_quads(objs, nobjs)) >
            dev->max_alloc ||
        sizeof(uint32_t) * ((size_t)g->nleaves + 1) > dev->max_alloc) {
        snprintf(err, errlen,
                 "%s: the scene (%u triangles, %u grid references in %u leaves) does not fit "
                 "in one allocation on %s (%.0f MiB at most)",
                 s->path, s->mesh.ntris, g->nleaf_refs, g->nleaves, dev->name,
                 (double)dev->max_alloc / 1048576.0);
        return 2;
    }
    VbTriangle *tris = pack_triangles(s);
    VbTriNormals *normals = pack_normals(s);
    uint32_t *quad_start = NULL, nquads = 0;
    VbLeafQuad *quads =
        tris ? pack_quads(g, s->tri_tag, tris, objs, nobjs, &quad_start, &nquads) : NULL;
    if (!tris || !normals || !quads) {
        free(tris);
        free(normals);
        free(quads);
        free(quad_start);
        snprintf(err, errlen, "out of memory packing %u triangles", s->mesh.ntris);
        return 1;
    }
    b->tris = clu_buffer(dev, tris, nbytes_tris, CL_MEM_READ_ONLY);
    int rc = upload_camera_tiles(b, dev, s, tris, ct, err, errlen);
    b->normals = clu_buffer(
        dev, normals,
        (features & VBCL_FEATURE_SMOOTH_NORMALS) ? sizeof(VbTriNormals) * s->mesh.ntris : 0,
        CL_MEM_READ_ONLY);
    free(tris);
    free(normals);
    b->grid_cells = clu_buffer(dev, g->cells, sizeof(VbGridCell) * g->ncells, CL_MEM_READ_ONLY);
    b->leaf_start =
        clu_buffer(dev, quad_start, sizeof(uint32_t) * (g->nleaves + 1u), CL_MEM_READ_ONLY);
    b->leaf_quads = clu_buffer(dev, quads, sizeof(VbLeafQuad) * nquads, CL_MEM_READ_ONLY);
    free(quad_start);
    free(quads);
    if (rc) return rc;
    if (b->tris && b->normals && b->grid_cells && b->leaf_start && b->leaf_quads) return 0;
    snprintf(err, errlen, "%s: %s", dev->name, clu_error());
    return 1;
}

/* Accumulates the vertices of triangles first .. first + n - 1 of m into a bounding box
 * (double precision). */
static void object_box(const Mesh *m, uint32_t first, uint32_t n, double lo[3], double hi[3])
{
    for (uint32_t t = first; t < first + n; t++)
        for (int k = 0; k < 3; k++) {
            vec3 v = m->verts[m->tris[3 * t + k]];
            double c[3] = {v.x, v.y, v.z};
            for (int a = 0; a < 3; a++) {
                lo[a] = fmin(lo[a], c[a]);
                hi[a] = fmax(hi[a], c[a]);
            }
        }
}

/* The largest distance of a vertex of triangles first .. first + n - 1 from the point c
 * (*r) and from the plane n.x = k (*dev). */
static void object_spread(const Mesh *m, uint32_t first, uint32_t n, const double c[3],
                          const double nrm[3], double k, double *r, double *dev)
{
    for (uint32_t t = first; t < first + n; t++)
        for (int j = 0; j < 3; j++) {
            vec3 v = m->verts[m->tris[3 * t + j]];
            double d[3] = {v.x - c[0], v.y - c[1], v.z - c[2]};
            *r = fmax(*r, sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
            *dev = fmax(*dev, fabs(nrm[0] * v.x + nrm[1] * v.y + nrm[2] * v.z - k));
        }
}

/* Whether every vertex of triangles first .. first + n - 1 of m and of the texture's
 * tex_first .. tex_first + tex_n - 1 lies behind (or within eps of) the plane of each of
 * the first ones (counter-clockwise seen from the front): a convex surface with its
 * texture inside. Tested where it takes at most `budget` vertex tests, 3 n (n + tex_n)
 * (2^24 for an object: 2364 triangles alone, or 8 with a texture of 699,000; 2^20 for a
 * part of a texture: 591 triangles); larger ones count as not convex, as do degenerate
 * triangles. */
static int object_convex(const Mesh *m, uint32_t first, uint32_t n, uint32_t tex_first,
                         uint32_t tex_n, double eps, uint64_t budget)
{
    if (n == 0 || 3 * (uint64_t)n * ((uint64_t)n + tex_n) > budget) return 0;
    /* each vertex once (a closed mesh's triangles share them about six ways) */
    size_t nv = 3 * ((size_t)n + tex_n), k = 0;
    uint32_t *vi = malloc(sizeof *vi * nv);
    if (!vi) return 0;
    for (uint32_t q = 0; q < n + tex_n; q++) {
        uint32_t u = q < n ? first + q : tex_first + (q - n);
        for (int j = 0; j < 3; j++) vi[3 * (size_t)q + j] = m->tris[3 * u + j];
    }
    qsort(vi, nv, sizeof *vi, mesh_cmp_u32);
    for (size_t i = 0; i < nv; i++)
        if (k == 0 || vi[i] != vi[k - 1]) vi[k++] = vi[i];
    int convex = 1;
    for (uint32_t t = first; t < first + n && convex; t++) {
        double x[3];
        vec3 p0 = mesh_tri_normal_d(m, t, x);
        double len = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        if (!(len > 0.0)) {
            convex = 0;
            break;
        }
        for (size_t i = 0; i < k; i++) {
            vec3 v = m->verts[vi[i]];
            double h = (x[0] * (v.x - p0.x) + x[1] * (v.y - p0.y) + x[2] * (v.z - p0.z)) / len;
            if (h > eps) {
                convex = 0;
                break;
            }
        }
    }
    free(vi);
    return convex;
}

/* object_convex's budget for an object's triangles: 2^24 vertex tests (2364 triangles
 * alone). */
#define OBJECT_CONVEX_BUDGET (1u << 24)

/* Whether n triangles alone are beyond OBJECT_CONVEX_BUDGET, so that hull_convex tests them
 * edge by edge. */
static int convex_by_edges(uint32_t n)
{
    return 3 * (uint64_t)n * (uint64_t)n > OBJECT_CONVEX_BUDGET;
}

/* Whether a host's own triangles first .. first + n - 1 of m bound a convex volume
 * (VBCL_OBJECT_HULL), for an object of size `size`: every vertex behind every plane within
 * 1e-6 of it (object_convex) within OBJECT_CONVEX_BUDGET; beyond (convex_by_edges),
 * strictly convex at every edge of one closed surface of genus 0 (mesh_part_convex, tol
 * 1e-9 of the size: a tessellated sphere of 81,920 triangles is convex by 4e-5 of it). */
static int hull_convex(const Mesh *m, uint32_t first, uint32_t n, double size)
{
    if (!convex_by_edges(n))
        return object_convex(m, first, n, 0, 0, 1e-6 * size, OBJECT_CONVEX_BUDGET);
    return mesh_part_convex(m, first, n, 1e-9 * size);
}

/* Where triangles first .. first + n - 1 of m and the texture's tex_first .. tex_first +
 * tex_n - 1 lie, for the shadow cone test (light.cl, light_cone_objects): a sphere and a box
 * holding them all, and where every vertex lies within 1e-6 of the size of one plane (a
 * floor, a wall: any planar mesh), that plane; VBCL_OBJECT_CONVEX as object_convex says
 * (within `budget`).
 * Computed in double precision from the float vertices the kernels use, and widened by
 * margins far above float rounding, so the tests that use them stay conservative. */
static void object_bounds(const Mesh *m, uint32_t first, uint32_t n, uint32_t tex_first,
                          uint32_t tex_n, uint64_t budget, VbObject *g)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    object_box(m, first, n, lo, hi);
    object_box(m, tex_first, tex_n, lo, hi);
    g->bound[3] = -1.0f; /* no triangles: nothing to meet */
    if (!(lo[0] <= hi[0])) return;
    double c[3], mag = 0.0;
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5 * (lo[a] + hi[a]);
        mag = fmax(mag, fmax(fabs(lo[a]), fabs(hi[a])));
    }
    /* the plane of the object's largest triangle */
    double nrm[3] = {0, 0, 0}, best = 0.0, k = 0.0;
    for (uint32_t t = first; t < first + n; t++) {
        double x[3];
        vec3 p0 = mesh_tri_normal_d(m, t, x);
        double len = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        if (len > best) {
            best = len;
            for (int a = 0; a < 3; a++) nrm[a] = x[a] / len;
            k = nrm[0] * p0.x + nrm[1] * p0.y + nrm[2] * p0.z;
        }
    }
    double r = 0.0, dev = 0.0;
    object_spread(m, first, n, c, nrm, k, &r, &dev);
    object_spread(m, tex_first, tex_n, c, nrm, k, &r, &dev);
    double margin = 1e-5 * (mag + r);
    for (int a = 0; a < 3; a++) {
        g->bound[a] = (float)c[a];
        g->lo[a] = (float)(lo[a] - margin);
        g->hi[a] = (float)(hi[a] + margin);
    }
    g->bound[3] = (float)(r + margin);
    if (object_convex(m, first, n, tex_first, tex_n, 1e-6 * (mag + r), budget))
        g->flags |= VBCL_OBJECT_CONVEX;
    if (best > 0.0 && dev <= 1e-6 * r) {
        g->flags |= VBCL_OBJECT_PLANAR;
        for (int a = 0; a < 3; a++) g->plane[a] = (float)nrm[a];
        g->plane[3] = (float)k;
        g->plane_eps = (float)(dev + margin);
    }
}

static uint32_t uf_find(uint32_t *parent, uint32_t v)
{
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
}

/* The parts of a texture (triangles first .. first + n - 1 of m) whose bounds the shadow
 * cone test takes one by one: the texture cut wherever the next triangle belongs to
 * another connected piece (triangles joined by shared vertices: a bombed sphere, a tube, a
 * ring), so each part is a stretch of one piece. Writes (first, count) pairs into runs and
 * returns their number, or -1 where there would be more than VBCL_CONE_TEST_MAX_ELEMENTS
 * (or no memory): the texture is then bounded as a whole. */
static int texture_parts(const Mesh *m, uint32_t first, uint32_t n, uint32_t runs[][2])
{
    if (n == 0) return 0;
    uint32_t *parent = malloc(sizeof *parent * m->nverts);
    if (!parent) return -1;
    for (uint32_t v = 0; v < m->nverts; v++) parent[v] = v;
    for (uint32_t t = first; t < first + n; t++)
        for (int k = 1; k < 3; k++) {
            uint32_t a = uf_find(parent, m->tris[3 * t]), b = uf_find(parent, m->tris[3 * t + k]);
            if (a != b) parent[a] = b;
        }
    int nruns = 0;
    uint32_t prev = UINT32_MAX;
    for (uint32_t t = first; t < first + n; t++) {
        uint32_t c = uf_find(parent, m->tris[3 * t]);
        if (nruns > 0 && c == prev) {
            runs[nruns - 1][1]++;
            continue;
        }
        if (nruns == VBCL_CONE_TEST_MAX_ELEMENTS) {
            nruns = -1;
            break;
        }
        runs[nruns][0] = t;
        runs[nruns][1] = 1;
        nruns++;
        prev = c;
    }
    free(parent);
    return nruns;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Whether triangles first .. first + n - 1 of m form a closed surface by their vertex
 * indices: every edge a -> b has its reverse b -> a among them. */
static int part_closed(const Mesh *m, uint32_t first, uint32_t n)
{
    uint64_t *e = malloc(sizeof *e * 3 * (size_t)n);
    if (!e) return 0;
    for (uint32_t t = 0; t < n; t++)
        for (int k = 0; k < 3; k++) {
            uint64_t a = m->tris[3 * (first + t) + k], b = m->tris[3 * (first + t) + (k + 1) % 3];
            e[3 * (size_t)t + k] = a << 32 | b;
        }
    qsort(e, 3 * (size_t)n, sizeof *e, cmp_u64);
    int closed = 1;
    for (size_t i = 0; i < 3 * (size_t)n && closed; i++) {
        uint64_t rev = e[i] << 32 | e[i] >> 32;
        closed = bsearch(&rev, e, 3 * (size_t)n, sizeof *e, cmp_u64) != NULL;
    }
    free(e);
    return closed;
}

/* A sphere inside the convex part first .. first + n - 1 of m (core: centre, radius): the
 * mean of its corners, and its least distance from the part's planes less 0.1% and
 * margin. 0 where there is none (the centre not strictly inside every plane). */
static int part_core(const Mesh *m, uint32_t first, uint32_t n, double margin, float core[4])
{
    double c[3] = {0, 0, 0};
    for (uint32_t t = first; t < first + n; t++)
        for (int k = 0; k < 3; k++) {
            vec3 v = m->verts[m->tris[3 * t + k]];
            c[0] += v.x / (3.0 * n);
            c[1] += v.y / (3.0 * n);
            c[2] += v.z / (3.0 * n);
        }
    double r = INFINITY;
    for (uint32_t t = first; t < first + n; t++) {
        double x[3];
        vec3 p0 = mesh_tri_normal_d(m, t, x);
        double len = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        double h = (x[0] * (c[0] - p0.x) + x[1] * (c[1] - p0.y) + x[2] * (c[2] - p0.z)) / len;
        if (!(h < 0.0)) return 0;
        r = fmin(r, -h);
    }
    r = r * (1.0 - 1e-3) - margin;
    if (!(r > 0.0)) return 0;
    for (int a = 0; a < 3; a++) core[a] = (float)c[a];
    core[3] = (float)r;
    return 1;
}

/* Shrinks the sphere core (centre, radius) to lie behind every plane of the host's
 * triangles host .. host + host_n - 1 of m by margin: inside the host, where the host is
 * convex. 0 where its centre is not that far inside. */
static int core_inside(const Mesh *m, float core[4], uint32_t host, uint32_t host_n, double margin)
{
    double r = core[3];
    for (uint32_t h = host; h < host + host_n; h++) {
        double x[3];
        vec3 p0 = mesh_tri_normal_d(m, h, x);
        double len = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        if (!(len > 0.0)) return 0;
        double d =
            (x[0] * (core[0] - p0.x) + x[1] * (core[1] - p0.y) + x[2] * (core[2] - p0.z)) / len;
        r = fmin(r, -d - margin);
    }
    if (!(r > margin)) return 0;
    core[3] = (float)r;
    return 1;
}

/* Gives host record g, whose own triangles first .. first + n - 1 of m bound a convex volume
 * of more than VBCL_OBJECT_SET_MAX_TRIS / 2 triangles, its inner sphere (VBCL_OBJECT_INNER,
 * in VbObject.plane): about the centre of their own sphere, behind every plane of them by
 * margin (core_inside). Nothing where that centre is not so far inside. */
static void host_inner(const Mesh *m, VbObject *g, uint32_t first, uint32_t n, double margin)
{
    float core[4];
    memcpy(core, g->own, sizeof core);
    if (n <= VBCL_OBJECT_SET_MAX_TRIS / 2 || (g->flags & VBCL_OBJECT_PLANAR) ||
        !core_inside(m, core, first, n, margin))
        return;
    memcpy(g->plane, core, sizeof core);
    g->flags |= VBCL_OBJECT_INNER;
}

/* Clears bits of the parts' VbObject.ahead (all set by objects_make) for host record g, whose
 * own triangles first .. first + n - 1 of m bound a convex volume (VBCL_OBJECT_HULL): for a
 * host of at most VBCL_AHEAD_BITS of them (part_ahead_bit), bit j where every vertex of the part
 * lies behind the plane of triangle first + j by at least margin (the part lies wholly behind it:
 * a ray leaving the host through the front of that triangle, ahead of its plane from then on,
 * cannot meet the part); for a larger host, every bit where the part's bounding sphere lies
 * within the host's inner sphere (VBCL_OBJECT_INNER) by margin, behind every plane of it. */
static void parts_ahead(const Mesh *m, const VbObject *g, uint32_t first, uint32_t n,
                        VbObject *parts, int nparts, double margin)
{
    if (n > VBCL_AHEAD_BITS) {
        for (int e = 0; e < nparts && (g->flags & VBCL_OBJECT_INNER); e++) {
            double d2 = 0.0;
            for (int a = 0; a < 3; a++)
                d2 += ((double)parts[e].bound[a] - g->plane[a]) *
                      ((double)parts[e].bound[a] - g->plane[a]);
            if (sqrt(d2) + parts[e].bound[3] + margin <= g->plane[3]) parts[e].ahead = 0u;
        }
        return;
    }
    for (uint32_t j = 0; j < n; j++) {
        double x[3];
        vec3 p0 = mesh_tri_normal_d(m, first + j, x);
        double len = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        if (!(len > 0.0)) continue;
        for (int e = 0; e < nparts; e++) {
            int behind = 1;
            for (uint32_t t = parts[e].first_tri; t < parts[e].first_tri + parts[e].ntris && behind;
                 t++)
                for (int k = 0; k < 3 && behind; k++) {
                    vec3 v = m->verts[m->tris[3 * t + k]];
                    double h =
                        (x[0] * (v.x - p0.x) + x[1] * (v.y - p0.y) + x[2] * (v.z - p0.z)) / len;
                    behind = h <= -margin;
                }
            if (behind) parts[e].ahead &= ~(1u << j);
        }
    }
}

/* Marks the solid parts (VBCL_OBJECT_SOLID) among the nparts records parts of object o's
 * texture (o's record g), with a core (part_core) in VbObject.plane: o a convex host whose
 * texture material T is opaque and no object's own material, the part closed, convex and
 * not planar, its core shrunk to lie inside o. A feeler that starts outside every texture element
 * and reaches a point of the core is there inside o and inside the part, where the material is T;
 * it started elsewhere, and the only crossings into T are entering ones (into the part, or into o
 * while inside a part), whose surface is T: opaque. So the walk returns nothing whatever it meets
 * on the way (a part that reaches out of o included), and the feeler need not be traced. */
static void parts_solid(const Scene *s, const SceneObject *o, const VbObject *g, VbObject *parts,
                        int nparts)
{
    const Mesh *m = &s->mesh;
    double mag = 0.0;
    for (int a = 0; a < 3; a++) mag = fmax(mag, fmax(fabs(g->lo[a]), fabs(g->hi[a])));
    double margin = 1e-5 * (mag + g->bound[3]);
    if (!o->is_host || !(g->flags & VBCL_OBJECT_HULL) ||
        s->materials[o->tex_material].gpu.k_global > 0.0f)
        return;
    for (int j = 0; j < s->nobjects; j++)
        if (s->objects[j].material == o->tex_material) return;
    for (int e = 0; e < nparts; e++) {
        VbObject *el = &parts[e];
        if (!(el->flags & VBCL_OBJECT_CONVEX) || (el->flags & VBCL_OBJECT_PLANAR)) continue;
        float core[4];
        if (part_closed(m, el->first_tri, el->ntris) &&
            part_core(m, el->first_tri, el->ntris, margin, core) &&
            core_inside(m, core, o->first_tri, o->ntris, margin)) {
            el->flags |= VBCL_OBJECT_SOLID;
            memcpy(el->plane, core, sizeof core);
        }
    }
}

/* For opaque object o (not a host: a feeler that crosses any of its triangles is stopped,
 * medium_cross) of more than the cone test's sets take one by one (VBCL_OBJECT_SET_MAX_TRIS /
 * 2), not planar, whose record g's bounds object_bounds gave for size `size`: where its
 * triangles bound a convex volume beyond object_convex's budget (convex_by_edges),
 * VBCL_OBJECT_CONVEX, so that a feeler leaving the front of one of them skips it
 * (light_cone_objects); where they are convex and close a surface, VBCL_OBJECT_SOLID with a
 * core (part_core) in g->plane: a feeler from outside its bounding sphere that reaches a point
 * of the core has crossed that surface, so nothing gets through and it need not be traced
 * (object_set_feeler). */
static void object_opaque_convex(const Mesh *m, const SceneObject *o, VbObject *g, double size)
{
    float core[4];
    if (o->is_host || o->ntris <= VBCL_OBJECT_SET_MAX_TRIS / 2 || (g->flags & VBCL_OBJECT_PLANAR))
        return;
    if (!(g->flags & VBCL_OBJECT_CONVEX)) {
        /* beyond object_convex's budget: the edge test, which also finds the surface closed */
        if (!convex_by_edges(o->ntris) || !hull_convex(m, o->first_tri, o->ntris, size)) return;
        g->flags |= VBCL_OBJECT_CONVEX;
    } else if (!part_closed(m, o->first_tri, o->ntris)) {
        return;
    }
    if (!part_core(m, o->first_tri, o->ntris, 1e-5 * size, core)) return;
    g->flags |= VBCL_OBJECT_SOLID;
    memcpy(g->plane, core, sizeof core);
}

/* The objects' records for the kernels: the scene's objects, then the parts of their
 * textures (texture_parts); *count is how many records in all. NULL: out of memory. */
static VbObject *objects_make(const Scene *s, size_t *count)
{
    size_t cap = (size_t)s->nobjects + 1, n = (size_t)s->nobjects;
    VbObject *objs = calloc(cap, sizeof *objs);
    uint32_t(*runs)[2] = malloc(sizeof *runs * VBCL_CONE_TEST_MAX_ELEMENTS);
    if (!objs || !runs) goto fail;
    for (int i = 0; i < s->nobjects; i++) {
        const SceneObject *o = &s->objects[i];
        VbObject *g = &objs[i];
        g->material = (unsigned)o->material;
        g->tex_material = o->tex_slot >= 0 ? (unsigned)o->tex_material : (unsigned)o->material;
        g->tex_slot = o->tex_slot;
        g->flags = o->is_host ? VBCL_OBJECT_HOST : 0u;
        object_bounds(&s->mesh, o->first_tri, o->ntris, o->first_tex_tri, o->ntex_tris,
                      OBJECT_CONVEX_BUDGET, g);
        memcpy(g->own, g->bound, sizeof g->own);
        if (o->ntex_tris > 0) { /* the sphere of its own triangles: the texture may reach out */
            VbObject own;
            memset(&own, 0, sizeof own);
            object_bounds(&s->mesh, o->first_tri, o->ntris, 0, 0, 0, &own);
            memcpy(g->own, own.bound, sizeof g->own);
        }
        g->first_tri = o->first_tri;
        g->ntris = o->ntris;
        g->first_tex = o->first_tex_tri;
        g->ntex = o->ntex_tris;
        int nruns = texture_parts(&s->mesh, o->first_tex_tri, o->ntex_tris, runs);
        double mag = 0.0;
        for (int a = 0; a < 3; a++) mag = fmax(mag, fmax(fabs(g->lo[a]), fabs(g->hi[a])));
        int big = o->ntris > VBCL_OBJECT_SET_MAX_TRIS / 2;
        int hull = o->is_host && (nruns > 0 || big) &&
                   hull_convex(&s->mesh, o->first_tri, o->ntris, mag + g->bound[3]);
        if (hull) host_inner(&s->mesh, g, o->first_tri, o->ntris, 1e-5 * (mag + g->bound[3]));
        object_opaque_convex(&s->mesh, o, g, mag + g->bound[3]);
        if (nruns <= 0) continue;
        if (hull) g->flags |= VBCL_OBJECT_HULL;
        VbObject *grown = realloc(objs, sizeof *objs * (n + (size_t)nruns));
        if (!grown) goto fail;
        objs = grown;
        objs[i].first_elem = (unsigned)n;
        objs[i].nelems = (unsigned)nruns;
        for (int e = 0; e < nruns; e++, n++) {
            VbObject *el = &objs[n];
            memset(el, 0, sizeof *el);
            object_bounds(&s->mesh, runs[e][0], runs[e][1], 0, 0, 1u << 20, el);
            el->first_tri = runs[e][0];
            el->ntris = runs[e][1];
            el->host = (unsigned)i;
            el->ahead = ~0u;
        }
        parts_solid(s, o, &objs[i], objs + objs[i].first_elem, nruns);
        if (hull)
            parts_ahead(&s->mesh, &objs[i], o->first_tri, o->ntris, objs + objs[i].first_elem,
                        nruns, 1e-5 * (mag + objs[i].bound[3]));
    }
    free(runs);
    *count = n;
    return objs;
fail:
    free(objs);
    free(runs);
    return NULL;
}

/* Materials (the scene's, then the medium outside every host: vacuum, eta 1), their
 * patterns and band tables, the nobjs records objs (objects_make) and lights. Returns as
 * upload_patterns. */
static int upload_materials(SceneBuffers *b, VbDevice *dev, const Scene *s, const VbObject *objs,
                            size_t nobjs, unsigned features, unsigned *band_weights, char *err,
                            size_t errlen)
{
    VbMaterial *mats = calloc((size_t)s->nmaterials + 1, sizeof *mats);
    int rc = 1;
    snprintf(err, errlen, "out of memory");
    if (!mats) goto done;
    for (int i = 0; i < s->nmaterials; i++) mats[i] = s->materials[i].gpu;
    mats[s->nmaterials].eta = 1.0f;
    mats[s->nmaterials].pattern = -1;
    mats[s->nmaterials].disp = -1;
    rc = upload_patterns(b, dev, s, features, mats, band_weights, err, errlen);
    if (rc) goto done;
    mats[s->nmaterials].k_global = 1.0f;
    b->materials =
        clu_buffer(dev, mats, sizeof *mats * ((size_t)s->nmaterials + 1), CL_MEM_READ_ONLY);
    b->objects = clu_buffer(dev, objs, sizeof *objs * nobjs, CL_MEM_READ_ONLY);
    b->lights = clu_buffer(dev, s->lights, sizeof(VbLight) * (size_t)s->nlights, CL_MEM_READ_ONLY);
    rc = b->materials && b->objects && b->lights ? 0 : 1;
    if (rc) snprintf(err, errlen, "%s: %s", dev->name, clu_error());
done:
    free(mats);
    return rc;
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

int scene_buffers_upload(SceneBuffers *b, VbDevice *dev, const Scene *s, const Grid *g,
                         unsigned features, VbFrame *f, char *err, size_t errlen)
{
    memset(b, 0, sizeof *b);
    unsigned band_weights = 0;
    VbCamTiles ct;
    size_t nobjs = 0;
    VbObject *objs = objects_make(s, &nobjs);
    if (!objs) {
        snprintf(err, errlen, "out of memory");
        return 1;
    }
    int rc = upload_geometry(b, dev, s, g, objs, nobjs, features, &ct, err, errlen);
    if (!rc) rc = upload_materials(b, dev, s, objs, nobjs, features, &band_weights, err, errlen);
    free(objs);
    if (rc) return rc;
    frame_fill(s, g, band_weights, f);
    f->flags |= features_frame_flags(features);
    f->cam_tiles = ct;
    b->frame = clu_buffer(dev, NULL, sizeof *f, CL_MEM_READ_ONLY);
    if (b->frame) return 0;
    snprintf(err, errlen, "%s: %s", dev->name, clu_error());
    return 1;
}

int scene_buffers_set_args(const SceneBuffers *b, cl_kernel k)
{
#define SCENE_BUFFER_PTR(space, type, name, field) &b->field,
    const cl_mem *m[SCENE_BUFFER_ARGS] = {VBCL_SCENE_BUFFERS(SCENE_BUFFER_PTR)};
    for (cl_uint i = 0; i < SCENE_BUFFER_ARGS; i++)
        if (clu_set_arg(k, i, sizeof(cl_mem), m[i])) return -1;
    return 0;
}

void scene_buffers_release(SceneBuffers *b)
{
    cl_mem *m[SCENE_BUFFER_ARGS] = {VBCL_SCENE_BUFFERS(SCENE_BUFFER_PTR)};
#undef SCENE_BUFFER_PTR
    for (int i = 0; i < SCENE_BUFFER_ARGS; i++)
        if (*m[i]) CL_WARN(clReleaseMemObject(*m[i]));
    memset(b, 0, sizeof *b);
}
