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
};

unsigned features_of_scene(const Scene *s)
{
    unsigned f = 0;
    for (int i = 0; i < s->nlights; i++)
        if (s->lights[i].radius > 0.0f) f |= VBCL_FEATURE_AREA_LIGHTS;
    if (s->mesh.normals) f |= VBCL_FEATURE_SMOOTH_NORMALS;
    for (int i = 0; i < s->nmaterials; i++) {
        const VbMaterial *m = &s->materials[i].gpu;
        if (m->k_local > 0.0f &&
            (m->specular[0] > 0.0f || m->specular[1] > 0.0f || m->specular[2] > 0.0f))
            f |= VBCL_FEATURE_SPECULAR;
    }
    return f;
}

void features_build_options(unsigned features, const Scene *s, const char *extra, char *out,
                            size_t n)
{
    size_t len = (size_t)snprintf(out, n, "-cl-std=CL1.2 -DVBCL_MAX_DEPTH=%d", s->max_depth);
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
