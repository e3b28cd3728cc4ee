/* grid.c — builds the two-level grid: padded bounds, resolution, exact triangle/cell overlap
 * (separating axes in double), the top level's compact layout in two passes (count, then
 * fill), and the sub-grids of its crowded cells in the same two passes. */
#include "grid.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "diag.h"

/* An axis thinner than this fraction of the largest extent is flat: `auto` gives it one cell,
 * as cube-ish cells could not split it without the other axes exceeding GRID_MAX_AXIS.
 * grid_build widens a flat axis to 3e-4 of the largest extent, padding included. */
#define GRID_FLAT_FRACTION (1.0 / GRID_MAX_AXIS)

/* One triangle prepared for many box tests with the same half-extents: each separating
 * axis with the interval the vertices project onto and the box's projected radius. */
typedef struct TriSat {
    double axis[13][3];
    double pmin[13], pmax[13];
    double rad[13];
    int naxes;
} TriSat;

/* What the build shares between its two passes. */
typedef struct GridCtx {
    double lo[3];   /* grid origin */
    double cs[3];   /* cell size */
    double half[3]; /* cell half-extent, enlarged for the conservative overlap test */
    double reach;   /* the enlargement beyond half a cell, used to find candidate cells */
} GridCtx;

static void grid_error(char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void grid_error(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || errlen == 0) return;
    va_list ap;
    va_start(ap, fmt);
    diag_vformat(err, errlen, fmt, ap);
    va_end(ap);
}

