#line 2 "render.cl"
/* render.cl — the kernel entry points of a frame, run tile by tile:
 *   camera_generate_rays    frame              -> rays
 *   aa_generate_rays        frame              -> rays (--ssaa: supersamples of pixels)
 *   scene_intersect_closest rays               -> hits, media (first interface of each ray)
 *   light_sample_shading    rays, hits, media  -> radiance (k_local term, shadow feelers)
 *   tree_trace_secondary    rays, hits, media  -> radiance += (k_global term: the ray tree;
 *                                                 only with VBCL_HAS_TRANSPARENCY), splits
 *   tree_trace_bands        splits             -> radiance += the recorded dispersive
 *                                                 subtrees (only with VBCL_HAS_DISPERSION)
 *   aa_reconstruct          radiance           -> film (--ssaa: box window per pixel)
 *   aa_contrast_mark        film, trees        -> marks (quadtree leaves to split)
 *   aa_contrast_list        film, trees, list  -> marks (the same, for listed pixels)
 *   aa_dirty_list           marks              -> list (the pixels the next round tests)
 *   aa_split_rays           frame, marks       -> rays (the new samples of split nodes)
 *   aa_split_store          radiance, marks    -> trees (four leaves for each split node)
 *   aa_resolve              trees, slots       -> film, info (each pixel from its samples)
 * The frame's entry points take the same arguments (FRAME_KERNEL_ARGS; aa_generate_rays
 * adds the pass, aa_split_rays the pass and the list, with dispersion the tree kernels add
 * the split records, the other aa_* kernels take only their own buffers), are
 * thin — index, bounds guard, device functions — and the host concatenates these files. */

#ifndef VBCL_RENDER_CL
#define VBCL_RENDER_CL

#include "aa.cl"
#include "light.cl"
#include "medium.cl"
#include "scene.cl"
#include "tree.cl"

#if defined(VBCL_HAS_TRANSPARENCY) || defined(VBCL_HAS_TEXTURES)
#define VBCL_HAS_MEDIA 1 /* rays track the medium they are in */
#endif

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

/* frame -> rays: one ray through the centre of each pixel of the tile; the sample id is
 * the pixel index. */
__kernel void camera_generate_rays(FRAME_KERNEL_ARGS)
{
    int i = get_global_id(0);
    if (i >= f->tile_pixels) return;
    int pixel = f->first_pixel + i;
    int x = pixel % f->width, y = pixel / f->width;
    rays[i] = camera_ray(f, (float)x + 0.5f, (float)y + 0.5f, (uint)pixel);
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
    VbMedium state = f->camera_medium;
    PathHit ph;
    uint passes = 0;
    VbHit miss = {r.tmax, -1, 0.0f, 0.0f};
    ObjectSet all = object_set_all();
    hits[i] = medium_trace(&sc, &all, vb_load3(r.org), vb_load3(r.dir), r.tmax, &state, &ph, &tc,
                           &passes, 1)
                  ? ph.hit
                  : miss;
    media[i] = state;
    if (passes) atomic_add(&counters[VBCL_COUNT_PASS_THROUGH], passes);
#else
    hits[i] = camera_trace_closest(&sc, vb_load3(r.org), vb_load3(r.dir), r.tmax, &tc);
#endif
    atomic_add(&counters[VBCL_COUNT_TRAVERSAL_STEPS], tc.steps);
    atomic_add(&counters[VBCL_COUNT_TRI_TESTS], tc.tests);
}

