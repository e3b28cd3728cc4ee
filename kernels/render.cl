#line 2 "render.cl"
/* render.cl — the tracing program's entry points, run tile by tile:
 *   camera_generate_rays    frame              -> rays
 *   aa_generate_rays        frame              -> rays (--ssaa: supersamples of pixels)
 *   aa_split_rays           frame, marks       -> rays (the new samples of split nodes)
 *   scene_intersect_closest rays               -> hits, media (first interface of each ray)
 *   light_sample_shading    rays, hits, media  -> radiance (k_local term, shadow feelers)
 *   tree_trace_secondary    rays, hits, media  -> radiance += (k_global term: the ray tree;
 *                                                 only with VBCL_HAS_TRANSPARENCY), splits;
 *                           splits             -> radiance += the recorded dispersive
 *                                                 subtrees (its second launch, `bands` 1:
 *                                                 only with VBCL_HAS_DISPERSION)
 * The anti-aliasing kernels that trace nothing are film.cl's program. The frame's entry
 * points take the same arguments (FRAME_KERNEL_ARGS; aa_generate_rays adds the pass,
 * aa_split_rays the pass and the list, with dispersion the tree kernels add the split
 * records), are thin — index, bounds guard, device functions — and the host concatenates
 * these files. A program has the code of the VBCL_HAS_* it is compiled with and tests the
 * scene's VBCL_FRAME_* flags where it has more (host/device/kernel_features.c). */

#ifndef VBCL_RENDER_CL
#define VBCL_RENDER_CL

#include "aa.cl"
#include "environment.cl"
#include "light.cl"
#include "medium.cl"
#include "scene.cl"
#include "tree.cl"

#if defined(VBCL_HAS_TRANSPARENCY) || defined(VBCL_HAS_TEXTURES)
#define VBCL_HAS_MEDIA 1 /* rays can track the medium they are in */
#endif
/* Whether the scene's rays track their medium: it has transparent surfaces or textures. */
#define FRAME_MEDIA(f) (((f)->flags & (VBCL_FRAME_TRANSPARENCY | VBCL_FRAME_TEXTURES)) != 0u)

/* The arguments every frame kernel takes: the scene's, then the ray batch's. */
#define FRAME_KERNEL_ARGS                                                                          \
    SCENE_KERNEL_ARGS __global VbRay *rays, int nrays, __global VbHit *hits,                       \
        __global VbMedium *media, __global float *radiance, __global uint *counters

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
    if (sc->f->flags & VBCL_FRAME_SMOOTH_NORMALS) {
        __global const VbTriNormals *tn = sc->normals + h.tri;
        float3 ns = w0 * vb_gload3(tn->n0) + h.u * vb_gload3(tn->n1) + h.v * vb_gload3(tn->n2);
        float len = length(ns);
        if (len > 0.0f) {
            ns = ns * (side / len);
            if (dot(ns, sp.wo) > 0.0f) sp.ns = ns;
        }
    }
#else
    (void)w0;
#endif
    sp.material = material;
    sp.key = key;
    sp.medium = medium;
    sp.err = tri_point_error(sc->tris, h, ng);
    uint tag = tri_tag(sc->tris, h.tri);
    /* a texture element's surface is not its host's: the host's shape says nothing of it */
    sp.object = (tag & VBCL_TAG_TEXTURE) ? -1 : (int)(tag & ~VBCL_TAG_FLAGS);
    sp.tri = h.tri;
    sp.front = side > 0.0f;
    sp.band = -1;
    return sp;
}

/* The factor by which light_node_strata counts the weight of a ray-tree point of film
 * sample `sample` (VbRay.sample): with VBCL_FRAME_SAMPLE_SHARES, 2^-L for a quadtree
 * sample fresh at level L (aa_tree_sample_id), 1 for pass 0's. A sample at level L weighs
 * about 4^-L in its pixel, but is compared with its neighbours at a threshold of about 2^L
 * times the pixel's (aa_leaf_fails): its points' relative noise grows as 2^(L/2) with 2^-L
 * of their feelers, slower than the threshold. The sample's own point keeps all of its
 * feelers (its noise is what the contrast test sees first). */
