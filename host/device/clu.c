/* clu.c — OpenCL host utilities: error names, the first-error record, devices, and
 * program builds with a binary cache. */
#include <stdio.h>

#include "clu.h"

#include "cache.h"
#include "fileio.h"

#include <ctype.h>
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* per thread: each device of a multi-device render runs in its own host thread */
static _Thread_local char first_error[1024];

const char *clu_error_name(cl_int code)
{
    switch (code) {
#define E(x)                                                                                       \
    case x:                                                                                        \
        return #x;
        E(CL_SUCCESS)
        E(CL_DEVICE_NOT_FOUND)
        E(CL_DEVICE_NOT_AVAILABLE)
        E(CL_COMPILER_NOT_AVAILABLE)
        E(CL_MEM_OBJECT_ALLOCATION_FAILURE)
        E(CL_OUT_OF_RESOURCES)
        E(CL_OUT_OF_HOST_MEMORY)
        E(CL_PROFILING_INFO_NOT_AVAILABLE)
        E(CL_MEM_COPY_OVERLAP)
        E(CL_IMAGE_FORMAT_MISMATCH)
        E(CL_IMAGE_FORMAT_NOT_SUPPORTED)
        E(CL_BUILD_PROGRAM_FAILURE)
        E(CL_MAP_FAILURE)
        E(CL_MISALIGNED_SUB_BUFFER_OFFSET)
        E(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
        E(CL_COMPILE_PROGRAM_FAILURE)
        E(CL_LINKER_NOT_AVAILABLE)
        E(CL_LINK_PROGRAM_FAILURE)
        E(CL_DEVICE_PARTITION_FAILED)
        E(CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
        E(CL_INVALID_VALUE)
        E(CL_INVALID_DEVICE_TYPE)
        E(CL_INVALID_PLATFORM)
        E(CL_INVALID_DEVICE)
        E(CL_INVALID_CONTEXT)
        E(CL_INVALID_QUEUE_PROPERTIES)
        E(CL_INVALID_COMMAND_QUEUE)
        E(CL_INVALID_HOST_PTR)
        E(CL_INVALID_MEM_OBJECT)
        E(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR)
        E(CL_INVALID_IMAGE_SIZE)
        E(CL_INVALID_SAMPLER)
        E(CL_INVALID_BINARY)
        E(CL_INVALID_BUILD_OPTIONS)
        E(CL_INVALID_PROGRAM)
        E(CL_INVALID_PROGRAM_EXECUTABLE)
        E(CL_INVALID_KERNEL_NAME)
        E(CL_INVALID_KERNEL_DEFINITION)
        E(CL_INVALID_KERNEL)
        E(CL_INVALID_ARG_INDEX)
        E(CL_INVALID_ARG_VALUE)
        E(CL_INVALID_ARG_SIZE)
        E(CL_INVALID_KERNEL_ARGS)
        E(CL_INVALID_WORK_DIMENSION)
        E(CL_INVALID_WORK_GROUP_SIZE)
        E(CL_INVALID_WORK_ITEM_SIZE)
        E(CL_INVALID_GLOBAL_OFFSET)
        E(CL_INVALID_EVENT_WAIT_LIST)
        E(CL_INVALID_EVENT)
        E(CL_INVALID_OPERATION)
        E(CL_INVALID_GL_OBJECT)
        E(CL_INVALID_BUFFER_SIZE)
        E(CL_INVALID_MIP_LEVEL)
        E(CL_INVALID_GLOBAL_WORK_SIZE)
        E(CL_INVALID_PROPERTY)
        E(CL_INVALID_IMAGE_DESCRIPTOR)
        E(CL_INVALID_COMPILER_OPTIONS)
        E(CL_INVALID_LINKER_OPTIONS)
        E(CL_INVALID_DEVICE_PARTITION_COUNT)
#undef E
    case -1001:
        return "CL_PLATFORM_NOT_FOUND_KHR (no OpenCL driver installed)";
    default:
        return "unknown OpenCL error";
    }
}

/* Whether the first recorded failure was a failed allocation (clu_error_out_of_memory). */
static _Thread_local int first_error_oom;

int clu_fail(cl_int code, const char *call, const char *file, int line)
{
    if (!first_error[0]) {
        snprintf(first_error, sizeof first_error, "%s failed: %s (%d) at %s:%d", call,
                 clu_error_name(code), (int)code, file, line);
        first_error_oom = code == CL_OUT_OF_HOST_MEMORY || code == CL_MEM_OBJECT_ALLOCATION_FAILURE;
    }
    return -1;
}

int clu_error_out_of_memory(void)
{
    return first_error[0] && first_error_oom;
}

const char *clu_error(void)
{
    return first_error;
}
void clu_error_clear(void)
{
    first_error[0] = 0;
    first_error_oom = 0;
}

double clu_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

double clu_event_ms(cl_event ev)
{
    cl_ulong a = 0, b = 0;
    if (clGetEventProfilingInfo(ev, CL_PROFILING_COMMAND_START, sizeof a, &a, NULL) ||
        clGetEventProfilingInfo(ev, CL_PROFILING_COMMAND_END, sizeof b, &b, NULL))
        return 0.0;
    return b > a ? (double)(b - a) * 1e-6 : 0.0;
}

/* Why enumerate found no device: no platform, or platforms whose drivers gave none. */
#define CLU_MIN_FILES 16 /* descriptors below which a missing platform is blamed on the limit */
static char enumerate_why[512];

/* All devices of all platforms, in listing order. Returns the count (<= max); with none,
 * enumerate_why says why. */
static int enumerate(cl_platform_id *plats, cl_device_id *devs, int max)
{
    cl_uint np = 0;
    cl_platform_id pl[16];
    cl_int rc = clGetPlatformIDs(16, pl, &np);
    struct rlimit nofile; /* the ICD loader opens a file per driver, the driver its own */
    if ((rc != CL_SUCCESS || np == 0) && getrlimit(RLIMIT_NOFILE, &nofile) == 0 &&
        nofile.rlim_cur < CLU_MIN_FILES) {
        snprintf(enumerate_why, sizeof enumerate_why,
                 "no OpenCL platform: the driver could not be loaded with so few file "
                 "descriptors (the descriptor limit, ulimit -n, is %lld; vbcl needs %d or more)",
                 (long long)nofile.rlim_cur, CLU_MIN_FILES);
        return 0;
    }
    if (rc != CL_SUCCESS || np == 0) {
        snprintf(enumerate_why, sizeof enumerate_why,
                 "no OpenCL platform: the ICD loader found no driver (%s; the drivers are "
                 "listed in /etc/OpenCL/vendors/*.icd): install one (make deps installs PoCL)",
                 rc == CL_SUCCESS ? "0 platforms" : clu_error_name(rc));
        return 0;
    }
    int n = 0;
    size_t len = (size_t)snprintf(enumerate_why, sizeof enumerate_why,
                                  "no OpenCL device: the drivers gave none (");
    for (cl_uint i = 0; i < np && i < 16; i++) {
        cl_uint nd = 0;
        cl_device_id dv[32];
        rc = clGetDeviceIDs(pl[i], CL_DEVICE_TYPE_ALL, 32, dv, &nd);
        if (rc != CL_SUCCESS || nd == 0) {
            char name[128] = "";
            clGetPlatformInfo(pl[i], CL_PLATFORM_NAME, sizeof name, name, NULL);
            if (len < sizeof enumerate_why)
                len += (size_t)snprintf(enumerate_why + len, sizeof enumerate_why - len, "%s%s: %s",
                                        i ? "; " : "", name,
                                        rc == CL_SUCCESS ? "0 devices" : clu_error_name(rc));
            continue;
        }
        for (cl_uint k = 0; k < nd && k < 32 && n < max; k++) {
            plats[n] = pl[i];
            devs[n++] = dv[k];
        }
    }
    if (len < sizeof enumerate_why)
        snprintf(enumerate_why + len, sizeof enumerate_why - len,
                 "); PoCL needs a writable cache directory (HOME, XDG_CACHE_HOME or "
                 "POCL_CACHE_DIR); check with clinfo");
    return n;
}

static void full_name(cl_platform_id p, cl_device_id d, char *out, size_t n)
{
    char pn[128] = "", dn[128] = "";
    clGetPlatformInfo(p, CL_PLATFORM_NAME, sizeof pn, pn, NULL);
    clGetDeviceInfo(d, CL_DEVICE_NAME, sizeof dn, dn, NULL);
    snprintf(out, n, "%s / %s", pn, dn);
}

int clu_list_devices(FILE *out)
{
    cl_platform_id plats[64];
    cl_device_id devs[64];
    int n = enumerate(plats, devs, 64);
    if (n == 0) fprintf(stderr, "vbcl: %s\n", enumerate_why);
    for (int i = 0; i < n; i++) {
        char name[256], ver[128] = "", cver[128] = "";
        cl_device_type type = 0;
        cl_uint cu = 0;
        cl_ulong mem = 0;
        full_name(plats[i], devs[i], name, sizeof name);
        clGetDeviceInfo(devs[i], CL_DEVICE_VERSION, sizeof ver, ver, NULL);
        clGetDeviceInfo(devs[i], CL_DEVICE_OPENCL_C_VERSION, sizeof cver, cver, NULL);
        clGetDeviceInfo(devs[i], CL_DEVICE_TYPE, sizeof type, &type, NULL);
        clGetDeviceInfo(devs[i], CL_DEVICE_MAX_COMPUTE_UNITS, sizeof cu, &cu, NULL);
        clGetDeviceInfo(devs[i], CL_DEVICE_GLOBAL_MEM_SIZE, sizeof mem, &mem, NULL);
        fprintf(out, "%d: %s\n   %s, %s, %s, %u compute units, %.1f GiB\n", i, name,
                type & CL_DEVICE_TYPE_GPU   ? "GPU"
                : type & CL_DEVICE_TYPE_CPU ? "CPU"
                                            : "accelerator",
                ver, cver, cu, (double)mem / (1024.0 * 1024.0 * 1024.0));
    }
    return n;
}

static int contains_nocase(const char *hay, const char *needle)
{
    size_t n = strlen(needle);
    for (; *hay; hay++) {
        size_t k = 0;
        while (k < n && hay[k] &&
               tolower((unsigned char)hay[k]) == tolower((unsigned char)needle[k]))
            k++;
        if (k == n) return 1;
    }
    return n == 0;
}

/* Whether device i (platform plat) matches item by its platform's name (pass 0) or by its
 * own name or version (pass 1: PoCL says "PoCL" only in its version). */
static int device_matches(cl_platform_id plat, cl_device_id dev, const char *item, int pass)
{
    char text[512] = "";
    if (pass == 0) {
        clGetPlatformInfo(plat, CL_PLATFORM_NAME, sizeof text, text, NULL);
        return contains_nocase(text, item);
    }
    clGetDeviceInfo(dev, CL_DEVICE_NAME, sizeof text, text, NULL);
    if (contains_nocase(text, item)) return 1;
    clGetDeviceInfo(dev, CL_DEVICE_VERSION, sizeof text, text, NULL);
    return contains_nocase(text, item);
}

/* The device one item of a --device list names: an index, or among the devices not picked
 * yet (picks[0 .. count - 1]) the first whose platform's name contains it, else the first
 * whose own name or version does; so "pocl,intel" names PoCL and Intel's runtime even on an
 * Intel CPU, whose name PoCL's device carries. Returns the index, or -1 after a message
 * in err. */
static int device_pick(const char *label, const char *spec, const char *item, cl_platform_id *plats,
                       cl_device_id *devs, int n, const int *picks, int count, char *err,
                       size_t errlen)
{
    char *end;
    long idx = strtol(item, &end, 10);
    if (*end == 0 && end != item) {
        if (idx >= 0 && idx < n) return (int)idx;
        snprintf(err, errlen, "%s%s: no such device %s (there are %d; see --list-devices)", label,
                 spec, item, n);
        return -1;
    }
    int named = -1; /* a matching device already picked */
    for (int pass = 0; pass < 2; pass++)
        for (int i = 0; i < n; i++) {
            if (!device_matches(plats[i], devs[i], item, pass)) continue;
            int taken = 0;
            for (int k = 0; k < count; k++) taken |= picks[k] == i;
            if (!taken) return i;
            named = i;
        }
    if (named >= 0)
        snprintf(err, errlen, "%s%s: device %d is named twice", label, spec, named);
    else
        snprintf(err, errlen, "%s%s: no device name contains \"%s\" (see --list-devices)", label,
                 spec, item);
    return -1;
}

int clu_device_pick(const char *spec, int *picks, int max, char *err, size_t errlen)
{
    cl_platform_id plats[64];
    cl_device_id devs[64];
    int n = enumerate(plats, devs, 64), count = 0;
    if (n == 0) {
        snprintf(err, errlen, "%s", enumerate_why);
        return -1;
    }
    /* the list given, named as the user gave it: the option, else the variable */
    const char *label = "--device ";
    if (!spec) {
        spec = getenv("VBCL_DEVICE");
        label = "VBCL_DEVICE=";
    }
    if (!spec || !*spec) spec = "0";
    if (!strcmp(spec, "all")) {
        for (int i = 0; i < n && i < max; i++) picks[count++] = i;
        return count;
    }
    char item[256];
    for (const char *p = spec;; p++) {
        size_t len = strcspn(p, ",");
        if (len == 0 || len >= sizeof item) {
            snprintf(err, errlen, "%s%s: expected all, or indices and names separated by commas",
                     label, spec);
            return -2;
        }
        memcpy(item, p, len);
        item[len] = 0;
        int pick = device_pick(label, spec, item, plats, devs, n, picks, count, err, errlen);
        if (pick < 0) return -2;
        for (int k = 0; k < count; k++)
            if (picks[k] == pick) {
                snprintf(err, errlen, "%s%s: device %d is named twice", label, spec, pick);
                return -2;
            }
        if (count == max) {
            snprintf(err, errlen, "%s%s: at most %d devices", label, spec, max);
            return -2;
        }
        picks[count++] = pick;
        p += len;
        if (!*p) return count;
    }
}

int clu_device_open_index(int index, VbDevice *d, char *err, size_t errlen)
{
    cl_platform_id plats[64];
    cl_device_id devs[64];
    memset(d, 0, sizeof *d);
    int n = enumerate(plats, devs, 64);
    if (index < 0 || index >= n) {
        snprintf(err, errlen, "OpenCL device %d is gone (there are %d)", index, n);
        return 1;
    }
    d->index = index;
    d->platform = plats[index];
    d->device = devs[index];
    full_name(d->platform, d->device, d->name, sizeof d->name);
    clGetDeviceInfo(d->device, CL_DEVICE_VERSION, sizeof d->version, d->version, NULL);
    clGetDeviceInfo(d->device, CL_DRIVER_VERSION, sizeof d->driver, d->driver, NULL);
    clGetDeviceInfo(d->device, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof d->global_mem, &d->global_mem,
                    NULL);
    clGetDeviceInfo(d->device, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof d->max_alloc, &d->max_alloc,
                    NULL);
    clGetDeviceInfo(d->device, CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof d->max_wg, &d->max_wg, NULL);
    cl_device_type type = 0;
    cl_uint align_bits = 0;
    clGetDeviceInfo(d->device, CL_DEVICE_TYPE, sizeof type, &type, NULL);
    clGetDeviceInfo(d->device, CL_DEVICE_MEM_BASE_ADDR_ALIGN, sizeof align_bits, &align_bits, NULL);
    d->host_memory = (type & CL_DEVICE_TYPE_CPU) != 0;
    d->host_align = align_bits / 8 > 128 ? align_bits / 8 : 128;
    cl_int rc;
    cl_context_properties props[] = {CL_CONTEXT_PLATFORM, (cl_context_properties)d->platform, 0};
    d->context = clCreateContext(props, 1, &d->device, NULL, NULL, &rc);
    CL_CHECK_ERR(rc, "clCreateContext", fail);
    d->queue = clCreateCommandQueue(d->context, d->device, CL_QUEUE_PROFILING_ENABLE, &rc);
    CL_CHECK_ERR(rc, "clCreateCommandQueue", fail_context);
    return 0;
fail_context:
    clReleaseContext(d->context);
    d->context = NULL;
fail:
    snprintf(err, errlen, "%s: %s", d->name, clu_error());
    return 1;
}

int clu_device_open(const char *spec, VbDevice *d, char *err, size_t errlen)
{
    int pick;
    int n = clu_device_pick(spec, &pick, 1, err, errlen);
    if (n == -1) return 1;
    if (n < 0) return 2;
    return clu_device_open_index(pick, d, err, errlen);
}

int clu_devices_open(const char *spec, VbDevice *devs, int max, int *ndev, char *err, size_t errlen)
{
    int picks[CLU_MAX_DEVICES];
    *ndev = 0;
    int n =
        clu_device_pick(spec, picks, max < CLU_MAX_DEVICES ? max : CLU_MAX_DEVICES, err, errlen);
    if (n == -1) return 1;
    if (n < 0) return 2;
    for (int i = 0; i < n; i++) {
        int rc = clu_device_open_index(picks[i], &devs[i], err, errlen);
        if (rc) {
            clu_devices_close(devs, i);
            return rc;
        }
    }
    *ndev = n;
    return 0;
}

void clu_devices_close(VbDevice *devs, int n)
{
    for (int i = 0; i < n; i++) clu_device_close(&devs[i]);
}

void clu_device_close(VbDevice *d)
{
    for (int i = 0; i < d->nkept; i++) CL_WARN(clReleaseProgram(d->kept[i].program));
    d->nkept = 0;
    if (d->queue) CL_WARN(clReleaseCommandQueue(d->queue));
    if (d->context) CL_WARN(clReleaseContext(d->context));
    d->queue = NULL;
    d->context = NULL;
}

static unsigned char *read_all(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    unsigned char *buf = NULL;
    if (fseek(f, 0, SEEK_END) == 0) {
        long n = ftell(f);
        if (n > 0 && n < (1L << 30) && fseek(f, 0, SEEK_SET) == 0 && (buf = malloc((size_t)n))) {
            if (fread(buf, 1, (size_t)n, f) != (size_t)n) {
                free(buf);
                buf = NULL;
            } else {
                *len = (size_t)n;
            }
        }
    }
    fclose(f);
    return buf;
}

/* A cached binary: this header, then the driver's bytes. The length and the hash of the
 * bytes let a truncated or damaged file be told from a good one before the driver sees it
 * (a driver may crash on a damaged binary instead of refusing it). */
typedef struct BinaryHeader {
    char magic[8]; /* BINARY_MAGIC */
    uint64_t bytes;
    uint64_t hash; /* FNV-1a of the bytes */
} BinaryHeader;
#define BINARY_MAGIC "vbclbin1"

static uint64_t bytes_hash(const unsigned char *p, size_t n)
{
    uint64_t h = CACHE_HASH_SEED;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

/* Stores the program's binary under path with its header, written whole (temporary file
 * + rename). */
static void cache_store(cl_program prog, const char *path)
{
    size_t size = 0;
    if (clGetProgramInfo(prog, CL_PROGRAM_BINARY_SIZES, sizeof size, &size, NULL) || !size) return;
    unsigned char *buf = malloc(sizeof(BinaryHeader) + size);
    if (!buf) return;
    unsigned char *bins[1] = {buf + sizeof(BinaryHeader)};
    if (clGetProgramInfo(prog, CL_PROGRAM_BINARIES, sizeof bins, bins, NULL) == CL_SUCCESS) {
        BinaryHeader h;
        memset(&h, 0, sizeof h);
        memcpy(h.magic, BINARY_MAGIC, sizeof h.magic);
        h.bytes = size;
        h.hash = bytes_hash(bins[0], size);
        memcpy(buf, &h, sizeof h);
        char err[256]; /* a cache that cannot be written is only slower next time */
        file_write_whole(path, buf, sizeof h + size, err, sizeof err);
    }
    free(buf);
}

/* The driver's bytes of a cached binary file of len bytes, or NULL when its header, length
 * or hash is wrong (*n: their count). */
static const unsigned char *cache_payload(const unsigned char *file, size_t len, size_t *n)
{
    BinaryHeader h;
    if (len <= sizeof h) return NULL;
    memcpy(&h, file, sizeof h);
    if (memcmp(h.magic, BINARY_MAGIC, sizeof h.magic) || h.bytes != len - sizeof h ||
        bytes_hash(file + sizeof h, len - sizeof h) != h.hash)
        return NULL;
    *n = len - sizeof h;
    return file + sizeof h;
}

static void print_build_log(VbDevice *d, cl_program prog, const char *options)
{
    size_t n = 0;
    clGetProgramBuildInfo(prog, d->device, CL_PROGRAM_BUILD_LOG, 0, NULL, &n);
    char *log = malloc(n + 1);
    if (log) {
        log[0] = 0;
        clGetProgramBuildInfo(prog, d->device, CL_PROGRAM_BUILD_LOG, n, log, NULL);
        log[n] = 0;
        fprintf(stderr, "vbcl: kernel build failed on %s\nbuild options: %s\nbuild log:\n%s\n",
                d->name, options, log);
        free(log);
    }
}

static int driver_is_pocl(const VbDevice *d)
{
    char name[256] = "";
    clGetPlatformInfo(d->platform, CL_PLATFORM_NAME, sizeof name, name, NULL);
    return strstr(name, "Portable Computing Language") != NULL;
}

/* Whether PoCL's kernel cache (POCL_CACHE_DIR, else XDG_CACHE_HOME/pocl, else
 * HOME/.cache/pocl), where it writes every kernel it builds, takes a file of 64 KiB (written
 * as vbcl writes any file, file_write_whole, then removed): if not, why, into why (a full
 * disk, a path through a file). Returns 1 where it does not. */
static int pocl_cache_unwritable(char *why, size_t n)
{
    char dir[1024], path[1100], err[1400];
    const char *env = getenv("POCL_CACHE_DIR"), *xdg = getenv("XDG_CACHE_HOME");
    const char *home = getenv("HOME");
    if (env && *env)
        snprintf(dir, sizeof dir, "%s", env);
    else if (xdg && *xdg)
        snprintf(dir, sizeof dir, "%s/pocl", xdg);
    else
        snprintf(dir, sizeof dir, "%s/.cache/pocl", home ? home : "");
    snprintf(path, sizeof path, "%s/.vbcl-probe-%ld", dir, (long)getpid());
    static const char block[65536];
    if (file_write_whole(path, block, sizeof block, err, sizeof err) == 0) {
        remove(path);
        return 0;
    }
    snprintf(why, n,
             "PoCL cannot write its kernel cache in %s (%s): free space there, or set "
             "POCL_CACHE_DIR to a writable directory",
             dir, err);
    return 1;
}

/* Whether d's driver keeps compiled kernels of its own between runs: PoCL does, in
 * POCL_CACHE_DIR, unless POCL_KERNEL_CACHE is 0. */
static int driver_caches_kernels(const VbDevice *d)
{
    const char *off = getenv("POCL_KERNEL_CACHE");
    return driver_is_pocl(d) && !(off && !strcmp(off, "0"));
}

/* Whether vbcl keeps d's program binaries itself: VBCL_CACHE_BINARIES 1 always, 0 never;
 * by default only where the driver keeps no kernels of its own. On PoCL, asking for a
 * program's binary compiles every kernel of the program once more, for the binary, which
 * costs a cold run far more than a build from source through PoCL's kernel cache costs a
 * warm one over loading the binary (docs/architecture.md, "Kernel programs"). */
static int binaries_wanted(const VbDevice *d)
{
    int set = cache_binaries_setting();
    return set >= 0 ? set : !driver_caches_kernels(d);
}

/* The key of source built with options on d: it names the binary and the stamp. */
static uint64_t program_key(const VbDevice *d, const char *source, const char *options)
{
    uint64_t h = CACHE_HASH_SEED;
    h = cache_hash(h, source);
    h = cache_hash(h, options);
    h = cache_hash(h, d->name);
    h = cache_hash(h, d->version);
    return cache_hash(h, d->driver);
}

/* The stamp of a program key: an empty file in the cache's programs/ folder, written once
 * the program and its kernels have been compiled on this device. Returns 0 or -1 (no cache
 * directory). */
static int stamp_path(uint64_t key, char *path, size_t n)
{
    char dir[4096];
    if (!cache_dir("programs", dir, sizeof dir)) return -1;
    snprintf(path, n, "%s/%016llx.built", dir, (unsigned long long)key);
    return 0;
}

/* Whether the stamp of key is there (renewed when it is). */
static int stamp_seen(uint64_t key)
{
    char path[4200];
    if (stamp_path(key, path, sizeof path)) return 0;
    if (access(path, F_OK) != 0) return 0;
    cache_touch(path);
    return 1;
}

int clu_program_seen(const VbDevice *d, const char *source, const char *options)
{
    return stamp_seen(program_key(d, source, options));
}

void clu_program_mark_seen(const VbDevice *d, const char *source, const char *options)
{
    char path[4200], err[256];
    if (stamp_path(program_key(d, source, options), path, sizeof path) == 0 &&
        access(path, F_OK) != 0)
        file_write_whole(path, "", 0, err, sizeof err); /* unwritten: a notice next time */
}

/* The program d keeps under key (a retained reference), or NULL. */
static cl_program kept_find(VbDevice *d, uint64_t key)
{
    for (int i = 0; i < d->nkept; i++)
        if (d->kept[i].key == key) {
            if (clRetainProgram(d->kept[i].program) != CL_SUCCESS) return NULL;
            return d->kept[i].program;
        }
    return NULL;
}

/* Keeps prog on d under key for later builds of the same program (the oldest goes first
 * when all CLU_KEPT_PROGRAMS places are taken). */
static void kept_add(VbDevice *d, uint64_t key, cl_program prog)
{
    if (clRetainProgram(prog) != CL_SUCCESS) return;
    if (d->nkept == CLU_KEPT_PROGRAMS) {
        CL_WARN(clReleaseProgram(d->kept[0].program));
        memmove(d->kept, d->kept + 1, sizeof d->kept[0] * (CLU_KEPT_PROGRAMS - 1));
        d->nkept--;
    }
    d->kept[d->nkept].key = key;
    d->kept[d->nkept++].program = prog;
}

const char *clu_build_how(int how)
{
    static const char *const text[] = {
        [CLU_BUILT] = "compiled from source: no earlier build of it in vbcl's cache",
        [CLU_BINARY] = "loaded from vbcl's binary cache",
        [CLU_BUILT_DRIVER_CACHE] = "built through the driver's kernel cache",
        [CLU_KEPT] = "kept from an earlier frame",
    };
    return text[how >= CLU_BUILT && how <= CLU_KEPT ? how : CLU_BUILT];
}

cl_program clu_program_build(VbDevice *d, const char *source, const char *options, double *ms,
                             int *cached)
{
    double t0 = clu_now_ms();
    cl_int rc;
    uint64_t key = program_key(d, source, options);
    cl_program prog = kept_find(d, key);
    if (prog) {
        *cached = CLU_KEPT;
        *ms = clu_now_ms() - t0;
        return prog;
    }
    int seen = stamp_seen(key);
    *cached = CLU_BUILT;
    char dir[4096], path[4200] = "";
    uint64_t cache_max = 0; /* read on every run, so that a bad value is always named */
    int binaries = binaries_wanted(d);
    if (!binaries && seen) *cached = CLU_BUILT_DRIVER_CACHE;
    if (binaries && cache_dir(NULL, dir, sizeof dir)) {
        cache_max = cache_max_bytes();
        snprintf(path, sizeof path, "%s/%016llx.bin", dir, (unsigned long long)key);
        size_t len = 0, n = 0;
        unsigned char *file = read_all(path, &len);
        const unsigned char *bin = file ? cache_payload(file, len, &n) : NULL;
        if (file && !bin) {
            fprintf(stderr, "vbcl: %s: a damaged cached kernel binary (%zu bytes); rebuilding it\n",
                    path, len);
            remove(path);
        }
        if (bin) {
            cl_int status;
            prog = clCreateProgramWithBinary(d->context, 1, &d->device, &n, &bin, &status, &rc);
            if (prog && rc == CL_SUCCESS && status == CL_SUCCESS &&
                clBuildProgram(prog, 1, &d->device, options, NULL, NULL) == CL_SUCCESS) {
                free(file);
                cache_touch(path); /* recently used: pruned last */
                kept_add(d, key, prog);
                *cached = CLU_BINARY;
                *ms = clu_now_ms() - t0;
                return prog;
            }
            if (prog) clReleaseProgram(prog);
            prog = NULL; /* a stale or foreign binary: build from source */
        }
        free(file);
    }
    prog = clCreateProgramWithSource(d->context, 1, &source, NULL, &rc);
    CL_CHECK_ERR(rc, "clCreateProgramWithSource", fail);
    rc = clBuildProgram(prog, 1, &d->device, options, NULL, NULL);
    if (rc != CL_SUCCESS) {
        char why[1400];
        if (driver_caches_kernels(d) && pocl_cache_unwritable(why, sizeof why)) {
            if (!first_error[0]) snprintf(first_error, sizeof first_error, "%s", why);
        } else {
            print_build_log(d, prog, options);
            clu_fail(rc, "clBuildProgram", __FILE__, __LINE__);
        }
        goto fail_program;
    }
    if (path[0]) { /* then the least recently used binaries go, beyond the cache's size */
        cache_store(prog, path);
        cache_prune(dir, ".bin", cache_max, path);
    }
    kept_add(d, key, prog);
    *ms = clu_now_ms() - t0;
    return prog;
fail_program:
    clReleaseProgram(prog);
fail:
    return NULL;
}

static void CL_CALLBACK free_host_memory(cl_mem m, void *mem)
{
    (void)m;
    free(mem);
}

/* A buffer in memory vbcl allocates (d->host_memory): the driver uses it as it is
 * (CL_MEM_USE_HOST_PTR) and frees nothing of it; the destructor callback frees it when the
 * buffer goes. NULL, with the error recorded, where the allocation fails. */
static cl_mem host_buffer(VbDevice *d, const void *data, size_t bytes, cl_mem_flags flags)
{
    void *mem = NULL;
    if (posix_memalign(&mem, d->host_align, bytes)) {
        if (!first_error[0]) {
            snprintf(first_error, sizeof first_error, "out of memory allocating %.1f MiB",
                     (double)bytes / 1048576.0);
            first_error_oom = 1;
        }
        return NULL;
    }
    if (data) memcpy(mem, data, bytes);
    cl_int rc;
    cl_mem m = clCreateBuffer(d->context, flags | CL_MEM_USE_HOST_PTR, bytes, mem, &rc);
    if (rc != CL_SUCCESS) {
        clu_fail(rc, "clCreateBuffer", __FILE__, __LINE__);
        free(mem);
        return NULL;
    }
    rc = clSetMemObjectDestructorCallback(m, free_host_memory, mem);
    if (rc == CL_SUCCESS) return m;
    clu_fail(rc, "clSetMemObjectDestructorCallback", __FILE__, __LINE__);
    clReleaseMemObject(m);
    free(mem);
    return NULL;
}

cl_mem clu_buffer(VbDevice *d, const void *data, size_t bytes, cl_mem_flags flags)
{
    cl_int rc;
    /* zero-sized buffers are invalid: keep at least 16 bytes */
    static const char zeros[16];
    if (bytes == 0) {
        bytes = sizeof zeros;
        data = zeros;
    }
    if (d->host_memory) return host_buffer(d, data, bytes, flags);
    cl_mem m = clCreateBuffer(d->context, flags | (data ? CL_MEM_COPY_HOST_PTR : 0), bytes,
                              (void *)data, &rc);
    if (rc != CL_SUCCESS) {
        clu_fail(rc, "clCreateBuffer", __FILE__, __LINE__);
        return NULL;
    }
    return m;
}

int clu_set_arg(cl_kernel k, cl_uint i, size_t size, const void *val)
{
    cl_int rc = clSetKernelArg(k, i, size, val);
    if (rc == CL_SUCCESS) return 0;
    char what[64];
    snprintf(what, sizeof what, "clSetKernelArg(argument %u)", i);
    return clu_fail(rc, what, __FILE__, __LINE__);
}
