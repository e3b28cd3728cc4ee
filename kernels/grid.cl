#line 2 "grid.cl"
/* grid.cl — two-level grid traversal (Amanatides & Woo 1987 at both levels; Kalojanov,
 * Stich & Slusallek 2011): the ray walks the top cells, and through a top cell with a
 * sub-grid it walks that cell's sub-cells. Closest hit, accepted only inside the current
 * (sub-)cell, and any hit for shadow feelers; grid_cell_box_range for walks of whole
 * bundles of rays. */
#ifndef VBCL_GRID_CL
#define VBCL_GRID_CL

#include "geometry.cl"

/* Work counters of one ray, summed by the caller into the frame counters. */
typedef struct TraceCount {
    uint steps; /* top cells and sub-cells visited */
    uint tests;
} TraceCount;

/* State of a ray walking a grid (the top level, or one top cell's sub-grid), cell by cell. */
typedef struct GridWalk {
    int cx, cy, cz;   /* the cell */
    int sx, sy, sz;   /* the step per axis, -1 or 1 */
    float nx, ny, nz; /* ray parameter at the next cell boundary, per axis */
    float dx, dy, dz; /* ray parameter across one cell, per axis */
    float3 inv;       /* 1 / direction */
    float t_enter;    /* where the ray enters the grid */
    float t_leave;    /* where it leaves it (or tmax) */
    int axis;         /* the axis of the last step (the face the ray entered the cell by); -1 */
} GridWalk;

/* The state of a closest-hit search: the best hit so far and how far a candidate may lie
 * (hit_before, hit_reach). */
typedef struct Closest {
    VbHit hit;
    uint opaque;
    float window;
    float reach;
} Closest;

/* Sets a walk's cell, steps, next boundaries and deltas: the walk keeps them as scalars,
 * as the step changes one axis at a time (vector lanes cost shuffles there on a CPU). */
VB_INLINE void grid_walk_set(GridWalk *w, int3 c, int3 step, float3 tn, float3 td)
{
    w->cx = c.x;
    w->cy = c.y;
    w->cz = c.z;
    w->sx = step.x;
    w->sy = step.y;
    w->sz = step.z;
    w->nx = tn.x;
    w->ny = tn.y;
    w->nz = tn.z;
    w->dx = td.x;
    w->dy = td.y;
    w->dz = td.z;
}

/* The walk's current cell. */
VB_INLINE int3 grid_walk_cell(const GridWalk *w)
{
    return (int3)(w->cx, w->cy, w->cz);
}

/* Where the ray leaves the current cell. */
VB_INLINE float grid_walk_exit(const GridWalk *w)
{
    return fmin(w->nx, fmin(w->ny, w->nz));
}

/* Where the line from org along the direction whose inverse is inv (+-inf for zero
 * components) lies in the grid's box, which holds every triangle: (enter, leave), the ray
 * parameters of its slab test. */
VB_INLINE float2 grid_box_span(__constant const VbGrid *g, float3 org, float3 inv)
{
    float3 lo = vb_cload3(g->lo), hi = vb_cload3(g->hi);
    float3 t0 = (lo - org) * inv, t1 = (hi - org) * inv;
    float3 tn = fmin(t0, t1), tf = fmax(t0, t1);
    /* NaN (0 * inf, a ray in a slab plane) must not narrow the interval */
    return (float2)(fmax(isnan(tn.x) ? 0.0f : tn.x,
                         fmax(isnan(tn.y) ? 0.0f : tn.y, isnan(tn.z) ? 0.0f : tn.z)),
                    fmin(isnan(tf.x) ? INFINITY : tf.x,
                         fmin(isnan(tf.y) ? INFINITY : tf.y, isnan(tf.z) ? INFINITY : tf.z)));
}

/* Clips the ray's stretch [tmin, tmax] (tmin >= 0) to the grid box and finds its first
 * cell. Returns 0 when the stretch misses the grid. */