VB_INLINE float sample_share(__constant const VbFrame *f, uint sample)
{
    if (!(f->flags & VBCL_FRAME_SAMPLE_SHARES) || !(sample & 0x80000000u)) return 1.0f;
    return 1.0f / (float)(1u << (sample >> 28 & 7u));
}

/* The jitter key of a film sample (VbRay.sample) under the frame's seed. */
VB_INLINE uint sample_key(__constant const VbFrame *f, uint sample)
{
    return vb_hash(sample ^ vb_hash(f->seed));
}

/* The place in the image of pixel p of the frame's window (VbFrame.window_x ...: row by
 * row, window_width a row). */
VB_INLINE int2 frame_pixel_xy(__constant const VbFrame *f, uint p)
{
    return (int2)(f->window_x + (int)(p % (uint)f->window_width),
                  f->window_y + (int)(p / (uint)f->window_width));
}

/* The index in the whole image (row-major) of the pixel at xy: the id of its pass-0 sample
 * and the key of its supersamples' ids, whatever window renders it. */
VB_INLINE uint frame_pixel_index(__constant const VbFrame *f, int2 xy)
{
    return (uint)(xy.y * f->width + xy.x);
}

/* frame -> rays: one ray through the centre of each pixel of the tile; the sample id is
 * the pixel's index in the image. */
__kernel void camera_generate_rays(FRAME_KERNEL_ARGS)
{
    int i = get_global_id(0);
    if (i >= f->tile_pixels) return;
    int2 xy = frame_pixel_xy(f, (uint)(f->first_pixel + i));
    rays[i] = camera_ray(f, (float)xy.x + 0.5f, (float)xy.y + 0.5f, frame_pixel_index(f, xy));
}

/* This work group's copy of the counters (VBCL_COUNTER_SLOTS in types.h). */
#define COUNTER_SLOT(counters)                                                                     \
    ((counters) + get_group_id(0) % VBCL_COUNTER_SLOTS * VBCL_COUNTER_STRIDE)

/* counters[k] += v: one atomic add, none when v is 0 (as most of a work item's counts are). */
VB_INLINE void counter_add(__global uint *counters, int k, uint v)
{
    if (v) atomic_add(&counters[k], v);
}

/* rays -> hits, media: the closest interface of each camera ray (camera_trace_closest: its
 * image tile's triangles, or the grid), and the medium the ray is in just before it (rays
 * start in the camera's medium). */
__kernel void scene_intersect_closest(FRAME_KERNEL_ARGS)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    DevScene sc = DEV_SCENE;
    VbRay r = rays[i];
    TraceCount tc = {0, 0};
#ifdef VBCL_HAS_MEDIA
    if (FRAME_MEDIA(f)) {
        VbMedium state = f->camera_medium;
        PathHit ph;
        uint passes = 0;
        VbHit miss = {r.tmax, -1, 0.0f, 0.0f};
        ObjectSet all = object_set_all();
        hits[i] = medium_trace(&sc, &all, vb_load3(r.org), vb_load3(r.dir), r.tmax, &state, &ph,
                               &tc, &passes, 1)
                      ? ph.hit
                      : miss;
        media[i] = state;
        counter_add(COUNTER_SLOT(counters), VBCL_COUNT_PASS_THROUGH, passes);
    } else
#endif
        hits[i] = camera_trace_closest(&sc, vb_load3(r.org), vb_load3(r.dir), r.tmax, &tc);
    counter_add(COUNTER_SLOT(counters), VBCL_COUNT_TRAVERSAL_STEPS, tc.steps);
    counter_add(COUNTER_SLOT(counters), VBCL_COUNT_TRI_TESTS, tc.tests);
}

