/* grid.h — the uniform grid over a scene's triangles: resolution choice, the build with
 * exact triangle/box overlap, and its compact layout (cell offsets + triangle index list). */
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
} Grid;

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

/* Frees the arrays and zeroes the grid; safe on a zeroed or failed grid. */
void grid_free(Grid *g);

/* Exact triangle / axis-aligned box overlap (separating axis test, Akenine-Möller 2001), in
 * double precision; touching counts as overlap. Works for degenerate triangles too. Returns
 * 1 when the triangle overlaps the box centre +- half, else 0. */
int grid_tri_box_overlap(const float centre[3], const float half[3], const float tri[3][3]);

#endif
