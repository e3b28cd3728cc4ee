/* grid.h — the two-level grid over a scene's triangles: the top level is a uniform grid
 * (resolution choice, exact triangle/box overlap, cell offsets + triangle index list); each
 * crowded top cell then gets its own uniform sub-grid sized by its occupancy (Kalojanov,
 * Stich & Slusallek 2011), the others keep their plain list. */
#ifndef VBCL_GRID_H
#define VBCL_GRID_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"

#define GRID_MAX_AXIS        1024       /* most cells on one axis chosen by `auto` */
#define GRID_MAX_CELLS       (1u << 27) /* most cells in a grid */
#define GRID_DEFAULT_DENSITY 3.0f       /* cells per triangle for `auto`'s first estimate */
#define GRID_AUTO_TARGET     3.5f /* `auto` refines while triangles per non-empty cell exceed this */
#define GRID_AUTO_MAX_CELLS  (1u << 24) /* `auto` refines no further than this many cells */
#define GRID_AUTO_MAX_ROUNDS 4          /* and at most this many times */

/* The second level. A top cell's sub-grid resolution is packed into one word, 10 bits per
 * axis (grid_sub_pack); 1x1x1 means the cell's plain list. */
#define GRID_TOP_DEFAULT_DENSITY 0.125f /* top cells per triangle of a two-level `auto` */
#define GRID_SUB_DEFAULT_DENSITY 2.0f   /* sub-cells per triangle of a crowded top cell */
#define GRID_SUB_MIN_TRIS        8      /* `auto` leaves a top cell with fewer triangles a list */
#define GRID_SUB_MAX_AXIS        64     /* most sub-cells per axis of one top cell */
#define GRID_MAX_LEAVES          (1u << 27) /* most leaves (sub-cells and lists) in all */

typedef struct Grid {
    float lo[3], hi[3];   /* bounds of the grid (scene bounds, padded slightly, never zero-thick) */
    int n[3];             /* cells per axis, each >= 1 */
    float cell[3];        /* cell size per axis = (hi-lo)/n */
    uint32_t ncells;      /* n[0]*n[1]*n[2]; cell index = x + n[0]*(y + n[1]*z) */
    uint32_t *cell_start; /* ncells+1 offsets into cell_tris (prefix sums) */
    uint32_t *cell_tris;  /* triangle indices, cell by cell, ascending within a cell */
    uint32_t nrefs;       /* length of cell_tris */
    /* statistics */
    double build_ms;
    float tris_per_cell_mean; /* nrefs / ncells */
    uint32_t tris_per_cell_max;
    float empty_fraction;         /* cells with no triangle / ncells */
    uint32_t nonempty;            /* cells with at least one triangle */
    float tris_per_nonempty_mean; /* nrefs / nonempty (0 when all cells are empty) */
    int refinements;              /* times `auto` raised the resolution after its estimate */
    double reach;                 /* the build's enlargement of cells beyond float rounding */
    /* The second level (grid_build_leaves): top cell c is a sub-grid whose sub-cells
     * ("leaves") are leaves first .. first + x*y*z - 1, sub-cell (i, j, k) at first +
     * i + x*(j + y*k); a plain list is one leaf. Leaves are numbered in top-cell order, so
     * their lists lie one after the other in leaf_tris. */
    uint32_t *cells;      /* 2 per top cell: first leaf, resolution (grid_sub_pack) */
    uint32_t *leaf_start; /* nleaves+1 offsets into leaf_tris (prefix sums) */
    uint32_t *leaf_tris;  /* triangle indices, leaf by leaf, ascending within a leaf */
    uint32_t nleaves, nleaf_refs;
    uint32_t subgrids; /* top cells with a sub-grid (more than one leaf) */
    uint32_t tris_per_leaf_max;
    double leaves_ms; /* host time of grid_build_leaves */
} Grid;

/* A sub-grid resolution as one word (each axis 1 .. 1023), and back: the kernels' VbGridCell
 * res (kernels/types.h). */
#define GRID_SUB_BITS 10
static inline uint32_t grid_sub_pack(const int n[3])
{
    return (uint32_t)n[0] | (uint32_t)n[1] << GRID_SUB_BITS | (uint32_t)n[2] << 2 * GRID_SUB_BITS;
}
static inline void grid_sub_unpack(uint32_t w, int n[3])
{
    const uint32_t mask = (1u << GRID_SUB_BITS) - 1u;
    n[0] = (int)(w & mask);
    n[1] = (int)(w >> GRID_SUB_BITS & mask);
    n[2] = (int)(w >> 2 * GRID_SUB_BITS & mask);
}

/* Picks a resolution for `auto`: about density*ntris cells (at most GRID_MAX_CELLS), cube-ish
 * cells, per-axis counts proportional to the extents, each in [1, GRID_MAX_AXIS]. An axis
 * thinner than one such cell, or than 1/GRID_MAX_AXIS of the largest one (flat), gets 1 cell
 * and its share goes to the others. density <= 0 (or not finite) means GRID_DEFAULT_DENSITY. */
