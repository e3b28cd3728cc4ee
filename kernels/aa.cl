#line 2 "aa.cl"
/* aa.cl — adaptive anti-aliasing as the thesis's subpixel quadtree (4.1.2, figures
 * 4.2–4.4) and uniform supersampling: the contrast test between adjacent leaves, sample
 * positions and ids, and the tree's storage. The entry points are in render.cl.
 *
 * Storage: a pixel nobody refined is its film value (level 0). A refined pixel owns a tree
 * slot of 256 float4 finest cells; each cell holds the value of the leaf that covers it
 * (rgb) and that leaf's level (w). A leaf at level L covers 4^(4-L) cells, so the
 * area-weighted mean of the leaves is the plain mean of the cells. */
#ifndef VBCL_AA_CL
#define VBCL_AA_CL

#include "aa_tree.h"
#include "sample.cl"
#include "types.h"

/* A value for the contrast test: scaled by 2^exposure and clamped to [0, 1], so that
 * differences a display cannot show (above white) do not refine. */
VB_INLINE float3 aa_display(__constant const VbAaPass *aa, float3 v)
{
    return clamp(v * aa->contrast_scale, 0.0f, 1.0f);
}

/* The thesis's contrast |a - b| / (a + b) > threshold, per channel, with a + b raised to
 * the floor (dark pairs need an absolute difference of threshold * floor); a + b = 0
 * never fails. */
VB_INLINE int aa_contrast_fails(float3 a, float3 b, float threshold, float floor)
{
    float3 d = fabs(a - b), s = fmax(a + b, (float3)(floor));
    return d.x > threshold * s.x || d.y > threshold * s.y || d.z > threshold * s.z;
}

/* The leaf covering finest cell (X, Y) of the image (16 cells per pixel axis): its value
 * (rgb, raw) and level (w). */
VB_INLINE float4 aa_leaf_at(__constant const VbAaPass *aa, __global const float *film,
                            __global const int *slots, __global const float *tree, int X, int Y)
{
    int q = (Y / AA_TREE_SIDE) * aa->width + X / AA_TREE_SIDE;
    int slot = slots[q];
    if (slot < 0) return (float4)(vload4(q, film).xyz, 0.0f);
    return vload4((size_t)slot * VBCL_AA_CELLS +
                      (size_t)((Y % AA_TREE_SIDE) * AA_TREE_SIDE + X % AA_TREE_SIDE),
                  tree);
}

/* Whether the leaf of s x s cells at (X0, Y0) (image cells), level lv, display value a,
 * fails the contrast test against an adjacent leaf at its level or deeper: the ring of
 * cells around it is walked one adjacent leaf at a time (leaves are aligned squares, so
 * the next leaf along a row starts at the next multiple of the current one's size). An
 * adjacent leaf at a lower level is not compared: it is the one to split (figure 4.2).
 * The threshold at level lv is threshold * level_gain^lv: with a gain of 1 the thesis's
 * (every level alike); with 2, an edge's share of its pixel's error, which halves with
 * each level (2^L leaves of 4^-L of the pixel along it), is what is held to the threshold. */
VB_INLINE int aa_leaf_fails(__constant const VbAaPass *aa, __global const float *film,
                            __global const int *slots, __global const float *tree, int X0, int Y0,
                            int s, int lv, float3 a)
{
    int W = aa->width * AA_TREE_SIDE, H = aa->height * AA_TREE_SIDE;
    float threshold = aa->threshold; /* x level_gain^lv (pown costs an exp and a log here) */
    for (int l = 0; l < lv; l++) threshold *= aa->level_gain;
    for (int side = 0; side < 4; side++) {
        int row = side < 2; /* sides 0, 1: the rows above and below, corners included */
        int fixed = row ? (side == 0 ? Y0 - 1 : Y0 + s) : (side == 2 ? X0 - 1 : X0 + s);
        if (fixed < 0 || fixed >= (row ? H : W)) continue;
        int lo = row ? max(X0 - 1, 0) : Y0, hi = row ? min(X0 + s, W - 1) : Y0 + s - 1;
        for (int t = lo; t <= hi;) {
            float4 c = row ? aa_leaf_at(aa, film, slots, tree, t, fixed)
                           : aa_leaf_at(aa, film, slots, tree, fixed, t);
            int lc = (int)c.w, sc = AA_TREE_SIDE >> lc;
            if (lc >= lv && aa_contrast_fails(a, aa_display(aa, c.xyz), threshold, aa->floor))
                return 1;
            t = (t / sc + 1) * sc;
        }
    }
    return 0;
}

