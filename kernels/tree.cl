#line 2 "tree.cl"
/* tree.cl — the ray tree of a sample (thesis figure 4.7), explored depth first with an
 * explicit stack: at every interface a reflected and a transmitted child, weighted by
 * k_global times R and T, attenuated by absorption along their way; bounded by
 * max_depth (frame, run time) and pruned when a branch's weight is below min_weight in every
 * channel, so a branch that cannot change the pixel is not traced. */
#ifndef VBCL_TREE_CL
#define VBCL_TREE_CL

#include "light.cl"
#include "medium.cl"
#include "optics.cl"

/* Depth-first with at most one pending sibling per level: max_depth + 1 entries suffice,
 * and with dispersion the level of a path's one split holds up to `bands` pending band rays
 * more. The host compiles the stack for the deepest tree any scene can ask of the program
 * (kernel_features.c: 65 entries, 129 with dispersion), so no scene setting rebuilds it. */
#ifndef VBCL_TREE_STACK
#define VBCL_TREE_STACK 65
#endif
#define VB_TREE_STACK VBCL_TREE_STACK

/* Whether the scene splits energy by the thesis's eq. 9 instead of Fresnel's equations. */
#define TREE_THESIS(sc) (((sc)->f->flags & VBCL_FRAME_FRESNEL_THESIS) != 0u)

/* A pending branch of the tree. */
typedef struct TreeRay {
    float3 org, dir;
    float3 weight; /* what its radiance counts for in the pixel */
    VbMedium medium;
    int tri; /* the triangle it leaves from, or -1: not known (ray_objects) */
    int depth;
    uint key; /* from the branch's path, so pruning one branch leaves the others' jitter alone */
    int band; /* the wavelength band it carries, or -1: all of them (white) */
} TreeRay;

/* What one sample's tree did, summed into the frame counters at the end. */
typedef struct TreeCount {
    uint reflected, transmitted, pruned, depth_cut, tir, passes, interfaces, energy_errors;
    uint splits, band_rays;
    uint tree_cut; /* branches left when the tree reached VBCL_TREE_MAX_RAYS */
    uint by_depth[VBCL_COUNT_DEPTH_BINS];
    float prune_budget; /* weight this sample may still drop: starts at min_weight */
} TreeCount;

/* Pushes a branch unless it is deeper than max_depth or pruned. Pruning: a branch whose
 * weight is below min_weight in every channel is dropped while the weights dropped in this
 * sample sum to at most min_weight (so pruning changes the pixel by at most min_weight
 * times the brightest radiance in the scene); beyond that budget only branches below
 * min_weight / 1000 are dropped. */
VB_INLINE void tree_push(TreeRay *stack, int *n, float3 org, int tri, float3 dir, float3 w,
                         VbMedium m, int depth, uint key, __constant const VbFrame *f,
                         TreeCount *cnt, int transmitted, int band)
{
    float wm = vb_max3(w);
    if (wm <= 0.0f) return; /* no energy: nothing to trace or count */
    if (depth > f->max_depth || *n >= VB_TREE_STACK) {
        cnt->depth_cut++;
        return;
    }
    if (wm < f->min_weight && (wm <= cnt->prune_budget || wm < f->min_weight * 1e-3f)) {
        if (wm <= cnt->prune_budget) cnt->prune_budget -= wm;
        cnt->pruned++;
        return;
    }
    TreeRay t;
    t.org = org;
    t.dir = dir;
    t.weight = w;
    t.medium = m;
    t.tri = tri;
    t.depth = depth;
    t.key = key;
    t.band = band;
    stack[(*n)++] = t;
    cnt->band_rays += band >= 0;
    if (transmitted)
        cnt->transmitted++;
    else
        cnt->reflected++;
    cnt->by_depth[min(depth, VBCL_COUNT_DEPTH_BINS - 1)]++;
}

#ifdef VBCL_HAS_DISPERSION
/* Pushes the transmitted bands of a white ray that refracts at interface c (seen at sp,
 * arriving along dir with weight wg, k_global included): one ray per band, weighted by the
 * band's rgb weight, its own T and what the entered material lets through of the band. */
VB_INLINE void tree_push_bands(const DevScene *sc, TreeRay *stack, int *n, const ShadePoint *sp,
                               float3 dir, const Crossing *c, float3 wg, int depth, uint tkey,
                               TreeCount *cnt)
{
    for (int b = 0; b < sc->f->bands; b++) {
        float3 bw = vb_gload3(sc->texels + sc->f->band_weights + 4 * b);
        OpticsSplit s = optics_split(dir, sp->ns, sp->ng, medium_eta(sc, c->mat_before, b),
                                     medium_eta(sc, c->mat_after, b), TREE_THESIS(sc));
        cnt->tir += (uint)s.tir;
        cnt->energy_errors += fabs(s.R + s.T - 1.0f) > 1e-5f;
        if (s.T > 0.0f)
            tree_push(stack, n, ray_offset_origin(sp->p, -sp->ng, sp->err), sp->tri, s.transmitted,
                      wg * bw * (s.T * medium_band_transmit(sc, c->mat_after, b)), c->after, depth,
                      vb_hash(tkey + (uint)b), sc->f, cnt, 1, b);
    }
}

/* Records a split in the ray's next free slot for the band launch; 0 when the slots are
 * full (the caller then pushes the bands itself). */