VB_INLINE int grid_walk_begin(__constant const VbGrid *g, float3 org, float3 dir, float tmin,
                              float tmax, GridWalk *w)
{
    float3 lo = vb_cload3(g->lo);
    float3 inv = (float3)(1.0f) / dir; /* +-inf for zero components */
    float2 box = grid_box_span(g, org, inv);
    float enter = fmax(tmin, box.x), leave = fmin(tmax, box.y);
    if (!(enter <= leave)) return 0;
    float3 cs = vb_cload3(g->cell), ics = vb_cload3(g->inv_cell);
    int3 n = (int3)(g->n[0], g->n[1], g->n[2]);
    float3 p = org + enter * dir;
    int3 c = convert_int3_sat_rtn((p - lo) * ics);
    c = clamp(c, (int3)(0), n - 1);
    int3 step = select((int3)(-1), (int3)(1), isgreaterequal(dir, (float3)(0.0f)));
    float3 boundary = lo + convert_float3(c + select((int3)(0), (int3)(1), step > 0)) * cs;
    float3 tb = select((boundary - org) * inv, (float3)(INFINITY), isequal(dir, (float3)(0.0f)));
    float3 td = select(cs * fabs(inv), (float3)(INFINITY), isequal(dir, (float3)(0.0f)));
    grid_walk_set(w, c, step, tb, td);
    w->inv = inv;
    w->t_enter = enter;
    w->t_leave = leave;
    w->axis = -1;
    return 1;
}

/* Steps to the next cell of a walk over n cells; returns 0 when the ray leaves them or
 * passes t_leave. */
VB_INLINE int grid_walk_step(int3 n, GridWalk *w)
{
    if (w->nx < w->ny && w->nx < w->nz) {
        if (w->nx > w->t_leave) return 0;
        w->cx += w->sx;
        w->nx += w->dx;
        w->axis = 0;
        return w->cx >= 0 && w->cx < n.x;
    }
    if (w->ny < w->nz) {
        if (w->ny > w->t_leave) return 0;
        w->cy += w->sy;
        w->ny += w->dy;
        w->axis = 1;
        return w->cy >= 0 && w->cy < n.y;
    }
    if (w->nz > w->t_leave) return 0;
    w->cz += w->sz;
    w->nz += w->dz;
    w->axis = 2;
    return w->cz >= 0 && w->cz < n.z;
}

/* Steps to the next top cell; returns 0 when the ray leaves the grid or passes t_leave. */
VB_INLINE int grid_walk_next(__constant const VbGrid *g, GridWalk *w)
{
    return grid_walk_step((int3)(g->n[0], g->n[1], g->n[2]), w);
}

VB_INLINE int grid_cell_index(__constant const VbGrid *g, int3 c)
{
    return c.x + g->n[0] * (c.y + g->n[1] * c.z);
}

/* A top cell's sub-grid resolution (1, 1, 1: a plain list). */
VB_INLINE int3 grid_cell_res(VbGridCell gc)
{
    return (int3)((int)(gc.res & VBCL_GRID_SUB_MASK),
                  (int)(gc.res >> VBCL_GRID_SUB_BITS & VBCL_GRID_SUB_MASK),
                  (int)(gc.res >> (2 * VBCL_GRID_SUB_BITS) & VBCL_GRID_SUB_MASK));
}

/* The box of top cell c: its low corner, and the size of one of its n sub-cells. */
VB_INLINE float3 grid_cell_lo(__constant const VbGrid *g, int3 c)
{
    return vb_cload3(g->lo) + convert_float3(c) * vb_cload3(g->cell);
}

/* Starts the walk of a ray through the sub-grid of n cells of the top cell the walk top is
 * in, from t_in (where the ray enters that cell) to t_out (where it leaves it, or the walk
 * ends). The first sub-cell is the one holding the point at t_in, on the face the ray
 * entered by (exactly, whatever the rounding of that point). */
