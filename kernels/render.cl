#line 2 "render.cl"
/* render.cl — the kernel entry points of a frame, run tile by tile:
 *   camera_generate_rays    frame              -> rays
 *   scene_intersect_closest rays               -> hits, media (first interface of each ray)
 *   light_sample_shading    rays, hits, media  -> radiance (k_local term, shadow feelers)
 *   tree_trace_secondary    rays, hits, media  -> radiance += (k_global term: the ray tree;
 *                                                 only with VBCL_HAS_TRANSPARENCY)
 * Every entry point takes the same arguments (FRAME_KERNEL_ARGS), is thin — index,
 * bounds guard, device functions — and the host concatenates these files in order. */

#include "types.h"
#include "geometry.cl"
#include "grid.cl"
#include "scene.cl"
#include "optics.cl"
#include "medium.cl"
#include "light.cl"
#include "tree.cl"

#if defined(VBCL_HAS_TRANSPARENCY) || defined(VBCL_HAS_TEXTURES)
#define VBCL_HAS_MEDIA 1 /* rays track the medium they are in */
#endif

#define FRAME_KERNEL_ARGS                                                                          \
    __constant const VbFrame *f, __global const VbTriangle *tris,                                  \
        __global const VbTriNormals *normals, __global const uint *cell_start,                     \
        __global const uint *cell_tris, __global const VbMaterial *materials,                      \
        __global const VbObject *objects, __global const VbLight *lights,                          \
        __global const VbPattern *patterns, __global const float *texels, __global VbRay *rays,    \
        int nrays, __global VbHit *hits, __global VbMedium *media, __global float *radiance,       \
        __global uint *counters

#define DEV_SCENE                                                                                  \
    {                                                                                              \
        f, tris, normals, cell_start, cell_tris, materials, objects, lights, patterns, texels      \
    }

/* Primary ray through the continuous image position (px, py), in pixels from the
 * top-left corner. */
VB_INLINE VbRay camera_ray(__constant const VbFrame *f, float px, float py, uint sample)
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

/* The shading point of a hit along dir: position, normals turned toward the ray, the
 * surface's material and the medium on the ray's side. */
VB_INLINE ShadePoint shade_point_make(const DevScene *sc, float3 dir, VbHit h, uint key,
                                      VbMedium medium, uint material)
{
    ShadePoint sp;
    float w0 = 1.0f - h.u - h.v;
    sp.p = tri_point(sc->tris, h);
    float3 ng = tri_normal(sc->tris, h.tri);
    float side = dot(ng, dir) < 0.0f ? 1.0f : -1.0f;
    sp.ng = ng * side;
    sp.ns = sp.ng;
    sp.wo = -dir;
#ifdef VBCL_HAS_SMOOTH_NORMALS
    __global const VbTriNormals *tn = sc->normals + h.tri;
    float3 ns = w0 * vb_gload3(tn->n0) + h.u * vb_gload3(tn->n1) + h.v * vb_gload3(tn->n2);
    float len = length(ns);
    if (len > 0.0f) {
        ns = ns * (side / len);
        if (dot(ns, sp.wo) > 0.0f) sp.ns = ns;
    }
#else
    (void)w0;
#endif
    sp.material = material;
    sp.key = key;
    sp.medium = medium;
    sp.scale = TRI_SCALE(sc->tris, h.tri);
    return sp;
}

VB_INLINE uint pixel_key(__constant const VbFrame *f, int i)
{
    return vb_hash((uint)(f->first_pixel + i) ^ vb_hash(f->seed));
}

/* frame -> rays: one ray through the centre of each pixel of the tile. */
__kernel void camera_generate_rays(FRAME_KERNEL_ARGS)
{
    int i = get_global_id(0);
    if (i >= f->tile_pixels) return;
    int pixel = f->first_pixel + i;
    int x = pixel % f->width, y = pixel / f->width;
    rays[i] = camera_ray(f, (float)x + 0.5f, (float)y + 0.5f, (uint)i);
}

/* rays -> hits, media: the closest interface of each ray through the grid, and the
 * medium the ray is in just before it (rays start in the camera's medium). */
__kernel void scene_intersect_closest(FRAME_KERNEL_ARGS)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    DevScene sc = DEV_SCENE;
    VbRay r = rays[i];
    TraceCount tc = {0, 0};
#ifdef VBCL_HAS_MEDIA
    VbMedium state = f->camera_medium;
    PathHit ph;
    uint passes = 0;
    VbHit miss = {r.tmax, -1, 0.0f, 0.0f};
    hits[i] = medium_trace(&sc, vb_load3(r.org), vb_load3(r.dir), r.tmax, &state, &ph, &tc, &passes)
                  ? ph.hit
                  : miss;
    media[i] = state;
    if (passes) atomic_add(&counters[VBCL_COUNT_PASS_THROUGH], passes);
#else
    hits[i] = scene_trace_closest(&sc, vb_load3(r.org), vb_load3(r.dir), r.tmax, &tc);
#endif
    atomic_add(&counters[VBCL_COUNT_TRAVERSAL_STEPS], tc.steps);
    atomic_add(&counters[VBCL_COUNT_TRI_TESTS], tc.tests);
}

/* rays, hits, media -> radiance (rgb + 1 per ray): the k_local term at each primary hit
 * with shadow feelers, or the background for rays that left the scene. */
