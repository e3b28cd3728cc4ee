/* watertight.c — rays aimed at the edges and vertices of a closed mesh, traced on the
 * device by scene_intersect_closest (and probe_intersect_brute), checked on the host for
 * leaks; rays leaving the hit points from the kernels' offset origin, checked for
 * self-intersection. */
#include "watertight.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "offset.h"
#include "render.h"
#include "scene.h"

#define WT_BATCH 32768 /* targets per device round trip (below PoCL's large grid) */
#define WT_AIMED 3     /* aimed rays per target at most (and 2 offset rays per hit) */

typedef struct D3 {
    double x, y, z;
} D3;

static D3 d3(double x, double y, double z)
{
    D3 r = {x, y, z};
    return r;
}
static D3 d3_add(D3 a, D3 b)
{
    return d3(a.x + b.x, a.y + b.y, a.z + b.z);
}
static D3 d3_sub(D3 a, D3 b)
{
    return d3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static D3 d3_mul(D3 a, double s)
{
    return d3(a.x * s, a.y * s, a.z * s);
}
static double d3_dot(D3 a, D3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static D3 d3_cross(D3 a, D3 b)
{
    return d3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static D3 d3_norm(D3 a)
{
    double l = sqrt(d3_dot(a, a));
    return l > 0 ? d3_mul(a, 1.0 / l) : a;
}
static D3 d3_of(vec3 v)
{
    return d3(v.x, v.y, v.z);
}
static double d3_maxabs(D3 a)
{
    return fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z)));
}

