/* test_dispersion.c — the host side of dispersion: index models against catalogue values,
 * band weights, the analytic prism, and the scene keys. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dispersion.h"
#include "fixture.h"
#include "harness.h"
#include "image_io.h"
#include "scene.h"
#include "testutil.h"

static void test_dispersion_models_match_catalogue(void)
{
    DispModel bk7 = {0}, f2 = {0}, cy = {0};
    CHECK(disp_sellmeier_preset(&bk7, "BK7") == 0 && disp_sellmeier_preset(&f2, "F2") == 0,
          "presets");
    CHECK(disp_sellmeier_preset(&cy, "unobtainium") == -1, "unknown preset accepted");
    /* Schott: N-BK7 n_d 1.5168, V_d 64.17; F2 n_d 1.62004, V_d 36.37 */
    double nd = disp_eta(&bk7, DISP_LAMBDA_D);
    double v = (nd - 1) / (disp_eta(&bk7, DISP_LAMBDA_F) - disp_eta(&bk7, DISP_LAMBDA_C));
    CHECK(fabs(nd - 1.5168) < 1e-4 && fabs(v - 64.17) < 0.1, "BK7 n_d %.5f V_d %.2f", nd, v);
    nd = disp_eta(&f2, DISP_LAMBDA_D);
    v = (nd - 1) / (disp_eta(&f2, DISP_LAMBDA_F) - disp_eta(&f2, DISP_LAMBDA_C));
    CHECK(fabs(nd - 1.62004) < 1e-4 && fabs(v - 36.37) < 0.1, "F2 n_d %.5f V_d %.2f", nd, v);
    disp_cauchy_from_abbe(&cy, 1.5, 40.0);
    nd = disp_eta(&cy, DISP_LAMBDA_D);
    v = (nd - 1) / (disp_eta(&cy, DISP_LAMBDA_F) - disp_eta(&cy, DISP_LAMBDA_C));
    CHECK(fabs(nd - 1.5) < 1e-12 && fabs(v - 40.0) < 1e-9, "Cauchy n_d %.6f V_d %.6f", nd, v);
    for (double l = 390; l < 780; l += 10)
        CHECK(disp_eta(&cy, l) > disp_eta(&cy, l + 10) &&
                  disp_eta(&bk7, l) > disp_eta(&bk7, l + 10),
              "normal dispersion: eta falls with wavelength at %g nm", l);
}

static void test_dispersion_band_weights_sum_to_white(void)
{
    int counts[] = {1, 2, 3, 4, 8, 16, 32, 64};
    for (size_t k = 0; k < sizeof counts / sizeof counts[0]; k++) {
        int n = counts[k];
        float w[DISP_MAX_BANDS][3];
        disp_band_weights(n, w);
        double s[3] = {0, 0, 0};
        for (int b = 0; b < n; b++)
            for (int r = 0; r < 3; r++) {
                CHECK(w[b][r] >= 0.0f, "%d bands: band %d channel %d weight %g", n, b, r, w[b][r]);
                s[r] += w[b][r];
            }
        CHECK(fabs(s[0] - 1) < 1e-4 && fabs(s[1] - 1) < 1e-4 && fabs(s[2] - 1) < 1e-4,
              "%d bands sum to (%g, %g, %g)", n, s[0], s[1], s[2]);
    }
    /* 8 bands: 630-680 nm is pure red, the bluest blue, the 530–580 band mostly green */
    float w[DISP_MAX_BANDS][3];
    disp_band_weights(8, w);
    CHECK(w[5][0] > 0.1f && w[5][1] == 0.0f && w[5][2] == 0.0f, "band 5 (630-680 nm) not red");
    CHECK(w[1][2] > w[1][0] && w[1][2] > w[1][1], "band 1 (430-480 nm) not blue");
    CHECK(w[3][1] > w[3][2], "band 3 (530-580 nm): green %g blue %g", w[3][1], w[3][2]);
    /* the CMFs: ȳ peaks near 555 nm at about 1 */
    double c[3];
    disp_cie_cmf(555.0, c);
    CHECK(fabs(c[1] - 1.0) < 0.02, "ybar(555) = %g", c[1]);
}