/* min and max without libm calls (no NaNs reach them). */
static inline double dmin(double a, double b)
{
    return a < b ? a : b;
}
static inline double dmax(double a, double b)
{
    return a > b ? a : b;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* Adds axis a (skipped when zero) with the triangle's projection interval and the radius of
 * a box with half-extents h. */
static void sat_add_axis(TriSat *s, const double a[3], const double t[3][3], const double h[3])
{
    if (a[0] == 0.0 && a[1] == 0.0 && a[2] == 0.0) return;
    int k = s->naxes++;
    double lo = INFINITY, hi = -INFINITY;
    for (int v = 0; v < 3; v++) {
        double p = a[0] * t[v][0] + a[1] * t[v][1] + a[2] * t[v][2];
        lo = dmin(lo, p);
        hi = dmax(hi, p);
    }
    memcpy(s->axis[k], a, sizeof s->axis[k]);
    s->pmin[k] = lo;
    s->pmax[k] = hi;
    s->rad[k] = h[0] * fabs(a[0]) + h[1] * fabs(a[1]) + h[2] * fabs(a[2]);
}

/* Prepares the 13 separating axes of triangle t against boxes of half-extents h: the
 * triangle normal first (it rejects most cells of a bounding box), the nine edge/box-axis
 * cross products, then the box normals. Zero axes (degenerate triangles) never separate and
 * are dropped, which keeps the test exact for segments and points. */
static void sat_init(TriSat *s, const double t[3][3], const double h[3])
{
    double e[3][3], a[3];
    s->naxes = 0;
    for (int i = 0; i < 3; i++)
        for (int c = 0; c < 3; c++) e[i][c] = t[(i + 1) % 3][c] - t[i][c];
    a[0] = e[0][1] * e[1][2] - e[0][2] * e[1][1];
    a[1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
    a[2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
    sat_add_axis(s, a, t, h);
    for (int i = 0; i < 3; i++) /* unit axis i cross edge j */
        for (int j = 0; j < 3; j++) {
            int p = (i + 1) % 3, q = (i + 2) % 3;
            a[i] = 0.0;
            a[p] = -e[j][q];
            a[q] = e[j][p];
            sat_add_axis(s, a, t, h);
        }
    for (int i = 0; i < 3; i++) {
        a[0] = a[1] = a[2] = 0.0;
        a[i] = 1.0;
        sat_add_axis(s, a, t, h);
    }
}

/* Returns 1 when no prepared axis separates the triangle from the box centred at c. */
static int sat_overlap(const TriSat *s, const double c[3])
{
    for (int k = 0; k < s->naxes; k++) {
        const double *a = s->axis[k];
        double d = a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
        if (s->pmin[k] - d > s->rad[k] || s->pmax[k] - d < -s->rad[k]) return 0;
    }
    return 1;
}

int grid_tri_box_overlap(const float centre[3], const float half[3], const float tri[3][3])
{
    double t[3][3], c[3], h[3];
    for (int i = 0; i < 3; i++) {
        c[i] = centre[i];
        h[i] = half[i];
        for (int j = 0; j < 3; j++) t[i][j] = tri[i][j];
    }
    TriSat s;
    sat_init(&s, t, h);
    return sat_overlap(&s, c);
}

void grid_auto_resolution(const float lo[3], const float hi[3], uint32_t ntris, float density,
                          int n[3])
{
    double ext[3], target, maxext = 0.0, dn[3] = {1.0, 1.0, 1.0};
    int active[3];
    if (!(density > 0.0f) || !isfinite(density)) density = GRID_DEFAULT_DENSITY;
    target = (double)density * (double)ntris;
    if (target < 1.0) target = 1.0;
    if (target > (double)GRID_MAX_CELLS) target = (double)GRID_MAX_CELLS;
    for (int i = 0; i < 3; i++) {
        ext[i] = (double)hi[i] - (double)lo[i];
        if (!isfinite(ext[i]) || !(ext[i] > 0.0)) ext[i] = 0.0;
        maxext = fmax(maxext, ext[i]);
        n[i] = 1;
    }
    for (int i = 0; i < 3; i++) active[i] = ext[i] > GRID_FLAT_FRACTION * maxext;
    /* Cube cells of side s share the target among the active axes; an axis that would get
     * fewer than 1 or more than GRID_MAX_AXIS cells is fixed there and leaves the rest of the
     * target to the others (this only grows s, so fixed axes stay fixed). */
    for (int round = 0; round < 4; round++) {
        double vol = 1.0, rest = target;
        int k = 0, changed = 0;
        for (int i = 0; i < 3; i++) {
            if (active[i]) {
                vol *= ext[i];
                k++;
            } else {
                rest /= dn[i];
            }
        }
        if (k == 0) break;
        if (rest < 1.0) rest = 1.0;
        double s = pow(vol / rest, 1.0 / k);
        for (int i = 0; i < 3; i++) {
            if (!active[i]) continue;
            dn[i] = ext[i] / s;
            if (dn[i] < 1.0 || dn[i] > GRID_MAX_AXIS) {
                dn[i] = dn[i] < 1.0 ? 1.0 : GRID_MAX_AXIS;
                active[i] = 0;
                changed = 1;
            }
        }
        if (!changed) break;
    }
    for (int i = 0; i < 3; i++) {
        double r = floor(dn[i] + 0.5);
        n[i] = r < 1.0 ? 1 : r > GRID_MAX_AXIS ? GRID_MAX_AXIS : (int)r;
    }
    while ((uint64_t)n[0] * (uint64_t)n[1] * (uint64_t)n[2] > GRID_MAX_CELLS) {
        int big = 0;
        for (int i = 1; i < 3; i++)
            if (n[i] > n[big]) big = i;
        n[big]--;
    }
}

/* Sets g->lo/hi from the triangles' bounds blo/bhi: padded by 1e-4 of the largest extent on
 * every side, an axis thinner than 1e-4 of it widened to that, rounded outwards to float.
 * Returns the reference length (largest extent, or a stand-in for a point-like scene). */
static double grid_set_bounds(Grid *g, const double blo[3], const double bhi[3])
{
    double ref = 0.0, maxabs = 0.0;
    for (int i = 0; i < 3; i++) {
        ref = fmax(ref, bhi[i] - blo[i]);
        maxabs = fmax(maxabs, fmax(fabs(blo[i]), fabs(bhi[i])));
    }
    if (!(ref > 1e-6 * maxabs)) ref = maxabs > 0.0 ? 1e-3 * maxabs : 1.0;
    double thick = 1e-4 * ref, pad = 1e-4 * ref;
    for (int i = 0; i < 3; i++) {
        double a = blo[i], b = bhi[i];
        if (b - a < thick) {
            double mid = 0.5 * (a + b);
            a = mid - 0.5 * thick;
            b = mid + 0.5 * thick;
        }
        g->lo[i] = nextafterf((float)(a - pad), -INFINITY);
        g->hi[i] = nextafterf((float)(b + pad), INFINITY);
    }
    return ref;
}

/* Visits the cells of a grid of n[] cells (x: its origin, cell size and enlargement) that
 * triangle t overlaps: counts them into cnt (out == NULL), or writes t at cnt[cell]++ into
 * out. Adds the number of cells to *total. */
static void grid_visit(const int n[3], const GridCtx *x, const double t[3][3], uint32_t ti,
                       uint32_t *cnt, uint32_t *out, uint64_t *total)
{
    int r0[3], r1[3];
    for (int i = 0; i < 3; i++) {
        double a = dmin(t[0][i], dmin(t[1][i], t[2][i]));
        double b = dmax(t[0][i], dmax(t[1][i], t[2][i]));
        double f0 = floor((a - x->lo[i] - 2.0 * x->reach) / x->cs[i]);
        double f1 = floor((b - x->lo[i] + 2.0 * x->reach) / x->cs[i]);
        r0[i] = f0 < 0.0 ? 0 : f0 > n[i] - 1 ? n[i] - 1 : (int)f0;
        r1[i] = f1 < 0.0 ? 0 : f1 > n[i] - 1 ? n[i] - 1 : (int)f1;
    }
    /* A bounding box inside one cell needs no test: the triangle lies in it. */
    int single = r0[0] == r1[0] && r0[1] == r1[1] && r0[2] == r1[2];
    TriSat s;
    if (!single) sat_init(&s, t, x->half);
    for (int z = r0[2]; z <= r1[2]; z++) {
        double c[3];
        c[2] = x->lo[2] + (z + 0.5) * x->cs[2];
        for (int y = r0[1]; y <= r1[1]; y++) {
            c[1] = x->lo[1] + (y + 0.5) * x->cs[1];
            uint32_t row = (uint32_t)n[0] * ((uint32_t)y + (uint32_t)n[1] * (uint32_t)z);
            for (int xi = r0[0]; xi <= r1[0]; xi++) {
                c[0] = x->lo[0] + (xi + 0.5) * x->cs[0];
                if (!single && !sat_overlap(&s, c)) continue;
                uint32_t cell = row + (uint32_t)xi;
                if (out)
                    out[cnt[cell]++] = ti;
                else
                    cnt[cell]++;
                (*total)++;
            }
        }
    }
}

static void grid_triangle(const Mesh *m, uint32_t t, double tri[3][3])
{
    for (int k = 0; k < 3; k++) {
        vec3 p = m->verts[m->tris[3 * (size_t)t + k]];
        tri[k][0] = p.x;
        tri[k][1] = p.y;
        tri[k][2] = p.z;
    }
}

/* Sets g->ncells, g->cell and x for g->n over g->lo..hi; ref is the scene's reference length. */
static void grid_ctx_init(Grid *g, double ref, GridCtx *x)
{
    double maxabs = 0.0;
    g->ncells = (uint32_t)g->n[0] * (uint32_t)g->n[1] * (uint32_t)g->n[2];
    for (int i = 0; i < 3; i++) {
        maxabs = fmax(maxabs, fmax(fabs((double)g->lo[i]), fabs((double)g->hi[i])));
        x->lo[i] = g->lo[i];
        x->cs[i] = ((double)g->hi[i] - (double)g->lo[i]) / g->n[i];
        g->cell[i] = (float)x->cs[i];
    }
    /* Conservative cells: a hair of the scene size and of float resolution at its
     * coordinates, plus 1e-5 of the cell, so faces on a cell boundary list on both sides. */
    x->reach = 1e-6 * ref + 2.0 * FLT_EPSILON * maxabs;
    g->reach = x->reach;
    for (int i = 0; i < 3; i++) x->half[i] = 0.5 * x->cs[i] + 1e-5 * x->cs[i] + x->reach;
    x->reach += 1e-5 * fmax(x->cs[0], fmax(x->cs[1], x->cs[2]));
}

/* Pass 1: adds each cell's number of triangles to cnt (ncells entries, zeroed by the caller).
 * Returns the number of references; sets *nonempty to the cells with at least one. */
static uint64_t grid_count(const Grid *g, const GridCtx *x, const Mesh *m, uint32_t *cnt,
                           uint32_t *nonempty)
{
    uint64_t total = 0;
    uint32_t ne = 0;
    double tri[3][3];
    for (uint32_t t = 0; t < m->ntris; t++) {
        grid_triangle(m, t, tri);
        grid_visit(g->n, x, tri, t, cnt, NULL, &total);
    }
    for (uint32_t c = 0; c < g->ncells; c++) ne += cnt[c] != 0;
    *nonempty = ne;
    return total;
}

/* Decides whether `auto` refines a grid of `cells` cells whose non-empty cells hold `mean`
 * triangles on average; prev_cells and prev_mean describe the previous round (0 in the
 * first). Returns the number of cells to aim for next, or 0 to keep this grid. The mean is
 * modelled as falling with the per-axis scale s as s^-p, and the step aims a little below the
 * target so that one step usually suffices. p is 1.25 at first (measured between densities 3
 * and 48 on the quickstart, spheres36 and glass_bombed_sphere: 1.1 to 1.6; 2 would hold for
 * triangles much smaller than the cells), then as measured between the last two rounds; a
 * round that lowered the mean by little (p < 0.5: the cells are already smaller than the
 * triangles, or the crowding is one spot no cell size splits) ends the refinement. */
static double grid_auto_next(double cells, double mean, double prev_cells, double prev_mean,
                             double target, double cap)
{
    double p = 1.25;
    if (!(mean > target) || cells >= cap) return 0.0;
    if (prev_cells > 0.0) {
        double s = cbrt(cells / prev_cells);
        p = s > 1.0 ? log(prev_mean / mean) / log(s) : 0.0;
        if (!(p >= 0.5)) return 0.0;
        p = fmin(p, 3.0);
    }
    double s = pow(mean / (0.9 * target), 1.0 / p);
    s = fmin(fmax(s, 1.1), 2.0); /* 1.33 to 8 times the cells */
    double want = fmin(cells * s * s * s, cap);
    return want >= 1.2 * cells ? want : 0.0;
}

int grid_build(Grid *g, const Mesh *m, const int res[3], float density, char *err, size_t errlen)
{
    return grid_build_tuned(g, m, res, density, GRID_AUTO_TARGET, GRID_AUTO_MAX_CELLS, err, errlen);
}

/* The scene's bounds from every vertex (checked: in range, finite), and the grid's box
 * around them. Returns the reference magnitude for the overlap tests, or -1 with a message
 * in err. */
static double grid_bounds(Grid *g, const Mesh *m, char *err, size_t errlen)
{
    double blo[3] = {INFINITY, INFINITY, INFINITY}, bhi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t t = 0; t < m->ntris; t++) {
        for (int k = 0; k < 3; k++) {
            uint32_t vi = m->tris[3 * (size_t)t + k];
            if (vi >= m->nverts) {
                grid_error(err, errlen, "grid: triangle %u uses vertex %u, but there are %u", t, vi,
                           m->nverts);
                return -1;
            }
            vec3 p = m->verts[vi];
            if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z)) {
                grid_error(err, errlen, "grid: triangle %u has a non-finite vertex (%g, %g, %g)", t,
                           (double)p.x, (double)p.y, (double)p.z);
                return -1;
            }
            double q[3] = {p.x, p.y, p.z};
            for (int i = 0; i < 3; i++) {
                blo[i] = fmin(blo[i], q[i]);
                bhi[i] = fmax(bhi[i], q[i]);
            }
        }
    }
    if (m->ntris == 0)
        for (int i = 0; i < 3; i++) {
            blo[i] = -0.5;
            bhi[i] = 0.5;
        }
    double ref = grid_set_bounds(g, blo, bhi);
    for (int i = 0; i < 3; i++)
        if (!isfinite(g->lo[i]) || !isfinite(g->hi[i])) {
            grid_error(err, errlen, "grid: scene bounds [%g, %g] on axis %d overflow a float",
                       blo[i], bhi[i], i);
            return -1;
        }
    return ref;
}