VB_INLINE void grid_sub_begin(__constant const VbGrid *g, const GridWalk *top, int3 n, float3 org,
                              float3 dir, float t_in, float t_out, GridWalk *s)
{
    float3 lo = grid_cell_lo(g, grid_walk_cell(top));
    float3 scs = vb_cload3(g->cell) / convert_float3(n);
    int3 c = clamp(convert_int3_sat_rtn((org + t_in * dir - lo) / scs), (int3)(0), n - 1);
    int3 step = (int3)(top->sx, top->sy, top->sz);
    int3 entry = select(n - 1, (int3)(0), step > 0);
    int3 face = (int3)(top->axis == 0 ? -1 : 0, top->axis == 1 ? -1 : 0, top->axis == 2 ? -1 : 0);
    c = select(c, entry, face);
    float3 boundary = lo + convert_float3(c + select((int3)(0), (int3)(1), step > 0)) * scs;
    float3 tn =
        select((boundary - org) * top->inv, (float3)(INFINITY), isequal(dir, (float3)(0.0f)));
    float3 td = (float3)(top->dx, top->dy, top->dz) / convert_float3(n);
    grid_walk_set(s, c, step, tn, td);
    s->inv = top->inv;
    s->t_enter = t_in;
    s->t_leave = t_out;
    s->axis = -1;
}

/* No hit yet, within tmax. */
VB_INLINE void closest_begin(Closest *c, float tmax)
{
    c->hit.t = tmax;
    c->hit.tri = -1;
    c->hit.u = c->hit.v = 0.0f;
    c->opaque = 0u;
    c->window = 0.0f;
    c->reach = tmax;
}

/* A hit at t (u, v) on triangle tri, offered to the closest-hit search *c: kept if it
 * comes before the best so far (hit_before). */
VB_INLINE void closest_offer(float3 org, float tmax, __global const VbTriangle *tris, int tri,
                             float t, float u, float v, Closest *c)
{
    uint opaque = tri_tag(tris, tri) & VBCL_TAG_OPAQUE;
    if (hit_before(t, tri, opaque, c->hit, c->opaque, c->window)) {
        c->hit.t = t;
        c->hit.tri = tri;
        c->hit.u = u;
        c->hit.v = v;
        c->opaque = opaque;
        c->window = hit_contact_window(org, t);
        c->reach = hit_reach(c->hit, c->opaque, c->window, tmax);
    }
}

/* Tests triangle tri for the closest hit, updating *c (ties: the lower index, so the
 * order of the tests does not matter). */
VB_INLINE void closest_test(const RayShear *rs, float3 org, float tmax,
                            __global const VbTriangle *tris, int tri, Closest *c)
{
    float t, u, v;
    if (tri_intersect(rs, tri_vertex(tris, tri, 0), tri_vertex(tris, tri, 1),
                      tri_vertex(tris, tri, 2), c->reach, &t, &u, &v))
        closest_offer(org, tmax, tris, tri, t, u, v, c);
}

/* Coordinate k (0, 1, 2: x, y, z) of four points, one per lane. */
VB_INLINE float4 vb_comp4(float4 x, float4 y, float4 z, uint k)
{
    return k == 0u ? x : (k == 1u ? y : z);
}

/* Vertex k of a quad's four triangles through the ray's shear: ray_shear_apply lane by
 * lane, with the same operations in the same order (contraction is off), so every value
 * below is bit for bit the one tri_intersect computes for that triangle. */
VB_INLINE void quad_shear_vertex(const RayShear *rs, __global const VbLeafQuad *q, int k, float4 *x,
                                 float4 *y, float4 *z)
{
    float4 px = vload4(0, q->xyz[3 * k]) - rs->ox;
    float4 py = vload4(0, q->xyz[3 * k + 1]) - rs->oy;
    float4 pz = vload4(0, q->xyz[3 * k + 2]) - rs->oz;
    float4 qx = vb_comp4(px, py, pz, rs->kx);
    float4 qy = vb_comp4(px, py, pz, rs->ky);
    float4 qz = vb_comp4(px, py, pz, rs->kz);
    *x = qx - rs->sx * qz;
    *y = qy - rs->sy * qz;
    *z = rs->sz * qz;
}

/* A quad's four triangles through the ray's shear, and their edge functions. */
typedef struct QuadShear {
    float4 ax, ay, az, bx, by, bz, cx, cy, cz;
    float4 U, V, W;
} QuadShear;

