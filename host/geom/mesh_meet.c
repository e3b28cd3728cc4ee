/* mesh_meet.c — whether the surfaces of separate meshes meet: exact orientation tests in
 * double precision, coplanar triangles included, over a sweep of triangle bounding boxes.
 * Used by texgen (its elements must be disjoint) and by the scene (hosts must not overlap). */
#include <math.h>
#include <stdlib.h>

#include "mesh.h"

typedef struct D3 {
    double x, y, z;
} D3;

static D3 d3(vec3 v)
{
    D3 r = {v.x, v.y, v.z};
    return r;
}

/* Sign of the volume of tetrahedron (a, b, c, d): > 0 when d is above abc (ccw). */
static double orient3(D3 a, D3 b, D3 c, D3 d)
{
    double ax = a.x - d.x, ay = a.y - d.y, az = a.z - d.z;
    double bx = b.x - d.x, by = b.y - d.y, bz = b.z - d.z;
    double cx = c.x - d.x, cy = c.y - d.y, cz = c.z - d.z;
    return ax * (by * cz - bz * cy) + bx * (cy * az - cz * ay) + cx * (ay * bz - az * by);
}

static double orient2(const double *a, const double *b, const double *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* Closed 2D segments ab and cd meet (touching counts). */
static int segs_meet(const double *a, const double *b, const double *c, const double *d)
{
    double o1 = orient2(a, b, c), o2 = orient2(a, b, d), o3 = orient2(c, d, a),
           o4 = orient2(c, d, b);
    if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
        return 1;
    /* collinear touching */
    const double *p[4] = {c, d, a, b}, *s0[4] = {a, a, c, c}, *s1[4] = {b, b, d, d};
    double o[4] = {o1, o2, o3, o4};
    for (int i = 0; i < 4; i++)
        if (o[i] == 0.0 && fmin(s0[i][0], s1[i][0]) <= p[i][0] &&
            p[i][0] <= fmax(s0[i][0], s1[i][0]) && fmin(s0[i][1], s1[i][1]) <= p[i][1] &&
            p[i][1] <= fmax(s0[i][1], s1[i][1]))
            return 1;
    return 0;
}

static int point_in_tri2(const double *p, double t[3][2])
{
    double a = orient2(t[0], t[1], p), b = orient2(t[1], t[2], p), c = orient2(t[2], t[0], p);
    return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}

/* Coplanar triangles: project on the plane of the dominant normal axis and overlap-test. */
static int coplanar_meet(const D3 *p, const D3 *q)
{
    D3 n = {(p[1].y - p[0].y) * (p[2].z - p[0].z) - (p[1].z - p[0].z) * (p[2].y - p[0].y),
            (p[1].z - p[0].z) * (p[2].x - p[0].x) - (p[1].x - p[0].x) * (p[2].z - p[0].z),
            (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x)};
    int ax =
        fabs(n.x) > fabs(n.y) ? (fabs(n.x) > fabs(n.z) ? 0 : 2) : (fabs(n.y) > fabs(n.z) ? 1 : 2);
    double a[3][2], b[3][2];
    for (int i = 0; i < 3; i++) {
        double pv[3] = {p[i].x, p[i].y, p[i].z}, qv[3] = {q[i].x, q[i].y, q[i].z};
        a[i][0] = pv[(ax + 1) % 3];
        a[i][1] = pv[(ax + 2) % 3];
        b[i][0] = qv[(ax + 1) % 3];
        b[i][1] = qv[(ax + 2) % 3];
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (segs_meet(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3])) return 1;
    return point_in_tri2(a[0], b) || point_in_tri2(b[0], a);
}

/* Segment pq against triangle t (not coplanar): meets, touching included. */
static int seg_meets_tri(D3 p, D3 q, const D3 *t)
{
    double sp = orient3(t[0], t[1], t[2], p), sq = orient3(t[0], t[1], t[2], q);
    if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0) || (sp == 0 && sq == 0)) return 0;
    double a = orient3(p, q, t[0], t[1]), b = orient3(p, q, t[1], t[2]),
           c = orient3(p, q, t[2], t[0]);
    return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}

static int tris_meet(const D3 *p, const D3 *q)
{
    double s0 = orient3(p[0], p[1], p[2], q[0]), s1 = orient3(p[0], p[1], p[2], q[1]),
           s2 = orient3(p[0], p[1], p[2], q[2]);
    if ((s0 > 0 && s1 > 0 && s2 > 0) || (s0 < 0 && s1 < 0 && s2 < 0)) return 0;
    if (s0 == 0 && s1 == 0 && s2 == 0) return coplanar_meet(p, q);
    for (int i = 0; i < 3; i++) {
        if (seg_meets_tri(p[i], p[(i + 1) % 3], q)) return 1;
        if (seg_meets_tri(q[i], q[(i + 1) % 3], p)) return 1;
    }
    return 0;
}

typedef struct TriRef {
    float lo[3], hi[3];
    int elem;
    uint32_t tri;
} TriRef;

static int cmp_lo_z(const void *a, const void *b)
{
    float x = ((const TriRef *)a)->lo[2], y = ((const TriRef *)b)->lo[2];
    return x < y ? -1 : x > y;
}

int mesh_parts_meet(const MeshPart *parts, int nparts, int *pa, int *pb, uint32_t *ta, uint32_t *tb)
{
    size_t n = 0;
    for (int e = 0; e < nparts; e++) n += parts[e].ntris;
    TriRef *r = malloc((n ? n : 1) * sizeof *r);
    if (!r) return -1;
    size_t k = 0;
    for (int e = 0; e < nparts; e++) {
        const Mesh *m = parts[e].mesh;
        for (uint32_t i = 0; i < parts[e].ntris; i++, k++) {
            uint32_t t = parts[e].first + i;
            vec3 a = m->verts[m->tris[3 * t]], b = m->verts[m->tris[3 * t + 1]],
                 c = m->verts[m->tris[3 * t + 2]];
            vec3 lo = v3_min(a, v3_min(b, c)), hi = v3_max(a, v3_max(b, c));
            r[k] = (TriRef){{lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z}, e, i};
        }
    }
    /* sweep along z: each triangle meets the later ones whose z range starts inside its own */
    qsort(r, n, sizeof *r, cmp_lo_z);
    int meet = 0;
    for (size_t i = 0; i < n && !meet; i++) {
        for (size_t j = i + 1; j < n && r[j].lo[2] <= r[i].hi[2]; j++) {
            if (r[j].elem == r[i].elem) continue;
            if (r[j].lo[0] > r[i].hi[0] || r[j].hi[0] < r[i].lo[0] || r[j].lo[1] > r[i].hi[1] ||
                r[j].hi[1] < r[i].lo[1])
                continue;
            const MeshPart *a = &parts[r[i].elem], *b = &parts[r[j].elem];
            D3 p[3], q[3];
            for (int c = 0; c < 3; c++) {
                p[c] = d3(a->mesh->verts[a->mesh->tris[3 * (a->first + r[i].tri) + c]]);
                q[c] = d3(b->mesh->verts[b->mesh->tris[3 * (b->first + r[j].tri) + c]]);
            }
            if (!tris_meet(p, q)) continue;
            int first = r[i].elem < r[j].elem;
            *pa = first ? r[i].elem : r[j].elem;
            *pb = first ? r[j].elem : r[i].elem;
            *ta = first ? r[i].tri : r[j].tri;
            *tb = first ? r[j].tri : r[i].tri;
            meet = 1;
            break;
        }
    }
    free(r);
    return meet;
}
