#line 2 "light.cl"
/* light.cl — local shading (thesis 4.1.1, 4.1.4): ambient + diffuse + specular from
 * spherical lights, with shadow feelers to stratified points on the visible cap. */
#ifndef VBCL_LIGHT_CL
#define VBCL_LIGHT_CL

#include "medium.cl"
#include "objects.cl"
#include "sample.cl"
#include "scene.cl"

/* Solid angle of the cap of a sphere of radius r seen from distance d > r:
 * 2 pi (1 - cos theta_max), with sin theta_max = r / d. */
VB_INLINE float light_cap_solid_angle(float r, float d)
{
    float s2 = (r * r) / (d * d);
    /* 1 - sqrt(1 - s2) without cancellation for small caps */
    return 2.0f * VB_PI * s2 / (1.0f + sqrt(fmax(0.0f, 1.0f - s2)));
}

/* Two unit vectors completing w to an orthonormal frame (Duff et al. 2017). */
VB_INLINE void vb_frame(float3 w, float3 *t, float3 *b)
{
    float s = copysign(1.0f, w.z);
    float a = -1.0f / (s + w.z);
    float c = w.x * w.y * a;
    *t = (float3)(1.0f + s * w.x * w.x * a, s * c, -s * w.x);
    *b = (float3)(c, s + w.y * w.y * a, -w.y);
}

/* A point being shaded, as seen by the ray that found it. */
typedef struct ShadePoint {
    float3 p;  /* position */
    float3 ng; /* unit geometric normal, on the side the ray came from */
    float3 ns; /* unit shading normal, same side */
    float3 wo; /* unit direction back along the ray */
    uint material;
    uint key;        /* decorrelates this point's random jitter */
    VbMedium medium; /* the medium on the viewer's side, where shadow feelers start */
    float err;       /* the ray offsets: 16 bounds of p's distance from its plane (offset.h) */
    int object;      /* the object whose surface it is, or -1: not known, or a texture's */
    int tri;         /* the triangle it lies on, or -1: not known */
    int front;       /* ng is the triangle's own normal (outward, on a closed object) */
    int band;        /* wavelength band of the ray that found it, or -1: white */
} ShadePoint;

/* What a shadow feeler from sp lets through toward a light at distance t: 0 or 1, or,
 * with transparent objects, the transmittance of the interfaces and media it crosses; only
 * the objects of os can stop it (os->n < 0: any object, through the grid). A program with
 * transparency takes the second way for every scene (it is exact for opaque ones too), so
 * that it holds one copy of each walk. */
VB_INLINE float3 light_feeler(const DevScene *sc, const ShadePoint *sp, const ObjectSet *os,
                              float3 origin, float3 w, float t, TraceCount *tc)
{
#ifdef VBCL_HAS_TRANSPARENCY
    return medium_shadow_transmittance(sc, os, origin, w, t, sp->medium, sp->band, tc);
#else
    (void)sp;
    /* Without transparency every host and element is opaque: a texture surface that a
     * feeler from outside meets before its host's surface lies outside the host, where the
     * texture does not exist, and one inside a host lies behind the host's opaque surface.
     * So texture triangles never stop a feeler here. */
    const uint skip = (sc->f->flags & VBCL_FRAME_TEXTURES) ? VBCL_TAG_TEXTURE : 0u;
    return scene_trace_any_in(sc, os, origin, w, t, skip, tc) ? (float3)(0.0f) : (float3)(1.0f);
#endif
}

/* What a feeler from sp that meets no surface lets through over distance t: all of it,
 * or with transparent objects what the medium it starts in absorbs, exactly as
 * light_feeler computes it when its walk finds nothing. */
VB_INLINE float3 light_feeler_open(const DevScene *sc, const ShadePoint *sp, float t)
{
#ifdef VBCL_HAS_TRANSPARENCY
    return medium_absorb(sc, medium_material(sc, sp->medium), t); /* 1 * x is x */
#else
    (void)sc;
    (void)sp;
    (void)t;
    return (float3)(1.0f);
#endif
}

