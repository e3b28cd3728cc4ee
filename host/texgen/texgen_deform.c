/* texgen_deform.c — deformed projection (thesis 2.1.3, 2.2.2.2): nested circles or
 * rectangles swept along Z while tapered and twisted, as closed bands; and thin tubes
 * twisted about the Z axis in separate lanes (marble veins). */
#include "texgen.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RING_STEP    (3.0 * PI_D / 180.0) /* at most this much twist between two rings */
#define MAX_SEGMENTS 4096
#define MAX_RINGS    4096

void deform_defaults(DeformParams *p)
{
    memset(p, 0, sizeof *p);
    p->kind = DEFORM_NESTED;
    p->rect = 0;
    p->count = 4;
    p->spacing = 2.0f;
    p->aspect = 0.6f;
    static const float fig22[4] = {0.1f, -0.1f, -0.05f, 0.05f};
    memcpy(p->taper, fig22, sizeof fig22);
    p->ntaper = 4;
    p->taper_max = 0.06f;
    p->twist_max = 2.0f;
    p->length = 8.0f;
    p->segments = 48;
    p->rings = 0;
    p->tube_radius = 2.0f;
    p->wobble = 0.5f;
    p->seed = 1;
}

int deform_preset(DeformParams *p, const char *name)
{
    deform_defaults(p);
    if (!strcmp(name, "figure2.2")) return 0;
    if (!strcmp(name, "wood")) {
        /* thesis A.3: 15 embedded circles, about 2500 triangles */
        p->count = 15;
        p->ntaper = 0;
        p->taper_random = 1;
        p->taper_max = 0.06f;
        p->spacing = 4.0f; /* > 2 * 0.06 * 32 = 3.84 */
        p->length = 32.0f;
        p->segments = 40;
        p->rings = 1; /* tapering is linear in z: one step is exact */
        return 0;
    }
    if (!strcmp(name, "marble")) {
        /* thin twisted tubes wandering through the block like veins (thesis A.1, A.2) */
        p->kind = DEFORM_TUBES;
        p->count = 6;
        p->ntaper = 0;
        p->taper_random = 1;
        p->taper_max = 0.008f;
        p->twist_random = 1;
        p->twist_max = 1.5f;
        p->spacing = 9.0f;
        p->tube_radius = 2.0f;
        p->wobble = 0.6f;
        p->length = 128.0f;
        p->segments = 10;
        p->rings = 0;
        return 0;
    }
    return -1;
}

/* One swept profile: at height z its points are
 * Rot(angle0 + twist z) * ((orbit + wobble(z), 0) + size(z) u_j), size(z) = size + grow z. */
typedef struct Prof {
    double size, grow;
    double angle0, twist;
    double orbit, wob_amp, wob_freq, wob_phase;
} Prof;

typedef struct Shape {
    int m;          /* points around the profile */
    double (*u)[2]; /* unit profile: circle radius 1, or rectangle half-sizes 1 x aspect */
    double *phi;    /* angle of u_j measured from u_0, increasing, in [0, 2 pi) */
    int smooth;     /* circles get smooth wall normals */
} Shape;

static double prof_size(const Prof *p, double z)
{
    return p->size + p->grow * z;
}

static double prof_angle(const Prof *p, double z)
{
    return p->angle0 + p->twist * z;
}

static vec3 prof_point(const Prof *p, const Shape *s, int j, double z)
{
    double r = prof_size(p, z), th = prof_angle(p, z);
    double lx = p->orbit + p->wob_amp * sin(p->wob_freq * z + p->wob_phase) + r * s->u[j][0];
    double ly = r * s->u[j][1];
    double c = cos(th), sn = sin(th);
    return v3((float)(c * lx - sn * ly), (float)(sn * lx + c * ly), (float)z);
}

static vec3 prof_centre(const Prof *p, double z)
{
    double lx = p->orbit + p->wob_amp * sin(p->wob_freq * z + p->wob_phase);
    double th = prof_angle(p, z);
    return v3((float)(cos(th) * lx), (float)(sin(th) * lx), (float)z);
}