/* A 64-bit LCG: uniform doubles in [0, 1). */
static double rng_uniform(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

/* A uniformly distributed unit vector. */
static D3 rng_direction(uint64_t *s)
{
    for (;;) {
        D3 v = d3(2 * rng_uniform(s) - 1, 2 * rng_uniform(s) - 1, 2 * rng_uniform(s) - 1);
        double l2 = d3_dot(v, v);
        if (l2 > 1e-6 && l2 <= 1.0) return d3_mul(v, 1.0 / sqrt(l2));
    }
}

/* The triangle's unit normal as tri_normal computes it, in float. */
static vec3 tri_normal_f(const Mesh *m, uint32_t t)
{
    vec3 a = m->verts[m->tris[3 * t]], b = m->verts[m->tris[3 * t + 1]],
         c = m->verts[m->tris[3 * t + 2]];
    vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
    float inv = 1.0f / sqrtf(v3_dot(n, n));
    return v3_scale(n, inv);
}

/* What the host needs to check the rays of one batch. */
typedef struct Aim {
    double t_aim; /* ray parameter of the aimed point */
    double tol;   /* allowed overshoot */
    int outside;  /* the ray starts outside the mesh */
} Aim;

/* The device side: the scene, its kernels and the batch buffers. */
typedef struct Tracer {
    VbDevice *d;
    Renderer r;
    cl_kernel brute;
    cl_mem rays, hits, media, radiance, counters;
    double ms;
} Tracer;

/* Whether direction d from the eye of frame f passes through its image (a camera ray). */
static int in_image(const VbFrame *f, D3 d)
{
    const VbCamera *c = &f->camera;
    D3 fw = d3(c->forward[0], c->forward[1], c->forward[2]);
    D3 r = d3(c->right[0], c->right[1], c->right[2]), u = d3(c->up[0], c->up[1], c->up[2]);
    double a = d3_dot(d, fw);
    if (!(a > 0.0)) return 0;
    double sx = d3_dot(d, r) / (d3_dot(r, r) * a), sy = d3_dot(d, u) / (d3_dot(u, u) * a);
    return fabs(sx) < 0.999 && fabs(sy) < 0.999;
}

static void set_ray(VbRay *r, D3 org, D3 dir)
{
    r->org[0] = (float)org.x, r->org[1] = (float)org.y, r->org[2] = (float)org.z;
    r->dir[0] = (float)dir.x, r->dir[1] = (float)dir.y, r->dir[2] = (float)dir.z;
    r->tmax = INFINITY;
    r->sample = 0;
}

/* Traces n rays with the grid kernel (brute = 0) or brute force (brute = 1). */
static int tracer_trace(Tracer *tr, const VbRay *rays, int n, VbHit *hits, int brute, char *err,
                        size_t errlen)
{
    if (n == 0) return 0;
    double t0 = clu_now_ms();
    cl_command_queue q = tr->d->queue;
    cl_int rc = clEnqueueWriteBuffer(q, tr->rays, CL_FALSE, 0, sizeof *rays * (size_t)n, rays, 0,
                                     NULL, NULL);
    cl_kernel k = brute ? tr->brute : tr->r.k_intersect;
    cl_uint ntris = tr->r.frame_host.ntris;
    if (brute) {
        const void *v[] = {&tr->r.buf.tris, &ntris, &tr->rays, &n, &tr->hits};
        const size_t sz[] = {sizeof(cl_mem), sizeof(cl_uint), sizeof(cl_mem), sizeof(int),
                             sizeof(cl_mem)};
        for (cl_uint i = 0; i < 5 && rc == CL_SUCCESS; i++) rc = clSetKernelArg(k, i, sz[i], v[i]);
    } else {
        if (renderer_set_frame_args(&tr->r, k, tr->rays, n, tr->hits, tr->media, tr->radiance,
                                    tr->counters))
            rc = CL_INVALID_KERNEL_ARGS;
    }
    size_t global = ((size_t)n + 63) / 64 * 64;
    if (rc == CL_SUCCESS)
        rc = clEnqueueNDRangeKernel(q, k, 1, NULL, &global, renderer_local(&tr->r, global), 0, NULL,
                                    NULL);
    if (rc == CL_SUCCESS)
        rc = clEnqueueReadBuffer(q, tr->hits, CL_TRUE, 0, sizeof *hits * (size_t)n, hits, 0, NULL,
                                 NULL);
    tr->ms += clu_now_ms() - t0;
    if (rc != CL_SUCCESS) {
        snprintf(err, errlen, "tracing %d rays (%s): %s", n, brute ? "brute force" : "grid",
                 clu_error_name(rc));
        return -1;
    }
    return 0;
}

static void tracer_close(Tracer *tr)
{
    if (tr->brute) clReleaseKernel(tr->brute);
    if (tr->rays) clReleaseMemObject(tr->rays);
    if (tr->hits) clReleaseMemObject(tr->hits);
    if (tr->counters) clReleaseMemObject(tr->counters);
    if (tr->media) clReleaseMemObject(tr->media);
    if (tr->radiance) clReleaseMemObject(tr->radiance);
    renderer_release(&tr->r);
    memset(tr, 0, sizeof *tr);
}

static int tracer_open(Tracer *tr, VbDevice *d, const Scene *s, char *err, size_t errlen)
{
    memset(tr, 0, sizeof *tr);
    tr->d = d;
    RenderStats st;
    memset(&st, 0, sizeof st);
    if (renderer_init(&tr->r, d, s, vbcl_probe_source, &st, err, errlen)) {
        memset(&tr->r, 0, sizeof tr->r);
        return -1;
    }
    cl_int rc = clEnqueueWriteBuffer(d->queue, tr->r.buf.frame, CL_TRUE, 0, sizeof(VbFrame),
                                     &tr->r.frame_host, 0, NULL, NULL);
    cl_int rc2, rc3, rc4, rc5;
    tr->brute = clCreateKernel(tr->r.probe, "probe_intersect_brute", &rc2);
    tr->rays = clCreateBuffer(d->context, CL_MEM_READ_ONLY, sizeof(VbRay) * 2 * WT_AIMED * WT_BATCH,
                              NULL, &rc3);
    tr->hits = clCreateBuffer(d->context, CL_MEM_WRITE_ONLY,
                              sizeof(VbHit) * 2 * WT_AIMED * WT_BATCH, NULL, &rc4);
    cl_uint zero[VBCL_COUNTER_WORDS] = {0};
    tr->counters = clCreateBuffer(d->context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, sizeof zero,
                                  zero, &rc5);
    cl_int rc6, rc7;
    tr->media = clCreateBuffer(d->context, CL_MEM_READ_WRITE,
                               sizeof(VbMedium) * 2 * WT_AIMED * WT_BATCH, NULL, &rc6);
    tr->radiance = clCreateBuffer(d->context, CL_MEM_READ_WRITE,
                                  sizeof(float) * 4 * 2 * WT_AIMED * WT_BATCH, NULL, &rc7);
    rc5 = rc5 ? rc5 : rc6 ? rc6 : rc7;
    if (rc || rc2 || rc3 || rc4 || rc5) {
        snprintf(err, errlen, "setting up the tracer: %s %s %s %s %s", clu_error_name(rc),
                 clu_error_name(rc2), clu_error_name(rc3), clu_error_name(rc4),
                 clu_error_name(rc5));
        tracer_close(tr);
        return -1;
    }
    return 0;
}

/* Triangles around each vertex position, as offsets into one list. Vertices are welded
 * by exact position first: shapes duplicate them where flat caps meet smooth walls, and
 * closedness (mesh_check_closed) is a matter of positions. */
typedef struct Adjacency {
    uint32_t *weld;  /* per vertex: the lowest index of a vertex at the same position */
    uint32_t *start; /* nverts + 1, by welded index */
    uint32_t *tris;
    uint32_t *part; /* per triangle: its connected piece (a texture's element), as a welded
                       vertex index */
} Adjacency;

/* The root of welded vertex v in the union-find forest up (path halving). */
static uint32_t part_root(uint32_t *up, uint32_t v)
{
    while (up[v] != v) v = up[v] = up[up[v]];
    return v;
}

static const Mesh *weld_mesh; /* for the qsort comparison */

static int weld_compare(const void *pa, const void *pb)
{
    uint32_t a = *(const uint32_t *)pa, b = *(const uint32_t *)pb;
    const vec3 *va = &weld_mesh->verts[a], *vb = &weld_mesh->verts[b];
    int c = memcmp(va, vb, sizeof *va);
    return c ? c : (a > b) - (a < b);
}

static int adjacency_build(Adjacency *a, const Mesh *m)
{
    size_t nv = m->nverts;
    a->weld = malloc(sizeof *a->weld * (nv + 1));
    a->start = calloc(nv + 1, sizeof *a->start);
    a->tris = malloc(sizeof *a->tris * 3 * (size_t)m->ntris + 1);
    uint32_t *order = malloc(sizeof *order * (nv + 1));
    uint32_t *fill = malloc(sizeof *fill * (nv + 1));
    if (!a->weld || !a->start || !a->tris || !order || !fill) {
        free(order);
        free(fill);
        return -1;
    }
    for (uint32_t v = 0; v < nv; v++) order[v] = v;
    weld_mesh = m;
    qsort(order, nv, sizeof *order, weld_compare);
    for (size_t i = 0; i < nv; i++)
        a->weld[order[i]] =
            (i > 0 && !memcmp(&m->verts[order[i]], &m->verts[order[i - 1]], sizeof(vec3)))
                ? a->weld[order[i - 1]]
                : order[i];
    for (uint32_t i = 0; i < 3 * m->ntris; i++) a->start[a->weld[m->tris[i]] + 1]++;
    for (size_t v = 0; v < nv; v++) a->start[v + 1] += a->start[v];
    memcpy(fill, a->start, sizeof *fill * (nv + 1));
    for (uint32_t i = 0; i < 3 * m->ntris; i++) a->tris[fill[a->weld[m->tris[i]]]++] = i / 3;
    /* pieces: the triangles joined through shared (welded) vertices */
    a->part = malloc(sizeof *a->part * ((size_t)m->ntris + 1));
    if (!a->part) {
        free(order);
        free(fill);
        return -1;
    }
    for (size_t v = 0; v < nv; v++) fill[v] = (uint32_t)v;
    for (uint32_t t = 0; t < m->ntris; t++)
        for (int k = 1; k < 3; k++) {
            uint32_t r0 = part_root(fill, a->weld[m->tris[3 * t]]),
                     rk = part_root(fill, a->weld[m->tris[3 * t + k]]);
            fill[rk] = r0;
        }
    for (uint32_t t = 0; t < m->ntris; t++) a->part[t] = part_root(fill, a->weld[m->tris[3 * t]]);
    free(order);
    free(fill);
    return 0;
}

static int tri_has_vertex(const Mesh *m, const Adjacency *adj, uint32_t t, uint32_t v)
{
    for (int k = 0; k < 3; k++)
        if (adj->weld[m->tris[3 * t + k]] == v) return 1;
    return 0;
}

/* Whether the offset from p (on triangle src) to o crosses the plane of a triangle that
 * shares a corner with src, or p or o lies within p's rounding (8 units of its largest
 * coordinate) of such a plane: p on the edge the two share, or the origin on the plane. */
static int offset_crosses_neighbour(const Mesh *m, const Adjacency *adj, const D3 *normals, int src,
                                    D3 p, D3 o)
{
    double tol = 8.0 * FLT_EPSILON * d3_maxabs(p);
    for (int k = 0; k < 3; k++) {
        uint32_t v = adj->weld[m->tris[3 * (uint32_t)src + k]];
        for (uint32_t i = adj->start[v]; i < adj->start[v + 1]; i++) {
            uint32_t t = adj->tris[i];
            if ((int)t == src) continue;
            D3 a = d3_of(m->verts[m->tris[3 * t]]);
            double sp = d3_dot(d3_sub(p, a), normals[t]), so = d3_dot(d3_sub(o, a), normals[t]);
            if ((sp > 0.0) != (so > 0.0) || fabs(so) <= tol || fabs(sp) <= tol) return 1;
        }
    }
    return 0;
}

/* Picks a random edge or vertex point of a random triangle and the unit normals of the
 * triangles that meet there (at most 64); returns how many, and the shortest edge from p. */
static int target_pick(const Mesh *m, const Adjacency *adj, const D3 *normals, uint64_t *rng, D3 *p,
                       D3 *nrm, double *edge)
{
    uint32_t t = (uint32_t)(rng_uniform(rng) * m->ntris) % m->ntris;
    int k = (int)(rng_uniform(rng) * 3) % 3;
    uint32_t va = adj->weld[m->tris[3 * t + k]], vb = adj->weld[m->tris[3 * t + (k + 1) % 3]];
    D3 a = d3_of(m->verts[va]), b = d3_of(m->verts[vb]);
    int n = 0;
    if (rng_uniform(rng) < 1.0 / 3.0) { /* a vertex: every triangle around it */
        *p = a;
        *edge = INFINITY;
        for (uint32_t i = adj->start[va]; i < adj->start[va + 1] && n < 64; i++) {
            uint32_t u = adj->tris[i];
            nrm[n++] = normals[u];
            for (int j = 0; j < 3; j++) {
                D3 q = d3_of(m->verts[m->tris[3 * u + j]]);
                double l = sqrt(d3_dot(d3_sub(q, a), d3_sub(q, a)));
                if (l > 0) *edge = fmin(*edge, l);
            }
        }
    } else { /* an edge: its midpoint or a random point on it, the two triangles */
        double s = rng_uniform(rng) < 0.5 ? 0.5 : 0.02 + 0.96 * rng_uniform(rng);
        *p = d3_add(a, d3_mul(d3_sub(b, a), s));
        *edge = sqrt(d3_dot(d3_sub(b, a), d3_sub(b, a))) * fmin(s, 1 - s);
        for (uint32_t i = adj->start[va]; i < adj->start[va + 1] && n < 64; i++)
            if (tri_has_vertex(m, adj, adj->tris[i], vb)) nrm[n++] = normals[adj->tris[i]];
    }
    return n;
}

/* A direction that crosses every plane in nrm with |cos| >= 0.1, entering (sign -1) or
 * leaving (+1), near the mean normal; 0 when none was found. */
static int crossing_direction(const D3 *nrm, int n, double sign, uint64_t *rng, D3 *dir)
{
    D3 mean = d3(0, 0, 0);
    for (int i = 0; i < n; i++) mean = d3_add(mean, nrm[i]);
    mean = d3_mul(d3_norm(mean), sign);
    for (int tries = 0; tries < 12; tries++) {
        double jitter = tries < 8 ? 0.6 : 0.0;
        D3 d = d3_norm(d3_add(mean, d3_mul(rng_direction(rng), jitter)));
        int ok = 1;
        for (int i = 0; i < n && ok; i++) ok = sign * d3_dot(d, nrm[i]) >= 0.1;
        if (ok) {
            *dir = d;
            return 1;
        }
    }
    return 0;
}

const WtShape watertight_shapes[] = {
    {"icosahedron", "\"shape\": \"sphere\", \"level\": 0", 1, 1.6},
    {"sphere-2", "\"shape\": \"sphere\", \"level\": 2", 1, 1.9},
    {"sphere-4", "\"shape\": \"sphere\", \"level\": 4", 1, 2},
    {"vase",
     "\"shape\": \"revolution\", \"segments\": 24, \"profile\": [[0, -1.1], [0.45, "
     "-1.1], [0.75, -0.75], [0.85, -0.25], [0.62, 0.35], [0.34, 0.75], [0.3, 0.95], "
     "[0.42, 1.15]]",
     0, 0.6},
    {"spindle",
     "\"shape\": \"revolution\", \"segments\": 12, \"profile\": [[0, -1], [1, 0], "
     "[0, 1]]",
     1, 2},
    {"prism", "\"shape\": \"prism\", \"depth\": 1.5", 1, 0.87},
    {"sliver-prism", "\"shape\": \"prism\", \"points\": [[-0.5, 0], [0.5, 0], [0, 0.01]]", 1, 0.01},
    {"box", "\"shape\": \"box\", \"size\": [1, 2, 3]", 1, 1},
    {"flat-box", "\"shape\": \"box\", \"size\": [1, 0.001, 1]", 1, 0.001},
};
const int watertight_nshapes = (int)(sizeof watertight_shapes / sizeof watertight_shapes[0]);

void watertight_scene_json(const char *object, double scale, const double offset[3],
                           int look_origin, char *out, size_t n)
{
    double at[3] = {offset[0], offset[1], offset[2]};
    if (look_origin) at[0] = at[1] = at[2] = 0.0;
    snprintf(out, n,
             "{\"camera\": {\"eye\": [%.17g, %.17g, %.17g], \"look_at\": [%.17g, %.17g, %.17g]},\n"
             " \"materials\": {\"m\": {}},\n"
             " \"objects\": [{%s, \"material\": \"m\",\n"
             "   \"transform\": {\"scale\": %.17g, \"rotate\": [17, 29, 41],"
             " \"translate\": [%.17g, %.17g, %.17g]}}]}\n",
             at[0], at[1], at[2] + 10.0 * scale, at[0], at[1], at[2], object, scale, offset[0],
             offset[1], offset[2]);
}

void watertight_case(int k, WtCase *c)
{
    static const double scales[] = {1e-6, 1e-3, 1.0, 1e4, 1e6}, far[] = {1e3, 1e4, 1e5};
    memset(c, 0, sizeof *c);
    if (k < 10) {
        int moved = k % 2;
        c->scale = scales[k / 2];
        c->offset[0] = moved * 50 * c->scale;
        c->offset[1] = moved * -30 * c->scale;
        c->offset[2] = moved * 40 * c->scale;
        c->label = moved ? "moved" : "";
    } else {
        double d = far[(k - 10) % 3];
        c->scale = 1.0;
        c->offset[0] = 0.6 * d, c->offset[1] = -0.48 * d, c->offset[2] = 0.64 * d;
        c->look_origin = 1;
        c->label = d == 1e3 ? "1e3 away" : d == 1e4 ? "1e4 away" : "1e5 away";
    }
}

int watertight_case_fits(const WtShape *sh, const WtCase *c)
{
    double far = 0.0;
    for (int k = 0; k < 3; k++) far = fmax(far, fabs(c->offset[k]));
    if (!c->look_origin) return 1; /* the scene's frame brings it to the origin at unit size */
    return sh->thin * c->scale >= 64.0 * FLT_EPSILON * (far + 2.0 * c->scale);
}

/* Checks the aimed rays' hits; appends rays leaving the good hits to out, with the medium
 * they travel in and their source triangle. Returns the number of leaks. */
static unsigned long long check_aimed(const Mesh *m, const D3 *normals, const VbRay *rays,
                                      const Aim *aim, const VbHit *hits, int n, uint64_t *rng,
                                      VbRay *out, int *src, int *outside, D3 *from, int *nout)
{
    unsigned long long leaks = 0;
    for (int i = 0; i < n; i++) {
        const VbHit *h = &hits[i];
        D3 dir = d3(rays[i].dir[0], rays[i].dir[1], rays[i].dir[2]);
        int leak = h->tri < 0 || h->t > aim[i].t_aim + aim[i].tol;
        /* from outside, a back face first is a leak unless it ties with the aimed point
         * (two triangles of an edge at the same t: either may be reported) */
        if (!leak && aim[i].outside)
            leak = d3_dot(dir, normals[h->tri]) > 1e-4 && h->t < aim[i].t_aim - aim[i].tol;
        leaks += (unsigned long long)leak;
        if (leak && getenv("VBCL_WT_VERBOSE"))
            fprintf(
                stderr,
                "      leak: %s ray org (%.9g %.9g %.9g) dir (%.9g %.9g %.9g): aimed t %.9g, hit "
                "triangle %d t %.9g facing %.3g\n",
                aim[i].outside ? "outside" : "inside", rays[i].org[0], rays[i].org[1],
                rays[i].org[2], dir.x, dir.y, dir.z, aim[i].t_aim, h->tri, h->t,
                h->tri >= 0 ? d3_dot(dir, normals[h->tri]) : 0.0);
        if (leak || !out) continue;
        /* the hit point and the offset origin as the kernels compute them */
        uint32_t t = (uint32_t)h->tri;
        vec3 a = m->verts[m->tris[3 * t]], b = m->verts[m->tris[3 * t + 1]],
             c = m->verts[m->tris[3 * t + 2]];
        float w0 = 1.0f - h->u - h->v;
        vec3 p = v3_add(v3_add(v3_scale(a, w0), v3_scale(b, h->u)), v3_scale(c, h->v));
        vec3 ng = tri_normal_f(m, t);
        float side = v3_dot(ng, v3((float)dir.x, (float)dir.y, (float)dir.z)) < 0.0f ? 1.0f : -1.0f;
        vec3 nf = v3_scale(ng, side);
        /* ray_offset_origin with tri_point_error (kernels/geometry.cl), from offset.h, the
         * kernels' own arithmetic */
        float err = vb_offset_error(ng.x, ng.y, ng.z, vb_offset_sum(w0, h->u, h->v, a.x, b.x, c.x),
                                    vb_offset_sum(w0, h->u, h->v, a.y, b.y, c.y),
                                    vb_offset_sum(w0, h->u, h->v, a.z, b.z, c.z));
        vec3 q = v3(vb_offset_coord(p.x, nf.x, err), vb_offset_coord(p.y, nf.y, err),
                    vb_offset_coord(p.z, nf.z, err));
        D3 org = d3(q.x, q.y, q.z);
        D3 hemi = rng_direction(rng);
        if (d3_dot(hemi, d3_of(nf)) < 0) hemi = d3_mul(hemi, -1);
        set_ray(&out[*nout], org, d3_of(nf));
        set_ray(&out[*nout + 1], org, hemi);
        src[*nout] = src[*nout + 1] = h->tri;
        outside[*nout] = outside[*nout + 1] = side > 0; /* leaving on the front: outside */
        from[*nout] = from[*nout + 1] = d3_of(p);
        *nout += 2;
    }
    return leaks;
}

int watertight_run(VbDevice *d, const char *scene_path, int convex, long targets, unsigned seed,
                   int brute_every, WtStats *st, char *err, size_t errlen)
{
    Scene s;
    Tracer tr;
    Adjacency adj = {NULL, NULL, NULL, NULL};
    int rc = -1, tracer_ok = 0;
    memset(&tr, 0, sizeof tr);
    if (scene_load(scene_path, &s, err, errlen)) return -1;
    const Mesh *m = &s.mesh;
    char cerr[512];
    VbRay *rays = malloc(sizeof *rays * WT_AIMED * WT_BATCH);
    VbRay *brays = malloc(sizeof *brays * WT_AIMED * WT_BATCH);
    VbRay *orays = malloc(sizeof *orays * 2 * WT_AIMED * WT_BATCH);
    VbHit *hits = malloc(sizeof *hits * 2 * WT_AIMED * WT_BATCH);
    VbHit *bhits = malloc(sizeof *bhits * WT_AIMED * WT_BATCH);
    Aim *aim = malloc(sizeof *aim * WT_AIMED * WT_BATCH);
    Aim *baim = malloc(sizeof *baim * WT_AIMED * WT_BATCH);
    int *src = malloc(sizeof *src * 2 * WT_AIMED * WT_BATCH),
        *outside = malloc(sizeof *outside * 2 * WT_AIMED * WT_BATCH);
    D3 *from = malloc(sizeof *from * 2 * WT_AIMED * WT_BATCH);
    D3 *normals = malloc(sizeof *normals * ((size_t)m->ntris + 1));
    if (!rays || !brays || !orays || !hits || !bhits || !aim || !baim || !src || !outside ||
        !from || !normals || adjacency_build(&adj, m)) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    if (mesh_check_closed(m, cerr, sizeof cerr)) {
        snprintf(err, errlen, "%s: not a closed mesh: %s", scene_path, cerr);
        goto done;
    }
    for (uint32_t t = 0; t < m->ntris; t++) {
        D3 a = d3_of(m->verts[m->tris[3 * t]]), b = d3_of(m->verts[m->tris[3 * t + 1]]),
           c = d3_of(m->verts[m->tris[3 * t + 2]]);
        normals[t] = d3_norm(d3_cross(d3_sub(b, a), d3_sub(c, a)));
    }
    if (tracer_open(&tr, d, &s, err, errlen)) goto done;
    tracer_ok = 1;
    vec3 lo, hi;
    mesh_bounds(m, &lo, &hi);
    D3 ext = d3_sub(d3_of(hi), d3_of(lo));
    double extent = sqrt(d3_dot(ext, ext));
    const float *ce = tr.r.frame_host.camera.eye;
    D3 eye = d3(ce[0], ce[1], ce[2]);
    int eye_out = eye.x < lo.x || eye.x > hi.x || eye.y < lo.y || eye.y > hi.y || eye.z < lo.z ||
                  eye.z > hi.z;
    uint64_t rng = 0x9e3779b97f4a7c15ull ^ ((uint64_t)seed << 17);
    for (long done_targets = 0; done_targets < targets;) {
        long nb = targets - done_targets < WT_BATCH ? targets - done_targets : WT_BATCH;
        int n = 0, nbrute = 0, nout = 0;
        for (long i = 0; i < nb; i++) {
            D3 p, nrm[64], din, dout;
            double edge;
            int k = target_pick(m, &adj, normals, &rng, &p, nrm, &edge);
            if (!k || !crossing_direction(nrm, k, -1.0, &rng, &din) ||
                !crossing_direction(nrm, k, 1.0, &rng, &dout)) {
                st->skipped++;
                continue;
            }
            /* from far outside, entering at p; from just inside, leaving at p */
            D3 o_far = d3_sub(p, d3_mul(din, 2.0 * extent));
            /* the inside origin must lie clearly before p in float, else only the ray
             * from outside is fired */
            double back = 0.25 * fmin(edge, extent);
            int inner = back >= 1024 * FLT_EPSILON * (d3_maxabs(p) + extent);
            st->skipped += (unsigned long long)!inner;
            D3 org[3] = {o_far}, dir[3] = {din};
            int outer[3] = {1}, nrays = 1;
            if (inner) {
                org[nrays] = d3_sub(p, d3_mul(dout, back)), dir[nrays] = dout;
                outer[nrays++] = 0;
            }
            /* a camera ray, where it crosses the surface at p as cleanly as the others */
            D3 to_p = d3_norm(d3_sub(p, eye));
            int clean = eye_out && in_image(&tr.r.frame_host, to_p);
            for (int f = 0; f < k && clean; f++) clean = d3_dot(to_p, nrm[f]) <= -0.1;
            if (clean) {
                org[nrays] = eye, dir[nrays] = to_p;
                outer[nrays++] = 2;
            }
            for (int j = 0; j < nrays; j++) {
                set_ray(&rays[n], org[j], dir[j]);
                D3 of = d3(rays[n].org[0], rays[n].org[1], rays[n].org[2]);
                D3 df = d3(rays[n].dir[0], rays[n].dir[1], rays[n].dir[2]);
                aim[n].t_aim = d3_dot(d3_sub(p, of), df) / d3_dot(df, df);
                aim[n].tol = 1e-4 * (d3_maxabs(of) + d3_maxabs(p) + aim[n].t_aim);
                aim[n].outside = outer[j] != 0;
                st->camera_aimed += outer[j] == 2;
                if (brute_every > 0 && (done_targets + i) % brute_every == 0) {
                    brays[nbrute] = rays[n];
                    baim[nbrute++] = aim[n];
                }
                n++;
            }
        }
        done_targets += nb;
        if (tracer_trace(&tr, rays, n, hits, 0, err, errlen)) goto done;
        st->aimed += (unsigned long long)n;
        st->leaks +=
            check_aimed(m, normals, rays, aim, hits, n, &rng, orays, src, outside, from, &nout);
        if (nbrute) {
            if (tracer_trace(&tr, brays, nbrute, bhits, 1, err, errlen)) goto done;
            st->brute_aimed += (unsigned long long)nbrute;
            st->brute_leaks += check_aimed(m, normals, brays, baim, bhits, nbrute, &rng, NULL, NULL,
                                           NULL, NULL, NULL);
        }
        /* rays leaving the hit points */
        if (tracer_trace(&tr, orays, nout, hits, 0, err, errlen)) goto done;
        st->offset_rays += (unsigned long long)nout;
        for (int i = 0; i < nout; i++) {
            const VbHit *h = &hits[i];
            if (h->tri < 0) continue;
            /* another piece (a texture's elements may overlap): inside and outside are each
             * piece's own, and this test knows nothing of the union */
            if (adj.part[h->tri] != adj.part[src[i]]) {
                st->other_piece++;
                continue;
            }
            D3 dir = d3(orays[i].dir[0], orays[i].dir[1], orays[i].dir[2]);
            double facing = d3_dot(dir, normals[h->tri]);
            /* a ray along a triangle's plane to within its direction's rounding (the shear
             * the test applies rounds it by as much) meets it or not as that rounding goes */
            if (fabs(facing) <= 4.0 * FLT_EPSILON) {
                st->grazing++;
                continue;
            }
            /* in the outside medium the first hit is a front face, inside a back face */
            int wrong = outside[i] ? facing > 1e-6 : facing < -1e-6;
            int suspect =
                h->tri == src[i] || (wrong && h->t < 1e-3 * extent) || (convex && outside[i]);
            if (!suspect) continue;
            /* does the ray cross that triangle's plane ahead, in double? If so the origin
             * really lies in the wrong medium (the offset carried it across a neighbour);
             * if not, the kernel reported a hit that is not there */
            D3 o = d3(orays[i].org[0], orays[i].org[1], orays[i].org[2]);
            D3 a = d3_of(m->verts[m->tris[3 * h->tri]]);
            double t_plane =
                fabs(facing) > 1e-12 ? d3_dot(d3_sub(a, o), normals[h->tri]) / facing : -1.0;
            double tol = 1e-6 * (d3_maxabs(o) + extent) / fmax(fabs(facing), 1e-3);
            int escaped = h->tri != src[i] && t_plane > -tol;
            if (escaped && outside[i])
                st->escapes_out++;
            else if (escaped)
                st->escapes++;
            else
                st->self_hits++;
            /* explained: the offset from the hit point to the origin crosses the plane of a
             * triangle around the start triangle's corners, or the hit point or the origin
             * lies within the point's rounding of one (8 units of its largest coordinate):
             * the hit point on an edge, and the offset, carried the origin past a
             * neighbour's face */
            if (escaped && !offset_crosses_neighbour(m, &adj, normals, src[i], from[i], o)) {
                st->escapes_unexplained++;
                if (getenv("VBCL_WT_VERBOSE"))
                    fprintf(stderr, "      unexplained: triangle %d from %d, offset %.3g\n", h->tri,
                            src[i], sqrt(d3_dot(d3_sub(o, from[i]), d3_sub(o, from[i]))));
            }
            if (getenv("VBCL_WT_VERBOSE"))
                fprintf(stderr,
                        "      %s: %s ray %s from triangle %d: hit triangle %d at t %.3g (size "
                        "%.3g), facing %.3g; its plane at t %.3g in double\n",
                        escaped ? "escape" : "self-hit", outside[i] ? "outside" : "inside",
                        i % 2 ? "random" : "normal", src[i], h->tri, h->t, extent, facing, t_plane);
        }
    }
    rc = 0;
done:
    st->seconds += tr.ms * 1e-3;
    if (tracer_ok) tracer_close(&tr);
    free(rays);
    free(brays);
    free(orays);
    free(hits);
    free(bhits);
    free(aim);
    free(baim);
    free(src);
    free(outside);
    free(from);
    free(normals);
    free(adj.weld);
    free(adj.start);
    free(adj.tris);
    free(adj.part);
    scene_free(&s);
    return rc;
}