VB_INLINE int tree_record_split(__global VbSplitSet *rec, const ShadePoint *sp, float3 dir,
                                const Crossing *c, float3 wg, int depth, uint tkey)
{
    if (!rec || rec->count >= VBCL_SPLIT_SLOTS) return 0;
    __global VbSplit *s = rec->s + rec->count++;
    vstore4((float4)(sp->p, sp->err), 0, s->p);
    vstore4((float4)(sp->ng, 0.0f), 0, s->ng);
    vstore4((float4)(sp->ns, 0.0f), 0, s->ns);
    vstore4((float4)(dir, 0.0f), 0, s->dir);
    vstore4((float4)(wg, 0.0f), 0, s->weight);
    s->after = c->after;
    s->mat_before = c->mat_before;
    s->mat_after = c->mat_after;
    s->depth = depth;
    s->key = tkey;
    return 1;
}
#endif

/* Pushes the children of a ray of band `band` (-1: white) that arrived along dir with
 * weight w at the interface c (seen at shading point sp, medium `before` on the incoming
 * side). A white ray refracting at an interface with a dispersive side splits: its
 * transmitted part becomes one ray per band (tree_push_bands), recorded in rec for the
 * band launch of tree_trace_secondary while it has a free slot; the reflected ray stays one white
 * ray, weighted by the band-weighted sum of the R. rec may be 0 (bands pushed here). */
VB_INLINE void tree_spawn(const DevScene *sc, TreeRay *stack, int *n, const ShadePoint *sp,
                          float3 dir, const Crossing *c, VbMedium before, float3 w, int depth,
                          TreeCount *cnt, int band, __global VbSplitSet *rec)
{
    __global const VbMaterial *ms = sc->materials + c->surface;
    float3 wg = w * ms->k_global;
#ifdef VBCL_HAS_DISPERSION
    if (band < 0 &&
        (sc->materials[c->mat_before].disp >= 0 || sc->materials[c->mat_after].disp >= 0)) {
        OpticsSplit s0 = optics_split(dir, sp->ns, sp->ng, sc->materials[c->mat_before].eta,
                                      sc->materials[c->mat_after].eta, TREE_THESIS(sc));
        cnt->interfaces++;
        if (s0.T > 0.0f) { /* a refraction: split into the bands */
            cnt->splits++;
            float3 wr = (float3)(0.0f);
            for (int b = 0; b < sc->f->bands; b++) {
                OpticsSplit s = optics_split(dir, sp->ns, sp->ng, medium_eta(sc, c->mat_before, b),
                                             medium_eta(sc, c->mat_after, b), TREE_THESIS(sc));
                wr += vb_gload3(sc->texels + sc->f->band_weights + 4 * b) * s.R;
            }
            tree_push(stack, n, ray_offset_origin(sp->p, sp->ng, sp->err), sp->tri, s0.reflected,
                      wg * wr, before, depth, vb_hash(2u * sp->key + 1u), sc->f, cnt, 0, -1);
            uint tkey = vb_hash(2u * sp->key + 2u);
            if (!tree_record_split(rec, sp, dir, c, wg, depth, tkey))
                tree_push_bands(sc, stack, n, sp, dir, c, wg, depth, tkey, cnt);
            return;
        }
        cnt->tir += (uint)s0.tir;
        tree_push(stack, n, ray_offset_origin(sp->p, sp->ng, sp->err), sp->tri, s0.reflected,
                  wg * s0.R, before, depth, vb_hash(2u * sp->key + 1u), sc->f, cnt, 0, -1);
        return;
    }
    float eta1 = medium_eta(sc, c->mat_before, band), eta2 = medium_eta(sc, c->mat_after, band);
    float tin = medium_band_transmit(sc, c->mat_after, band);
#else
    (void)rec;
    float eta1 = sc->materials[c->mat_before].eta, eta2 = sc->materials[c->mat_after].eta;
    float tin = 1.0f;
#endif
    OpticsSplit s = optics_split(dir, sp->ns, sp->ng, eta1, eta2, TREE_THESIS(sc));
    cnt->tir += (uint)s.tir;
    cnt->interfaces++;
    cnt->energy_errors += fabs(s.R + s.T - 1.0f) > 1e-5f;
    tree_push(stack, n, ray_offset_origin(sp->p, sp->ng, sp->err), sp->tri, s.reflected, wg * s.R,
              before, depth, vb_hash(2u * sp->key + 1u), sc->f, cnt, 0, band);
    if (s.T > 0.0f)
        tree_push(stack, n, ray_offset_origin(sp->p, -sp->ng, sp->err), sp->tri, s.transmitted,
                  wg * (s.T * tin), c->after, depth, vb_hash(2u * sp->key + 2u), sc->f, cnt, 1,
                  band);
}

/* The first interface along tree ray tr within the triangles it can meet (ray_objects;
 * medium_trace follows it through pass-through crossings, updating *state). */
VB_INLINE int tree_trace(const DevScene *sc, const TreeRay *tr, VbMedium *state, PathHit *ph,
                         TraceCount *tc, uint *passes)
{
    ObjectSet os;
    float reach = ray_objects(sc, tr->org, tr->dir, tr->tri, tr->medium.host, &os);
    return medium_trace(sc, &os, tr->org, tr->dir, reach, state, ph, tc, passes, 0);
}

#endif
