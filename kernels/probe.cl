#line 2 "probe.cl"
/* probe.cl — kernels for the tests and the ray-throughput bench only, a program of their
 * own (the test binaries embed it; vbcl does not, so it is in no render's source or cache
 * key): brute-force closest hit, the layout of the shared structs as the device sees it,
 * local shading at arbitrary points for analytic checks, the grid's box ranges, and the
 * renderer's tracing and shading on rays the bench picks (tests/bench/bench_rays.c). */
#ifndef VBCL_PROBE_CL
#define VBCL_PROBE_CL

#include "render.cl"

/* For the tests: per query (a top cell and a box: cell xyz in q[0..2] as floats, box
 * corners in q[4..6] and q[8..10], 12 floats a query) marks in mark[query * ntris + tri]
 * every triangle of the leaves grid_cell_box_range gives. */
__kernel void probe_grid_box_range(__constant const VbFrame *f, __global const VbGridCell *cells,
                                   __global const uint *leaf_start,
                                   __global const VbLeafQuad *leaf_quads, __global const float *q,
                                   uint nq, uint ntris, __global uchar *mark)
{
    uint i = get_global_id(0);
    if (i >= nq) return;
    __global const float *p = q + 12 * i;
    int3 cell = convert_int3((float3)(p[0], p[1], p[2]));
    GridBoxRange r = grid_cell_box_range(&f->grid, cells, cell, vload3(0, p + 4), vload3(0, p + 8));
    for (uint k = 0; k < r.count; k++) {
        uint leaf = grid_box_leaf(&r, k);
        for (uint j = leaf_start[leaf]; j < leaf_start[leaf + 1]; j++)
            for (int l = 0; l < 4; l++)
                if (leaf_quads[j].tri[l] >= 0) mark[(size_t)i * ntris + leaf_quads[j].tri[l]] = 1;
    }
}

/* rays -> hits by testing every triangle: the reference for the grid. */
__kernel void probe_intersect_brute(__global const VbTriangle *tris, uint ntris,
                                    __global const VbRay *rays, int nrays, __global VbHit *hits)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    VbRay r = rays[i];
    RayShear rs = ray_shear_make(vb_load3(r.org), vb_load3(r.dir));
    VbHit hit = {r.tmax, -1, 0.0f, 0.0f};
    uint hit_opaque = 0u;
    float window = 0.0f, reach = r.tmax;
    for (uint k = 0; k < ntris; k++) {
        float t, u, v;
        if (!tri_intersect(&rs, tri_vertex(tris, k, 0), tri_vertex(tris, k, 1),
                           tri_vertex(tris, k, 2), reach, &t, &u, &v))
            continue;
        uint opaque = tri_tag(tris, (int)k) & VBCL_TAG_OPAQUE;
        if (hit_before(t, (int)k, opaque, hit, hit_opaque, window)) {
            hit.t = t;
            hit.tri = (int)k;
            hit.u = u;
            hit.v = v;
            hit_opaque = opaque;
            window = hit_contact_window(vb_load3(r.org), t);
            reach = hit_reach(hit, hit_opaque, window, r.tmax);
        }
    }
    hits[i] = hit;
}

/* The sizes and offsets of the shared structs as compiled for the device. */
__kernel void probe_layout(__global uint *out)
{
    if (get_global_id(0) != 0) return;
    uint k = 0;
#define PROBE_LAYOUT_ITEM(e) out[k++] = (uint)(e);
    VBCL_LAYOUT_ITEMS(PROBE_LAYOUT_ITEM)
#undef PROBE_LAYOUT_ITEM
}

/* The scene arguments every frame kernel starts with, for probes that shade. */
/* points (xyz + unused), normals (xyz + band + 1: 0 for white) -> radiance: local shading of
 * material 0 at given points with given normals, seen from along the normal, in the
 * camera's medium, by a ray of the given wavelength band. */
__kernel void probe_shade_points(SCENE_KERNEL_ARGS __global const float *points,
                                 __global const float *pnormals, int npoints,
                                 __global float *radiance)
{
    int i = get_global_id(0);
    if (i >= npoints) return;
    DevScene sc = DEV_SCENE;
    ShadePoint sp;
    sp.p = vload3(0, points + 4 * i);
    sp.ng = normalize(vload3(0, pnormals + 4 * i));
    sp.ns = sp.ng;
    sp.wo = sp.ng;
    sp.material = 0;
    sp.key = vb_hash((uint)i);
    sp.medium = f->camera_medium;
    sp.err = vb_offset_error(sp.ng.x, sp.ng.y, sp.ng.z, fabs(sp.p.x), fabs(sp.p.y), fabs(sp.p.z));
    sp.object = -1;
    sp.tri = -1;
    sp.front = 0;
    sp.band = (int)pnormals[4 * i + 3] - 1;
    TraceCount tc = {0, 0};
    ShadowCount sc2 = {0, 0, 0, 0, 0, 0};
    float3 col = light_shade_local(&sc, &sp, f->shadow_strata, &tc, &sc2);
    vstore4((float4)(col, (float)sc2.traced), i, radiance);
}

/* cases (dir xyz, eta1; normal xyz, eta2) -> (reflected xyz, R; transmitted xyz, T;
 * tir, 0, 0, 0): the interface optics on their own, normal facing the ray; thesis 1: the
 * energy split of the thesis's eq. 9. */
__kernel void probe_optics(__global const float *in, int n, __global float *out, int thesis)
{
    int i = get_global_id(0);
    if (i >= n) return;
    float3 d = vload3(0, in + 8 * i), nrm = vload3(0, in + 8 * i + 4);
    float eta1 = in[8 * i + 3], eta2 = in[8 * i + 7];
    OpticsSplit s = optics_split(d, nrm, nrm, eta1, eta2, thesis);
    vstore4((float4)(s.reflected, s.R), 0, out + 12 * i);
    vstore4((float4)(s.transmitted, s.T), 0, out + 12 * i + 4);
    vstore4((float4)((float)s.tir, 0.0f, 0.0f, 0.0f), 0, out + 12 * i + 8);
}

