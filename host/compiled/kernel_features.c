/* kernel_features.c — a scene's needs as VBCL_FEATURE_* bits, and the three programs that
 * cover every scene ("skip what a scene doesn't need": at run time first, at compile time
 * only where it measurably pays; docs/architecture.md, "Kernel programs"). */
#include "kernel_features.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dispersion.h"

/* One row per feature bit: its name in logs and the macro the kernels test (NULL: the
 * kernels test a VBCL_FRAME_* flag instead, in every program). */
static const struct {
    unsigned bit;
    const char *name;
    const char *macro;
} feature_table[VBCL_FEATURE_COUNT] = {
    {VBCL_FEATURE_AREA_LIGHTS, "area-lights", "VBCL_HAS_AREA_LIGHTS"},
    {VBCL_FEATURE_SMOOTH_NORMALS, "smooth-normals", "VBCL_HAS_SMOOTH_NORMALS"},
    {VBCL_FEATURE_SPECULAR, "specular", "VBCL_HAS_SPECULAR"},
    {VBCL_FEATURE_TRANSPARENCY, "transparency", "VBCL_HAS_TRANSPARENCY"},
    {VBCL_FEATURE_TEXTURES, "textures", "VBCL_HAS_TEXTURES"},
    {VBCL_FEATURE_ABSORPTION, "absorption", "VBCL_HAS_ABSORPTION"},
    {VBCL_FEATURE_FRESNEL_THESIS, "fresnel-thesis", NULL},
    {VBCL_FEATURE_PATTERNS, "patterns", "VBCL_HAS_PATTERNS"},
    {VBCL_FEATURE_DISPERSION, "dispersion", "VBCL_HAS_DISPERSION"},
    {VBCL_FEATURE_ENVIRONMENT, "environment", NULL},
};

#define OPAQUE_FEATURES                                                                            \
    (VBCL_FEATURE_AREA_LIGHTS | VBCL_FEATURE_SMOOTH_NORMALS | VBCL_FEATURE_SPECULAR |              \
     VBCL_FEATURE_PATTERNS | VBCL_FEATURE_TEXTURES | VBCL_FEATURE_ENVIRONMENT)
#define DIELECTRIC_FEATURES                                                                        \
    (OPAQUE_FEATURES | VBCL_FEATURE_TRANSPARENCY | VBCL_FEATURE_ABSORPTION |                       \
     VBCL_FEATURE_FRESNEL_THESIS)

static const struct {
    const char *name;
    unsigned features;
} programs[PROGRAM_COUNT] = {
    {"opaque", OPAQUE_FEATURES},
    {"dielectric", DIELECTRIC_FEATURES},
    {"dispersive", DIELECTRIC_FEATURES | VBCL_FEATURE_DISPERSION},
};

/* The deepest tree a scene may ask for (render.max_depth) and so the tree stack of the
 * dielectric program: one pending sibling per level; the dispersive one adds a split's
 * bands (kernels/tree.cl). */
#define PROGRAM_MAX_DEPTH 64

static pthread_once_t mode_once = PTHREAD_ONCE_INIT;
static int mode = PROGRAMS_CLASSES;

static void mode_read(void)
{
    const char *env = getenv("VBCL_KERNEL_PROGRAMS");
    if (!env || !*env || !strcmp(env, "classes")) return;
    if (!strcmp(env, "scene"))
        mode = PROGRAMS_SCENE;
    else if (!strcmp(env, "all"))
        mode = PROGRAMS_ALL;
    else
        fprintf(stderr,
                "vbcl: VBCL_KERNEL_PROGRAMS=\"%s\" is not classes, scene or all; using classes\n",
                env);
}

int features_programs_mode(void)
{
    pthread_once(&mode_once, mode_read);
    return mode;
}

/* What material m needs from the kernels when an object uses it. */
static unsigned material_features(const VbMaterial *m)
{
    unsigned f = m->pattern >= 0 ? VBCL_FEATURE_PATTERNS : 0;
    if (m->k_local > 0.0f &&
        (m->specular[0] > 0.0f || m->specular[1] > 0.0f || m->specular[2] > 0.0f))
        f |= VBCL_FEATURE_SPECULAR;
    if (m->k_global > 0.0f) {
        f |= VBCL_FEATURE_TRANSPARENCY;
        if (m->extinction[0] > 0.0f || m->extinction[1] > 0.0f || m->extinction[2] > 0.0f)
            f |= VBCL_FEATURE_ABSORPTION;
        if (m->disp >= 0) f |= VBCL_FEATURE_DISPERSION;
    }
    return f;
}

