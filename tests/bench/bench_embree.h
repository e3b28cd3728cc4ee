/* bench_embree.h — the Embree side of the ray-throughput bench (bench_rays.c): the scene's
 * world-space triangles in an Embree 3 BVH, traced with the single-ray API (rtcIntersect1,
 * rtcOccluded1) on a given number of threads. Compiled against Embree when
 * VBCL_HAVE_EMBREE is defined (the Makefile finds embree3/rtcore.h); without it every call
 * says Embree is not installed. */
#ifndef VBCL_BENCH_EMBREE_H
#define VBCL_BENCH_EMBREE_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "types.h"

/* What is asked of each ray. */
typedef enum {
    EMBREE_CLOSEST,  /* rtcIntersect1: out = hit distance, or -1 for a miss */
    EMBREE_OCCLUDED, /* rtcOccluded1: out = 1 blocked before tmax, 0 free */
    EMBREE_WALK      /* steps[i] rtcIntersect1 from crossing to crossing (each from the last
                      * hit, offset as the kernels offset it, over what is left of tmax),
                      * stopping early at a miss: out = distance along the ray of the last
                      * call's hit, or -1 when it found nothing */
} EmbreeOp;

typedef struct BenchEmbree BenchEmbree;

/* 1 when the bench was built with Embree. */
int bench_embree_available(void);

/* A human-readable description of the Embree build and the scene settings used. */
const char *bench_embree_describe(void);

/* Builds the BVH over m's triangles (primitive i = triangle i) with `threads` build threads;
 * robust: RTC_SCENE_FLAG_ROBUST. *build_ms gets the build time. Returns NULL with a message
 * in err (also when Embree is not installed). m must outlive the result. */
BenchEmbree *bench_embree_open(const Mesh *m, int robust, int threads, double *build_ms, char *err,
                               size_t errlen);

/* Traces n rays (org, dir, tmax of VbRay; tnear 0) with op on `threads` threads, results in
 * out[i] and, for EMBREE_CLOSEST, the triangle hit in prim[i] (-1: none; prim may be NULL).
 * steps: per ray, for EMBREE_WALK only. Returns the wall time of the tracing in ms. */
double bench_embree_trace(BenchEmbree *e, EmbreeOp op, const VbRay *rays, size_t n,
                          const uint32_t *steps, float *out, int32_t *prim, int threads);

void bench_embree_close(BenchEmbree *e);

#endif