static void test_dispersion_prism_order(void)
{
    DispModel bk7 = {0};
    disp_sellmeier_preset(&bk7, "BK7");
    /* 60° prism at BK7's minimum deviation for n_d: 38.6° incidence... the order holds at
     * any fixed incidence that transmits. */
    double dmin = disp_prism_min_deviation(1.5168, 60.0);
    double inc = (dmin + 60.0) / 2.0; /* symmetric passage for n_d */
    CHECK(fabs(disp_prism_deviation(1.5168, 60.0, inc) - dmin) < 1e-9, "min deviation");
    int n = 8;
    double prev = 1e9;
    for (int b = 0; b < n; b++) {
        double d = disp_prism_deviation(disp_eta(&bk7, disp_band_centre(n, b)), 60.0, inc);
        CHECK(d > 0 && d < prev, "band %d deviation %g after %g: red must deviate least", b, d,
              prev);
        prev = d;
    }
    /* anomalous: an absorption band 500–560 nm with a jump of +0.03: the bands above it
     * deviate more than those below it (thesis figure 3.4) */
    DispModel an = bk7;
    an.has_band = 1;
    an.band_lo = 500;
    an.band_hi = 560;
    an.jump = 0.03;
    double below = disp_prism_deviation(disp_eta(&an, 480), 60.0, inc);
    double above = disp_prism_deviation(disp_eta(&an, 600), 60.0, inc);
    CHECK(above > below, "anomalous: 600 nm deviates %g, 480 nm %g", above, below);
    CHECK(disp_band_transmit(&an, 530, 580) > 0.39 && disp_band_transmit(&an, 530, 580) < 0.41 &&
              disp_band_transmit(&an, 400, 450) == 1.0 && disp_band_transmit(&an, 510, 550) == 0.0,
          "band transmittance");
}

static void test_dispersion_scene_keys(void)
{
    char err[1024];
    Scene s;
    const char *ok = tu_write_file(
        "disp_ok.json",
        "{\"camera\":{\"eye\":[0,0,5],\"look_at\":[0,0,0]},\"render\":{\"bands\":16},"
        "\"materials\":{\"g\":{\"eta\":1.6,\"k_global\":1,\"dispersion\":{\"model\":\"cauchy\","
        "\"abbe\":30,\"band\":[500,550],\"jump\":0.02}},"
        "\"b\":{\"eta\":1.5,\"dispersion\":{\"model\":\"sellmeier\",\"preset\":\"BK7\"}}},"
        "\"objects\":[{\"shape\":\"sphere\",\"material\":\"g\"}]}");
    int rc = scene_load(ok, &s, err, sizeof err);
    CHECK(rc == 0, "%s", err);
    if (rc == 0) {
        CHECK(s.bands == 16, "bands %d", s.bands);
        CHECK(s.materials[0].disp.model == DISP_CAUCHY && s.materials[0].disp.has_band &&
                  fabs(disp_eta(&s.materials[0].disp, DISP_LAMBDA_D) - 1.62) < 1e-6,
              "cauchy material");
        CHECK(s.materials[1].disp.model == DISP_SELLMEIER, "sellmeier material");
        scene_free(&s);
    }
    const char *bad[] = {"{\"model\":\"abbe\"}", "{\"model\":\"cauchy\"}",
                         "{\"model\":\"sellmeier\",\"preset\":\"X\"}",
                         "{\"model\":\"cauchy\",\"abbe\":40,\"band\":[600,500]}",
                         "{\"model\":\"cauchy\",\"abbe\":40,\"colour\":1}"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "{\"camera\":{\"eye\":[0,0,5],\"look_at\":[0,0,0]},\"materials\":{\"g\":{"
                 "\"dispersion\":%s}},\"objects\":[{\"shape\":\"sphere\",\"material\":\"g\"}]}",
                 bad[i]);
        rc = scene_load(tu_write_file("disp_bad.json", text), &s, err, sizeof err);
        CHECK(rc == 2 && strstr(err, "materials.g.dispersion"), "%s: rc %d: %s", bad[i], rc, err);
        if (rc == 0) scene_free(&s);
    }
    /* an index that is not a finite number > 0 somewhere in 380..780 nm (issue 17): a
     * Sellmeier pole at 548 nm (eta squared < 0 from 388 nm), one at 600 nm (from 425 nm),
     * a jump that takes eta below 0 */
    const char *nan[][2] = {
        {"{\"model\":\"sellmeier\",\"B\":[1,0,0],\"C\":[0.3,0,0]}", "at 388 nm"},
        {"{\"model\":\"sellmeier\",\"B\":[1,0,0],\"C\":[0.36,0,0]}", "at 425 nm"},
        {"{\"model\":\"cauchy\",\"abbe\":40,\"band\":[500,550],\"jump\":-3}", "at 526 nm"}};
    for (size_t i = 0; i < sizeof nan / sizeof nan[0]; i++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "{\"camera\":{\"eye\":[0,0,5],\"look_at\":[0,0,0]},\"materials\":{\"g\":{"
                 "\"dispersion\":%s}},\"objects\":[{\"shape\":\"sphere\",\"material\":\"g\"}]}",
                 nan[i][0]);
        rc = scene_load(tu_write_file("disp_nan.json", text), &s, err, sizeof err);
        CHECK(rc == 2 && strstr(err, "materials.g.dispersion: eta") && strstr(err, nan[i][1]),
              "%s: rc %d: %s", nan[i][0], rc, err);
        if (rc == 0) scene_free(&s);
    }
}

