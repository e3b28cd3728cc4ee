/* mesh_io.c — loads triangle meshes from Wavefront OBJ and PLY (ASCII and binary) files. */
#include "mesh.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "diag.h"

/* ---- shared helpers ---- */

/* Error sink: the file name and the caller's buffer. */
typedef struct Ctx {
    const char *path;
    char *err;
    size_t errlen;
} Ctx;

static int fail(const Ctx *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int fail(const Ctx *c, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    diag_vformat(msg, sizeof msg, fmt, ap);
    va_end(ap);
    diag_format(c->err, c->errlen, "%s%s", c->path, msg);
    return -1;
}

/* Reads the whole file into a NUL-terminated buffer, once: a regular file of at most
 * MESH_MAX_FILE_BYTES (a link to /dev/zero or a pipe would never end). */
static int read_file(const Ctx *c, char **data, size_t *len)
{
    struct stat st; /* before opening: opening a pipe waits for a writer */
    if (stat(c->path, &st)) return fail(c, ": cannot open: %s", strerror(errno));
    if (!S_ISREG(st.st_mode))
        return fail(c, ": not a regular file (a mesh must be a file, not a %s)",
                    S_ISDIR(st.st_mode) ? "directory" : "device, pipe or socket");
    FILE *f = fopen(c->path, "rb");
    if (!f) return fail(c, ": cannot open: %s", strerror(errno));
    if (fstat(fileno(f), &st) || !S_ISREG(st.st_mode)) {
        fclose(f);
        return fail(c, ": not a regular file");
    }
    if ((uint64_t)st.st_size > MESH_MAX_FILE_BYTES) {
        fclose(f);
        return fail(c, ": %llu bytes, more than the limit of 1 GiB",
                    (unsigned long long)st.st_size);
    }
    size_t cap = (size_t)st.st_size + 2, n = 0; /* one more byte shows a file still growing */
    char *buf = malloc(cap);
    if (!buf) {
        fclose(f);
        return fail(c, ": out of memory");
    }
    n = fread(buf, 1, cap - 1, f);
    int bad = ferror(f), read_errno = errno;
    fclose(f);
    if (bad || n > (size_t)st.st_size) {
        free(buf);
        if (bad) return fail(c, ": cannot read: %s", strerror(read_errno));
        return fail(c, ": the file grew while it was read");
    }
    buf[n] = '\0';
    *data = buf;
    *len = n;
    return 0;
}

static int is_space(char ch)
{
    return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\f' || ch == '\v';
}

static char *skip_space(char *s)
{
    while (is_space(*s)) s++;
    return s;
}

/* Parses one whitespace-delimited finite float at *s (within a NUL-terminated line);
 * advances *s past it. Returns 0, 1 when the line has no more tokens, -1 when the token
 * is not a number, -2 when it is not finite as a float. */
static int parse_float(char **s, float *out)
{
    char *p = skip_space(*s), *end;
    if (*p == '\0' || *p == '\n') return 1;
    errno = 0;
    double d = strtod(p, &end);
    if (end == p || (*end != '\0' && !is_space(*end))) return -1;
    if (!isfinite(d) || (errno == ERANGE && fabs(d) > 1.0) || fabs(d) > 3.4028234663852886e38)
        return -2;
    *out = (float)d;
    *s = end;
    return 0;
}

/* Moves the loaded mesh into out: taken over whole when out is empty, else appended. */
static int move_into(Mesh *out, Mesh *m)
{
    if (out->nverts == 0 && out->ntris == 0) {
        mesh_free(out);
        *out = *m;
        mesh_init(m);
        return 0;
    }
    return mesh_append(out, m);
}

/* ---- index map for (position, normal) pairs ---- */

typedef struct PairMap {
    uint64_t *keys; /* (pos << 32 | normal) + 1; 0 = empty */
    uint32_t *vals;
    size_t size, used;
} PairMap;

static uint64_t mix64(uint64_t h)
{
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ull;
    return h ^ (h >> 33);
}

/* Finds or inserts key; *val is the existing value or is stored. Returns 1 when found,
 * 0 when inserted, -1 on memory failure. */
static int pairmap_get(PairMap *pm, uint64_t key, uint32_t *val)
{
    if ((pm->used + 1) * 2 > pm->size) {
        size_t ns = pm->size ? pm->size * 2 : 1024;
        uint64_t *nk = calloc(ns, sizeof *nk);
        uint32_t *nv = malloc(ns * sizeof *nv);
        if (!nk || !nv) {
            free(nk);
            free(nv);
            return -1;
        }
        for (size_t i = 0; i < pm->size; i++) {
            if (!pm->keys[i]) continue;
            size_t h = mix64(pm->keys[i]) & (ns - 1);
            while (nk[h]) h = (h + 1) & (ns - 1);
            nk[h] = pm->keys[i];
            nv[h] = pm->vals[i];
        }
        free(pm->keys);
        free(pm->vals);
        pm->keys = nk;
        pm->vals = nv;
        pm->size = ns;
    }
    key += 1;
    size_t h = mix64(key) & (pm->size - 1);
    while (pm->keys[h]) {
        if (pm->keys[h] == key) {
            *val = pm->vals[h];
            return 1;
        }
        h = (h + 1) & (pm->size - 1);
    }
    pm->keys[h] = key;
    pm->vals[h] = *val;
    pm->used++;
    return 0;
}

/* ---- OBJ ---- */

/* Growable array of vec3 or of face corners. */
typedef struct Vec3List {
    vec3 *v;
    size_t n, cap;
} Vec3List;

typedef struct Corner {
    uint32_t pos, nrm; /* 0-based; nrm == UINT32_MAX when absent */
} Corner;

typedef struct CornerList {
    Corner *c;
    size_t n, cap;
} CornerList;

static int vec3list_push(Vec3List *l, vec3 p)
{
    if (l->n == l->cap) {
        size_t cap = l->cap ? l->cap * 2 : 256;
        if (cap > UINT32_MAX) return -1;
        vec3 *v = realloc(l->v, cap * sizeof *v);
        if (!v) return -1;
        l->v = v;
        l->cap = cap;
    }
    l->v[l->n++] = p;
    return 0;
}

static int cornerlist_push(CornerList *l, Corner c)
{
    if (l->n == l->cap) {
        size_t cap = l->cap ? l->cap * 2 : 768;
        if (cap > SIZE_MAX / sizeof(Corner)) return -1;
        Corner *v = realloc(l->c, cap * sizeof *v);
        if (!v) return -1;
        l->c = v;
        l->cap = cap;
    }
    l->c[l->n++] = c;
    return 0;
}

/* Parses an OBJ index (1-based, or negative = relative to count); returns the 0-based index
 * in *out, or -1 when the text is not an integer, 1 when out of range (*raw holds it). */
static int obj_index(char **s, size_t count, uint32_t *out, long long *raw)
{
    char *p = *s, *end;
    if (!(*p == '-' || *p == '+' || (*p >= '0' && *p <= '9'))) return -1;
    errno = 0;
    long long v = strtoll(p, &end, 10);
    if (end == p) return -1;
    *s = end;
    *raw = v;
    if (errno == ERANGE) return 1;
    long long idx = v > 0 ? v - 1 : (long long)count + v;
    if (v == 0 || idx < 0 || (unsigned long long)idx >= count) return 1;
    *out = (uint32_t)idx;
    return 0;
}

/* Parses one face token "i", "i/j", "i//k" or "i/j/k". */
static int obj_corner(const Ctx *c, long line, char **s, size_t npos, size_t nnrm, size_t ntex,
                      Corner *out)
{
    char *p = *s;
    long long raw = 0;
    uint32_t idx = 0;
    int r = obj_index(&p, npos, &idx, &raw);
    if (r < 0) return fail(c, ":%ld: expected a vertex index in 'f'", line);
    if (r > 0) return fail(c, ":%ld: face index %lld out of range (%zu vertices)", line, raw, npos);
    out->pos = idx;
    out->nrm = UINT32_MAX;
    if (*p == '/') {
        p++;
        if (*p != '/') {
            r = obj_index(&p, ntex, &idx, &raw);
            if (r < 0) return fail(c, ":%ld: expected a texture index after '/' in 'f'", line);
            /* texture coordinates are not used; their range is not checked */
        }
        if (*p == '/') {
            p++;
            r = obj_index(&p, nnrm, &idx, &raw);
            if (r < 0) return fail(c, ":%ld: expected a normal index after '//' in 'f'", line);
            if (r > 0)
                return fail(c, ":%ld: face normal index %lld out of range (%zu normals)", line, raw,
                            nnrm);
            out->nrm = idx;
        }
    }
    if (*p != '\0' && !is_space(*p)) return fail(c, ":%ld: malformed face vertex in 'f'", line);
    *s = p;
    return 0;
}

/* OBJ parser state: what the lines read so far gave. */
typedef struct ObjState {
    const Ctx *c;
    long line;
    Vec3List pos, nrm;
    CornerList corners; /* 3 per triangle */
    size_t ntex;
} ObjState;

/* "v x y z [w | r g b [a]]" or "vn x y z"; s points past the keyword. */
static int obj_vertex(ObjState *st, char *s, int is_v)
{
    const char *kw = is_v ? "v" : "vn";
    float xyz[3], extra;
    int r = 0, got = 0, nextra = 0;
    while (got < 3 && (r = parse_float(&s, &xyz[got])) == 0) got++;
    while (r == 0 && (r = parse_float(&s, &extra)) == 0) nextra++;
    if (r == -2) return fail(st->c, ":%ld: non-finite number after '%s'", st->line, kw);
    if (r != 1 || got < 3 || nextra > (is_v ? 4 : 0))
        return fail(st->c, ":%ld: expected 3 numbers after '%s'", st->line, kw);
    vec3 q = v3(xyz[0], xyz[1], xyz[2]);
    if (vec3list_push(is_v ? &st->pos : &st->nrm, is_v ? q : v3_norm(q)) < 0)
        return fail(st->c, ":%ld: too many vertices or out of memory", st->line);
    return 0;
}

/* "f c1 c2 c3 ...": a polygon, kept as a fan of triangles (3 corners each). */
static int obj_face(ObjState *st, char *s)
{
    Corner first = {0, 0}, prev = {0, 0}, cur;
    size_t n = 0;
    for (;;) {
        s = skip_space(s);
        if (*s == '\0') break;
        if (obj_corner(st->c, st->line, &s, st->pos.n, st->nrm.n, st->ntex, &cur) < 0) return -1;
        if (n == 0)
            first = cur;
        else if (n >= 2 && (cornerlist_push(&st->corners, first) < 0 ||
                            cornerlist_push(&st->corners, prev) < 0 ||
                            cornerlist_push(&st->corners, cur) < 0))
            return fail(st->c, ":%ld: out of memory", st->line);
        prev = cur;
        n++;
    }
    if (n < 3) return fail(st->c, ":%ld: face with %zu vertices (need at least 3)", st->line, n);
    return 0;
}

/* One NUL-terminated line, by its keyword. */
static int obj_line(ObjState *st, char *s)
{
    char *kw = skip_space(s);
    s = kw;
    while (*s && !is_space(*s)) s++;
    size_t kwlen = (size_t)(s - kw);
    if (kwlen == 1 && kw[0] == 'v') return obj_vertex(st, s, 1);
    if (kwlen == 2 && kw[0] == 'v' && kw[1] == 'n') return obj_vertex(st, s, 0);
    if (kwlen == 2 && kw[0] == 'v' && kw[1] == 't') {
        st->ntex++;
        return 0;
    }
    if (kwlen == 1 && kw[0] == 'f') return obj_face(st, s);
    /* everything else (vt, o, g, s, usemtl, mtllib, l, comments, ...) is ignored */
    return 0;
}

/* Every corner has a normal: one mesh vertex per distinct (position, normal) pair.
 * Returns -1 when out of memory. */
static int obj_mesh_normals(const ObjState *st, Mesh *m)
{
    const CornerList *cl = &st->corners;
    PairMap pm = {0};
    uint32_t t[3];
    size_t i;
    if (mesh_enable_normals(m) < 0) return -1;
    for (i = 0; i < cl->n; i++) {
        Corner k = cl->c[i];
        uint32_t v = m->nverts;
        int r = pairmap_get(&pm, (uint64_t)k.pos << 32 | k.nrm, &v);
        if (r < 0) break;
        if (r == 0) {
            if (mesh_add_vertex(m, st->pos.v[k.pos]) == UINT32_MAX) break;
            m->normals[v] = st->nrm.v[k.nrm];
        }
        t[i % 3] = v;
        if (i % 3 == 2 && mesh_add_triangle(m, t[0], t[1], t[2]) < 0) break;
    }
    free(pm.keys);
    free(pm.vals);
    return i == cl->n ? 0 : -1;
}

/* Builds the mesh from the corners: the positions as they are when any corner lacks a
 * normal, else with normals. Returns -1 when out of memory. */
static int obj_mesh(const ObjState *st, Mesh *m)
{
    const CornerList *cl = &st->corners;
    int with_normals = 1;
    for (size_t i = 0; i < cl->n && with_normals; i++) with_normals = cl->c[i].nrm != UINT32_MAX;
    if (with_normals) return obj_mesh_normals(st, m);
    for (size_t i = 0; i < st->pos.n; i++)
        if (mesh_add_vertex(m, st->pos.v[i]) == UINT32_MAX) return -1;
    for (size_t i = 0; i < cl->n; i += 3)
        if (mesh_add_triangle(m, cl->c[i].pos, cl->c[i + 1].pos, cl->c[i + 2].pos) < 0) return -1;
    return 0;
}

static int load_obj(const Ctx *c, char *data, size_t len, Mesh *out)
{
    ObjState st = {.c = c};
    Mesh m;
    int rc = -1;
    char *p = data, *endp = data + len;
    mesh_init(&m);
    while (p < endp) {
        st.line++;
        char *eol = memchr(p, '\n', (size_t)(endp - p));
        if (!eol) eol = endp;
        *eol = '\0';
        char *s = p;
        p = eol + 1;
        if (obj_line(&st, s) < 0) goto done;
    }
    if (st.corners.n == 0)
        fail(c, ": no faces");
    else if (st.corners.n / 3 > UINT32_MAX / 3)
        fail(c, ": too many faces");
    else if (obj_mesh(&st, &m) < 0 || move_into(out, &m) < 0)
        fail(c, ": out of memory");
    else
        rc = 0;
done:
    mesh_free(&m);
    free(st.pos.v);
    free(st.nrm.v);
    free(st.corners.c);
    return rc;
}
/* ---- PLY ---- */

enum { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 };
static const int type_size[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};

static int ply_type(const char *name)
{
    static const struct {
        const char *name;
        int type;
    } names[] = {{"char", T_I8},   {"uchar", T_U8},   {"short", T_I16},   {"ushort", T_U16},
                 {"int", T_I32},   {"uint", T_U32},   {"float", T_F32},   {"double", T_F64},
                 {"int8", T_I8},   {"uint8", T_U8},   {"int16", T_I16},   {"uint16", T_U16},
                 {"int32", T_I32}, {"uint32", T_U32}, {"float32", T_F32}, {"float64", T_F64}};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(name, names[i].name) == 0) return names[i].type;
    return T_NONE;
}

