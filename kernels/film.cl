#line 2 "film.cl"
/* film.cl — the anti-aliasing kernels that trace nothing (thesis 4.1.2): the contrast test
 * over the film and the quadtrees, the list of pixels to test again, storing a split's
 * samples, and the reconstruction of supersampled and refined pixels. A small program of
 * its own, the same for every scene (the kernels that generate anti-aliasing's rays are in
 * render.cl, beside the camera's). */
#ifndef VBCL_FILM_CL
#define VBCL_FILM_CL

#include "aa.cl"

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

#endif
