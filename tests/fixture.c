/* fixture.c — prepares scenes on the test device and runs probe kernels on them. */
#include "fixture.h"

#include <stdio.h>
#include <string.h>

#include "harness.h"
#include "testutil.h"

/* A scene loaded from JSON text and prepared on the test device with the probe kernels. */

int fixture_open(Fixture *fx, const char *json)
{
    memset(fx, 0, sizeof *fx);
    VbDevice *d = tu_device();
    if (!d) {
        th_skip("no OpenCL device");
        return -1;
    }
    char err[1024];
    const char *path = tu_write_file("fixture.json", json);
    if (scene_load(path, &fx->s, err, sizeof err)) {
        CHECK(0, "fixture scene: %s", err);
        return -1;
    }
    RenderStats st;
    memset(&st, 0, sizeof st);
    if (renderer_init(&fx->r, d, &fx->s, vbcl_probe_source, &st, err, sizeof err)) {
        CHECK(0, "renderer_init: %s", err);
        scene_free(&fx->s);
        return -1;
    }
    /* the frame buffer normally written per tile */
    if (clEnqueueWriteBuffer(d->queue, fx->r.buf.frame, CL_TRUE, 0, sizeof(VbFrame),
                             &fx->r.frame_host, 0, NULL, NULL) != CL_SUCCESS) {
        CHECK(0, "frame upload failed");
        return -1;
    }
    fx->ok = 1;
    return 0;
}

void fixture_close(Fixture *fx)
{
    if (fx->ok) renderer_release(&fx->r);
    if (fx->ok) scene_free(&fx->s);
    fx->ok = 0;
}

/* The work-group size of the tests' launches: the renderer's (64), so that a driver that
 * compiles a kernel for each work-group size (PoCL) compiles each kernel once. */
static const size_t *tu_local(size_t global)
{
    static const size_t local = 64;
    return tu_device()->max_wg >= local && global % local == 0 ? &local : NULL;
}

cl_mem buffer(const void *data, size_t bytes)
{
    VbDevice *d = tu_device();
    cl_int rc;
    cl_mem m = clCreateBuffer(d->context, CL_MEM_READ_WRITE | (data ? CL_MEM_COPY_HOST_PTR : 0),
                              bytes, (void *)data, &rc);
    CHECK(rc == CL_SUCCESS, "clCreateBuffer: %s", clu_error_name(rc));
    return m;
}

/* Runs kernel `name` over n work items with the given arguments (all cl_mem or int). */
int run_kernel(cl_program prog, const char *name, size_t n, int nargs, const size_t *sizes,
               const void *const *vals)
{
    VbDevice *d = tu_device();
    cl_int rc;
    cl_kernel k = clCreateKernel(prog, name, &rc);
    CHECK(rc == CL_SUCCESS, "clCreateKernel(%s): %s", name, clu_error_name(rc));
    if (rc != CL_SUCCESS) return -1;
    for (int i = 0; i < nargs; i++) {
        rc = clSetKernelArg(k, (cl_uint)i, sizes[i], vals[i]);
        CHECK(rc == CL_SUCCESS, "%s argument %d: %s", name, i, clu_error_name(rc));
    }
    size_t global = (n + 63) / 64 * 64;
    rc = clEnqueueNDRangeKernel(d->queue, k, 1, NULL, &global, tu_local(global), 0, NULL, NULL);
    CHECK(rc == CL_SUCCESS, "enqueue %s: %s", name, clu_error_name(rc));
    clFinish(d->queue);
    clReleaseKernel(k);
    return rc == CL_SUCCESS ? 0 : -1;
}

void read_buffer(cl_mem m, void *dst, size_t bytes)
{
    cl_int rc = clEnqueueReadBuffer(tu_device()->queue, m, CL_TRUE, 0, bytes, dst, 0, NULL, NULL);
    CHECK(rc == CL_SUCCESS, "read: %s", clu_error_name(rc));
}

void fixture_run_frame_kernel(Fixture *fx, const char *name, cl_mem rays, int n, cl_mem hits,
                              cl_mem counters)
{
    VbDevice *d = tu_device();
    cl_int rc;
    cl_kernel k = clCreateKernel(fx->r.program, name, &rc);
    CHECK(rc == CL_SUCCESS, "clCreateKernel(%s): %s", name, clu_error_name(rc));
    if (rc != CL_SUCCESS) return;
    cl_mem media = buffer(NULL, sizeof(VbMedium) * (size_t)n);
    cl_mem radiance = buffer(NULL, sizeof(float) * 4 * (size_t)n);
    CHECK(renderer_set_frame_args(&fx->r, k, rays, n, hits, media, radiance, counters) == 0,
          "frame arguments: %s", clu_error());
    size_t global = ((size_t)n + 63) / 64 * 64;
    rc = clEnqueueNDRangeKernel(d->queue, k, 1, NULL, &global, tu_local(global), 0, NULL, NULL);
    CHECK(rc == CL_SUCCESS, "enqueue %s: %s", name, clu_error_name(rc));
    clFinish(d->queue);
    clReleaseMemObject(media);
    clReleaseMemObject(radiance);
    clReleaseKernel(k);
}

int fixture_run_probe(Fixture *fx, const char *name, size_t n, int nargs, const size_t *sizes,
                      const void *const *vals)
{
    VbDevice *d = tu_device();
    cl_int rc;
    cl_kernel k = clCreateKernel(fx->r.probe, name, &rc);
    CHECK(rc == CL_SUCCESS, "clCreateKernel(%s): %s", name, clu_error_name(rc));
    if (rc != CL_SUCCESS) return -1;
    CHECK(scene_buffers_set_args(&fx->r.buf, k) == 0, "scene arguments: %s", clu_error());
    for (int i = 0; i < nargs; i++) {
        rc = clSetKernelArg(k, (cl_uint)(SCENE_BUFFER_ARGS + i), sizes[i], vals[i]);
        CHECK(rc == CL_SUCCESS, "%s argument %d: %s", name, SCENE_BUFFER_ARGS + i,
              clu_error_name(rc));
    }
    size_t global = (n + 63) / 64 * 64;
    rc = clEnqueueNDRangeKernel(d->queue, k, 1, NULL, &global, tu_local(global), 0, NULL, NULL);
    CHECK(rc == CL_SUCCESS, "enqueue %s: %s", name, clu_error_name(rc));
    clFinish(d->queue);
    clReleaseKernel(k);
    return rc == CL_SUCCESS ? 0 : -1;
}

int fixture_shade_points(Fixture *fx, const float *pts, const float *nrm, int n, float *out)
{
    size_t bytes = sizeof(float) * 4 * (size_t)n;
    cl_mem mp = buffer(pts, bytes), mn = buffer(nrm, bytes), mo = buffer(NULL, bytes);
    const size_t sz[] = {sizeof(cl_mem), sizeof(cl_mem), sizeof(int), sizeof(cl_mem)};
    const void *v[] = {&mp, &mn, &n, &mo};
    int rc = fixture_run_probe(fx, "probe_shade_points", (size_t)n, 4, sz, v);
    if (rc == 0) read_buffer(mo, out, bytes);
    clReleaseMemObject(mp);
    clReleaseMemObject(mn);
    clReleaseMemObject(mo);
    return rc;
}