/* The lanes of a quad that tri_intersect could accept within tmax (-1 per lane; padding
 * lanes included, the caller masks them): tri_intersect's edge-sign and distance tests on
 * all four triangles at once in float4 lanes, whose values are kept in *qs. A lane is left
 * out only where tri_intersect, computing the same values, rejects it too: with an edge
 * function of exactly 0 (which tri_intersect decides again in double) or a NaN the lane
 * stays in. The caller finishes the test of the lanes left on their values (quad_lane_hit),
 * so the hits are those of testing every triangle alone. */
VB_INLINE int4 quad_candidates(const RayShear *rs, __global const VbLeafQuad *q, float tmax,
                               QuadShear *qs)
{
    quad_shear_vertex(rs, q, 0, &qs->ax, &qs->ay, &qs->az);
    quad_shear_vertex(rs, q, 1, &qs->bx, &qs->by, &qs->bz);
    quad_shear_vertex(rs, q, 2, &qs->cx, &qs->cy, &qs->cz);
    float4 ax = qs->ax, ay = qs->ay, bx = qs->bx, by = qs->by, cx = qs->cx, cy = qs->cy;
    float4 U = cx * by - cy * bx;
    float4 V = ax * cy - ay * cx;
    float4 W = bx * ay - by * ax;
    qs->U = U;
    qs->V = V;
    qs->W = W;
    int4 zero = (U == 0.0f) | (V == 0.0f) | (W == 0.0f);
    int4 mixed = ((U < 0.0f) | (V < 0.0f) | (W < 0.0f)) & ((U > 0.0f) | (V > 0.0f) | (W > 0.0f));
    float4 det = U + V + W;
    float4 T = U * qs->az + V * qs->bz + W * qs->cz;
    float4 lim = tmax * det;
    int4 outside = select((T >= 0.0f) | (T < lim), (T <= 0.0f) | (T > lim), det > 0.0f);
    return zero | ~(mixed | outside);
}

/* Lane l (0 .. 3, a constant where it is called) of v. */
VB_INLINE float vb_lane4(float4 v, int l)
{
    return l == 0 ? v.s0 : (l == 1 ? v.s1 : (l == 2 ? v.s2 : v.s3));
}

/* tri_intersect of triangle tri in lane l of a quad within tmax, finished from the values
 * quad_candidates kept: no second read of the triangle, no second shear (but for a hit
 * closer than the float test's error bound, decided in double from its vertices). */
VB_INLINE int quad_lane_hit(const RayShear *rs, const QuadShear *qs, int l,
                            __global const VbTriangle *tris, int tri, float tmax, float *t,
                            float *u, float *v)
{
    int hit = tri_finish(vb_lane4(qs->ax, l), vb_lane4(qs->ay, l), vb_lane4(qs->az, l),
                         vb_lane4(qs->bx, l), vb_lane4(qs->by, l), vb_lane4(qs->bz, l),
                         vb_lane4(qs->cx, l), vb_lane4(qs->cy, l), vb_lane4(qs->cz, l),
                         vb_lane4(qs->U, l), vb_lane4(qs->V, l), vb_lane4(qs->W, l), tmax, t, u, v);
#ifdef cl_khr_fp64
    if (hit == TRI_CLOSE)
        hit = tri_close(rs, tri_vertex(tris, tri, 0), tri_vertex(tris, tri, 1),
                        tri_vertex(tris, tri, 2), tmax, t);
#else
    (void)rs;
    (void)tris;
    (void)tri;
#endif
    return hit;
}

/* closest_test of triangle tri, in lane l of a quad. */
VB_INLINE void closest_lane(const RayShear *rs, const QuadShear *qs, int l, float3 org, float tmax,
                            __global const VbTriangle *tris, int tri, Closest *c)
{
    float t, u, v;
    if (quad_lane_hit(rs, qs, l, tris, tri, c->reach, &t, &u, &v))
        closest_offer(org, tmax, tris, tri, t, u, v, c);
}