/* Counts of one work item's shadow feelers, summed by the caller: traced; skipped, the
 * light being below the surface's horizon; unneeded, the BRDF giving the direction
 * nothing (no diffuse term, and outside the specular lobe: (N.H)^n < 1e-4), so that
 * whether the light is visible there changes nothing; clear, not traced because the cone
 * they lie in meets no object (light_cone_objects); blocked, not traced because they pass
 * through the core of a solid texture part (object_set_feeler). */
typedef struct ShadowCount {
    uint traced;
    uint skipped;
    uint unneeded;
    uint clear;
    uint blocked;
    uint penumbra; /* points (per light) whose first feelers disagreed and got more */
} ShadowCount;

/* What shading a point under one light needs besides the point itself: the BRDF's
 * terms, where its feelers start, and where the light's centre is. */
typedef struct LightShading {
    float3 kd; /* diffuse / pi */
#ifdef VBCL_HAS_SPECULAR
    float3 ks;
    float spec_norm; /* normalises the Blinn-Phong lobe: (n + 8) / (8 pi) */
    float nh_min;    /* (N.H)^n < 1e-4 below this cosine: such samples skip the costly pow */
    float exponent;
#endif
    int diffuse; /* kd is not zero */
#ifdef VBCL_HAS_SPECULAR
    int specular; /* ks is not zero */
#endif
    float3 origin; /* feelers start here, off the surface on the viewer's side */
    float3 to_c;   /* from the point to the light's centre */
    float d2, d;   /* its squared length and length */
} LightShading;

/* The cosine N.H below which the Blinn-Phong lobe of exponent n, (N.H)^n, is under 1e-4. */
VB_INLINE float light_nh_min(float exponent)
{
    return exp(-9.2103f / fmax(exponent, 1e-3f));
}

#ifdef VBCL_HAS_SPECULAR
/* The Blinn-Phong lobe (N.H)^n for nh in (nh_min, 1]: exp2(n log2 nh), each within 3 ulp
 * (OpenCL 1.2), in place of powr and its argument reduction in extended precision. Above
 * nh_min, n |log2 nh| < 13.3, so the result is within about 4e-6 of the exact power,
 * relative. */
VB_INLINE float light_lobe(float nh, float exponent)
{
    return exp2(exponent * log2(nh));
}
#endif

/* The distance along unit w from the point of ls to the near side of the light sphere of
 * radius r (w a direction of the light's cap: the line meets the sphere). */
VB_INLINE float light_sphere_near(const LightShading *ls, float3 w, float r)
{
    float b = dot(w, ls->to_c);
    return b - sqrt(fmax(0.0f, b * b - (ls->d2 - r * r)));
}

/* The terms of the BRDF at sp for material m (its diffuse colour `diffuse`, pattern
 * included) under a light whose centre is c. */
VB_INLINE LightShading light_shading_make(__global const VbMaterial *m, float3 diffuse,
                                          const ShadePoint *sp, float3 c)
{
    LightShading ls;
    ls.to_c = c - sp->p;
    ls.d2 = dot(ls.to_c, ls.to_c);
    ls.d = sqrt(ls.d2);
    ls.kd = diffuse * (1.0f / VB_PI);
    ls.diffuse = vb_max3(ls.kd) > 0.0f;
#ifdef VBCL_HAS_SPECULAR
    ls.ks = vb_gload3(m->specular);
    ls.specular = vb_max3(ls.ks) > 0.0f;
    ls.exponent = m->exponent;
    ls.spec_norm = (m->exponent + 8.0f) * (1.0f / (8.0f * VB_PI));
    ls.nh_min = light_nh_min(m->exponent);
#else
    (void)m;
#endif
    ls.origin = ray_offset_origin(sp->p, sp->ng, sp->err);
    return ls;
}