enum { ROLE_NONE, ROLE_X, ROLE_Y, ROLE_Z, ROLE_NX, ROLE_NY, ROLE_NZ, ROLE_INDICES };

typedef struct PlyProp {
    int type;       /* scalar type, or list item type */
    int count_type; /* list count type, T_NONE for scalars */
    int role;
} PlyProp;

#define PLY_MAX_PROPS    64
#define PLY_MAX_ELEMENTS 32

typedef struct PlyElement {
    char name[32];
    uint64_t count;
    int kind; /* 0 other, 1 vertex, 2 face */
    int nprops;
    PlyProp props[PLY_MAX_PROPS];
} PlyElement;

enum { FMT_ASCII, FMT_LE, FMT_BE };

/* Data cursor over the body of the file. */
typedef struct PlyReader {
    const Ctx *c;
    int format;
    const unsigned char *p, *end;
    long line; /* ASCII only */
    const char *what;
    uint64_t item;
} PlyReader;

/* Location prefix for data errors: ":LINE: vertex 3" (ASCII) or ": vertex 3". */
static void ply_where(const PlyReader *r, char *buf, size_t len)
{
    if (r->format == FMT_ASCII)
        snprintf(buf, len, ":%ld: %s %llu", r->line, r->what, (unsigned long long)r->item);
    else
        snprintf(buf, len, ": %s %llu", r->what, (unsigned long long)r->item);
}

