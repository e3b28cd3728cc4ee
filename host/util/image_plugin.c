/* image_plugin.c — image_write and image_read of the vbcl binary, by OpenImageIO loaded
 * as a plugin. Debian's OpenImageIO brings some 260 shared libraries, whose symbols the
 * dynamic loader resolves in about 0.2 s (docs/benchmarks.md, "What every render pays
 * before its first ray"); linked into vbcl, every run paid that before main, `--help`
 * included. Instead image_io.cpp is built into a shared object embedded in the binary
 * (vbcl_image_plugin, Makefile). image_preload loads it on a thread of its own while the
 * program builds its kernels and renders, and the first image_write or image_read waits
 * for it. main starts it once the devices are open: the dynamic loader loads one library
 * at a time, so starting earlier would hold up the OpenCL driver's own loading. The
 * binary stays one file: the plugin is loaded from an anonymous memory file
 * (memfd_create), or from an unlinked temporary file where there is none. */
#include "image_io.h"

#include <dlfcn.h>
#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

/* The plugin's bytes (image_plugin_blob.o, which the Makefile makes). */
extern const unsigned char vbcl_image_plugin[], vbcl_image_plugin_end[];

typedef int (*WriteFn)(const char *, int, int, const float *, float, char *, size_t);
typedef int (*ReadFn)(const char *, int *, int *, float **, char *, size_t);

static pthread_mutex_t plugin_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t plugin_loaded = PTHREAD_COND_INITIALIZER;
static struct {
    int state; /* PLUGIN_NONE, _LOADING (on the preload thread) or _DONE (tried) */
    WriteFn write;
    ReadFn read;
    char err[512]; /* why it failed */
} plugin;
enum { PLUGIN_NONE = 0, PLUGIN_LOADING = 1, PLUGIN_DONE = 2 };

/* Writes the plugin to a new file: an anonymous memory file, else one in TMPDIR (or
 * /tmp) already unlinked, and returns its descriptor, or -1 with a message in plugin.err. */
static int plugin_file(void)
{
    int fd = -1;
#ifdef MFD_CLOEXEC
    fd = memfd_create("vbcl-image", MFD_CLOEXEC);
#endif
    if (fd < 0) {
        const char *dir = getenv("TMPDIR");
        if (!dir || !*dir) dir = "/tmp";
        char path[4096];
        snprintf(path, sizeof path, "%s/vbcl-image-XXXXXX", dir);
        fd = mkstemp(path);
        if (fd < 0) {
            snprintf(plugin.err, sizeof plugin.err, "cannot make a file for it in %s: %s", dir,
                     strerror(errno));
            return -1;
        }
        unlink(path);
    }
    const unsigned char *p = vbcl_image_plugin;
    while (p < vbcl_image_plugin_end) {
        ssize_t k = write(fd, p, (size_t)(vbcl_image_plugin_end - p));
        if (k <= 0) {
            snprintf(plugin.err, sizeof plugin.err, "cannot write it: %s", strerror(errno));
            close(fd);
            return -1;
        }
        p += k;
    }
    return fd;
}

/* Loads the plugin and finds its two functions; on failure says why in plugin.err. */
static void plugin_load(void)
{
    int fd = plugin_file();
    if (fd < 0) return;
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    close(fd);
    if (!h) {
        snprintf(plugin.err, sizeof plugin.err, "%s", dlerror());
        return;
    }
    plugin.write = (WriteFn)dlsym(h, "image_write");
    plugin.read = (ReadFn)dlsym(h, "image_read");
    if (!plugin.write || !plugin.read) {
        snprintf(plugin.err, sizeof plugin.err, "its functions are missing");
        plugin.write = NULL;
        plugin.read = NULL;
    }
}

/* The preload thread (detached): loads the plugin and wakes whoever waits for it. */
static void *plugin_thread(void *arg)
{
    (void)arg;
    plugin_load();
    pthread_mutex_lock(&plugin_lock);
    plugin.state = PLUGIN_DONE;
    pthread_cond_broadcast(&plugin_loaded);
    pthread_mutex_unlock(&plugin_lock);
    return NULL;
}

void image_preload(void)
{
    pthread_mutex_lock(&plugin_lock);
    if (plugin.state == PLUGIN_NONE) {
        pthread_t t;
        if (pthread_create(&t, NULL, plugin_thread, NULL) == 0) {
            pthread_detach(t);
            plugin.state = PLUGIN_LOADING;
        }
    }
    pthread_mutex_unlock(&plugin_lock);
}

void image_preload_wait(void)
{
    pthread_mutex_lock(&plugin_lock);
    while (plugin.state == PLUGIN_LOADING) pthread_cond_wait(&plugin_loaded, &plugin_lock);
    pthread_mutex_unlock(&plugin_lock);
}

/* Waits for the plugin (loading it here if image_preload did not start it); 0 when it
 * is there, else -1 with a message naming path in err. */
static int plugin_ready(const char *path, char *err, size_t errlen)
{
    pthread_mutex_lock(&plugin_lock);
    if (plugin.state == PLUGIN_NONE) {
        plugin_load();
        plugin.state = PLUGIN_DONE;
    }
    while (plugin.state != PLUGIN_DONE) pthread_cond_wait(&plugin_loaded, &plugin_lock);
    int ok = plugin.write != NULL;
    pthread_mutex_unlock(&plugin_lock);
    if (!ok)
        snprintf(err, errlen, "%s: cannot load vbcl's OpenImageIO plugin: %s", path, plugin.err);
    return ok ? 0 : -1;
}

int image_write(const char *path, int width, int height, const float *rgba, float exposure,
                char *err, size_t errlen)
{
    if (image_check_path(path, err, errlen)) return -1;
    if (image_is_native_format(path))
        return image_write_pfm(path, width, height, rgba, exposure, err, errlen);
    if (plugin_ready(path, err, errlen)) return -1;
    return plugin.write(path, width, height, rgba, exposure, err, errlen);
}

int image_read(const char *path, int *width, int *height, float **rgba, char *err, size_t errlen)
{
    if (plugin_ready(path, err, errlen)) return -1;
    return plugin.read(path, width, height, rgba, err, errlen);
}
