/* texgen.c — the `vbcl texgen` command line: parses a method's options, runs the
 * generator and writes the mesh or preview image (exit 0 done, 2 bad input, 1 I/O). */
#include "texgen.h"

#include <errno.h>
#include <stdarg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "diag.h"
#include "image_io.h"

static const char usage_main[] =
    "usage: vbcl texgen METHOD [options] -o FILE\n"
    "\n"
    "Generates a 3D texture (thesis chapter 2). Methods:\n"
    "  bomb      random spheres, cylinders or cubes in the texture block (mesh)\n"
    "  deform    nested profiles swept along Z, tapered and twisted (mesh)\n"
    "  fourier   Gardner's Fourier synthesis: writes a z-slice preview image\n"
    "  project   orthogonal projection of an image: checks the image\n"
    "\n"
    "Meshes are written as .obj (one `o element_N` group per closed element) or .ply\n"
    "(binary). `vbcl texgen METHOD --help` lists a method's options; docs/texgen.md\n"
    "explains them.\n";

static const char usage_bomb[] =
    "usage: vbcl texgen bomb [options] -o FILE.obj|FILE.ply\n"
    "\n"
    "Drops elements of random size, position and orientation into the block [0,SIZE]^3\n"
    "(thesis 2.1.1). Centres lie inside the block; elements may cross its faces.\n"
    "  --shape sphere|cylinder|cube  element shape (default sphere)\n"
    "  --count N             number of elements (default 365)\n"
    "  --size MIN:MAX        radius range; cylinders are 2r high, cubes 2r wide (1:14)\n"
    "  --seed S              random seed (default 1)\n"
    "  --no-overlap          reject positions whose bounding spheres overlap\n"
    "  --block SIZE          edge of the texture block (default 128)\n"
    "  --level L             sphere subdivisions 0..5: 20*4^L triangles (default 2)\n"
    "  --segments N          cylinder steps around the axis (default 24)\n"
    "  -o, --output FILE     mesh to write\n";

static const char usage_deform[] =
    "usage: vbcl texgen deform [options] -o FILE.obj|FILE.ply\n"
    "\n"
    "Sweeps nested profiles along z in [0, Max_Z], tapering (X_i = (f_i(z) + f_{i-1}(z)) x\n"
    "radially + x) and twisting them (thesis 2.2.2.2). Elements are the bands between\n"
    "profiles N and N-1, N-2 and N-3, ... (and the core when N is odd).\n"
    "  --preset figure2.2|wood|marble  start from a preset (default figure2.2)\n"
    "  --profile circle|rect           profile shape (default circle)\n"
    "  --kind nested|tubes             nested profiles, or tubes in lanes (marble)\n"
    "  --count N                       profiles (default 4)\n"
    "  --spacing C                     radius / half-width difference (default 2)\n"
    "  --taper A1,A2,...|random|none   slopes a_i of f_i(z) = a_i z (default figure 2.2)\n"
    "  --taper-max A                   range of random slopes (default 0.06)\n"
    "  --twist T1,T2,...|random|none   twist rates, degrees per unit z (default none)\n"
    "  --twist-max T                   range of random twist rates (default 2)\n"
    "  --aspect K                      rectangle height / width, (0, 1] (default 0.6)\n"
    "  --length MAX_Z                  sweep length (default 8)\n"
    "  --segments N                    points around each profile (default 48)\n"
    "  --rings N                       steps along z (default auto)\n"
    "  --tube-radius R, --wobble W     tubes: radius, lane wobble fraction in [0, 1)\n"
    "  --seed S                        random seed (default 1)\n"
    "  -o, --output FILE               mesh to write\n";

static const char usage_fourier[] =
    "usage: vbcl texgen fourier [options] -o FILE.png\n"
    "\n"
    "Bakes the z-slice [0,E]^2 of Gardner's G(X,Y,Z) (thesis 2.1.2) as a grey image.\n"
    "  --terms N           terms per axis, 4..7 (default 5)\n"
    "  --contrast A0       offset A_0 >= 0 (default 1)\n"
    "  --freq F|FX,FY,FZ   base frequencies, radians per unit (default 12.566)\n"
    "  --seed S            seed of the random phases (default 1)\n"
    "  --z Z               height of the slice (default 0.5)\n"
    "  --extent E          side of the square shown (default 1)\n"
    "  --pixels N          image width and height (default 256)\n"
    "  -o, --output FILE   image to write (.png .jpg .tif .exr)\n";

