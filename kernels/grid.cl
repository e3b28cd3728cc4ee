#line 2 "grid.cl"
/* grid.cl — uniform-grid traversal (Amanatides & Woo 1987): closest hit, accepted only
 * inside the current cell, and any hit for shadow feelers. */
#ifndef VBCL_GRID_CL
#define VBCL_GRID_CL

#include "geometry.cl"

/* Work counters of one ray, summed by the caller into the frame counters. */
typedef struct TraceCount {
    uint steps;
    uint tests;
} TraceCount;

/* State of a ray walking the grid, cell by cell. */
typedef struct GridWalk {
    int3 cell;
    int3 step;
    float3 t_next;  /* ray parameter at the next cell boundary, per axis */
    float3 t_delta; /* ray parameter across one cell, per axis */
    float t_enter;  /* where the ray enters the grid */
    float t_leave;  /* where it leaves it (or tmax) */
} GridWalk;

/* Clips the ray to the grid box and finds its first cell. Returns 0 when the ray misses
 * the grid or the part of it within (0, tmax]. */
VB_INLINE int grid_walk_begin(__constant const VbGrid *g, float3 org, float3 dir, float tmax,
                              GridWalk *w)
{
    float3 lo = vb_cload3(g->lo), hi = vb_cload3(g->hi);
    float3 inv = (float3)(1.0f) / dir; /* +-inf for zero components */
    float3 t0 = (lo - org) * inv, t1 = (hi - org) * inv;
    float3 tn = fmin(t0, t1), tf = fmax(t0, t1);
    /* NaN (0 * inf, a ray in a slab plane) must not narrow the interval */
    float enter = fmax(0.0f, fmax(isnan(tn.x) ? 0.0f : tn.x,
                                  fmax(isnan(tn.y) ? 0.0f : tn.y, isnan(tn.z) ? 0.0f : tn.z)));
    float leave =
        fmin(tmax, fmin(isnan(tf.x) ? INFINITY : tf.x,
                        fmin(isnan(tf.y) ? INFINITY : tf.y, isnan(tf.z) ? INFINITY : tf.z)));
    if (!(enter <= leave)) return 0;
    float3 cs = vb_cload3(g->cell), ics = vb_cload3(g->inv_cell);
    int3 n = (int3)(g->n[0], g->n[1], g->n[2]);
    float3 p = org + enter * dir;
    int3 c = convert_int3_sat_rtn((p - lo) * ics);
    c = clamp(c, (int3)(0), n - 1);
    w->cell = c;
    w->step = select((int3)(-1), (int3)(1), isgreaterequal(dir, (float3)(0.0f)));
    float3 boundary = lo + convert_float3(c + select((int3)(0), (int3)(1), w->step > 0)) * cs;
    w->t_next = select((boundary - org) * inv, (float3)(INFINITY), isequal(dir, (float3)(0.0f)));
    w->t_delta = select(cs * fabs(inv), (float3)(INFINITY), isequal(dir, (float3)(0.0f)));
    w->t_enter = enter;
    w->t_leave = leave;
    return 1;
}

/* Steps to the next cell; returns 0 when the ray leaves the grid or passes t_leave. */
VB_INLINE int grid_walk_next(__constant const VbGrid *g, GridWalk *w)
{
    float3 tn = w->t_next;
    if (tn.x < tn.y && tn.x < tn.z) {
        if (tn.x > w->t_leave) return 0;
        w->cell.x += w->step.x;
        w->t_next.x += w->t_delta.x;
        return w->cell.x >= 0 && w->cell.x < g->n[0];
    }
    if (tn.y < tn.z) {
        if (tn.y > w->t_leave) return 0;
        w->cell.y += w->step.y;
        w->t_next.y += w->t_delta.y;
        return w->cell.y >= 0 && w->cell.y < g->n[1];
    }
    if (tn.z > w->t_leave) return 0;
    w->cell.z += w->step.z;
    w->t_next.z += w->t_delta.z;
    return w->cell.z >= 0 && w->cell.z < g->n[2];
}

VB_INLINE int grid_cell_index(__constant const VbGrid *g, int3 c)
{
    return c.x + g->n[0] * (c.y + g->n[1] * c.z);
}

/* Closest hit of the ray (org, dir) with 0 < t <= tmax. A hit found in a cell is
 * accepted only if it (and the window in which an opaque surface in contact would still
 * come first, hit_before) lies before the cell's exit, so a triangle that also spans later
 * cells cannot hide a closer one there. Ties go to the lower triangle index. */
VB_INLINE VbHit grid_trace_closest(__constant const VbGrid *g, __global const VbTriangle *tris,
                                   __global const uint *cell_start, __global const uint *cell_tris,
                                   float3 org, float3 dir, float tmax, TraceCount *count)
{
    VbHit hit;
    hit.t = tmax;
    hit.tri = -1;
    hit.u = hit.v = 0.0f;
    GridWalk w;
    if (!grid_walk_begin(g, org, dir, tmax, &w)) return hit;
    RayShear rs = ray_shear_make(org, dir);
    uint steps = 0, tests = 0, hit_opaque = 0u;
    float window = 0.0f, reach = tmax;
    do {
        steps++;
        int ci = grid_cell_index(g, w.cell);
        uint begin = cell_start[ci], end = cell_start[ci + 1];
        tests += end - begin;
        for (uint k = begin; k < end; k++) {
            int tri = (int)cell_tris[k];
            float t, u, v;
            if (tri_intersect(&rs, tri_vertex(tris, tri, 0), tri_vertex(tris, tri, 1),
                              tri_vertex(tris, tri, 2), reach, &t, &u, &v)) {
                uint opaque = tri_tag(tris, tri) & VBCL_TAG_OPAQUE;
                if (hit_before(t, tri, opaque, hit, hit_opaque, window)) {
                    hit.t = t;
                    hit.tri = tri;
                    hit.u = u;
                    hit.v = v;
                    hit_opaque = opaque;
                    window = hit_contact_window(org, t);
                    reach = hit_reach(hit, hit_opaque, window, tmax);
                }
            }
        }
        float cell_exit = fmin(w.t_next.x, fmin(w.t_next.y, w.t_next.z));
        if (hit.tri >= 0 && reach <= cell_exit) break;
    } while (grid_walk_next(g, &w));
    count->steps += steps;
    count->tests += tests;
    return hit;
}

/* Returns 1 when anything lies on the ray (org, dir) with 0 < t < tmax (a shadow
 * feeler: the first occluder ends the walk). */
VB_INLINE int grid_trace_any(__constant const VbGrid *g, __global const VbTriangle *tris,
                             __global const uint *cell_start, __global const uint *cell_tris,
                             float3 org, float3 dir, float tmax, TraceCount *count)
{
    GridWalk w;
    if (!grid_walk_begin(g, org, dir, tmax, &w)) return 0;
    RayShear rs = ray_shear_make(org, dir);
    uint steps = 0, tests = 0;
    int blocked = 0;
    do {
        steps++;
        int ci = grid_cell_index(g, w.cell);
        uint begin = cell_start[ci], end = cell_start[ci + 1];
        for (uint k = begin; k < end && !blocked; k++) {
            int tri = (int)cell_tris[k];
            float t, u, v;
            tests++;
            blocked = tri_intersect(&rs, tri_vertex(tris, tri, 0), tri_vertex(tris, tri, 1),
                                    tri_vertex(tris, tri, 2), tmax, &t, &u, &v);
        }
    } while (!blocked && grid_walk_next(g, &w));
    count->steps += steps;
    count->tests += tests;
    return blocked;
}

#endif
