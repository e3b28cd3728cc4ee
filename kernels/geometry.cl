#line 2 "geometry.cl"
/* geometry.cl — ray origins off their surface by the error bound of the hit point (pbrt-v4),
 * watertight ray/triangle intersection (Woop, Benthin & Wald 2013), triangle access and the
 * closest-hit rule. */
#ifndef VBCL_GEOMETRY_CL
#define VBCL_GEOMETRY_CL

#include "offset.h"
#include "types.h"

/* Moves a point p on a surface off it along the unit geometric normal n (pointing to the
 * side the new ray leaves into) by err, 16 times the bound of p's distance from the surface's
 * plane (tri_point_error), and one float further in each coordinate that moves (offset.h,
 * after pbrt-v4's OffsetRayOrigin): a ray from the result cannot hit the triangle it starts
 * on, at any scene scale or position, and moves as far as the point's own rounding says. */
VB_INLINE float3 ray_offset_origin(float3 p, float3 n, float err)
{
    return (float3)(vb_offset_coord(p.x, n.x, err), vb_offset_coord(p.y, n.y, err),
                    vb_offset_coord(p.z, n.z, err));
}

/* Per-ray constants of the watertight test (Woop, Benthin & Wald 2013): the axis
 * permutation that makes the largest direction component z (kx, ky, kz) and the shear
 * that maps the ray onto +z. A vertex p maps to (q.x - sx q.z, q.y - sy q.z, sz q.z) with
 * q = (p - org) permuted: the same few operations for every triangle that shares the
 * vertex (contraction is off), which is what watertightness needs, and a third of the
 * multiplications of a full 3x3 shear. All in scalars: on a CPU, OpenCL's 3-lane vectors
 * and a shuffle by a run-time mask cost lane moves that made the test about 5% slower. */
typedef struct RayShear {
    float ox, oy, oz; /* the origin */
    uint kx, ky, kz;  /* the permutation */
    float sx, sy, sz;
} RayShear;

/* Coordinate k (0, 1, 2) of (x, y, z). */
VB_INLINE float vb_pick(float x, float y, float z, uint k)
{
    return k == 0u ? x : (k == 1u ? y : z);
}

VB_INLINE float vb_comp(float3 v, uint k)
{
    return vb_pick(v.x, v.y, v.z, k);
}

VB_INLINE RayShear ray_shear_make(float3 org, float3 dir)
{
    RayShear r;
    float3 ad = fabs(dir);
    uint kz = (ad.x > ad.y) ? ((ad.x > ad.z) ? 0u : 2u) : ((ad.y > ad.z) ? 1u : 2u);
    uint kx = kz == 2u ? 0u : kz + 1u;
    uint ky = kx == 2u ? 0u : kx + 1u;
    float dz = vb_comp(dir, kz);
    if (dz < 0.0f) { /* keep the winding: swap x and y */
        uint t = kx;
        kx = ky;
        ky = t;
    }
    r.sx = vb_comp(dir, kx) / dz;
    r.sy = vb_comp(dir, ky) / dz;
    r.sz = 1.0f / dz;
    r.ox = org.x;
    r.oy = org.y;
    r.oz = org.z;
    r.kx = kx;
    r.ky = ky;
    r.kz = kz;
    return r;
}

/* Vertex p through the ray's shear, in scalars (the same operations as on vectors). */
VB_INLINE void ray_shear_apply(const RayShear *r, float4 p, float *x, float *y, float *z)
{
    float dx = p.x - r->ox, dy = p.y - r->oy, dz = p.z - r->oz;
    float qx = vb_pick(dx, dy, dz, r->kx), qy = vb_pick(dx, dy, dz, r->ky),
          qz = vb_pick(dx, dy, dz, r->kz);
    *x = qx - r->sx * qz;
    *y = qy - r->sy * qz;
    *z = r->sz * qz;
}

/* tri_finish's answer for a hit closer than its own rounding-error bound, where the device
 * has cl_khr_fp64: the caller decides it again in double (tri_close_double). */
#define TRI_CLOSE 2

