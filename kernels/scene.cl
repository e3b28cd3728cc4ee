#line 2 "scene.cl"
/* scene.cl — the scene as device functions see it: one bundle of the frame's buffers,
 * passed by pointer instead of eight arguments to every function. */
#ifndef VBCL_SCENE_CL
#define VBCL_SCENE_CL

#include "grid.cl"

#define VB_SCENE_FIELD(space, type, name, field) space const type *name;
#define VB_SCENE_PARAM(space, type, name, field) space const type *name,
#define VB_SCENE_INIT(space, type, name, field)  name,

typedef struct DevScene {
    VBCL_SCENE_BUFFERS(VB_SCENE_FIELD)
} DevScene;

/* The scene arguments every frame kernel and scene probe starts with (a trailing comma
 * included: `__kernel void k(SCENE_KERNEL_ARGS int n)`), and the DevScene made of them. */
#define SCENE_KERNEL_ARGS VBCL_SCENE_BUFFERS(VB_SCENE_PARAM)
#define DEV_SCENE                                                                                  \
    {                                                                                              \
        VBCL_SCENE_BUFFERS(VB_SCENE_INIT)                                                          \
    }

/* The colour a material's surface pattern gives at point p (1 without a pattern):
 * max(G, 0) for Fourier synthesis, the image's texel for an orthogonal projection along
 * one axis (0 outside its unit square), at texture coordinates (p - origin) / size. */
VB_INLINE float3 scene_pattern_colour(const DevScene *sc, __global const VbMaterial *m, float3 p)
{
#ifdef VBCL_HAS_PATTERNS
    int pattern = m->pattern;
    if (pattern < 0) return (float3)(1.0f);
    __global const VbPattern *pt = sc->patterns + pattern;
    float3 q = (p - vb_gload3(pt->origin)) * vb_gload3(pt->inv_size);
    if (pt->kind == VBCL_PATTERN_FOURIER)
        return (float3)(fmax(0.0f, solidtex_fourier_eval(&pt->fourier, q.x, q.y, q.z)));
    if (pt->kind == VBCL_PATTERN_CHECKER) { /* the parity of the cell along the axes used */
        int3 cell = convert_int3_sat(floor(q));
        int sum = ((pt->axes & 1u) ? cell.x : 0) + ((pt->axes & 2u) ? cell.y : 0) +
                  ((pt->axes & 4u) ? cell.z : 0);
        return vb_gload3(pt->colours[sum & 1]);
    }
    /* a projection along axis k (bit k of axes): u, v the next two axes in cyclic order */
    float2 uv = (pt->axes & 1u) ? q.yz : (pt->axes & 2u) ? q.zx : q.xy;
    int t = solidtex_projection_texel(pt->width, pt->height, uv.x, uv.y);
    if (t < 0) return (float3)(0.0f);
    return vload3(0, sc->texels + 4 * ((size_t)pt->texel_offset + (size_t)t));
#else
    (void)sc;
    (void)m;
    (void)p;
    return (float3)(1.0f);
#endif
}

/* Closest hit of (org, dir) within tmax, through the grid. */
VB_INLINE VbHit scene_trace_closest(const DevScene *sc, float3 org, float3 dir, float tmax,
                                    TraceCount *tc)
{
    return grid_trace_closest(&sc->f->grid, sc->tris, sc->grid_cells, sc->leaf_start,
                              sc->leaf_quads, org, dir, tmax, tc);
}

/* Closest hit of a camera ray (org the eye) within tmax: the triangles
 * of the ray's image tile (host/device/camera_tiles.h), nearest first, until the next quad
 * lies beyond the best hit; the same hit as scene_trace_closest, which rays from elsewhere,
 * or of a frame without tiles, take, and so do rays from the eye that leave the image. The
 * tile is found from dir; the host widened each triangle's tiles by a margin for the
 * rounding of that. */
