/* texgen_args.c — a texgen method's options parsed into its parameters, written once for
 * the `vbcl texgen` command line (texgen.c) and a scene's inline "generate" (scene_texture.c).
 * No I/O and no image library: the scene fuzzer links it. */
#include "texgen.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diag.h"

/* Where a parse writes its one message. */
typedef struct Out {
    TexgenOpts *o;
    char *err;
    size_t errlen;
    int *no_overlap; /* bomb: where --no-overlap, an option without a value, goes */
    int taper_given; /* deform: --taper came */
} Out;

static int bad(Out *u, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int bad(Out *u, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    diag_vformat(u->err, u->errlen, fmt, ap);
    va_end(ap);
    return -1;
}

#define BAD_VALUE(opt, v, what) bad(u, "%s %s: expected %s", opt, v, what)

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

int texgen_is_help(const char *arg)
{
    return !strcmp(arg, "--help") || !strcmp(arg, "-h");
}

/* What argv[*i] starts: 1 an option with its value in *v (i moves past it), 0 --help
 * (u->o->help set: stop), -1 an error. */
static int next_option(Out *u, int argc, char **argv, int *i, const char **v)
{
    const char *a = argv[*i];
    if (texgen_is_help(a)) {
        u->o->help = 1;
        return 0;
    }
    if (a[0] != '-') return bad(u, "unexpected argument '%s'", a);
    if (*i + 1 >= argc) return bad(u, "%s needs a value", a);
    *v = argv[++*i];
    return 1;
}

/* One option a with its value v into a method's parameters; 0 or -1 (reported). */
typedef int (*OptionFn)(Out *u, void *params, const char *a, const char *v);

/* Reads argv[1..] option by option through fn; stops at --help. */
static int parse_options(Out *u, int argc, char **argv, OptionFn fn, void *params)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = NULL;
        if (u->no_overlap && !strcmp(a, "--no-overlap")) {
            *u->no_overlap = 1;
            continue;
        }
        int r = next_option(u, argc, argv, &i, &v);
        if (r <= 0) return r;
        if (fn(u, params, a, v)) return -1;
    }
    return 0;
}

/* --shape, --size: the options of `bomb` that take words or pairs. */
static int bomb_shape_or_size(Out *u, BombParams *p, const char *a, const char *v)
{
    if (!strcmp(a, "--shape")) {
        if (!strcmp(v, "sphere"))
            p->shape = TEX_SPHERE;
        else if (!strcmp(v, "cylinder"))
            p->shape = TEX_CYLINDER;
        else if (!strcmp(v, "cube"))
            p->shape = TEX_CUBE;
        else
            return BAD_VALUE(a, v, "sphere, cylinder or cube");
        return 0;
    }
    const char *colon = strchr(v, ':');
    char lo[64];
    if (!colon || (size_t)(colon - v) >= sizeof lo) return BAD_VALUE(a, v, "MIN:MAX");
    memcpy(lo, v, (size_t)(colon - v));
    lo[colon - v] = 0;
    if (parse_float(lo, &p->size_min) || parse_float(colon + 1, &p->size_max))
        return BAD_VALUE(a, v, "MIN:MAX with two numbers");
    if (!(p->size_min > 0) || p->size_min > p->size_max) return BAD_VALUE(a, v, "0 < MIN <= MAX");
    return 0;
}

/* One option of `bomb` with its value v. */
static int bomb_option(Out *u, void *params, const char *a, const char *v)
{
    BombParams *p = params;
    if (!strcmp(a, "--shape") || !strcmp(a, "--size")) return bomb_shape_or_size(u, p, a, v);
    if (!strcmp(a, "--count")) {
        if (parse_int(v, 1, 1000000, &p->count)) return BAD_VALUE(a, v, "1 to 1000000");
    } else if (!strcmp(a, "--seed")) {
        if (parse_u64(v, &p->seed)) return BAD_VALUE(a, v, "an integer >= 0");
    } else if (!strcmp(a, "--block")) {
        if (parse_float(v, &p->block) || !(p->block > 0)) return BAD_VALUE(a, v, "a size > 0");
    } else if (!strcmp(a, "--level")) {
        if (parse_int(v, 0, 5, &p->level)) return BAD_VALUE(a, v, "0 to 5");
    } else if (!strcmp(a, "--segments")) {
        if (parse_int(v, 3, 1024, &p->segments)) return BAD_VALUE(a, v, "3 to 1024");
    } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
        u->o->output = v;
    } else {
        return bad(u, "unknown option %s (see vbcl texgen bomb --help)", a);
    }
    return 0;
}

