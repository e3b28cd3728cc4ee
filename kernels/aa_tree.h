/* aa_tree.h — the subpixel quadtree of adaptive anti-aliasing (thesis 4.1.2, figure 4.3):
 * node codes and the nested sample positions, in integer arithmetic that compiles both as
 * host C (tests/test_aa.c checks the nesting exhaustively) and as OpenCL C (kernels/aa.cl).
 *
 * A pixel is divided into 16x16 finest cells; a node at level L is a square of
 * 16 >> L cells, (x, y) in 0 .. 2^L - 1. Every node has one sample, at the centre of one
 * of its finest cells (its sample cell). The pixel's (level 0) is the pixel centre, pass
 * 0's ray, kept in cell (8, 8). The sample of a node is its parent's when it lies inside
 * the node; otherwise the node gets a fresh one, the central cell of the node farthest
 * from the parent's centre. So each level's samples include the previous level's: a node
 * splits into four children with three new samples, and no position is traced twice. */
#ifndef VBCL_AA_TREE_H
#define VBCL_AA_TREE_H

#include "compat.h"

#ifdef VBCL_DEVICE
#define AA_TREE_FN inline
#else
#define AA_TREE_FN static inline
#endif

#define AA_TREE_SIDE        16  /* finest cells per pixel axis: 2^VBCL_AA_MAX_LEVEL */
#define AA_TREE_CENTRE_CELL 136 /* (8, 8): the cell holding the pixel centre */
#define AA_TREE_NODES       340 /* nodes at levels 1 .. 4: 4 + 16 + 64 + 256 */

/* A refined pixel's tree lives in a slot of two buffers: its levels, one byte per finest
 * cell (the level of the leaf covering it), and its values, one float4 per node at levels
 * 1 .. 4 (the value of the node's sample). The values are kept level by level: level L
 * (4^L nodes per slot) begins at cap * aa_level_base(L), cap the slots the buffers hold,
 * so a pixel refined only to level 1 uses 64 bytes of them. */
AA_TREE_FN int aa_level_base(int level)
{
    return ((1 << (2 * level)) - 4) / 3;
}

/* A node as one integer: level in bits 8-10, y in bits 4-7, x in bits 0-3. */
AA_TREE_FN unsigned int aa_node_code(int level, int x, int y)
{
    return ((unsigned int)level << 8) | ((unsigned int)y << 4) | (unsigned int)x;
}
AA_TREE_FN int aa_node_level(unsigned int code)
{
    return (int)(code >> 8);
}
AA_TREE_FN int aa_node_x(unsigned int code)
{
    return (int)(code & 15u);
}
AA_TREE_FN int aa_node_y(unsigned int code)
{
    return (int)((code >> 4) & 15u);
}

/* The fresh sample cell along one axis of a node of s cells from o: the central cell
 * farthest from its parent's centre (which is at o + s for a left/top child, at o for a
 * right/bottom one). */
AA_TREE_FN int aa_fresh_cell(int o, int s, int odd)
{
    if (s == 1) return o;
    return odd ? o + s / 2 : o + s / 2 - 1;
}

/* The sample cell (row-major, fy * 16 + fx) of node (level, x, y), walking down from the
 * pixel centre through its ancestors. */
AA_TREE_FN int aa_node_sample_cell(int level, int x, int y)
{
    int fx = 8, fy = 8;
    for (int l = 1; l <= level; l++) {
        int ax = x >> (level - l), ay = y >> (level - l), s = AA_TREE_SIDE >> l;
        int ox = ax * s, oy = ay * s;
        if (fx >= ox && fx < ox + s && fy >= oy && fy < oy + s) continue;
        fx = aa_fresh_cell(ox, s, ax & 1);
        fy = aa_fresh_cell(oy, s, ay & 1);
    }
    return fy * AA_TREE_SIDE + fx;
}

/* Which of the four children of node `code` (0 .. 3: x | y << 1 within the node) holds
 * its sample, without walking the sample cells (aa_node_sample_cell, which this equals over
 * every node: test_aa_samples_nested_never_retraced). Down from the pixel, whose centre
 * (8, 8) child 3 holds: a child that does not hold its parent's sample takes its fresh cell,
 * which its own child of the same parity (x & 1, y & 1) holds; the fresh cell lies beside
 * the node's centre lines, so it sits in a corner of every deeper node that holds it: the
 * holder's child opposite its owner's parity holds it next, and each one after that the
 * child of its own parity. */
AA_TREE_FN int aa_kept_index(unsigned int code)
{
    int level = aa_node_level(code), x = aa_node_x(code), y = aa_node_y(code);
    int k = 3, owner = 1; /* the pixel: child 3 holds (8, 8), which the pixel owns */
    for (int l = 1; l <= level; l++) {
        int sh = level - l, p = ((y >> sh) & 1) << 1 | ((x >> sh) & 1);
        int held = p == k; /* this ancestor holds its parent's sample */
        k = held && owner ? p ^ 3 : p;
        owner = !held;
    }
    return k;
}

/* The sample cell of a child that does not hold its parent's sample (aa_new_child): its
 * fresh cell, the central cell farthest from the parent's centre (aa_node_sample_cell
 * without the walk). */
AA_TREE_FN int aa_new_child_cell(unsigned int child)
{
    int s = AA_TREE_SIDE >> aa_node_level(child), x = aa_node_x(child), y = aa_node_y(child);
    return aa_fresh_cell(y * s, s, y & 1) * AA_TREE_SIDE + aa_fresh_cell(x * s, s, x & 1);
}

/* Child c (0 .. 3: x | y << 1 within the node) of node `code`. */
AA_TREE_FN unsigned int aa_child(unsigned int code, int c)
{
    return aa_node_code(aa_node_level(code) + 1, 2 * aa_node_x(code) + (c & 1),
                        2 * aa_node_y(code) + (c >> 1));
}

/* The child of node `code` that holds its sample and keeps its value when it splits. */
AA_TREE_FN unsigned int aa_kept_child(unsigned int code)
{
    return aa_child(code, aa_kept_index(code));
}

/* Child j (0, 1, 2) of the three children of node `code` that do not hold its sample: the
 * children that need new samples when the node splits. */
AA_TREE_FN unsigned int aa_new_child(unsigned int code, int j)
{
    int keep = aa_kept_index(code);
    return aa_child(code, j < keep ? j : j + 1);
}

#endif
