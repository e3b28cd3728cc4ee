#line 2 "aa.cl"
/* aa.cl — adaptive anti-aliasing as the thesis's subpixel quadtree (4.1.2, figures
 * 4.2–4.4) and uniform supersampling: the contrast test between adjacent leaves, sample
 * positions and ids, and the tree's storage. The entry points are in render.cl.
 *
 * Storage: a pixel nobody refined is its film value (level 0). A refined pixel owns a tree
 * slot (aa_tree.h): the level of the leaf covering each of its 256 finest cells, one byte
 * each, and the value of each node's sample, level by level. A leaf at level L covers
 * 4^(4-L) cells, so the area-weighted mean of the leaves is the plain mean of the cells'
 * leaves; the default reconstruction instead weighs each sample, the pixel's own or a
 * refined neighbour's, by the pixel's cells nearest to it (aa_nearest_weights). */
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

/* The trees of the refined pixels (aa_tree.h): levels and values of cap slots. */
typedef struct AaTree {
    __global const uchar *levels; /* 256 per slot: the level of the leaf covering each cell */
    __global const float *values; /* a float4 per node, level by level (aa_level_base) */
    uint cap;
} AaTree;

/* The index (in float4) of the value of node (x, y) at level lv (1 .. 4) of a tree slot. */
VB_INLINE size_t aa_node_value(uint cap, int slot, int lv, int x, int y)
{
    return (size_t)cap * (size_t)aa_level_base(lv) + ((size_t)slot << (2 * lv)) +
           (size_t)((y << lv) + x);
}

/* The index (in float4) of the value of the leaf at level lv covering finest cell (fx, fy)
 * of a tree slot. */
VB_INLINE size_t aa_cell_value(uint cap, int slot, int lv, int fx, int fy)
{
    int shift = VBCL_AA_MAX_LEVEL - lv;
    return aa_node_value(cap, slot, lv, fx >> shift, fy >> shift);
}

/* Whether a leaf whose corner is image cell (X0, Y0) leaves its comparison with an adjacent
 * leaf of its own level whose corner is (NX0, NY0) to that leaf: with VbAaPass.pairs 0 a
 * failing pair of one level splits only its first leaf in raster order, as the thesis's
 * figure 4.2 refines the pixel it scans and then compares again (the second one splits in a
 * later round if it still fails against the first's children, now deeper than it). Where
 * the edge lies in the first leaf, the second one's split would only repeat its value. */
VB_INLINE int aa_pair_left_to(__constant const VbAaPass *aa, int X0, int Y0, int NX0, int NY0)
{
    return aa->pairs == 0 && (NY0 < Y0 || (NY0 == Y0 && NX0 < X0));
}

/* Whether the leaf of s x s cells at (X0, Y0) (image cells), level lv, display value a,
 * fails the contrast test against an adjacent leaf at its level or deeper: the ring of
 * cells around it is walked one adjacent leaf at a time (leaves are aligned squares, so
 * the next leaf along a row starts at the next multiple of the current one's size). An
 * adjacent leaf at a lower level is not compared: it is the one to split (figure 4.2); one
 * at the same level that comes first in raster order is not either (aa_pair_left_to).
 * The threshold at level lv is threshold * level_gain^lv: with a gain of 1 the thesis's
 * (every level alike); with 2, an edge's share of its pixel's error, which halves with
 * each level (2^L leaves of 4^-L of the pixel along it), is what is held to the threshold. */
VB_INLINE int aa_leaf_fails(__constant const VbAaPass *aa, __global const float *film,
                            __global const int *slots, AaTree tree, int X0, int Y0, int s, int lv,
                            float3 a)
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
            int X = row ? t : fixed, Y = row ? fixed : t;
            int q = (Y / AA_TREE_SIDE) * aa->width + X / AA_TREE_SIDE, slot = slots[q], lc = 0;
            int fx = X % AA_TREE_SIDE, fy = Y % AA_TREE_SIDE;
            if (slot >= 0)
                lc = tree.levels[(size_t)slot * VBCL_AA_CELLS + (size_t)(fy * AA_TREE_SIDE + fx)];
            int ls = AA_TREE_SIDE >> lc; /* the adjacent leaf's side, in cells */
            if (lc > lv || (lc == lv && !aa_pair_left_to(aa, X0, Y0, X / ls * ls, Y / ls * ls))) {
                float3 c = slot < 0
                               ? vload4(q, film).xyz
                               : vload4(aa_cell_value(tree.cap, slot, lc, fx, fy), tree.values).xyz;
                if (aa_contrast_fails(a, aa_display(aa, c), threshold, aa->floor)) return 1;
            }
            t = (t / ls + 1) * ls;
        }
    }
    return 0;
}

