/* texgen_set.c — a generated texture as a set of closed meshes: the random number
 * generator, storage, writing OBJ/PLY whole or not at all, and the disjointness check. */
#include "texgen.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

/* ---- random numbers ---- */

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

void texrng_seed(TexRng *r, uint64_t seed)
{
    for (int i = 0; i < 4; i++) r->s[i] = splitmix64(&seed);
}

static uint64_t rotl(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

uint64_t texrng_next(TexRng *r)
{
    uint64_t *s = r->s;
    uint64_t result = rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

double texrng_uniform(TexRng *r)
{
    return (double)(texrng_next(r) >> 11) * (1.0 / 9007199254740992.0);
}

const char *texgen_float_str(char *buf, size_t len, float v)
{
    for (int digits = 6; digits <= 9; digits++) {
        snprintf(buf, len, "%.*g", digits, v);
        if (strtof(buf, NULL) == v) break;
    }
    return buf;
}

/* ---- storage ---- */

void texset_init(TexSet *t)
{
    memset(t, 0, sizeof *t);
}

void texset_free(TexSet *t)
{
    for (int i = 0; i < t->count; i++) mesh_free(&t->elems[i]);
    free(t->elems);
    free(t->bound);
    texset_init(t);
}

int texset_add(TexSet *t, Mesh *m, const float bound[4])
{
    if (t->count == t->cap) {
        int cap = t->cap ? 2 * t->cap : 16;
        Mesh *e = realloc(t->elems, (size_t)cap * sizeof *e);
        if (e) t->elems = e;
        float(*b)[4] = realloc(t->bound, (size_t)cap * sizeof *b);
        if (b) t->bound = b;
        if (!e || !b) {
            mesh_free(m);
            return -1;
        }
        t->cap = cap;
    }
    t->elems[t->count] = *m;
    memcpy(t->bound[t->count], bound, sizeof t->bound[0]);
    t->count++;
    mesh_init(m);
    return 0;
}

/* ---- writing ---- */

static int all_have_normals(const TexSet *t)
{
    for (int i = 0; i < t->count; i++)
        if (!t->elems[i].normals) return 0;
    return t->count > 0;
}

static void write_obj(FILE *f, const TexSet *t)
{
    int normals = all_have_normals(t);
    uint64_t base = 1;
    fprintf(f, "# vbcl texgen %s\n", t->params);
    fprintf(f, "# block %.9g %.9g %.9g %.9g %.9g %.9g\n", t->block_lo[0], t->block_lo[1],
            t->block_lo[2], t->block_hi[0], t->block_hi[1], t->block_hi[2]);
    fprintf(f, "# %d elements, each a closed outward-oriented mesh; the texture is their union\n",
            t->count);
    for (int e = 0; e < t->count; e++) {
        const Mesh *m = &t->elems[e];
        fprintf(f, "o element_%d\n", e + 1);
        for (uint32_t i = 0; i < m->nverts; i++)
            fprintf(f, "v %.9g %.9g %.9g\n", m->verts[i].x, m->verts[i].y, m->verts[i].z);
        if (normals)
            for (uint32_t i = 0; i < m->nverts; i++)
                fprintf(f, "vn %.9g %.9g %.9g\n", m->normals[i].x, m->normals[i].y,
                        m->normals[i].z);
        for (uint32_t i = 0; i < m->ntris; i++) {
            uint64_t a = base + m->tris[3 * i], b = base + m->tris[3 * i + 1],
                     c = base + m->tris[3 * i + 2];
            if (normals)
                fprintf(f, "f %llu//%llu %llu//%llu %llu//%llu\n", (unsigned long long)a,
                        (unsigned long long)a, (unsigned long long)b, (unsigned long long)b,
                        (unsigned long long)c, (unsigned long long)c);
            else
                fprintf(f, "f %llu %llu %llu\n", (unsigned long long)a, (unsigned long long)b,
                        (unsigned long long)c);
        }
        base += m->nverts;
    }
}

static void put_f32(FILE *f, float v)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    unsigned char b[4] = {(unsigned char)u, (unsigned char)(u >> 8), (unsigned char)(u >> 16),
                          (unsigned char)(u >> 24)};
    fwrite(b, 1, 4, f);
}

static void put_u32(FILE *f, uint32_t u)
{
    unsigned char b[4] = {(unsigned char)u, (unsigned char)(u >> 8), (unsigned char)(u >> 16),
                          (unsigned char)(u >> 24)};
    fwrite(b, 1, 4, f);
}

static void write_ply(FILE *f, const TexSet *t)
{
    int normals = all_have_normals(t);
    uint64_t nv = 0, nt = 0;
    for (int e = 0; e < t->count; e++) {
        nv += t->elems[e].nverts;
        nt += t->elems[e].ntris;
    }
    fprintf(f, "ply\nformat binary_little_endian 1.0\n");
    fprintf(f, "comment vbcl texgen %s\n", t->params);
    fprintf(f, "comment block %.9g %.9g %.9g %.9g %.9g %.9g\n", t->block_lo[0], t->block_lo[1],
            t->block_lo[2], t->block_hi[0], t->block_hi[1], t->block_hi[2]);
    uint64_t first = 0;
    for (int e = 0; e < t->count; e++) {
        fprintf(f, "comment element_%d faces %llu %u\n", e + 1, (unsigned long long)first,
                t->elems[e].ntris);
        first += t->elems[e].ntris;
    }
    fprintf(f, "element vertex %llu\nproperty float x\nproperty float y\nproperty float z\n",
            (unsigned long long)nv);
    if (normals) fprintf(f, "property float nx\nproperty float ny\nproperty float nz\n");
    fprintf(f, "element face %llu\nproperty list uchar uint vertex_indices\nend_header\n",
            (unsigned long long)nt);
    for (int e = 0; e < t->count; e++) {
        const Mesh *m = &t->elems[e];
        for (uint32_t i = 0; i < m->nverts; i++) {
            put_f32(f, m->verts[i].x);
            put_f32(f, m->verts[i].y);
            put_f32(f, m->verts[i].z);
            if (normals) {
                put_f32(f, m->normals[i].x);
                put_f32(f, m->normals[i].y);
                put_f32(f, m->normals[i].z);
            }
        }
    }
    uint32_t base = 0;
    for (int e = 0; e < t->count; e++) {
        const Mesh *m = &t->elems[e];
        for (uint32_t i = 0; i < m->ntris; i++) {
            fputc(3, f);
            for (int k = 0; k < 3; k++) put_u32(f, base + m->tris[3 * i + k]);
        }
        base += m->nverts;
    }
}

static int has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), k = strlen(ext);
    return n > k && strcasecmp(path + n - k, ext) == 0;
}