static int ply_eof(const PlyReader *r)
{
    return fail(r->c, ": unexpected end of file in %s %llu", r->what, (unsigned long long)r->item);
}

/* Reads one value of the given type as a double. */
static int ply_value(PlyReader *r, int type, double *out)
{
    char where[96];
    if (r->format != FMT_ASCII) {
        int n = type_size[type];
        if (r->end - r->p < n) return ply_eof(r);
        unsigned char b[8];
        for (int i = 0; i < n; i++) b[i] = r->p[r->format == FMT_LE ? i : n - 1 - i];
        r->p += n;
        /* b now holds the value little-endian; assemble portably */
        uint64_t u = 0;
        for (int i = n - 1; i >= 0; i--) u = u << 8 | b[i];
        switch (type) {
        case T_I8:
            *out = (int8_t)u;
            break;
        case T_U8:
            *out = (uint8_t)u;
            break;
        case T_I16:
            *out = (int16_t)(uint16_t)u;
            break;
        case T_U16:
            *out = (uint16_t)u;
            break;
        case T_I32:
            *out = (int32_t)(uint32_t)u;
            break;
        case T_U32:
            *out = (uint32_t)u;
            break;
        case T_F32: {
            uint32_t u32 = (uint32_t)u;
            float f;
            memcpy(&f, &u32, sizeof f);
            *out = f;
            break;
        }
        default: {
            double d;
            memcpy(&d, &u, sizeof d);
            *out = d;
            break;
        }
        }
        return 0;
    }
    /* ASCII: one whitespace-delimited token */
    while (r->p < r->end && (is_space((char)*r->p) || *r->p == '\n' || *r->p == '\0')) {
        if (*r->p == '\n') r->line++;
        r->p++;
    }
    if (r->p == r->end) return ply_eof(r);
    char tok[64];
    size_t n = 0;
    while (r->p < r->end && !is_space((char)*r->p) && *r->p != '\n' && *r->p != '\0') {
        if (n + 1 >= sizeof tok) {
            ply_where(r, where, sizeof where);
            return fail(r->c, "%s: number too long", where);
        }
        tok[n++] = (char)*r->p++;
    }
    tok[n] = '\0';
    char *end;
    errno = 0;
    double d = strtod(tok, &end);
    if (end == tok || *end != '\0' || !isfinite(d) || (errno == ERANGE && fabs(d) > 1.0)) {
        ply_where(r, where, sizeof where);
        return fail(r->c, "%s: bad number '%s'", where, tok);
    }
    static const double lo[] = {0, -128, 0, -32768, 0, -2147483648.0, 0, -3.4028234663852886e38};
    static const double hi[] = {0,     127,          255,          32767,
                                65535, 2147483647.0, 4294967295.0, 3.4028234663852886e38};
    if (type != T_F64 && (d < lo[type] || d > hi[type] || (type < T_F32 && d != floor(d)))) {
        ply_where(r, where, sizeof where);
        return fail(r->c, "%s: value '%s' does not fit the property type", where, tok);
    }
    *out = d;
    return 0;
}