/* Adds one work item's shading counts (its feelers and their walks) to the frame counters. */
VB_INLINE void shade_flush_counts(__global uint *counters, const TraceCount *tc,
                                  const ShadowCount *shc)
{
    atomic_add(&counters[VBCL_COUNT_SHADOW], shc->traced);
    atomic_add(&counters[VBCL_COUNT_SHADOW_SKIPPED], shc->skipped);
    atomic_add(&counters[VBCL_COUNT_SHADOW_UNNEEDED], shc->unneeded);
    atomic_add(&counters[VBCL_COUNT_SHADOW_CLEAR], shc->clear);
    atomic_add(&counters[VBCL_COUNT_SHADOW_BLOCKED], shc->blocked);
    atomic_add(&counters[VBCL_COUNT_SHADOW_PENUMBRA], shc->penumbra);
    atomic_add(&counters[VBCL_COUNT_TRAVERSAL_STEPS], tc->steps);
    atomic_add(&counters[VBCL_COUNT_TRI_TESTS], tc->tests);
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
        ShadePoint sp = shade_point_make(&sc, dir, h, sample_key(f, r.sample), before, material);
        TraceCount tc = {0, 0};
        ShadowCount shc = {0, 0, 0, 0, 0, 0};
        col = weight * light_shade_local(&sc, &sp, f->shadow_strata, &tc, &shc);
        shade_flush_counts(counters, &tc, &shc);
    }
    vstore4((float4)(col, 1.0f), i, radiance);
}

#ifdef VBCL_HAS_TRANSPARENCY
#ifdef VBCL_HAS_DISPERSION
#define TREE_SPLIT_ARG , __global VbSplitSet *splits
#else
#define TREE_SPLIT_ARG
#endif

/* Traces the pending branches on the stack, depth first, until it is empty; returns the
 * radiance they carry to the sample. White rays that split record it in rec (may be 0). */
