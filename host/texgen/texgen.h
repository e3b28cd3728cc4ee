/* texgen.h — the 3D texture generator (thesis chapter 2): bombing and deformed projection
 * as sets of closed meshes, Fourier synthesis and orthogonal projection set-up, and the
 * `vbcl texgen` command line. */
#ifndef VBCL_TEXGEN_H
#define VBCL_TEXGEN_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "solidtex.h"

/* ---- random numbers: xoshiro256** seeded by splitmix64 (never rand()) ---- */

typedef struct TexRng {
    uint64_t s[4];
} TexRng;

/* Seeds the generator; every seed (0 included) gives its own fixed sequence. */
void texrng_seed(TexRng *r, uint64_t seed);
/* Next 64 random bits. */
uint64_t texrng_next(TexRng *r);
/* Uniform double in [0, 1) with 53 random bits. */
double texrng_uniform(TexRng *r);

/* Writes v with the fewest significant digits (6..9) that read back as the same float;
 * returns buf. */
const char *texgen_float_str(char *buf, size_t len, float v);

/* ---- a texture: the closed meshes (elements) placed in a texture block ---- */

typedef struct TexSet {
    Mesh *elems;       /* each a closed, outward-oriented mesh */
    float (*bound)[4]; /* per element: bounding sphere centre xyz and radius */
    int count, cap;
    float block_lo[3], block_hi[3]; /* the texture block the elements were made for */
    char params[512];               /* canonical parameter line, written into the file */
} TexSet;

/* Sets an empty texture. */
void texset_init(TexSet *t);
/* Frees every element and leaves an empty texture. */
void texset_free(TexSet *t);
/* Appends an element, taking over m's arrays (m is left empty); bound is its bounding
 * sphere. Returns 0, or -1 when out of memory (m is then freed). */
int texset_add(TexSet *t, Mesh *m, const float bound[4]);

/* Writes the texture to path, OBJ (one `o element_N` group per element, "%.9g") or
 * binary little-endian PLY, chosen by extension; under a temporary name renamed into
 * place. Returns 0, -1 (I/O, message in err) or -2 (unknown extension). */
int texset_write(const TexSet *t, const char *path, char *err, size_t errlen);

/* Checks that no two elements' surfaces intersect or touch (exact orientation tests in
 * double precision, coplanar triangles included). Returns 0, or -1 naming one pair. */
int texset_check_disjoint(const TexSet *t, char *err, size_t errlen);

/* ---- bombing (thesis 2.1.1, 2.2.2.1) ---- */

enum { TEX_SPHERE, TEX_CYLINDER, TEX_CUBE };

typedef struct BombParams {
    int shape;                /* TEX_SPHERE, TEX_CYLINDER or TEX_CUBE */
    int count;                /* elements, >= 1 */
    float size_min, size_max; /* radius (sphere, cylinder; height 2r) or half edge (cube) */
    uint64_t seed;
    int no_overlap; /* reject placements whose bounding spheres overlap */
    float block;    /* texture block [0, block]^3; element centres lie in it */
    int level;      /* sphere subdivisions, 0..5 */
    int segments;   /* cylinder steps around the axis, 3..1024 */
} BombParams;

/* Sets the thesis's example: 365 spheres of radius 1..14 in a 128 block, seed 1. */
void bomb_defaults(BombParams *p);
/* Drops p->count elements into the block. Returns 0, -1 with a message for parameters
 * that cannot work (including a --no-overlap count that does not fit), -2 out of memory. */
int texgen_bomb(const BombParams *p, TexSet *out, char *err, size_t errlen);

/* ---- deformed projection (thesis 2.1.3, 2.2.2.2) ---- */

#define DEFORM_MAX 64

enum { DEFORM_NESTED, DEFORM_TUBES };

