/* compat.h — the thin layer that lets types.h compile both as host C and as OpenCL C, and
 * on the device the helpers every kernel file uses (VB_INLINE, VB_PI, float3 loads). */
#ifndef VBCL_COMPAT_H
#define VBCL_COMPAT_H

#ifdef __OPENCL_C_VERSION__
#define VBCL_DEVICE         1
#define VBCL_OFFSETOF(T, m) __builtin_offsetof(T, m)
#else
#include <stddef.h>
#define VBCL_OFFSETOF(T, m) offsetof(T, m)
#endif

/* A compile-time check that works in C99/C11 and in OpenCL C 1.2 (which has no
 * _Static_assert): a negative array size stops the build on either side. */
#define VBCL_STATIC_ASSERT(cond, name) typedef char vbcl_assert_##name[(cond) ? 1 : -1]

#ifdef VBCL_DEVICE
/* Contraction into fused multiply-adds would make the edge functions of two triangles
 * sharing an edge differ, and rays could slip between them: off for every kernel file,
 * which all include this one first. */
#pragma OPENCL FP_CONTRACT OFF

#ifdef cl_khr_fp64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#endif

#define VB_PI 3.14159265358979323846f

/* Hot helpers must be inlined: on CPU drivers a call passes structs through the stack
 * and every counter update becomes a store and a reload (a called medium_trace cost
 * prism_dispersion 11% of its kernel time on PoCL; docs/architecture.md, "Kernel
 * programs"). */
#ifdef __clang__
#define VB_INLINE inline __attribute__((always_inline))
#else
#define VB_INLINE inline
#endif

/* float3 from three floats of a host-written array (the shared structs hold float[3]). */
inline float3 vb_load3(const float *p)
{
    return (float3)(p[0], p[1], p[2]);
}
inline float3 vb_gload3(__global const float *p)
{
    return (float3)(p[0], p[1], p[2]);
}
inline float3 vb_cload3(__constant const float *p)
{
    return (float3)(p[0], p[1], p[2]);
}

inline float vb_max3(float3 v)
{
    return fmax(v.x, fmax(v.y, v.z));
}
#endif

#endif