VB_INLINE VbHit camera_trace_closest(const DevScene *sc, float3 org, float3 dir, float tmax,
                                     TraceCount *tc)
{
    __constant const VbFrame *f = sc->f;
    __constant const VbCamTiles *ct = &f->cam_tiles;
    float a = dot(dir, vb_cload3(f->camera.forward));
    if (ct->nx == 0 || !(a > 0.0f) || any(org != vb_cload3(f->camera.eye)))
        return scene_trace_closest(sc, org, dir, tmax, tc);
    float px = (dot(dir, vb_cload3(ct->right_n)) / a + 1.0f) * (0.5f * (float)f->width);
    float py = (1.0f - dot(dir, vb_cload3(ct->up_n)) / a) * (0.5f * (float)f->height);
    if (!(px >= 0.0f && px <= (float)f->width && py >= 0.0f && py <= (float)f->height))
        return scene_trace_closest(sc, org, dir, tmax, tc);
    int tx = clamp(convert_int_sat_rtn(px * (1.0f / VBCL_CAM_TILE)), 0, ct->nx - 1);
    int ty = clamp(convert_int_sat_rtn(py * (1.0f / VBCL_CAM_TILE)), 0, ct->ny - 1);
    uint t = (uint)(ty * ct->nx + tx), end = sc->cam_start[t + 1];
    Closest c;
    closest_begin(&c, tmax);
    RayShear rs = ray_shear_make(org, dir);
    uint tests = 0;
    /* a hit at t lies t |dir| from the eye (1e-4 more is ample for the rounding) */
    float reach_scale = length(dir) * 1.0001f;
    for (uint k = sc->cam_start[t]; k < end && sc->cam_near[k] <= c.reach * reach_scale; k++)
        tests += quad_closest(&rs, org, tmax, sc->tris, sc->cam_quads + k, &c);
    tc->steps++;
    tc->tests += tests;
    return c.hit;
}

/* Whether anything lies on (org, dir) before tmax, triangles whose tag has a bit of `skip`
 * (VBCL_TAG_TEXTURE, or 0) left out. */
VB_INLINE int scene_trace_any(const DevScene *sc, float3 org, float3 dir, float tmax, uint skip,
                              TraceCount *tc)
{
    return grid_trace_any(&sc->f->grid, sc->tris, sc->grid_cells, sc->leaf_start, sc->leaf_quads,
                          org, dir, (float2)(0.0f, tmax), tmax, skip, tc);
}

/* A few ranges of triangles, the only ones a ray may meet (the shadow cone test,
 * light.cl, has shown the rest of the scene to be out of its way), or n < 0: any
 * triangle (the grid). */
#define VB_OBJECT_SET_MAX     4 /* ranges */
#define VB_OBJECT_SET_MAX_BIG 4 /* parts too big for the set, each feeler tests their bounds */
typedef struct ObjectSet {
    int n;
    uint tris;                     /* triangles in all, at most VBCL_OBJECT_SET_MAX_TRIS */
    uint first[VB_OBJECT_SET_MAX]; /* a range's first quad in leaf_quads (VbObject.quad_tri) */
    uint count[VB_OBJECT_SET_MAX]; /* its triangles, ceil(count / 4) quads */
    int nbig; /* records (VbObject: objects of many triangles, their textures included, and
               * texture parts) of big: a feeler that meets the bounding sphere of one of
               * them walks the grid, the others test the ranges alone */
    uint big[VB_OBJECT_SET_MAX_BIG];
    int sole;  /* the host that all the set holds (ranges and big records) belongs to, where
                * its own triangles bound a convex volume (VBCL_OBJECT_CONVEX or _HULL; its
                * texture may reach out), or -1: a feeler that leaves it meets nothing more */
    int walk;  /* 1: the big records' triangles too, through the grid where the ray lies in
                * their bounding spheres (object_set_span); 0: the ranges alone */
    int shell; /* a host the ray starts inside (VBCL_OBJECT_INNER), whose own triangles the
                * walk takes where the ray has left the host's inner sphere and not yet its
                * own sphere (ray_objects), or -1 */
} ObjectSet;

/* Where the line from org along the unit dir lies in sphere b (centre, radius; radius < 0:
 * none), widened by margins as the cone test's (1e-5 of the distances, reach the farthest
 * one along the line that matters): (in, out), or (inf, -inf) where it misses the sphere. */
VB_INLINE float2 sphere_chord(float4 b, float3 org, float3 dir, float reach)
{
    if (b.w < 0.0f) return (float2)(INFINITY, -INFINITY);
    float3 v = b.xyz - org;
    float along = dot(v, dir);
    float3 q = v - along * dir;
    float m = b.w + 1e-5f * (fabs(reach) + length(v) + b.w);
    float h2 = m * m - dot(q, q);
    if (h2 < 0.0f) return (float2)(INFINITY, -INFINITY);
    float h = sqrt(h2);
    return (float2)(along - h, along + h);
}

