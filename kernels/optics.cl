#line 2 "optics.cl"
/* optics.cl — directions and energy at an interface between two dielectrics (thesis
 * 3.1–3.3): vector Snell's law (eq. 4, 6), reflection (eq. 8), total internal reflection
 * (eq. 10), and the split of energy by the Fresnel equations or by thesis eq. 9. */
#ifndef VBCL_OPTICS_CL
#define VBCL_OPTICS_CL

#include "compat.h"

/* Mirror direction of d about the unit normal n (either orientation): eq. 8. */
VB_INLINE float3 optics_reflect(float3 d, float3 n)
{
    return d - (2.0f * dot(d, n)) * n;
}

/* Refracted direction (eq. 4 and 6): N* = mu N + gamma nbar with nbar the unit normal
 * oriented along the ray (N . nbar = cos i1 >= 0), mu = eta1 / eta2 and
 * gamma = -mu cos i1 + sqrt(1 - mu^2 (1 - cos^2 i1)). Returns 0 when the root is
 * negative — total internal reflection — else writes the direction and cos i2. */
VB_INLINE int optics_refract(float3 d, float3 n, float mu, float3 *t, float *cos_t)
{
    float3 nb = dot(d, n) < 0.0f ? -n : n;
    float c1 = fmin(1.0f, dot(d, nb));
    float k = 1.0f - mu * mu * (1.0f - c1 * c1);
    if (k < 0.0f) return 0;
    float c2 = sqrt(k);
    *t = normalize(mu * d + (c2 - mu * c1) * nb);
    *cos_t = c2;
    return 1;
}

/* Reflected fraction for unpolarised light, eta1 -> eta2, cosines of incidence and
 * transmission (Fresnel). */
VB_INLINE float optics_fresnel_reflect(float eta1, float eta2, float ci, float ct)
{
    float rs = (eta1 * ci - eta2 * ct) / (eta1 * ci + eta2 * ct);
    float rp = (eta1 * ct - eta2 * ci) / (eta1 * ct + eta2 * ci);
    return 0.5f * (rs * rs + rp * rp);
}

/* Transmitted fraction for unpolarised light, from the transmission amplitudes:
 * (eta2 ct / eta1 ci) (ts^2 + tp^2) / 2 — computed on its own, so that R + T = 1 is a
 * check of both formulas rather than a definition. */
VB_INLINE float optics_fresnel_transmit(float eta1, float eta2, float ci, float ct)
{
    float ts = 2.0f * eta1 * ci / (eta1 * ci + eta2 * ct);
    float tp = 2.0f * eta1 * ci / (eta1 * ct + eta2 * ci);
    return (eta2 * ct) / (eta1 * ci) * 0.5f * (ts * ts + tp * tp);
}

/* What happens to a ray d meeting an interface eta1 -> eta2. */
typedef struct OpticsSplit {
    float R, T; /* reflected and transmitted fractions, R + T = 1 */
    float3 reflected;
    float3 transmitted; /* valid when T > 0 */
    int tir;
} OpticsSplit;

/* Splits d at a surface with shading normal ns and geometric normal ng (both facing the
 * incoming ray). The shading normal gives the directions unless it would send a ray to
 * the wrong side of the surface; the geometric one is used then. */
VB_INLINE OpticsSplit optics_split(float3 d, float3 ns, float3 ng, float eta1, float eta2,
                                   int thesis)
{
    OpticsSplit s;
    float3 n = ns;
    s.reflected = optics_reflect(d, n);
    float cos_t;
    int ok = optics_refract(d, n, eta1 / eta2, &s.transmitted, &cos_t);
    if (dot(s.reflected, ng) <= 0.0f || (ok && dot(s.transmitted, ng) >= 0.0f)) {
        n = ng;
        s.reflected = optics_reflect(d, n);
        ok = optics_refract(d, n, eta1 / eta2, &s.transmitted, &cos_t);
    }
    float ci = fabs(dot(d, n));
    s.tir = !ok;
    if (!ok || ci < 1e-7f) { /* total internal reflection, or exactly grazing */
        s.R = 1.0f;
        s.T = 0.0f;
        return s;
    }
    if (thesis) { /* thesis eq. 9: angle-independent, |eta2 - eta1| / (eta2 + eta1) */
        s.R = fabs(eta2 - eta1) / (eta2 + eta1);
        s.T = 1.0f - s.R;
    } else {
        s.R = optics_fresnel_reflect(eta1, eta2, ci, cos_t);
        s.T = optics_fresnel_transmit(eta1, eta2, ci, cos_t);
    }
    return s;
}

/* Fraction of light a shadow feeler keeps through an interface (feelers are not bent). */
VB_INLINE float optics_transmitted_fraction(float3 d, float3 ng, float eta1, float eta2, int thesis)
{
    float3 t;
    float cos_t;
    float ci = fabs(dot(d, ng));
    if (!optics_refract(d, ng, eta1 / eta2, &t, &cos_t) || ci < 1e-7f) return 0.0f;
    return thesis ? 1.0f - fabs(eta2 - eta1) / (eta2 + eta1)
                  : optics_fresnel_transmit(eta1, eta2, ci, cos_t);
}

#endif
