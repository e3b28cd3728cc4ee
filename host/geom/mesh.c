/* mesh.c — indexed triangle mesh storage, transforms, bounds and the closed-surface check. */
#include "mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void mesh_init(Mesh *m)
{
    memset(m, 0, sizeof *m);
}

void mesh_free(Mesh *m)
{
    free(m->verts);
    free(m->normals);
    free(m->tris);
    mesh_init(m);
}

/* Next capacity for an array that must hold `need` items: doubling from 16, capped so the
 * byte size of the array (elem bytes per item) and the item count both fit. Returns 0 when
 * impossible. */
static uint32_t grow_capacity(uint32_t cap, uint32_t need, size_t elem)
{
    uint64_t c = cap < 16 ? 16 : cap;
    while (c < need) c *= 2;
    if (c > UINT32_MAX) c = UINT32_MAX;
    if (c < need || c > SIZE_MAX / elem) return 0;
    return (uint32_t)c;
}

/* Makes room for `need` vertices (and normals when present). */
static int reserve_verts(Mesh *m, uint32_t need)
{
    if (need <= m->cap_verts) return 0;
    uint32_t cap = grow_capacity(m->cap_verts, need, sizeof(vec3));
    if (!cap) return -1;
    vec3 *v = realloc(m->verts, (size_t)cap * sizeof *v);
    if (!v) return -1;
    m->verts = v;
    if (m->normals) {
        vec3 *n = realloc(m->normals, (size_t)cap * sizeof *n);
        if (!n) return -1; /* verts is merely larger than cap_verts says */
        m->normals = n;
    }
    m->cap_verts = cap;
    return 0;
}

uint32_t mesh_add_vertex(Mesh *m, vec3 p)
{
    if (m->nverts >= UINT32_MAX - 1 || reserve_verts(m, m->nverts + 1) < 0) return UINT32_MAX;
    m->verts[m->nverts] = p;
    if (m->normals) m->normals[m->nverts] = v3(0, 0, 0);
    return m->nverts++;
}

int mesh_add_triangle(Mesh *m, uint32_t a, uint32_t b, uint32_t c)
{
    if (m->ntris == m->cap_tris) {
        if (m->ntris >= UINT32_MAX / 3) return -1;
        uint32_t cap = grow_capacity(m->cap_tris, m->ntris + 1, 3 * sizeof(uint32_t));
        if (!cap || cap > UINT32_MAX / 3) cap = UINT32_MAX / 3;
        uint32_t *t = realloc(m->tris, (size_t)cap * 3 * sizeof *t);
        if (!t) return -1;
        m->tris = t;
        m->cap_tris = cap;
    }
    uint32_t *t = m->tris + (size_t)m->ntris * 3;
    t[0] = a;
    t[1] = b;
    t[2] = c;
    m->ntris++;
    return 0;
}

int mesh_enable_normals(Mesh *m)
{
    if (m->normals) return 0;
    size_t n = m->cap_verts ? m->cap_verts : 1;
    m->normals = calloc(n, sizeof *m->normals);
    return m->normals ? 0 : -1;
}

/* A vertex that has no normal of its own gets the zero vector (the renderer falls back to
 * the geometric normal for it). */
int mesh_append(Mesh *dst, const Mesh *src)
{
    if (src->nverts > UINT32_MAX - 1 - dst->nverts) return -1;
    if (src->normals && mesh_enable_normals(dst) < 0) return -1;
    uint32_t base = dst->nverts;
    if (reserve_verts(dst, base + src->nverts) < 0) return -1;
    if (src->nverts) memcpy(dst->verts + base, src->verts, (size_t)src->nverts * sizeof(vec3));
    if (dst->normals) {
        if (src->normals)
            memcpy(dst->normals + base, src->normals, (size_t)src->nverts * sizeof(vec3));
        else
            memset(dst->normals + base, 0, (size_t)src->nverts * sizeof(vec3));
    }
    dst->nverts += src->nverts;
    for (uint32_t i = 0; i < src->ntris; i++) {
        const uint32_t *t = src->tris + (size_t)i * 3;
        if (mesh_add_triangle(dst, t[0] + base, t[1] + base, t[2] + base) < 0) return -1;
    }
    return 0;
}

