#line 2 "tree.cl"
/* tree.cl — the ray tree of a sample (thesis figure 4.7), explored depth first with an
 * explicit stack: at every interface a reflected and a transmitted child, weighted by
 * k_global times R and T, attenuated by absorption along their way; bounded by
 * max_depth (frame, run time) and pruned when a branch's weight is below min_weight in every
 * channel, so a branch that cannot change the pixel is not traced. */

/* Depth-first with at most one pending sibling per level: max_depth + 1 entries suffice.
 * The host compiles the stack for the next size class (8, 16, 32, 64) above the scene's
 * max_depth, so changing the depth rarely rebuilds the program. */
#ifndef VBCL_TREE_STACK
#define VBCL_TREE_STACK 8
#endif
#define VB_TREE_STACK VBCL_TREE_STACK

/* A pending branch of the tree. */
typedef struct TreeRay {
    float3 org, dir;
    float3 weight; /* what its radiance counts for in the pixel */
    VbMedium medium;
    int depth;
    uint key; /* from the branch's path, so pruning one branch leaves the others' jitter alone */
} TreeRay;

/* What one sample's tree did, summed into the frame counters at the end. */
typedef struct TreeCount {
    uint reflected, transmitted, pruned, depth_cut, tir, passes, interfaces, energy_errors;
    uint by_depth[VBCL_COUNT_DEPTH_BINS];
    float prune_budget; /* weight this sample may still drop: starts at min_weight */
} TreeCount;

/* Pushes a branch unless it is deeper than max_depth or pruned. Pruning: a branch whose
 * weight is below min_weight in every channel is dropped while the weights dropped in this
 * sample sum to at most min_weight (so pruning changes the pixel by at most min_weight
 * times the brightest radiance in the scene); beyond that budget only branches below
 * min_weight / 1000 are dropped. */
VB_INLINE void tree_push(TreeRay *stack, int *n, float3 org, float3 dir, float3 w, VbMedium m,
                         int depth, uint key, __constant const VbFrame *f, TreeCount *cnt,
                         int transmitted)
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
    t.depth = depth;
    t.key = key;
    stack[(*n)++] = t;
    if (transmitted)
        cnt->transmitted++;
    else
        cnt->reflected++;
    cnt->by_depth[min(depth, VBCL_COUNT_DEPTH_BINS - 1)]++;
}

/* Pushes the children of a ray that arrived along dir with weight w at the interface c
 * (seen at shading point sp, medium `before` on the incoming side). */
VB_INLINE void tree_spawn(const DevScene *sc, TreeRay *stack, int *n, const ShadePoint *sp,
                          float3 dir, const Crossing *c, VbMedium before, float3 w, int depth,
                          TreeCount *cnt)
{
    __global const VbMaterial *ms = sc->materials + c->surface;
    OpticsSplit s = optics_split(dir, sp->ns, sp->ng, sc->materials[c->mat_before].eta,
                                 sc->materials[c->mat_after].eta);
    cnt->tir += (uint)s.tir;
    cnt->interfaces++;
    cnt->energy_errors += fabs(s.R + s.T - 1.0f) > 1e-5f;
    float3 wg = w * ms->k_global;
    tree_push(stack, n, ray_offset_origin(sp->p, sp->ng, sp->scale), s.reflected, wg * s.R, before,
              depth, vb_hash(2u * sp->key + 1u), sc->f, cnt, 0);
    if (s.T > 0.0f)
        tree_push(stack, n, ray_offset_origin(sp->p, -sp->ng, sp->scale), s.transmitted, wg * s.T,
                  c->after, depth, vb_hash(2u * sp->key + 2u), sc->f, cnt, 1);
}