/* Adds one work item's shading counts (its feelers and their walks) to its group's copy of
 * the frame counters (COUNTER_SLOT). */
VB_INLINE void shade_flush_counts(__global uint *counters, const TraceCount *tc,
                                  const ShadowCount *shc)
{
    counter_add(counters, VBCL_COUNT_SHADOW, shc->traced);
    counter_add(counters, VBCL_COUNT_SHADOW_SKIPPED, shc->skipped);
    counter_add(counters, VBCL_COUNT_SHADOW_UNNEEDED, shc->unneeded);
    counter_add(counters, VBCL_COUNT_SHADOW_CLEAR, shc->clear);
    counter_add(counters, VBCL_COUNT_SHADOW_BLOCKED, shc->blocked);
    counter_add(counters, VBCL_COUNT_SHADOW_PENUMBRA, shc->penumbra);
    counter_add(counters, VBCL_COUNT_TRAVERSAL_STEPS, tc->steps);
    counter_add(counters, VBCL_COUNT_TRI_TESTS, tc->tests);
}

/* rays, hits, media -> radiance (rgb + 1 per ray): the k_local term at each primary hit
 * with shadow feelers, or the environment or background for rays that left the scene. */
__kernel void light_sample_shading(FRAME_KERNEL_ARGS)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    DevScene sc = DEV_SCENE;
    VbHit h = hits[i];
    VbRay r = rays[i];
    float3 dir = vb_load3(r.dir);
    float3 col;
    VbMedium before = {-1, 0u};
#ifdef VBCL_HAS_MEDIA
    const int tracked = FRAME_MEDIA(f);
    if (tracked) before = media[i];
#endif
    if (h.tri < 0) {
        col = scene_escape_radiance(&sc, dir);
#ifdef VBCL_HAS_MEDIA
        if (tracked) col *= medium_absorb(&sc, medium_material(&sc, before), INFINITY);
#endif
    } else {
        float3 weight = (float3)(1.0f);
        uint material;
#ifdef VBCL_HAS_MEDIA
        if (tracked) {
            Crossing c = medium_cross(&sc, h.tri, dir, before);
            material = c.surface;
            weight = medium_absorb(&sc, c.mat_before, h.t);
        } else
#endif
            material = scene_tri_material(&sc, h.tri);
        ShadePoint sp = shade_point_make(&sc, dir, h, sample_key(f, r.sample), before, material);
        TraceCount tc = {0, 0};
        ShadowCount shc = {0, 0, 0, 0, 0, 0};
        col = weight * light_shade_local(&sc, &sp, f->shadow_strata, &tc, &shc);
        shade_flush_counts(COUNTER_SLOT(counters), &tc, &shc);
    }
    vstore4((float4)(col, 1.0f), i, radiance);
}

#ifdef VBCL_HAS_TRANSPARENCY
#ifdef VBCL_HAS_DISPERSION
#define TREE_SPLIT_ARG , __global VbSplitSet *splits, int bands
#else
#define TREE_SPLIT_ARG
#endif

/* Traces the pending branches on the stack, depth first, until it is empty or the tree has
 * traced VBCL_TREE_MAX_RAYS; returns the radiance they carry to the sample. White rays that
 * split record it in rec (may be 0). */