/* The first resolution: `auto` from the density, or the one given (checked against the
 * cell limit). Returns 0, or -1 with a message in err. */
static int grid_first_resolution(Grid *g, const int res[3], uint32_t ntris, float density,
                                 char *err, size_t errlen)
{
    if (res == NULL || res[0] <= 0 || res[1] <= 0 || res[2] <= 0) {
        if (!(density > 0.0f) || !isfinite(density)) density = GRID_DEFAULT_DENSITY;
        grid_auto_resolution(g->lo, g->hi, ntris, density, g->n);
        return 0;
    }
    uint64_t cells = 1;
    for (int i = 0; i < 3 && cells <= GRID_MAX_CELLS; i++) cells *= (uint64_t)res[i];
    if (cells > GRID_MAX_CELLS) {
        grid_error(err, errlen, "resolution %dx%dx%d gives %.0f cells, more than the limit %u",
                   res[0], res[1], res[2], (double)res[0] * res[1] * res[2], GRID_MAX_CELLS);
        return -1;
    }
    for (int i = 0; i < 3; i++) g->n[i] = res[i];
    return 0;
}

/* Pass 1, once per resolution tried: counts each cell's triangles into cell_start[cell];
 * with `auto` (use_auto) it keeps raising the resolution while the non-empty cells are
 * crowded. Leaves the context of the final resolution in x, the total of references in
 * *total and the non-empty cells in *nonempty. Returns 0, or -1 (out of memory). */