#ifdef VBCL_HAS_TRANSPARENCY
/* For probe_cone_brute: whether a feeler (org, w, t) that object_set_feeler calls blocked
 * meets the solid part whose core it passes (every triangle of it tested), and, from a
 * point of a surface that bounds no volume outside every host's box (where the probe's
 * medium, the camera's, is right), whether its walk through the grid lets nothing by. */
VB_INLINE int probe_blocked_feeler(const DevScene *sc, const ShadePoint *sp, const ObjectSet *os,
                                   float3 org, float3 w, float t)
{
    int meets = 0;
    RayShear rb = ray_shear_make(org, w);
    for (int k = 0; k < os->nbig && !meets; k++) {
        __global const VbObject *el = sc->objects + os->big[k];
        if (!(el->flags & VBCL_OBJECT_SOLID) || !object_segment_through_core(el, org, w, t))
            continue;
        Closest cp;
        closest_begin(&cp, t);
        for (uint q = el->first_tri; q < el->first_tri + el->ntris; q++)
            closest_test(&rb, org, t, sc->tris, (int)q, &cp);
        meets = cp.hit.tri >= 0;
    }
    int plain = sp->object >= 0 && !(sc->objects[sp->object].flags & VBCL_OBJECT_HOST);
    for (uint o = 0; o < sc->f->nobjects; o++) {
        __global const VbObject *ho = sc->objects + o;
        if ((ho->flags & VBCL_OBJECT_HOST) && all(isgreaterequal(org, vload3(0, ho->lo))) &&
            all(islessequal(org, vload3(0, ho->hi))))
            plain = 0;
    }
    float3 v = (float3)(0.0f);
    if (plain) {
        ObjectSet grid;
        grid.n = -1;
        grid.sole = -1;
        TraceCount tw = {0, 0};
        v = medium_shadow_transmittance(sc, &grid, org, w, t, sp->medium, -1, &tw);
    }
    return meets && vb_max3(v) <= 0.0f;
}
#endif

/* For probe_cone_brute: the closest hit of the feeler (org, w, t) among all triangles but
 * those of os's big parts, into *all; returns a big part's triangle the feeler meets
 * inside its host (by more than 1e-4 of the scene's size; outside, a part's surface
 * changes nothing), or 0xffffffff. A texture triangle met outside the sphere of its host's
 * own triangles (VbObject.own, whose radius has the host's margins) is left out too: it
 * lies outside the host, where it changes nothing. */
VB_INLINE uint probe_feeler_closest(const DevScene *sc, const ObjectSet *os, float3 org, float3 w,
                                    float t, Closest *all)
{
    RayShear rs = ray_shear_make(org, w);
    closest_begin(all, t);
    for (uint q = 0; q < sc->f->ntris; q++) {
        int part = -1;
        for (int k = 0; k < os->nbig; k++) {
            __global const VbObject *el = sc->objects + os->big[k];
            if (os->big[k] >= sc->f->nobjects && q - el->first_tri < el->ntris)
                part = (int)os->big[k];
        }
        uint tag = tri_tag(sc->tris, (int)q);
        if (part < 0 && (tag & VBCL_TAG_TEXTURE)) {
            float th, uh, vh;
            if (!tri_intersect(&rs, tri_vertex(sc->tris, (int)q, 0),
                               tri_vertex(sc->tris, (int)q, 1), tri_vertex(sc->tris, (int)q, 2), t,
                               &th, &uh, &vh))
                continue;
            float3 p = org + th * w;
            float4 own = vload4(0, sc->objects[tag & ~VBCL_TAG_FLAGS].own);
            if (length(p - own.xyz) > own.w) continue; /* own.w has the host's margins */
        }
        if (part < 0) {
            closest_test(&rs, org, t, sc->tris, (int)q, all);
            continue;
        }
        float th, uh, vh;
        if (!tri_intersect(&rs, tri_vertex(sc->tris, (int)q, 0), tri_vertex(sc->tris, (int)q, 1),
                           tri_vertex(sc->tris, (int)q, 2), t, &th, &uh, &vh))
            continue;
        float3 p = org + th * w;
        __global const VbObject *ho = sc->objects + sc->objects[part].host;
        float depth = INFINITY; /* how far inside every host plane */
        for (uint h = ho->first_tri; h < ho->first_tri + ho->ntris; h++) {
            float3 v0 = tri_vertex(sc->tris, (int)h, 0).xyz;
            float3 nq = normalize(cross(tri_vertex(sc->tris, (int)h, 1).xyz - v0,
                                        tri_vertex(sc->tris, (int)h, 2).xyz - v0));
            depth = fmin(depth, -dot(nq, p - v0));
        }
        if (depth > 1e-4f * (ho->bound[3] + vb_max3(fabs(p)))) return q;
    }
    return 0xffffffffu;
}

/* The shading point of a cone probe's case (probe_cone_brute's layout) in medium m. */
VB_INLINE ShadePoint probe_case_point(__global const float *cs, VbMedium m)
{
    ShadePoint sp;
    sp.p = vload3(0, cs);
    sp.object = (int)cs[3];
    sp.tri = (int)cs[13];
    sp.ng = normalize(vload3(0, cs + 4));
    sp.front = cs[7] > 0.0f;
    sp.ns = sp.ng;
    sp.wo = sp.ng;
    sp.material = 0;
    sp.key = 0;
    sp.medium = m;
    sp.err = cs[12];
    sp.band = -1;
    return sp;
}

/* The cap of the light (radius r) that a cone probe's point sees (ls): its frame and
 * 1 - cos of its half-angle, as light_reflect_area makes them. */
typedef struct ProbeCap {
    float3 wc, tx, ty;
    float one_minus_cos;
} ProbeCap;

VB_INLINE ProbeCap probe_cap_make(const LightShading *ls, float r)
{
    ProbeCap cap;
    cap.wc = ls->to_c / ls->d;
    vb_frame(cap.wc, &cap.tx, &cap.ty);
    cap.one_minus_cos = light_cap_solid_angle(r, ls->d) * (1.0f / (2.0f * VB_PI));
    return cap;
}

