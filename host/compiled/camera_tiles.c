/* camera_tiles.c — each image tile's triangles, nearest first (camera_tiles.h). */
#include "camera_tiles.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A camera ray's tile comes from its direction in float (camera_trace_closest): its pixel
 * coordinates there are off by a few ulps of the image size, so a triangle's tiles are
 * those its projection meets widened by this many pixels (and a relative part for large
 * images). */
#define CAM_MARGIN_PX  0.125
#define CAM_MARGIN_REL 1e-5

typedef struct CamRef {
    float near;
    uint32_t tri;
} CamRef;

typedef struct CamView {
    double eye[3], fwd[3], right[3], up[3]; /* right and up divided by their squared lengths */
    int width, height, nx, ny;
    double margin;
} CamView;

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The tiles whose pixels the projection of triangle t can meet, as box[0..3] = first and
 * last column, first and last row. Returns 0 when no camera ray can hit it (wholly behind
 * the eye, or outside the image). A triangle with corners on both sides of the plane through
 * the eye across the view is not projected: all tiles. */
static int tri_tile_box(const CamView *cv, const VbTriangle *t, int box[4])
{
    const float *v[3] = {t->v0, t->v1, t->v2};
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    int behind = 0;
    for (int k = 0; k < 3; k++) {
        double q[3] = {v[k][0] - cv->eye[0], v[k][1] - cv->eye[1], v[k][2] - cv->eye[2]};
        double a = dot3(q, cv->fwd);
        if (!(a > 0.0)) {
            behind++;
            continue;
        }
        double px = (dot3(q, cv->right) / a + 1.0) * 0.5 * cv->width;
        double py = (1.0 - dot3(q, cv->up) / a) * 0.5 * cv->height;
        x0 = fmin(x0, px);
        x1 = fmax(x1, px);
        y0 = fmin(y0, py);
        y1 = fmax(y1, py);
    }
    if (behind == 3) return 0;
    if (behind > 0) {
        box[0] = box[2] = 0;
        box[1] = cv->nx - 1;
        box[3] = cv->ny - 1;
        return 1;
    }
    double m = cv->margin;
    if (!(x1 + m >= 0.0 && y1 + m >= 0.0 && x0 - m <= cv->width && y0 - m <= cv->height)) return 0;
    double lim[4] = {(x0 - m) / VBCL_CAM_TILE, (x1 + m) / VBCL_CAM_TILE, (y0 - m) / VBCL_CAM_TILE,
                     (y1 + m) / VBCL_CAM_TILE};
    int hi[4] = {cv->nx - 1, cv->nx - 1, cv->ny - 1, cv->ny - 1};
    for (int i = 0; i < 4; i++) {
        double f = floor(lim[i]);
        box[i] = f < 0.0 ? 0 : f > hi[i] ? hi[i] : (int)f;
    }
    return 1;
}

/* The distance from the eye to the bounding box of t, rounded down to a float: no point of
 * t is nearer. */
static float tri_near(const CamView *cv, const VbTriangle *t)
{
    const float *v[3] = {t->v0, t->v1, t->v2};
    double d2 = 0.0;
    for (int a = 0; a < 3; a++) {
        double lo = fmin(v[0][a], fmin(v[1][a], v[2][a]));
        double hi = fmax(v[0][a], fmax(v[1][a], v[2][a]));
        double e = cv->eye[a] < lo ? lo - cv->eye[a] : cv->eye[a] > hi ? cv->eye[a] - hi : 0.0;
        d2 += e * e;
    }
    double d = sqrt(d2);
    float f = (float)d;
    return (double)f > d ? nextafterf(f, 0.0f) : f;
}

static int ref_cmp(const void *pa, const void *pb)
{
    const CamRef *a = pa, *b = pb;
    if (a->near != b->near) return a->near < b->near ? -1 : 1;
    return (a->tri > b->tri) - (a->tri < b->tri);
}

static void cam_view(CamView *cv, const VbCamera *cam, int width, int height)
{
    const float *src[4] = {cam->eye, cam->forward, cam->right, cam->up};
    double *dst[4] = {cv->eye, cv->fwd, cv->right, cv->up};
    for (int i = 0; i < 4; i++)
        for (int a = 0; a < 3; a++) dst[i][a] = src[i][a];
    double r2 = dot3(cv->right, cv->right), u2 = dot3(cv->up, cv->up);
    for (int a = 0; a < 3; a++) {
        cv->right[a] /= r2;
        cv->up[a] /= u2;
    }
    cv->width = width;
    cv->height = height;
    cv->nx = (width + VBCL_CAM_TILE - 1) / VBCL_CAM_TILE;
    cv->ny = (height + VBCL_CAM_TILE - 1) / VBCL_CAM_TILE;
    cv->margin = CAM_MARGIN_PX + CAM_MARGIN_REL * (width > height ? width : height);
}