static int grid_count_pass(Grid *g, const Mesh *m, double ref, int use_auto, float target,
                           uint32_t max_cells, GridCtx *x, uint64_t *total, uint32_t *nonempty,
                           char *err, size_t errlen)
{
    uint32_t ntris = m->ntris;
    double prev_cells = 0.0, prev_mean = 0.0;
    double cap = fmin((double)max_cells, (double)GRID_MAX_CELLS);
    for (;;) {
        grid_ctx_init(g, ref, x);
        g->cell_start = calloc((size_t)g->ncells + 1, sizeof *g->cell_start);
        if (!g->cell_start) {
            grid_error(err, errlen, "grid: out of memory for %u cells", g->ncells);
            return -1;
        }
        *total = grid_count(g, x, m, g->cell_start, nonempty);
        if (!use_auto || !(target > 0.0f) || g->refinements >= GRID_AUTO_MAX_ROUNDS ||
            *nonempty == 0)
            return 0;
        double mean = (double)*total / *nonempty;
        double want = grid_auto_next(g->ncells, mean, prev_cells, prev_mean, target, cap);
        if (want == 0.0) return 0;
        int n[3];
        grid_auto_resolution(g->lo, g->hi, ntris, (float)(want / fmax(ntris, 1.0)), n);
        while ((double)n[0] * n[1] * n[2] > cap) { /* rounding may overshoot the cap */
            int big = 0;
            for (int i = 1; i < 3; i++)
                if (n[i] > n[big]) big = i;
            n[big]--;
        }
        if ((double)n[0] * n[1] * n[2] <= g->ncells) return 0;
        prev_cells = g->ncells;
        prev_mean = mean;
        memcpy(g->n, n, sizeof n);
        free(g->cell_start);
        g->cell_start = NULL;
        g->refinements++;
    }
}