/* Feeler k of case i over the cap: uniform in solid angle, the first 8 on its rim. */
VB_INLINE float3 probe_cap_feeler(const ProbeCap *cap, int i, int k)
{
    uint h = vb_hash((uint)i * 7919u + (uint)k);
    float2 u = (float2)(k < 8 ? 1.0f : vb_unit_float(h), vb_unit_float(vb_hash(h ^ 0x5bd1e995u)));
    return light_cap_at(u, cap->one_minus_cos, cap->tx, cap->ty, cap->wc);
}

/* For probe_cone_brute: 1 where the feeler (org, w, t) from sp starts outside some host and
 * meets the bounding sphere of the host with its texture but not the sphere of its own
 * triangles (VbObject.own). */
VB_INLINE uint probe_beside_host(const DevScene *sc, const ShadePoint *sp, float3 org, float3 w,
                                 float t)
{
    for (uint o = 0; o < sc->f->nobjects; o++) {
        __global const VbObject *ho = sc->objects + o;
        if ((ho->flags & VBCL_OBJECT_HOST) && sp->medium.host != (int)o &&
            object_segment_meets(ho, org, w, t) &&
            !sphere_stretch_meets(vload4(0, ho->own), org, w, (float2)(0.0f, t)))
            return 1u;
    }
    return 0u;
}

/* The shadow cone test against brute force. cases, 16 floats each: a point (xyz, its
 * object or -1), its normal on the viewer's side (xyz, 1 when that is its triangle's own
 * normal), a light (centre xyz, radius), the point's ray offset, its triangle -> out:
 * bits 0-1 what light_cone_objects says (0: the grid, 1: clear, 2: a set of triangles
 * alone; 3: the point is inside the light, no test), bit 2 set where the set (or clear
 * cone) has big objects or texture parts whose bounds each feeler tests, bit 3 where some feeler
 * met such bounds (and walks the grid where it lies in them), bit 4 where some feeler passed
 * through a solid part's core (not traced in a render: its walk through the grid, run here, must
 * let nothing through), bit 5 where some feeler that starts outside a host met the bounds of the
 * host with its texture but not the sphere of its own triangles (VbObject.own: object_set_feeler
 * leaves the host out for it), bits 6-15 how many of nrays feelers spread over the light's cap
 * (uniform in solid angle, 8 on its rim; those leaving the surface's front only, each to the near
 * side of the sphere) the brute force (or for the blocked ones, the walk) contradicts: for a clear
 * cone, feelers that meet a triangle, every triangle tested; for a set, feelers whose closest hit
 * among the set's triangles (scene_trace_closest_in) is not the closest of all triangles (the same
 * test, ties to the lower index; the big parts' left out, but a feeler that meets one inside its
 * host is wrong), and for a feeler that meets a big record's bounds, one whose closest or any hit
 * through the set and the grid over object_set_span differs from the whole walk's (bit for bit),
 * bits 16-31 such a feeler's triangle (clear) or its hit + 1 (set). */
__kernel void probe_cone_brute(SCENE_KERNEL_ARGS __global const float *cases, int ncases, int nrays,
                               __global uint *out)
{
    int i = get_global_id(0);
    if (i >= ncases) return;
    DevScene sc = DEV_SCENE;
    __global const float *cs = cases + 16 * i;
    ShadePoint sp = probe_case_point(cs, f->camera_medium);
    float3 c = vload3(0, cs + 8);
    float r = cs[11];
    LightShading ls = light_shading_make(sc.materials, (float3)(0.0f), &sp, c);
    if (ls.d <= r * 1.0001f) {
        out[i] = 3u;
        return;
    }
    ObjectSet os;
    light_cone_objects(&sc, &sp, &ls, r, &os);
    uint kind = os.n == 0 ? 1u : os.n > 0 ? 2u : 0u;
    uint wrong = 0u, which = 0u, big = 0u, blocked = 0u, shell = 0u;
    if (kind != 0u) {
        ProbeCap cap = probe_cap_make(&ls, r);
        for (int k = 0; k < nrays; k++) {
            float3 w = probe_cap_feeler(&cap, i, k);
            if (dot(sp.ng, w) <= 0.0f) continue;
            float t_light = light_sphere_near(&ls, w, r);
            shell |= probe_beside_host(&sc, &sp, ls.origin, w, t_light);
            int need = os.nbig > 0 ? object_set_feeler(&sc, &os, ls.origin, w, t_light,
                                                       sp.medium.tex_counts == 0u, sp.medium.host)
                                   : OBJECT_SET_ALONE;
            if (need == OBJECT_SET_GRID) {
                /* this feeler walks the grid where it lies in the big records' bounds, as a
                 * render's does: the same closest and any hit as a walk of its whole way */
                big++;
                ObjectSet walk = os;
                walk.walk = 1;
                TraceCount tc = {0, 0};
                VbHit h = scene_trace_closest_in(&sc, &walk, ls.origin, w, t_light, &tc);
                VbHit g = scene_trace_closest(&sc, ls.origin, w, t_light, &tc);
                int bad = h.tri != g.tri || (h.tri >= 0 && h.t != g.t) ||
                          scene_trace_any_in(&sc, &walk, ls.origin, w, t_light, 0u, &tc) !=
                              scene_trace_any(&sc, ls.origin, w, t_light, 0u, &tc);
                if (bad && !wrong) which = (uint)(g.tri + 1);
                wrong += bad ? 1u : 0u;
                continue;
            }
#ifdef VBCL_HAS_TRANSPARENCY
            if (need == OBJECT_SET_BLOCKED) {
                int bad = !probe_blocked_feeler(&sc, &sp, &os, ls.origin, w, t_light);
                blocked++;
                if (bad && !wrong) which = 0u;
                wrong += bad ? 1u : 0u;
                continue;
            }
#endif
            Closest all;
            uint inside_tri = probe_feeler_closest(&sc, &os, ls.origin, w, t_light, &all);
            int inside_big = inside_tri != 0xffffffffu;
            if (inside_big && !wrong) which = inside_tri;
            int bad;
            if (inside_big) {
                bad = 1;
            } else if (kind == 1u) {
                bad = all.hit.tri >= 0;
            } else {
                TraceCount tc = {0, 0};
                VbHit h = scene_trace_closest_in(&sc, &os, ls.origin, w, t_light, &tc);
                bad = h.tri != all.hit.tri || (h.tri >= 0 && h.t != all.hit.t);
            }
            if (bad && !wrong && !inside_big) which = (uint)(all.hit.tri + (kind == 2u ? 1 : 0));
            wrong += bad ? 1u : 0u;
        }
    }
    out[i] = kind | (kind != 0u && os.nbig > 0 ? 4u : 0u) | (big > 0u ? 8u : 0u) |
             (blocked > 0u ? 16u : 0u) | shell << 5 | min(wrong, 1023u) << 6 | which << 16;
}