static const char usage_project[] =
    "usage: vbcl texgen project --image IMG\n"
    "\n"
    "Checks that an image can be read for orthogonal projection (thesis 2.1.3) and prints\n"
    "its size; R(X,Y,Z) is the texel nearest to (X, Y) in [0,1]^2, 0 outside.\n"
    "  --image IMG         image to project (any format OpenImageIO reads)\n";

/* While texgen_run_quiet runs: where messages go instead of stderr, and no reports. */
static char *quiet_err;
static size_t quiet_len;

/* Reports "vbcl texgen[ METHOD]: message" (on stderr, or into the quiet buffer, keeping
 * the first) and returns status. */
static int report(int status, const char *method, const char *fmt, va_list ap)
{
    char msg[768];
    diag_vformat(msg, sizeof msg, fmt, ap);
    if (quiet_err) {
        if (!quiet_err[0])
            snprintf(quiet_err, quiet_len, "%s%s%s", method ? method : "", method ? ": " : "", msg);
    } else {
        char prefix[64];
        snprintf(prefix, sizeof prefix, "vbcl texgen%s%s", method ? " " : "", method ? method : "");
        diag_print(prefix, "%s", msg);
    }
    return status;
}

/* Reports a bad parameter and returns 2. */
static int fail(const char *method, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int fail(const char *method, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int rc = report(2, method, fmt, ap);
    va_end(ap);
    return rc;
}

/* Reports a failure while generating or writing (not the parameters' fault): returns 1. */
static int fail_io(const char *method, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int fail_io(const char *method, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int rc = report(1, method, fmt, ap);
    va_end(ap);
    return rc;
}

static int parse_int(const char *s, long lo, long hi, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi) return -1;
    *out = (int)v;
    return 0;
}

static int parse_u64(const char *s, uint64_t *out)
{
    char *end;
    errno = 0;
    if (*s == '-') return -1;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || end == s || *end) return -1;
    *out = v;
    return 0;
}

static int parse_float(const char *s, float *out)
{
    char *end;
    errno = 0;
    float v = strtof(s, &end);
    if (errno || end == s || *end || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

/* Comma-separated numbers; returns how many, or -1. */
static int parse_list(const char *s, float *out, int max)
{
    int n = 0;
    const char *p = s;
    while (*p) {
        char *end;
        errno = 0;
        float v = strtof(p, &end);
        if (errno || end == p || !isfinite(v) || n == max) return -1;
        out[n++] = v;
        if (*end == ',' && end[1])
            p = end + 1;
        else if (*end == 0)
            p = end;
        else
            return -1;
    }
    return n ? n : -1;
}

static int is_help(const char *a)
{
    return !strcmp(a, "--help") || !strcmp(a, "-h");
}

/* The value after option i, or NULL (with the message printed) when it is missing. */
static const char *value(int argc, char **argv, int *i, const char *method)
{
    if (*i + 1 >= argc) {
        fail(method, "%s needs a value", argv[*i]);
        return NULL;
    }
    return argv[++*i];
}

static int has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), k = strlen(ext);
    return n > k && strcasecmp(path + n - k, ext) == 0;
}

static int check_mesh_path(const char *method, const char *out)
{
    if (!out) return fail(method, "missing -o FILE (expected a .obj or .ply path)");
    if (!has_ext(out, ".obj") && !has_ext(out, ".ply"))
        return fail(method, "-o %s: unknown mesh extension (expected .obj or .ply)", out);
    return 0;
}

/* Writes the texture and reports it; returns the exit status. */
static int write_texture(const char *method, TexSet *t, const char *out)
{
    char err[512];
    int rc = texset_write(t, out, err, sizeof err);
    uint64_t ntris = 0;
    for (int e = 0; e < t->count; e++) ntris += t->elems[e].ntris;
    if (rc == 0 && !quiet_err)
        printf("%s: %d elements, %llu triangles\n", out, t->count, (unsigned long long)ntris);
    texset_free(t);
    if (rc == -2) return fail(method, "%s", err);
    if (rc < 0) return fail_io(method, "%s", err);
    return 0;
}

