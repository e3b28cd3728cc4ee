/* dispersion.h — wavelength-dependent refractive index (thesis 3.4.2, 3.5): per-material
 * index models, the band layout over the visible range, and each band's RGB weight from the
 * CIE 1931 colour-matching functions. Host side only: the renderer turns a material's model
 * into a small table of per-band indices, so that the kernels only look η up per band. */
#ifndef VBCL_DISPERSION_H
#define VBCL_DISPERSION_H

#define DISP_LAMBDA_MIN 380.0 /* nm: the band layout covers [380, 780] */
#define DISP_LAMBDA_MAX 780.0
#define DISP_MAX_BANDS  64
#define DISP_LAMBDA_D   587.56 /* helium d line (n_d, Abbe number) */
#define DISP_LAMBDA_F   486.13 /* hydrogen F line */
#define DISP_LAMBDA_C   656.27 /* hydrogen C line */

enum { DISP_NONE = 0, DISP_CAUCHY = 1, DISP_SELLMEIER = 2, DISP_THESIS = 3 /* a Cauchy model */ };

/* A material's index model. eta(λ) = model(λ), plus `jump` for λ beyond the absorption
 * band [band_lo, band_hi] (anomalous dispersion, thesis figure 3.4); light inside the band
 * is absorbed. */
typedef struct DispModel {
    int model;    /* DISP_* */
    double a, b;  /* Cauchy: a + b / λ² (λ in µm) */
    double sb[3]; /* Sellmeier: n² = 1 + Σ B_i λ² / (λ² − C_i), λ in µm, C_i in µm² */
    double sc[3];
    int has_band; /* absorption band present */
    double band_lo, band_hi, jump;
} DispModel;

/* Cauchy coefficients from n_d and the Abbe number V_d = (n_d − 1) / (n_F − n_C). */
void disp_cauchy_from_abbe(DispModel *m, double n_d, double abbe);

/* Named Sellmeier presets ("BK7", "F2", Schott catalogue); 0 on success, -1 if unknown. */
int disp_sellmeier_preset(DispModel *m, const char *name);

/* Refractive index at wavelength lambda_nm (without the absorption band's jump when
 * lambda is below the band). */
double disp_eta(const DispModel *m, double lambda_nm);

/* Fraction of band [lo, hi] (nm) that is not absorbed by the model's absorption band. */
double disp_band_transmit(const DispModel *m, double lo, double hi);

/* Band b of n: [lo, hi] in nm (equal widths over 380–780) and its centre. */
void disp_band_edges(int n, int b, double *lo, double *hi);
double disp_band_centre(int n, int b);

/* The thesis's own index model (section 3.5): eta is given at the lithium line, 670 nm, and
 * varies as the thesis's 1/λ³ dispersion law integrates, η(λ) = η_670 + K (1/λ² − 1/670²),
 * with K set by `spread`, the rise of η from 700 to 400 nm (0.03 for the thesis's glass,
 * figure 3.5: 1.50 .. 1.53). A Cauchy model anchored at 670 nm. */
#define DISP_LAMBDA_LITHIUM 670.0
void disp_thesis_model(DispModel *m, double eta_670, double spread);

/* Band layouts: N bands of equal width over 380–780 nm with CIE weights, or the thesis's
 * per-channel scheme (section 3.5): 1 ray for red, at 670 nm; 2 for green over 500–600 nm;
 * 3 for blue over 380–500 nm; within a channel the rays sit at equal steps of η (equal steps
 * of 1/λ², exact for the thesis and Cauchy models), each carrying its channel's primary
 * divided by the channel's ray count, so that the six sum to white. */
enum { DISP_LAYOUT_UNIFORM = 0, DISP_LAYOUT_THESIS = 1 };
#define DISP_THESIS_BANDS 6
typedef struct DispBand {
    double lo, hi; /* nm: the wavelengths the band stands for (its absorption-band overlap) */
    double centre; /* nm: where its index is taken */
    float rgb[3];  /* linear sRGB weight; a layout's bands sum to (1, 1, 1) */
} DispBand;

/* Fills out (DISP_MAX_BANDS entries) with the layout's bands, n of them for the uniform
 * layout (n is ignored for the thesis's); returns the count. */
int disp_layout_bands(int layout, int n, DispBand *out);

/* CIE 1931 2° colour-matching functions at lambda_nm (x̄, ȳ, z̄). */
void disp_cie_cmf(double lambda_nm, double xyz[3]);

/* Per-band linear sRGB weights for n bands (n ≤ DISP_MAX_BANDS): XYZ of each band
 * integrated from the CMFs, converted to linear sRGB, negative components clamped to 0,
 * then each channel scaled so that the n bands sum to exactly 1 (an equal-energy white
 * stays (1, 1, 1)). */
void disp_band_weights(int n, float rgb[][3]);

/* Deviation (degrees) of a ray through a prism of apex angle apex_deg with index n,
 * entering at incidence inc_deg (both in air). Returns a negative value on total internal
 * reflection at the exit face. */
double disp_prism_deviation(double n, double apex_deg, double inc_deg);

/* Minimum deviation (degrees): 2 asin(n sin(A/2)) − A. */
double disp_prism_min_deviation(double n, double apex_deg);

#endif
