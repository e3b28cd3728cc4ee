#line 2 "probe.cl"
/* probe.cl — kernels for the tests only (built with -DVBCL_TEST_KERNELS): brute-force
 * closest hit, the layout of the shared structs as the device sees it, and local
 * shading at arbitrary points for analytic checks. */

/* rays -> hits by testing every triangle: the reference for the grid. */
__kernel void probe_intersect_brute(__global const VbTriangle *tris, uint ntris,
                                    __global const VbRay *rays, int nrays, __global VbHit *hits)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    VbRay r = rays[i];
    RayShear rs = ray_shear_make(vb_load3(r.org), vb_load3(r.dir));
    VbHit hit = {r.tmax, -1, 0.0f, 0.0f};
    for (uint k = 0; k < ntris; k++) {
        float t, u, v;
        if (tri_intersect(&rs, tri_vertex(tris, k, 0), tri_vertex(tris, k, 1),
                          tri_vertex(tris, k, 2), hit.t, &t, &u, &v) &&
            (hit.tri < 0 || t < hit.t)) {
            hit.t = t;
            hit.tri = (int)k;
            hit.u = u;
            hit.v = v;
        }
    }
    hits[i] = hit;
}

/* The sizes and offsets of the shared structs as compiled for the device. */
__kernel void probe_layout(__global uint *out)
{
    if (get_global_id(0) != 0) return;
    out[0] = sizeof(VbRay);
    out[1] = sizeof(VbHit);
    out[2] = sizeof(VbTriangle);
    out[3] = sizeof(VbMaterial);
    out[4] = sizeof(VbLight);
    out[5] = sizeof(VbFrame);
    out[6] = VBCL_OFFSETOF(VbFrame, background);
    out[7] = VBCL_OFFSETOF(VbFrame, seed);
    out[8] = VBCL_OFFSETOF(VbMaterial, eta);
    out[9] = VBCL_OFFSETOF(VbLight, radiance);
}

/* points (xyz + unused), normals -> radiance: local shading of material 0 at given points
 * with given normals, seen from along the normal. */
__kernel void probe_shade_points(__constant const VbFrame *f, __global const VbTriangle *tris,
                                 __global const uint *cell_start, __global const uint *cell_tris,
                                 __global const VbMaterial *materials,
                                 __global const VbLight *lights, __global const float *points,
                                 __global const float *normals, int npoints,
                                 __global float *radiance)
{
    int i = get_global_id(0);
    if (i >= npoints) return;
    ShadePoint sp;
    sp.p = vload3(0, points + 4 * i);
    sp.ng = normalize(vload3(0, normals + 4 * i));
    sp.ns = sp.ng;
    sp.wo = sp.ng;
    sp.material = 0;
    sp.key = vb_hash((uint)i);
    TraceCount tc = {0, 0};
    ShadowCount sc = {0, 0};
    float3 col =
        light_shade_local(f, tris, cell_start, cell_tris, materials, lights, &sp, &tc, &sc);
    vstore4((float4)(col, (float)sc.traced), i, radiance);
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