static int shape_make(Shape *s, int rect, double aspect, int m)
{
    if (rect) m = (m + 3) / 4 * 4;
    s->m = m;
    s->smooth = !rect;
    s->u = malloc((size_t)m * sizeof *s->u);
    s->phi = malloc((size_t)m * sizeof *s->phi);
    if (!s->u || !s->phi) return -1;
    int q = m / 4;
    for (int j = 0; j < m; j++) {
        if (!rect) {
            s->u[j][0] = cos(2 * PI_D * j / m);
            s->u[j][1] = sin(2 * PI_D * j / m);
            continue;
        }
        /* counter-clockwise from corner (1, -aspect), q points per side */
        int side = j / q;
        double t = (double)(j % q) / q;
        static const double c0[4][2] = {{1, -1}, {1, 1}, {-1, 1}, {-1, -1}};
        static const double c1[4][2] = {{1, 1}, {-1, 1}, {-1, -1}, {1, -1}};
        s->u[j][0] = c0[side][0] + t * (c1[side][0] - c0[side][0]);
        s->u[j][1] = aspect * (c0[side][1] + t * (c1[side][1] - c0[side][1]));
    }
    double a0 = atan2(s->u[0][1], s->u[0][0]);
    for (int j = 0; j < m; j++) {
        double a = atan2(s->u[j][1], s->u[j][0]) - a0;
        while (a < 0) a += 2 * PI_D;
        s->phi[j] = j == 0 ? 0.0 : a;
    }
    return 0;
}

static void shape_release(Shape *s)
{
    free(s->u);
    free(s->phi);
}

/* Adds a vertex with a normal (when the mesh has normals); UINT32_MAX on failure. */
static uint32_t add_v(Mesh *m, vec3 p, vec3 n)
{
    uint32_t i = mesh_add_vertex(m, p);
    if (i != UINT32_MAX && m->normals) m->normals[i] = n;
    return i;
}

/* The side wall of profile p over the rings; outward = 1 faces away from the profile's
 * inside (a solid or the outer wall of a band), 0 faces into it (inner wall of a band). */
static int add_wall(Mesh *m, const Prof *p, const Shape *s, const double *zs, int rings,
                    int outward)
{
    uint32_t first = m->nverts;
    int M = s->m;
    for (int k = 0; k <= rings; k++)
        for (int j = 0; j < M; j++)
            if (add_v(m, prof_point(p, s, j, zs[k]), v3(0, 0, 0)) == UINT32_MAX) return -1;
    for (int k = 0; k < rings; k++)
        for (int j = 0; j < M; j++) {
            uint32_t a = first + (uint32_t)(k * M + j), b = first + (uint32_t)(k * M + (j + 1) % M);
            uint32_t c = b + (uint32_t)M, d = a + (uint32_t)M;
            int rc = outward ? mesh_add_triangle(m, a, b, c) | mesh_add_triangle(m, a, c, d)
                             : mesh_add_triangle(m, a, c, b) | mesh_add_triangle(m, a, d, c);
            if (rc) return -1;
        }
    if (m->normals) {
        /* smooth normals: area-weighted face normals summed at the wall's vertices */
        uint32_t t0 = m->ntris - (uint32_t)(2 * rings * M);
        for (uint32_t t = t0; t < m->ntris; t++) {
            uint32_t *v = &m->tris[3 * t];
            vec3 n = v3_cross(v3_sub(m->verts[v[1]], m->verts[v[0]]),
                              v3_sub(m->verts[v[2]], m->verts[v[0]]));
            for (int c = 0; c < 3; c++) m->normals[v[c]] = v3_add(m->normals[v[c]], n);
        }
        for (uint32_t i = first; i < m->nverts; i++) m->normals[i] = v3_norm(m->normals[i]);
    }
    return 0;
}