/* Packs each tile's sorted references (refs[start[t] ..]) four at a time into ct. */
static int pack_quads(CamTiles *ct, const CamRef *refs, const size_t *start, const VbTriangle *tris)
{
    size_t ntiles = (size_t)ct->nx * (size_t)ct->ny, n = 0;
    for (size_t t = 0; t < ntiles; t++) n += (start[t + 1] - start[t] + 3) / 4;
    ct->start = malloc(sizeof *ct->start * (ntiles + 1));
    ct->quads = calloc(n ? n : 1, sizeof *ct->quads);
    ct->near = malloc(sizeof *ct->near * (n ? n : 1));
    if (!ct->start || !ct->quads || !ct->near) return -1;
    size_t k = 0;
    for (size_t t = 0; t < ntiles; t++) {
        ct->start[t] = (uint32_t)k;
        for (size_t i = start[t]; i < start[t + 1]; k++) {
            ct->near[k] = refs[i].near; /* the first is the nearest */
            for (int lane = 0; lane < 4; lane++, i++) {
                ct->quads[k].tri[lane] = i < start[t + 1] ? (int)refs[i].tri : -1;
                if (i >= start[t + 1]) continue;
                const VbTriangle *tr = tris + refs[i].tri;
                const float *v[3] = {tr->v0, tr->v1, tr->v2};
                for (int a = 0; a < 9; a++) ct->quads[k].xyz[a][lane] = v[a / 3][a % 3];
            }
        }
    }
    ct->start[ntiles] = (uint32_t)k;
    ct->nquads = (uint32_t)k;
    return 0;
}

int camtiles_build(CamTiles *ct, const VbCamera *cam, int width, int height, const VbTriangle *tris,
                   uint32_t ntris, size_t max_refs)
{
    memset(ct, 0, sizeof *ct);
    if (ntris == 0 || width <= 0 || height <= 0) return 0;
    CamView cv;
    cam_view(&cv, cam, width, height);
    size_t ntiles = (size_t)cv.nx * (size_t)cv.ny, total = 0;
    int(*box)[4] = malloc(sizeof *box * ntris);
    size_t *start = calloc(ntiles + 1, sizeof *start);
    CamRef *refs = NULL;
    int rc = -1;
    if (!box || !start) goto done;
    for (uint32_t i = 0; i < ntris; i++) {
        if (!tri_tile_box(&cv, tris + i, box[i])) {
            box[i][0] = -1;
            continue;
        }
        total += (size_t)(box[i][1] - box[i][0] + 1) * (size_t)(box[i][3] - box[i][2] + 1);
    }
    rc = 0;
    if (total > max_refs) goto done; /* none: camera rays walk the grid */
    rc = -1;
    refs = malloc(sizeof *refs * (total ? total : 1));
    if (!refs) goto done;
    for (uint32_t i = 0; i < ntris; i++) /* counts, then each tile's first reference */
        for (int y = box[i][2]; box[i][0] >= 0 && y <= box[i][3]; y++)
            for (int x = box[i][0]; x <= box[i][1]; x++) start[(size_t)y * cv.nx + x + 1]++;
    for (size_t t = 0; t < ntiles; t++) start[t + 1] += start[t];
    for (uint32_t i = 0; i < ntris; i++) {
        if (box[i][0] < 0) continue;
        float near = tri_near(&cv, tris + i);
        for (int y = box[i][2]; y <= box[i][3]; y++)
            for (int x = box[i][0]; x <= box[i][1]; x++) {
                size_t t = (size_t)y * cv.nx + x, at = start[t]++;
                refs[at] = (CamRef){near, i};
            }
    }
    for (size_t t = ntiles; t > 0; t--) start[t] = start[t - 1]; /* back to the firsts */
    start[0] = 0;
    for (size_t t = 0; t < ntiles; t++)
        qsort(refs + start[t], start[t + 1] - start[t], sizeof *refs, ref_cmp);
    ct->nx = cv.nx;
    ct->ny = cv.ny;
    ct->refs = total;
    rc = pack_quads(ct, refs, start, tris);
    if (rc) camtiles_free(ct);
done:
    free(box);
    free(start);
    free(refs);
    return rc;
}

void camtiles_free(CamTiles *ct)
{
    free(ct->start);
    free(ct->quads);
    free(ct->near);
    memset(ct, 0, sizeof *ct);
}
