#line 2 "medium.cl"
/* medium.cl — volume textures as geometry (thesis 1.2, DESIGN "Volume textures"): each
 * ray carries its medium — which host it is inside and how many of each textured
 * object's elements — updated at every crossing. A crossing is an optical interface only
 * when the effective material changes; any other crossing is passed through. So texture
 * geometry exists only inside its host, a host surface cut by an element has the
 * element's material, and overlapping elements form a union without inner faces. */
#ifndef VBCL_MEDIUM_CL
#define VBCL_MEDIUM_CL

#include "optics.cl"
#include "scene.cl"

/* The effective material where the medium state says the ray is. */
VB_INLINE uint medium_material(const DevScene *sc, VbMedium m)
{
    if (m.host < 0) return sc->f->air_material;
    __global const VbObject *o = sc->objects + m.host;
    if (o->tex_slot >= 0 && ((m.tex_counts >> (8u * (uint)o->tex_slot)) & 0xffu) != 0u)
        return o->tex_material;
    return o->material;
}

/* What crossing triangle `tri` along dir does to the medium. */
typedef struct Crossing {
    VbMedium after;
    uint mat_before, mat_after;
    uint surface;  /* material of the surface: the one on its inner side */
    int interface; /* the effective material changes, or an opaque surface */
} Crossing;

VB_INLINE Crossing medium_cross(const DevScene *sc, int tri, float3 dir, VbMedium before)
{
    Crossing c;
    uint tag = tri_tag(sc->tris, tri);
    uint obj = tag & ~VBCL_TAG_FLAGS;
    __global const VbObject *o = sc->objects + obj;
    int entering = dot(tri_normal(sc->tris, tri), dir) < 0.0f; /* normals point outward */
    c.after = before;
    c.mat_before = medium_material(sc, before);
    if (tag & VBCL_TAG_TEXTURE) {
        uint shift = 8u * (uint)o->tex_slot;
        uint k = (before.tex_counts >> shift) & 0xffu;
        k = entering ? min(k + 1u, 255u) : (k > 0u ? k - 1u : 0u);
        c.after.tex_counts = (before.tex_counts & ~(0xffu << shift)) | (k << shift);
    } else if (o->flags & VBCL_OBJECT_HOST) {
        c.after.host = entering ? (int)obj : -1;
    } else { /* a surface that bounds no tracked volume: opaque */
        c.mat_after = c.surface = o->material;
        c.interface = 1;
        return c;
    }
    c.mat_after = medium_material(sc, c.after);
    c.interface = c.mat_after != c.mat_before;
    c.surface = entering ? c.mat_after : c.mat_before;
    return c;
}

/* Beer–Lambert attenuation exp(-alpha d) over a distance d inside material mat (1 without
 * a load when no material of the scene absorbs). */
VB_INLINE float3 medium_absorb(const DevScene *sc, uint mat, float d)
{
#ifdef VBCL_HAS_ABSORPTION
    if (!(sc->f->flags & VBCL_FRAME_ABSORPTION)) return (float3)(1.0f);
    float3 a = vb_gload3(sc->materials[mat].extinction);
    return select(exp(-a * d), (float3)(1.0f), isequal(a, (float3)(0.0f)));
#else
    (void)sc;
    (void)mat;
    (void)d;
    return (float3)(1.0f);
#endif
}

/* The first interface along a ray. */
typedef struct PathHit {
    VbHit hit;
    float3 p;   /* where */
    float dist; /* distance from the ray's origin */
    Crossing cx;
} PathHit;

/* Follows (org, dir) through pass-through crossings (updating *state and counting them)
 * to the first interface within tmax, among the triangles of os (os->n < 0: any, through
 * the grid; a set holds for every stretch of the ray). Returns 0 when there is none.
 * camera: a camera ray, whose first search is camera_trace_closest. */
VB_INLINE int medium_trace(const DevScene *sc, const ObjectSet *os, float3 org, float3 dir,
                           float tmax, VbMedium *state, PathHit *out, TraceCount *tc, uint *passes,
                           int camera)
{
    float3 o = org;
    for (int guard = 0; guard < 1024; guard++) {
        float done = dot(o - org, dir);
        VbHit h = camera && guard == 0 ? camera_trace_closest(sc, o, dir, tmax - done, tc)
                                       : scene_trace_closest_in(sc, os, o, dir, tmax - done, tc);
        if (h.tri < 0) return 0;
        float3 p = tri_point(sc->tris, h);
        Crossing c = medium_cross(sc, h.tri, dir, *state);
        if (c.interface) {
            out->hit = h;
            out->p = p;
            out->dist = dot(p - org, dir);
            out->hit.t = out->dist;
            out->cx = c;
            return 1;
        }
        *state = c.after;
        (*passes)++;
        float3 ng = tri_normal(sc->tris, h.tri);
        o = ray_offset_origin(p, dot(ng, dir) > 0.0f ? ng : -ng, tri_point_error(sc->tris, h, ng));
    }
    return 0;
}