VB_INLINE float3 tree_run(const DevScene *sc, TreeRay *stack, int n, float share, TreeCount *cnt,
                          TraceCount *tc, ShadowCount *shc, __global VbSplitSet *rec)
{
    __constant const VbFrame *f = sc->f;
    float3 acc = (float3)(0.0f);
    while (n > 0) {
        TreeRay tr = stack[--n];
        VbMedium state = tr.medium;
        PathHit ph;
        if (!tree_trace(sc, &tr, &state, &ph, tc, &cnt->passes)) {
            acc += tr.weight * vb_cload3(f->background) *
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

/* Adds one work item's tree counts to the frame counters. */
VB_INLINE void tree_flush_counts(__global uint *counters, const TreeCount *cnt,
                                 const TraceCount *tc, const ShadowCount *shc)
{
    atomic_add(&counters[VBCL_COUNT_REFLECTED], cnt->reflected);
    atomic_add(&counters[VBCL_COUNT_TRANSMITTED], cnt->transmitted);
    atomic_add(&counters[VBCL_COUNT_PRUNED], cnt->pruned);
    atomic_add(&counters[VBCL_COUNT_DEPTH_CUT], cnt->depth_cut);
    atomic_add(&counters[VBCL_COUNT_TIR], cnt->tir);
    atomic_add(&counters[VBCL_COUNT_PASS_THROUGH], cnt->passes);
    atomic_add(&counters[VBCL_COUNT_INTERFACES], cnt->interfaces);
    atomic_add(&counters[VBCL_COUNT_ENERGY_ERRORS], cnt->energy_errors);
#ifdef VBCL_HAS_DISPERSION
    if (cnt->splits) atomic_add(&counters[VBCL_COUNT_SPLITS], cnt->splits);
    if (cnt->band_rays) atomic_add(&counters[VBCL_COUNT_BAND_RAYS], cnt->band_rays);
#endif
    for (int d = 1; d < VBCL_COUNT_DEPTH_BINS; d++)
        if (cnt->by_depth[d]) atomic_add(&counters[VBCL_COUNT_DEPTH0 + d], cnt->by_depth[d]);
    shade_flush_counts(counters, tc, shc);
}

/* rays, hits, media -> radiance += the k_global term: the reflected and transmitted
 * subtree below each primary hit on a dielectric, with its own shadow feelers. With
 * dispersion, the first VBCL_SPLIT_SLOTS splits of each tree are left in splits for
 * tree_trace_bands, with the pruning budget that is left. */
__kernel void tree_trace_secondary(FRAME_KERNEL_ARGS TREE_SPLIT_ARG)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
#ifdef VBCL_HAS_DISPERSION
    __global VbSplitSet *rec = splits + i;
    rec->count = 0;
    rec->budget = 0.0f;
#else
    __global VbSplitSet *rec = 0;
#endif
    VbHit h = hits[i];
    if (h.tri < 0) return;
    DevScene sc = DEV_SCENE;
    VbRay r = rays[i];
    float3 dir = vb_load3(r.dir);
    VbMedium before = media[i];
    Crossing c = medium_cross(&sc, h.tri, dir, before);
    if (materials[c.surface].k_global <= 0.0f) return;
    uint key = sample_key(f, r.sample);
    ShadePoint sp = shade_point_make(&sc, dir, h, key, before, c.surface);
    TreeRay stack[VB_TREE_STACK];
    int n = 0;
    TreeCount cnt = {0};
    cnt.prune_budget = f->min_weight;
    TraceCount tc = {0, 0};
    ShadowCount shc = {0, 0, 0, 0, 0, 0};
    tree_spawn(&sc, stack, &n, &sp, dir, &c, before, medium_absorb(&sc, c.mat_before, h.t), 1, &cnt,
               -1, rec);
    float3 acc = tree_run(&sc, stack, n, sample_share(f, r.sample), &cnt, &tc, &shc, rec);
    vstore4(vload4(i, radiance) + (float4)(acc, 0.0f), i, radiance);
#ifdef VBCL_HAS_DISPERSION
    rec->budget = cnt.prune_budget;
#endif
    tree_flush_counts(counters, &cnt, &tc, &shc);
}

#ifdef VBCL_HAS_DISPERSION
/* splits -> radiance += the dispersive subtrees tree_trace_secondary recorded: for each
 * recorded split its bands (tree_push_bands) and everything below them. Its own kernel, so
 * that the time spent in dispersive subtrees is measured (--stats). */
__kernel void tree_trace_bands(FRAME_KERNEL_ARGS TREE_SPLIT_ARG)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    __global const VbSplitSet *rec = splits + i;
    int count = rec->count;
    if (count == 0) return;
    DevScene sc = DEV_SCENE;
    TreeRay stack[VB_TREE_STACK];
    TreeCount cnt = {0};
    cnt.prune_budget = rec->budget;
    TraceCount tc = {0, 0};
    ShadowCount shc = {0, 0, 0, 0, 0, 0};
    float3 acc = (float3)(0.0f);
    float share = sample_share(f, rays[i].sample);
    for (int k = 0; k < count; k++) {
        VbSplit s = rec->s[k];
        ShadePoint sp;
        sp.p = vload3(0, s.p);
        sp.scale = s.p[3];
        sp.ng = vload3(0, s.ng);
        sp.ns = vload3(0, s.ns);
        sp.tri = -1; /* not recorded: its rays leave nothing out (ray_objects) */
        Crossing c;
        c.after = s.after;
        c.mat_before = s.mat_before;
        c.mat_after = s.mat_after;
        int n = 0;
        tree_push_bands(&sc, stack, &n, &sp, vload3(0, s.dir), &c, vload3(0, s.weight), s.depth,
                        s.key, &cnt);
        acc += tree_run(&sc, stack, n, share, &cnt, &tc, &shc, 0);
    }
    vstore4(vload4(i, radiance) + (float4)(acc, 0.0f), i, radiance);
    tree_flush_counts(counters, &cnt, &tc, &shc);
}
#endif
#endif

/* frame -> rays: uniform supersampling, side x side rays through the subpixel centres of
 * each pixel of a batch of pixels from aa->first on (complete stratification), ray i
 * belonging to pixel first + i / side^2 and subpixel i % side^2 (row-major). */
__kernel void aa_generate_rays(FRAME_KERNEL_ARGS, __constant const VbAaPass *aa)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    uint n = (uint)(aa->side * aa->side);
    uint pixel = aa->first + (uint)i / n, sub = (uint)i % n;
    int x = (int)(pixel % (uint)f->width), y = (int)(pixel / (uint)f->width);
    float inv = 1.0f / (float)aa->side;
    float px = (float)x + ((float)(sub % (uint)aa->side) + 0.5f) * inv;
    float py = (float)y + ((float)(sub / (uint)aa->side) + 0.5f) * inv;
    rays[i] = camera_ray(f, px, py, aa_sample_id(pixel, aa->side, sub));
}

