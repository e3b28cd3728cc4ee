/* dispersion.c — index models, band layout and band RGB weights (see dispersion.h and
 * docs/architecture.md, "Dispersion"). */
#include "dispersion.h"

#include <math.h>
#include <string.h>

#define DEG (3.14159265358979323846 / 180.0)

void disp_cauchy_from_abbe(DispModel *m, double n_d, double abbe)
{
    double ld = DISP_LAMBDA_D * 1e-3, lf = DISP_LAMBDA_F * 1e-3, lc = DISP_LAMBDA_C * 1e-3;
    m->model = DISP_CAUCHY;
    m->b = (n_d - 1.0) / (abbe * (1.0 / (lf * lf) - 1.0 / (lc * lc)));
    m->a = n_d - m->b / (ld * ld);
}

void disp_thesis_model(DispModel *m, double eta_670, double spread)
{
    double l4 = 0.4, l7 = 0.7, ll = DISP_LAMBDA_LITHIUM * 1e-3; /* µm */
    m->model = DISP_THESIS;
    m->b = spread / (1.0 / (l4 * l4) - 1.0 / (l7 * l7));
    m->a = eta_670 - m->b / (ll * ll);
}

int disp_sellmeier_preset(DispModel *m, const char *name)
{
    /* Schott optical glass catalogue coefficients (λ in µm, C in µm²). */
    static const struct {
        const char *name;
        double b[3], c[3];
    } presets[] = {
        {"BK7", {1.03961212, 0.231792344, 1.01046945}, {0.00600069867, 0.0200179144, 103.560653}},
        {"F2", {1.34533359, 0.209073176, 0.937357162}, {0.00997743871, 0.0470450767, 111.886764}},
    };
    for (size_t i = 0; i < sizeof presets / sizeof presets[0]; i++)
        if (strcmp(presets[i].name, name) == 0) {
            m->model = DISP_SELLMEIER;
            memcpy(m->sb, presets[i].b, sizeof m->sb);
            memcpy(m->sc, presets[i].c, sizeof m->sc);
            return 0;
        }
    return -1;
}

double disp_eta(const DispModel *m, double lambda_nm)
{
    double l = lambda_nm * 1e-3, l2 = l * l, n = 1.0;
    if (m->model == DISP_CAUCHY || m->model == DISP_THESIS) {
        n = m->a + m->b / l2;
    } else if (m->model == DISP_SELLMEIER) {
        double n2 = 1.0;
        for (int i = 0; i < 3; i++) n2 += m->sb[i] * l2 / (l2 - m->sc[i]);
        n = sqrt(n2);
    }
    if (m->has_band && lambda_nm > 0.5 * (m->band_lo + m->band_hi)) n += m->jump;
    return n;
}

double disp_band_transmit(const DispModel *m, double lo, double hi)
{
    if (!m->has_band || hi <= lo) return 1.0;
    double a = fmax(lo, m->band_lo), b = fmin(hi, m->band_hi);
    return b > a ? 1.0 - (b - a) / (hi - lo) : 1.0;
}

void disp_band_edges(int n, int b, double *lo, double *hi)
{
    double w = (DISP_LAMBDA_MAX - DISP_LAMBDA_MIN) / n;
    *lo = DISP_LAMBDA_MIN + w * b;
    *hi = DISP_LAMBDA_MIN + w * (b + 1);
}

double disp_band_centre(int n, int b)
{
    double lo, hi;
    disp_band_edges(n, b, &lo, &hi);
    return 0.5 * (lo + hi);
}

/* Piecewise Gaussian: sigma s1 left of the mean, s2 right of it. */
static double lobe(double x, double mu, double s1, double s2)
{
    double t = (x - mu) / (x < mu ? s1 : s2);
    return exp(-0.5 * t * t);
}

/* The CIE 1931 2° observer as the multi-lobe fit of Wyman, Sloan and Shirley, "Simple
 * Analytic Approximations to the CIE XYZ Color Matching Functions", JCGT 2(2), 2013
 * (their equation 2); it follows the CIE table within about 1% of each function's peak. */
static void cmf_fit(double l, double xyz[3])
{
    xyz[0] = 1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) -
             0.065 * lobe(l, 501.1, 20.4, 26.2);
    xyz[1] = 0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1);
    xyz[2] = 1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8);
}

/* The CMFs tabulated at 5 nm over 380–780 (81 rows), filled from the fit on first use;
 * between rows they are interpolated linearly. */
#define CMF_ROWS 81
static double cmf_table[CMF_ROWS][3];
static int cmf_ready;