/* A flat cap of a solid profile at height z: a fan to the profile's centre, facing
 * -z (bottom) or +z (top). */
static int add_fan_cap(Mesh *m, const Prof *p, const Shape *s, double z, int top)
{
    vec3 n = v3(0, 0, top ? 1.0f : -1.0f);
    uint32_t c = add_v(m, prof_centre(p, z), n), first = m->nverts;
    if (c == UINT32_MAX) return -1;
    for (int j = 0; j < s->m; j++)
        if (add_v(m, prof_point(p, s, j, z), n) == UINT32_MAX) return -1;
    for (int j = 0; j < s->m; j++) {
        uint32_t a = first + (uint32_t)j, b = first + (uint32_t)((j + 1) % s->m);
        if ((top ? mesh_add_triangle(m, c, a, b) : mesh_add_triangle(m, c, b, a)) < 0) return -1;
    }
    return 0;
}

static double zcross(vec3 a, vec3 b, vec3 c)
{
    return ((double)b.x - a.x) * ((double)c.y - a.y) - ((double)b.y - a.y) * ((double)c.x - a.x);
}

/* The flat annulus between an inner and an outer profile (both about the Z axis) at height
 * z, triangulated by walking both rings in angular order. Returns 0, -1 (memory) or -3
 * when a triangle folds over (the rings are too close for the tessellation). */
static int add_band_cap(Mesh *m, const Prof *in, const Prof *out, const Shape *s, double z, int top)
{
    int M = s->m;
    vec3 n = v3(0, 0, top ? 1.0f : -1.0f);
    uint32_t fi = m->nverts;
    for (int j = 0; j < M; j++)
        if (add_v(m, prof_point(in, s, j, z), n) == UINT32_MAX) return -1;
    uint32_t fo = m->nverts;
    for (int j = 0; j < M; j++)
        if (add_v(m, prof_point(out, s, j, z), n) == UINT32_MAX) return -1;
    /* angles from inner point 0: inner A[i] = phi[i]; outer O[o] for outer point s0 + o,
     * unwrapped to increase from the smallest; both end one turn later */
    double delta = prof_angle(out, z) - prof_angle(in, z);
    double *A = malloc(2 * (size_t)(M + 1) * sizeof *A), *O = A + M + 1;
    if (!A) return -1;
    int s0 = 0;
    for (int j = 0; j < M; j++) {
        double b = fmod(s->phi[j] + delta, 2 * PI_D);
        O[j] = b < 0 ? b + 2 * PI_D : b;
        if (O[j] < O[s0]) s0 = j;
    }
    double first = O[s0];
    for (int j = 0; j < M; j++) {
        A[j] = s->phi[j];
        double b = s->phi[(s0 + j) % M] + delta;
        while (b - first >= 2 * PI_D) b -= 2 * PI_D;
        while (b < first) b += 2 * PI_D;
        O[j] = b;
    }
    A[M] = 2 * PI_D;
    O[M] = first + 2 * PI_D;
    int i = 0, o = 0, rc = 0;
    while ((i < M || o < M) && rc == 0) {
        uint32_t vi = fi + (uint32_t)(i % M), vo = fo + (uint32_t)((s0 + o) % M);
        uint32_t a = vi, b, c = vo;
        if (o == M || (i < M && A[i + 1] < O[o + 1])) {
            b = fi + (uint32_t)((i + 1) % M);
            i++;
        } else {
            b = fo + (uint32_t)((s0 + o + 1) % M);
            o++;
        }
        /* walking counter-clockwise, each triangle's natural winding faces -z */
        if (zcross(m->verts[a], m->verts[b], m->verts[c]) >= 0)
            rc = -3;
        else
            rc = top ? mesh_add_triangle(m, a, c, b) : mesh_add_triangle(m, a, b, c);
    }
    free(A);
    return rc;
}

