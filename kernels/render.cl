#line 2 "render.cl"
/* render.cl — the kernel entry points of a frame, run tile by tile:
 *   camera_generate_rays    frame            -> rays
 *   scene_intersect_closest rays             -> hits
 *   light_sample_shading    rays, hits       -> radiance (shadow feelers to area lights)
 * Each entry point is thin: index, bounds guard, then device functions from the other
 * files. The host concatenates types.h and the .cl files in dependency order. */

#include "types.h"
#include "geometry.cl"
#include "grid.cl"
#include "light.cl"

/* Primary ray through the continuous image position (px, py), in pixels from the
 * top-left corner. */
inline VbRay camera_ray(__constant const VbFrame *f, float px, float py, uint sample)
{
    __constant const VbCamera *c = &f->camera;
    float sx = 2.0f * px / (float)f->width - 1.0f;
    float sy = 1.0f - 2.0f * py / (float)f->height;
    float3 dir =
        normalize(vb_cload3(c->forward) + sx * vb_cload3(c->right) + sy * vb_cload3(c->up));
    VbRay r;
    r.org[0] = c->eye[0];
    r.org[1] = c->eye[1];
    r.org[2] = c->eye[2];
    r.tmax = INFINITY;
    r.dir[0] = dir.x;
    r.dir[1] = dir.y;
    r.dir[2] = dir.z;
    r.sample = sample;
    return r;
}

/* The shading point of a hit: position, normals turned toward the ray, material. */
inline ShadePoint shade_point_make(__global const VbTriangle *tris,
                                   __global const VbTriNormals *normals, float3 org, float3 dir,
                                   VbHit h, uint key)
{
    ShadePoint sp;
    float w0 = 1.0f - h.u - h.v;
    /* interpolate on the triangle rather than org + t*dir: the point lies on the plane */
    sp.p = w0 * tri_vertex(tris, h.tri, 0).xyz + h.u * tri_vertex(tris, h.tri, 1).xyz +
           h.v * tri_vertex(tris, h.tri, 2).xyz;
    float3 ng = tri_normal(tris, h.tri);
    float side = dot(ng, dir) < 0.0f ? 1.0f : -1.0f;
    sp.ng = ng * side;
    sp.ns = sp.ng;
    sp.wo = -dir;
#ifdef VBCL_HAS_SMOOTH_NORMALS
    __global const VbTriNormals *tn = normals + h.tri;
    float3 ns = w0 * vb_gload3(tn->n0) + h.u * vb_gload3(tn->n1) + h.v * vb_gload3(tn->n2);
    float len = length(ns);
    if (len > 0.0f) {
        ns = ns * (side / len);
        if (dot(ns, sp.wo) > 0.0f) sp.ns = ns;
    }
#else
    (void)normals;
#endif
    sp.material = tri_material(tris, h.tri);
    sp.key = key;
    return sp;
}

/* frame -> rays: one ray through the centre of each pixel of the tile. */
__kernel void camera_generate_rays(__constant const VbFrame *f, __global VbRay *rays)
{
    int i = get_global_id(0);
    if (i >= f->tile_pixels) return;
    int pixel = f->first_pixel + i;
    int x = pixel % f->width, y = pixel / f->width;
    rays[i] = camera_ray(f, (float)x + 0.5f, (float)y + 0.5f, (uint)i);
}

/* rays -> hits: the closest hit of each ray through the grid. */
__kernel void scene_intersect_closest(__constant const VbFrame *f, __global const VbTriangle *tris,
                                      __global const uint *cell_start,
                                      __global const uint *cell_tris, __global const VbRay *rays,
                                      int nrays, __global VbHit *hits, __global uint *counters)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    VbRay r = rays[i];
    TraceCount tc = {0, 0};
    hits[i] = grid_trace_closest(&f->grid, tris, cell_start, cell_tris, vb_load3(r.org),
                                 vb_load3(r.dir), r.tmax, &tc);
    atomic_add(&counters[VBCL_COUNT_TRAVERSAL_STEPS], tc.steps);
    atomic_add(&counters[VBCL_COUNT_TRI_TESTS], tc.tests);
}

/* rays, hits -> radiance (rgb + 1 per ray): local shading with shadow feelers, or the
 * background for rays that left the scene. */
__kernel void light_sample_shading(__constant const VbFrame *f, __global const VbTriangle *tris,
                                   __global const VbTriNormals *normals,
                                   __global const uint *cell_start, __global const uint *cell_tris,
                                   __global const VbMaterial *materials,
                                   __global const VbLight *lights, __global const VbRay *rays,
                                   __global const VbHit *hits, int nrays, __global float *radiance,
                                   __global uint *counters)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    VbHit h = hits[i];
    float3 col;
    if (h.tri < 0) {
        col = vb_cload3(f->background);
    } else {
        VbRay r = rays[i];
        uint key = vb_hash((uint)(f->first_pixel + i) ^ vb_hash(f->seed));
        ShadePoint sp = shade_point_make(tris, normals, vb_load3(r.org), vb_load3(r.dir), h, key);
        TraceCount tc = {0, 0};
        ShadowCount sc = {0, 0};
        col = light_shade_local(f, tris, cell_start, cell_tris, materials, lights, &sp, &tc, &sc);
        atomic_add(&counters[VBCL_COUNT_SHADOW], sc.traced);
        atomic_add(&counters[VBCL_COUNT_SHADOW_SKIPPED], sc.skipped);
    }
    vstore4((float4)(col, 1.0f), i, radiance);
}

#ifdef VBCL_TEST_KERNELS
#include "probe.cl"
#endif