/* The triangles that feelers from ls->origin toward the light sphere (radius r, 0 for a
 * point light) may meet (VBCL_FRAME_CONE_TEST; the host sets it for scenes of at most
 * VBCL_CONE_TEST_MAX_OBJECTS objects): none, so that no feeler need be traced; a few
 * (at most VB_OBJECT_SET_MAX ranges of VBCL_OBJECT_SET_MAX_TRIS triangles in all, held four
 * at a time in the records' quads: VbObject.quad_tri, quad_tex), which alone each feeler
 * then tests, without walking the grid; or n = -1, the grid (too many, or the
 * test off). Every feeler lies in the cone from the origin around the direction to the
 * light's centre, of half-angle theta with sin theta = r / d, and ends before distance d;
 * an object can stop one only if the cone meets its bounds (light_cone_meets). Where it
 * does, its own triangles are taken, and of its texture only the parts (connected pieces,
 * VbObject.first_elem) whose own bounds the cone meets; an object or part of more than
 * VBCL_OBJECT_SET_MAX_TRIS / 2 triangles is kept aside as big instead (a glass ball of
 * thousands of triangles: only the feelers that meet its bounding sphere walk the grid). The
 * point's own object cannot stop a feeler when it is planar (a feeler is traced only toward the
 * side of the surface it leaves from), nor when it is convex and the feeler leaves from the front
 * of its triangle: all of the object lies behind that triangle's plane; the same holds for the
 * convex part of a texture the point lies on, for a host's own triangles where they bound a
 * convex volume (VBCL_OBJECT_HULL), and for the parts of its texture that lie behind that
 * plane (VbObject.ahead, part_ahead_bit). Margins (1e-5 of the distances, the host's
 * planarity margin) keep float rounding on the safe side: a triangle left out is one no
 * feeler's walk would meet, and the image is the same as with every feeler walked through
 * the grid. */
VB_INLINE void light_cone_objects(const DevScene *scn, const ShadePoint *sp, const LightShading *ls,
                                  float r, ObjectSet *os)
{
    os->n = -1;
    os->sole = -1;
    os->shell = -1;
    if (!(scn->f->flags & VBCL_FRAME_CONE_TEST)) return;
    os->n = 0;
    os->tris = 0u;
    os->nbig = 0;
    os->walk = 0;
    LightCone k;
    k.o = ls->origin;
    k.axis = ls->to_c / ls->d;
    k.c = sp->p + ls->to_c;
    k.d = ls->d;
    k.r = r;
    k.sin_t = fmin(1.0f, r / ls->d);
    k.cos_t = sqrt(fmax(0.0f, 1.0f - k.sin_t * k.sin_t));
    k.reach = vb_max3(fabs(k.o)) + vb_max3(fabs(k.c)) + r;
    uint tri = (uint)sp->tri; /* -1: no part's triangle */
    int owners = -1; /* the one object the cone meets, if a convex host; -2: another case */
    for (uint i = 0; i < scn->f->nobjects; i++) {
        __global const VbObject *ob = scn->objects + i;
        uint flags = ob->flags;
        if ((int)i == sp->object &&
            ((flags & VBCL_OBJECT_PLANAR) || ((flags & VBCL_OBJECT_CONVEX) && sp->front)))
            continue;
        if (!light_cone_meets(&k, ob)) continue;
        owners = owners == -1 && (flags & VBCL_OBJECT_HOST) &&
                         (flags & (VBCL_OBJECT_CONVEX | VBCL_OBJECT_HULL))
                     ? (int)i
                     : -2;
        if (ob->ntris > VBCL_OBJECT_SET_MAX_TRIS / 2) { /* each feeler tests its bounds */
            if (!object_set_big(os, i)) return;
            continue;
        }
        /* leaving the point's own host outward: its own triangles lie behind the plane of
         * sp's where they bound a convex volume, as do the parts without its ahead bit */
        uint ahead = (int)i == sp->object && sp->front ? part_ahead_bit(ob, sp->tri) : 0u;
        if (!(ahead && (flags & VBCL_OBJECT_HULL)) && !object_set_add(os, ob->quad_tri, ob->ntris))
            return;
        if (ob->nelems == 0u) {
            if (!object_set_add(os, ob->quad_tex, ob->ntex)) return;
            continue;
        }
        for (uint e = 0; e < ob->nelems; e++) {
            __global const VbObject *el = scn->objects + ob->first_elem + e;
            if (tri - el->first_tri < el->ntris && (el->flags & VBCL_OBJECT_CONVEX) && sp->front)
                continue;
            if ((ahead && !(el->ahead & ahead)) || !light_cone_meets(&k, el)) continue;
            if (el->ntris > VBCL_OBJECT_SET_MAX_TRIS / 2) { /* each feeler tests its bounds */
                if (!object_set_big(os, ob->first_elem + e)) return;
            } else if (!object_set_add(os, el->quad_tri, el->ntris)) {
                return;
            }
        }
    }
    os->sole = owners;
}