typedef struct DeformParams {
    int kind;                /* DEFORM_NESTED (rings, bands) or DEFORM_TUBES (marble veins) */
    int rect;                /* profile: 0 circle, 1 rectangle */
    int count;               /* profiles (nested) or tubes */
    float spacing;           /* C: radius / half-side difference (nested), lane width (tubes) */
    float aspect;            /* rectangle height / width, (0, 1] */
    float taper[DEFORM_MAX]; /* a_i: f_i(z) = a_i z */
    float twist[DEFORM_MAX]; /* degrees per unit z */
    int taper_random, twist_random; /* draw a_i in [-taper_max, taper_max] (twist alike) */
    float taper_max, twist_max;
    int ntaper, ntwist; /* values given in the lists (0: none) */
    float length;       /* Max_Z: profiles are swept over z in [0, length] */
    int segments;       /* points around each profile */
    int rings;          /* steps along z (0: automatic) */
    float tube_radius;  /* tubes: cross-section radius */
    float wobble;       /* tubes: amplitude of the lane wobble, fraction of the free gap */
    uint64_t seed;
} DeformParams;

/* Sets thesis figure 2.2: 4 circles, radii 2, 4, 6, 8, f = 0.1z, -0.1z, -0.05z, 0.05z. */
void deform_defaults(DeformParams *p);
/* Applies a preset ("figure2.2", "wood", "marble"); returns 0, or -1 if unknown. */
int deform_preset(DeformParams *p, const char *name);
/* Sweeps the profiles. Nested profiles become the regions inside an odd number of them
 * (bands between profiles N and N-1, N-2 and N-3, ..., and the core when N is odd), so
 * that the union of the elements shows the rings. Returns 0, -1 with a message (bad
 * parameters, clearance rule violated), -2 out of memory. */
int texgen_deform(const DeformParams *p, TexSet *out, char *err, size_t errlen);

/* ---- Fourier synthesis and orthogonal projection (thesis 2.1.2, 2.1.3) ---- */

/* Fills f for Gardner's G with n terms (4..7), contrast a0 >= 0, base frequencies per axis
 * (radians per unit) and random phases from seed: w_{i+1} = 2 w_i, C_{i+1} = 0.707 C_i,
 * C_1 = 1 / ((1 + a0) sum 0.707^i) so that every factor, and so |G|, is at most 1.
 * Returns 0, or -1 with a message for parameters out of range. */
int texgen_fourier_init(VbFourier *f, int n, float a0, const float base_freq[3], uint64_t seed,
                        char *err, size_t errlen);

/* Loads an image for orthogonal projection as 4 floats per texel, rows top first.
 * Returns 0, or -1 with a message naming the file. *rgba is malloc'ed. */
int texgen_projection_load(const char *path, int *width, int *height, float **rgba, char *err,
                           size_t errlen);

/* ---- a method's options: the command line's, and a scene's inline "generate" ---- */

/* What the options say besides the parameters. */
typedef struct TexgenOpts {
    const char *output; /* -o FILE, or NULL */
    const char *image;  /* project: --image IMG, or NULL */
    int help;           /* --help or -h came: parsing stopped there */
} TexgenOpts;

/* `texgen fourier`'s options: G's parameters and the preview slice. */
typedef struct FourierArgs {
    int terms, pixels;
    float a0, freq[3], z, extent;
    uint64_t seed;
} FourierArgs;

/* Whether arg asks for help: "--help" or "-h". */
int texgen_is_help(const char *arg);

/* Parse the options of `vbcl texgen METHOD` (argv[0] is the method's name) into the
 * method's parameters, starting from its defaults (bomb_defaults, deform_defaults, and
 * a preset first when --preset is given). Return 0, or -1 with what was expected in err,
 * without the method's name ("--count 0: expected 1 to 1000000"). */
int texgen_bomb_args(int argc, char **argv, BombParams *p, TexgenOpts *o, char *err, size_t errlen);
int texgen_deform_args(int argc, char **argv, DeformParams *p, TexgenOpts *o, char *err,
                       size_t errlen);
int texgen_fourier_args(int argc, char **argv, FourierArgs *f, TexgenOpts *o, char *err,
                        size_t errlen);
int texgen_project_args(int argc, char **argv, TexgenOpts *o, char *err, size_t errlen);

/* ---- command line ---- */

/* `vbcl texgen METHOD [options]`; argv[0] is "texgen". Returns the exit status: 0 done,
 * 2 bad parameters or usage (one line on stderr), 1 I/O failure. */
int texgen_main(int argc, char **argv);

#endif