/* radiance -> film: uniform supersampling, each pixel of a batch the mean of its side^2
 * samples (a box window over its own subpixels, thesis figure 4.4). */
__kernel void aa_reconstruct(__constant const VbAaPass *aa, __global const float *radiance,
                             __global float *film)
{
    uint j = get_global_id(0);
    if (j >= aa->entries) return;
    uint n = (uint)(aa->side * aa->side);
    float4 sum = (float4)(0.0f);
    for (uint k = 0; k < n; k++) sum += vload4(j * n + k, radiance);
    vstore4(sum * (1.0f / (float)n), aa->first + j, film);
}

/* The contrast test of pixel p (x, y) in a round (aa_contrast_mark, aa_contrast_list): an
 * unsplit pixel against its neighbours, or each leaf of a split one below the top level
 * against its adjacent leaves (aa_leaf_fails), after round 0 only the leaves that lie in or
 * next to a block split last round (aa_leaf_touched; last: the last round's half of split).
 * A failing leaf is appended to marks as (pixel, node code); counts[0] counts the marks,
 * counts[1 + l] those at level l. */
VB_INLINE void aa_contrast_pixel(__constant const VbAaPass *aa, __global const float *film,
                                 __global const int *slots, AaTree tree, __global uint2 *marks,
                                 __global uint *counts, __global const uint *last, int p)
{
    int x = p % aa->width, y = p / aa->width, slot = slots[p], all_plain = 0;
    if (slot < 0) {
        float3 a = aa_display(aa, vload4(p, film).xyz);
        int fails = aa_plain_pixel_fails(aa, film, slots, x, y, a, &all_plain);
        if (all_plain ? !fails
                      : !aa_leaf_fails(aa, film, slots, tree, x * AA_TREE_SIDE, y * AA_TREE_SIDE,
                                       AA_TREE_SIDE, 0, a))
            return;
        uint m = atomic_inc(&counts[0]);
        atomic_inc(&counts[1]);
        marks[m] = (uint2)((uint)p, aa_node_code(0, 0, 0));
        return;
    }
    __global const uchar *own = tree.levels + (size_t)slot * VBCL_AA_CELLS;
    for (int fy = 0; fy < AA_TREE_SIDE; fy++) /* each row one leaf at a time */
        for (int fx = 0; fx < AA_TREE_SIDE;) {
            int lv = own[fy * AA_TREE_SIDE + fx], s = AA_TREE_SIDE >> lv, at = fx;
            fx += s;
            if (lv >= aa->max_level || fy % s) continue; /* not the leaf's first row */
            int X0 = x * AA_TREE_SIDE + at, Y0 = y * AA_TREE_SIDE + fy;
            if (aa->round > 0 && !aa_leaf_touched(aa, last, X0, Y0, s)) continue;
            float3 c = vload4(aa_cell_value(tree.cap, slot, lv, at, fy), tree.values).xyz;
            if (!aa_leaf_fails(aa, film, slots, tree, X0, Y0, s, lv, aa_display(aa, c))) continue;
            uint m = atomic_inc(&counts[0]);
            atomic_inc(&counts[1 + lv]);
            marks[m] = (uint2)((uint)p, aa_node_code(lv, at / s, fy / s));
        }
}

/* film, slots, trees, split -> marks, counts: the contrast test (aa_contrast_pixel) over the
 * whole image: in round 0 every pixel, later those whose neighbourhood was split last round
 * (aa_pixel_dirty). split holds two rounds' blocks, the last round's read and this round's
 * cleared. */
__kernel void aa_contrast_mark(__constant const VbAaPass *aa, __global const float *film,
                               __global const int *slots, __global const uchar *levels,
                               __global const float *values, __global uint2 *marks,
                               __global uint *counts, __global uint *split)
{
    int p = get_global_id(0), npix = aa->width * aa->height;
    AaTree tree = {levels, values, aa->tree_cap};
    if (p >= npix) return;
    /* this round's splits are recorded in the other half of split[] */
    __global const uint *last = split + (aa->round + 1) % 2 * npix;
    split[aa->round % 2 * npix + p] = 0u;
    if (!aa_pixel_dirty(aa, last, p % aa->width, p / aa->width)) return;
    aa_contrast_pixel(aa, film, slots, tree, marks, counts, last, p);
}