/* Pass 2: counts become start offsets; visiting every triangle advances each to its cell's
 * end; shifting by one cell then gives the starts again, with cell_start[ncells] = nrefs.
 * Returns the most triangles in one cell. */
static uint32_t grid_fill_pass(Grid *g, const Mesh *m, const GridCtx *x)
{
    uint32_t sum = 0, maxc = 0;
    for (uint32_t c = 0; c < g->ncells; c++) {
        uint32_t k = g->cell_start[c];
        maxc = k > maxc ? k : maxc;
        g->cell_start[c] = sum;
        sum += k;
    }
    g->cell_start[g->ncells] = sum;
    uint64_t total = 0;
    double tri[3][3];
    for (uint32_t t = 0; t < m->ntris; t++) {
        grid_triangle(m, t, tri);
        grid_visit(g->n, x, tri, t, g->cell_start, g->cell_tris, &total);
    }
    memmove(g->cell_start + 1, g->cell_start, (size_t)g->ncells * sizeof *g->cell_start);
    g->cell_start[0] = 0;
    return maxc;
}

int grid_build_tuned(Grid *g, const Mesh *m, const int res[3], float density, float target,
                     uint32_t max_cells, char *err, size_t errlen)
{
    double t0 = now_ms();
    memset(g, 0, sizeof *g);
    double ref = grid_bounds(g, m, err, errlen);
    if (ref < 0 || grid_first_resolution(g, res, m->ntris, density, err, errlen)) return -1;
    int use_auto = res == NULL || res[0] <= 0 || res[1] <= 0 || res[2] <= 0;
    GridCtx x;
    uint64_t total;
    uint32_t nonempty;
    if (grid_count_pass(g, m, ref, use_auto, target, max_cells, &x, &total, &nonempty, err,
                        errlen)) {
        grid_free(g);
        return -1;
    }
    if (total > UINT32_MAX) {
        grid_error(err, errlen,
                   "grid: %llu triangle references in %u cells, more than 2^32-1; use a "
                   "coarser resolution",
                   (unsigned long long)total, g->ncells);
        grid_free(g);
        return -1;
    }
    g->nrefs = (uint32_t)total;
    g->cell_tris = malloc((total > 0 ? (size_t)total : 1) * sizeof *g->cell_tris);
    if (!g->cell_tris) {
        grid_error(err, errlen, "grid: out of memory for %llu triangle references",
                   (unsigned long long)total);
        grid_free(g);
        return -1;
    }
    uint32_t maxc = grid_fill_pass(g, m, &x);
    g->tris_per_cell_mean = (float)((double)g->nrefs / g->ncells);
    g->tris_per_cell_max = maxc;
    g->nonempty = nonempty;
    g->tris_per_nonempty_mean = nonempty ? (float)((double)g->nrefs / nonempty) : 0.0f;
    g->empty_fraction = (float)((double)(g->ncells - nonempty) / g->ncells);
    g->build_ms = now_ms() - t0;
    return 0;
}