/* What feeler (w, t) from origin lets through, where the point's cone gave set os (and
 * tex_free: the point lies outside every texture element), counted in sc by how it was
 * decided: blocked (object_set_feeler: through a solid part's core, nothing gets
 * through), clear (nothing in the way: light_feeler_open), or traced through the set's
 * triangles alone or the grid. */
VB_INLINE float3 light_feeler_decided(const DevScene *scn, const ShadePoint *sp,
                                      const ObjectSet *os, float3 origin, float3 w, float t,
                                      int tex_free, TraceCount *tc, ShadowCount *sc)
{
    int need = os->n >= 0 && os->nbig > 0
                   ? object_set_feeler(scn, os, origin, w, t, tex_free, sp->medium.host)
                   : (os->n < 0 ? OBJECT_SET_GRID : OBJECT_SET_ALONE);
    if (need == OBJECT_SET_BLOCKED) {
        sc->blocked++;
        return (float3)(0.0f);
    }
    if (need == OBJECT_SET_ALONE && os->n == 0) {
        sc->clear++;
        return light_feeler_open(scn, sp, t);
    }
    sc->traced++;
    if (need == OBJECT_SET_GRID && os->n >= 0) {
        /* the set is whole: only a big record's bounds send it to the grid, and only where
         * the feeler lies in them */
        ObjectSet walk = *os;
        walk.walk = 1;
        return light_feeler(scn, sp, &walk, origin, w, t, tc);
    }
    return light_feeler(scn, sp, os, origin, w, t, tc);
}

/* Whether the BRDF gives direction w anything: a diffuse term, or w inside the specular
 * lobe ((N.H)^n >= 1e-4), with *nh = N.H. A feeler the BRDF gives nothing is not traced:
 * the light's visibility there cannot change the image. */
VB_INLINE int light_brdf_responds(const LightShading *ls, const ShadePoint *sp, float3 w, float *nh)
{
#ifdef VBCL_HAS_SPECULAR
    *nh = dot(sp->ns, normalize(w + sp->wo));
    return ls->diffuse || (ls->specular && *nh > ls->nh_min);
#else
    (void)sp;
    (void)w;
    *nh = 0.0f;
    return ls->diffuse;
#endif
}

/* Whether no direction w of the cap of half-angle alpha (sin alpha = sin_a) around wc can
 * reach the specular lobe (N.H > nh_min, light_brdf_responds), so that a point without a
 * diffuse term needs none of its feelers. w is the mirror image of wo about the half
 * vector H, and the mirror direction m is wo's about N; reflecting about H after N is a
 * turn by twice the angle between them, so angle(w, m) <= 2 angle(H, N). Every w lies
 * within alpha of wc: if wc is farther than alpha + 2 acos(nh_min) from m, N.H < nh_min for
 * all of them. Kept for lobes narrower than 45 degrees (2 acos(nh_min) < 90 degrees), with
 * a margin of 1e-4 in the cosine for float rounding. Without a specular term nothing
 * responds at all. */
VB_INLINE int light_lobe_misses_cap(const LightShading *ls, const ShadePoint *sp, float3 wc,
                                    float sin_a)
{
#ifdef VBCL_HAS_SPECULAR
    if (!ls->specular) return 1;
    float cos_2t = 2.0f * ls->nh_min * ls->nh_min - 1.0f;
    if (cos_2t <= 0.0f) return 0;
    float sin_2t = 2.0f * ls->nh_min * sqrt(fmax(0.0f, 1.0f - ls->nh_min * ls->nh_min));
    float cos_a = sqrt(fmax(0.0f, 1.0f - sin_a * sin_a));
    float3 m = 2.0f * dot(sp->ns, sp->wo) * sp->ns - sp->wo;
    return dot(wc, m) < cos_a * cos_2t - sin_a * sin_2t - 1e-4f;
#else
    (void)ls;
    (void)sp;
    (void)wc;
    (void)sin_a;
    return 1;
#endif
}