/* Whether pixel p (x, y) needs its contrast test this round: in round 0 every pixel, later
 * only a pixel that was split last round or has a neighbour that was (changed[] holds the
 * round of each pixel's last split, or -1). A leaf's test reads only its own pixel and
 * its 8 neighbours, so a pixel none of them changed gives last round's answer again:
 * nothing (its marked leaves were split, which changed it). */
VB_INLINE int aa_pixel_dirty(__constant const VbAaPass *aa, __global const int *changed, int x,
                             int y)
{
    if (aa->round == 0) return 1;
    for (int qy = max(y - 1, 0); qy <= min(y + 1, aa->height - 1); qy++)
        for (int qx = max(x - 1, 0); qx <= min(x + 1, aa->width - 1); qx++)
            if (changed[qy * aa->width + qx] == aa->round - 1) return 1;
    return 0;
}

/* Whether an unsplit pixel p (x, y), display value a, whose 8 neighbours are all unsplit
 * too fails against one of them: the plain 8-neighbour test of the thesis, all at level 0
 * (the ring walk of aa_leaf_fails gives the same answer, one neighbour at a time). */
VB_INLINE int aa_plain_pixel_fails(__constant const VbAaPass *aa, __global const float *film,
                                   __global const int *slots, int x, int y, float3 a,
                                   int *all_plain)
{
    int fails = 0;
    *all_plain = 1;
    for (int qy = max(y - 1, 0); qy <= min(y + 1, aa->height - 1); qy++)
        for (int qx = max(x - 1, 0); qx <= min(x + 1, aa->width - 1); qx++) {
            int q = qy * aa->width + qx;
            if (q == y * aa->width + x) continue;
            if (slots[q] >= 0) *all_plain = 0;
            fails |=
                aa_contrast_fails(a, aa_display(aa, vload4(q, film).xyz), aa->threshold, aa->floor);
        }
    return fails;
}

/* The position of finest cell `cell` in its pixel, in pixels from the pixel's corner: the
 * cell's centre, except the centre cell whose sample is the pixel centre (pass 0's). */
VB_INLINE float2 aa_cell_position(int cell)
{
    if (cell == AA_TREE_CENTRE_CELL) return (float2)(0.5f);
    return (float2)((float)(cell % AA_TREE_SIDE) + 0.5f, (float)(cell / AA_TREE_SIDE) + 0.5f) *
           (1.0f / (float)AA_TREE_SIDE);
}

/* The id of subpixel sub (row-major, of side x side) of a pixel: the pixel index itself
 * for one sample per pixel (so that keys match the unrefined render), otherwise a hash
 * of the three, so every supersample has its own shading jitter. A quadtree sample in
 * finest cell c has the id of subpixel c of 16 x 16 (the pixel index for the centre). */
VB_INLINE uint aa_sample_id(uint pixel, int side, uint sub)
{
    if (side == 1) return pixel;
    return vb_hash(pixel ^ vb_hash(((uint)side << 16) ^ sub ^ 0x5bd1e995u));
}

/* Writes value (rgb) and level lv into the cells of node `code` of a tree slot. */
VB_INLINE void aa_fill_node(__global float *cells, unsigned int code, float3 v, int lv)
{
    int s = AA_TREE_SIDE >> aa_node_level(code);
    int ox = aa_node_x(code) * s, oy = aa_node_y(code) * s;
    for (int y = oy; y < oy + s; y++)
        for (int x = ox; x < ox + s; x++)
            vstore4((float4)(v, (float)lv), y * AA_TREE_SIDE + x, cells);
}

#endif
