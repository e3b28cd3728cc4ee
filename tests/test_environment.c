/* test_environment.c — image.environment (host/scene/scene_environment.c,
 * kernels/environment.cl) through whole renders of the vbcl binary: a constant environment
 * renders bit for bit as the background colour it equals (a glass scene, anti-aliased, and a
 * dispersive one), every pixel of cameras looking along the six axes sees the texel the
 * latitude-longitude mapping gives (computed here, in double, from an image whose texels
 * hold their own coordinates), a rotation moves the lookup as predicted, and bad input is
 * refused with exit 2, the file, the JSON path and what was expected, and nothing written. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "image_io.h"
#include "testutil.h"

/* Writes a w x h EXR (32-bit floats, exact) of the rgb triples rgb (row 0 first) into the
 * temporary directory; returns its path (a static buffer ring). */
static const char *write_exr(const char *name, int w, int h, const float *rgb)
{
    static char ring[4][512];
    static int next;
    char *path = ring[next++ % 4];
    snprintf(path, sizeof ring[0], "%s/%s", tu_tmpdir(), name);
    float *rgba = malloc(sizeof(float) * 4 * (size_t)w * (size_t)h);
    char err[512];
    if (!rgba) return path;
    for (int i = 0; i < w * h; i++) {
        for (int c = 0; c < 3; c++) rgba[4 * i + c] = rgb[3 * i + c];
        rgba[4 * i + 3] = 1.0f;
    }
    CHECK(image_write(path, w, h, rgba, 0.0f, err, sizeof err) == 0, "%s", err);
    free(rgba);
    return path;
}

/* Renders scene (a file) into out with extra options; returns the exit status. */
static int render(const char *scene, const char *out, const char *extra)
{
    char cmd[4096], log[8192];
    snprintf(cmd, sizeof cmd, "%s %s -q -o %s %s", tu_vbcl, scene, out, extra ? extra : "");
    int rc = tu_run(cmd, log, sizeof log);
    CHECK(rc == 0, "%s exited %d: %s", cmd, rc, log);
    return rc;
}

/* The bytes of the file at path (malloc'ed, *n of them), or NULL. */
static unsigned char *read_bytes(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = len > 0 ? malloc((size_t)len) : NULL;
    *n = b ? fread(b, 1, (size_t)len, f) : 0;
    fclose(f);
    return b;
}

/* Renders text twice, once with `"background": BG` and once with `"environment":
 * {"file": EXR}` of a constant image of BG in its place (text holds one "%s" in the image
 * object), with extra options, into PFM files (vbcl's own, floats as rendered), and checks
 * that the two files are equal byte for byte. */
static void check_constant_matches(const char *name, const char *text, const char *extra)
{
    static const float bg[3] = {0.3f, 0.45f, 0.6f};
    float rgb[6 * 3 * 3];
    for (int i = 0; i < 6 * 3; i++) memcpy(rgb + 3 * i, bg, sizeof bg);
    const char *exr = write_exr("constant.exr", 6, 3, rgb);
    char key[2][700], file[2][64], scene[8192], out[2][512];
    snprintf(key[0], sizeof key[0], "\"background\": [0.3, 0.45, 0.6]");
    snprintf(key[1], sizeof key[1], "\"environment\": {\"file\": \"%s\"}", exr);
    size_t n[2] = {0, 0};
    unsigned char *b[2] = {NULL, NULL};
    for (int k = 0; k < 2; k++) {
        snprintf(file[k], sizeof file[k], "%s_%d.json", name, k);
        snprintf(scene, sizeof scene, text, key[k]);
        snprintf(out[k], sizeof out[k], "%s/%s_%d.pfm", tu_tmpdir(), name, k);
        if (render(tu_write_file(file[k], scene), out[k], extra)) return;
        b[k] = read_bytes(out[k], &n[k]);
    }
    CHECK(b[0] && b[1] && n[0] == n[1] && n[0] > 64 && memcmp(b[0], b[1], n[0]) == 0,
          "%s %s: the constant environment's image equals the background's bit for bit", name,
          extra ? extra : "");
    /* the scene sees the background somewhere: some pixel is exactly its colour */
    int seen = 0;
    for (size_t i = n[0] > 12 ? n[0] % 12 : 0; b[0] && i + 12 <= n[0]; i += 12)
        seen |= memcmp(b[0] + i, bg, sizeof bg) == 0;
    CHECK(seen, "%s: some pixel is the background itself", name);
    free(b[0]);
    free(b[1]);
}