/* Splits the header line at *s into whitespace tokens (at most max); returns the count. */
static int split_tokens(char *s, char **tok, int max)
{
    int n = 0;
    for (;;) {
        s = skip_space(s);
        if (*s == '\0') return n;
        if (n == max) return max + 1;
        tok[n++] = s;
        while (*s && !is_space(*s)) s++;
        if (*s) *s++ = '\0';
    }
}

/* What the header says: the elements in file order and the body's format. */
typedef struct PlyHeader {
    PlyElement *els; /* PLY_MAX_ELEMENTS of them */
    int nels;
    int format;            /* FMT_*, -1 until the format line */
    long line;             /* the header line being read; at the end, end_header's */
    PlyElement *vel, *fel; /* the vertex and face elements */
    int has_normals;
} PlyHeader;

/* "format FORMAT 1.0" */
static int ply_format_line(const Ctx *c, PlyHeader *h, char **tok, int nt)
{
    if (nt != 3 || strcmp(tok[2], "1.0") != 0)
        return fail(c, ": line %ld of header: expected 'format FORMAT 1.0'", h->line);
    if (strcmp(tok[1], "ascii") == 0)
        h->format = FMT_ASCII;
    else if (strcmp(tok[1], "binary_little_endian") == 0)
        h->format = FMT_LE;
    else if (strcmp(tok[1], "binary_big_endian") == 0)
        h->format = FMT_BE;
    else
        return fail(c, ": line %ld of header: unknown format '%s'", h->line, tok[1]);
    return 0;
}

