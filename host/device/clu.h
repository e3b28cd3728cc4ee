/* clu.h — OpenCL host utilities: checked calls, device listing and choice, and program
 * builds that print the log and options on failure and cache binaries between runs. */
#ifndef VBCL_CLU_H
#define VBCL_CLU_H

#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>
#include <stddef.h>
#include <stdio.h>

/* The most programs a device keeps built: the tracing programs, film and probe. */
#define CLU_KEPT_PROGRAMS 6

/* An OpenCL device with its context and an in-order profiling queue. */
typedef struct VbDevice {
    cl_platform_id platform;
    cl_device_id device;
    cl_context context;
    cl_command_queue queue;
    int index;         /* in clu_list_devices's order */
    char name[256];    /* "platform / device" */
    char version[128]; /* device version */
    char driver[128];  /* driver version */
    cl_ulong global_mem, max_alloc;
    size_t max_wg;
    /* a device on the host's memory (a CPU): vbcl allocates its buffers itself (clu_buffer),
     * aligned to host_align bytes, so that running out of memory is a message, not a
     * driver's failure at the buffer's first use */
    int host_memory;
    size_t host_align;
    /* the programs built on this device, kept for later frames and renderers (released
     * by clu_device_close) */
    struct {
        unsigned long long key;
        cl_program program;
    } kept[CLU_KEPT_PROGRAMS];
    int nkept;
} VbDevice;

/* Whether the first failure recorded since clu_error_clear was a failed allocation (the
 * host's, CL_OUT_OF_HOST_MEMORY or CL_MEM_OBJECT_ALLOCATION_FAILURE): the caller names what
 * it was allocating and what would take less. */
int clu_error_out_of_memory(void);

/* The name of an OpenCL error code ("CL_OUT_OF_RESOURCES"). */
const char *clu_error_name(cl_int code);

/* Records the first failed call of this thread (later ones are ignored until
 * clu_error_clear) with the call text, file, line and the error's name; returns -1 so
 * callers can `return`. */
int clu_fail(cl_int code, const char *call, const char *file, int line);
/* The first recorded error message, or "" when none. */
const char *clu_error(void);
void clu_error_clear(void);

/* Checks a call that returns cl_int; on failure records it and jumps to label. */
#define CL_CHECK(call, label)                                                                      \
    do {                                                                                           \
        cl_int clu_rc_ = (call);                                                                   \
        if (clu_rc_ != CL_SUCCESS) {                                                               \
            clu_fail(clu_rc_, #call, __FILE__, __LINE__);                                          \
            goto label;                                                                            \
        }                                                                                          \
    } while (0)

/* Checks the cl_int error out-parameter of a create call. */
#define CL_CHECK_ERR(rc, what, label)                                                              \
    do {                                                                                           \
        if ((rc) != CL_SUCCESS) {                                                                  \
            clu_fail((rc), (what), __FILE__, __LINE__);                                            \
            goto label;                                                                            \
        }                                                                                          \
    } while (0)

/* For clean-up paths: warns on stderr instead of recording. */
#define CL_WARN(call)                                                                              \
    do {                                                                                           \
        cl_int clu_rc_ = (call);                                                                   \
        if (clu_rc_ != CL_SUCCESS)                                                                 \
            fprintf(stderr, "vbcl: warning: %s failed: %s (%s:%d)\n", #call,                       \
                    clu_error_name(clu_rc_), __FILE__, __LINE__);                                  \
    } while (0)

/* Prints every platform and device with its index. Returns the number of devices. */
int clu_list_devices(FILE *out);

/* The most devices one process drives (--device all takes the first this many). */
#define CLU_MAX_DEVICES 16

/* The devices spec names, as indices of clu_list_devices: "all", or a comma-separated list
 * of items, each an index or a case-insensitive part of a name (among the devices the list
 * has not named yet, the first whose platform's name contains it, else whose device name
 * or version does); NULL is $VBCL_DEVICE (named so in messages), and NULL or "" there is
 * device 0. Returns how many (<= max) are in
 * picks, -1 when there is no OpenCL device at all, or -2 when spec is not a valid list
 * (a usage error: an item that matches nothing, a device named twice); err says which. */
int clu_device_pick(const char *spec, int *picks, int max, char *err, size_t errlen);

/* Opens device `index` of clu_list_devices: its context and profiling queue. Returns 0, or
 * 1 on an OpenCL failure with a message in err. */
int clu_device_open_index(int index, VbDevice *d, char *err, size_t errlen);

/* Opens the one device chosen by spec (clu_device_pick with one item). Returns 0, 2 when
 * spec matches nothing (usage error), or 1 on an OpenCL failure (err says which). */
int clu_device_open(const char *spec, VbDevice *d, char *err, size_t errlen);
void clu_device_close(VbDevice *d);

/* Opens every device spec names (clu_device_pick), at most max, into devs[0..*ndev).
 * Returns as clu_device_open; on failure none is left open. */
int clu_devices_open(const char *spec, VbDevice *devs, int max, int *ndev, char *err,
                     size_t errlen);
void clu_devices_close(VbDevice *devs, int n);

/* How clu_program_build got its program. */
enum {
    CLU_BUILT = 0,              /* compiled from source: the first time on this device */
    CLU_BINARY = 1,             /* loaded from vbcl's binary cache */
    CLU_BUILT_DRIVER_CACHE = 2, /* built from source by a driver that keeps compiled kernels
                                 * itself (PoCL), which has built it before */
    CLU_KEPT = 3,               /* built earlier in this run (an earlier frame) */
};

/* How a program came (CLU_BUILT ...), as --stats and vbcl --warm-cache say it. */
const char *clu_build_how(int how);

/* Builds source with options for d, or returns the program d keeps from an earlier build
 * of the same source and options (retained: the caller releases it). A binary cache keyed
 * by source, options and device is used unless VBCL_CACHE_DIR is "off", or the driver keeps
 * its own kernel cache and VBCL_CACHE_BINARIES is not 1; a cached binary whose header,
 * length or hash is wrong is removed and rebuilt. *cached says how the program came
 * (CLU_BUILT ...) and *ms the time taken. On a failed build the log and the options are
 * printed to stderr. Returns the program, or NULL (clu_error() says why). */
cl_program clu_program_build(VbDevice *d, const char *source, const char *options, double *ms,
                             int *cached);

/* Whether this program has been compiled on d before, with its kernels launched
 * (clu_program_mark_seen: a stamp in the cache's programs/ folder). */
int clu_program_seen(const VbDevice *d, const char *source, const char *options);
void clu_program_mark_seen(const VbDevice *d, const char *source, const char *options);

/* A buffer of `bytes` (at least 16: zero-sized buffers are invalid), initialised from data
 * when not NULL. Returns NULL with the failure recorded (clu_error). */
cl_mem clu_buffer(VbDevice *d, const void *data, size_t bytes, cl_mem_flags flags);

/* clSetKernelArg, recording a failure with the argument's index; returns 0 or -1. */
int clu_set_arg(cl_kernel k, cl_uint i, size_t size, const void *val);

/* Milliseconds between the start and end of a completed, profiled event (0 on error). */
double clu_event_ms(cl_event ev);

/* Wall-clock milliseconds from a monotonic clock. */
double clu_now_ms(void);

#endif