void mesh_transform(Mesh *m, const mat4 *xf)
{
    for (uint32_t i = 0; i < m->nverts; i++) m->verts[i] = mat4_apply_point(xf, m->verts[i]);
    if (m->normals)
        for (uint32_t i = 0; i < m->nverts; i++) {
            /* zero normals mean "none" and stay zero */
            if (v3_dot(m->normals[i], m->normals[i]) > 0.0f)
                m->normals[i] = mat4_apply_normal(xf, m->normals[i]);
        }
    if (mat4_det3(xf) < 0.0)
        for (uint32_t i = 0; i < m->ntris; i++) {
            uint32_t *t = m->tris + (size_t)i * 3, s = t[1];
            t[1] = t[2];
            t[2] = s;
        }
}

void mesh_bounds(const Mesh *m, vec3 *lo, vec3 *hi)
{
    *lo = v3(INFINITY, INFINITY, INFINITY);
    *hi = v3(-INFINITY, -INFINITY, -INFINITY);
    for (uint32_t i = 0; i < m->nverts; i++) {
        *lo = v3_min(*lo, m->verts[i]);
        *hi = v3_max(*hi, m->verts[i]);
    }
}

/* ---- closed-surface check ---- */

/* Bits of a coordinate with -0 folded onto +0, so equal positions hash equally. */
static uint32_t float_key(float f)
{
    uint32_t u;
    if (f == 0.0f) f = 0.0f;
    memcpy(&u, &f, sizeof u);
    return u;
}

static uint64_t hash_position(vec3 p)
{
    uint64_t h = float_key(p.x) * 0x9E3779B97F4A7C15ull;
    h ^= (h >> 29) + float_key(p.y) * 0xBF58476D1CE4E5B9ull;
    h ^= (h >> 31) + float_key(p.z) * 0x94D049BB133111EBull;
    return h ^ (h >> 32);
}

static int same_position(vec3 a, vec3 b)
{
    return float_key(a.x) == float_key(b.x) && float_key(a.y) == float_key(b.y) &&
           float_key(a.z) == float_key(b.z);
}

/* Fills canon[i] with the smallest index of a vertex at the same position as vertex i. */
static int weld_positions(const Mesh *m, uint32_t *canon)
{
    size_t size = 16;
    while (size < (size_t)m->nverts * 2) size *= 2;
    uint32_t *table = malloc(size * sizeof *table);
    if (!table) return -1;
    memset(table, 0xff, size * sizeof *table);
    for (uint32_t i = 0; i < m->nverts; i++) {
        size_t h = (size_t)hash_position(m->verts[i]) & (size - 1);
        for (;;) {
            uint32_t j = table[h];
            if (j == UINT32_MAX) {
                table[h] = i;
                canon[i] = i;
                break;
            }
            if (same_position(m->verts[j], m->verts[i])) {
                canon[i] = j;
                break;
            }
            h = (h + 1) & (size - 1);
        }
    }
    free(table);
    return 0;
}

/* One triangle edge: key is (min << 32 | max) of its welded endpoints; tri_dir is the
 * triangle index times two plus 1 when the triangle runs the edge from max to min. */
typedef struct Edge {
    uint64_t key;
    uint32_t tri_dir;
} Edge;

int mesh_cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static int compare_edges(const void *pa, const void *pb)
{
    const Edge *a = pa, *b = pb;
    if (a->key != b->key) return a->key < b->key ? -1 : 1;
    return (a->tri_dir > b->tri_dir) - (a->tri_dir < b->tri_dir);
}

/* Sorts edges into compare_edges's order: a least-significant-digit radix sort on the
 * key, 16 bits a pass, skipping a pass whose digit is the same in every key; it keeps equal
 * keys in their order, which is compare_edges's since the edges come in triangle order and
 * no triangle has two edges with one key. Loading glass_bombed_sphere (an 81,920-triangle
 * ball, 245,760 edges) it took 0.8% of the process's perf samples; before it, glibc's merge
 * sort (every qsort of the process) and compare_edges took 5.0%. Without memory for its
 * buffers, qsort. */
static void sort_edges(Edge *edges, size_t n)
{
    enum { DIGITS = 1 << 16 };
    if (n < 2) return;
    Edge *tmp = malloc(n * sizeof *tmp);
    size_t *start = malloc(DIGITS * sizeof *start);
    if (!tmp || !start) {
        free(tmp);
        free(start);
        qsort(edges, n, sizeof *edges, compare_edges);
        return;
    }
    Edge *src = edges, *dst = tmp;
    for (int shift = 0; shift < 64; shift += 16) {
        memset(start, 0, DIGITS * sizeof *start);
        for (size_t i = 0; i < n; i++) start[(src[i].key >> shift) & (DIGITS - 1)]++;
        if (start[(src[0].key >> shift) & (DIGITS - 1)] == n) continue;
        size_t sum = 0;
        for (size_t d = 0; d < DIGITS; d++) {
            size_t c = start[d];
            start[d] = sum;
            sum += c;
        }
        for (size_t i = 0; i < n; i++) dst[start[(src[i].key >> shift) & (DIGITS - 1)]++] = src[i];
        Edge *t = src;
        src = dst;
        dst = t;
    }
    if (src != edges) memcpy(edges, src, n * sizeof *edges);
    free(tmp);
    free(start);
}

