/* warm.h — vbcl --warm-cache: every tracing program (kernel_features.h) and the film
 * program built, and every kernel launched once, on the chosen devices, so that later
 * renders find them in the driver's cache (or vbcl's binary cache) and compile nothing. */
#ifndef VBCL_WARM_H
#define VBCL_WARM_H

#include <stddef.h>

#include "clu.h"

/* Builds every program on each device spec names (clu_device_pick; NULL: device 0), in
 * `jobs` processes at once (forked before any of them starts OpenCL: a driver may compile
 * one program at a time in a process, as PoCL does), each program in a context of its own;
 * prints a line per program on stderr unless quiet. Returns 0, or 1 after a message. */
int warm_cache(const char *spec, int jobs, int quiet);

#endif
