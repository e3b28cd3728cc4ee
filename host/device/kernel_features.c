/* kernel_features.c — turns a scene's needs into -D options, so that a scene pays only for the
 * kernel code it uses ("skip what a scene doesn't need", docs/architecture.md). */
#include "kernel_features.h"

#include <stdio.h>
#include <string.h>

/* One row per feature bit: its name in logs and the macro the kernels test. */
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
    {VBCL_FEATURE_FRESNEL_THESIS, "fresnel-thesis", "VBCL_HAS_FRESNEL_THESIS"},
    {VBCL_FEATURE_PATTERNS, "patterns", "VBCL_HAS_PATTERNS"},
    {VBCL_FEATURE_DISPERSION, "dispersion", "VBCL_HAS_DISPERSION"},
};

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
    return f;
}

void features_build_options(unsigned features, const Scene *s, const char *extra, char *out,
                            size_t n)
{
    int stack = 8;
    /* depth first: one pending sibling per level, plus the bands of the one split on the
     * path (a band ray never splits again) */
    int need = s->max_depth + 1 + ((features & VBCL_FEATURE_DISPERSION) ? s->bands : 0);
    while (stack < need) stack *= 2; /* size classes 8, 16, 32, 64, 128 */
    size_t len = (size_t)snprintf(out, n, "-cl-std=CL1.2");
    if (features & VBCL_FEATURE_TRANSPARENCY)
        len += (size_t)snprintf(out + len, n - len, " -DVBCL_TREE_STACK=%d", stack);
    for (int i = 0; i < VBCL_FEATURE_COUNT && len < n; i++)
        if (features & feature_table[i].bit)
            len += (size_t)snprintf(out + len, n - len, " -D%s", feature_table[i].macro);
    if (extra && *extra && len < n) snprintf(out + len, n - len, " %s", extra);
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