static int sweep_solid(Mesh *m, const Prof *p, const Shape *s, const double *zs, int rings)
{
    if (s->smooth && mesh_enable_normals(m) < 0) return -1;
    if (add_wall(m, p, s, zs, rings, 1) < 0) return -1;
    if (add_fan_cap(m, p, s, zs[0], 0) < 0) return -1;
    return add_fan_cap(m, p, s, zs[rings], 1);
}

static int sweep_band(Mesh *m, const Prof *in, const Prof *out, const Shape *s, const double *zs,
                      int rings)
{
    if (s->smooth && mesh_enable_normals(m) < 0) return -1;
    if (add_wall(m, out, s, zs, rings, 1) < 0 || add_wall(m, in, s, zs, rings, 0) < 0) return -1;
    int rc = add_band_cap(m, in, out, s, zs[0], 0);
    if (rc == 0) rc = add_band_cap(m, in, out, s, zs[rings], 1);
    return rc;
}

/* Reads n values from a list, or draws them uniformly in [-max, max]. */
static void fill_values(double *v, int n, const float *list, int nlist, int random, double max,
                        TexRng *rng)
{
    for (int i = 0; i < n; i++)
        v[i] = random ? max * (2.0 * texrng_uniform(rng) - 1.0) : i < nlist ? list[i] : 0.0;
}

static void format_list(char *buf, size_t len, const float *v, int n, int random, float max,
                        const char *name)
{
    size_t k = 0;
    if (random) {
        char f[32];
        snprintf(buf, len, " --%s random --%s-max %s", name, name,
                 texgen_float_str(f, sizeof f, max));
        return;
    }
    if (n == 0) {
        buf[0] = 0;
        return;
    }
    k += (size_t)snprintf(buf, len, " --%s ", name);
    for (int i = 0; i < n && k < len; i++) {
        char f[32];
        k += (size_t)snprintf(buf + k, len - k, "%s%s", i ? "," : "",
                              texgen_float_str(f, sizeof f, v[i]));
    }
}

static int check_common(const DeformParams *p, char *err, size_t errlen)
{
    if (p->count < 1 || p->count > DEFORM_MAX) {
        snprintf(err, errlen, "--count %d: expected 1 to %d profiles", p->count, DEFORM_MAX);
        return -1;
    }
    if (p->ntaper && p->ntaper != p->count) {
        snprintf(err, errlen, "--taper has %d values but --count is %d: expected one per profile",
                 p->ntaper, p->count);
        return -1;
    }
    if (p->ntwist && p->ntwist != p->count) {
        snprintf(err, errlen, "--twist has %d values but --count is %d: expected one per profile",
                 p->ntwist, p->count);
        return -1;
    }
    if (!(p->length > 0.0f) || !isfinite(p->length)) {
        snprintf(err, errlen, "--length %g: expected a positive Max_Z", p->length);
        return -1;
    }
    if (!(p->spacing > 0.0f) || !isfinite(p->spacing)) {
        snprintf(err, errlen, "--spacing %g: expected a positive clearance C", p->spacing);
        return -1;
    }
    if (!(p->aspect > 0.0f && p->aspect <= 1.0f)) {
        snprintf(err, errlen, "--aspect %g: expected a rectangle height/width in (0, 1]",
                 p->aspect);
        return -1;
    }
    if (!(p->taper_max >= 0.0f) || !(p->twist_max >= 0.0f) || !isfinite(p->taper_max) ||
        !isfinite(p->twist_max)) {
        snprintf(err, errlen, "--taper-max %g / --twist-max %g: expected values >= 0", p->taper_max,
                 p->twist_max);
        return -1;
    }
    if (p->segments < 3 || p->segments > MAX_SEGMENTS || p->rings < 0 || p->rings > MAX_RINGS) {
        snprintf(err, errlen, "--segments %d / --rings %d: expected 3..%d and 1..%d (0: auto)",
                 p->segments, p->rings, MAX_SEGMENTS, MAX_RINGS);
        return -1;
    }
    for (int i = 0; i < p->ntaper; i++)
        if (!isfinite(p->taper[i]) || fabsf(p->taper[i]) > 10.0f) {
            snprintf(err, errlen, "--taper value %g: expected a slope in [-10, 10]", p->taper[i]);
            return -1;
        }
    for (int i = 0; i < p->ntwist; i++)
        if (!isfinite(p->twist[i]) || fabsf(p->twist[i]) > 3600.0f) {
            snprintf(err, errlen, "--twist value %g: expected degrees per unit z in [-3600, 3600]",
                     p->twist[i]);
            return -1;
        }
    return 0;
}

