/* solidtex.h — surface-colour solid textures evaluated at a hit point (thesis 2.2.2.3):
 * Gardner's Fourier synthesis G(X,Y,Z) and the orthogonal projection R(X,Y,Z) of an image.
 * Compiles both as host C11 and as OpenCL C 1.2; parameters live in plain structs. */
#ifndef VBCL_SOLIDTEX_H
#define VBCL_SOLIDTEX_H

#include "compat.h"

/* VB_GLOBAL: the address space of texture data (a __global buffer on the device). A
 * kernel that keeps it elsewhere defines VB_GLOBAL first (e.g. as __constant). */
#ifdef __OPENCL_C_VERSION__
#ifndef VB_GLOBAL
#define VB_GLOBAL __global
#endif
#define VBST_FN     inline
#define VBST_COS(x) cos(x)
#define VBST_FLOOR  floor
#else
#include <math.h>
#ifndef VB_GLOBAL
#define VB_GLOBAL
#endif
#define VBST_FN     static inline
#define VBST_COS(x) cosf(x)
#define VBST_FLOOR  floorf
#endif

#define VBST_FOURIER_MAX_TERMS 8

/* Gardner's G(X,Y,Z) = prod over axes of sum_i C_i [cos(w_i X + phi_i) + A_0] (thesis
 * 2.1.2), filled on the host by texgen_fourier_init. Unused terms have c = 0. */
typedef struct VbFourier {
    int n;      /* terms in use, 4..7 */
    float a0;   /* A_0, the contrast offset */
    float gmax; /* analytic bound of |G| (1 after texgen_fourier_init) */
    float pad;
    float c[VBST_FOURIER_MAX_TERMS];  /* amplitudes C_i */
    float wx[VBST_FOURIER_MAX_TERMS]; /* frequencies per axis, radians per texture unit */
    float wy[VBST_FOURIER_MAX_TERMS];
    float wz[VBST_FOURIER_MAX_TERMS];
    float px[VBST_FOURIER_MAX_TERMS]; /* phases per axis, radians */
    float py[VBST_FOURIER_MAX_TERMS];
    float pz[VBST_FOURIER_MAX_TERMS];
} VbFourier;

VBCL_STATIC_ASSERT(sizeof(VbFourier) == 16 + 7 * 32, fourier_size);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFourier, c) == 16, fourier_c);
VBCL_STATIC_ASSERT(VBCL_OFFSETOF(VbFourier, pz) == 16 + 6 * 32, fourier_pz);

/* The pattern sums need nothing of what FP_CONTRACT OFF (compat.h) protects, the watertight
 * edge tests: on the device they keep the compiler's default. */
#ifdef VBCL_DEVICE
#pragma OPENCL FP_CONTRACT DEFAULT
#endif

/* G at texture point (x, y, z); |G| <= 1, and G >= 0 when a0 >= 1. */
VBST_FN float solidtex_fourier_eval(VB_GLOBAL const VbFourier *f, float x, float y, float z)
{
    float gx = 0.0f, gy = 0.0f, gz = 0.0f;
    for (int i = 0; i < f->n; i++) {
        gx += f->c[i] * (VBST_COS(f->wx[i] * x + f->px[i]) + f->a0);
        gy += f->c[i] * (VBST_COS(f->wy[i] * y + f->py[i]) + f->a0);
        gz += f->c[i] * (VBST_COS(f->wz[i] * z + f->pz[i]) + f->a0);
    }
    return gx * gy * gz;
}

/* Points within this distance of the unit square count as on its edge: a surface that
 * lies on the square's boundary (a box face at the projection's origin) computes its hit
 * points to within a few ulps either side, and would otherwise be speckled with R = 0
 * where rounding (which differs between OpenCL drivers) puts a point just outside. */
#define SOLIDTEX_PROJECTION_EDGE 1e-5f

/* Orthogonal projection along Z (thesis 2.1.3): the texel of a width x height image
 * (rows top first) nearest to (x, y), with x to the right and y up, both in [0, 1]
 * (widened by SOLIDTEX_PROJECTION_EDGE); -1 outside that square, where R is 0. The caller
 * reads the texel's channels. */
VBST_FN int solidtex_projection_texel(int width, int height, float x, float y)
{
    const float e = SOLIDTEX_PROJECTION_EDGE;
    if (!(x >= -e && x <= 1.0f + e && y >= -e && y <= 1.0f + e)) return -1;
    int col = (int)VBST_FLOOR(x * (float)width);
    int row = (int)VBST_FLOOR((1.0f - y) * (float)height);
    col = col < 0 ? 0 : col < width ? col : width - 1;
    row = row < 0 ? 0 : row < height ? row : height - 1;
    return row * width + col;
}

/* R(X, Y, Z) for one channel of an image stored as `channels` floats per texel. */
VBST_FN float solidtex_projection_eval(VB_GLOBAL const float *texels, int width, int height,
                                       int channels, int channel, float x, float y)
{
    int t = solidtex_projection_texel(width, height, x, y);
    return t < 0 ? 0.0f : texels[t * channels + channel];
}

#ifdef VBCL_DEVICE
#pragma OPENCL FP_CONTRACT OFF
#endif

#endif