VB_INLINE float3 tree_run(const DevScene *sc, TreeRay *stack, int n, float share, TreeCount *cnt,
                          TraceCount *tc, ShadowCount *shc, __global VbSplitSet *rec)
{
    __constant const VbFrame *f = sc->f;
    float3 acc = (float3)(0.0f);
    for (uint traced = 0; n > 0; traced++) {
        if (traced == VBCL_TREE_MAX_RAYS) { /* the tree's budget: the rest is not traced */
            cnt->tree_cut += (uint)n;
            break;
        }
        TreeRay tr = stack[--n];
        VbMedium state = tr.medium;
        PathHit ph;
        if (!tree_trace(sc, &tr, &state, &ph, tc, &cnt->passes)) {
            acc += tr.weight * scene_escape_radiance(sc, tr.dir) *
                   medium_absorb(sc, medium_material(sc, state), INFINITY);
            continue;
        }
        float3 w = tr.weight * medium_absorb(sc, ph.cx.mat_before, ph.dist);
        ShadePoint q = shade_point_make(sc, tr.dir, ph.hit, tr.key, state, ph.cx.surface);
        q.band = tr.band;
        __global const VbMaterial *ms = sc->materials + ph.cx.surface;
        if (ms->k_local > 0.0f)
            acc += w * light_shade_local(
                           sc, &q, light_node_strata(f, vb_max3(w) * ms->k_local, share), tc, shc);
        if (ms->k_global > 0.0f)
            tree_spawn(sc, stack, &n, &q, tr.dir, &ph.cx, state, w, tr.depth + 1, cnt, tr.band,
                       rec);
    }
    return acc;
}

/* Adds one work item's tree counts to its group's copy of the frame counters. */
VB_INLINE void tree_flush_counts(__global uint *counters, const TreeCount *cnt,
                                 const TraceCount *tc, const ShadowCount *shc)
{
    counter_add(counters, VBCL_COUNT_REFLECTED, cnt->reflected);
    counter_add(counters, VBCL_COUNT_TRANSMITTED, cnt->transmitted);
    counter_add(counters, VBCL_COUNT_PRUNED, cnt->pruned);
    counter_add(counters, VBCL_COUNT_DEPTH_CUT, cnt->depth_cut);
    counter_add(counters, VBCL_COUNT_TIR, cnt->tir);
    counter_add(counters, VBCL_COUNT_PASS_THROUGH, cnt->passes);
    counter_add(counters, VBCL_COUNT_INTERFACES, cnt->interfaces);
    counter_add(counters, VBCL_COUNT_ENERGY_ERRORS, cnt->energy_errors);
    counter_add(counters, VBCL_COUNT_TREE_CUT, cnt->tree_cut);
#ifdef VBCL_HAS_DISPERSION
    counter_add(counters, VBCL_COUNT_SPLITS, cnt->splits);
    counter_add(counters, VBCL_COUNT_BAND_RAYS, cnt->band_rays);
#endif
    for (int d = 1; d < VBCL_COUNT_DEPTH_BINS; d++)
        counter_add(counters, VBCL_COUNT_DEPTH0 + d, cnt->by_depth[d]);
    shade_flush_counts(counters, tc, shc);
}

/* rays, hits, media -> radiance += the k_global term: the reflected and transmitted
 * subtree below each primary hit on a dielectric, with its own shadow feelers. With
 * dispersion the kernel runs twice a batch: with `bands` 0 it traces the white trees and
 * leaves the first VBCL_SPLIT_SLOTS splits of each tree in splits, with the pruning budget
 * that is left; with `bands` 1 it traces those dispersive subtrees, each split's bands
 * (tree_push_bands) and everything below them. One kernel with one copy of the inlined
 * tree_run for both, so that a driver compiles the walk once (a second kernel of its own
 * doubled the dispersive program's compile); two launches, so that the time spent in
 * dispersive subtrees is measured (--stats). */
__kernel void tree_trace_secondary(FRAME_KERNEL_ARGS TREE_SPLIT_ARG)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
#ifdef VBCL_HAS_DISPERSION
    __global VbSplitSet *rec = bands ? 0 : (f->flags & VBCL_FRAME_DISPERSION) ? splits + i : 0;
    if (rec) {
        rec->count = 0;
        rec->budget = 0.0f;
    }
    int trees = bands ? splits[i].count : 1;
    if (trees == 0) return;
#else
    __global VbSplitSet *rec = 0;
    const int bands = 0, trees = 1;