/* The sub-grid resolution n of a top cell holding k triangles (see grid_build_leaves). */
static void leaves_resolution(const Grid *g, uint32_t k, const int sub_res[3], float density,
                              int n[3])
{
    n[0] = n[1] = n[2] = 1;
    if (sub_res) {
        if (k >= 2) memcpy(n, sub_res, 3 * sizeof *n);
        return;
    }
    if (k < GRID_SUB_MIN_TRIS) return;
    float lo[3] = {0.0f, 0.0f, 0.0f};
    grid_auto_resolution(lo, g->cell, k, density, n);
    for (int i = 0; i < 3; i++) n[i] = n[i] > GRID_SUB_MAX_AXIS ? GRID_SUB_MAX_AXIS : n[i];
}

/* The build context of top cell c's sub-grid of n[] cells: its box and sub-cell size from
 * the top level's (x), each sub-cell enlarged by 1e-5 of itself plus three times the top
 * level's rounding reach (the kernels compute a sub-cell's bounds from the top cell's in
 * float, a few more roundings than the top level's own). */
static void leaves_ctx(const Grid *g, const GridCtx *x, uint32_t c, const int n[3], GridCtx *sx)
{
    uint32_t idx[3] = {c % (uint32_t)g->n[0], c / (uint32_t)g->n[0] % (uint32_t)g->n[1],
                       c / ((uint32_t)g->n[0] * (uint32_t)g->n[1])};
    double big = 0.0;
    for (int i = 0; i < 3; i++) {
        sx->lo[i] = x->lo[i] + idx[i] * x->cs[i];
        sx->cs[i] = x->cs[i] / n[i];
        big = fmax(big, sx->cs[i]);
    }
    for (int i = 0; i < 3; i++) sx->half[i] = 0.5 * sx->cs[i] + 1e-5 * sx->cs[i] + 3.0 * g->reach;
    sx->reach = 3.0 * g->reach + 1e-5 * big;
}