int texgen_bomb_args(int argc, char **argv, BombParams *p, TexgenOpts *o, char *err, size_t errlen)
{
    Out u = {o, err, errlen, &p->no_overlap, 0};
    memset(o, 0, sizeof *o);
    bomb_defaults(p);
    return parse_options(&u, argc, argv, bomb_option, p);
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

/* --profile, --kind: the options of `deform` that take words. */
static int deform_word(Out *u, DeformParams *p, const char *a, const char *v)
{
    if (!strcmp(a, "--profile")) {
        if (!strcmp(v, "circle"))
            p->rect = 0;
        else if (!strcmp(v, "rect"))
            p->rect = 1;
        else
            return BAD_VALUE(a, v, "circle or rect");
    } else if (!strcmp(v, "nested")) {
        p->kind = DEFORM_NESTED;
    } else if (!strcmp(v, "tubes")) {
        p->kind = DEFORM_TUBES;
    } else {
        return BAD_VALUE(a, v, "nested or tubes");
    }
    return 0;
}

/* One option of `deform` with its value v (--preset was applied first). */
static int deform_option(Out *u, void *params, const char *a, const char *v)
{
    DeformParams *p = params;
    float *f;
    if (!strcmp(a, "--preset")) return 0;
    if (!strcmp(a, "--profile") || !strcmp(a, "--kind")) return deform_word(u, p, a, v);
    if (!strcmp(a, "--count")) {
        if (parse_int(v, 1, DEFORM_MAX, &p->count)) return BAD_VALUE(a, v, "1 to 64");
    } else if (!strcmp(a, "--taper")) {
        u->taper_given = 1;
        if (parse_values(v, p->taper, &p->ntaper, &p->taper_random))
            return BAD_VALUE(a, v, "A1,A2,... (one per profile), random or none");
    } else if (!strcmp(a, "--twist")) {
        if (parse_values(v, p->twist, &p->ntwist, &p->twist_random))
            return BAD_VALUE(a, v, "T1,T2,... (one per profile), random or none");
    } else if ((f = deform_float_field(p, a))) {
        if (parse_float(v, f)) return BAD_VALUE(a, v, "a number");
    } else if (!strcmp(a, "--segments")) {
        if (parse_int(v, 3, 4096, &p->segments)) return BAD_VALUE(a, v, "3 to 4096");
    } else if (!strcmp(a, "--rings")) {
        if (parse_int(v, 0, 4096, &p->rings)) return BAD_VALUE(a, v, "0 (auto) to 4096");
    } else if (!strcmp(a, "--seed")) {
        if (parse_u64(v, &p->seed)) return BAD_VALUE(a, v, "an integer >= 0");
    } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
        u->o->output = v;
    } else {
        return bad(u, "unknown option %s (see vbcl texgen deform --help)", a);
    }
    return 0;
}

int texgen_deform_args(int argc, char **argv, DeformParams *p, TexgenOpts *o, char *err,
                       size_t errlen)
{
    Out u0 = {o, err, errlen, NULL, 0}, *u = &u0;
    memset(o, 0, sizeof *o);
    deform_defaults(p);
    /* the preset first, so that other options override it wherever they stand */
    for (int i = 1; i + 1 < argc; i++)
        if (!strcmp(argv[i], "--preset") && deform_preset(p, argv[i + 1]) < 0)
            return BAD_VALUE("--preset", argv[i + 1], "figure2.2, wood or marble");
    int rc = parse_options(u, argc, argv, deform_option, p);
    if (rc || o->help) return rc;
    if (p->ntaper && p->ntaper != p->count && !u->taper_given)
        return bad(u,
                   "--count %d: the default --taper has %d values (figure 2.2); expected "
                   "--taper with %d values, --taper random or --taper none",
                   p->count, p->ntaper, p->count);
    return 0;
}

static void fourier_args_defaults(FourierArgs *f)
{
    *f = (FourierArgs){.terms = 5,
                       .pixels = 256,
                       .a0 = 1.0f,
                       .freq = {12.566371f, 12.566371f, 12.566371f},
                       .z = 0.5f,
                       .extent = 1.0f,
                       .seed = 1};
}

/* One option of `fourier` with its value v. */
static int fourier_option(Out *u, void *params, const char *a, const char *v)
{
    FourierArgs *f = params;
    if (!strcmp(a, "--terms")) {
        if (parse_int(v, 4, 7, &f->terms)) return BAD_VALUE(a, v, "4 to 7 (thesis 2.1.2)");
    } else if (!strcmp(a, "--contrast")) {
        if (parse_float(v, &f->a0) || !(f->a0 >= 0)) return BAD_VALUE(a, v, "A_0 >= 0");
    } else if (!strcmp(a, "--freq")) {
        int n = parse_list(v, f->freq, 3);
        if (n == 1) f->freq[1] = f->freq[2] = f->freq[0];
        if (n != 1 && n != 3) return BAD_VALUE(a, v, "F or FX,FY,FZ");
    } else if (!strcmp(a, "--seed")) {
        if (parse_u64(v, &f->seed)) return BAD_VALUE(a, v, "an integer >= 0");
    } else if (!strcmp(a, "--z")) {
        if (parse_float(v, &f->z)) return BAD_VALUE(a, v, "a number");
    } else if (!strcmp(a, "--extent")) {
        if (parse_float(v, &f->extent) || !(f->extent > 0)) return BAD_VALUE(a, v, "a size > 0");
    } else if (!strcmp(a, "--pixels")) {
        if (parse_int(v, 1, 8192, &f->pixels)) return BAD_VALUE(a, v, "1 to 8192");
    } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
        u->o->output = v;
    } else {
        return bad(u, "unknown option %s (see vbcl texgen fourier --help)", a);
    }
    return 0;
}

int texgen_fourier_args(int argc, char **argv, FourierArgs *f, TexgenOpts *o, char *err,
                        size_t errlen)
{
    Out u = {o, err, errlen, NULL, 0};
    memset(o, 0, sizeof *o);
    fourier_args_defaults(f);
    return parse_options(&u, argc, argv, fourier_option, f);
}

/* The one option of `project`. */
static int project_option(Out *u, void *params, const char *a, const char *v)
{
    (void)params;
    if (strcmp(a, "--image"))
        return bad(u, "unknown option %s (see vbcl texgen project --help)", a);
    u->o->image = v;
    return 0;
}

int texgen_project_args(int argc, char **argv, TexgenOpts *o, char *err, size_t errlen)
{
    Out u = {o, err, errlen, NULL, 0};
    memset(o, 0, sizeof *o);
    return parse_options(&u, argc, argv, project_option, NULL);
}