#ifdef VBCL_HAS_TRANSPARENCY
/* medium_shadow_transmittance as it was before ObjectSet.sole: every crossing followed to
 * the light. The reference of probe_sole_exit. */
VB_INLINE float3 probe_transmittance_plain(const DevScene *sc, const ObjectSet *os, float3 org,
                                           float3 dir, float tmax, VbMedium state)
{
    float3 trans = (float3)(1.0f), o = org;
    float left = tmax;
    TraceCount tc = {0, 0};
    for (int guard = 0; guard < 1024; guard++) {
        uint mb = medium_material(sc, state);
        VbHit h = scene_trace_closest_in(sc, os, o, dir, left, &tc);
        if (h.tri < 0) return trans * medium_absorb(sc, mb, left);
        float3 p = tri_point(sc->tris, h);
        float seg = fmax(0.0f, dot(p - o, dir));
        trans *= medium_absorb(sc, mb, seg);
        Crossing c = medium_cross(sc, h.tri, dir, state);
        float3 ng = tri_normal(sc->tris, h.tri);
        if (c.interface) {
            if (sc->materials[c.surface].k_global <= 0.0f) return (float3)(0.0f);
            trans *= sc->materials[c.surface].k_global *
                     medium_interface_transmit(sc, dir, ng, c.mat_before, c.mat_after, -1);
        }
        if (vb_max3(trans) < 1e-7f) return (float3)(0.0f);
        state = c.after;
        left -= seg;
        o = ray_offset_origin(p, dot(ng, dir) > 0.0f ? ng : -ng, tri_point_error(sc->tris, h, ng));
    }
    return (float3)(0.0f);
}

/* The sole host (ObjectSet.sole) against following every crossing: cases as
 * probe_cone_brute's, each point in the medium of host cs[14] (-1: the camera's) -> out:
 * bit 0 where the cone's set belongs to one convex host, bits 1-15 how many of nrays
 * feelers over the light's cap get another amount through as a render traces them (the
 * set's triangles alone, or the grid where a big part's bounds are met; light_feeler_decided)
 * than with every crossing followed (probe_transmittance_plain, the same triangles), bits
 * 16-31 how many feelers start inside the sole host and get light through (each has left
 * it: the walk stopped there). */
__kernel void probe_sole_exit(SCENE_KERNEL_ARGS __global const float *cases, int ncases, int nrays,
                              __global uint *out)
{
    int i = get_global_id(0);
    if (i >= ncases) return;
    DevScene sc = DEV_SCENE;
    __global const float *cs = cases + 16 * i;
    VbMedium m = f->camera_medium;
    if (cs[14] >= 0.0f) {
        m.host = (int)cs[14];
        m.tex_counts = 0u;
    }
    ShadePoint sp = probe_case_point(cs, m);
    float3 c = vload3(0, cs + 8);
    float r = cs[11];
    LightShading ls = light_shading_make(sc.materials, (float3)(0.0f), &sp, c);
    out[i] = 0u;
    if (ls.d <= r * 1.0001f) return;
    ObjectSet os;
    light_cone_objects(&sc, &sp, &ls, r, &os);
    ProbeCap cap = probe_cap_make(&ls, r);
    ObjectSet grid;
    grid.n = -1;
    uint wrong = 0u, exits = 0u;
    for (int k = 0; k < nrays; k++) {
        float3 w = probe_cap_feeler(&cap, i, k);
        if (dot(sp.ng, w) <= 0.0f) continue;
        float t_light = light_sphere_near(&ls, w, r);
        int need = os.n >= 0 && os.nbig > 0
                       ? object_set_feeler(&sc, &os, ls.origin, w, t_light,
                                           sp.medium.tex_counts == 0u, sp.medium.host)
                       : (os.n < 0 ? OBJECT_SET_GRID : OBJECT_SET_ALONE);
        if (need == OBJECT_SET_BLOCKED || (need == OBJECT_SET_ALONE && os.n == 0)) continue;
        TraceCount tc = {0, 0};
        ShadowCount shc = {0, 0, 0, 0, 0, 0};
        float3 fast = light_feeler_decided(&sc, &sp, &os, ls.origin, w, t_light,
                                           sp.medium.tex_counts == 0u, &tc, &shc);
        float3 ref = probe_transmittance_plain(&sc, need == OBJECT_SET_GRID ? &grid : &os,
                                               ls.origin, w, t_light, sp.medium);
        wrong += any(fast != ref) ? 1u : 0u;
        exits += os.sole >= 0 && sp.medium.host == os.sole && vb_max3(ref) > 0.0f;
    }
    out[i] = (os.sole >= 0 ? 1u : 0u) | min(wrong, 32767u) << 1 | min(exits, 65535u) << 16;
}
#endif

/* The feelers' (u1, u2) of light_cap_uv (mode LIGHT_FEELERS_*) for keys key0 .. key0 +
 * nkeys - 1: strata^2 pairs per key, row-major (i, j). */
__kernel void probe_cap_uv(uint strata, uint key0, uint nkeys, int mode, __global float *out)
{
    uint k = get_global_id(0);
    if (k >= nkeys) return;
    CapFeelers cf = light_cap_feelers(mode, strata, key0 + k);
    for (uint i = 0; i < strata; i++)
        for (uint j = 0; j < strata; j++)
            vstore2(light_cap_uv(&cf, i, j), (k * strata + i) * strata + j, out);
}