/* "element NAME COUNT" */
static int ply_element_line(const Ctx *c, PlyHeader *h, char **tok, int nt)
{
    if (nt != 3) return fail(c, ": line %ld of header: expected 'element NAME COUNT'", h->line);
    if (h->nels == PLY_MAX_ELEMENTS)
        return fail(c, ": line %ld of header: too many elements", h->line);
    char *end;
    errno = 0;
    unsigned long long cnt = strtoull(tok[2], &end, 10);
    if (tok[2][0] < '0' || tok[2][0] > '9' || *end != '\0')
        return fail(c, ": line %ld of header: bad element count '%s'", h->line, tok[2]);
    if (errno == ERANGE || cnt > 0x7fffffffull)
        return fail(c, ": line %ld of header: element count %s too large", h->line, tok[2]);
    PlyElement *el = &h->els[h->nels++];
    snprintf(el->name, sizeof el->name, "%s", tok[1]);
    el->count = cnt;
    el->kind = strcmp(tok[1], "vertex") == 0 ? 1 : strcmp(tok[1], "face") == 0 ? 2 : 0;
    for (int i = 0; i < h->nels - 1; i++)
        if (el->kind && h->els[i].kind == el->kind)
            return fail(c, ": line %ld of header: second '%s' element", h->line, tok[1]);
    return 0;
}