/* Whether pixel p (x, y) needs its contrast test this round: in round 0 every pixel, later
 * only a pixel that was split last round or has a neighbour that was (last[q]: the blocks
 * of pixel q split last round, aa_node_blocks, 0 where none). A leaf's test reads only its
 * own pixel and its 8 neighbours, so a pixel none of them changed gives last round's
 * answer again: nothing (its marked leaves were split, which changed it). */
VB_INLINE int aa_pixel_dirty(__constant const VbAaPass *aa, __global const uint *last, int x, int y)
{
    if (aa->round == 0) return 1;
    for (int qy = max(y - 1, 0); qy <= min(y + 1, aa->height - 1); qy++)
        for (int qx = max(x - 1, 0); qx <= min(x + 1, aa->width - 1); qx++)
            if (last[qy * aa->width + qx] != 0u) return 1;
    return 0;
}

/* The 4 x 4-cell blocks of a pixel (bit by * 4 + bx) that cells x0 .. x1, y0 .. y1 of it
 * (0 .. 15, x0 <= x1, y0 <= y1) meet. */
VB_INLINE uint aa_block_mask(int x0, int x1, int y0, int y1)
{
    uint cols = (0xfu >> (3 - x1 / 4)) & (0xfu << (x0 / 4)) & 0xfu;
    uint rows = (0xffffu >> (4 * (3 - y1 / 4))) & (0xffffu << (4 * (y0 / 4))) & 0x1111u;
    return cols * rows;
}

/* The blocks (aa_block_mask) of node `code` of a pixel. */
VB_INLINE uint aa_node_blocks(unsigned int code)
{
    int s = AA_TREE_SIDE >> aa_node_level(code);
    int x0 = aa_node_x(code) * s, y0 = aa_node_y(code) * s;
    return aa_block_mask(x0, x0 + s - 1, y0, y0 + s - 1);
}

/* Whether the leaf of s x s cells at (X0, Y0) (image cells) needs its contrast test in a
 * round after the first: whether it or an adjacent cell lies in a block split last round
 * (split[q]: the blocks of pixel q split last round). Otherwise the leaf and every leaf
 * around it are as they were when it last passed the test (each split is followed by the
 * test of every leaf around it), so it passes again. */
VB_INLINE int aa_leaf_touched(__constant const VbAaPass *aa, __global const uint *split, int X0,
                              int Y0, int s)
{
    int W = aa->width * AA_TREE_SIDE, H = aa->height * AA_TREE_SIDE;
    int bx0 = max(X0 - 1, 0), bx1 = min(X0 + s, W - 1), by0 = max(Y0 - 1, 0),
        by1 = min(Y0 + s, H - 1);
    for (int qy = by0 / AA_TREE_SIDE; qy <= by1 / AA_TREE_SIDE; qy++)
        for (int qx = bx0 / AA_TREE_SIDE; qx <= bx1 / AA_TREE_SIDE; qx++) {
            uint m = split[qy * aa->width + qx];
            if (!m) continue;
            int ox = qx * AA_TREE_SIDE, oy = qy * AA_TREE_SIDE;
            if (m & aa_block_mask(max(bx0 - ox, 0), min(bx1 - ox, AA_TREE_SIDE - 1),
                                  max(by0 - oy, 0), min(by1 - oy, AA_TREE_SIDE - 1)))
                return 1;
        }
    return 0;
}

/* Whether an unsplit pixel p (x, y), display value a, whose 8 neighbours are all unsplit
 * too fails against one of them: the plain 8-neighbour test of the thesis, all at level 0
 * (the ring walk of aa_leaf_fails gives the same answer, one neighbour at a time, and
 * leaves the same neighbours to be compared by their own test: aa_pair_left_to). */
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
            if (aa_pair_left_to(aa, x, y, qx, qy)) continue;
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

/* The id of the quadtree sample in finest cell `cell` of a pixel, fresh at level `level`
 * (1 .. 4): aa_sample_id of subpixel cell of 16 x 16, its top four bits replaced by 1 and
 * the level, so that sample_share can read the level back. Pass 0's ids (pixel indices)
 * have bit 31 clear. */
VB_INLINE uint aa_tree_sample_id(uint pixel, uint cell, int level)
{
    return (aa_sample_id(pixel, AA_TREE_SIDE, cell) & 0x0fffffffu) | 0x80000000u |
           (uint)level << 28;
}

