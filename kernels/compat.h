/* compat.h — the thin layer that lets types.h compile both as host C and as OpenCL C. */
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

#endif