/* film, slots, trees, split, list -> marks, counts: the contrast test (aa_contrast_pixel) of
 * the aa->entries pixels listed, those in or next to a pixel split last round
 * (aa_dirty_list): the other pixels' leaves and their neighbours are as they were when they
 * last passed. The host clears this round's half of split. */
__kernel void aa_contrast_list(__constant const VbAaPass *aa, __global const float *film,
                               __global const int *slots, __global const uchar *levels,
                               __global const float *values, __global uint2 *marks,
                               __global uint *counts, __global const uint *split,
                               __global const uint *list)
{
    uint j = get_global_id(0);
    AaTree tree = {levels, values, aa->tree_cap};
    if (j >= aa->entries) return;
    __global const uint *last = split + (aa->round + 1) % 2 * aa->width * aa->height;
    aa_contrast_pixel(aa, film, slots, tree, marks, counts, last, (int)list[j]);
}

/* marks, tags -> list, count: the pixels the next round tests, each once: the pixel of each
 * of the aa->entries marks split in round aa->round and its 8 neighbours. tags[q] holds the
 * round after the last one whose list q joined (0: none). */
__kernel void aa_dirty_list(__constant const VbAaPass *aa, __global const uint2 *marks,
                            __global uint *tags, __global uint *list, __global uint *count)
{
    uint j = get_global_id(0);
    if (j >= aa->entries) return;
    int p = (int)marks[j].x, x = p % aa->width, y = p / aa->width;
    uint tag = (uint)aa->round + 1u;
    for (int qy = max(y - 1, 0); qy <= min(y + 1, aa->height - 1); qy++)
        for (int qx = max(x - 1, 0); qx <= min(x + 1, aa->width - 1); qx++) {
            int q = qy * aa->width + qx;
            if (atomic_xchg(&tags[q], tag) != tag) list[atomic_inc(count)] = (uint)q;
        }
}

/* frame, marks -> rays: three rays per marked node of a batch, through the samples of the
 * three children that do not hold the node's own sample (aa_tree.h): ray i belongs to
 * mark first + i / 3. */
__kernel void aa_split_rays(FRAME_KERNEL_ARGS, __constant const VbAaPass *aa,
                            __global const uint2 *marks)
{
    int i = get_global_id(0);
    if (i >= nrays) return;
    uint2 m = marks[aa->first + (uint)i / 3u];
    uint child = aa_new_child(m.y, i % 3);
    int cell = aa_new_child_cell(child);
    float2 at = aa_cell_position(cell);
    int x = (int)(m.x % (uint)f->width), y = (int)(m.x / (uint)f->width);
    rays[i] = camera_ray(f, (float)x + at.x, (float)y + at.y,
                         aa_tree_sample_id(m.x, (uint)cell, aa_node_level(child)));
}

/* radiance, marks -> levels, values, slots, slot_pixels, split: each marked node of a
 * batch becomes four leaves one level deeper: the child holding the node's sample keeps its
 * value, the other three take the new samples. A pixel split for the first time gets a tree
 * slot (counts[VBCL_AA_MAX_LEVEL + 1] counts the slots; the host made room for them); each
 * split node's blocks (aa_node_blocks) are ORed into its pixel's mask in this round's half
 * of split. */