#define RAD (3.14159265358979323846 / 180.0)

/* A thin ray through the 60° prism shape (apex up, faces at ±60°) at the incidence of
 * minimum deviation for n_d: runs the kernel's ray tree (probe_tree_exits) and returns, per
 * band, the exit angle (degrees, in the xy plane) of the band ray that went straight
 * through (depth 2), or NAN where none did. */
static int prism_exits(const char *dispersion, const char *bands_json, int bands, double inc,
                       double *angle, double *weight_sum)
{
    char json[2048];
    snprintf(json, sizeof json,
             "{\"camera\": {\"eye\": [0, 0, 5], \"look_at\": [0, 0, 0]},"
             " \"render\": {\"bands\": %s, \"max_depth\": 8},"
             " \"materials\": {\"glass\": {\"k_local\": 0, \"k_global\": 1, \"eta\": 1.5168,"
             "   \"dispersion\": %s}},"
             " \"objects\": [{\"shape\": \"prism\", \"depth\": 1, \"material\": \"glass\"}]}",
             bands_json, dispersion);
    Fixture fx;
    if (fixture_open(&fx, json)) return -1;
    /* the left face runs from (-0.5, -0.2887) to (0, 0.5774); its inward normal is at -30°,
     * so the ray meets it at incidence inc travelling at inc - 30° */
    double a = (inc - 30.0) * RAD;
    float ray[8] = {(float)(-0.25 - 2 * cos(a)),
                    (float)(0.1443 - 2 * sin(a)),
                    0,
                    0,
                    (float)cos(a),
                    (float)sin(a),
                    0,
                    0};
    enum { CAP = 256 };
    static float out[CAP * 8];
    int cap = CAP, count = 0;
    cl_mem mr = buffer(ray, sizeof ray), mo = buffer(NULL, sizeof out),
           mc = buffer(&count, sizeof count);
    const size_t sz[] = {sizeof(cl_mem), sizeof(int), sizeof(cl_mem), sizeof(cl_mem)};
    const void *v[] = {&mr, &cap, &mo, &mc};
    fixture_run_probe(&fx, "probe_tree_exits", 1, 4, sz, v);
    read_buffer(mo, out, sizeof out);
    read_buffer(mc, &count, sizeof count);
    for (int b = 0; b < bands; b++) angle[b] = NAN;
    weight_sum[0] = weight_sum[1] = weight_sum[2] = 0;
    for (int k = 0; k < count && k < CAP; k++) {
        const float *e = out + 8 * k;
        for (int c = 0; c < 3; c++) weight_sum[c] += e[4 + c];
        int band = (int)e[3];
        if (band >= 0 && band < bands && e[7] == 2.0f) angle[band] = atan2(e[1], e[0]) / RAD;
    }
    clReleaseMemObject(mr);
    clReleaseMemObject(mo);
    clReleaseMemObject(mc);
    fixture_close(&fx);
    return count;
}

/* Each band leaves the prism at the angle Snell's law gives for the material's index at the
 * band's centre wavelength, within 0.01°; red is deviated least. */
