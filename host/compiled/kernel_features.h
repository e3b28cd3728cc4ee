/* kernel_features.h — what a scene needs from the kernels (VBCL_FEATURE_* bits), the few
 * programs that cover every scene, and the OpenCL build options of each. */
#ifndef VBCL_KERNEL_FEATURES_H
#define VBCL_KERNEL_FEATURES_H

#include <stddef.h>

#include "scene.h"

/* The tracing programs: each compiles in the features of the one before it and more. A
 * scene runs on the first whose features hold all of its own; the program tests the
 * scene's VBCL_FRAME_* flags where it has code the scene does not use. */
enum {
    PROGRAM_OPAQUE,     /* lights, normals, specular, patterns, volume textures */
    PROGRAM_DIELECTRIC, /* and transparency, absorption (a stack for depth 64) */
    PROGRAM_DISPERSIVE, /* and dispersion (a stack for depth 64 and 64 bands) */
    PROGRAM_COUNT
};

/* How vbcl picks a scene's program: its class (the default), or with VBCL_KERNEL_PROGRAMS
 * "scene" a program of exactly the scene's features and stack size class (the way kernels
 * were specialised before the classes, kept to measure what a class costs), or "all" the
 * dispersive program for every scene. */
enum { PROGRAMS_CLASSES, PROGRAMS_SCENE, PROGRAMS_ALL };
int features_programs_mode(void);

/* The feature bits the scene uses. */
unsigned features_of_scene(const Scene *s);
/* The program (PROGRAM_*) that covers those features. */
int features_program(unsigned scene_features);
/* The features compiled into program p. */
unsigned features_of_program(int p);
/* The features compiled into the program a scene of these features runs on, as
 * features_programs_mode says: its class's, or with "scene" exactly its own. */
unsigned features_compiled(unsigned scene_features);
/* The program's name in messages ("opaque", "dielectric", "dispersive"). */
const char *features_program_name(int p);
/* The VBCL_FRAME_* flags that tell a program which of its features the scene uses. */
unsigned features_frame_flags(unsigned scene_features);
/* Writes the build options of the program for a scene of these features into out: the
 * class's (features_program) by default, else as features_programs_mode says; s gives the
 * tree depth and band count the "scene" mode sizes the stack by. */
void features_build_options(unsigned scene_features, const Scene *s, char *out, size_t n);
/* The options of program p itself (the "classes" mode). */
void features_program_options(int p, char *out, size_t n);
/* Writes the features' names, space separated ("none" when empty), into out. */
void features_describe(unsigned features, char *out, size_t n);

#endif
