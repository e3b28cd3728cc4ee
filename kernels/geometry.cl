#line 2 "geometry.cl"
/* geometry.cl — device-side vector helpers, robust ray origins (Waechter & Binder 2019)
 * and watertight ray/triangle intersection (Woop, Benthin & Wald 2013). */

/* Contraction into fused multiply-adds would make the edge functions of two triangles
 * sharing an edge differ, and rays could slip between them. */
#pragma OPENCL FP_CONTRACT OFF

#ifdef cl_khr_fp64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#endif

#define VB_PI 3.14159265358979323846f

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

/* Moves a point p on a surface off it along the geometric normal n (pointing to the
 * side the new ray leaves into) by a few ulps of p's own magnitude, so a ray from the
 * result cannot hit the surface it starts on, at any scene scale. */
inline float3 ray_offset_origin(float3 p, float3 n)
{
    const float origin = 1.0f / 32.0f;
    const float float_scale = 1.0f / 65536.0f;
    const float int_scale = 256.0f;
    int3 of_i = convert_int3(int_scale * n);
    int3 neg = isless(p, (float3)(0.0f));
    float3 p_i = as_float3(as_int3(p) + select(of_i, -of_i, neg));
    float3 p_f = p + float_scale * n;
    return select(p_i, p_f, isless(fabs(p), (float3)(origin)));
}

/* Per-ray constants of the watertight test: the axis permutation that makes the
 * largest direction component z, and the shear that maps the ray onto +z. */
typedef struct RayShear {
    float4 org; /* w = 0 */
    uint4 perm; /* (kx, ky, kz, 3) */
    float sx, sy, sz;
} RayShear;

inline RayShear ray_shear_make(float3 org, float3 dir)
{
    RayShear r;
    float3 ad = fabs(dir);
    uint kz = (ad.x > ad.y) ? ((ad.x > ad.z) ? 0u : 2u) : ((ad.y > ad.z) ? 1u : 2u);
    uint kx = kz == 2u ? 0u : kz + 1u;
    uint ky = kx == 2u ? 0u : kx + 1u;
    float4 d = shuffle((float4)(dir, 0.0f), (uint4)(kx, ky, kz, 3u));
    if (d.z < 0.0f) { /* keep the winding: swap x and y */
        uint t = kx;
        kx = ky;
        ky = t;
        d = shuffle((float4)(dir, 0.0f), (uint4)(kx, ky, kz, 3u));
    }
    r.org = (float4)(org, 0.0f);
    r.perm = (uint4)(kx, ky, kz, 3u);
    r.sx = d.x / d.z;
    r.sy = d.y / d.z;
    r.sz = 1.0f / d.z;
    return r;
}

/* Intersects the sheared ray with triangle (a, b, c). On a hit with 0 < t < tmax
 * returns 1 and writes t and the barycentric weights of b (u) and c (v). Rays through
 * a shared edge or vertex of a closed mesh hit at least one of its triangles. */
inline int tri_intersect(const RayShear *r, float4 a4, float4 b4, float4 c4, float tmax,
                         float *t_out, float *u_out, float *v_out)
{
    float4 A = shuffle(a4 - r->org, r->perm);
    float4 B = shuffle(b4 - r->org, r->perm);
    float4 C = shuffle(c4 - r->org, r->perm);
    float ax = A.x - r->sx * A.z, ay = A.y - r->sy * A.z;
    float bx = B.x - r->sx * B.z, by = B.y - r->sy * B.z;
    float cx = C.x - r->sx * C.z, cy = C.y - r->sy * C.z;
    float U = cx * by - cy * bx;
    float V = ax * cy - ay * cx;
    float W = bx * ay - by * ax;
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
    float az = r->sz * A.z, bz = r->sz * B.z, cz = r->sz * C.z;
    float T = U * az + V * bz + W * cz;
    if (det > 0.0f) {
        if (T <= 0.0f || T > tmax * det) return 0;
    } else {
        if (T >= 0.0f || T < tmax * det) return 0;
    }
    float rcp = 1.0f / det;
    *t_out = T * rcp;
    *u_out = V * rcp;
    *v_out = W * rcp;
    return 1;
}

inline float4 tri_vertex(__global const VbTriangle *tris, int tri, int k)
{
    __global const float *p = (__global const float *)(tris + tri) + 4 * k;
    return (float4)(p[0], p[1], p[2], 0.0f);
}

inline uint tri_material(__global const VbTriangle *tris, int tri)
{
    return ((__global const uint *)(tris + tri))[3];
}

/* Unit geometric normal, from the winding (outward for closed meshes). */
inline float3 tri_normal(__global const VbTriangle *tris, int tri)
{
    float3 a = tri_vertex(tris, tri, 0).xyz;
    float3 b = tri_vertex(tris, tri, 1).xyz;
    float3 c = tri_vertex(tris, tri, 2).xyz;
    return normalize(cross(b - a, c - a));
}