static void test_dispersion_prism_device(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const int nb = 8;
    double inc = 0.5 * (disp_prism_min_deviation(1.5168, 60.0) + 60.0);
    double angle[DISP_MAX_BANDS], ws[3], worst = 0;
    DispModel bk7 = {0};
    disp_sellmeier_preset(&bk7, "BK7");
    int n = prism_exits("{\"model\": \"sellmeier\", \"preset\": \"BK7\"}", "8", nb, inc, angle, ws);
    CHECK(n > 0, "no rays left the prism");
    if (n <= 0) return;
    double prev = -1e9;
    for (int b = 0; b < nb; b++) {
        double dev = disp_prism_deviation(disp_eta(&bk7, disp_band_centre(nb, b)), 60.0, inc);
        double want = (inc - 30.0) - dev; /* exit direction: incoming direction turned by dev */
        CHECK(fabs(angle[b] - want) < 0.01, "band %d (%.0f nm): exit %.4f°, Snell %.4f°", b,
              disp_band_centre(nb, b), angle[b], want);
        if (fabs(angle[b] - want) > worst) worst = fabs(angle[b] - want);
        /* shorter wavelengths are bent further toward the base: lower exit angle */
        CHECK(b == 0 || angle[b] > prev, "band %d not deviated less than band %d", b, b - 1);
        prev = angle[b];
    }
    fprintf(stderr,
            "    BK7, 8 bands: deviation %.3f° (405 nm) .. %.3f° (755 nm), worst error %.2e°\n",
            (inc - 30.0) - angle[0], (inc - 30.0) - angle[nb - 1], worst);
    /* everything that left: the bands' weights add up to at most white, and nearly all of
     * it (no extinction; only rays below the pruning floor are lost) */
    for (int c = 0; c < 3; c++)
        CHECK(ws[c] > 0.99 && ws[c] < 1.0 + 1e-4, "channel %d: %g of the energy left", c, ws[c]);
    /* anomalous: absorption band 500-560 nm, eta jumps by +0.04 across it; the bands above it
     * are deviated more than those below it (thesis figure 3.4), and the bands inside it are
     * absorbed */
    n = prism_exits("{\"model\": \"cauchy\", \"abbe\": 60, \"band\": [500, 560], \"jump\": 0.04}",
                    "8", nb, inc, angle, ws);
    CHECK(n > 0, "anomalous: no rays left");
    if (n <= 0) return;
    /* 8 bands of 50 nm: band 2 = 480-530 and band 3 = 530-580 overlap the absorption band */
    CHECK(!isnan(angle[1]) && !isnan(angle[4]) && angle[4] < angle[1],
          "anomalous: 605 nm exits at %.3f°, 455 nm at %.3f°: the long side must deviate more",
          angle[4], angle[1]);
    CHECK(angle[5] < angle[0], "anomalous: 655 nm (%.3f°) deviated more than 405 nm (%.3f°)",
          angle[5], angle[0]);
}

/* A ray that refracts into no dispersive material gives the same pixel with 1, 8 and 16
 * bands: the split never happens. Through the prism the total colour of what leaves stays
 * white at every band count. */
static void test_dispersion_bands_leave_other_paths_alone(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const char *json = tu_write_file(
        "disp_plain.json",
        "{\"image\": {\"width\": 32, \"height\": 24, \"background\": [0.3, 0.4, 0.5]},"
        " \"camera\": {\"eye\": [0, 1, 4], \"look_at\": [0, 0.3, 0], \"fov\": 40},"
        " \"render\": {\"shadow_samples\": 1},"
        " \"lights\": [{\"centre\": [2, 4, 3], \"flux\": 300}],"
        " \"materials\": {\"floor\": {\"diffuse\": [0.6, 0.5, 0.4]},"
        "   \"water\": {\"k_local\": 0, \"k_global\": 1, \"eta\": 1.33},"
        "   \"flint\": {\"k_local\": 0, \"k_global\": 1, \"eta\": 1.62,"
        "     \"dispersion\": {\"model\": \"sellmeier\", \"preset\": \"F2\"}}},"
        " \"objects\": [{\"shape\": \"quad\", \"size\": [6, 6], \"material\": \"floor\"},"
        "   {\"shape\": \"sphere\", \"radius\": 0.5, \"centre\": [-0.6, 0.5, 0], \"material\": "
        "\"water\"},"
        "   {\"name\": \"unused\", \"shape\": \"sphere\", \"radius\": 0.01, \"centre\": [0, -5, 0],"
        "    \"material\": \"flint\"}]}");
    char cmd[2048], out[4096];
    float *img[3] = {NULL};
    int w = 0, h = 0;
    const int bands[3] = {1, 8, 16};
    for (int k = 0; k < 3; k++) {
        char path[512];
        snprintf(path, sizeof path, "%s/plain%d.exr", tu_tmpdir(), bands[k]);
        snprintf(cmd, sizeof cmd, "%s %s --bands %d -q -o %s --stats", tu_vbcl, json, bands[k],
                 path);
        int rc = tu_run(cmd, out, sizeof out);
        CHECK(rc == 0 && strstr(out, "dispersion"), "%s: %d %s", cmd, rc, out);
        char err[512];
        if (image_read(path, &w, &h, &img[k], err, sizeof err)) {
            CHECK(0, "%s", err);
            goto done;
        }
    }
    for (int k = 1; k < 3; k++) {
        double worst = 0;
        for (int i = 0; i < w * h * 4; i++) worst = fmax(worst, fabs(img[k][i] - img[0][i]));
        CHECK(worst == 0.0, "%d bands differ from 1 band by %g on a path without dispersion",
              bands[k], worst);
    }
done:
    for (int k = 0; k < 3; k++) free(img[k]);
}