/* One pass over the top cells: each cell's triangles into its leaves, counted into cnt
 * (out == NULL) or written at out[cnt[leaf]++]. Returns the number of references. */
static uint64_t leaves_pass(const Grid *g, const Mesh *m, uint32_t *cnt, uint32_t *out)
{
    GridCtx x;
    uint64_t total = 0;
    double tri[3][3];
    for (int i = 0; i < 3; i++) {
        x.lo[i] = g->lo[i];
        x.cs[i] = ((double)g->hi[i] - (double)g->lo[i]) / g->n[i];
    }
    for (uint32_t c = 0; c < g->ncells; c++) {
        uint32_t first = g->cells[2 * c], b = g->cell_start[c], e = g->cell_start[c + 1];
        int n[3];
        grid_sub_unpack(g->cells[2 * c + 1], n);
        if (n[0] * n[1] * n[2] == 1) {
            for (uint32_t k = b; k < e; k++)
                if (out)
                    out[cnt[first]++] = g->cell_tris[k];
                else
                    cnt[first]++;
            total += e - b;
            continue;
        }
        GridCtx sx;
        leaves_ctx(g, &x, c, n, &sx);
        for (uint32_t k = b; k < e; k++) {
            grid_triangle(m, g->cell_tris[k], tri);
            grid_visit(n, &sx, tri, g->cell_tris[k], cnt + first, out, &total);
        }
    }
    return total;
}

static void grid_leaves_free(Grid *g)
{
    free(g->cells);
    free(g->leaf_start);
    free(g->leaf_tris);
    g->cells = g->leaf_start = g->leaf_tris = NULL;
    g->nleaves = g->nleaf_refs = g->subgrids = g->tris_per_leaf_max = 0;
}

/* Every top cell's sub-grid resolution and first leaf into g->cells. Returns the number
 * of leaves. */
static uint64_t leaves_layout(Grid *g, const int sub_res[3], float density)
{
    uint64_t nleaves = 0;
    g->subgrids = 0;
    for (uint32_t c = 0; c < g->ncells; c++) {
        int n[3];
        leaves_resolution(g, g->cell_start[c + 1] - g->cell_start[c], sub_res, density, n);
        g->cells[2 * c] = (uint32_t)(nleaves < UINT32_MAX ? nleaves : UINT32_MAX);
        g->cells[2 * c + 1] = grid_sub_pack(n);
        nleaves += (uint64_t)n[0] * (uint64_t)n[1] * (uint64_t)n[2];
        g->subgrids += n[0] * n[1] * n[2] > 1;
    }
    return nleaves;
}

