/* bench_embree.c — the Embree side of the ray-throughput bench: an Embree 3 BVH over the
 * scene's world-space triangles and single-ray tracing on worker threads. */
#include "bench_embree.h"

#include <stdio.h>

#ifdef VBCL_HAVE_EMBREE
#include <embree3/rtcore.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "offset.h"

struct BenchEmbree {
    RTCDevice device;
    RTCScene scene;
    const Mesh *mesh;
};

int bench_embree_available(void)
{
    return 1;
}

const char *bench_embree_describe(void)
{
    static char text[128];
    snprintf(text, sizeof text, "Embree %d.%d.%d, one triangle geometry, build quality high",
             RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH);
    return text;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

BenchEmbree *bench_embree_open(const Mesh *m, int robust, int threads, double *build_ms, char *err,
                               size_t errlen)
{
    char config[64];
    snprintf(config, sizeof config, "threads=%d", threads);
    BenchEmbree *e = calloc(1, sizeof *e);
    if (!e) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    e->mesh = m;
    e->device = rtcNewDevice(config);
    if (!e->device) {
        snprintf(err, errlen, "rtcNewDevice(\"%s\") failed: error %d", config,
                 (int)rtcGetDeviceError(NULL));
        free(e);
        return NULL;
    }
    double t0 = now_ms();
    e->scene = rtcNewScene(e->device);
    rtcSetSceneFlags(e->scene, robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(e->scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry g = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                       4 * sizeof(float), m->nverts);
    unsigned *idx = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                            3 * sizeof(unsigned), m->ntris);
    if (!v || !idx) {
        snprintf(err, errlen, "Embree: out of memory for %u triangles", m->ntris);
        rtcReleaseGeometry(g);
        bench_embree_close(e);
        return NULL;
    }
    for (uint32_t i = 0; i < m->nverts; i++) {
        v[4 * i] = m->verts[i].x;
        v[4 * i + 1] = m->verts[i].y;
        v[4 * i + 2] = m->verts[i].z;
        v[4 * i + 3] = 0.0f;
    }
    memcpy(idx, m->tris, sizeof(unsigned) * 3 * (size_t)m->ntris);
    rtcCommitGeometry(g);
    rtcAttachGeometry(e->scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(e->scene);
    *build_ms = now_ms() - t0;
    enum RTCError rc = rtcGetDeviceError(e->device);
    if (rc != RTC_ERROR_NONE) {
        snprintf(err, errlen, "Embree: building the BVH failed: error %d", (int)rc);
        bench_embree_close(e);
        return NULL;
    }
    return e;
}

void bench_embree_close(BenchEmbree *e)
{
    if (!e) return;
    if (e->scene) rtcReleaseScene(e->scene);
    if (e->device) rtcReleaseDevice(e->device);
    free(e);
}

/* One ray of VbRay r from org o with tfar, tnear 0. */
static void make_ray(struct RTCRay *ray, const float o[3], const float d[3], float tfar)
{
    ray->org_x = o[0];
    ray->org_y = o[1];
    ray->org_z = o[2];
    ray->tnear = 0.0f;
    ray->dir_x = d[0];
    ray->dir_y = d[1];
    ray->dir_z = d[2];
    ray->time = 0.0f;
    ray->tfar = tfar;
    ray->mask = 0xffffffffu;
    ray->id = 0;
    ray->flags = 0;
}

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* kernels/geometry.cl ray_offset_origin on the host, with offset.h's arithmetic: p moved
 * off its surface along n (unit, on the side to leave toward) by err, the bound of p's
 * distance from the triangle's plane, and one float further. */
static void offset_origin(const float p[3], const float n[3], float err, float q[3])
{
    for (int k = 0; k < 3; k++) q[k] = vb_offset_coord(p[k], n[k], err);
}

/* The hit point of a triangle at barycentrics (u, v), its unit normal turned along d, and
 * the bound of the point's distance from the plane, as the kernels compute them (tri_point,
 * tri_normal, tri_point_error). */
static void hit_geometry(const Mesh *m, unsigned tri, float u, float v, const float d[3],
                         float p[3], float ng[3], float *err)
{
    const vec3 *a = &m->verts[m->tris[3 * tri]], *b = &m->verts[m->tris[3 * tri + 1]],
               *c = &m->verts[m->tris[3 * tri + 2]];
    float va[3] = {a->x, a->y, a->z}, vb[3] = {b->x, b->y, b->z}, vc[3] = {c->x, c->y, c->z};
    float e1[3], e2[3], s[3], w0 = 1.0f - u - v;
    for (int k = 0; k < 3; k++) {
        p[k] = w0 * va[k] + u * vb[k] + v * vc[k];
        e1[k] = vb[k] - va[k];
        e2[k] = vc[k] - va[k];
        s[k] = vb_offset_sum(w0, u, v, va[k], vb[k], vc[k]);
    }
    ng[0] = e1[1] * e2[2] - e1[2] * e2[1];
    ng[1] = e1[2] * e2[0] - e1[0] * e2[2];
    ng[2] = e1[0] * e2[1] - e1[1] * e2[0];
    float len = sqrtf(dot3(ng, ng)), side = dot3(ng, d) > 0.0f ? 1.0f : -1.0f;
    for (int k = 0; k < 3; k++) ng[k] *= side / len;
    *err = vb_offset_error(ng[0], ng[1], ng[2], s[0], s[1], s[2]);
}

/* EMBREE_WALK for one ray: up to `steps` closest hits from crossing to crossing. */
static float walk_one(const BenchEmbree *e, struct RTCIntersectContext *ctx, const VbRay *r,
                      uint32_t steps)
{
    float o[3] = {r->org[0], r->org[1], r->org[2]}, left = r->tmax, end = -1.0f;
    for (uint32_t s = 0; s < steps; s++) {
        struct RTCRayHit rh;
        make_ray(&rh.ray, o, r->dir, left);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(e->scene, ctx, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return -1.0f;
        float p[3], ng[3], err;
        hit_geometry(e->mesh, rh.hit.primID, rh.hit.u, rh.hit.v, r->dir, p, ng, &err);
        float from_org[3] = {p[0] - r->org[0], p[1] - r->org[1], p[2] - r->org[2]};
        float from_o[3] = {p[0] - o[0], p[1] - o[1], p[2] - o[2]};
        end = dot3(from_org, r->dir);
        left -= fmaxf(0.0f, dot3(from_o, r->dir));
        offset_origin(p, ng, err, o);
    }
    return end;
}

/* The work shared by the threads: rays handed out in chunks. */
typedef struct TraceJob {
    const BenchEmbree *e;
    EmbreeOp op;
    const VbRay *rays;
    size_t n;
    const uint32_t *steps;
    float *out;
    int32_t *prim;
    atomic_size_t next;
} TraceJob;

#define TRACE_CHUNK 256

static void trace_range(TraceJob *job, struct RTCIntersectContext *ctx, size_t lo, size_t hi)
{
    for (size_t i = lo; i < hi; i++) {
        const VbRay *r = &job->rays[i];
        if (job->op == EMBREE_WALK) {
            job->out[i] = walk_one(job->e, ctx, r, job->steps[i]);
        } else if (job->op == EMBREE_OCCLUDED) {
            struct RTCRay ray;
            make_ray(&ray, r->org, r->dir, r->tmax);
            rtcOccluded1(job->e->scene, ctx, &ray);
            job->out[i] = ray.tfar < 0.0f ? 1.0f : 0.0f; /* tfar = -inf when blocked */
        } else {
            struct RTCRayHit rh;
            make_ray(&rh.ray, r->org, r->dir, r->tmax);
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(job->e->scene, ctx, &rh);
            int hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
            job->out[i] = hit ? rh.ray.tfar : -1.0f;
            if (job->prim) job->prim[i] = hit ? (int32_t)rh.hit.primID : -1;
        }
    }
}

static void *trace_worker(void *arg)
{
    TraceJob *job = arg;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (;;) {
        size_t lo = atomic_fetch_add(&job->next, TRACE_CHUNK);
        if (lo >= job->n) break;
        size_t hi = lo + TRACE_CHUNK < job->n ? lo + TRACE_CHUNK : job->n;
        trace_range(job, &ctx, lo, hi);
    }
    return NULL;
}

double bench_embree_trace(BenchEmbree *e, EmbreeOp op, const VbRay *rays, size_t n,
                          const uint32_t *steps, float *out, int32_t *prim, int threads)
{
    TraceJob job = {e, op, rays, n, steps, out, prim, 0};
    atomic_init(&job.next, 0);
    pthread_t tid[64];
    if (threads > 64) threads = 64;
    double t0 = now_ms();
    int started = 0;
    for (int k = 1; k < threads; k++)
        if (pthread_create(&tid[started], NULL, trace_worker, &job) == 0) started++;
    trace_worker(&job); /* the calling thread is one of them */
    for (int k = 0; k < started; k++) pthread_join(tid[k], NULL);
    return now_ms() - t0;
}

#else /* no Embree: the bench measures vbcl alone */

int bench_embree_available(void)
{
    return 0;
}

const char *bench_embree_describe(void)
{
    return "skipped: Embree not installed";
}

BenchEmbree *bench_embree_open(const Mesh *m, int robust, int threads, double *build_ms, char *err,
                               size_t errlen)
{
    (void)m, (void)robust, (void)threads;
    *build_ms = 0.0;
    snprintf(err, errlen, "skipped: Embree not installed (scripts/install-deps.sh --bench)");
    return NULL;
}

double bench_embree_trace(BenchEmbree *e, EmbreeOp op, const VbRay *rays, size_t n,
                          const uint32_t *steps, float *out, int32_t *prim, int threads)
{
    (void)e, (void)op, (void)rays, (void)n, (void)steps, (void)out, (void)prim, (void)threads;
    return 0.0;
}

void bench_embree_close(BenchEmbree *e)
{
    (void)e;
}

#endif