/* A glass ball with absorption over an opaque floor, before the background: camera rays,
 * reflections, refractions and rays leaving the glass all end in the background. */
#define GLASS_SCENE                                                                                \
    "{\"image\": {\"width\": 40, \"height\": 30, %s},"                                             \
    " \"camera\": {\"eye\": [0, 1.2, 4], \"look_at\": [0, 0.7, 0], \"fov\": 40},"                  \
    " \"render\": {\"shadow_samples\": 4, \"max_depth\": 8},"                                      \
    " \"lights\": [{\"centre\": [-3, 5, 3], \"radius\": 0.5, \"flux\": 2000}],"                    \
    " \"materials\": {\"floor\": {\"diffuse\": [0.7, 0.6, 0.5]},"                                  \
    "   \"glass\": {\"diffuse\": [0, 0, 0], \"ambient\": [0, 0, 0], \"k_local\": 0.05,"            \
    "     \"k_global\": 0.95, \"eta\": 1.5, \"extinction\": [0.3, 0.1, 0.05]}},"                   \
    " \"objects\": [{\"shape\": \"quad\", \"size\": [3, 3], \"material\": \"floor\"},"             \
    "   {\"shape\": \"sphere\", \"radius\": 0.7, \"centre\": [0, 0.7, 0], \"level\": 3,"           \
    "    \"material\": \"glass\"}]}"

/* A flint prism that splits white rays into wavelength bands, each of which leaves the
 * scene with its band's colour weight. */
#define PRISM_SCENE                                                                                \
    "{\"image\": {\"width\": 36, \"height\": 24, %s},"                                             \
    " \"camera\": {\"eye\": [0, 0, 6], \"look_at\": [0, 0, 0], \"fov\": 30},"                      \
    " \"render\": {\"shadow_samples\": 1, \"max_depth\": 6, \"bands\": 8},"                        \
    " \"materials\": {\"f2\": {\"diffuse\": [0, 0, 0], \"ambient\": [0, 0, 0], \"k_local\": 0,"    \
    "   \"k_global\": 1, \"eta\": 1.62004, \"dispersion\": {\"model\": \"sellmeier\","             \
    "   \"preset\": \"F2\"}}},"                                                                    \
    " \"objects\": [{\"shape\": \"prism\", \"depth\": 1.5, \"material\": \"f2\","                  \
    "   \"points\": [[-1, -0.8], [1, -0.8], [0, 0.9]], \"transform\": {\"rotate\": [0, 20, 0]}}]}"

/* A constant environment equal to the background gives the same image bit for bit: a glass
 * scene (plain, uniformly supersampled and adaptively anti-aliased) and a dispersive one. */
static void test_environment_constant_is_background(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    check_constant_matches("glass", GLASS_SCENE, NULL);
    check_constant_matches("glass", GLASS_SCENE, "--ssaa 2");
    check_constant_matches("glass", GLASS_SCENE, "--aa 0.05");
    check_constant_matches("prism", PRISM_SCENE, NULL);
}

/* The mapping's image: W x H texels, texel (i, j) holding (u, v, 1/4) of its own place, u =
 * (i + 1/2) / W its centre around the up axis and v = j / (H - 1) its row from the zenith;
 * bilinear filtering then gives (u, v) of the direction looked along, but across the seam. */
enum { MAP_W = 16, MAP_H = 9 };

static const char *write_map_image(void)
{
    float rgb[MAP_W * MAP_H * 3];
    for (int j = 0; j < MAP_H; j++)
        for (int i = 0; i < MAP_W; i++) {
            float *t = rgb + 3 * (j * MAP_W + i);
            t[0] = (float)((i + 0.5) / MAP_W);
            t[1] = (float)((double)j / (MAP_H - 1));
            t[2] = 0.25f;
        }
    return write_exr("map.exr", MAP_W, MAP_H, rgb);
}