/* Rings along z: the given number, or enough that no profile turns more than RING_STEP
 * between two rings (and, for wobbling tubes, 16 per wobble cycle). */
static int ring_count(const DeformParams *p, const Prof *pr, int n)
{
    if (p->rings > 0) return p->rings;
    double tmax = 0, fwob = 0;
    for (int i = 0; i < n; i++) {
        tmax = fmax(tmax, fabs(pr[i].twist));
        if (pr[i].wob_amp > 0) fwob = fmax(fwob, pr[i].wob_freq);
    }
    double r = ceil(tmax * p->length / RING_STEP);
    r = fmax(r, ceil(fwob * p->length / (2 * PI_D) * 16));
    if (r < 1) r = 1;
    return r > MAX_RINGS ? MAX_RINGS : (int)r;
}

/* The nested profiles' sizes, growth and twists: untwisted, R_i = i C; twisted
 * rectangles, both edges of i+1 longer than the diagonal of i (g = sqrt(1 + k^2) / k);
 * twisted circles, the polygon's circumradius over its inradius. Returns 0, or -1 with the
 * clearance rule's message (thesis 2.2.2.2) in err. */
static int profiles_nested(const DeformParams *p, const double *a, const double *t, double amax,
                           int twisted, int segments, Prof *pr, char *err, size_t errlen)
{
    const double L = p->length, C = p->spacing, k = p->aspect;
    double g = 1.0;
    if (twisted) g = p->rect ? sqrt(1.0 + k * k) / k : 1.0 / cos(PI_D / segments);
    double lim = 2.0 * g * amax * L;
    if (!(C > lim)) {
        snprintf(err, errlen,
                 "clearance rule violated: --spacing C = %g must exceed 2*g*max|a|*Max_Z = "
                 "2*%.4g*%.4g*%g = %.4g (thesis 2.2.2.2); expected a larger --spacing, a "
                 "shorter --length or smaller tapers",
                 C, g, amax, L, lim);
        return -1;
    }
    double R = C;
    for (int i = 0; i < p->count; i++) {
        pr[i].size = R;
        pr[i].grow = a[i] + (i > 0 ? a[i - 1] : 0.0); /* X_i = (f_i + f_{i-1} + 1) x */
        pr[i].twist = t[i] * PI_D / 180.0;
        R = g * R + C;
    }
    return 0;
}

/* The tubes: lane m is the annulus around D_m = (m + 1) C; the tube (radius r + a z,
 * wobbling by +-w) must stay inside it whatever the twists do. Returns as profiles_nested. */
static int profiles_tubes(const DeformParams *p, const double *a, const double *t, double amax,
                          double circ, TexRng *rng, Prof *pr, char *err, size_t errlen)
{
    const double L = p->length, C = p->spacing;
    double rmax = p->tube_radius + amax * L, rmin = p->tube_radius - amax * L;
    double w = p->wobble * 0.5 * (C - 2.0 * rmax * circ);
    if (!(rmin > 0) || !(w >= 0) || !(p->wobble >= 0.0f && p->wobble < 1.0f)) {
        snprintf(err, errlen,
                 "clearance rule violated: tubes of radius %g +- %.4g (taper over Max_Z) need "
                 "a positive radius and lanes wider than %.4g (--spacing %g, --wobble %g in "
                 "[0, 1))",
                 p->tube_radius, amax * L, 2.0 * rmax * circ, C, p->wobble);
        return -1;
    }
    for (int i = 0; i < p->count; i++) {
        pr[i].size = p->tube_radius;
        pr[i].grow = a[i];
        pr[i].twist = t[i] * PI_D / 180.0;
        pr[i].orbit = (i + 1) * C;
        pr[i].angle0 = 2 * PI_D * texrng_uniform(rng);
        pr[i].wob_amp = w;
        pr[i].wob_freq = 2 * PI_D * (1 + (int)(3 * texrng_uniform(rng))) / L;
        pr[i].wob_phase = 2 * PI_D * texrng_uniform(rng);
    }
    return 0;
}