/* The types of "property TYPE NAME" or "property list COUNT ITEM NAME"; *name is NAME. */
static int ply_prop_types(const Ctx *c, long line, char **tok, int nt, PlyProp *pr,
                          const char **name)
{
    if (nt >= 2 && strcmp(tok[1], "list") == 0) {
        if (nt != 5)
            return fail(c, ": line %ld of header: expected 'property list COUNT ITEM NAME'", line);
        pr->count_type = ply_type(tok[2]);
        pr->type = ply_type(tok[3]);
        for (int k = 2; k <= 3; k++)
            if (ply_type(tok[k]) == T_NONE)
                return fail(c, ": line %ld of header: unknown property type '%s'", line, tok[k]);
        if (pr->count_type >= T_F32)
            return fail(c, ": line %ld of header: list count type '%s' is not an integer", line,
                        tok[2]);
        *name = tok[4];
        return 0;
    }
    if (nt != 3) return fail(c, ": line %ld of header: expected 'property TYPE NAME'", line);
    pr->type = ply_type(tok[1]);
    pr->count_type = T_NONE;
    if (pr->type == T_NONE)
        return fail(c, ": line %ld of header: unknown property type '%s'", line, tok[1]);
    *name = tok[2];
    return 0;
}

/* The role of property pr, named name, of element el: a vertex coordinate or normal
 * component, or a face's vertex indices, each at most once and of the right shape. */
static int ply_prop_role(const Ctx *c, long line, const PlyElement *el, PlyProp *pr,
                         const char *name)
{
    pr->role = ROLE_NONE;
    if (el->kind == 1) {
        static const char *vnames[] = {"x", "y", "z", "nx", "ny", "nz"};
        for (int k = 0; k < 6; k++)
            if (strcmp(name, vnames[k]) == 0) pr->role = ROLE_X + k;
    } else if (el->kind == 2) {
        if (strcmp(name, "vertex_indices") == 0 || strcmp(name, "vertex_index") == 0)
            pr->role = ROLE_INDICES;
    }
    if (pr->role == ROLE_NONE) return 0;
    for (int k = 0; k < el->nprops; k++)
        if (el->props[k].role == pr->role)
            return fail(c, ": line %ld of header: property '%s' given twice", line, name);
    if ((pr->role == ROLE_INDICES) != (pr->count_type != T_NONE))
        return fail(c, ": line %ld of header: property '%s' must %sbe a list", line, name,
                    pr->role == ROLE_INDICES ? "" : "not ");
    if (pr->role == ROLE_INDICES && pr->type >= T_F32)
        return fail(c, ": line %ld of header: vertex indices must be integers", line);
    return 0;
}

/* "property ...", added to the last element */
static int ply_property_line(const Ctx *c, PlyHeader *h, char **tok, int nt)
{
    if (h->nels == 0) return fail(c, ": line %ld of header: property before any element", h->line);
    PlyElement *el = &h->els[h->nels - 1];
    if (el->nprops == PLY_MAX_PROPS)
        return fail(c, ": line %ld of header: too many properties", h->line);
    PlyProp *pr = &el->props[el->nprops];
    const char *name = NULL;
    if (ply_prop_types(c, h->line, tok, nt, pr, &name) < 0 ||
        ply_prop_role(c, h->line, el, pr, name) < 0)
        return -1;
    el->nprops++;
    return 0;
}

/* Reads the header up to end_header; *p is left at the body. */
static int ply_header(const Ctx *c, PlyHeader *h, char **p, char *endp)
{
    for (;;) {
        if (*p >= endp) return fail(c, ": header has no end_header");
        h->line++;
        char *eol = memchr(*p, '\n', (size_t)(endp - *p));
        if (!eol) eol = endp;
        *eol = '\0';
        char *s = *p;
        *p = eol < endp ? eol + 1 : endp;
        if (h->line == 1) {
            char *t = skip_space(s);
            if (strncmp(t, "ply", 3) != 0 || *skip_space(t + 3) != '\0')
                return fail(c, ": not a PLY file (first line is not 'ply')");
            continue;
        }
        char *tok[8];
        int nt = split_tokens(s, tok, 6), r;
        if (nt == 0) continue;
        if (strcmp(tok[0], "comment") == 0 || strcmp(tok[0], "obj_info") == 0) continue;
        if (strcmp(tok[0], "end_header") == 0) break;
        if (strcmp(tok[0], "format") == 0)
            r = ply_format_line(c, h, tok, nt);
        else if (strcmp(tok[0], "element") == 0)
            r = ply_element_line(c, h, tok, nt);
        else if (strcmp(tok[0], "property") == 0)
            r = ply_property_line(c, h, tok, nt);
        else
            r = fail(c, ": line %ld of header: unknown keyword '%s'", h->line, tok[0]);
        if (r < 0) return -1;
    }
    if (h->format < 0) return fail(c, ": header has no format line");
    return 0;
}