#define BAD_VALUE(opt, v, what) fail(M, "%s %s: expected %s", opt, v, what)

static int cmd_bomb(int argc, char **argv)
{
    static const char *M = "bomb";
    BombParams p;
    bomb_defaults(&p);
    const char *out = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v;
        if (is_help(a)) {
            fputs(usage_bomb, stdout);
            return 0;
        }
        if (!strcmp(a, "--no-overlap")) {
            p.no_overlap = 1;
            continue;
        }
        if (a[0] != '-') return fail(M, "unexpected argument '%s'", a);
        if (!(v = value(argc, argv, &i, M))) return 2;
        if (!strcmp(a, "--shape")) {
            if (!strcmp(v, "sphere"))
                p.shape = TEX_SPHERE;
            else if (!strcmp(v, "cylinder"))
                p.shape = TEX_CYLINDER;
            else if (!strcmp(v, "cube"))
                p.shape = TEX_CUBE;
            else
                return BAD_VALUE(a, v, "sphere, cylinder or cube");
        } else if (!strcmp(a, "--count")) {
            if (parse_int(v, 1, 1000000, &p.count)) return BAD_VALUE(a, v, "1 to 1000000");
        } else if (!strcmp(a, "--size")) {
            const char *colon = strchr(v, ':');
            char lo[64];
            if (!colon || (size_t)(colon - v) >= sizeof lo) return BAD_VALUE(a, v, "MIN:MAX");
            memcpy(lo, v, (size_t)(colon - v));
            lo[colon - v] = 0;
            if (parse_float(lo, &p.size_min) || parse_float(colon + 1, &p.size_max))
                return BAD_VALUE(a, v, "MIN:MAX with two numbers");
            if (!(p.size_min > 0) || p.size_min > p.size_max)
                return BAD_VALUE(a, v, "0 < MIN <= MAX");
        } else if (!strcmp(a, "--seed")) {
            if (parse_u64(v, &p.seed)) return BAD_VALUE(a, v, "an integer >= 0");
        } else if (!strcmp(a, "--block")) {
            if (parse_float(v, &p.block) || !(p.block > 0)) return BAD_VALUE(a, v, "a size > 0");
        } else if (!strcmp(a, "--level")) {
            if (parse_int(v, 0, 5, &p.level)) return BAD_VALUE(a, v, "0 to 5");
        } else if (!strcmp(a, "--segments")) {
            if (parse_int(v, 3, 1024, &p.segments)) return BAD_VALUE(a, v, "3 to 1024");
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            out = v;
        } else {
            return fail(M, "unknown option %s (see vbcl texgen bomb --help)", a);
        }
    }
    if (check_mesh_path(M, out)) return 2;
    TexSet t;
    char err[512];
    int rc = texgen_bomb(&p, &t, err, sizeof err);
    if (rc == -1) return fail(M, "%s", err);
    if (rc < 0) return fail_io(M, "%s", err);
    return write_texture(M, &t, out);
}

/* --taper/--twist: a list, "random" or "none". */
static int parse_values(const char *v, float *list, int *n, int *random)
{
    if (!strcmp(v, "random")) {
        *random = 1;
        *n = 0;
        return 0;
    }
    *random = 0;
    if (!strcmp(v, "none")) {
        *n = 0;
        return 0;
    }
    *n = parse_list(v, list, DEFORM_MAX);
    return *n < 0 ? -1 : 0;
}

/* The number option a of `texgen deform` sets in p, or NULL. */
static float *deform_float_field(DeformParams *p, const char *a)
{
    const struct {
        const char *name;
        float *field;
    } opts[] = {{"--taper-max", &p->taper_max}, {"--twist-max", &p->twist_max},
                {"--spacing", &p->spacing},     {"--aspect", &p->aspect},
                {"--length", &p->length},       {"--tube-radius", &p->tube_radius},
                {"--wobble", &p->wobble}};
    for (size_t i = 0; i < sizeof opts / sizeof opts[0]; i++)
        if (!strcmp(a, opts[i].name)) return opts[i].field;
    return NULL;
}