/* The triangles of a quad, one index per lane (-1: padding). */
VB_INLINE int4 quad_ids(__global const VbLeafQuad *q)
{
    return vload4(0, q->tri);
}

/* How many lanes of a mask (-1 or 0 each) are set. */
VB_INLINE uint vb_count4(int4 m)
{
    return (uint)(-(m.s0 + m.s1 + m.s2 + m.s3));
}

/* Tests the triangles of one quad for the closest hit, four at a time (quad_candidates) and
 * then each lane the quad's test leaves in on its own (quad_lane_hit), updating *c. Returns
 * the number of triangles tested. */
VB_INLINE uint quad_closest(const RayShear *rs, float3 org, float tmax,
                            __global const VbTriangle *tris, __global const VbLeafQuad *q,
                            Closest *c)
{
    int4 id = quad_ids(q);
    int4 real = id >= 0;
    QuadShear qs;
    int4 cand = quad_candidates(rs, q, c->reach, &qs) & real;
    if (cand.s0) closest_lane(rs, &qs, 0, org, tmax, tris, id.s0, c);
    if (cand.s1) closest_lane(rs, &qs, 1, org, tmax, tris, id.s1, c);
    if (cand.s2) closest_lane(rs, &qs, 2, org, tmax, tris, id.s2, c);
    if (cand.s3) closest_lane(rs, &qs, 3, org, tmax, tris, id.s3, c);
    return vb_count4(real);
}

/* Tests the triangles of quads begin .. end - 1 for the closest hit, quad by quad
 * (quad_closest), updating *c. Returns the number of triangles tested. */
VB_INLINE uint quads_closest(const RayShear *rs, float3 org, float tmax,
                             __global const VbTriangle *tris, __global const VbLeafQuad *quads,
                             uint begin, uint end, Closest *c)
{
    uint n = 0;
    for (uint k = begin; k < end; k++) n += quad_closest(rs, org, tmax, tris, quads + k, c);
    return n;
}

/* Tests the triangles of one leaf (a sub-cell or a top cell's list) for the closest hit
 * (quads_closest), updating *c. Returns the number of triangles tested. */
VB_INLINE uint grid_leaf_closest(const RayShear *rs, float3 org, float tmax,
                                 __global const VbTriangle *tris, __global const uint *leaf_start,
                                 __global const VbLeafQuad *quads, uint leaf, Closest *c)
{
    return quads_closest(rs, org, tmax, tris, quads, leaf_start[leaf], leaf_start[leaf + 1], c);
}

/* The closest-hit search *cp (hits with 0 < t <= tmax) carried on through the cells that
 * the ray's stretch span (within [0, tmax]) crosses: a search begun on some triangles
 * alone goes on in the grid where only the grid can say. A hit found in a cell (a
 * sub-cell where the top cell has a sub-grid) is accepted only if it (and the window in
 * which an opaque surface in contact would still come first, hit_before) lies before that
 * cell's exit, so a triangle that also spans later cells cannot hide a closer one there.
 * Ties go to the lower triangle index. */
VB_INLINE void grid_walk_closest(__constant const VbGrid *g, __global const VbTriangle *tris,
                                 __global const VbGridCell *cells, __global const uint *leaf_start,
                                 __global const VbLeafQuad *leaf_quads, float3 org, float3 dir,
                                 float2 span, float tmax, Closest *cp, TraceCount *count)
{
    Closest c = *cp;
    GridWalk w;
    if (!grid_walk_begin(g, org, dir, span.x, span.y, &w)) return;
    RayShear rs = ray_shear_make(org, dir);
    uint steps = 0, tests = 0;
    float t_in = w.t_enter;
    do {
        steps++;
        VbGridCell gc = cells[grid_cell_index(g, grid_walk_cell(&w))];
        float cell_exit = grid_walk_exit(&w);
        if (gc.res == VBCL_GRID_LIST) {
            tests += grid_leaf_closest(&rs, org, tmax, tris, leaf_start, leaf_quads, gc.first, &c);
        } else {
            int3 n = grid_cell_res(gc);
            GridWalk s;
            grid_sub_begin(g, &w, n, org, dir, t_in, fmin(cell_exit, w.t_leave), &s);
            do {
                steps++;
                uint leaf = gc.first + (uint)(s.cx + n.x * (s.cy + n.y * s.cz));
                tests += grid_leaf_closest(&rs, org, tmax, tris, leaf_start, leaf_quads, leaf, &c);
                float sub_exit = grid_walk_exit(&s);
                if (c.hit.tri >= 0 && c.reach <= fmin(sub_exit, cell_exit)) break;
            } while (grid_walk_step(n, &s));
        }
        if (c.hit.tri >= 0 && c.reach <= cell_exit) break;
        t_in = cell_exit;
    } while (grid_walk_next(g, &w));
    count->steps += steps;
    count->tests += tests;
    *cp = c;
}