int texset_write(const TexSet *t, const char *path, char *err, size_t errlen)
{
    int obj = has_ext(path, ".obj"), ply = has_ext(path, ".ply");
    if (!obj && !ply) {
        snprintf(err, errlen, "%s: unknown mesh extension (expected .obj or .ply)", path);
        return -2;
    }
    char tmp[4096];
    if (snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid()) >= (int)sizeof tmp) {
        snprintf(err, errlen, "%s: path too long", path);
        return -1;
    }
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        snprintf(err, errlen, "%s: cannot write: %s", path, strerror(errno));
        return -1;
    }
    if (obj)
        write_obj(f, t);
    else
        write_ply(f, t);
    int bad = ferror(f);
    if (fclose(f) != 0) bad = 1;
    if (bad || rename(tmp, path) != 0) {
        snprintf(err, errlen, "%s: cannot write: %s", path, strerror(errno ? errno : EIO));
        remove(tmp);
        return -1;
    }
    return 0;
}

/* ---- disjointness: exact-enough triangle/triangle intersection ---- */

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

int texset_check_disjoint(const TexSet *t, char *err, size_t errlen)
{
    size_t n = 0;
    for (int e = 0; e < t->count; e++) n += t->elems[e].ntris;
    TriRef *r = malloc((n ? n : 1) * sizeof *r);
    if (!r) {
        snprintf(err, errlen, "out of memory checking %zu triangles", n);
        return -1;
    }
    size_t k = 0;
    for (int e = 0; e < t->count; e++) {
        const Mesh *m = &t->elems[e];
        for (uint32_t i = 0; i < m->ntris; i++, k++) {
            vec3 a = m->verts[m->tris[3 * i]], b = m->verts[m->tris[3 * i + 1]],
                 c = m->verts[m->tris[3 * i + 2]];
            vec3 lo = v3_min(a, v3_min(b, c)), hi = v3_max(a, v3_max(b, c));
            r[k] = (TriRef){{lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z}, e, i};
        }
    }
    /* sweep along z: each triangle meets the later ones whose z range starts inside its own */
    qsort(r, n, sizeof *r, cmp_lo_z);
    int rc = 0;
    for (size_t i = 0; i < n && rc == 0; i++) {
        for (size_t j = i + 1; j < n && r[j].lo[2] <= r[i].hi[2]; j++) {
            if (r[j].elem == r[i].elem) continue;
            if (r[j].lo[0] > r[i].hi[0] || r[j].hi[0] < r[i].lo[0] || r[j].lo[1] > r[i].hi[1] ||
                r[j].hi[1] < r[i].lo[1])
                continue;
            const Mesh *ma = &t->elems[r[i].elem], *mb = &t->elems[r[j].elem];
            D3 p[3], q[3];
            for (int c = 0; c < 3; c++) {
                p[c] = d3(ma->verts[ma->tris[3 * r[i].tri + c]]);
                q[c] = d3(mb->verts[mb->tris[3 * r[j].tri + c]]);
            }
            if (tris_meet(p, q)) {
                int ea = r[i].elem < r[j].elem ? r[i].elem : r[j].elem;
                int eb = r[i].elem < r[j].elem ? r[j].elem : r[i].elem;
                snprintf(err, errlen,
                         "elements %d and %d intersect (triangle %u of one meets triangle %u "
                         "of the other)",
                         ea + 1, eb + 1, r[i].tri, r[j].tri);
                rc = -1;
                break;
            }
        }
    }
    free(r);
    return rc;
}