#ifdef VBCL_HAS_SPECULAR
/* For the lobe test (light_lobe_misses_cap): each case of 12 floats (ns, wo, wc, sin alpha,
 * the exponent, two unused) -> 3 floats: 1 where the test lets a point without a diffuse
 * term skip its feelers, the largest N.H over 65 x 64 directions of the cap (its rim
 * included, placed as light_cap_at places feelers), and nh_min. */
__kernel void probe_lobe_cap(__global const float *cases, int n, __global float *out)
{
    int i = get_global_id(0);
    if (i >= n) return;
    __global const float *c = cases + 12 * i;
    ShadePoint sp;
    sp.ns = normalize(vload3(0, c));
    sp.wo = normalize(vload3(1, c));
    float3 wc = normalize(vload3(2, c));
    float sin_a = c[9];
    LightShading ls;
    ls.diffuse = 0;
    ls.specular = 1;
    ls.nh_min = light_nh_min(c[10]);
    float one_minus_cos = light_cap_solid_angle(sin_a, 1.0f) * (1.0f / (2.0f * VB_PI));
    float3 tx, ty;
    vb_frame(wc, &tx, &ty);
    float best = -1.0f;
    for (int a = 0; a <= 64; a++)
        for (int b = 0; b < 64; b++) {
            float3 w = light_cap_at((float2)((float)a / 64.0f, (float)b / 64.0f), one_minus_cos, tx,
                                    ty, wc);
            best = fmax(best, dot(sp.ns, normalize(w + sp.wo)));
        }
    vstore3((float3)((float)light_lobe_misses_cap(&ls, &sp, wc, sin_a), best, ls.nh_min), i, out);
}
#endif

/* shear constants and single-triangle tests for the watertightness checks:
 * rays x triangles -> 1 if hit. */
__kernel void probe_hit_matrix(__global const VbTriangle *tris, uint ntris,
                               __global const VbRay *rays, int nrays, __global uchar *hit)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    VbRay r = rays[i];
    RayShear rs = ray_shear_make(vb_load3(r.org), vb_load3(r.dir));
    for (uint k = 0; k < ntris; k++) {
        float t, u, v;
        hit[(size_t)i * ntris + k] =
            (uchar)tri_intersect(&rs, tri_vertex(tris, k, 0), tri_vertex(tris, k, 1),
                                 tri_vertex(tris, k, 2), r.tmax, &t, &u, &v);
    }
}

/* points (xyz + unused) -> colours: material `material`'s surface pattern at each point. */
__kernel void probe_pattern(SCENE_KERNEL_ARGS int material, __global const float *points,
                            int npoints, __global float *out)
{
    int i = get_global_id(0);
    if (i >= npoints) return;
    DevScene sc = DEV_SCENE;
    float3 c = scene_pattern_colour(&sc, materials + material, vload3(0, points + 4 * i));
    vstore4((float4)(c, 0.0f), i, out);
}

#ifdef VBCL_HAS_TRANSPARENCY
/* ray (org xyz, dir xyz) -> the rays of its tree that leave the scene, 8 floats each:
 * (dir xyz, band; weight rgb, depth), at most cap of them; *count gets how many left.
 * The same tree as tree_trace_secondary, from a ray of the test's choosing. */
__kernel void probe_tree_exits(SCENE_KERNEL_ARGS __global const float *ray, int cap,
                               __global float *out, __global int *count)
{
    if (get_global_id(0) != 0) return;
    DevScene sc = DEV_SCENE;
    float3 org = vload3(0, ray), dir = normalize(vload3(0, ray + 4));
    VbMedium state = f->camera_medium;
    PathHit ph;
    TraceCount tc = {0, 0};
    TreeCount cnt = {0};
    cnt.prune_budget = 0.0f;
    int k = 0;
    ObjectSet all = object_set_all();
    if (medium_trace(&sc, &all, org, dir, INFINITY, &state, &ph, &tc, &cnt.passes, 0)) {
        TreeRay stack[VB_TREE_STACK];
        int n = 0;
        ShadePoint sp = shade_point_make(&sc, dir, ph.hit, 1u, state, ph.cx.surface);
        tree_spawn(&sc, stack, &n, &sp, dir, &ph.cx, state, (float3)(1.0f), 1, &cnt, -1, 0);
        while (n > 0) {
            TreeRay tr = stack[--n];
            VbMedium st = tr.medium;
            if (!tree_trace(&sc, &tr, &st, &ph, &tc, &cnt.passes)) {
                if (k < cap) {
                    vstore4((float4)(tr.dir, (float)tr.band), 0, out + 8 * k);
                    vstore4((float4)(tr.weight, (float)tr.depth), 0, out + 8 * k + 4);
                }
                k++;
                continue;
            }
            ShadePoint q = shade_point_make(&sc, tr.dir, ph.hit, tr.key, st, ph.cx.surface);
            if (materials[ph.cx.surface].k_global > 0.0f)
                tree_spawn(&sc, stack, &n, &q, tr.dir, &ph.cx, st, tr.weight, tr.depth + 1, &cnt,
                           tr.band, 0);
        }
    }
    *count = k;
}
#endif

#ifdef VBCL_HAS_TRANSPARENCY
/* The object sets of ray-tree rays (ray_objects) against the grid. cases as
 * probe_cone_brute's (a point, its object, its normal on the viewer's side, its ray
 * offset and triangle), and in [14] the host of the viewer's side, in [15] the host of the other
 * side (-1: none) -> out: bits 0-15 how many of nrays rays from the point (directions
 * uniform over the sphere, each from the side it leaves to, but every fourth from the other
 * side, as a reflection about a smooth normal can turn back in) follow a different way
 * through medium_trace with their set than through the grid: another first interface,
 * distance, medium state or count of pass-through crossings, bit for bit; bits 16-21 which
 * of the set's ways some ray took: 16 a set (not the grid), 17 a shell host
 * (VBCL_OBJECT_INNER), 18 a search cut where the ray leaves its convex host (a shorter
 * reach than the grid's box), 19 its own object left behind (the start triangle's, convex
 * or planar, and the ray moving away from it), 20 a big record walked, 21 a set whose
 * ranges and walk found the interface; bits 22-31 a wrong ray's index + 1. */