void grid_auto_resolution(const float lo[3], const float hi[3], uint32_t ntris, float density,
                          int n[3]);

/* Builds the grid over all triangles of m. res: cells per axis, used as given; or NULL (or any
 * res[i] <= 0) for auto: it starts from grid_auto_resolution with `density` cells per
 * triangle, counts, and while the mean number of triangles per non-empty cell exceeds
 * GRID_AUTO_TARGET it raises the resolution (keeping the cells' shape) and counts again, at
 * most GRID_AUTO_MAX_ROUNDS times, never beyond GRID_AUTO_MAX_CELLS cells (nor below the
 * estimate), and stops once a round no longer lowers that mean enough to pay. A triangle is listed
 * in every cell it overlaps (exact test, each cell enlarged by a hair so that triangles on a cell
 * face are listed on both sides). Degenerate triangles (segments, points) are listed in the cells
 * they touch. An empty mesh gives one empty cell over a unit box at the origin. Returns 0, or -1
 * with a message in err (a vertex index out of range or a non-finite vertex, naming the triangle;
 * out of memory; too many cells: more than GRID_MAX_CELLS; more than 2^32-1 references).
 * On failure g holds no memory (grid_free is still safe). */
int grid_build(Grid *g, const Mesh *m, const int res[3], float density, char *err, size_t errlen);

/* grid_build with the refinement of `auto` spelled out: it aims at `target` triangles per
 * non-empty cell (target <= 0: no refinement, the density estimate alone) and stops at
 * max_cells cells (at most GRID_MAX_CELLS; a cap below the estimate refines nothing).
 * grid_build is this with GRID_AUTO_TARGET and GRID_AUTO_MAX_CELLS. */
int grid_build_tuned(Grid *g, const Mesh *m, const int res[3], float density, float target,
                     uint32_t max_cells, char *err, size_t errlen);

/* Builds the second level of a grid that grid_build made over the same mesh m. sub_res NULL
 * (or any sub_res[i] <= 0) is `auto`: a top cell with at least GRID_SUB_MIN_TRIS triangles
 * gets about density * (its triangles) sub-cells of cube-like shape (grid_auto_resolution
 * over the cell's box, at most GRID_SUB_MAX_AXIS per axis; density <= 0 or not finite:
 * GRID_SUB_DEFAULT_DENSITY); a cell whose estimate is one sub-cell keeps its list. A given
 * sub_res (1 .. GRID_SUB_MAX_AXIS per axis) is used in every top cell with two or more
 * triangles; 1,1,1 gives no sub-grids (the single-level grid). A triangle of a top cell is
 * listed in every sub-cell it overlaps, by the same conservative test as the top level.
 * Returns 0, or -1 with a message in err (out of memory; more than GRID_MAX_LEAVES leaves or
 * 2^32-1 references); on failure the second level holds no memory. */
int grid_build_leaves(Grid *g, const Mesh *m, const int sub_res[3], float density, char *err,
                      size_t errlen);

/* The grid a scene renders with: both levels. sub NULL (or any sub[i] <= 0) is auto, as in
 * grid_build_leaves. With sub-grids (sub not 1,1,1), `auto` (res NULL or any res[i] <= 0)
 * is a coarse top level: the density estimate alone (grid_auto_resolution with `density`
 * cells per triangle, GRID_TOP_DEFAULT_DENSITY when density <= 0), the sub-grids taking the
 * crowding; with sub = 1,1,1 (one level) it is grid_build's `auto`, refined by occupancy from
 * `density` (GRID_DEFAULT_DENSITY when <= 0). A given res is used as given. Returns as
 * grid_build; g->build_ms covers both levels. */
int grid_build_levels(Grid *g, const Mesh *m, const int res[3], float density, const int sub[3],
                      float sub_density, char *err, size_t errlen);

/* Frees the arrays and zeroes the grid; safe on a zeroed or failed grid. */
void grid_free(Grid *g);

/* Quads the kernels' leaves take (VbLeafQuad, kernels/types.h): per leaf, its triangles whose
 * tag (tri_tag, the scene's per-triangle tags) has `kind_bit` and those without it, each
 * group four to a quad. */
size_t grid_leaf_quads(const Grid *g, const uint32_t *tri_tag, uint32_t kind_bit);

/* Exact triangle / axis-aligned box overlap (separating axis test, Akenine-Möller 2001), in
 * double precision; touching counts as overlap. Works for degenerate triangles too. Returns
 * 1 when the triangle overlaps the box centre +- half, else 0. */
int grid_tri_box_overlap(const float centre[3], const float half[3], const float tri[3][3]);

#endif