/* The command line that reproduces the set, as its params. */
static void deform_params_text(const DeformParams *p, int segments, int rings, TexSet *out)
{
    char tl[256], wl[256];
    format_list(tl, sizeof tl, p->taper, p->ntaper, p->taper_random, p->taper_max, "taper");
    format_list(wl, sizeof wl, p->twist, p->ntwist, p->twist_random, p->twist_max, "twist");
    char fs[32], fl[32], fa[32];
    snprintf(out->params, sizeof out->params,
             "deform --kind %s --profile %s --count %d --spacing %s%s%s --length %s "
             "--segments %d --rings %d --seed %llu%s%s",
             p->kind == DEFORM_NESTED ? "nested" : "tubes", p->rect ? "rect" : "circle", p->count,
             texgen_float_str(fs, sizeof fs, p->spacing), tl, wl,
             texgen_float_str(fl, sizeof fl, p->length), segments, rings,
             (unsigned long long)p->seed, p->rect ? " --aspect " : "",
             p->rect ? texgen_float_str(fa, sizeof fa, p->aspect) : "");
    if (p->kind == DEFORM_TUBES) {
        size_t len = strlen(out->params);
        char fr[32], fw[32];
        snprintf(out->params + len, sizeof out->params - len, " --tube-radius %s --wobble %s",
                 texgen_float_str(fr, sizeof fr, p->tube_radius),
                 texgen_float_str(fw, sizeof fw, p->wobble));
    }
}

/* The texture block: out to the farthest any profile reaches from the axis, z over the
 * length. */
static void deform_block(const DeformParams *p, const Prof *pr, double circ, TexSet *out)
{
    double ext = 0, L = p->length;
    for (int i = 0; i < p->count; i++) {
        double r = fmax(prof_size(&pr[i], 0), prof_size(&pr[i], L)) * circ;
        ext = fmax(ext, pr[i].orbit + pr[i].wob_amp + r);
    }
    out->block_lo[0] = out->block_lo[1] = (float)-ext;
    out->block_hi[0] = out->block_hi[1] = (float)ext;
    out->block_lo[2] = 0.0f;
    out->block_hi[2] = (float)L;
}

/* The elements: the solids (tubes), or the regions inside an odd number of nested
 * profiles: bands (n-1, n), (n-3, n-2), ..., and the core when n is odd. Returns 0, -3 (a
 * band's cap folds over) or another negative value (out of memory). */
static int deform_elements(const DeformParams *p, const Prof *pr, const Shape *s, const double *zs,
                           int rings, TexSet *out)
{
    int rc = 0;
    for (int hi = p->count - 1; hi >= 0 && rc == 0; hi -= (p->kind == DEFORM_NESTED ? 2 : 1)) {
        Mesh m;
        mesh_init(&m);
        int band = p->kind == DEFORM_NESTED && hi > 0;
        rc = band ? sweep_band(&m, &pr[hi - 1], &pr[hi], s, zs, rings)
                  : sweep_solid(&m, &pr[hi], s, zs, rings);
        if (rc) {
            mesh_free(&m);
            break;
        }
        vec3 lo, hi3;
        mesh_bounds(&m, &lo, &hi3);
        vec3 c = v3_scale(v3_add(lo, hi3), 0.5f);
        float bound[4] = {c.x, c.y, c.z, v3_len(v3_sub(hi3, c))};
        if (texset_add(out, &m, bound) < 0) rc = -1;
    }
    return rc;
}

