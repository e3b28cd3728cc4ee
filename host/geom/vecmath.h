/* vecmath.h — small 3-vector and 4x4 affine-matrix helpers for the host side. */
#ifndef VBCL_VECMATH_H
#define VBCL_VECMATH_H

#include <math.h>

/* pi in double; M_PI is POSIX, not C99. */
#define PI_D 3.14159265358979323846

typedef struct vec3 {
    float x, y, z;
} vec3;

/* Row-major affine transform: p' = M * p, last row is (0 0 0 1). */
typedef struct mat4 {
    double m[4][4];
} mat4;

static inline vec3 v3(float x, float y, float z)
{
    vec3 r = {x, y, z};
    return r;
}
static inline vec3 v3_add(vec3 a, vec3 b)
{
    return v3(a.x + b.x, a.y + b.y, a.z + b.z);
}
static inline vec3 v3_sub(vec3 a, vec3 b)
{
    return v3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static inline vec3 v3_scale(vec3 a, float s)
{
    return v3(a.x * s, a.y * s, a.z * s);
}
static inline float v3_dot(vec3 a, vec3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static inline vec3 v3_cross(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float v3_len(vec3 a)
{
    return sqrtf(v3_dot(a, a));
}
static inline vec3 v3_norm(vec3 a)
{
    float l = v3_len(a);
    return l > 0.0f ? v3_scale(a, 1.0f / l) : a;
}
static inline vec3 v3_min(vec3 a, vec3 b)
{
    return v3(fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z));
}
static inline vec3 v3_max(vec3 a, vec3 b)
{
    return v3(fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z));
}
static inline float v3_get(vec3 a, int axis)
{
    return axis == 0 ? a.x : axis == 1 ? a.y : a.z;
}

static inline mat4 mat4_identity(void)
{
    mat4 r = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
    return r;
}

static inline mat4 mat4_mul(mat4 a, mat4 b)
{
    mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++) s += a.m[i][k] * b.m[k][j];
            r.m[i][j] = s;
        }
    return r;
}

static inline mat4 mat4_translate(vec3 t)
{
    mat4 r = mat4_identity();
    r.m[0][3] = t.x;
    r.m[1][3] = t.y;
    r.m[2][3] = t.z;
    return r;
}

static inline mat4 mat4_scale(vec3 s)
{
    mat4 r = mat4_identity();
    r.m[0][0] = s.x;
    r.m[1][1] = s.y;
    r.m[2][2] = s.z;
    return r;
}

/* Rotation by deg degrees about the x (axis 0), y (1) or z (2) axis, right-handed. */
static inline mat4 mat4_rotate_axis(int axis, double deg)
{
    double a = deg * (3.14159265358979323846 / 180.0), c = cos(a), s = sin(a);
    mat4 r = mat4_identity();
    int i = (axis + 1) % 3, j = (axis + 2) % 3;
    r.m[i][i] = c;
    r.m[i][j] = -s;
    r.m[j][i] = s;
    r.m[j][j] = c;
    return r;
}

static inline vec3 mat4_apply_point(const mat4 *m, vec3 p)
{
    return v3((float)(m->m[0][0] * p.x + m->m[0][1] * p.y + m->m[0][2] * p.z + m->m[0][3]),
              (float)(m->m[1][0] * p.x + m->m[1][1] * p.y + m->m[1][2] * p.z + m->m[1][3]),
              (float)(m->m[2][0] * p.x + m->m[2][1] * p.y + m->m[2][2] * p.z + m->m[2][3]));
}

/* Transforms a normal by the inverse transpose of the upper 3x3 (cofactor matrix,
 * which differs from it only by the positive or negative determinant). */
static inline vec3 mat4_apply_normal(const mat4 *m, vec3 n)
{
    const double(*a)[4] = m->m;
    double c[3][3];
    c[0][0] = a[1][1] * a[2][2] - a[1][2] * a[2][1];
    c[0][1] = a[1][2] * a[2][0] - a[1][0] * a[2][2];
    c[0][2] = a[1][0] * a[2][1] - a[1][1] * a[2][0];
    c[1][0] = a[0][2] * a[2][1] - a[0][1] * a[2][2];
    c[1][1] = a[0][0] * a[2][2] - a[0][2] * a[2][0];
    c[1][2] = a[0][1] * a[2][0] - a[0][0] * a[2][1];
    c[2][0] = a[0][1] * a[1][2] - a[0][2] * a[1][1];
    c[2][1] = a[0][2] * a[1][0] - a[0][0] * a[1][2];
    c[2][2] = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    double det = a[0][0] * c[0][0] + a[0][1] * c[0][1] + a[0][2] * c[0][2];
    double sgn = det < 0 ? -1.0 : 1.0;
    vec3 r = v3((float)(sgn * (c[0][0] * n.x + c[0][1] * n.y + c[0][2] * n.z)),
                (float)(sgn * (c[1][0] * n.x + c[1][1] * n.y + c[1][2] * n.z)),
                (float)(sgn * (c[2][0] * n.x + c[2][1] * n.y + c[2][2] * n.z)));
    return v3_norm(r);
}

static inline double mat4_det3(const mat4 *m)
{
    const double(*a)[4] = m->m;
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
           a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

#endif