static void format_edge(char *buf, size_t len, vec3 a, vec3 b)
{
    snprintf(buf, len, "(%g, %g, %g)-(%g, %g, %g)", a.x, a.y, a.z, b.x, b.y, b.z);
}

/* The three edges of every triangle, between welded vertices, into edges (3 ntris).
 * Returns 0, or -1 with the first degenerate triangle named in err. */
static int collect_edges(const Mesh *m, const uint32_t *canon, Edge *edges, char *err,
                         size_t errlen)
{
    size_t ne = 0;
    for (uint32_t i = 0; i < m->ntris; i++) {
        const uint32_t *t = m->tris + (size_t)i * 3;
        uint32_t w[3];
        for (int k = 0; k < 3; k++) {
            if (t[k] >= m->nverts) {
                snprintf(err, errlen, "triangle %u: vertex index %u out of range (%u vertices)", i,
                         t[k], m->nverts);
                return -1;
            }
            w[k] = canon[t[k]];
        }
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
            snprintf(err, errlen, "triangle %u repeats a vertex index (%u, %u, %u)", i, t[0], t[1],
                     t[2]);
            return -1;
        }
        if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) {
            vec3 a = m->verts[w[0]], b = m->verts[w[1]], c = m->verts[w[2]];
            snprintf(err, errlen,
                     "triangle %u has two corners at the same position: (%g, %g, %g), "
                     "(%g, %g, %g), (%g, %g, %g)",
                     i, a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z);
            return -1;
        }
        for (int k = 0; k < 3; k++) {
            uint32_t a = w[k], b = w[(k + 1) % 3];
            Edge *ed = &edges[ne++];
            ed->key = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
            ed->tri_dir = i * 2 + (a > b);
        }
    }
    return 0;
}

/* Checks the sorted edges: each must be used by exactly two triangles, once in each
 * direction. Returns 0, or -1 with the first bad edge named in err. */
static int check_edges(const Mesh *m, const Edge *edges, size_t ne, char *err, size_t errlen)
{
    char e[160];
    for (size_t s = 0; s < ne;) {
        size_t r = s, fwd = 0;
        while (r < ne && edges[r].key == edges[s].key) fwd += !(edges[r++].tri_dir & 1);
        size_t count = r - s, bwd = count - fwd;
        uint32_t lo = (uint32_t)(edges[s].key >> 32), hi = (uint32_t)edges[s].key;
        if (count == 2 && fwd == 1) {
            s = r;
            continue;
        }
        if (count == 1) {
            int back = edges[s].tri_dir & 1;
            format_edge(e, sizeof e, m->verts[back ? hi : lo], m->verts[back ? lo : hi]);
            snprintf(err, errlen, "open edge %s: used by 1 triangle (triangle %u)", e,
                     edges[s].tri_dir >> 1);
        } else if (count == 2) {
            int back = bwd == 2;
            format_edge(e, sizeof e, m->verts[back ? hi : lo], m->verts[back ? lo : hi]);
            snprintf(err, errlen,
                     "edge %s used twice in the same direction (inconsistent orientation; "
                     "triangles %u and %u)",
                     e, edges[s].tri_dir >> 1, edges[s + 1].tri_dir >> 1);
        } else {
            format_edge(e, sizeof e, m->verts[lo], m->verts[hi]);
            snprintf(err, errlen, "edge %s used by %zu triangles (non-manifold)", e, count);
        }
        return -1;
    }
    return 0;
}