/* The map image's texel (i, j) channel c (i wrapped, j clamped). */
static double map_texel(int i, int j, int c)
{
    i = ((i % MAP_W) + MAP_W) % MAP_W;
    j = j < 0 ? 0 : j >= MAP_H ? MAP_H - 1 : j;
    return c == 0 ? (i + 0.5) / MAP_W : c == 1 ? (double)j / (MAP_H - 1) : 0.25;
}

/* What the environment of the map image shows along world direction d when its
 * world-to-environment rotation is m (rows): the mapping and filter of
 * docs/scene-format.md, in double. */
static void map_expected(const double d[3], const double m[3][3], double out[3], double uv[2])
{
    double e[3];
    for (int r = 0; r < 3; r++) e[r] = m[r][0] * d[0] + m[r][1] * d[1] + m[r][2] * d[2];
    double u = atan2(e[0], -e[2]) / (2 * M_PI);
    if (u < 0) u += 1;
    double v = atan2(sqrt(e[0] * e[0] + e[2] * e[2]), e[1]) / M_PI;
    uv[0] = u;
    uv[1] = v;
    double x = u * MAP_W - 0.5, y = v * (MAP_H - 1);
    int i = (int)floor(x), j = (int)floor(y);
    double tx = x - i, ty = y - j;
    for (int c = 0; c < 3; c++) {
        double top = map_texel(i, j, c) * (1 - tx) + map_texel(i + 1, j, c) * tx;
        double bottom = map_texel(i, j + 1, c) * (1 - tx) + map_texel(i + 1, j + 1, c) * tx;
        out[c] = top * (1 - ty) + bottom * ty;
    }
}

/* The pinhole camera of vbcl (docs/scene-format.md, "camera"; host frame_camera): the unit
 * direction through the centre of pixel (x, y) of a size x size image. */
static void pixel_direction(const double fwd[3], const double up[3], double fov, int size, int x,
                            int y, double d[3])
{
    double r[3] = {fwd[1] * up[2] - fwd[2] * up[1], fwd[2] * up[0] - fwd[0] * up[2],
                   fwd[0] * up[1] - fwd[1] * up[0]};
    double rl = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int k = 0; k < 3; k++) r[k] /= rl;
    double u[3] = {r[1] * fwd[2] - r[2] * fwd[1], r[2] * fwd[0] - r[0] * fwd[2],
                   r[0] * fwd[1] - r[1] * fwd[0]};
    double th = tan(fov * 0.5 * M_PI / 180.0);
    double sx = 2.0 * (x + 0.5) / size - 1.0, sy = 1.0 - 2.0 * (y + 0.5) / size, len = 0;
    for (int k = 0; k < 3; k++) {
        d[k] = fwd[k] + sx * th * r[k] + sy * th * u[k];
        len += d[k] * d[k];
    }
    for (int k = 0; k < 3; k++) d[k] /= sqrt(len);
}

/* The environment-to-world rotation of "rotation": [x, y, z] (about x, then y, then z),
 * transposed: the world-to-environment rows. */
static void rotation_rows(const double deg[3], double m[3][3])
{
    double r[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int a = 0; a < 3; a++) {
        double t = deg[a] * M_PI / 180.0, c = cos(t), s = sin(t), q[3][3], n[3][3];
        memset(q, 0, sizeof q);
        q[a][a] = 1;
        int i = (a + 1) % 3, j = (a + 2) % 3;
        q[i][i] = c, q[i][j] = -s, q[j][i] = s, q[j][j] = c;
        for (int p = 0; p < 3; p++)
            for (int k = 0; k < 3; k++)
                n[p][k] = q[p][0] * r[0][k] + q[p][1] * r[1][k] + q[p][2] * r[2][k];
        memcpy(r, n, sizeof r);
    }
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < 3; k++) m[p][k] = r[k][p];
}

enum { CAM_SIZE = 33 }; /* odd: the centre pixel looks straight along the axis */

/* The six cameras: forward along +x, -x, +z, -z, +y, -y, and their up vectors. */
static const double cam_fwd[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 0, 1},
                                     {0, 0, -1}, {0, 1, 0},  {0, -1, 0}};
static const double cam_up[6][3] = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0},
                                    {0, 1, 0}, {0, 0, 1}, {0, 0, 1}};

