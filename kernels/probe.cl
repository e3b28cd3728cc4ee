#line 2 "probe.cl"
/* probe.cl — kernels for the tests only (built with -DVBCL_TEST_KERNELS): brute-force
 * closest hit, the layout of the shared structs as the device sees it, and local
 * shading at arbitrary points for analytic checks. */
#ifndef VBCL_PROBE_CL
#define VBCL_PROBE_CL

#include "render.cl"

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
    sp.scale = 0.0f;
    sp.band = (int)pnormals[4 * i + 3] - 1;
    TraceCount tc = {0, 0};
    ShadowCount sc2 = {0, 0};
    float3 col = light_shade_local(&sc, &sp, &tc, &sc2);
    vstore4((float4)(col, (float)sc2.traced), i, radiance);
}

/* cases (dir xyz, eta1; normal xyz, eta2) -> (reflected xyz, R; transmitted xyz, T;
 * tir, 0, 0, 0): the interface optics on their own, normal facing the ray. */
__kernel void probe_optics(__global const float *in, int n, __global float *out)
{
    int i = get_global_id(0);
    if (i >= n) return;
    float3 d = vload3(0, in + 8 * i), nrm = vload3(0, in + 8 * i + 4);
    float eta1 = in[8 * i + 3], eta2 = in[8 * i + 7];
    OpticsSplit s = optics_split(d, nrm, nrm, eta1, eta2);
    vstore4((float4)(s.reflected, s.R), 0, out + 12 * i);
    vstore4((float4)(s.transmitted, s.T), 0, out + 12 * i + 4);
    vstore4((float4)((float)s.tir, 0.0f, 0.0f, 0.0f), 0, out + 12 * i + 8);
}

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
    if (medium_trace(&sc, org, dir, INFINITY, &state, &ph, &tc, &cnt.passes)) {
        TreeRay stack[VB_TREE_STACK];
        int n = 0;
        ShadePoint sp = shade_point_make(&sc, dir, ph.hit, 1u, state, ph.cx.surface);
        tree_spawn(&sc, stack, &n, &sp, dir, &ph.cx, state, (float3)(1.0f), 1, &cnt, -1, 0);
        while (n > 0) {
            TreeRay tr = stack[--n];
            VbMedium st = tr.medium;
            if (!medium_trace(&sc, tr.org, tr.dir, INFINITY, &st, &ph, &tc, &cnt.passes)) {
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

#endif