__kernel void probe_ray_objects(SCENE_KERNEL_ARGS __global const float *cases, int ncases,
                                int nrays, __global uint *out)
{
    int i = get_global_id(0);
    if (i >= ncases) return;
    DevScene sc = DEV_SCENE;
    __global const float *cs = cases + 16 * i;
    float3 p = vload3(0, cs), n = normalize(vload3(0, cs + 4));
    int tri = (int)cs[13];
    float err = cs[12];
    float3 a = tri_vertex(sc.tris, tri, 0).xyz;
    float3 nt = cross(tri_vertex(sc.tris, tri, 1).xyz - a, tri_vertex(sc.tris, tri, 2).xyz - a);
    uint tag = tri_tag(sc.tris, tri);
    __global const VbObject *ob = objects + (tag & ~VBCL_TAG_FLAGS);
    int planar_or_convex =
        !(tag & VBCL_TAG_TEXTURE) &&
        (ob->flags & (VBCL_OBJECT_PLANAR | VBCL_OBJECT_CONVEX | VBCL_OBJECT_HULL));
    uint wrong = 0u, flags = 0u, first = 0u;
    for (int k = 0; k < nrays; k++) {
        uint h1 = vb_hash((uint)(i * nrays + k) * 2u + 1u), h2 = vb_hash(h1 + 0x9e3779b9u);
        float z = 2.0f * ((float)(h1 >> 8) * (1.0f / 16777216.0f)) - 1.0f;
        float phi = 2.0f * VB_PI * ((float)(h2 >> 8) * (1.0f / 16777216.0f));
        float rr = sqrt(fmax(0.0f, 1.0f - z * z));
        float3 w = (float3)(rr * cos(phi), rr * sin(phi), z);
        float s = dot(w, n) >= 0.0f ? 1.0f : -1.0f;
        if ((k & 3) == 3) s = -s; /* turned back */
        float3 o = ray_offset_origin(p, s * n, err);
        VbMedium m0 = {s > 0.0f ? (int)cs[14] : (int)cs[15], 0u};
        ObjectSet os;
        float reach = ray_objects(&sc, o, w, tri, m0.host, &os);
        ObjectSet all = object_set_all();
        VbMedium sa = m0, sb = m0;
        PathHit pa, pb;
        TraceCount tc = {0, 0};
        uint na = 0u, nb = 0u;
        int ha = medium_trace(&sc, &os, o, w, reach, &sa, &pa, &tc, &na, 0);
        int hb = medium_trace(&sc, &all, o, w, INFINITY, &sb, &pb, &tc, &nb, 0);
        int bad = ha != hb || sa.host != sb.host || sa.tex_counts != sb.tex_counts || na != nb ||
                  (ha && (pa.hit.tri != pb.hit.tri || pa.dist != pb.dist));
        if (bad && !first) first = (uint)k + 1u;
        wrong += (uint)bad;
        if (os.n < 0) continue;
        flags |= 1u;
        flags |= os.shell >= 0 ? 2u : 0u;
        if (m0.host >= 0 && (objects[m0.host].flags & VBCL_OBJECT_HULL)) {
            float3 lo = vb_cload3(f->grid.lo), hi = vb_cload3(f->grid.hi);
            float3 t0 = (lo - o) / w, t1 = (hi - o) / w;
            float3 tf = fmax(t0, t1);
            flags |= reach < 0.5f * fmin(tf.x, fmin(tf.y, tf.z)) ? 4u : 0u;
        }
        flags |= planar_or_convex && dot(nt, w) > 0.0f && dot(nt, o - a) > 0.0f ? 8u : 0u;
        flags |= os.nbig > 0 ? 16u : 0u;
        flags |= ha ? 32u : 0u;
        if ((flags & 8u) && ob->nelems > 0u) /* leaving its host: a part left behind */
            for (uint e = ob->first_elem; e < ob->first_elem + ob->nelems; e++)
                flags |= objects[e].ahead & part_ahead_bit(ob, tri) ? 0u : 64u;
    }
    out[i] = min(wrong, 0xffffu) | flags << 16 | min(first, 511u) << 23;
}
#endif

/* ---- The ray-throughput bench (tests/bench/bench_rays.c, `make bench` part "embree") ----
 * Each kernel runs the renderer's own device functions on rays the bench picks, so that a
 * change to the traversal or to the shading path's feelers is measured without editing the
 * bench. Point lists hold indices of primary rays whose first interfaces (hits, media) came
 * from scene_intersect_closest, as in a frame. */

/* rays -> hits: the closest hit of each ray as the renderer finds it: mode 0 through the
 * grid (scene_trace_closest); 1 a camera ray's (camera_trace_closest: its image tile); 2 a
 * ray tree's ray, which leaves triangle r.sample (probe_secondary_rays), among the triangles
 * it can meet (ray_objects, scene_trace_closest_in). Such a ray is inside the host whose
 * triangle it leaves inward, else outside every host, as a ray is that leaves the surface
 * of a host seen from outside (the bench's secondary rays do). */
__kernel void probe_trace_closest(SCENE_KERNEL_ARGS __global const VbRay *rays, int nrays,
                                  __global VbHit *hits, int mode)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    DevScene sc = DEV_SCENE;
    VbRay r = rays[i];
    TraceCount tc = {0, 0};
    float3 org = vb_load3(r.org), dir = vb_load3(r.dir);
    if (mode == 2) {
        int tri = (int)r.sample;
        uint tag = tri_tag(sc.tris, tri);
        __global const VbObject *ob = sc.objects + (tag & ~VBCL_TAG_FLAGS);
        int host = !(tag & VBCL_TAG_TEXTURE) && (ob->flags & VBCL_OBJECT_HOST) &&
                           dot(tri_normal(sc.tris, tri), dir) < 0.0f
                       ? (int)(tag & ~VBCL_TAG_FLAGS)
                       : -1;
        ObjectSet os;
        float reach = ray_objects(&sc, org, dir, tri, host, &os);
        hits[i] = scene_trace_closest_in(&sc, &os, org, dir, fmin(r.tmax, reach), &tc);
        return;
    }
    hits[i] = mode == 1 ? camera_trace_closest(&sc, org, dir, r.tmax, &tc)
                        : scene_trace_closest(&sc, org, dir, r.tmax, &tc);
}