/* Closest hit of the ray (org, dir) with 0 < t <= tmax, through the grid. */
VB_INLINE VbHit grid_trace_closest(__constant const VbGrid *g, __global const VbTriangle *tris,
                                   __global const VbGridCell *cells,
                                   __global const uint *leaf_start,
                                   __global const VbLeafQuad *leaf_quads, float3 org, float3 dir,
                                   float tmax, TraceCount *count)
{
    Closest c;
    closest_begin(&c, tmax);
    grid_walk_closest(g, tris, cells, leaf_start, leaf_quads, org, dir, (float2)(0.0f, tmax), tmax,
                      &c, count);
    return c.hit;
}

/* Whether any triangle of quads begin .. end - 1 lies on the ray before tmax, those whose
 * tag has a bit of `skip` (VBCL_TAG_TEXTURE or 0) not counted; adds the tests to *tests (a
 * quad's real lanes; a skipped texture quad none). */
VB_INLINE int quads_any(const RayShear *rs, float tmax, __global const VbTriangle *tris,
                        __global const VbLeafQuad *quads, uint begin, uint end, uint skip,
                        uint *tests)
{
    for (uint k = begin; k < end; k++) {
        __global const VbLeafQuad *q = quads + k;
        int4 id = quad_ids(q);
        /* the real lanes of a quad share VBCL_TAG_TEXTURE (pack_quads), lane 0 is real */
        if ((skip & tri_tag(tris, id.s0) & VBCL_TAG_TEXTURE) != 0u) continue;
        int4 real = id >= 0;
        *tests += vb_count4(real);
        QuadShear qs;
        int4 cand = quad_candidates(rs, q, tmax, &qs) & real;
        float t, u, v;
        if ((cand.s0 && quad_lane_hit(rs, &qs, 0, tris, id.s0, tmax, &t, &u, &v)) ||
            (cand.s1 && quad_lane_hit(rs, &qs, 1, tris, id.s1, tmax, &t, &u, &v)) ||
            (cand.s2 && quad_lane_hit(rs, &qs, 2, tris, id.s2, tmax, &t, &u, &v)) ||
            (cand.s3 && quad_lane_hit(rs, &qs, 3, tris, id.s3, tmax, &t, &u, &v)))
            return 1;
    }
    return 0;
}

/* quads_any over the quads of one leaf. */
VB_INLINE int grid_leaf_any(const RayShear *rs, float tmax, __global const VbTriangle *tris,
                            __global const uint *leaf_start, __global const VbLeafQuad *quads,
                            uint leaf, uint skip, uint *tests)
{
    return quads_any(rs, tmax, tris, quads, leaf_start[leaf], leaf_start[leaf + 1], skip, tests);
}

/* Returns 1 when anything lies on the ray (org, dir) with 0 < t < tmax (a shadow
 * feeler: the first occluder ends the walk) in the cells the stretch span (within
 * [0, tmax]) crosses; triangles whose tag has a bit of `skip` (VBCL_TAG_TEXTURE, or 0) are
 * not occluders. */