static int cmd_deform(int argc, char **argv)
{
    static const char *M = "deform";
    DeformParams p;
    float *f;
    deform_defaults(&p);
    const char *out = NULL;
    int taper_given = 0;
    /* the preset first, so that other options override it wherever they stand */
    for (int i = 1; i + 1 < argc; i++)
        if (!strcmp(argv[i], "--preset") && deform_preset(&p, argv[i + 1]) < 0)
            return BAD_VALUE("--preset", argv[i + 1], "figure2.2, wood or marble");
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v;
        if (is_help(a)) {
            fputs(usage_deform, stdout);
            return 0;
        }
        if (a[0] != '-') return fail(M, "unexpected argument '%s'", a);
        if (!(v = value(argc, argv, &i, M))) return 2;
        if (!strcmp(a, "--preset")) {
            continue;
        } else if (!strcmp(a, "--profile")) {
            if (!strcmp(v, "circle"))
                p.rect = 0;
            else if (!strcmp(v, "rect"))
                p.rect = 1;
            else
                return BAD_VALUE(a, v, "circle or rect");
        } else if (!strcmp(a, "--kind")) {
            if (!strcmp(v, "nested"))
                p.kind = DEFORM_NESTED;
            else if (!strcmp(v, "tubes"))
                p.kind = DEFORM_TUBES;
            else
                return BAD_VALUE(a, v, "nested or tubes");
        } else if (!strcmp(a, "--count")) {
            if (parse_int(v, 1, DEFORM_MAX, &p.count)) return BAD_VALUE(a, v, "1 to 64");
        } else if (!strcmp(a, "--taper")) {
            taper_given = 1;
            if (parse_values(v, p.taper, &p.ntaper, &p.taper_random))
                return BAD_VALUE(a, v, "A1,A2,... (one per profile), random or none");
        } else if (!strcmp(a, "--twist")) {
            if (parse_values(v, p.twist, &p.ntwist, &p.twist_random))
                return BAD_VALUE(a, v, "T1,T2,... (one per profile), random or none");
        } else if ((f = deform_float_field(&p, a))) {
            if (parse_float(v, f)) return BAD_VALUE(a, v, "a number");
        } else if (!strcmp(a, "--segments")) {
            if (parse_int(v, 3, 4096, &p.segments)) return BAD_VALUE(a, v, "3 to 4096");
        } else if (!strcmp(a, "--rings")) {
            if (parse_int(v, 0, 4096, &p.rings)) return BAD_VALUE(a, v, "0 (auto) to 4096");
        } else if (!strcmp(a, "--seed")) {
            if (parse_u64(v, &p.seed)) return BAD_VALUE(a, v, "an integer >= 0");
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            out = v;
        } else {
            return fail(M, "unknown option %s (see vbcl texgen deform --help)", a);
        }
    }
    if (p.ntaper && p.ntaper != p.count && !taper_given)
        return fail(M,
                    "--count %d: the default --taper has %d values (figure 2.2); expected "
                    "--taper with %d values, --taper random or --taper none",
                    p.count, p.ntaper, p.count);
    if (check_mesh_path(M, out)) return 2;
    TexSet t;
    char err[1024];
    int rc = texgen_deform(&p, &t, err, sizeof err);
    if (rc == -1) return fail(M, "%s", err);
    if (rc < 0) {
        return fail_io("deform", "%s", err);
    }
    return write_texture(M, &t, out);
}