__kernel void light_sample_shading(FRAME_KERNEL_ARGS)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    DevScene sc = DEV_SCENE;
    VbHit h = hits[i];
    VbRay r = rays[i];
    float3 dir = vb_load3(r.dir);
    float3 col;
#ifdef VBCL_HAS_MEDIA
    VbMedium before = media[i];
#else
    VbMedium before = {-1, 0u};
#endif
    if (h.tri < 0) {
        col = vb_cload3(f->background);
#ifdef VBCL_HAS_MEDIA
        col *= medium_absorb(&sc, medium_material(&sc, before), INFINITY);
#endif
    } else {
        float3 weight = (float3)(1.0f);
#ifdef VBCL_HAS_MEDIA
        Crossing c = medium_cross(&sc, h.tri, dir, before);
        uint material = c.surface;
        weight = medium_absorb(&sc, c.mat_before, h.t);
#else
        uint material = scene_tri_material(&sc, h.tri);
#endif
        ShadePoint sp = shade_point_make(&sc, dir, h, pixel_key(f, i), before, material);
        TraceCount tc = {0, 0};
        ShadowCount shc = {0, 0};
        col = weight * light_shade_local(&sc, &sp, &tc, &shc);
        atomic_add(&counters[VBCL_COUNT_SHADOW], shc.traced);
        atomic_add(&counters[VBCL_COUNT_SHADOW_SKIPPED], shc.skipped);
        atomic_add(&counters[VBCL_COUNT_TRAVERSAL_STEPS], tc.steps);
        atomic_add(&counters[VBCL_COUNT_TRI_TESTS], tc.tests);
    }
    vstore4((float4)(col, 1.0f), i, radiance);
}

#ifdef VBCL_HAS_TRANSPARENCY
/* rays, hits, media -> radiance += the k_global term: the reflected and transmitted
 * subtree below each primary hit on a dielectric, with its own shadow feelers. */
__kernel void tree_trace_secondary(FRAME_KERNEL_ARGS)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    VbHit h = hits[i];
    if (h.tri < 0) return;
    DevScene sc = DEV_SCENE;
    VbRay r = rays[i];
    float3 dir = vb_load3(r.dir);
    VbMedium before = media[i];
    Crossing c = medium_cross(&sc, h.tri, dir, before);
    if (materials[c.surface].k_global <= 0.0f) return;
    uint key = pixel_key(f, i);
    ShadePoint sp = shade_point_make(&sc, dir, h, key, before, c.surface);
    TreeRay stack[VB_TREE_STACK];
    int n = 0;
    TreeCount cnt = {0};
    cnt.prune_budget = f->min_weight;
    TraceCount tc = {0, 0};
    ShadowCount shc = {0, 0};
    tree_spawn(&sc, stack, &n, &sp, dir, &c, before, medium_absorb(&sc, c.mat_before, h.t), 1,
               &cnt);
    float3 acc = (float3)(0.0f);
    while (n > 0) {
        TreeRay tr = stack[--n];
        VbMedium state = tr.medium;
        PathHit ph;
        if (!medium_trace(&sc, tr.org, tr.dir, INFINITY, &state, &ph, &tc, &cnt.passes)) {
            acc += tr.weight * vb_cload3(f->background) *
                   medium_absorb(&sc, medium_material(&sc, state), INFINITY);
            continue;
        }
        float3 w = tr.weight * medium_absorb(&sc, ph.cx.mat_before, ph.dist);
        ShadePoint q = shade_point_make(&sc, tr.dir, ph.hit, tr.key, state, ph.cx.surface);
        __global const VbMaterial *ms = materials + ph.cx.surface;
        if (ms->k_local > 0.0f) acc += w * light_shade_local(&sc, &q, &tc, &shc);
        if (ms->k_global > 0.0f)
            tree_spawn(&sc, stack, &n, &q, tr.dir, &ph.cx, state, w, tr.depth + 1, &cnt);
    }
    vstore4(vload4(i, radiance) + (float4)(acc, 0.0f), i, radiance);
    atomic_add(&counters[VBCL_COUNT_REFLECTED], cnt.reflected);
    atomic_add(&counters[VBCL_COUNT_TRANSMITTED], cnt.transmitted);
    atomic_add(&counters[VBCL_COUNT_PRUNED], cnt.pruned);
    atomic_add(&counters[VBCL_COUNT_DEPTH_CUT], cnt.depth_cut);
    atomic_add(&counters[VBCL_COUNT_TIR], cnt.tir);
    atomic_add(&counters[VBCL_COUNT_PASS_THROUGH], cnt.passes);
    atomic_add(&counters[VBCL_COUNT_INTERFACES], cnt.interfaces);
    atomic_add(&counters[VBCL_COUNT_ENERGY_ERRORS], cnt.energy_errors);
    for (int d = 1; d < VBCL_COUNT_DEPTH_BINS; d++)
        if (cnt.by_depth[d]) atomic_add(&counters[VBCL_COUNT_DEPTH0 + d], cnt.by_depth[d]);
    atomic_add(&counters[VBCL_COUNT_SHADOW], shc.traced);
    atomic_add(&counters[VBCL_COUNT_SHADOW_SKIPPED], shc.skipped);
    atomic_add(&counters[VBCL_COUNT_TRAVERSAL_STEPS], tc.steps);
    atomic_add(&counters[VBCL_COUNT_TRI_TESTS], tc.tests);
}
#endif

#ifdef VBCL_TEST_KERNELS
#include "probe.cl"
#endif