/* The least number of bytes each element needs must fit in the left bytes of the body,
 * so absurd counts are refused before anything is allocated for them. */
static int ply_check_sizes(const Ctx *c, const PlyHeader *h, double left)
{
    double acc = 0.0;
    int exact = h->format != FMT_ASCII; /* acc is exact while no lists came before */
    for (int i = 0; i < h->nels; i++) {
        const PlyElement *el = &h->els[i];
        double per = 0.0;
        int fixed = 1;
        for (int k = 0; k < el->nprops; k++) {
            const PlyProp *pr = &el->props[k];
            fixed &= pr->count_type == T_NONE;
            if (h->format == FMT_ASCII)
                per += 2.0; /* a digit and a separator */
            else
                per += type_size[pr->count_type != T_NONE ? pr->count_type : pr->type];
        }
        if (acc + per * (double)el->count > left + (h->format == FMT_ASCII)) {
            if (exact && fixed && per > 0.0)
                return fail(c, ": unexpected end of file in %s %llu", el->name,
                            (unsigned long long)((left - acc) / per));
            return fail(c,
                        ": unexpected end of file: the header promises %llu '%s' items, more "
                        "than the remaining %.0f bytes can hold",
                        (unsigned long long)el->count, el->name, left);
        }
        acc += per * (double)el->count;
        exact &= fixed;
    }
    return 0;
}

/* What the header promises: vertices with x, y and z, faces with vertex indices, and no
 * more elements than the left bytes of the body can hold. */
static int ply_check_header(const Ctx *c, PlyHeader *h, double left)
{
    for (int i = 0; i < h->nels; i++) {
        if (h->els[i].kind == 1) h->vel = &h->els[i];
        if (h->els[i].kind == 2) h->fel = &h->els[i];
    }
    if (!h->vel) return fail(c, ": no vertex element");
    int roles = 0;
    for (int k = 0; k < h->vel->nprops; k++) roles |= 1 << h->vel->props[k].role;
    int xyz = 1 << ROLE_X | 1 << ROLE_Y | 1 << ROLE_Z;
    int nxyz = 1 << ROLE_NX | 1 << ROLE_NY | 1 << ROLE_NZ;
    if ((roles & xyz) != xyz) return fail(c, ": vertex element lacks x, y or z");
    h->has_normals = (roles & nxyz) == nxyz;
    if (!h->fel || h->fel->count == 0) return fail(c, ": no faces");
    int found = 0;
    for (int k = 0; k < h->fel->nprops; k++) found |= h->fel->props[k].role == ROLE_INDICES;
    if (!found) return fail(c, ": face element has no 'vertex_indices' list");
    if (ply_check_sizes(c, h, left) < 0) return -1;
    if (h->vel->count >= UINT32_MAX) return fail(c, ": too many vertices");
    return 0;
}

/* Reads one scalar property; a vertex's coordinates and normal are kept in vals. */
static int ply_scalar(PlyReader *r, const PlyProp *pr, float *vals)
{
    double d;
    if (ply_value(r, pr->type, &d) < 0) return -1;
    if (pr->role == ROLE_NONE) return 0;
    if (!isfinite(d) || fabs(d) > 3.4028234663852886e38) {
        char where[96];
        ply_where(r, where, sizeof where);
        return fail(r->c, "%s: non-finite coordinate", where);
    }
    vals[pr->role] = (float)d;
    return 0;
}

/* Reads one list property; a face's vertex indices (of nverts vertices) are added to m as
 * a fan of triangles. */
