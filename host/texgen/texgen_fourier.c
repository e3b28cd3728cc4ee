/* texgen_fourier.c — host set-up of the surface-colour solid textures (thesis 2.1.2,
 * 2.1.3, 2.2.2.3): Gardner's Fourier-synthesis parameters and the projected image. */
#include "texgen.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image_io.h"

int texgen_fourier_init(VbFourier *f, int n, float a0, const float base_freq[3], uint64_t seed,
                        char *err, size_t errlen)
{
    if (n < 4 || n > 7) {
        snprintf(err, errlen, "--terms %d: expected n from 4 to 7 (thesis 2.1.2)", n);
        return -1;
    }
    if (!(a0 >= 0.0f) || !isfinite(a0)) {
        snprintf(err, errlen, "--contrast %g: expected A_0 >= 0", a0);
        return -1;
    }
    for (int a = 0; a < 3; a++)
        if (!(base_freq[a] > 0.0f) || !isfinite(base_freq[a]) || base_freq[a] > 1e6f) {
            snprintf(err, errlen, "--freq %g: expected base frequencies in (0, 1e6]", base_freq[a]);
            return -1;
        }
    memset(f, 0, sizeof *f);
    f->n = n;
    f->a0 = a0;
    /* each factor sum_i C_i [cos + A_0] lies in [-(1+A_0), 1+A_0] * sum_i C_i; C_1 makes
     * the bound 1, so |G| <= 1 (and 0 <= G when A_0 >= 1) */
    double sum = 0.0, c = 1.0;
    for (int i = 0; i < n; i++, c *= 0.707) sum += c;
    double c1 = 1.0 / ((1.0 + a0) * sum);
    TexRng rng;
    texrng_seed(&rng, seed);
    c = c1;
    for (int i = 0; i < n; i++, c *= 0.707) {
        f->c[i] = (float)c;
        double mul = (double)(1 << i);
        f->wx[i] = (float)(base_freq[0] * mul);
        f->wy[i] = (float)(base_freq[1] * mul);
        f->wz[i] = (float)(base_freq[2] * mul);
        f->px[i] = (float)(2 * PI_D * texrng_uniform(&rng));
        f->py[i] = (float)(2 * PI_D * texrng_uniform(&rng));
        f->pz[i] = (float)(2 * PI_D * texrng_uniform(&rng));
    }
    /* rounding C_i to float may push the bound by an ulp: renormalise in float */
    float s = 0.0f;
    for (int i = 0; i < n; i++) s += f->c[i] * (1.0f + a0);
    if (s > 1.0f)
        for (int i = 0; i < n; i++) f->c[i] *= 0.99999f;
    f->gmax = 1.0f;
    return 0;
}

int texgen_projection_load(const char *path, int *width, int *height, float **rgba, char *err,
                           size_t errlen)
{
    if (image_read(path, width, height, rgba, err, errlen) < 0) return -1;
    if (*width < 1 || *height < 1) {
        snprintf(err, errlen, "%s: empty image (%d x %d)", path, *width, *height);
        free(*rgba);
        *rgba = NULL;
        return -1;
    }
    return 0;
}