/* The reconstruction also uses the samples of the adjacent pixels' trees that lie in their
 * cells within AA_BAND finest cells of the pixel (a pixel's centre sample counts as lying
 * in its cell (8, 8)): positions are in half-cells of the square of AA_EXT_SIDE cells
 * around the pixel, the pixel itself from 2 * AA_BAND to 2 * (AA_BAND + AA_TREE_SIDE). */
#define AA_BAND     8
#define AA_EXT_SIDE (AA_TREE_SIDE + 2 * AA_BAND)
#define AA_EXT_MAX  (4 * VBCL_AA_CELLS) /* own 256; sides 4 x 128, corners 4 x 64 */
#define AA_OWN      4u                  /* the source of the pixel's own samples */

/* The code of the sample of a leaf at level lv whose sample cell is `at` (a cell of the
 * leaf) in the tree of pixel `src` (0 .. 8, row-major over the
 * 3 x 3 pixels, AA_OWN the pixel itself), offset by (ox, oy) half-cells:
 * x | y << 8 | at << 16 | lv << 24 | src << 28, (x, y) the sample's position in half-cells
 * of the square around the pixel (exact: a cell's centre is odd, a pixel's centre even). */
VB_INLINE uint aa_sample_code(int at, int lv, uint src, int ox, int oy)
{
    int hx = at == AA_TREE_CENTRE_CELL ? AA_TREE_SIDE : 2 * (at % AA_TREE_SIDE) + 1;
    int hy = at == AA_TREE_CENTRE_CELL ? AA_TREE_SIDE : 2 * (at / AA_TREE_SIDE) + 1;
    return (uint)(hx + ox) | (uint)(hy + oy) << 8 | (uint)at << 16 | (uint)lv << 24 | src << 28;
}

/* The leaves of the cells fx0 .. fx1 - 1, fy0 .. fy1 - 1 of a tree slot (a region whose
 * bounds are multiples of 8 cells, so that each leaf below the pixel lies wholly in it or
 * out of it), in the order of their first cells, appended to leaf from n on
 * (aa_sample_code: held in the leaf's sample cell, source src, offset (ox, oy)). Each row
 * is walked one leaf at a time (the next leaf along a row starts at the next multiple of
 * the current one's size). Returns the new count; *deepest gets the deepest level. */
VB_INLINE int aa_region_leaves(__global const uchar *levels, int fx0, int fx1, int fy0, int fy1,
                               uint src, int ox, int oy, uint *leaf, int n, int *deepest)
{
    for (int fy = fy0; fy < fy1; fy++)
        for (int fx = fx0; fx < fx1;) {
            int lv = levels[fy * AA_TREE_SIDE + fx], s = AA_TREE_SIDE >> lv;
            *deepest = max(*deepest, lv);
            if (fy % s == 0) {
                int at = aa_node_sample_cell(lv, fx / s, fy / s);
                leaf[n++] = aa_sample_code(at, lv, src, ox, oy);
            }
            fx = (fx / s + 1) * s;
        }
    return n;
}

/* The leaves of a tree slot (aa_region_leaves over the whole pixel). */
VB_INLINE int aa_leaf_list(__global const uchar *levels, uint *leaf, int *deepest)
{
    return aa_region_leaves(levels, 0, AA_TREE_SIDE, 0, AA_TREE_SIDE, AA_OWN, 2 * AA_BAND,
                            2 * AA_BAND, leaf, 0, deepest);
}

/* The samples of the tree of the adjacent pixel at (dx, dy) (each -1 .. 1) that lie in its
 * cells within AA_BAND cells of the pixel, appended to leaf from n on. Returns the new
 * count. */
VB_INLINE int aa_band_list(__global const uchar *levels, int dx, int dy, uint *leaf, int n)
{
    int x0 = dx < 0 ? AA_TREE_SIDE - AA_BAND : 0, x1 = dx > 0 ? AA_BAND : AA_TREE_SIDE;
    int y0 = dy < 0 ? AA_TREE_SIDE - AA_BAND : 0, y1 = dy > 0 ? AA_BAND : AA_TREE_SIDE;
    int deepest = 0;
    return aa_region_leaves(levels, x0, x1, y0, y1, (uint)((dy + 1) * 3 + dx + 1),
                            2 * (AA_BAND + dx * AA_TREE_SIDE), 2 * (AA_BAND + dy * AA_TREE_SIDE),
                            leaf, n, &deepest);
}

/* The squared distance in half-cells from a cell's centre (cx, cy) to the sample
 * coded l (aa_sample_code): an exact integer. */