VB_INLINE int grid_trace_any(__constant const VbGrid *g, __global const VbTriangle *tris,
                             __global const VbGridCell *cells, __global const uint *leaf_start,
                             __global const VbLeafQuad *leaf_quads, float3 org, float3 dir,
                             float2 span, float tmax, uint skip, TraceCount *count)
{
    GridWalk w;
    if (!grid_walk_begin(g, org, dir, span.x, span.y, &w)) return 0;
    RayShear rs = ray_shear_make(org, dir);
    uint steps = 0, tests = 0;
    int blocked = 0;
    float t_in = w.t_enter;
    do {
        steps++;
        VbGridCell gc = cells[grid_cell_index(g, grid_walk_cell(&w))];
        float cell_exit = grid_walk_exit(&w);
        if (gc.res == VBCL_GRID_LIST) {
            blocked =
                grid_leaf_any(&rs, tmax, tris, leaf_start, leaf_quads, gc.first, skip, &tests);
        } else {
            int3 n = grid_cell_res(gc);
            GridWalk s;
            grid_sub_begin(g, &w, n, org, dir, t_in, fmin(cell_exit, w.t_leave), &s);
            do {
                steps++;
                uint leaf = gc.first + (uint)(s.cx + n.x * (s.cy + n.y * s.cz));
                blocked =
                    grid_leaf_any(&rs, tmax, tris, leaf_start, leaf_quads, leaf, skip, &tests);
            } while (!blocked && grid_walk_step(n, &s));
        }
        t_in = cell_exit;
    } while (!blocked && grid_walk_next(g, &w));
    count->steps += steps;
    count->tests += tests;
    return blocked;
}

/* The leaves of one top cell that an axis-aligned box overlaps: for a walk of whole bundles
 * of rays, whose cone within the cell lies in the box. Leaf k of k = 0 .. count - 1 is
 * grid_box_leaf(&range, k); its triangles are those of leaf_quads[leaf_start[leaf] ..
 * leaf_start[leaf + 1] - 1] (lanes with tri >= 0). A cell without a sub-grid gives its one list. A
 * triangle can be listed in several of the leaves. */
typedef struct GridBoxRange {
    uint first; /* the cell's first leaf */
    int3 n;     /* its sub-grid resolution */
    int3 lo;    /* the first sub-cell of the box, per axis */
    int3 size;  /* sub-cells of the box per axis */
    uint count; /* size.x * size.y * size.z */
} GridBoxRange;

/* The sub-cells of top cell `cell` overlapping the box [blo, bhi] (world coordinates; the
 * part beyond the cell is ignored, a box outside the cell gives its border sub-cells). The
 * box is widened by 1e-3 of a sub-cell so that rounding never drops a sub-cell it touches
 * (the build lists a triangle on a sub-cell face on both sides). */
VB_INLINE GridBoxRange grid_cell_box_range(__constant const VbGrid *g,
                                           __global const VbGridCell *cells, int3 cell, float3 blo,
                                           float3 bhi)
{
    GridBoxRange r;
    VbGridCell gc = cells[grid_cell_index(g, cell)];
    r.first = gc.first;
    r.n = grid_cell_res(gc);
    float3 lo = grid_cell_lo(g, cell);
    float3 iscs = convert_float3(r.n) / vb_cload3(g->cell);
    int3 a = convert_int3_sat_rtn((blo - lo) * iscs - 1e-3f);
    int3 b = convert_int3_sat_rtn((bhi - lo) * iscs + 1e-3f);
    r.lo = clamp(a, (int3)(0), r.n - 1);
    r.size = clamp(b, (int3)(0), r.n - 1) - r.lo + 1;
    r.size = max(r.size, (int3)(1)); /* an inverted box: one border sub-cell */
    r.count = (uint)(r.size.x * r.size.y * r.size.z);
    return r;
}

/* Leaf k (0 .. r->count - 1) of a box range, x fastest. */
VB_INLINE uint grid_box_leaf(const GridBoxRange *r, uint k)
{
    int x = r->lo.x + (int)(k % (uint)r->size.x);
    int y = r->lo.y + (int)(k / (uint)r->size.x % (uint)r->size.y);
    int z = r->lo.z + (int)(k / ((uint)r->size.x * (uint)r->size.y));
    return r->first + (uint)(x + r->n.x * (y + r->n.y * z));
}

#endif