static int ply_list(PlyReader *r, const PlyProp *pr, uint32_t nverts, Mesh *m)
{
    char where[96];
    double d;
    if (ply_value(r, pr->count_type, &d) < 0) return -1;
    if (d < 0) {
        ply_where(r, where, sizeof where);
        return fail(r->c, "%s: negative list length", where);
    }
    uint64_t n = (uint64_t)d;
    if (r->format != FMT_ASCII && (uint64_t)(r->end - r->p) / (uint64_t)type_size[pr->type] < n)
        return ply_eof(r);
    if (pr->role == ROLE_INDICES && n < 3) {
        ply_where(r, where, sizeof where);
        return fail(r->c, "%s: has %llu vertices (need at least 3)", where, (unsigned long long)n);
    }
    uint32_t first = 0, prev = 0;
    for (uint64_t j = 0; j < n; j++) {
        if (ply_value(r, pr->type, &d) < 0) return -1;
        if (pr->role != ROLE_INDICES) continue;
        if (d < 0 || d >= (double)nverts) {
            ply_where(r, where, sizeof where);
            return fail(r->c, "%s: index %.0f out of range (%u vertices)", where, d, nverts);
        }
        uint32_t v = (uint32_t)d;
        if (j == 0)
            first = v;
        else if (j >= 2 && mesh_add_triangle(m, first, prev, v) < 0)
            return fail(r->c, ": out of memory");
        prev = v;
    }
    return 0;
}

/* Reads one item of element el; a vertex is added to m. */
static int ply_item(PlyReader *r, const PlyHeader *h, const PlyElement *el, Mesh *m)
{
    float vals[7] = {0};
    uint32_t nverts = (uint32_t)h->vel->count;
    for (int k = 0; k < el->nprops; k++) {
        const PlyProp *pr = &el->props[k];
        if ((pr->count_type == T_NONE ? ply_scalar(r, pr, vals) : ply_list(r, pr, nverts, m)) < 0)
            return -1;
    }
    if (el != h->vel) return 0;
    uint32_t v = mesh_add_vertex(m, v3(vals[ROLE_X], vals[ROLE_Y], vals[ROLE_Z]));
    if (v == UINT32_MAX) return fail(r->c, ": out of memory");
    if (h->has_normals) m->normals[v] = v3_norm(v3(vals[ROLE_NX], vals[ROLE_NY], vals[ROLE_NZ]));
    return 0;
}

/* Reads the body, from p to endp, into m. */
static int ply_body(const Ctx *c, const PlyHeader *h, char *p, char *endp, Mesh *m)
{
    PlyReader r = {
        c, h->format, (const unsigned char *)p, (const unsigned char *)endp, h->line + 1, "", 0};
    for (int i = 0; i < h->nels; i++) {
        const PlyElement *el = &h->els[i];
        r.what = el->name;
        /* an element without properties takes no bytes: nothing to read, however many */
        if (el->nprops == 0) continue;
        for (uint64_t it = 0; it < el->count; it++) {
            r.item = it;
            if (ply_item(&r, h, el, m) < 0) return -1;
        }
    }
    return 0;
}

static int load_ply(const Ctx *c, char *data, size_t len, Mesh *out)
{
    PlyHeader h = {.els = calloc(PLY_MAX_ELEMENTS, sizeof(PlyElement)), .format = -1};
    if (!h.els) return fail(c, ": out of memory");
    char *p = data, *endp = data + len;
    int rc = -1;
    Mesh m;
    mesh_init(&m);
    if (ply_header(c, &h, &p, endp) < 0 || ply_check_header(c, &h, (double)(endp - p)) < 0)
        goto done;
    if (h.has_normals && mesh_enable_normals(&m) < 0) {
        fail(c, ": out of memory");
        goto done;
    }
    if (ply_body(c, &h, p, endp, &m) < 0) goto done;
    if (m.ntris == 0)
        fail(c, ": no faces");
    else if (move_into(out, &m) < 0)
        fail(c, ": out of memory");
    else
        rc = 0;
done:
    mesh_free(&m);
    free(h.els);
    return rc;
}
int mesh_load(const char *path, Mesh *out, char *err, size_t errlen)
{
    return mesh_load_head(path, out, NULL, 0, err, errlen);
}

int mesh_load_head(const char *path, Mesh *out, char *head, size_t headlen, char *err,
                   size_t errlen)
{
    Ctx c = {path, err, errlen};
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    if (!dot || (slash && dot < slash)) return fail(&c, ": no file extension (.obj or .ply)");
    int is_obj = strcasecmp(dot, ".obj") == 0, is_ply = strcasecmp(dot, ".ply") == 0;
    if (!is_obj && !is_ply)
        return fail(&c, ": unknown mesh file extension '%s' (.obj or .ply)", dot);
    char *data = NULL;
    size_t len = 0;
    if (read_file(&c, &data, &len) < 0) return -1;
    if (head && headlen)
        snprintf(head, headlen, "%.*s", (int)(len < headlen ? len : headlen - 1), data);
    int rc = is_obj ? load_obj(&c, data, len, out) : load_ply(&c, data, len, out);
    free(data);
    return rc;
}
