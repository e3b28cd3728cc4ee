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

#include "fileio.h"

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

static void write_obj(FILE *f, const void *ctx)
{
    const TexSet *t = ctx;
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

static void write_ply(FILE *f, const void *ctx)
{
    const TexSet *t = ctx;
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
    return file_write_stream(path, obj ? write_obj : write_ply, t, err, errlen);
}

int texset_check_disjoint(const TexSet *t, char *err, size_t errlen)
{
    MeshPart *parts = malloc((size_t)(t->count ? t->count : 1) * sizeof *parts);
    if (!parts) {
        snprintf(err, errlen, "out of memory checking %d elements", t->count);
        return -1;
    }
    for (int e = 0; e < t->count; e++) parts[e] = (MeshPart){&t->elems[e], 0, t->elems[e].ntris};
    int ea, eb;
    uint32_t ta, tb;
    int meet = mesh_parts_meet(parts, t->count, &ea, &eb, &ta, &tb);
    free(parts);
    if (meet < 0) snprintf(err, errlen, "out of memory checking the elements");
    if (meet > 0)
        snprintf(err, errlen,
                 "elements %d and %d intersect (triangle %u of one meets triangle %u of the other)",
                 ea + 1, eb + 1, ta, tb);
    return meet ? -1 : 0;
}