/* The thesis's model and its per-channel rays (section 3.5): eta is the given value at
 * 670 nm and rises by `spread` from 700 to 400 nm; the layout has 1 red, 2 green and 3 blue
 * rays at equal steps of eta within each channel, summing to white. */
static void test_dispersion_thesis_model_and_rays(void)
{
    DispModel m = {0};
    disp_thesis_model(&m, 1.525, 0.03);
    CHECK(fabs(disp_eta(&m, 670.0) - 1.525) < 1e-12, "eta(670) %.12f", disp_eta(&m, 670.0));
    CHECK(fabs(disp_eta(&m, 400.0) - disp_eta(&m, 700.0) - 0.03) < 1e-12, "spread %.12f",
          disp_eta(&m, 400.0) - disp_eta(&m, 700.0));
    /* the 1/λ³ law the thesis states: dη/dλ ∝ λ⁻³ */
    double k1 = (disp_eta(&m, 450.001) - disp_eta(&m, 449.999)) / 0.002 * pow(450.0, 3);
    double k2 = (disp_eta(&m, 650.001) - disp_eta(&m, 649.999)) / 0.002 * pow(650.0, 3);
    CHECK(fabs(k1 / k2 - 1.0) < 1e-5, "dη/dλ·λ³ at 450 and 650 nm: %g, %g", k1, k2);
    DispBand b[DISP_MAX_BANDS];
    int n = disp_layout_bands(DISP_LAYOUT_THESIS, 0, b);
    CHECK(n == DISP_THESIS_BANDS && n == 6, "%d thesis rays", n);
    int per[3] = {0, 0, 0};
    double sum[3] = {0, 0, 0};
    for (int i = 0; i < n; i++) {
        int ch = -1;
        for (int c = 0; c < 3; c++) {
            sum[c] += b[i].rgb[c];
            if (b[i].rgb[c] > 0) ch = c;
        }
        CHECK(ch >= 0, "ray %d carries no colour", i);
        if (ch >= 0) per[ch]++;
        CHECK(b[i].lo < b[i].centre && b[i].centre < b[i].hi, "ray %d: %g not in [%g, %g]", i,
              b[i].centre, b[i].lo, b[i].hi);
        CHECK(i == 0 || b[i].lo == b[i - 1].hi, "ray %d does not start where %d ends", i, i - 1);
    }
    CHECK(per[0] == 1 && per[1] == 2 && per[2] == 3, "rays per channel: red %d green %d blue %d",
          per[0], per[1], per[2]);
    CHECK(fabs(sum[0] - 1) < 1e-6 && fabs(sum[1] - 1) < 1e-6 && fabs(sum[2] - 1) < 1e-6,
          "thesis rays sum to (%g, %g, %g)", sum[0], sum[1], sum[2]);
    CHECK(b[5].centre == DISP_LAMBDA_LITHIUM, "the red ray at %g nm", b[5].centre);
    /* equal steps of eta within a channel: blue rays 0..2 over 380–500, green 3..4 over
     * 500–600; each ray's eta is the midpoint of its share of the channel's eta range */
    double e_lo = disp_eta(&m, 500.0), e_hi = disp_eta(&m, DISP_LAMBDA_MIN);
    for (int j = 0; j < 3; j++) {
        double want = e_hi - (e_hi - e_lo) * (j + 0.5) / 3.0;
        CHECK(fabs(disp_eta(&m, b[j].centre) - want) < 1e-12, "blue ray %d: eta %.9f, want %.9f", j,
              disp_eta(&m, b[j].centre), want);
    }
    e_lo = disp_eta(&m, 600.0), e_hi = disp_eta(&m, 500.0);
    for (int j = 0; j < 2; j++) {
        double want = e_hi - (e_hi - e_lo) * (j + 0.5) / 2.0;
        CHECK(fabs(disp_eta(&m, b[3 + j].centre) - want) < 1e-12,
              "green ray %d: eta %.9f, want %.9f", j, disp_eta(&m, b[3 + j].centre), want);
    }
    /* the scene keys: "model": "thesis" alone selects the thesis rays; "bands" overrides */
    const char *base = "{\"camera\":{\"eye\":[0,0,5],\"look_at\":[0,0,0]},%s"
                       "\"materials\":{\"g\":{\"k_global\":1,\"eta\":1.5,\"dispersion\":"
                       "{\"model\":\"thesis\"%s}}},"
                       "\"objects\":[{\"shape\":\"sphere\",\"material\":\"g\"}]}";
    const struct {
        const char *render, *extra;
        int bands, layout;
    } cases[] = {{"", "", 6, DISP_LAYOUT_THESIS},
                 {"\"render\":{\"bands\":16},", ",\"spread\":0.05", 16, DISP_LAYOUT_UNIFORM},
                 {"\"render\":{\"bands\":\"thesis\"},", "", 6, DISP_LAYOUT_THESIS}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char json[1024], err[512];
        snprintf(json, sizeof json, base, cases[i].render, cases[i].extra);
        Scene s;
        int rc = scene_load(tu_write_file("thesis.json", json), &s, err, sizeof err);
        CHECK(rc == 0, "case %zu: %s", i, err);
        if (rc) continue;
        CHECK(s.bands == cases[i].bands && s.band_layout == cases[i].layout,
              "case %zu: %d bands, layout %d", i, s.bands, s.band_layout);
        CHECK(s.materials[0].disp.model == DISP_THESIS, "case %zu: model %d", i,
              s.materials[0].disp.model);
        scene_free(&s);
    }
}