/* The watertight test of a triangle whose vertices went through the ray's shear
 * (ax .. cz) and whose edge functions are U = cx by - cy bx, V = ax cy - ay cx and
 * W = bx ay - by ax: tri_intersect from there on. For the triangles of a leaf quad
 * (grid.cl), which computes the same values four at a time. Returns 1 for a hit, 0 for
 * none, and TRI_CLOSE (t, u and v written) for a hit within the bound of its distance's
 * rounding error (without cl_khr_fp64: 0). */
VB_INLINE int tri_finish(float ax, float ay, float az, float bx, float by, float bz, float cx,
                         float cy, float cz, float U, float V, float W, float tmax, float *t_out,
                         float *u_out, float *v_out)
{
#ifdef cl_khr_fp64
    if (U == 0.0f || V == 0.0f || W == 0.0f) { /* on an edge in float: decide in double */
        U = (float)((double)cx * (double)by - (double)cy * (double)bx);
        V = (float)((double)ax * (double)cy - (double)ay * (double)cx);
        W = (float)((double)bx * (double)ay - (double)by * (double)ax);
    }
#endif
    if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return 0;
    float det = U + V + W;
    if (det == 0.0f) return 0;
    float T = U * az + V * bz + W * cz;
    if (det > 0.0f) {
        if (T <= 0.0f || T > tmax * det) return 0;
    } else {
        if (T >= 0.0f || T < tmax * det) return 0;
    }
    float rcp = 1.0f / det;
    float t = T * rcp;
    /* Hits closer than the rounding error of the sheared computation (Pharr, Jakob &
     * Humphreys, pbrt 3rd ed., 3.9.6) are not taken as they are: a ray leaving a triangle
     * from its offset origin must not find that triangle again. They go to double. */
    const float g2 = 2.0f * 5.9604645e-8f / (1.0f - 2.0f * 5.9604645e-8f);
    const float g3 = 3.0f * 5.9604645e-8f / (1.0f - 3.0f * 5.9604645e-8f);
    const float g5 = 5.0f * 5.9604645e-8f / (1.0f - 5.0f * 5.9604645e-8f);
    float max_z = fmax(fabs(az), fmax(fabs(bz), fabs(cz)));
    float max_x = fmax(fabs(ax), fmax(fabs(bx), fabs(cx)));
    float max_y = fmax(fabs(ay), fmax(fabs(by), fabs(cy)));
    float delta_x = g5 * (max_x + max_z), delta_y = g5 * (max_y + max_z), delta_z = g3 * max_z;
    float delta_e = 2.0f * (g2 * max_x * max_y + delta_y * max_x + delta_x * max_y);
    float max_e = fmax(fabs(U), fmax(fabs(V), fabs(W)));
    float delta_t = 3.0f * (g3 * max_e * max_z + delta_e * max_z + delta_z * max_e) * fabs(rcp);
    *t_out = t;
    *u_out = V * rcp;
    *v_out = W * rcp;
    if (t > delta_t) return 1;
#ifdef cl_khr_fp64
    return TRI_CLOSE;
#else
    return 0;
#endif
}

#ifdef cl_khr_fp64
/* A hit that tri_finish found within its float error bound (TRI_CLOSE), decided again from
 * the triangle's own vertices (a, b, c) with the ray's shear (origin o, permutation k,
 * shear s) and the edge functions in double, whose bound (the same terms, u = 2^-53) is 2^29
 * times smaller: a ray that starts near a long, thin triangle (the side of a flat box, whose
 * float bound spans a good part of the box) finds the edge it crosses there, and a ray from
 * an offset origin (ray_offset_origin), beyond its own triangle's plane by 16 times the
 * point's float error bound, still does not find its own. The edge signs stay the float test's.
 * Returns the hit's t, or 0 for none. Rare, and kept out of line (noinline, cold): inlined into
 * every lane of the quad loops it made the bench scenes' kernels 13 - 22% slower. */