/* Checks that no profile turns more than 45 degrees between two rings. */
static int check_rings(const Prof *pr, int n, double L, int rings, char *err, size_t errlen)
{
    for (int i = 0; i < n; i++)
        if (fabs(pr[i].twist) * L / rings > PI_D / 4) {
            snprintf(err, errlen,
                     "--rings %d: profile %d turns %.4g degrees between rings; expected at most 45 "
                     "(more --rings, or 0 for automatic)",
                     rings, i + 1, fabs(pr[i].twist) * L / rings * 180 / PI_D);
            return -1;
        }
    return 0;
}

/* Sweeps the elements of the set and checks them (disjoint). Returns as texgen_deform. */
static int deform_sweep(const DeformParams *p, const Prof *pr, const Shape *s, int rings,
                        TexSet *out, char *err, size_t errlen)
{
    double *zs = malloc((size_t)(rings + 1) * sizeof *zs);
    if (!zs) {
        snprintf(err, errlen, "out of memory");
        return -2;
    }
    for (int r = 0; r <= rings; r++) zs[r] = (double)p->length * r / rings;
    int rc = deform_elements(p, pr, s, zs, rings, out);
    free(zs);
    if (rc == -3) {
        snprintf(err, errlen,
                 "a band's end cap folds over: the profiles are too close for %d segments; "
                 "expected a larger --spacing or more --segments",
                 p->segments);
        return -1;
    }
    if (rc) {
        snprintf(err, errlen, "out of memory");
        return -2;
    }
    if (texset_check_disjoint(out, err, errlen)) {
        size_t len = strlen(err);
        snprintf(err + len, errlen - len,
                 ": the tessellation is too coarse for the deformation; expected more --rings "
                 "or --segments, or a larger --spacing");
        return -1;
    }
    return 0;
}

int texgen_deform(const DeformParams *p, TexSet *out, char *err, size_t errlen)
{
    if (check_common(p, err, errlen)) return -1;
    int n = p->count;
    TexRng rng;
    texrng_seed(&rng, p->seed);
    double a[DEFORM_MAX], t[DEFORM_MAX];
    fill_values(a, n, p->taper, p->ntaper, p->taper_random, p->taper_max, &rng);
    fill_values(t, n, p->twist, p->ntwist, p->twist_random, p->twist_max, &rng);
    double amax = p->taper_random ? p->taper_max : 0.0;
    int twisted = p->twist_random && p->twist_max > 0;
    for (int i = 0; i < n; i++) {
        if (!p->taper_random) amax = fmax(amax, fabs(a[i]));
        if (t[i] != 0.0) twisted = 1;
    }
    Shape s;
    if (shape_make(&s, p->rect, p->aspect, p->segments) < 0) {
        shape_release(&s);
        snprintf(err, errlen, "out of memory");
        return -2;
    }
    /* circumradius over inradius-like ratio of one profile to the next (thesis 2.2.2.2) */
    double circ = p->rect ? sqrt(1.0 + (double)p->aspect * p->aspect) : 1.0;
    Prof pr[DEFORM_MAX];
    memset(pr, 0, sizeof pr);
    int rc = p->kind == DEFORM_NESTED
                 ? profiles_nested(p, a, t, amax, twisted, s.m, pr, err, errlen)
                 : profiles_tubes(p, a, t, amax, circ, &rng, pr, err, errlen);
    int rings = rc ? 0 : ring_count(p, pr, n);
    if (!rc) rc = check_rings(pr, n, p->length, rings, err, errlen);
    if (!rc) {
        texset_init(out);
        deform_params_text(p, s.m, rings, out);
        deform_block(p, pr, circ, out);
        rc = deform_sweep(p, pr, &s, rings, out, err, errlen);
        if (rc) texset_free(out);
    }
    shape_release(&s);
    return rc;
}
