#line 2 "environment.cl"
/* environment.cl — what a ray that leaves the scene sees: the frame's background colour, or
 * with VBCL_FRAME_ENVIRONMENT its latitude-longitude environment (image.environment,
 * VbEnvironment in types.h), looked up along the ray's direction. */
#ifndef VBCL_ENVIRONMENT_CL
#define VBCL_ENVIRONMENT_CL

#include "scene.cl"

/* The environment's radiance along dir (any length but 0; world space), bilinear: along u
 * between texel centres, wrapping across the seam at u = 0 (the direction -z of the
 * environment), along v between rows, row 0 at v = 0 (its +y, the zenith) and the last at
 * v = 1; the texels hold the image times its scale. Kept out of line: only rays that leave
 * the scene call it, and the tracing loops around its callers stay as small as without it. */
__attribute__((noinline)) float3 environment_radiance(__constant const VbEnvironment *e,
                                                      __global const float *texels, float3 dir)
{
    float3 d = (float3)(dot(vb_cload3(e->rot[0]), dir), dot(vb_cload3(e->rot[1]), dir),
                        dot(vb_cload3(e->rot[2]), dir));
    float u = atan2(d.x, -d.z) * (0.5f / VB_PI); /* [-1/2, 1/2] */
    u = u < 0.0f ? u + 1.0f : u;
    float v = atan2(sqrt(d.x * d.x + d.z * d.z), d.y) * (1.0f / VB_PI); /* acos(d.y / |d|) */
    int w = e->width, h = e->height;
    float x = u * (float)w - 0.5f, y = v * (float)(h - 1);
    float x0 = floor(x), y0 = floor(y);
    float tx = x - x0, ty = y - y0;
    /* convert_int_sat makes a NaN 0; the clamps keep any rounding inside the image */
    int i0 = clamp(convert_int_sat(x0), -1, w - 1), j0 = clamp(convert_int_sat(y0), 0, h - 1);
    i0 += i0 < 0 ? w : 0;
    int i1 = i0 + 1 == w ? 0 : i0 + 1, j1 = min(j0 + 1, h - 1);
    __global const float *r0 = texels + 4 * ((size_t)e->first + (size_t)j0 * (size_t)w);
    __global const float *r1 = texels + 4 * ((size_t)e->first + (size_t)j1 * (size_t)w);
    float3 a = vb_gload3(r0 + 4 * i0), b = vb_gload3(r0 + 4 * i1);
    float3 c = vb_gload3(r1 + 4 * i0), g = vb_gload3(r1 + 4 * i1);
    /* a + (b - a) t: equal texels give their value exactly, so a constant environment is
     * its colour bit for bit */
    float3 top = a + (b - a) * tx, bottom = c + (g - c) * tx;
    return top + (bottom - top) * ty;
}

/* The radiance a ray leaving the scene along dir carries back: the environment's, or the
 * background colour. */
VB_INLINE float3 scene_escape_radiance(const DevScene *sc, float3 dir)
{
    __constant const VbFrame *f = sc->f;
    if (f->flags & VBCL_FRAME_ENVIRONMENT) return environment_radiance(&f->env, sc->texels, dir);
    return vb_cload3(f->background);
}

#endif