unsigned features_of_scene(const Scene *s)
{
    unsigned f = 0;
    for (int i = 0; i < s->nlights; i++)
        if (s->lights[i].radius > 0.0f) f |= VBCL_FEATURE_AREA_LIGHTS;
    if (s->mesh.normals) f |= VBCL_FEATURE_SMOOTH_NORMALS;
    for (int i = 0; i < s->nobjects; i++) {
        const SceneObject *o = &s->objects[i];
        f |= material_features(&s->materials[o->material].gpu);
        if (o->tex_slot >= 0)
            f |= VBCL_FEATURE_TEXTURES | material_features(&s->materials[o->tex_material].gpu);
    }
    if ((f & VBCL_FEATURE_TRANSPARENCY) && s->fresnel == SCENE_FRESNEL_THESIS)
        f |= VBCL_FEATURE_FRESNEL_THESIS;
    if (s->env.file) f |= VBCL_FEATURE_ENVIRONMENT;
    return f;
}

int features_program(unsigned scene_features)
{
    if (features_programs_mode() == PROGRAMS_ALL) return PROGRAM_DISPERSIVE;
    for (int p = 0; p < PROGRAM_COUNT - 1; p++)
        if (!(scene_features & ~programs[p].features)) return p;
    return PROGRAM_DISPERSIVE;
}

unsigned features_of_program(int p)
{
    return programs[p].features;
}

unsigned features_compiled(unsigned scene_features)
{
    return features_programs_mode() == PROGRAMS_SCENE
               ? scene_features
               : features_of_program(features_program(scene_features));
}

const char *features_program_name(int p)
{
    return programs[p].name;
}

unsigned features_frame_flags(unsigned f)
{
    return ((f & VBCL_FEATURE_FRESNEL_THESIS) ? VBCL_FRAME_FRESNEL_THESIS : 0u) |
           ((f & VBCL_FEATURE_SMOOTH_NORMALS) ? VBCL_FRAME_SMOOTH_NORMALS : 0u) |
           ((f & VBCL_FEATURE_TRANSPARENCY) ? VBCL_FRAME_TRANSPARENCY : 0u) |
           ((f & VBCL_FEATURE_TEXTURES) ? VBCL_FRAME_TEXTURES : 0u) |
           ((f & VBCL_FEATURE_DISPERSION) ? VBCL_FRAME_DISPERSION : 0u) |
           ((f & VBCL_FEATURE_ABSORPTION) ? VBCL_FRAME_ABSORPTION : 0u) |
           ((f & VBCL_FEATURE_ENVIRONMENT) ? VBCL_FRAME_ENVIRONMENT : 0u);
}

/* "-cl-std=CL1.2", the tree stack when the program has transparency, and a -D for each of
 * the features with a macro. */
static void options_write(unsigned features, int stack, char *out, size_t n)
{
    size_t len = (size_t)snprintf(out, n, "-cl-std=CL1.2");
    if ((features & VBCL_FEATURE_TRANSPARENCY) && len < n)
        len += (size_t)snprintf(out + len, n - len, " -DVBCL_TREE_STACK=%d", stack);
    for (int i = 0; i < VBCL_FEATURE_COUNT && len < n; i++)
        if ((features & feature_table[i].bit) && feature_table[i].macro)
            len += (size_t)snprintf(out + len, n - len, " -D%s", feature_table[i].macro);
}

void features_program_options(int p, char *out, size_t n)
{
    unsigned f = programs[p].features;
    int stack = PROGRAM_MAX_DEPTH + 1 + ((f & VBCL_FEATURE_DISPERSION) ? DISP_MAX_BANDS : 0);
    options_write(f, stack, out, n);
}

void features_build_options(unsigned scene_features, const Scene *s, char *out, size_t n)
{
    if (features_programs_mode() != PROGRAMS_SCENE) {
        features_program_options(features_program(scene_features), out, n);
        return;
    }
    /* depth first: one pending sibling per level, plus the bands of the one split on the
     * path (a band ray never splits again); size classes 8, 16, 32, 64, 128 */
    int stack = 8;
    int need = s->max_depth + 1 + ((scene_features & VBCL_FEATURE_DISPERSION) ? s->bands : 0);
    while (stack < need) stack *= 2;
    options_write(scene_features, stack, out, n);
}

void features_describe(unsigned features, char *out, size_t n)
{
    size_t len = 0;
    out[0] = 0;
    for (int i = 0; i < VBCL_FEATURE_COUNT && len < n; i++)
        if (features & feature_table[i].bit)
            len +=
                (size_t)snprintf(out + len, n - len, "%s%s", len ? " " : "", feature_table[i].name);
    if (!len) snprintf(out, n, "none");
}