/* How a point's feelers are placed, from the frame's flags: LIGHT_FEELERS_NET for jittered
 * feelers of a power-of-two side (the host decides, VBCL_FRAME_NET_FEELERS), _JITTERED
 * for other jittered ones, _FIXED at the strata's centres. */
enum { LIGHT_FEELERS_FIXED = 0, LIGHT_FEELERS_JITTERED = 1, LIGHT_FEELERS_NET = 2 };
VB_INLINE int light_feeler_mode(uint flags)
{
    return (flags & VBCL_FRAME_FIXED_FEELERS) ? LIGHT_FEELERS_FIXED
           : (flags & VBCL_FRAME_NET_FEELERS) ? LIGHT_FEELERS_NET
                                              : LIGHT_FEELERS_JITTERED;
}

/* One point's feelers toward one light: how they are placed (LIGHT_FEELERS_*), the
 * point's key and, for the net, its two scramble seeds, hashed once per point rather than
 * once per feeler. */
typedef struct CapFeelers {
    int mode;
    uint strata; /* strata x strata feelers */
    uint key;
    uint seed_u, seed_v;
} CapFeelers;

VB_INLINE CapFeelers light_cap_feelers(int mode, uint strata, uint key)
{
    CapFeelers cf = {mode, strata, key, 0u, 0u};
    if (mode == LIGHT_FEELERS_NET) {
        cf.seed_u = vb_hash(key);
        cf.seed_v = vb_hash(key ^ 0x68bc21ebu);
    }
    return cf;
}

/* Feeler k = i * strata + j, (i, j) of the point's strata x strata, as (u1, u2) in the unit
 * square (for the net, k from strata^2 on continues it: light_penumbra).
 * LIGHT_FEELERS_NET (strata a power of two: 16, the default, 4, 64, ...): point
 * k of the (0, 2)-sequence, Owen-scrambled by the key, a (0, 2m, 2)-net with
 * one point in every elementary rectangle of every shape, so a shadow edge crossing the
 * cap at any angle is sampled more evenly than by jittered squares. _JITTERED: a random
 * point of square stratum (i, j); _FIXED: its centre. */
VB_INLINE float2 light_cap_uv_at(const CapFeelers *cf, uint k)
{
    uint strata = cf->strata;
    if (cf->mode == LIGHT_FEELERS_NET) {
        uint2 q = vb_sobol2_reversed(k);
        return (float2)(vb_unit_float(vb_owen_scramble_reversed(q.x, cf->seed_u)),
                        vb_unit_float(vb_owen_scramble_reversed(q.y, cf->seed_v)));
    }
    uint i = k / strata, j = k - i * strata;
    int jitter = cf->mode == LIGHT_FEELERS_JITTERED;
    uint h = vb_hash(cf->key ^ vb_hash(k + 0x9e3779b9u));
    return (float2)(((float)i + (jitter ? vb_unit_float(h) : 0.5f)) / (float)strata,
                    ((float)j + (jitter ? vb_unit_float(vb_hash(h)) : 0.5f)) / (float)strata);
}

/* light_cap_uv_at of feeler (i, j). */
VB_INLINE float2 light_cap_uv(const CapFeelers *cf, uint i, uint j)
{
    return light_cap_uv_at(cf, i * cf->strata + j);
}

/* The direction at (u1, u2) of the unit square on the cap of half-angle theta_max around
 * wc (frame tx, ty, wc; one_minus_cos = 1 - cos theta_max): uniform in solid angle, u1 the
 * cosine's share (1: the rim) and u2 the turn. */
VB_INLINE float3 light_cap_at(float2 u, float one_minus_cos, float3 tx, float3 ty, float3 wc)
{
    float cos_t = 1.0f - u.x * one_minus_cos;
    float sin_t = sqrt(fmax(0.0f, 1.0f - cos_t * cos_t));
    float turn = 2.0f * u.y; /* phi / pi: cospi and sinpi reduce it exactly */
    return normalize(tx * (sin_t * cospi(turn)) + ty * (sin_t * sinpi(turn)) + wc * cos_t);
}