/* sphere_chord of record ob's bounding sphere. */
VB_INLINE float2 object_chord(__global const VbObject *ob, float3 org, float3 dir, float reach)
{
    return sphere_chord(vload4(0, ob->bound), org, dir, reach);
}

/* Whether the stretch [st.x, st.y] of the line from org along the unit dir can meet sphere
 * b (conservative: margins as the cone test's). */
VB_INLINE int sphere_stretch_meets(float4 b, float3 org, float3 dir, float2 st)
{
    float2 c = sphere_chord(b, org, dir, st.y);
    return c.x <= st.y && c.y >= st.x;
}

/* sphere_stretch_meets for the bounding sphere of record ob. */
VB_INLINE int object_stretch_meets(__global const VbObject *ob, float3 org, float3 dir, float2 st)
{
    return sphere_stretch_meets(vload4(0, ob->bound), org, dir, st);
}

/* Whether the segment from org along the unit dir to distance t can meet the bounding
 * sphere of record ob. */
VB_INLINE int object_segment_meets(__global const VbObject *ob, float3 org, float3 dir, float t)
{
    return object_stretch_meets(ob, org, dir, (float2)(0.0f, t));
}

/* Where the line from org along the unit dir leaves sphere b (centre, radius; radius < 0:
 * none), drawn in by margins as sphere_chord's: -INFINITY where it misses it. */
VB_INLINE float sphere_exit_inner(float4 b, float3 org, float3 dir, float reach)
{
    if (b.w < 0.0f) return -INFINITY;
    float3 v = b.xyz - org;
    float along = dot(v, dir);
    float3 q = v - along * dir;
    float h2 = b.w * b.w - dot(q, q);
    if (h2 < 0.0f) return -INFINITY;
    return along + sqrt(h2) - 1e-5f * (fabs(reach) + length(v) + b.w);
}

/* The stretch of the segment from org along the unit dir to distance t that holds every
 * point where it lies in the bounding sphere of one of the set's big records (margins as
 * object_stretch_meets), and, for its shell host, between where it leaves the host's inner
 * sphere and where it leaves the sphere of the host's own triangles; x > y where it meets
 * none. All of a big record's triangles lie in its sphere, a convex host's own triangles
 * outside its inner sphere (from inside, the line meets them once, on its way out), and
 * the cone test has shown that no triangle outside the set can meet the segment: the grid
 * need be walked only there. */
VB_INLINE float2 object_set_span(const DevScene *sc, const ObjectSet *os, float3 org, float3 dir,
                                 float t)
{
    float2 span = (float2)(INFINITY, -INFINITY);
    for (int k = 0; k < os->nbig; k++) {
        float2 c = object_chord(sc->objects + os->big[k], org, dir, t);
        span = (float2)(fmin(span.x, c.x), fmax(span.y, c.y));
    }
    if (os->shell >= 0) {
        __global const VbObject *ob = sc->objects + os->shell;
        float2 c = sphere_chord(vload4(0, ob->own), org, dir, t);
        float in = sphere_exit_inner(vload4(0, ob->inside), org, dir, t);
        span = (float2)(fmin(span.x, fmax(c.x, in)), fmax(span.y, c.y));
    }
    return (float2)(fmax(span.x, 0.0f), fmin(span.y, t));
}

/* Whether the segment from org along the unit dir to distance t passes through the core
 * of solid object or part ob (VBCL_OBJECT_SOLID) from outside its bounds: then it enters it
 * before t (the core lies inside it, the origin outside). The core's radius has the
 * margins taken off already. */
VB_INLINE int object_segment_through_core(__global const VbObject *ob, float3 org, float3 dir,
                                          float t)
{
    float4 b = vload4(0, ob->bound), core = vload4(0, ob->inside);
    float3 vb = b.xyz - org;
    if (dot(vb, vb) <= b.w * b.w) return 0;
    float3 v = core.xyz - org;
    float along = dot(v, dir);
    if (!(along > 0.0f && along < t)) return 0;
    float3 q = v - along * dir;
    return dot(q, q) < core.w * core.w;
}