#endif
    DevScene sc = DEV_SCENE;
    TreeRay stack[VB_TREE_STACK];
    TreeCount cnt = {0};
    cnt.prune_budget = f->min_weight;
    TraceCount tc = {0, 0};
    ShadowCount shc = {0, 0, 0, 0, 0, 0};
    VbRay r = rays[i];
    ShadePoint sp;
    Crossing c;
    float3 dir, weight;
    VbMedium before;
    if (!bands) {
        VbHit h = hits[i];
        if (h.tri < 0) return;
        dir = vb_load3(r.dir);
        before = media[i];
        c = medium_cross(&sc, h.tri, dir, before);
        if (materials[c.surface].k_global <= 0.0f) return;
        sp = shade_point_make(&sc, dir, h, sample_key(f, r.sample), before, c.surface);
        weight = medium_absorb(&sc, c.mat_before, h.t);
    }
#ifdef VBCL_HAS_DISPERSION
    else
        cnt.prune_budget = splits[i].budget;
#endif
    float3 acc = (float3)(0.0f);
    float share = sample_share(f, r.sample);
    for (int k = 0; k < trees; k++) {
        int n = 0;
#ifdef VBCL_HAS_DISPERSION
        if (bands) {
            VbSplit s = splits[i].s[k];
            sp.p = vload3(0, s.p);
            sp.err = s.p[3];
            sp.ng = vload3(0, s.ng);
            sp.ns = vload3(0, s.ns);
            sp.tri = -1; /* not recorded: its rays leave nothing out (ray_objects) */
            c.after = s.after;
            c.mat_before = s.mat_before;
            c.mat_after = s.mat_after;
            tree_push_bands(&sc, stack, &n, &sp, vload3(0, s.dir), &c, vload3(0, s.weight), s.depth,
                            s.key, &cnt);
        } else
#endif
            tree_spawn(&sc, stack, &n, &sp, dir, &c, before, weight, 1, &cnt, -1, rec);
        acc += tree_run(&sc, stack, n, share, &cnt, &tc, &shc, rec);
    }
    vstore4(vload4(i, radiance) + (float4)(acc, 0.0f), i, radiance);
#ifdef VBCL_HAS_DISPERSION
    if (rec) rec->budget = cnt.prune_budget;
#endif
    tree_flush_counts(COUNTER_SLOT(counters), &cnt, &tc, &shc);
}
#endif

/* frame -> rays: uniform supersampling, side x side rays through the subpixel centres of
 * each pixel of a batch of pixels of the window from aa->first on (complete
 * stratification), ray i belonging to pixel first + i / side^2 and subpixel i % side^2
 * (row-major). */
__kernel void aa_generate_rays(FRAME_KERNEL_ARGS, __constant const VbAaPass *aa)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    uint n = (uint)(aa->side * aa->side), sub = (uint)i % n;
    int2 xy = frame_pixel_xy(f, aa->first + (uint)i / n);
    float inv = 1.0f / (float)aa->side;
    float px = (float)xy.x + ((float)(sub % (uint)aa->side) + 0.5f) * inv;
    float py = (float)xy.y + ((float)(sub / (uint)aa->side) + 0.5f) * inv;
    rays[i] = camera_ray(f, px, py, aa_sample_id(frame_pixel_index(f, xy), aa->side, sub));
}

/* frame, marks -> rays: three rays per marked node of a batch, through the samples of the
 * three children that do not hold the node's own sample (aa_tree.h): ray i belongs to
 * mark first + i / 3 (its pixel one of the window's). */
__kernel void aa_split_rays(FRAME_KERNEL_ARGS, __constant const VbAaPass *aa,
                            __global const uint2 *marks)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    uint2 m = marks[aa->first + (uint)i / 3u];
    uint child = aa_new_child(m.y, i % 3);
    int cell = aa_new_child_cell(child);
    float2 at = aa_cell_position(cell);
    int2 xy = frame_pixel_xy(f, m.x);
    rays[i] =
        camera_ray(f, (float)xy.x + at.x, (float)xy.y + at.y,
                   aa_tree_sample_id(frame_pixel_index(f, xy), (uint)cell, aa_node_level(child)));
}

#endif