VB_INLINE int aa_sample_d2(uint l, int cx, int cy)
{
    int dx = (int)(l & 255u) - cx, dy = (int)(l >> 8 & 255u) - cy;
    return dx * dx + dy * dy;
}

/* Whether the sample coded l (aa_sample_code) is at least as near as the sample at
 * (hx, hy) to some cell centre of the rectangle lx .. hx2, ly .. hy2 (half-cells): the
 * cells where it is, d^2(l, c) - d^2(h, c) <= 0, lie on one side of a straight line (the
 * difference is linear in c), so the rectangle's corner that minimises it decides. Exact:
 * a sample that fails is neither nearer nor tied anywhere in the rectangle. */
VB_INLINE int aa_sample_may_win(uint l, int hx, int hy, int lx, int ly, int hx2, int hy2)
{
    int jx = (int)(l & 255u), jy = (int)(l >> 8 & 255u), dx = hx - jx, dy = hy - jy;
    int px = dx >= 0 ? lx : hx2, py = dy >= 0 ? ly : hy2;
    return 2 * (px * dx + py * dy) + jx * jx + jy * jy - hx * hx - hy * hy <= 0;
}

/* The weights of the n samples (aa_sample_code: the pixel's own leaves first, nown of
 * them, then its neighbours' band) for a pixel's value: w[i] is the number of the pixel's
 * finest cells whose centre lies nearer to sample i than to any other, a cell equally near
 * to m samples counted 1/m to each (the areas of the samples' Voronoi cells over the
 * pixel, at the resolution of the cells). Over the 256 cells they sum to 256.
 * Leaf by leaf: no sample is nearer to a cell of the leaf than the leaf's own sample is
 * to its farthest cell, so the candidates for all its cells are the samples lying in the
 * cells within that distance of the leaf (held: the sample lying in each cell of the
 * square around the pixel, a pixel centre's in its cell (8, 8)), or every sample where
 * those cells are more, less each sample that is farther than the leaf's own from every
 * cell of the leaf (aa_sample_may_win). Scalar code:
 * oclgrind 21.10 computed a search over every leaf written in int4 or int16 lanes wrongly where
 * PoCL ran it right. */
VB_INLINE void aa_nearest_weights(const uint *leaf, int n, int nown, float *w)
{
    short held[AA_EXT_SIDE * AA_EXT_SIDE], cand[AA_EXT_MAX];
    for (int k = 0; k < AA_EXT_SIDE * AA_EXT_SIDE; k++) held[k] = -1;
    for (int i = 0; i < n; i++) {
        held[(int)(leaf[i] >> 8 & 255u) / 2 * AA_EXT_SIDE + (int)(leaf[i] & 255u) / 2] = (short)i;
        w[i] = 0.0f;
    }
    for (int i = 0; i < nown; i++) {
        int at = (int)(leaf[i] >> 16 & 255u), s = AA_TREE_SIDE >> (int)(leaf[i] >> 24 & 15u);
        int hx = (int)(leaf[i] & 255u), hy = (int)(leaf[i] >> 8 & 255u);
        int lx = 2 * (at % AA_TREE_SIDE / s * s + AA_BAND) + 1; /* the leaf's first cell */
        int ly = 2 * (at / AA_TREE_SIDE / s * s + AA_BAND) + 1;
        int hx2 = lx + 2 * (s - 1), hy2 = ly + 2 * (s - 1); /* the last cell centres */
        int ax = max(abs(lx - hx), abs(hx2 - hx)), ay = max(abs(ly - hy), abs(hy2 - hy));
        /* a candidate lies within r half-cells of some cell centre of the leaf; a cell's
         * centre is odd, a pixel centre (even) on the corner of its cell (8, 8), hence the 1 */
        int r = (int)ceil(sqrt((float)(ax * ax + ay * ay))) + 1;
        int x0 = max(lx - r, 0) / 2, x1 = min(hx2 + r, 2 * AA_EXT_SIDE - 1) / 2;
        int y0 = max(ly - r, 0) / 2, y1 = min(hy2 + r, 2 * AA_EXT_SIDE - 1) / 2;
        int m = 0;
        if ((x1 - x0 + 1) * (y1 - y0 + 1) < n) {
            for (int y = y0; y <= y1; y++)
                for (int x = x0; x <= x1; x++) {
                    int j = held[y * AA_EXT_SIDE + x];
                    if (j >= 0 && aa_sample_may_win(leaf[j], hx, hy, lx, ly, hx2, hy2))
                        cand[m++] = (short)j;
                }
        } else {
            for (int j = 0; j < n; j++)
                if (aa_sample_may_win(leaf[j], hx, hy, lx, ly, hx2, hy2)) cand[m++] = (short)j;
        }
        for (int cy = ly; cy <= hy2; cy += 2)
            for (int cx = lx; cx <= hx2; cx += 2) {
                int best = INT_MAX, ties = 0, nearest = i;
                for (int j = 0; j < m; j++) {
                    int d = aa_sample_d2(leaf[cand[j]], cx, cy);
                    if (d < best) {
                        best = d;
                        ties = 1;
                        nearest = cand[j];
                    } else {
                        ties += d == best;
                    }
                }
                if (ties == 1) {
                    w[nearest] += 1.0f;
                    continue;
                }
                float share = 1.0f / (float)ties; /* on a bisector: rare, a second look */
                for (int j = 0; j < m; j++)
                    if (aa_sample_d2(leaf[cand[j]], cx, cy) == best) w[cand[j]] += share;
            }
    }
}

