/* objects.c — the object analysis: what the kernels may assume of each object and of each
 * part of a volume texture, from the geometry alone (bounds, planarity, convexity, closed
 * parts, cores, inner spheres, parts behind a host's planes). Device-independent: a frame
 * runs it once for every device (compiled_scene.c), and tests/test_objects.c checks each
 * rule on small meshes. */
#include "objects.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

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
 * in VbObject.inside): about the centre of their own sphere, behind every plane of them by
 * margin (core_inside). Nothing where that centre is not so far inside. */
static void host_inner(const Mesh *m, VbObject *g, uint32_t first, uint32_t n, double margin)
{
    float core[4];
    memcpy(core, g->own, sizeof core);
    if (n <= VBCL_OBJECT_SET_MAX_TRIS / 2 || (g->flags & VBCL_OBJECT_PLANAR) ||
        !core_inside(m, core, first, n, margin))
        return;
    memcpy(g->inside, core, sizeof core);
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
                d2 += ((double)parts[e].bound[a] - g->inside[a]) *
                      ((double)parts[e].bound[a] - g->inside[a]);
            if (sqrt(d2) + parts[e].bound[3] + margin <= g->inside[3]) parts[e].ahead = 0u;
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
 * texture (o's record g), with a core (part_core) in VbObject.inside: o a convex host whose
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
            memcpy(el->inside, core, sizeof core);
        }
    }
}

/* For opaque object o (not a host: a feeler that crosses any of its triangles is stopped,
 * medium_cross) of more than the cone test's sets take one by one (VBCL_OBJECT_SET_MAX_TRIS /
 * 2), not planar, whose record g's bounds object_bounds gave for size `size`: where its
 * triangles bound a convex volume beyond object_convex's budget (convex_by_edges),
 * VBCL_OBJECT_CONVEX, so that a feeler leaving the front of one of them skips it
 * (light_cone_objects); where they are convex and close a surface, VBCL_OBJECT_SOLID with a
 * core (part_core) in g->inside: a feeler from outside its bounding sphere that reaches a point
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
    memcpy(g->inside, core, sizeof core);
}

VbObject *objects_make(const Scene *s, size_t *count)
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