/* The stretch [s0, s1] of the segment from org along the unit dir to distance t that lies
 * inside the convex host ob (VBCL_OBJECT_HULL), each plane of its triangles clipping it,
 * widened by margin m at both ends; s0 > s1 where it misses the host. A host of more than
 * VB_HULL_PLANES triangles gives the stretch in the sphere of its own triangles instead
 * (VbObject.own, its texture left out), which holds the one inside it. */
#define VB_HULL_PLANES 64
VB_INLINE float2 object_hull_stretch(const DevScene *sc, __global const VbObject *ob, float3 org,
                                     float3 dir, float t, float m)
{
    if (ob->ntris > VB_HULL_PLANES) {
        float2 c = sphere_chord(vload4(0, ob->own), org, dir, t);
        return (float2)(fmax(c.x, 0.0f) - m, fmin(c.y, t) + m);
    }
    float s0 = 0.0f, s1 = t;
    for (uint k = ob->first_tri; k < ob->first_tri + ob->ntris; k++) {
        float3 v0 = tri_vertex(sc->tris, (int)k, 0).xyz;
        float3 n = cross(tri_vertex(sc->tris, (int)k, 1).xyz - v0,
                         tri_vertex(sc->tris, (int)k, 2).xyz - v0);
        /* inside: d0 + s dn <= 0; the crossing -d0 / dn needs no unit normal */
        float d0 = dot(n, org - v0), dn = dot(n, dir);
        if (dn > 0.0f)
            s1 = fmin(s1, -d0 / dn);
        else if (dn < 0.0f)
            s0 = fmax(s0, -d0 / dn);
        else if (d0 > 0.0f)
            return (float2)(1.0f, -1.0f);
    }
    return (float2)(s0 - m, s1 + m);
}

/* What a feeler (org, dir, t) of set os needs: OBJECT_SET_ALONE, its set's triangles alone;
 * OBJECT_SET_GRID, the grid (it meets the bounds of one of the set's big objects or parts);
 * OBJECT_SET_BLOCKED, nothing: it passes through the core of a solid big object or part
 * (VBCL_OBJECT_SOLID) and is stopped there, whatever it crosses before (for a part, with
 * transparency, where the feeler starts outside every texture element: tex_free). start_host: the
 * host the feeler starts in (VbMedium.host). A big host that the feeler starts outside needs it
 * only where the feeler meets the sphere of the host's own triangles (VbObject.own): one
 * that never enters the host crosses none of its own triangles, and its texture's
 * surfaces outside the host change no material (medium_cross), so they stop nothing. */
enum { OBJECT_SET_ALONE = 0, OBJECT_SET_GRID = 1, OBJECT_SET_BLOCKED = 2 };
VB_INLINE int object_set_feeler(const DevScene *sc, const ObjectSet *os, float3 org, float3 dir,
                                float t, int tex_free, int start_host)
{
    int need = OBJECT_SET_ALONE;
    uint host = 0xffffffffu; /* whose stretch st is */
    float2 st = (float2)(0.0f);
    for (int k = 0; k < os->nbig; k++) {
        __global const VbObject *ob = sc->objects + os->big[k];
        if (!object_segment_meets(ob, org, dir, t)) continue;
        if (os->big[k] < sc->f->nobjects) { /* an object, not a part */
            if ((ob->flags & VBCL_OBJECT_HOST) && start_host != (int)os->big[k] &&
                !sphere_stretch_meets(vload4(0, ob->own), org, dir, (float2)(0.0f, t)))
                continue;
            /* an opaque object stops the feeler wherever it crosses its surface, in any
             * medium: a later record's core may still do so where this one's does not */
            if ((ob->flags & VBCL_OBJECT_SOLID) && object_segment_through_core(ob, org, dir, t))
                return OBJECT_SET_BLOCKED;
            need = OBJECT_SET_GRID;
            continue;
        }
#ifdef VBCL_HAS_TRANSPARENCY
        if (tex_free && (ob->flags & VBCL_OBJECT_SOLID) &&
            object_segment_through_core(ob, org, dir, t))
            return OBJECT_SET_BLOCKED;
        /* outside its convex host a part's surface changes no material: the feeler need
         * only meet it inside */
        __global const VbObject *ho = sc->objects + ob->host;
        if (ho->flags & VBCL_OBJECT_HULL) {
            if (ob->host != host) {
                host = ob->host;
                st = object_hull_stretch(sc, ho, org, dir, t,
                                         1e-5f * (t + vb_max3(fabs(org)) + ho->bound[3]));
            }
            if (st.x > st.y) continue; /* it misses the host, and so the part inside */
            if (!object_stretch_meets(ob, org, dir, st)) continue;
        }
#else
        (void)tex_free;
#endif
        need = OBJECT_SET_GRID;
    }
    return need;
}

