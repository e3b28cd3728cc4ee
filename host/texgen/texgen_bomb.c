/* texgen_bomb.c — bombing (thesis 2.1.1, 2.2.2.1): spheres, cylinders or cubes of random
 * size, position and orientation dropped into the texture block. */
#include "texgen.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define TRIES_PER_ELEMENT 2000

void bomb_defaults(BombParams *p)
{
    p->shape = TEX_SPHERE;
    p->count = 365;
    p->size_min = 1.0f;
    p->size_max = 14.0f;
    p->seed = 1;
    p->no_overlap = 0;
    p->block = 128.0f;
    p->level = 2;
    p->segments = 24;
}

static const char *shape_name(int s)
{
    return s == TEX_SPHERE ? "sphere" : s == TEX_CYLINDER ? "cylinder" : "cube";
}

/* Bounding-sphere radius of an element of size r. */
static double bound_radius(int shape, double r)
{
    return shape == TEX_SPHERE ? r : shape == TEX_CYLINDER ? r * sqrt(2.0) : r * sqrt(3.0);
}

/* A uniformly distributed rotation (Shoemake's unit quaternion from three uniforms). */
static mat4 random_rotation(TexRng *rng)
{
    double u1 = texrng_uniform(rng), u2 = texrng_uniform(rng), u3 = texrng_uniform(rng);
    double a = sqrt(1.0 - u1), b = sqrt(u1);
    double x = a * sin(2 * PI_D * u2), y = a * cos(2 * PI_D * u2);
    double z = b * sin(2 * PI_D * u3), w = b * cos(2 * PI_D * u3);
    mat4 m = mat4_identity();
    m.m[0][0] = 1 - 2 * (y * y + z * z);
    m.m[0][1] = 2 * (x * y - z * w);
    m.m[0][2] = 2 * (x * z + y * w);
    m.m[1][0] = 2 * (x * y + z * w);
    m.m[1][1] = 1 - 2 * (x * x + z * z);
    m.m[1][2] = 2 * (y * z - x * w);
    m.m[2][0] = 2 * (x * z - y * w);
    m.m[2][1] = 2 * (y * z + x * w);
    m.m[2][2] = 1 - 2 * (x * x + y * y);
    return m;
}

/* The unit element: sphere of radius 1, cylinder of radius 1 and height 2, cube of edge 2. */
static int unit_element(const BombParams *p, Mesh *m)
{
    if (p->shape == TEX_SPHERE) return shape_sphere(m, p->level);
    if (p->shape == TEX_CUBE) return shape_box(m, v3(2, 2, 2));
    static const float prof[4][2] = {{0, -1}, {1, -1}, {1, 1}, {0, 1}};
    return shape_revolution(m, prof, 4, p->segments, 1);
}

/* Checks the parameters' ranges. Returns 0, or -1 with a message in err. */
static int bomb_check(const BombParams *p, char *err, size_t errlen)
{
    if (p->count < 1 || p->count > 1000000) {
        snprintf(err, errlen, "--count %d: expected 1 to 1000000 elements", p->count);
        return -1;
    }
    if (!(p->size_min > 0.0f) || !isfinite(p->size_max) || p->size_min > p->size_max) {
        snprintf(err, errlen, "--size %g:%g: expected 0 < MIN <= MAX", p->size_min, p->size_max);
        return -1;
    }
    if (!(p->block > 0.0f) || !isfinite(p->block)) {
        snprintf(err, errlen, "--block %g: expected a positive size", p->block);
        return -1;
    }
    if (p->level < 0 || p->level > 5 || p->segments < 3 || p->segments > 1024) {
        snprintf(err, errlen, "--level %d / --segments %d: expected 0..5 and 3..1024", p->level,
                 p->segments);
        return -1;
    }
    return 0;
}

/* A centre for an element of bounding radius br: uniform in the block, and with
 * --no-overlap away from every element placed so far. Returns 1, or 0 when no try
 * succeeded. */
static int bomb_place(const BombParams *p, const TexSet *out, double br, TexRng *rng, double c[3])
{
    int placed = 0;
    for (int tries = 0; tries < TRIES_PER_ELEMENT && !placed; tries++) {
        for (int a = 0; a < 3; a++) c[a] = p->block * texrng_uniform(rng);
        placed = 1;
        for (int j = 0; j < out->count && p->no_overlap && placed; j++) {
            const float *b = out->bound[j];
            double dx = c[0] - b[0], dy = c[1] - b[1], dz = c[2] - b[2], rr = br + b[3];
            if (dx * dx + dy * dy + dz * dz <= rr * rr) placed = 0;
        }
    }
    return placed;
}

int texgen_bomb(const BombParams *p, TexSet *out, char *err, size_t errlen)
{
    if (bomb_check(p, err, errlen)) return -1;
    texset_init(out);
    char f0[32], f1[32], f2[32];
    snprintf(out->params, sizeof out->params,
             "bomb --shape %s --count %d --size %s:%s --seed %llu%s --block %s --level %d "
             "--segments %d",
             shape_name(p->shape), p->count, texgen_float_str(f0, sizeof f0, p->size_min),
             texgen_float_str(f1, sizeof f1, p->size_max), (unsigned long long)p->seed,
             p->no_overlap ? " --no-overlap" : "", texgen_float_str(f2, sizeof f2, p->block),
             p->level, p->segments);
    for (int a = 0; a < 3; a++) {
        out->block_lo[a] = 0.0f;
        out->block_hi[a] = p->block;
    }

    Mesh unit;
    mesh_init(&unit);
    if (unit_element(p, &unit) < 0) {
        mesh_free(&unit);
        return -2;
    }
    TexRng rng;
    texrng_seed(&rng, p->seed);
    int rc = 0;
    for (int e = 0; e < p->count && rc == 0; e++) {
        double r = p->size_min + (p->size_max - p->size_min) * texrng_uniform(&rng);
        double br = bound_radius(p->shape, r);
        double c[3];
        if (!bomb_place(p, out, br, &rng, c)) {
            snprintf(err, errlen,
                     "--no-overlap: cannot place element %d of %d (radius %.3g) after %d tries; "
                     "expected fewer or smaller elements, or a larger --block",
                     e + 1, p->count, r, TRIES_PER_ELEMENT);
            rc = -1;
            break;
        }
        mat4 xf = mat4_scale(v3((float)r, (float)r, (float)r));
        mat4 rot = random_rotation(&rng);
        if (p->shape != TEX_SPHERE) xf = mat4_mul(rot, xf);
        xf = mat4_mul(mat4_translate(v3((float)c[0], (float)c[1], (float)c[2])), xf);
        Mesh m;
        mesh_init(&m);
        if (mesh_append(&m, &unit) < 0) {
            mesh_free(&m);
            rc = -2;
            break;
        }
        mesh_transform(&m, &xf);
        float bound[4] = {(float)c[0], (float)c[1], (float)c[2], (float)br};
        if (texset_add(out, &m, bound) < 0) rc = -2;
    }
    mesh_free(&unit);
    if (rc == -2) snprintf(err, errlen, "out of memory after %d elements", out->count);
    if (rc) texset_free(out);
    return rc;
}