void disp_cie_cmf(double lambda_nm, double xyz[3])
{
    if (!cmf_ready) {
        for (int i = 0; i < CMF_ROWS; i++) cmf_fit(DISP_LAMBDA_MIN + 5.0 * i, cmf_table[i]);
        cmf_ready = 1;
    }
    double u = (lambda_nm - DISP_LAMBDA_MIN) / 5.0;
    if (u <= 0.0 || u >= CMF_ROWS - 1) {
        int i = u <= 0.0 ? 0 : CMF_ROWS - 1;
        memcpy(xyz, cmf_table[i], 3 * sizeof(double));
        return;
    }
    int i = (int)u;
    double f = u - i;
    for (int k = 0; k < 3; k++) xyz[k] = (1.0 - f) * cmf_table[i][k] + f * cmf_table[i + 1][k];
}

void disp_band_weights(int n, float rgb[][3])
{
    /* XYZ -> linear sRGB (IEC 61966-2-1, D65). */
    static const double m[3][3] = {{3.2404542, -1.5371385, -0.4985314},
                                   {-0.9692660, 1.8760108, 0.0415560},
                                   {0.0556434, -0.2040259, 1.0572252}};
    double w[DISP_MAX_BANDS][3], sum[3] = {0, 0, 0};
    for (int b = 0; b < n; b++) {
        double lo, hi, xyz[3] = {0, 0, 0};
        disp_band_edges(n, b, &lo, &hi);
        int steps = 64; /* midpoint rule over the band, finer than the 5 nm table */
        double h = (hi - lo) / steps;
        for (int s = 0; s < steps; s++) {
            double c[3];
            disp_cie_cmf(lo + (s + 0.5) * h, c);
            for (int k = 0; k < 3; k++) xyz[k] += c[k] * h;
        }
        for (int r = 0; r < 3; r++) {
            double v = m[r][0] * xyz[0] + m[r][1] * xyz[1] + m[r][2] * xyz[2];
            w[b][r] = v > 0.0 ? v : 0.0;
            sum[r] += w[b][r];
        }
    }
    for (int b = 0; b < n; b++)
        for (int r = 0; r < 3; r++) rgb[b][r] = (float)(w[b][r] / sum[r]);
}

/* k rays over [lo, hi] nm at equal steps of 1/λ²: sub-band j's edges and the λ at the
 * midpoint of its 1/λ² interval. */
static void thesis_channel(DispBand *out, double lo, double hi, int k, const float rgb[3])
{
    double ua = 1.0 / (hi * hi), ub = 1.0 / (lo * lo);
    for (int j = 0; j < k; j++) {
        double u0 = ua + (ub - ua) * j / k, u1 = ua + (ub - ua) * (j + 1) / k;
        DispBand *b = out + (k - 1 - j); /* ascending wavelength */
        b->lo = 1.0 / sqrt(u1);
        b->hi = 1.0 / sqrt(u0);
        b->centre = 1.0 / sqrt(0.5 * (u0 + u1));
        for (int c = 0; c < 3; c++) b->rgb[c] = rgb[c] / (float)k;
    }
}

int disp_layout_bands(int layout, int n, DispBand *out)
{
    if (layout == DISP_LAYOUT_THESIS) {
        static const float blue[3] = {0, 0, 1}, green[3] = {0, 1, 0};
        thesis_channel(out, DISP_LAMBDA_MIN, 500.0, 3, blue);
        thesis_channel(out + 3, 500.0, 600.0, 2, green);
        DispBand *red = out + 5; /* one ray, at the wavelength the given eta is measured at */
        red->lo = 600.0;
        red->hi = DISP_LAMBDA_MAX;
        red->centre = DISP_LAMBDA_LITHIUM;
        red->rgb[0] = 1.0f;
        red->rgb[1] = red->rgb[2] = 0.0f;
        return DISP_THESIS_BANDS;
    }
    float w[DISP_MAX_BANDS][3];
    disp_band_weights(n, w);
    for (int b = 0; b < n; b++) {
        disp_band_edges(n, b, &out[b].lo, &out[b].hi);
        out[b].centre = 0.5 * (out[b].lo + out[b].hi);
        memcpy(out[b].rgb, w[b], sizeof out[b].rgb);
    }
    return n;
}

double disp_prism_deviation(double n, double apex_deg, double inc_deg)
{
    double a = apex_deg * DEG, t1 = inc_deg * DEG;
    double t2 = asin(sin(t1) / n), t3 = a - t2, s4 = n * sin(t3);
    if (fabs(s4) > 1.0) return -1.0;
    return (t1 + asin(s4) - a) / DEG;
}

double disp_prism_min_deviation(double n, double apex_deg)
{
    double a = apex_deg * DEG;
    return (2.0 * asin(n * sin(0.5 * a)) - a) / DEG;
}