#ifdef VBCL_HAS_DISPERSION
/* A material's index in band b (its constant eta for white rays or without dispersion). */
VB_INLINE float medium_eta(const DevScene *sc, uint m, int band)
{
    int d = sc->materials[m].disp;
    return (band >= 0 && d >= 0) ? sc->texels[d + 4 * band] : sc->materials[m].eta;
}

/* Fraction of band b that material m lets in (its absorption band takes the rest). */
VB_INLINE float medium_band_transmit(const DevScene *sc, uint m, int band)
{
    int d = sc->materials[m].disp;
    return (band >= 0 && d >= 0) ? sc->texels[d + 4 * band + 1] : 1.0f;
}
#endif

/* The fraction of light of band `band` (-1: white) that crosses the interface from
 * material mb into ma along d, per channel. White light crossing into or out of a
 * dispersive material is the band-weighted sum over the bands, each with its own index and
 * with what the entered material's absorption band lets through. */
VB_INLINE float3 medium_interface_transmit(const DevScene *sc, float3 d, float3 ng, uint mb,
                                           uint ma, int band)
{
    int thesis = (sc->f->flags & VBCL_FRAME_FRESNEL_THESIS) != 0u;
#ifdef VBCL_HAS_DISPERSION
    if (band >= 0)
        return (float3)(optics_transmitted_fraction(d, ng, medium_eta(sc, mb, band),
                                                    medium_eta(sc, ma, band), thesis) *
                        medium_band_transmit(sc, ma, band));
    if (sc->materials[mb].disp >= 0 || sc->materials[ma].disp >= 0) {
        float3 t = (float3)(0.0f);
        for (int b = 0; b < sc->f->bands; b++)
            t += vb_gload3(sc->texels + sc->f->band_weights + 4 * b) *
                 (optics_transmitted_fraction(d, ng, medium_eta(sc, mb, b), medium_eta(sc, ma, b),
                                              thesis) *
                  medium_band_transmit(sc, ma, b));
        return t;
    }
#else
    (void)band;
#endif
    return (float3)(optics_transmitted_fraction(d, ng, sc->materials[mb].eta, sc->materials[ma].eta,
                                                thesis));
}

/* Light a shadow feeler of band `band` (-1: white) carries from the point to a light at
 * distance tmax, starting in medium `state`: multiplied by the transmitted fraction of
 * every interface it crosses (weighted by that surface's k_global) and by absorption along
 * the way; zero at an opaque surface. Feelers are not bent. Only the objects of os can be
 * met (os->n < 0: any object, through the grid); a feeler that crosses out of os's sole
 * convex host meets nothing more (light_cone_objects) and only the outer medium's
 * absorption is left. */
VB_INLINE float3 medium_shadow_transmittance(const DevScene *sc, const ObjectSet *os, float3 org,
                                             float3 dir, float tmax, VbMedium state, int band,
                                             TraceCount *tc)
{
    float3 trans = (float3)(1.0f);
    float3 o = org;
    float left = tmax;
    for (int guard = 0; guard < 1024; guard++) {
        uint mb = medium_material(sc, state);
        VbHit h = scene_trace_closest_in(sc, os, o, dir, left, tc);
        if (h.tri < 0) return trans * medium_absorb(sc, mb, left);
        float3 p = tri_point(sc->tris, h);
        float seg = fmax(0.0f, dot(p - o, dir));
        trans *= medium_absorb(sc, mb, seg);
        Crossing c = medium_cross(sc, h.tri, dir, state);
        float3 ng = tri_normal(sc->tris, h.tri);
        if (c.interface) {
            __global const VbMaterial *ms = sc->materials + c.surface;
            if (ms->k_global <= 0.0f) return (float3)(0.0f);
            trans *= ms->k_global *
                     medium_interface_transmit(sc, dir, ng, c.mat_before, c.mat_after, band);
        }
        if (vb_max3(trans) < 1e-7f) return (float3)(0.0f); /* nothing gets through */
        int left_sole = os->sole >= 0 && state.host == os->sole && c.after.host < 0;
        state = c.after;
        left -= seg;
        if (left_sole) return trans * medium_absorb(sc, medium_material(sc, state), left);
        o = ray_offset_origin(p, dot(ng, dir) > 0.0f ? ng : -ng, tri_point_error(sc->tris, h, ng));
    }
    return (float3)(0.0f);
}

#endif