/* Through the kernel's ray tree, the thesis's six rays leave a 60° prism each at the Snell
 * angle for its own index, within 0.01°: blue bent most, red (at the given eta) least. */
static void test_dispersion_thesis_prism_device(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    DispModel m = {0};
    disp_thesis_model(&m, 1.5168, 0.03);
    DispBand b[DISP_MAX_BANDS];
    int nb = disp_layout_bands(DISP_LAYOUT_THESIS, 0, b);
    double inc = 0.5 * (disp_prism_min_deviation(1.5168, 60.0) + 60.0);
    double angle[DISP_MAX_BANDS], ws[3], worst = 0, prev = -1e9;
    int n =
        prism_exits("{\"model\": \"thesis\", \"spread\": 0.03}", "\"thesis\"", nb, inc, angle, ws);
    CHECK(n > 0, "no rays left the prism");
    if (n <= 0) return;
    for (int i = 0; i < nb; i++) {
        double want = (inc - 30.0) - disp_prism_deviation(disp_eta(&m, b[i].centre), 60.0, inc);
        CHECK(fabs(angle[i] - want) < 0.01, "ray %d (%.1f nm): exit %.4f°, Snell %.4f°", i,
              b[i].centre, angle[i], want);
        worst = fmax(worst, fabs(angle[i] - want));
        CHECK(i == 0 || angle[i] > prev, "ray %d not deviated less than ray %d", i, i - 1);
        prev = angle[i];
    }
    fprintf(stderr, "    thesis rays: deviation %.3f° (blue) .. %.3f° (red), worst error %.2e°\n",
            (inc - 30.0) - angle[0], (inc - 30.0) - angle[nb - 1], worst);
    for (int c = 0; c < 3; c++)
        CHECK(ws[c] > 0.99 && ws[c] < 1.0 + 1e-4, "channel %d: %g of the energy left", c, ws[c]);
}

/* Shadow feelers through dispersive glass: a point behind a slab of glass with an absorption
 * band, lit by a point light at normal incidence. A feeler of one band lets through that
 * band's two Fresnel transmissions and what the absorption band leaves of it. A white feeler
 * carries rgb, so at each interface it takes the band-weighted mean of the bands'
 * transmissions: exact per interface, and within 1e-3 of the band-resolved sum over both. */