/* rays -> 1 where something lies on the ray before tmax (scene_trace_any), else 0. */
__kernel void probe_trace_any(SCENE_KERNEL_ARGS __global const VbRay *rays, int nrays,
                              __global uchar *blocked)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    DevScene sc = DEV_SCENE;
    VbRay r = rays[i];
    TraceCount tc = {0, 0};
    blocked[i] = (uchar)scene_trace_any(&sc, vb_load3(r.org), vb_load3(r.dir), r.tmax, 0u, &tc);
}

/* The shading point at the first interface of primary ray i, as light_sample_shading makes
 * it; 0 when the ray left the scene. */
VB_INLINE int probe_primary_point(const DevScene *sc, __global const VbRay *rays,
                                  __global const VbHit *hits, __global const VbMedium *media, int i,
                                  ShadePoint *sp)
{
    VbHit h = hits[i];
    if (h.tri < 0) return 0;
    VbRay r = rays[i];
    float3 dir = vb_load3(r.dir);
    VbMedium before = {-1, 0u};
    uint material;
#ifdef VBCL_HAS_MEDIA
    if (FRAME_MEDIA(sc->f)) { /* scene_intersect_closest wrote media[i] */
        before = media[i];
        material = medium_cross(sc, h.tri, dir, before).surface;
    } else
#endif
        material = scene_tri_material(sc, h.tri);
    *sp = shade_point_make(sc, dir, h, sample_key(sc->f, r.sample), before, material);
    return 1;
}

/* rays, hits, media -> the material of each first interface's surface, or -1: a miss. */
__kernel void probe_hit_surface(SCENE_KERNEL_ARGS __global const VbRay *rays,
                                __global const VbHit *hits, __global const VbMedium *media,
                                int nrays, __global int *surface)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    DevScene sc = DEV_SCENE;
    ShadePoint sp;
    surface[i] = probe_primary_point(&sc, rays, hits, media, i, &sp) ? (int)sp.material : -1;
}

/* points -> feelers decided (ShadowCount.traced + clear + blocked: traced, or not traced
 * because their cone meets no object or they pass through a solid part's core) and
 * radiance: the renderer's local shading of each point
 * with its shadow feelers, light_shade_local as light_sample_shading runs it. */
__kernel void probe_shade_feelers(SCENE_KERNEL_ARGS __global const VbRay *rays,
                                  __global const VbHit *hits, __global const VbMedium *media,
                                  __global const uint *points, int npoints, __global uint *traced,
                                  __global float *radiance)
{
    int j = get_global_id(0);
    if (j >= npoints) return;
    DevScene sc = DEV_SCENE;
    ShadePoint sp;
    float3 col = (float3)(0.0f);
    TraceCount tc = {0, 0};
    ShadowCount shc = {0, 0, 0, 0, 0, 0};
    if (probe_primary_point(&sc, rays, hits, media, (int)points[j], &sp))
        col = light_shade_local(&sc, &sp, f->shadow_strata, &tc, &shc);
    /* decided: traced, or clear or blocked by the cone test */
    traced[j] = shc.traced + shc.clear + shc.blocked;
    vstore4((float4)(col, 0.0f), j, radiance);
}

VB_INLINE void probe_store_ray(__global VbRay *out, float3 org, float3 dir, float tmax, uint sample)
{
    VbRay r;
    vstore3(org, 0, r.org);
    vstore3(dir, 0, r.dir);
    r.tmax = tmax;
    r.sample = sample;
    *out = r;
}

#ifdef VBCL_HAS_AREA_LIGHTS
/* The feelers light_reflect_area traces toward a light of radius r > 0 whose centre is to_c
 * away (d2, d: its squared length and length), in its order; returns how many. */
VB_INLINE int probe_cap_feelers(const DevScene *sc, const ShadePoint *sp, const LightShading *ls,
                                float r, uint key, uint sample, __global VbRay *out)
{
    float3 origin = ls->origin, to_c = ls->to_c;
    float d2 = ls->d2, d = ls->d;
    uint strata = sc->f->shadow_strata;
    float3 wc = to_c / d;
    if (dot(sp->ng, wc) < -(r / d)) return 0;
    float one_minus_cos = light_cap_solid_angle(r, d) * (1.0f / (2.0f * VB_PI));
    float3 tx, ty;
    vb_frame(wc, &tx, &ty);
    CapFeelers cf = light_cap_feelers(light_feeler_mode(sc->f->flags), strata, key);
    int k = 0;
    for (uint i = 0; i < strata; i++)
        for (uint j = 0; j < strata; j++) {
            float3 w = light_cap_direction(&cf, i, j, one_minus_cos, tx, ty, wc);
            float nh;
            if (dot(sp->ns, w) <= 0.0f || dot(sp->ng, w) <= 0.0f) continue;
            if (!light_brdf_responds(ls, sp, w, &nh)) continue; /* unneeded: not traced */
            float b = dot(w, to_c);
            float disc = fmax(0.0f, b * b - (d2 - r * r));
            probe_store_ray(out + k++, origin, w, b - sqrt(disc), sample);
        }
    return k;
}
#endif

/* The feelers light_shade_local traces at sp (light_reflect_one for each light, in its
 * order: origin, direction and distance to the light), from out[0] on; returns how many.
 * It repeats light.cl's sampling; the bench checks that the counts equal ShadowCount.traced. */