static int cmd_fourier(int argc, char **argv)
{
    static const char *M = "fourier";
    int terms = 5, pixels = 256;
    float a0 = 1.0f, freq[3] = {12.566371f, 12.566371f, 12.566371f}, z = 0.5f, extent = 1.0f;
    uint64_t seed = 1;
    const char *out = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v;
        if (is_help(a)) {
            fputs(usage_fourier, stdout);
            return 0;
        }
        if (a[0] != '-') return fail(M, "unexpected argument '%s'", a);
        if (!(v = value(argc, argv, &i, M))) return 2;
        if (!strcmp(a, "--terms")) {
            if (parse_int(v, 4, 7, &terms)) return BAD_VALUE(a, v, "4 to 7 (thesis 2.1.2)");
        } else if (!strcmp(a, "--contrast")) {
            if (parse_float(v, &a0) || !(a0 >= 0)) return BAD_VALUE(a, v, "A_0 >= 0");
        } else if (!strcmp(a, "--freq")) {
            int n = parse_list(v, freq, 3);
            if (n == 1) freq[1] = freq[2] = freq[0];
            if (n != 1 && n != 3) return BAD_VALUE(a, v, "F or FX,FY,FZ");
        } else if (!strcmp(a, "--seed")) {
            if (parse_u64(v, &seed)) return BAD_VALUE(a, v, "an integer >= 0");
        } else if (!strcmp(a, "--z")) {
            if (parse_float(v, &z)) return BAD_VALUE(a, v, "a number");
        } else if (!strcmp(a, "--extent")) {
            if (parse_float(v, &extent) || !(extent > 0)) return BAD_VALUE(a, v, "a size > 0");
        } else if (!strcmp(a, "--pixels")) {
            if (parse_int(v, 1, 8192, &pixels)) return BAD_VALUE(a, v, "1 to 8192");
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            out = v;
        } else {
            return fail(M, "unknown option %s (see vbcl texgen fourier --help)", a);
        }
    }
    char err[512];
    if (!out) return fail(M, "missing -o FILE (expected an image path: .png .jpg .tif .exr)");
    if (image_check_path(out, err, sizeof err)) return fail(M, "%s", err);
    VbFourier f;
    if (texgen_fourier_init(&f, terms, a0, freq, seed, err, sizeof err)) return fail(M, "%s", err);
    float *rgba = malloc((size_t)pixels * (size_t)pixels * 4 * sizeof *rgba);
    if (!rgba) return fail_io(M, "out of memory for a %d x %d image", pixels, pixels);
    for (int y = 0; y < pixels; y++)
        for (int x = 0; x < pixels; x++) {
            float X = extent * (x + 0.5f) / pixels, Y = extent * (pixels - y - 0.5f) / pixels;
            float g = solidtex_fourier_eval(&f, X, Y, z);
            g = g < 0.0f ? 0.0f : g;
            float *px = &rgba[4 * ((size_t)y * pixels + x)];
            px[0] = px[1] = px[2] = g;
            px[3] = 1.0f;
        }
    int rc = image_write(out, pixels, pixels, rgba, 0.0f, err, sizeof err);
    free(rgba);
    if (rc) return fail_io(M, "%s", err);
    printf("%s: G(X, Y, %g) on [0, %g]^2, %d terms, C_1 = %.6g, A_0 = %g\n", out, z, extent, terms,
           f.c[0], a0);
    return 0;
}

static int cmd_project(int argc, char **argv)
{
    static const char *M = "project";
    const char *image = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v;
        if (is_help(a)) {
            fputs(usage_project, stdout);
            return 0;
        }
        if (a[0] != '-') return fail(M, "unexpected argument '%s'", a);
        if (!(v = value(argc, argv, &i, M))) return 2;
        if (!strcmp(a, "--image"))
            image = v;
        else
            return fail(M, "unknown option %s (see vbcl texgen project --help)", a);
    }
    if (!image) return fail(M, "missing --image IMG");
    int w, h;
    float *rgba;
    char err[512];
    if (texgen_projection_load(image, &w, &h, &rgba, err, sizeof err)) return fail(M, "%s", err);
    free(rgba);
    printf("%s: %d x %d texels, projected along Z over [0,1]^2\n", image, w, h);
    return 0;
}

int texgen_run_quiet(int argc, char **argv, char *err, size_t errlen)
{
    err[0] = 0;
    quiet_err = err;
    quiet_len = errlen;
    int rc = texgen_main(argc, argv);
    quiet_err = NULL;
    return rc;
}

int texgen_main(int argc, char **argv)
{
    if (argc < 2)
        return fail(NULL, "expected a method: bomb, deform, fourier or project (see vbcl texgen "
                          "--help)");
    const char *m = argv[1];
    if (is_help(m)) {
        fputs(usage_main, stdout);
        return 0;
    }
    if (!strcmp(m, "bomb")) return cmd_bomb(argc - 1, argv + 1);
    if (!strcmp(m, "deform")) return cmd_deform(argc - 1, argv + 1);
    if (!strcmp(m, "fourier")) return cmd_fourier(argc - 1, argv + 1);
    if (!strcmp(m, "project")) return cmd_project(argc - 1, argv + 1);
    return fail(NULL, "unknown method '%s': expected bomb, deform, fourier or project", m);
}