/* Whether the light's reflected radiance at sp, where no feeler is stopped or dimmed, has a
 * closed form: a diffuse BRDF whose specular lobe, if any, misses the whole cap
 * (light_lobe_misses_cap: no feeler would add a specular term), the whole cap above the
 * horizons of both normals (with a margin for the feelers' rounding) and a medium that absorbs
 * nothing. Then it is L kd pi sin^2(alpha) (ns . wc) exactly (the integral of cos over the
 * cap), the value the feelers' mean estimates. lobe_off: light_lobe_misses_cap's answer for
 * this cap, which the caller has already. */
VB_INLINE int light_cap_closed_form(const DevScene *scn, const ShadePoint *sp,
                                    const LightShading *ls, float3 wc, float sin_max, int lobe_off)
{
    if (!ls->diffuse || !lobe_off) return 0;
#ifdef VBCL_HAS_ABSORPTION
    if ((scn->f->flags & VBCL_FRAME_ABSORPTION) &&
        vb_max3(vb_gload3(scn->materials[medium_material(scn, sp->medium)].extinction)) != 0.0f)
        return 0;
#else
    (void)scn;
#endif
    float m = sin_max + 1e-4f;
    return dot(sp->ns, wc) > m && dot(sp->ng, wc) > m;
}

/* That closed form (light_cap_closed_form), per unit of the light's radiance. */
VB_INLINE float3 light_cap_closed(const LightShading *ls, const ShadePoint *sp, float3 wc,
                                  float sin_max)
{
    return ls->kd * (VB_PI * sin_max * sin_max * dot(sp->ns, wc));
}

#ifdef VBCL_HAS_AREA_LIGHTS
/* Whether a point whose first feelers (cf) let through between lo and hi of the light (the
 * largest channel) traces penumbra_factor times as many: they disagree by more than
 * LIGHT_PENUMBRA_SPREAD, so the cap is part hidden, and there are at least 4 of them in a
 * scrambled net, whose continuation keeps every elementary rectangle filled. Where the first
 * ones agree the point keeps them: a cap all visible or all hidden needs no more. */
#define LIGHT_PENUMBRA_SPREAD 0.05f
VB_INLINE int light_penumbra(__constant const VbFrame *f, const CapFeelers *cf, float lo, float hi)
{
    return f->penumbra_factor > 1u && cf->mode == LIGHT_FEELERS_NET && cf->strata >= 2u &&
           hi - lo > LIGHT_PENUMBRA_SPREAD;
}

/* The direction of feeler (i, j) on the cap (light_cap_at at light_cap_uv). */
VB_INLINE float3 light_cap_direction(const CapFeelers *cf, uint i, uint j, float one_minus_cos,
                                     float3 tx, float3 ty, float3 wc)
{
    return light_cap_at(light_cap_uv(cf, i, j), one_minus_cos, tx, ty, wc);
}

/* Reflected radiance from a spherical light of radius r > 0 that the point sees from
 * outside: the visible cap sampled at strata^2 stratified directions, each direction's
 * feeler traced to the sphere, L * Omega * mean(V * f * cos); where those disagree (a
 * penumbra: light_penumbra) the mean is over penumbra_factor times as many, the net's next
 * points. strata: the point's
 * (light_node_strata); where the specular lobe can reach the cap the frame's own instead,
 * since a highlight's feelers differ far more than a diffuse term's (their spread is what
 * light_node_strata takes to be alike at every point). */