/* Renders the map image seen by camera k with rotation `rotation` (JSON text) into *px
 * (malloc'ed rgba). Returns 0, or -1 after a failed check. */
static int render_map(int k, const char *rotation, float **px)
{
    char text[2048], out[512], name[64], err[512];
    /* the one object, a small ball, lies along (1, 1, 1), which no camera's view reaches */
    snprintf(text, sizeof text,
             "{\"image\": {\"width\": %d, \"height\": %d, \"environment\": {\"file\": \"%s\","
             " \"rotation\": %s}},"
             " \"camera\": {\"eye\": [0, 0, 0], \"look_at\": [%g, %g, %g], \"up\": [%g, %g, %g],"
             " \"fov\": 60}, \"materials\": {\"m\": {}},"
             " \"objects\": [{\"shape\": \"sphere\", \"radius\": 0.1, \"centre\": [50, 50, 50],"
             " \"level\": 0, \"material\": \"m\"}]}",
             CAM_SIZE, CAM_SIZE, write_map_image(), rotation, cam_fwd[k][0], cam_fwd[k][1],
             cam_fwd[k][2], cam_up[k][0], cam_up[k][1], cam_up[k][2]);
    snprintf(name, sizeof name, "map_%d.json", k);
    snprintf(out, sizeof out, "%s/map_%d.exr", tu_tmpdir(), k);
    if (render(tu_write_file(name, text), out, NULL)) return -1;
    int w, h;
    if (image_read(out, &w, &h, px, err, sizeof err) || w != CAM_SIZE || h != CAM_SIZE) {
        CHECK(0, "%s: %s", out, err);
        return -1;
    }
    return 0;
}

/* Every pixel of the first ncam axis cameras against the mapping computed here with the
 * rotation m (world-to-environment rows): the bilinear value everywhere (seam included), and
 * away from the seam and the poles (u, v) itself. Puts each camera's centre pixel (rgb) in
 * centre and the worst differences in worst[2]. Returns 0, or -1 where a render failed. */
static int check_map(const char *rotation, const double m[3][3], int ncam, float centre[6][3],
                     double worst[2])
{
    worst[0] = worst[1] = 0;
    for (int k = 0; k < ncam; k++) {
        float *px;
        if (render_map(k, rotation, &px)) return -1;
        int mid = CAM_SIZE / 2;
        memcpy(centre[k], px + 4 * (mid * CAM_SIZE + mid), sizeof centre[k]);
        for (int y = 0; y < CAM_SIZE; y++)
            for (int x = 0; x < CAM_SIZE; x++) {
                double d[3], want[3], uv[2];
                pixel_direction(cam_fwd[k], cam_up[k], 60.0, CAM_SIZE, x, y, d);
                map_expected(d, m, want, uv);
                const float *p = px + 4 * (y * CAM_SIZE + x);
                double e[3];
                for (int c = 0; c < 3; c++) e[c] = fabs(p[c] - want[c]);
                /* at a pole u is undefined: its row alone (v) is checked there */
                double polar = sqrt(d[0] * d[0] + d[2] * d[2]) < 1e-3 ? 0 : 1;
                e[0] *= polar;
                worst[0] = fmax(worst[0], fmax(e[0], fmax(e[1], e[2])));
                CHECK(e[0] < 1e-4 && e[1] < 1e-4 && e[2] < 1e-6,
                      "%s, camera %d pixel (%d, %d): (%.6f, %.6f, %.6f), expected (%.6f, %.6f, "
                      "%.6f)",
                      rotation, k, x, y, p[0], p[1], p[2], want[0], want[1], want[2]);
                if (polar > 0 && uv[0] > 1.0 / MAP_W && uv[0] < 1 - 1.0 / MAP_W) {
                    double f = fmax(fabs(p[0] - uv[0]), fabs(p[1] - uv[1]));
                    worst[1] = fmax(worst[1], f);
                    CHECK(f < 1e-4,
                          "%s, camera %d pixel (%d, %d): (%.6f, %.6f), (u, v) (%.6f, %.6f)",
                          rotation, k, x, y, p[0], p[1], uv[0], uv[1]);
                }
            }
        free(px);
    }
    return 0;
}