/* Union-find root of i, halving the path. */
static uint32_t uf_root(uint32_t *parent, uint32_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

vec3 mesh_tri_normal_d(const Mesh *m, uint32_t t, double n[3])
{
    vec3 p0 = m->verts[m->tris[3 * t]], p1 = m->verts[m->tris[3 * t + 1]],
         p2 = m->verts[m->tris[3 * t + 2]];
    double e1[3] = {p1.x - p0.x, p1.y - p0.y, p1.z - p0.z};
    double e2[3] = {p2.x - p0.x, p2.y - p0.y, p2.z - p0.z};
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    return p0;
}

/* Signed distance (times the normal's length) of vertex v from the plane of triangle t. */
static double plane_side(const Mesh *m, uint32_t t, uint32_t v, double *len)
{
    double n[3];
    vec3 a = mesh_tri_normal_d(m, t, n), p = m->verts[v];
    *len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return n[0] * ((double)p.x - a.x) + n[1] * ((double)p.y - a.y) + n[2] * ((double)p.z - a.z);
}

/* The corner of triangle t that is neither end of the edge with key `key`. */
static uint32_t far_corner(const Mesh *m, uint32_t t, uint64_t key)
{
    const uint32_t *c = m->tris + 3 * (size_t)t;
    uint32_t lo = (uint32_t)(key >> 32), hi = (uint32_t)key;
    for (int k = 0; k < 3; k++)
        if (c[k] != lo && c[k] != hi) return c[k];
    return c[0];
}

int mesh_part_convex(const Mesh *m, uint32_t first, uint32_t n, double tol)
{
    if (n < 4 || n > (UINT32_MAX >> 1) || first > m->ntris || n > m->ntris - first) return 0;
    size_t ne = 3 * (size_t)n;
    Edge *edges = malloc(ne * sizeof *edges);
    uint32_t *parent = malloc((size_t)n * sizeof *parent);
    int convex = edges && parent;
    for (uint32_t i = 0; i < n && convex; i++) {
        const uint32_t *t = m->tris + 3 * (size_t)(first + i);
        parent[i] = i;
        for (int k = 0; k < 3; k++) {
            uint32_t a = t[k], b = t[(k + 1) % 3];
            if (a >= m->nverts || a == b) convex = 0;
            Edge *ed = &edges[3 * (size_t)i + (size_t)k];
            ed->key = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
            ed->tri_dir = i * 2 + (a > b);
        }
    }
    if (convex) sort_edges(edges, ne);
    for (size_t s = 0; convex && s < ne; s += 2) {
        /* exactly two uses, in opposite directions (sorted: forward first) */
        if (s + 1 >= ne || edges[s + 1].key != edges[s].key ||
            (s + 2 < ne && edges[s + 2].key == edges[s].key) ||
            (edges[s].tri_dir & 1) == (edges[s + 1].tri_dir & 1)) {
            convex = 0;
            break;
        }
        uint32_t ta = edges[s].tri_dir >> 1, tb = edges[s + 1].tri_dir >> 1;
        for (int side = 0; side < 2 && convex; side++) {
            uint32_t t = side ? tb : ta, o = side ? ta : tb;
            double len, h = plane_side(m, first + t, far_corner(m, first + o, edges[s].key), &len);
            convex = len > 0.0 && h < -tol * len;
        }
        uint32_t ra = uf_root(parent, ta), rb = uf_root(parent, tb);
        parent[ra] = rb;
    }
    for (uint32_t i = 1; convex && i < n; i++) convex = uf_root(parent, i) == uf_root(parent, 0);
    unsigned char *seen = convex ? calloc(m->nverts, 1) : NULL;
    convex = convex && seen;
    if (convex) { /* genus 0: V - E + F = 2 */
        size_t nv = 0;
        for (size_t i = 0; i < ne; i++) {
            uint32_t v = m->tris[3 * (size_t)first + i];
            nv += !seen[v];
            seen[v] = 1;
        }
        convex = (long long)nv - (long long)(ne / 2) + (long long)n == 2;
    }
    free(edges);
    free(parent);
    free(seen);
    return convex;
}

int mesh_check_closed(const Mesh *m, char *err, size_t errlen)
{
    if (m->ntris == 0) {
        snprintf(err, errlen, "no triangles");
        return -1;
    }
    if (m->ntris > (UINT32_MAX >> 1)) {
        snprintf(err, errlen, "too many triangles to check (%u)", m->ntris);
        return -1;
    }
    int rc = -1;
    uint32_t *canon = malloc(((size_t)m->nverts + 1) * sizeof *canon);
    Edge *edges = malloc((size_t)m->ntris * 3 * sizeof *edges);
    if (!canon || !edges || weld_positions(m, canon) < 0) {
        snprintf(err, errlen, "out of memory checking the mesh");
    } else if (!collect_edges(m, canon, edges, err, errlen)) {
        size_t ne = (size_t)m->ntris * 3;
        sort_edges(edges, ne);
        rc = check_edges(m, edges, ne, err, errlen);
    }
    free(canon);
    free(edges);
    return rc;
}