/* Adds the count triangles held by the quads from leaf_quads[first] on (a record's range:
 * VbObject.quad_tri or quad_tex) to the set; 0 where the set is full (n = -1: the grid from
 * then on). */
VB_INLINE int object_set_add(ObjectSet *os, uint first, uint count)
{
    if (count == 0u) return 1;
    os->tris += count;
    if (os->n == VB_OBJECT_SET_MAX || os->tris > VBCL_OBJECT_SET_MAX_TRIS) {
        os->n = -1;
        return 0;
    }
    os->first[os->n] = first;
    os->count[os->n++] = count;
    return 1;
}

/* Adds record rec (an object, its texture included, or a texture part) to the set's big
 * ones, whose bounds each feeler tests; 0 where there are too many (n = -1: the grid). */
VB_INLINE int object_set_big(ObjectSet *os, uint rec)
{
    if (os->nbig == VB_OBJECT_SET_MAX_BIG) {
        os->n = -1;
        return 0;
    }
    os->big[os->nbig++] = rec;
    return 1;
}

/* The set of every triangle: scene_trace_closest_in walks the grid. */
VB_INLINE ObjectSet object_set_all(void)
{
    ObjectSet os;
    os.n = -1;
    os.tris = 0u;
    os.nbig = 0;
    os.sole = -1;
    os.walk = 0;
    os.shell = -1;
    return os;
}

/* The quad after the last of range k of a set. */
VB_INLINE uint object_set_end(const ObjectSet *os, int k)
{
    return os->first[k] + (os->count[k] + 3u) / 4u;
}

/* scene_trace_closest among the set's triangles alone: each of them tested, four at a time
 * as in the grid's leaves (the same test and the same order of hits as the grid's, ties to
 * the lower index), and with os->walk the grid over object_set_span, which finds the big
 * records' triangles (and the ranges' again, which changes nothing). */
VB_INLINE VbHit scene_trace_closest_in(const DevScene *sc, const ObjectSet *os, float3 org,
                                       float3 dir, float tmax, TraceCount *tc)
{
    if (os->n < 0) return scene_trace_closest(sc, org, dir, tmax, tc);
    Closest c;
    closest_begin(&c, tmax);
    RayShear rs = ray_shear_make(org, dir);
    for (int k = 0; k < os->n; k++)
        tc->tests += quads_closest(&rs, org, tmax, sc->tris, sc->leaf_quads, os->first[k],
                                   object_set_end(os, k), &c);
    if (os->walk) {
        float2 span = object_set_span(sc, os, org, dir, tmax);
        if (span.x <= span.y)
            grid_walk_closest(&sc->f->grid, sc->tris, sc->grid_cells, sc->leaf_start,
                              sc->leaf_quads, org, dir, span, tmax, &c, tc);
    }
    return c.hit;
}

/* scene_trace_any among the set's triangles alone, and with os->walk the grid over
 * object_set_span. */
VB_INLINE int scene_trace_any_in(const DevScene *sc, const ObjectSet *os, float3 org, float3 dir,
                                 float tmax, uint skip, TraceCount *tc)
{
    if (os->n < 0) return scene_trace_any(sc, org, dir, tmax, skip, tc);
    RayShear rs = ray_shear_make(org, dir);
    for (int k = 0; k < os->n; k++)
        if (quads_any(&rs, tmax, sc->tris, sc->leaf_quads, os->first[k], object_set_end(os, k),
                      skip, &tc->tests))
            return 1;
    if (!os->walk) return 0;
    float2 span = object_set_span(sc, os, org, dir, tmax);
    return span.x <= span.y &&
           grid_trace_any(&sc->f->grid, sc->tris, sc->grid_cells, sc->leaf_start, sc->leaf_quads,
                          org, dir, span, tmax, skip, tc);
}

/* Material of an opaque-scene triangle: its object's own material. */
VB_INLINE uint scene_tri_material(const DevScene *sc, int tri)
{
    return sc->objects[tri_tag(sc->tris, tri) & ~VBCL_TAG_FLAGS].material;
}

#endif
