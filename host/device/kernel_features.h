/* kernel_features.h — what a scene needs from the kernels, as VBCL_FEATURE_* bits, and the
 * OpenCL build options that compile in only that. */
#ifndef VBCL_KERNEL_FEATURES_H
#define VBCL_KERNEL_FEATURES_H

#include <stddef.h>

#include "scene.h"

/* The feature bits the scene uses. */
unsigned features_of_scene(const Scene *s);
/* Writes the build options for those features (plus extra, may be NULL) into out. */
void features_build_options(unsigned features, const Scene *s, const char *extra, char *out,
                            size_t n);
/* Writes the features' names, space separated ("none" when empty), into out. */
void features_describe(unsigned features, char *out, size_t n);

#endif