VB_INLINE int probe_point_feelers(const DevScene *sc, const ShadePoint *sp, uint sample,
                                  __global VbRay *out)
{
    int k = 0;
    for (uint l = 0; l < sc->f->nlights; l++) {
        __global const VbLight *light = sc->lights + l;
        uint key = vb_hash(sp->key * 0x27d4eb2fu + l);
        __global const VbMaterial *m = sc->materials + sp->material;
        LightShading ls =
            light_shading_make(m, vb_gload3(m->diffuse) * scene_pattern_colour(sc, m, sp->p), sp,
                               vb_gload3(light->centre));
#ifdef VBCL_HAS_AREA_LIGHTS
        if (light->radius > 0.0f) {
            if (ls.d > light->radius * 1.0001f)
                k += probe_cap_feelers(sc, sp, &ls, light->radius, key, sample, out + k);
            continue;
        }
#else
        (void)key;
#endif
        float3 w = ls.to_c / ls.d;
        float nh;
        if (dot(sp->ns, w) <= 0.0f || dot(sp->ng, w) <= 0.0f) continue;
        if (!light_brdf_responds(&ls, sp, w, &nh)) continue; /* unneeded: not traced */
        probe_store_ray(out + k++, ls.origin, w, ls.d, sample);
    }
    return k;
}

/* points, offsets -> the feelers of point j from feelers[offsets[j]] on (sample: the point's
 * primary ray), and written[j]: how many. */
__kernel void probe_feeler_rays(SCENE_KERNEL_ARGS __global const VbRay *rays,
                                __global const VbHit *hits, __global const VbMedium *media,
                                __global const uint *points, int npoints,
                                __global const uint *offsets, __global VbRay *feelers,
                                __global uint *written)
{
    int j = get_global_id(0);
    if (j >= npoints) return;
    DevScene sc = DEV_SCENE;
    ShadePoint sp;
    int k = 0;
    if (probe_primary_point(&sc, rays, hits, media, (int)points[j], &sp))
        k = probe_point_feelers(&sc, &sp, points[j], feelers + offsets[j]);
    written[j] = (uint)k;
}

/* feelers (sample: the primary ray of their point), media of the primary rays -> steps, end:
 * the walk light_feeler makes (with transparency, medium_shadow_transmittance's crossings
 * from the point's medium; without, one trace): its closest-hit calls, and the distance
 * along the feeler of the last one's hit, or -1 when the last one reached the light. */
__kernel void probe_feeler_walk(SCENE_KERNEL_ARGS __global const VbRay *feelers, int n,
                                __global const VbMedium *media, __global uint *steps,
                                __global float *end)
{
    int i = get_global_id(0);
    if (i >= n) return;
    DevScene sc = DEV_SCENE;
    VbRay r = feelers[i];
    float3 org = vb_load3(r.org), dir = vb_load3(r.dir), o = org;
    TraceCount tc = {0, 0};
    float left = r.tmax;
    uint k = 0;
    float last = -1.0f;
    /* the walk of the scene's own program: media only where it has transparency */
    int walk = (sc.f->flags & VBCL_FRAME_TRANSPARENCY) != 0u;
    VbMedium state = {-1, 0u};
    if (walk) state = media[r.sample];
    float3 trans = (float3)(1.0f);
    for (int guard = 0; walk && guard < 1024; guard++) {
        uint mb = medium_material(&sc, state);
        VbHit h = scene_trace_closest(&sc, o, dir, left, &tc);
        k++;
        if (h.tri < 0) break;
        float3 p = tri_point(sc.tris, h);
        last = dot(p - org, dir);
        float seg = fmax(0.0f, dot(p - o, dir));
        trans *= medium_absorb(&sc, mb, seg);
        Crossing c = medium_cross(&sc, h.tri, dir, state);
        float3 ng = tri_normal(sc.tris, h.tri);
        if (c.interface) {
            __global const VbMaterial *ms = sc.materials + c.surface;
            if (ms->k_global <= 0.0f) break;
            trans *= ms->k_global *
                     medium_interface_transmit(&sc, dir, ng, c.mat_before, c.mat_after, -1);
        }
        if (vb_max3(trans) < 1e-7f) break;
        last = -1.0f;
        state = c.after;
        left -= seg;
        o = ray_offset_origin(p, dot(ng, dir) > 0.0f ? ng : -ng, tri_point_error(sc.tris, h, ng));
    }
    if (!walk) {
        VbHit h = scene_trace_closest(&sc, o, dir, left, &tc);
        k = 1;
        if (h.tri >= 0) last = dot(tri_point(sc.tris, h) - org, dir);
    }
    steps[i] = k;
    end[i] = last;
}

#ifdef VBCL_HAS_TRANSPARENCY
/* points (primary rays whose first interface is a dielectric) -> the reflected and
 * transmitted rays tree_spawn pushes there, as tree_trace_secondary starts a tree: two
 * slots per point, tmax INFINITY, sample the triangle the ray leaves from (TreeRay.tri) or
 * 0xffffffff (slot unused; with dispersion only the first two of the bands are kept). */
__kernel void probe_secondary_rays(SCENE_KERNEL_ARGS __global const VbRay *rays,
                                   __global const VbHit *hits, __global const VbMedium *media,
                                   __global const uint *points, int npoints, __global VbRay *out)
{
    int j = get_global_id(0);
    if (j >= npoints) return;
    DevScene sc = DEV_SCENE;
    int i = (int)points[j];
    VbHit h = hits[i];
    VbRay r = rays[i];
    float3 dir = vb_load3(r.dir);
    VbMedium before = media[i];
    Crossing c = medium_cross(&sc, h.tri, dir, before);
    ShadePoint sp = shade_point_make(&sc, dir, h, sample_key(f, r.sample), before, c.surface);
    TreeRay stack[VB_TREE_STACK];
    int n = 0;
    TreeCount cnt = {0};
    cnt.prune_budget = f->min_weight;
    tree_spawn(&sc, stack, &n, &sp, dir, &c, before, medium_absorb(&sc, c.mat_before, h.t), 1, &cnt,
               -1, 0);
    for (int k = 0; k < 2; k++) {
        if (k < n)
            probe_store_ray(out + 2 * j + k, stack[k].org, stack[k].dir, INFINITY,
                            (uint)stack[k].tri);
        else
            probe_store_ray(out + 2 * j + k, (float3)(0.0f), (float3)(0.0f, 0.0f, 1.0f), 0.0f,
                            0xffffffffu);
    }
}
#endif

#endif