int grid_build_leaves(Grid *g, const Mesh *m, const int sub_res[3], float density, char *err,
                      size_t errlen)
{
    double t0 = now_ms();
    grid_leaves_free(g);
    if (sub_res && (sub_res[0] <= 0 || sub_res[1] <= 0 || sub_res[2] <= 0)) sub_res = NULL;
    if (!(density > 0.0f) || !isfinite(density)) density = GRID_SUB_DEFAULT_DENSITY;
    g->cells = malloc(2 * (size_t)g->ncells * sizeof *g->cells);
    if (!g->cells) goto oom;
    uint64_t nleaves = leaves_layout(g, sub_res, density);
    if (nleaves > GRID_MAX_LEAVES) {
        grid_error(err, errlen, "grid: the sub-grids have %llu cells, more than the limit %u",
                   (unsigned long long)nleaves, GRID_MAX_LEAVES);
        grid_leaves_free(g);
        return -1;
    }
    g->nleaves = (uint32_t)nleaves;
    g->leaf_start = calloc((size_t)nleaves + 1, sizeof *g->leaf_start);
    if (!g->leaf_start) goto oom;
    uint64_t total = leaves_pass(g, m, g->leaf_start, NULL);
    if (total > UINT32_MAX) {
        grid_error(err, errlen,
                   "grid: %llu triangle references in the sub-grids, more than 2^32-1; use "
                   "coarser sub-grids",
                   (unsigned long long)total);
        grid_leaves_free(g);
        return -1;
    }
    g->leaf_tris = malloc((total > 0 ? (size_t)total : 1) * sizeof *g->leaf_tris);
    if (!g->leaf_tris) goto oom;
    uint32_t sum = 0;
    for (uint32_t l = 0; l < g->nleaves; l++) {
        uint32_t k = g->leaf_start[l];
        g->tris_per_leaf_max = k > g->tris_per_leaf_max ? k : g->tris_per_leaf_max;
        g->leaf_start[l] = sum;
        sum += k;
    }
    g->leaf_start[g->nleaves] = sum;
    g->nleaf_refs = sum;
    leaves_pass(g, m, g->leaf_start, g->leaf_tris);
    memmove(g->leaf_start + 1, g->leaf_start, (size_t)g->nleaves * sizeof *g->leaf_start);
    g->leaf_start[0] = 0;
    g->leaves_ms = now_ms() - t0;
    return 0;
oom:
    grid_error(err, errlen, "grid: out of memory for the sub-grids of %u cells", g->ncells);
    grid_leaves_free(g);
    return -1;
}

int grid_build_levels(Grid *g, const Mesh *m, const int res[3], float density, const int sub[3],
                      float sub_density, char *err, size_t errlen)
{
    int one_level = sub && sub[0] == 1 && sub[1] == 1 && sub[2] == 1;
    int rc;
    if (one_level)
        rc = grid_build(g, m, res, density, err, errlen);
    else
        rc = grid_build_tuned(g, m, res, density > 0.0f ? density : GRID_TOP_DEFAULT_DENSITY, 0.0f,
                              GRID_AUTO_MAX_CELLS, err, errlen);
    if (rc) return rc;
    if (grid_build_leaves(g, m, sub, sub_density, err, errlen)) {
        grid_free(g);
        return -1;
    }
    g->build_ms += g->leaves_ms;
    return 0;
}

void grid_free(Grid *g)
{
    free(g->cell_start);
    free(g->cell_tris);
    grid_leaves_free(g);
    memset(g, 0, sizeof *g);
}

size_t grid_leaf_quads(const Grid *g, const uint32_t *tri_tag, uint32_t kind_bit)
{
    size_t n = 0;
    for (uint32_t l = 0; l < g->nleaves; l++) {
        size_t with = 0, all = (size_t)g->leaf_start[l + 1] - g->leaf_start[l];
        for (uint32_t i = g->leaf_start[l]; i < g->leaf_start[l + 1]; i++)
            with += (tri_tag[g->leaf_tris[i]] & kind_bit) != 0u;
        n += (with + 3) / 4 + (all - with + 3) / 4;
    }
    return n;
}