static void test_dispersion_shadow_feelers(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    Fixture fx;
    if (fixture_open(&fx,
                     "{\"camera\": {\"eye\": [0, 0, 20], \"look_at\": [0, 0, 0]},"
                     " \"render\": {\"shadow_samples\": 1, \"ambient\": [0, 0, 0], \"bands\": 8},"
                     " \"lights\": [{\"centre\": [0, 0, 0], \"radius\": 0, \"intensity\": 1}],"
                     " \"materials\": {\"m\": {\"diffuse\": [1, 1, 1]},"
                     "   \"g\": {\"k_local\": 0, \"k_global\": 1, \"eta\": 1.6, \"dispersion\":"
                     "     {\"model\": \"cauchy\", \"abbe\": 20, \"band\": [500, 560], "
                     "\"jump\": 0.05}}},"
                     " \"objects\": [{\"shape\": \"box\", \"size\": [0.2, 2, 2], "
                     "\"material\": \"g\", \"transform\": {\"translate\": [1, 0, 0]}}]}"))
        return;
    DispModel g = {0};
    disp_cauchy_from_abbe(&g, 1.6, 20.0);
    g.has_band = 1, g.band_lo = 500, g.band_hi = 560, g.jump = 0.05;
    DispBand b[DISP_MAX_BANDS];
    int nb = disp_layout_bands(DISP_LAYOUT_UNIFORM, 8, b);
    enum { N = 9 }; /* white, then each band */
    float pts[N * 4], nrm[N * 4], out[N * 4];
    for (int i = 0; i < N; i++) {
        pts[4 * i] = 2.0f, pts[4 * i + 1] = pts[4 * i + 2] = pts[4 * i + 3] = 0;
        nrm[4 * i] = -1.0f, nrm[4 * i + 1] = nrm[4 * i + 2] = 0, nrm[4 * i + 3] = (float)i;
    }
    if (fixture_shade_points(&fx, pts, nrm, N, out)) {
        fixture_close(&fx);
        return;
    }
    const double unlit = 1.0 / (4.0 * M_PI); /* E = I / d², radiance E / π, d = 2 */
    double white[3] = {0, 0, 0}, in[3] = {0, 0, 0}, outw[3] = {0, 0, 0};
    for (int k = 0; k < nb; k++) {
        double e = disp_eta(&g, b[k].centre), r = (e - 1) / (e + 1);
        double tb = disp_band_transmit(&g, b[k].lo, b[k].hi);
        double t = (1 - r * r) * (1 - r * r) * tb;
        for (int c = 0; c < 3; c++) {
            white[c] += b[k].rgb[c] * t;
            in[c] += b[k].rgb[c] * (1 - r * r) * tb;
            outw[c] += b[k].rgb[c] * (1 - r * r);
        }
        double got = out[4 * (k + 1)] / unlit;
        CHECK(fabs(got - t) < 2e-5, "band %d feeler lets %.6f through, want %.6f", k, got, t);
    }
    for (int c = 0; c < 3; c++) {
        double got = out[c] / unlit;
        CHECK(fabs(got - in[c] * outw[c]) < 2e-5, "white feeler, channel %d: %.6f, want %.6f", c,
              got, in[c] * outw[c]);
        CHECK(fabs(got - white[c]) < 1e-3, "white feeler, channel %d: %.6f, band-resolved %.6f", c,
              got, white[c]);
    }
    fprintf(stderr,
            "    white feeler through the slab: (%.5f, %.5f, %.5f); band-resolved (%.5f, %.5f, "
            "%.5f); base eta alone would give %.5f\n",
            out[0] / unlit, out[1] / unlit, out[2] / unlit, white[0], white[1], white[2],
            pow(1 - pow(0.6 / 2.6, 2), 2));
    fixture_close(&fx);
}

void suite_dispersion(void)
{
    RUN_TEST(test_dispersion_models_match_catalogue);
    RUN_TEST(test_dispersion_band_weights_sum_to_white);
    RUN_TEST(test_dispersion_prism_order);
    RUN_TEST(test_dispersion_scene_keys);
    RUN_PROBE_TEST(test_dispersion_prism_device);
    RUN_TEST(test_dispersion_bands_leave_other_paths_alone);
    RUN_TEST(test_dispersion_thesis_model_and_rays);
    RUN_PROBE_TEST(test_dispersion_thesis_prism_device);
    RUN_PROBE_TEST(test_dispersion_shadow_feelers);
}