__kernel void aa_split_store(__constant const VbAaPass *aa, __global const uint2 *marks,
                             __global const float *radiance, __global const float *film,
                             __global int *slots, __global int *slot_pixels, __global uchar *levels,
                             __global float *values, __global uint *counts, __global uint *split)
{
    uint j = get_global_id(0);
    if (j >= aa->entries) return;
    uint2 m = marks[aa->first + j];
    int lv = aa_node_level(m.y) + 1, slot = slots[m.x];
    atomic_or(&split[aa->round % 2 * aa->width * aa->height + (int)m.x], aa_node_blocks(m.y));
    if (slot < 0) {
        slot = (int)atomic_inc(&counts[VBCL_AA_MAX_LEVEL + 1]);
        slots[m.x] = slot;
        slot_pixels[slot] = (int)m.x;
    }
    uint cap = aa->tree_cap;
    int keep = aa_kept_index(m.y);
    float4 v =
        lv == 1 ? vload4(m.x, film)
                : vload4(aa_node_value(cap, slot, lv - 1, aa_node_x(m.y), aa_node_y(m.y)), values);
    aa_fill_levels(levels + (size_t)slot * VBCL_AA_CELLS, m.y, lv);
    for (int c = 0; c < 4; c++) { /* the kept child the node's value, the others (in
                                   * aa_new_child's order) the new samples */
        uint child = aa_child(m.y, c);
        float4 cv = c == keep ? v : vload4(3 * j + (uint)(c < keep ? c : c - 1), radiance);
        vstore4((float4)(cv.xyz, 0.0f),
                aa_node_value(cap, slot, lv, aa_node_x(child), aa_node_y(child)), values);
    }
}

/* levels, values, slot_pixels, slots -> film, info: each refined pixel becomes the mean of
 * its finest cells (a box window over the pixel's own footprint, figure 4.4), each cell the
 * value of the sample nearest to it among the pixel's own and its refined neighbours' near
 * it (aa_nearest_weights; from[s] is the tree slot of the pixel at source s) or, with
 * aa->reconstruct 1, of the leaf covering it (the area-weighted mean of the leaves, the
 * thesis's); info its deepest level | leaf count << 8. */
__kernel void aa_resolve(__constant const VbAaPass *aa, __global const int *slot_pixels,
                         __global const uchar *levels, __global const float *values,
                         __global float *film, __global int *info, __global const int *slots)
{
    uint slot = get_global_id(0);
    if (slot >= aa->entries) return;
    __global const uchar *own = levels + (size_t)slot * VBCL_AA_CELLS;
    uint leaf[AA_EXT_MAX];
    float w[AA_EXT_MAX];
    uint cap = aa->tree_cap;
    int p = slot_pixels[slot];
    int deepest = 0, nown = aa_leaf_list(own, leaf, &deepest);
    float3 sum = (float3)(0.0f);
    if (aa->reconstruct == 1) { /* each cell the value of the leaf covering it */
        for (int k = 0; k < VBCL_AA_CELLS; k++)
            sum += vload4(aa_cell_value(cap, (int)slot, own[k], k % AA_TREE_SIDE, k / AA_TREE_SIDE),
                          values)
                       .xyz;
    } else {
        int x = p % aa->width, y = p / aa->width, n = nown, from[9];
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                int q = (y + dy) * aa->width + x + dx, src = (dy + 1) * 3 + dx + 1;
                from[src] = (int)slot;
                if (src == (int)AA_OWN || x + dx < 0 || x + dx >= aa->width || y + dy < 0 ||
                    y + dy >= aa->height || slots[q] < 0)
                    continue;
                from[src] = slots[q];
                n = aa_band_list(levels + (size_t)slots[q] * VBCL_AA_CELLS, dx, dy, leaf, n);
            }
        aa_nearest_weights(leaf, n, nown, w);
        for (int i = 0; i < n; i++)
            if (w[i] > 0.0f) {
                int at = (int)(leaf[i] >> 16 & 255u), lv = (int)(leaf[i] >> 24 & 15u);
                sum += w[i] * vload4(aa_cell_value(cap, from[leaf[i] >> 28], lv, at % AA_TREE_SIDE,
                                                   at / AA_TREE_SIDE),
                                     values)
                                  .xyz;
            }
    }
    vstore4((float4)(sum * (1.0f / (float)VBCL_AA_CELLS), 1.0f), p, film);
    info[p] = deepest | nown << 8;
}

#ifdef VBCL_TEST_KERNELS
#include "probe.cl"
#endif

#endif
