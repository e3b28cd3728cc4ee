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

/* Child j (0, 1, 2) of the three children of node `code` that do not hold its sample: the
 * children that need new samples when the node splits. */
AA_TREE_FN unsigned int aa_new_child(unsigned int code, int j)
{
    int level = aa_node_level(code), x = aa_node_x(code), y = aa_node_y(code);
    int cell = aa_node_sample_cell(level, x, y), s = AA_TREE_SIDE >> (level + 1);
    int keep = ((cell / AA_TREE_SIDE / s) & 1) * 2 + ((cell % AA_TREE_SIDE / s) & 1);
    int c = j < keep ? j : j + 1;
    return aa_node_code(level + 1, 2 * x + (c & 1), 2 * y + (c >> 1));
}

#endif