VB_INLINE float3 light_reflect_area(const DevScene *scn, const ShadePoint *sp,
                                    const LightShading *ls, float3 radiance, float r, uint key,
                                    uint strata, TraceCount *tc, ShadowCount *sc)
{
    float3 wc = ls->to_c / ls->d;
    float sin_max = r / ls->d;
    if (dot(sp->ng, wc) < -sin_max) { /* the whole cap is below the horizon */
        sc->skipped += strata * strata;
        return (float3)(0.0f);
    }
    int lobe_off = light_lobe_misses_cap(ls, sp, wc, sin_max);
    if (!lobe_off) strata = scn->f->shadow_strata; /* a highlight keeps all its feelers */
    if (!ls->diffuse && lobe_off) {
        sc->unneeded += strata * strata;
        return (float3)(0.0f);
    }
    ObjectSet os;
    light_cone_objects(scn, sp, ls, r, &os);
    int closed = light_cap_closed_form(scn, sp, ls, wc, sin_max, lobe_off);
    if (closed && os.n == 0 && os.nbig == 0) { /* every feeler would be clear */
        sc->clear += strata * strata;
        return radiance * light_cap_closed(ls, sp, wc, sin_max);
    }
    float omega = light_cap_solid_angle(r, ls->d);
    float one_minus_cos = omega * (1.0f / (2.0f * VB_PI));
    float3 tx, ty;
    vb_frame(wc, &tx, &ty);
    CapFeelers cf = light_cap_feelers(light_feeler_mode(scn->f->flags), strata, key);
    int tex_free = sp->medium.tex_counts == 0u;
    uint open = 0u; /* feelers that found nothing in the way */
    float3 sum_cos = (float3)(0.0f);
#ifdef VBCL_HAS_SPECULAR
    float3 sum_s = (float3)(0.0f);
#endif
    uint n = strata * strata, total = n;
    float vis_lo = 2.0f, vis_hi = -1.0f;
    for (uint k = 0;;) {
        for (; k < total; k++) {
            float3 w = light_cap_at(light_cap_uv_at(&cf, k), one_minus_cos, tx, ty, wc);
            float cos_n = dot(sp->ns, w);
            if (cos_n <= 0.0f || dot(sp->ng, w) <= 0.0f) {
                sc->skipped++;
                continue;
            }
            float nh;
            if (!light_brdf_responds(ls, sp, w, &nh)) {
                sc->unneeded++;
                continue;
            }
            float t_light = light_sphere_near(ls, w, r);
            float3 vis =
                light_feeler_decided(scn, sp, &os, ls->origin, w, t_light, tex_free, tc, sc);
            float v = vb_max3(vis);
            vis_lo = fmin(vis_lo, v);
            vis_hi = fmax(vis_hi, v);
            if (v <= 0.0f) continue;
            open += fmin(vis.x, fmin(vis.y, vis.z)) >= 1.0f;
            sum_cos += vis * cos_n;
#ifdef VBCL_HAS_SPECULAR
            if (ls->specular && nh > ls->nh_min)
                sum_s += vis * (light_lobe(nh, ls->exponent) * cos_n);
#endif
        }
        if (total != n || !light_penumbra(scn->f, &cf, vis_lo, vis_hi)) break;
        total = n * scn->f->penumbra_factor; /* the net's next points: still a (0, 2)-net */
        sc->penumbra++;
    }
    if (closed && open == total) /* as if the cone test had found nothing */
        return radiance * light_cap_closed(ls, sp, wc, sin_max);
    float scale = omega / (float)total;
    float3 sum_d = ls->kd * (sum_cos * scale);
#ifdef VBCL_HAS_SPECULAR
    sum_d += ls->ks * (ls->spec_norm * sum_s * scale);
#endif
    return radiance * sum_d;
}
#endif

/* Reflected radiance toward wo from one light: the cap of the light sphere visible from
 * the point is sampled at strata^2 directions (light_cap_uv: a scrambled net, jittered
 * strata, or the strata's centres with VBCL_FRAME_FIXED_FEELERS); each direction's feeler is
 * traced to the sphere and the unoccluded fraction of the BRDF-weighted integral is kept:
 * L * Omega * mean(V * f * cos). Lights wholly behind the surface cost no feelers. A light
 * of radius 0 is a point light. */
