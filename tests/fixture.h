/* fixture.h — a scene prepared on the test device with the probe kernels built in, and
 * small helpers to run kernels on it. */
#ifndef VBCL_FIXTURE_H
#define VBCL_FIXTURE_H

#include "render.h"

/* A scene loaded from JSON text and prepared on the test device, with the probe program
 * (kernels/probe.cl) built beside the renderer's (r.probe). */
typedef struct Fixture {
    Scene s;
    Renderer r;
    int ok;
} Fixture;

/* Loads json as a scene and prepares it; -1 (test skipped or failed) when it cannot. */
int fixture_open(Fixture *fx, const char *json);
void fixture_close(Fixture *fx);
/* A read-write buffer, initialised from data when not NULL. */
cl_mem buffer(const void *data, size_t bytes);
/* Runs kernel `name` of prog over n work items with the given arguments. */
int run_kernel(cl_program prog, const char *name, size_t n, int nargs, const size_t *sizes,
               const void *const *vals);
void read_buffer(cl_mem m, void *dst, size_t bytes);
/* Runs a probe that starts with the scene arguments (SCENE_KERNEL_ARGS), followed by
 * nargs arguments of its own. */
int fixture_run_probe(Fixture *fx, const char *name, size_t n, int nargs, const size_t *sizes,
                      const void *const *vals);
/* Shades n points (probe_shade_points: xyz per 4 floats, normals likewise, the normal's w the
 * band + 1, 0 for white) into out (n x 4 floats: radiance, feelers traced). */
int fixture_shade_points(Fixture *fx, const float *pts, const float *nrm, int n, float *out);
/* Runs a frame kernel (FRAME_KERNEL_ARGS) of the fixture over n rays, with fresh media and
 * radiance buffers; hits and counters are the caller's. */
void fixture_run_frame_kernel(Fixture *fx, const char *name, cl_mem rays, int n, cl_mem hits,
                              cl_mem counters);

#endif
