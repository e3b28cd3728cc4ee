/* texgen.c — the `vbcl texgen` command line: parses a method's options, runs the
 * generator and writes the mesh or preview image (exit 0 done, 2 bad input, 1 I/O); the
 * options themselves are parsed in texgen_args.c. */
#include "texgen.h"

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
    "  -o, --output FILE   image to write (.png .jpg .tif .exr .pfm)\n";

static const char usage_project[] =
    "usage: vbcl texgen project --image IMG\n"
    "\n"
    "Checks that an image can be read for orthogonal projection (thesis 2.1.3) and prints\n"
    "its size; R(X,Y,Z) is the texel nearest to (X, Y) in [0,1]^2, 0 outside.\n"
    "  --image IMG         image to project (any format OpenImageIO reads)\n";

/* Reports "vbcl texgen[ METHOD]: message" on stderr and returns status. */
static int report(int status, const char *method, const char *fmt, va_list ap)
{
    char msg[768];
    diag_vformat(msg, sizeof msg, fmt, ap);
    char prefix[64];
    snprintf(prefix, sizeof prefix, "vbcl texgen%s%s", method ? " " : "", method ? method : "");
    diag_print(prefix, "%s", msg);
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
    if (rc == 0)
        printf("%s: %d elements, %llu triangles\n", out, t->count, (unsigned long long)ntris);
    texset_free(t);
    if (rc == -2) return fail(method, "%s", err);
    if (rc < 0) return fail_io(method, "%s", err);
    return 0;
}

/* The status of a method's generator: -1 bad parameters (2), else I/O or memory (1). */
static int generated(const char *method, int rc, const char *err)
{
    return rc == -1 ? fail(method, "%s", err) : fail_io(method, "%s", err);
}

static int cmd_bomb(int argc, char **argv)
{
    static const char *M = "bomb";
    BombParams p;
    TexgenOpts o;
    char err[1024];
    if (texgen_bomb_args(argc, argv, &p, &o, err, sizeof err)) return fail(M, "%s", err);
    if (o.help) return fputs(usage_bomb, stdout), 0;
    if (check_mesh_path(M, o.output)) return 2;
    TexSet t;
    int rc = texgen_bomb(&p, &t, err, sizeof err);
    if (rc < 0) return generated(M, rc, err);
    return write_texture(M, &t, o.output);
}

static int cmd_deform(int argc, char **argv)
{
    static const char *M = "deform";
    DeformParams p;
    TexgenOpts o;
    char err[1024];
    if (texgen_deform_args(argc, argv, &p, &o, err, sizeof err)) return fail(M, "%s", err);
    if (o.help) return fputs(usage_deform, stdout), 0;
    if (check_mesh_path(M, o.output)) return 2;
    TexSet t;
    int rc = texgen_deform(&p, &t, err, sizeof err);
    if (rc < 0) return generated(M, rc, err);
    return write_texture(M, &t, o.output);
}

static int cmd_fourier(int argc, char **argv)
{
    static const char *M = "fourier";
    FourierArgs a;
    TexgenOpts o;
    char err[1024];
    if (texgen_fourier_args(argc, argv, &a, &o, err, sizeof err)) return fail(M, "%s", err);
    if (o.help) return fputs(usage_fourier, stdout), 0;
    const char *out = o.output;
    int pixels = a.pixels;
    if (!out) return fail(M, "missing -o FILE (expected an image path: .png .jpg .tif .exr .pfm)");
    if (image_check_path(out, err, sizeof err)) return fail(M, "%s", err);
    VbFourier f;
    if (texgen_fourier_init(&f, a.terms, a.a0, a.freq, a.seed, err, sizeof err))
        return fail(M, "%s", err);
    float *rgba = malloc((size_t)pixels * (size_t)pixels * 4 * sizeof *rgba);
    if (!rgba) return fail_io(M, "out of memory for a %d x %d image", pixels, pixels);
    for (int y = 0; y < pixels; y++)
        for (int x = 0; x < pixels; x++) {
            float X = a.extent * (x + 0.5f) / pixels, Y = a.extent * (pixels - y - 0.5f) / pixels;
            float g = solidtex_fourier_eval(&f, X, Y, a.z);
            g = g < 0.0f ? 0.0f : g;
            float *px = &rgba[4 * ((size_t)y * pixels + x)];
            px[0] = px[1] = px[2] = g;
            px[3] = 1.0f;
        }
    int rc = image_write(out, pixels, pixels, rgba, 0.0f, err, sizeof err);
    free(rgba);
    if (rc) return fail_io(M, "%s", err);
    printf("%s: G(X, Y, %g) on [0, %g]^2, %d terms, C_1 = %.6g, A_0 = %g\n", out, a.z, a.extent,
           a.terms, f.c[0], a.a0);
    return 0;
}

static int cmd_project(int argc, char **argv)
{
    static const char *M = "project";
    TexgenOpts o;
    char err[1024];
    if (texgen_project_args(argc, argv, &o, err, sizeof err)) return fail(M, "%s", err);
    if (o.help) return fputs(usage_project, stdout), 0;
    if (!o.image) return fail(M, "missing --image IMG");
    int w, h;
    float *rgba;
    if (texgen_projection_load(o.image, &w, &h, &rgba, err, sizeof err)) return fail(M, "%s", err);
    free(rgba);
    printf("%s: %d x %d texels, projected along Z over [0,1]^2\n", o.image, w, h);
    return 0;
}

int texgen_main(int argc, char **argv)
{
    if (argc < 2)
        return fail(NULL, "expected a method: bomb, deform, fourier or project (see vbcl texgen "
                          "--help)");
    const char *m = argv[1];
    if (texgen_is_help(m)) {
        fputs(usage_main, stdout);
        return 0;
    }
    if (!strcmp(m, "bomb")) return cmd_bomb(argc - 1, argv + 1);
    if (!strcmp(m, "deform")) return cmd_deform(argc - 1, argv + 1);
    if (!strcmp(m, "fourier")) return cmd_fourier(argc - 1, argv + 1);
    if (!strcmp(m, "project")) return cmd_project(argc - 1, argv + 1);
    return fail(NULL, "unknown method '%s': expected bomb, deform, fourier or project", m);
}