VB_INLINE float3 light_reflect_one(const DevScene *scn, __global const VbLight *light,
                                   __global const VbMaterial *m, float3 diffuse,
                                   const ShadePoint *sp, uint key, uint strata, TraceCount *tc,
                                   ShadowCount *sc)
{
    float3 radiance = vb_gload3(light->radiance);
    float r = light->radius;
    LightShading ls = light_shading_make(m, diffuse, sp, vb_gload3(light->centre));
#ifdef VBCL_HAS_AREA_LIGHTS
    if (r > 0.0f) {
        if (ls.d <= r * 1.0001f) { /* inside the light: lit from every direction, no shadow */
            return radiance * VB_PI * ls.kd;
        }
        return light_reflect_area(scn, sp, &ls, radiance, r, key, strata, tc, sc);
    }
#else
    (void)key;
    (void)strata;
#endif
    /* a point light: radiance holds the intensity (W/sr) */
    float3 w = ls.to_c / ls.d;
    float cos_n = dot(sp->ns, w);
    if (cos_n <= 0.0f || dot(sp->ng, w) <= 0.0f) {
        sc->skipped++;
        return (float3)(0.0f);
    }
    float nh;
    if (!light_brdf_responds(&ls, sp, w, &nh)) {
        sc->unneeded++;
        return (float3)(0.0f);
    }
    float3 brdf = ls.kd;
#ifdef VBCL_HAS_SPECULAR
    if (ls.specular && nh > ls.nh_min) brdf += ls.ks * (ls.spec_norm * light_lobe(nh, ls.exponent));
#endif
    ObjectSet os;
    light_cone_objects(scn, sp, &ls, 0.0f, &os);
    float3 vis =
        light_feeler_decided(scn, sp, &os, ls.origin, w, ls.d, sp->medium.tex_counts == 0u, tc, sc);
    if (vb_max3(vis) <= 0.0f) return (float3)(0.0f);
    return radiance * brdf * vis * (cos_n / ls.d2);
}

/* The side s, halved while (s/2)^2 still holds at least `need` feelers (and above 1). */
VB_INLINE uint light_halve_strata(uint s, float need)
{
    while (s > 1u && (float)((s >> 1) * (s >> 1)) >= need) s >>= 1;
    return s;
}

/* The side of the feeler grid of a point deeper in a ray tree whose local term counts for
 * `weight` (the branch's weight times k_local, largest channel) in its sample: with
 * VBCL_FRAME_WEIGHTED_FEELERS, the frame's strata halved while the smaller grid still has
 * at least strata^2 * weight feelers, so the feelers of a node are about in proportion to
 * its share of the sample (at weight 1/4 a quarter of them, at 1/16 a sixteenth; never
 * fewer than one): the variance a node adds is weight^2 / feelers, and for a fixed number
 * of feelers in all, the sum over nodes is least with feelers in proportion to weight.
 * Otherwise, or for weight above 1/4, all of them.
 * `share` (sample_share: below 1 for an adaptive quadtree sample deeper than the pixel)
 * multiplies the weight, but does not take the point below 2 x 2 where the weight alone
 * gives at least that, so that light_penumbra still looks at its feelers (a single
 * feeler's visibility is all or nothing, and its noise draws splits). */
VB_INLINE uint light_node_strata(__constant const VbFrame *f, float weight, float share)
{
    uint s = f->shadow_strata;
    if (!(f->flags & VBCL_FRAME_WEIGHTED_FEELERS)) return s;
    uint by_weight = light_halve_strata(s, weight * (float)(s * s));
    if (share >= 1.0f) return by_weight;
    return max(min(by_weight, 2u), light_halve_strata(by_weight, weight * share * (float)(s * s)));
}

/* Local radiance toward the viewer at sp (thesis figure 4.7, the k_local term):
 * k_local * (ambient + sum over lights of diffuse + specular). */
VB_INLINE float3 light_shade_local(const DevScene *scn, const ShadePoint *sp, uint strata,
                                   TraceCount *tc, ShadowCount *sc)
{
    __global const VbMaterial *m = scn->materials + sp->material;
    float3 pattern = scene_pattern_colour(scn, m, sp->p);
    float3 col = vb_gload3(m->ambient) * pattern * vb_cload3(scn->f->ambient);
    float3 diffuse = vb_gload3(m->diffuse) * pattern;
    for (uint l = 0; l < scn->f->nlights; l++)
        col += light_reflect_one(scn, scn->lights + l, m, diffuse, sp,
                                 vb_hash(sp->key * 0x27d4eb2fu + l), strata, tc, sc);
    return m->k_local * col;
}

#endif