__attribute__((noinline, cold)) float tri_close_double(float ox, float oy, float oz, uint kx,
                                                       uint ky, uint kz, float sx, float sy,
                                                       float sz, float4 a4, float4 b4, float4 c4,
                                                       float tmax)
{
    double p[9];
    float4 v[3] = {a4, b4, c4};
    for (int k = 0; k < 3; k++) {
        double dx = (double)v[k].x - (double)ox, dy = (double)v[k].y - (double)oy,
               dz = (double)v[k].z - (double)oz;
        double qx = kx == 0u ? dx : (kx == 1u ? dy : dz);
        double qy = ky == 0u ? dx : (ky == 1u ? dy : dz);
        double qz = kz == 0u ? dx : (kz == 1u ? dy : dz);
        p[3 * k] = qx - (double)sx * qz;
        p[3 * k + 1] = qy - (double)sy * qz;
        p[3 * k + 2] = (double)sz * qz;
    }
    double U = p[6] * p[4] - p[7] * p[3], V = p[0] * p[7] - p[1] * p[6],
           W = p[3] * p[1] - p[4] * p[0];
    double det = U + V + W;
    if (det == 0.0) return 0.0f;
    double t = (U * p[2] + V * p[5] + W * p[8]) / det;
    const double u = 1.1102230246251565e-16; /* 2^-53 */
    const double g2 = 2.0 * u / (1.0 - 2.0 * u), g3 = 3.0 * u / (1.0 - 3.0 * u),
                 g5 = 5.0 * u / (1.0 - 5.0 * u);
    double max_x = fmax(fabs(p[0]), fmax(fabs(p[3]), fabs(p[6])));
    double max_y = fmax(fabs(p[1]), fmax(fabs(p[4]), fabs(p[7])));
    double max_z = fmax(fabs(p[2]), fmax(fabs(p[5]), fabs(p[8])));
    double delta_x = g5 * (max_x + max_z), delta_y = g5 * (max_y + max_z), delta_z = g3 * max_z;
    double delta_e = 2.0 * (g2 * max_x * max_y + delta_y * max_x + delta_x * max_y);
    double max_e = fmax(fabs(U), fmax(fabs(V), fabs(W)));
    double delta_t = 3.0 * (g3 * max_e * max_z + delta_e * max_z + delta_z * max_e) / fabs(det);
    if (!(t > delta_t) || t > (double)tmax) return 0.0f;
    return (float)t;
}

/* tri_close_double for the ray of r: 1 with *t_out, or 0. */
VB_INLINE int tri_close(const RayShear *r, float4 a4, float4 b4, float4 c4, float tmax,
                        float *t_out)
{
    float t = tri_close_double(r->ox, r->oy, r->oz, r->kx, r->ky, r->kz, r->sx, r->sy, r->sz, a4,
                               b4, c4, tmax);
    if (!(t > 0.0f)) return 0;
    *t_out = t;
    return 1;
}
#endif

/* Intersects the sheared ray with triangle (a, b, c). On a hit with 0 < t < tmax
 * returns 1 and writes t and the barycentric weights of b (u) and c (v). Rays through
 * a shared edge or vertex of a closed mesh hit at least one of its triangles. */
VB_INLINE int tri_intersect(const RayShear *r, float4 a4, float4 b4, float4 c4, float tmax,
                            float *t_out, float *u_out, float *v_out)
{
    float ax, ay, az, bx, by, bz, cx, cy, cz;
    ray_shear_apply(r, a4, &ax, &ay, &az);
    ray_shear_apply(r, b4, &bx, &by, &bz);
    ray_shear_apply(r, c4, &cx, &cy, &cz);
    float U = cx * by - cy * bx;
    float V = ax * cy - ay * cx;
    float W = bx * ay - by * ax;
    int hit = tri_finish(ax, ay, az, bx, by, bz, cx, cy, cz, U, V, W, tmax, t_out, u_out, v_out);
#ifdef cl_khr_fp64
    if (hit == TRI_CLOSE) hit = tri_close(r, a4, b4, c4, tmax, t_out);
#endif
    return hit;
}

/* Vertex k (0, 1, 2) of a triangle, read from its own array (indexing past v0 into v1
 * would be out of bounds for a checker such as oclgrind). */
VB_INLINE float4 tri_vertex(__global const VbTriangle *tris, int tri, int k)
{
    __global const VbTriangle *t = tris + tri;
    __global const float *p = k == 0 ? t->v0 : (k == 1 ? t->v1 : t->v2);
    return (float4)(p[0], p[1], p[2], 0.0f);
}