/* Writes level lv into the cells of node `code` of a tree slot's levels. */
VB_INLINE void aa_fill_levels(__global uchar *levels, unsigned int code, int lv)
{
    int s = AA_TREE_SIDE >> aa_node_level(code);
    int ox = aa_node_x(code) * s, oy = aa_node_y(code) * s;
    for (int y = oy; y < oy + s; y++)
        for (int x = ox; x < ox + s; x++) levels[y * AA_TREE_SIDE + x] = (uchar)lv;
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

/* Splits the node of mark m (pixel, node code), the j-th of a batch, into four leaves one
 * level deeper (aa_split_store): the child holding the node's sample keeps its value, the
 * other three take the batch's new samples 3j .. 3j + 2 of radiance. A pixel split for the
 * first time gets a tree slot (counts[VBCL_AA_MAX_LEVEL + 1] counts the slots); the node's
 * blocks (aa_node_blocks) are ORed into its pixel's mask in this round's half of split. */
VB_INLINE void aa_split_node(__constant const VbAaPass *aa, uint2 m, uint j,
                             __global const float *radiance, __global const float *film,
                             __global int *slots, __global int *slot_pixels, __global uchar *levels,
                             __global float *values, __global uint *counts, __global uint *split)
{
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

/* The sum over the finest cells of refined pixel p (tree slot `slot`), each cell the value of
 * the sample nearest to it among the pixel's own and its refined neighbours' near it
 * (aa_nearest_weights; from[s] is the tree slot of the pixel at source s) or, with
 * aa->reconstruct 1, of the leaf covering it (the thesis's area-weighted mean of the
 * leaves); *deepest its deepest level, *nleaves its leaf count. */
VB_INLINE float3 aa_resolve_pixel(__constant const VbAaPass *aa, AaTree tree,
                                  __global const int *slots, int slot, int p, int *deepest,
                                  int *nleaves)
{
    __global const uchar *own = tree.levels + (size_t)slot * VBCL_AA_CELLS;
    uint leaf[AA_EXT_MAX];
    float w[AA_EXT_MAX];
    int nown = aa_leaf_list(own, leaf, deepest);
    float3 sum = (float3)(0.0f);
    *nleaves = nown;
    if (aa->reconstruct == 1) { /* each cell the value of the leaf covering it */
        for (int k = 0; k < VBCL_AA_CELLS; k++)
            sum += vload4(aa_cell_value(tree.cap, slot, own[k], k % AA_TREE_SIDE, k / AA_TREE_SIDE),
                          tree.values)
                       .xyz;
        return sum;
    }
    int x = p % aa->width, y = p / aa->width, n = nown, from[9];
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            int q = (y + dy) * aa->width + x + dx, src = (dy + 1) * 3 + dx + 1;
            from[src] = slot;
            if (src == (int)AA_OWN || x + dx < 0 || x + dx >= aa->width || y + dy < 0 ||
                y + dy >= aa->height || slots[q] < 0)
                continue;
            from[src] = slots[q];
            n = aa_band_list(tree.levels + (size_t)slots[q] * VBCL_AA_CELLS, dx, dy, leaf, n);
        }
    aa_nearest_weights(leaf, n, nown, w);
    for (int i = 0; i < n; i++)
        if (w[i] > 0.0f) {
            int at = (int)(leaf[i] >> 16 & 255u), lv = (int)(leaf[i] >> 24 & 15u);
            sum += w[i] * vload4(aa_cell_value(tree.cap, from[leaf[i] >> 28], lv, at % AA_TREE_SIDE,
                                               at / AA_TREE_SIDE),
                                 tree.values)
                              .xyz;
        }
    return sum;
}

#endif