/* The direction -> texel mapping: +y is the zenith (row 0), -z is u = 0 (the seam, where the
 * first and last columns meet), +x is u = 1/4, +z u = 1/2, -x u = 3/4; checked at every
 * pixel of six cameras along the axes (6 x 33 x 33 directions), and at the axes themselves. */
static void test_environment_mapping(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const double id[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    double worst[2];
    float centre[6][3];
    if (check_map("0", id, 6, centre, worst)) return;
    fprintf(stderr, "    worst |pixel - bilinear| %.2e, |pixel - (u, v)| %.2e\n", worst[0],
            worst[1]);
    /* the axes: the centre pixel of each camera looks straight along it */
    static const double want_u[3] = {0.25, 0.75, 0.5};
    for (int k = 0; k < 3; k++)
        CHECK(fabs(centre[k][0] - want_u[k]) < 1e-6 && fabs(centre[k][1] - 0.5) < 1e-6,
              "axis %d: u %.7f v %.7f, expected %.2f 0.5", k, centre[k][0], centre[k][1],
              want_u[k]);
    /* -z: the seam, the mean of the last column ((W - 1/2) / W) and the first (1/2 / W) */
    CHECK(fabs(centre[3][0] - 0.5) < 1e-6 && fabs(centre[3][1] - 0.5) < 1e-6,
          "-z: %.7f %.7f, expected the seam's mean 0.5 and v 0.5", centre[3][0], centre[3][1]);
    /* +y: row 0 (v 0), -y: the last row (v 1) */
    CHECK(centre[4][1] == 0.0f && centre[5][1] == 1.0f, "poles: v %.7f and %.7f, expected 0, 1",
          centre[4][1], centre[5][1]);
}

/* A rotation moves the lookup as predicted: 90 degrees about the up axis brings the
 * image's u = 1/2 (the environment's +z) to the world's +x, so a camera along +x sees u =
 * 1/2 instead of 1/4, and one along -z u = 1/4 instead of the seam; [0, 90, 0] is the same
 * rotation; a full [x, y, z] rotation matches the mapping of R^T d at every pixel. */
static void test_environment_rotation(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    double m[3][3], worst[2];
    float centre[6][3], again[6][3];
    const double y90[3] = {0, 90, 0}, full[3] = {30, -45, 60};
    rotation_rows(y90, m);
    if (check_map("90", m, 4, centre, worst)) return; /* +x, -x, +z, -z */
    CHECK(fabs(centre[0][0] - 0.5) < 1e-6 && fabs(centre[0][1] - 0.5) < 1e-6,
          "rotation 90: +x sees u %.7f v %.7f, expected 0.5 0.5", centre[0][0], centre[0][1]);
    CHECK(fabs(centre[3][0] - 0.25) < 1e-6, "rotation 90: -z sees u %.7f, expected 0.25",
          centre[3][0]);
    if (check_map("[0, 90, 0]", m, 1, again, worst)) return;
    CHECK(memcmp(again[0], centre[0], sizeof again[0]) == 0, "[0, 90, 0] is rotation 90");
    rotation_rows(full, m);
    if (check_map("[30, -45, 60]", m, 6, centre, worst)) return;
    fprintf(stderr, "    [30, -45, 60]: worst |pixel - bilinear| %.2e\n", worst[0]);
}

/* image_read_radiance decodes by the colour space: an 8-bit sRGB PNG (image_write's) back to
 * the linear values written within its quantisation, a grey PGM (OpenImageIO: Rec709) by the
 * Rec. 709 curve in r, g and b alike, an EXR exactly. */
static void test_environment_image_decoding(void)
{
    static const float lin[4 * 3] = {0.0f, 0.002f, 0.04f, 0.2f, 0.5f,  0.8f,
                                     1.0f, 0.3f,   0.1f,  0.6f, 0.05f, 0.9f};
    char path[512], err[512];
    int w, h;
    float *px;
    const char *exr = write_exr("decode.exr", 2, 2, lin);
    if (!image_read_radiance(exr, &w, &h, &px, err, sizeof err)) {
        for (int i = 0; i < 4; i++)
            for (int c = 0; c < 3; c++)
                CHECK(px[4 * i + c] == lin[3 * i + c] && px[4 * i + 3] == 1.0f,
                      "EXR texel %d channel %d: %g, written %g", i, c, px[4 * i + c],
                      lin[3 * i + c]);
        free(px);
    } else {
        CHECK(0, "%s", err);
    }
    float rgba[4 * 4];
    for (int i = 0; i < 4; i++) {
        for (int c = 0; c < 3; c++) rgba[4 * i + c] = lin[3 * i + c];
        rgba[4 * i + 3] = 1.0f;
    }
    snprintf(path, sizeof path, "%s/decode.png", tu_tmpdir());
    CHECK(image_write(path, 2, 2, rgba, 0.0f, err, sizeof err) == 0, "%s", err);
    if (!image_read_radiance(path, &w, &h, &px, err, sizeof err)) {
        double worst = 0;
        for (int i = 0; i < 4; i++)
            for (int c = 0; c < 3; c++) {
                /* half a step of 8 bits, at the slope of the sRGB curve there */
                double v = lin[3 * i + c],
                       slope = v <= 0.0031308 ? 1 / 12.92 : 2.4 * pow(v, 1 - 1 / 2.4) / 1.055;
                double e = fabs(px[4 * i + c] - v);
                worst = fmax(worst, e);
                CHECK(e <= 0.5 / 255 * slope + 1e-6, "PNG texel %d channel %d: %g, written %g", i,
                      c, px[4 * i + c], v);
            }
        fprintf(stderr, "    sRGB PNG: worst |read - written| %.2e\n", worst);
        free(px);
    } else {
        CHECK(0, "%s", err);
    }
    snprintf(path, sizeof path, "%s/decode.pgm", tu_tmpdir());
    FILE *f = fopen(path, "wb");
    if (f) {
        fputs("P5\n2 1\n255\n", f);
        fputc(128, f);
        fputc(10, f);
        fclose(f);
    }
    if (!image_read_radiance(path, &w, &h, &px, err, sizeof err)) {
        static const int code[2] = {128, 10};
        for (int i = 0; i < 2; i++) {
            double v = code[i] / 255.0;
            double want = v < 0.081 ? v / 4.5 : pow((v + 0.099) / 1.099, 1 / 0.45);
            CHECK(w == 2 && h == 1 && fabs(px[4 * i] - want) < 1e-5 && px[4 * i + 1] == px[4 * i] &&
                      px[4 * i + 2] == px[4 * i],
                  "grey PGM texel %d: (%g, %g, %g), expected %g in each", i, px[4 * i],
                  px[4 * i + 1], px[4 * i + 2], want);
        }
        free(px);
    } else {
        CHECK(0, "%s", err);
    }
}

/* A bad environment: exit 2, one line naming `needle` (the JSON path, the file, what was
 * expected), and no image written. */
static void expect_refused(const char *env, const char *needle, const char *needle2)
{
    char text[2048], out[512], log[8192], cmd[4096];
    snprintf(text, sizeof text,
             "{\"image\": {\"width\": 8, \"height\": 8, %s},"
             " \"camera\": {\"eye\": [0, 0, 4], \"look_at\": [0, 0, 0]},"
             " \"materials\": {\"m\": {}}, \"objects\": [{\"shape\": \"box\", \"material\":"
             " \"m\"}]}",
             env);
    snprintf(out, sizeof out, "%s/refused.png", tu_tmpdir());
    remove(out);
    snprintf(cmd, sizeof cmd, "%s %s -o %s", tu_vbcl, tu_write_file("refused.json", text), out);
    int rc = tu_run(cmd, log, sizeof log);
    CHECK(rc == 2, "exit 2 (got %d) for %s: %s", rc, env, log);
    CHECK(strstr(log, "refused.json: ") && strstr(log, needle) &&
              (!needle2 || strstr(log, needle2)),
          "message names \"%s\"%s%s: %s", needle, needle2 ? " and " : "", needle2 ? needle2 : "",
          log);
    char *nl = strchr(log, '\n');
    CHECK(nl && nl[1] == 0, "one line: %s", log);
    FILE *f = fopen(out, "rb");
    CHECK(!f, "nothing written for %s", env);
    if (f) fclose(f);
}

/* Missing and unreadable files, negative and non-finite texels, a negative scale, wrong
 * types, unknown keys, and an environment beside a background colour. */
static void test_environment_bad_input(void)
{
    char env[1024], path[512];
    const char *dir = tu_tmpdir();
    snprintf(env, sizeof env, "\"environment\": {\"file\": \"%s/no-such-sky.exr\"}", dir);
    expect_refused(env, "image.environment.file: ", "no-such-sky.exr: cannot open");
    snprintf(path, sizeof path, "%s/not-an-image.exr", dir);
    FILE *f = fopen(path, "w");
    if (f) {
        fputs("this is not an image\n", f);
        fclose(f);
    }
    snprintf(env, sizeof env, "\"environment\": {\"file\": \"%s\"}", path);
    expect_refused(env, "image.environment.file: ", "not-an-image.exr: cannot read");
    snprintf(env, sizeof env, "\"environment\": {\"file\": \"%s\"}", dir);
    expect_refused(env, "image.environment.file: ", "not a regular file");
    float bad[4 * 3] = {0.5f, 0.5f, 0.5f, 0.5f, -0.25f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
    snprintf(env, sizeof env, "\"environment\": {\"file\": \"%s\"}",
             write_exr("neg.exr", 2, 2, bad));
    expect_refused(env, "image.environment.file: ", "texel (1, 0) G is -0.25: expected finite");
    bad[4] = NAN;
    snprintf(env, sizeof env, "\"environment\": {\"file\": \"%s\"}",
             write_exr("nan.exr", 2, 2, bad));
    expect_refused(env, "texel (1, 0) G is nan", "expected finite radiance >= 0");
    bad[4] = INFINITY;
    snprintf(env, sizeof env, "\"environment\": {\"file\": \"%s\"}",
             write_exr("inf.exr", 2, 2, bad));
    expect_refused(env, "texel (1, 0) G is inf", NULL);
    bad[4] = 0.5f;
    const char *good = write_exr("good.exr", 2, 2, bad);
    snprintf(env, sizeof env, "\"environment\": {\"file\": \"%s\", \"scale\": -1}", good);
    expect_refused(env, "image.environment.scale: -1 is out of range: expected >= 0", NULL);
    snprintf(env, sizeof env, "\"environment\": {\"file\": \"%s\", \"scale\": \"2\"}", good);
    expect_refused(env, "image.environment.scale: expected a number", NULL);
    float bright[4 * 3];
    for (int i = 0; i < 12; i++) bright[i] = 8.0f;
    snprintf(env, sizeof env, "\"environment\": {\"file\": \"%s\", \"scale\": 1e38}",
             write_exr("bright.exr", 2, 2, bright));
    expect_refused(env, "texel (0, 0) R times scale 1e+38 overflows", NULL);
    snprintf(env, sizeof env, "\"environment\": {\"file\": \"%s\", \"rotation\": \"up\"}", good);
    expect_refused(env, "image.environment.rotation: expected degrees about the up axis", NULL);
    snprintf(env, sizeof env, "\"environment\": {\"file\": \"%s\", \"rotation\": [1, 2]}", good);
    expect_refused(env, "image.environment.rotation: expected an array of 3 numbers", NULL);
    snprintf(env, sizeof env, "\"environment\": {\"file\": \"%s\", \"scal\": 2}", good);
    expect_refused(env, "image.environment.scal", "scale");
    expect_refused("\"environment\": {\"file\": 3}", "image.environment.file: expected a file name",
                   NULL);
    expect_refused("\"environment\": {\"scale\": 2}", "image.environment.file: missing", NULL);
    expect_refused("\"environment\": \"sky.exr\"", "image.environment: expected an object", NULL);
    snprintf(env, sizeof env, "\"background\": [0, 0, 0], \"environment\": {\"file\": \"%s\"}",
             good);
    expect_refused(env, "image.background: an environment replaces the background", NULL);
}

void suite_environment(void)
{
    RUN_TEST(test_environment_image_decoding);
    RUN_TEST(test_environment_bad_input);
    RUN_TEST(test_environment_constant_is_background);
    RUN_TEST(test_environment_mapping);
    RUN_TEST(test_environment_rotation);
}