/* The triangle's tag: object index | VBCL_TAG_TEXTURE for volume-texture triangles |
 * VBCL_TAG_OPAQUE for opaque surfaces. */
VB_INLINE uint tri_tag(__global const VbTriangle *tris, int tri)
{
    return ((__global const uint *)(tris + tri))[3];
}

/* Unit geometric normal, from the winding (outward for closed meshes). */
VB_INLINE float3 tri_normal(__global const VbTriangle *tris, int tri)
{
    float3 a = tri_vertex(tris, tri, 0).xyz;
    float3 b = tri_vertex(tris, tri, 1).xyz;
    float3 c = tri_vertex(tris, tri, 2).xyz;
    return normalize(cross(b - a, c - a));
}

/* The point of a hit, interpolated on the triangle (it lies on its plane). */
VB_INLINE float3 tri_point(__global const VbTriangle *tris, VbHit h)
{
    return (1.0f - h.u - h.v) * tri_vertex(tris, h.tri, 0).xyz +
           h.u * tri_vertex(tris, h.tri, 1).xyz + h.v * tri_vertex(tris, h.tri, 2).xyz;
}

/* The offset for ray_offset_origin from a hit's point (tri_point) on the triangle whose unit
 * normal is n (either side): 16 times the bound of the point's distance from the plane, the
 * interpolation's error, from the magnitudes of its terms (offset.h). */
VB_INLINE float tri_point_error(__global const VbTriangle *tris, VbHit h, float3 n)
{
    float w0 = 1.0f - h.u - h.v;
    float3 a = tri_vertex(tris, h.tri, 0).xyz, b = tri_vertex(tris, h.tri, 1).xyz,
           c = tri_vertex(tris, h.tri, 2).xyz;
    return vb_offset_error(n.x, n.y, n.z, vb_offset_sum(w0, h.u, h.v, a.x, b.x, c.x),
                           vb_offset_sum(w0, h.u, h.v, a.y, b.y, c.y),
                           vb_offset_sum(w0, h.u, h.v, a.z, b.z, c.z));
}

/* Surfaces in contact: a glass prism standing on a floor has its bottom face in the
 * floor's plane, and a ray leaving the glass there hits both at the same distance up to
 * rounding. Were the winner a coin toss per ray, the ray that first crossed the glass
 * face would start again from an offset origin past the floor and never see it, and the
 * glass would show a fixed per-pixel speckle of floor and no floor. Contact is decided
 * here, in every closest-hit search: within this window of the closest hit, an opaque
 * surface (VBCL_TAG_OPAQUE) comes before a medium boundary, so the ray meets the floor
 * while still in the glass, as light does where glass touches a floor. The window is 2^-16
 * of the magnitudes of the computation, the ray's distance and its origin (about 128 ulps of
 * them: above the rounding of the two distances, a few ulps each (tri_finish), and of the two
 * surfaces' vertices), so the same at any scale; far below a gap a scene means. */
VB_INLINE float hit_contact_window(float3 org, float t)
{
    return (1.0f / 65536.0f) * (t + vb_max3(fabs(org)));
}

/* Whether a hit at t on triangle tri (opaque: its VBCL_TAG_OPAQUE bit) comes before the
 * best hit so far (best_opaque likewise; window: hit_contact_window at the best hit):
 * across kinds within the window the opaque one, else the closer one, and of equal t the
 * lower triangle index. */
VB_INLINE int hit_before(float t, int tri, uint opaque, VbHit best, uint best_opaque, float window)
{
    if (best.tri < 0) return 1;
    if (opaque != best_opaque) return opaque ? t <= best.t + window : t + window < best.t;
    return t < best.t || (t == best.t && tri < best.tri);
}

/* How far a candidate hit may lie and still come before the best hit (see hit_before). */
VB_INLINE float hit_reach(VbHit best, uint best_opaque, float window, float tmax)
{
    return best.tri < 0 || best_opaque ? best.t : fmin(tmax, best.t + window);
}

#endif
