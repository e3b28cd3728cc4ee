/* image_plugin.c — image_encode, image_read and image_read_radiance of the vbcl binary, by
 * OpenImageIO loaded as a plugin. Debian's OpenImageIO brings some 260 shared libraries,
 * whose symbols the dynamic loader resolves in about 0.4 s (docs/benchmarks.md, "What every render
 * pays before its first ray"); linked into vbcl, every run paid that before main, `--help`
 * included. Instead image_io.cpp is built into a shared object embedded in the binary
 * (vbcl_image_plugin, Makefile), loaded from an anonymous memory file (memfd_create), or
 * from an unlinked temporary file where there is none, so that the binary stays one file.
 *
 * A render that writes such an image has it encoded by a helper process: image_preload
 * starts vbcl again as `vbcl --image-helper` (image_helper_main), which loads the plugin
 * while this process opens its devices, builds its kernels and renders; image_encode sends
 * it the pixels with a copy of the descriptor of the file's temporary (SCM_RIGHTS), into
 * which the helper encodes the image, answering with the result and a message only. This
 * process made the temporary and syncs, renames or removes it (image_write.c, fileio.h), so
 * that the file's owner checks the write and no temporary outlives a failure. A helper that
 * dies, does not answer in time or is gone leaves the image to this process, which empties
 * the temporary and encodes into it itself.
 * Loaded on a thread of this process instead, the plugin held up the kernels' build from
 * source for as long as it loaded (the dynamic loader serves one thread at a time:
 * docs/benchmarks.md, "OpenImageIO in a process of its own"). Where the helper cannot
 * start, with VBCL_IMAGE_HELPER=0, and for the reads (textures, environments; before any
 * device is open), the plugin loads here, on a thread of its own (image_preload) or at the
 * first call. */
#include "image_io.h"

#include "diag.h"

#include <dlfcn.h>
#include <errno.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

/* The plugin's bytes (image_plugin_blob.o, which the Makefile makes). */
extern const unsigned char vbcl_image_plugin[], vbcl_image_plugin_end[];

typedef int (*EncodeFn)(const char *, int, int, int, const float *, float, char *, size_t);
typedef int (*ReadFn)(const char *, int *, int *, float **, char *, size_t);

static pthread_mutex_t plugin_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t plugin_loaded = PTHREAD_COND_INITIALIZER;
static struct {
    int state; /* PLUGIN_NONE, _LOADING (on the preload thread) or _DONE (tried) */
    EncodeFn encode;
    ReadFn read, read_radiance;
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

/* Loads the plugin and finds its three functions; on failure says why in plugin.err. */
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
    plugin.encode = (EncodeFn)dlsym(h, "image_encode");
    plugin.read = (ReadFn)dlsym(h, "image_read");
    plugin.read_radiance = (ReadFn)dlsym(h, "image_read_radiance");
    if (!plugin.encode || !plugin.read || !plugin.read_radiance) {
        snprintf(plugin.err, sizeof plugin.err, "its functions are missing");
        plugin.encode = NULL;
        plugin.read = NULL;
        plugin.read_radiance = NULL;
    }
}

/* Why the plugin is not there, for an image at path, in err; returns -1. */
static int plugin_missing(const char *path, char *err, size_t errlen)
{
    snprintf(err, errlen, "%s: cannot load vbcl's OpenImageIO plugin: %s", path, plugin.err);
    return -1;
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

/* The plugin loaded on a thread of this process (the helper's fallback). */
static void preload_thread(void)
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

/* The helper process: its pid and this end of the socket to it (-1: none). */
#define HELPER_FD    63 /* the socket's descriptor in the helper */
#define HELPER_MAGIC 0x76626932u
static pthread_mutex_t helper_lock = PTHREAD_MUTEX_INITIALIZER;
static struct {
    pid_t pid;
    int fd;
    int tried; /* helper_start was called: one helper a run */
    int stuck; /* it did not answer within helper_timeout_ms */
} helper = {0, -1, 0, 0};

/* An encoding request: the header, with the descriptor of the file to encode into attached
 * to its bytes (SCM_RIGHTS), then path_len bytes of path (whose extension names the
 * format), then width * height * 4 floats. The reply: rc (0 or -1), then err_len bytes of
 * message; the image is in the file. */
typedef struct {
    uint32_t magic;
    int32_t width, height;
    float exposure;
    uint32_t path_len;
} HelperRequest;
typedef struct {
    int32_t rc;
    uint32_t err_len;
} HelperReply;

/* The control message that carries one descriptor, and room for it. */
typedef union {
    char buf[CMSG_SPACE(sizeof(int))];
    struct cmsghdr align;
} FdControl;

/* Sends or receives up to n bytes at p in one call (send or recv's result). pass, where not
 * NULL, is a descriptor: sending, a copy of *pass goes with the bytes (SCM_RIGHTS) unless it
 * is -1, and is -1 once sent; receiving, one that came with them lands there
 * (close-on-exec). */
static ssize_t sock_move(int fd, char *p, size_t n, int sending, int flags, int *pass)
{
    FdControl ctl;
    memset(&ctl, 0, sizeof ctl);
    struct iovec iov = {p, n};
    struct msghdr m = {.msg_iov = &iov, .msg_iovlen = 1};
    if (pass && (!sending || *pass >= 0)) {
        m.msg_control = ctl.buf;
        m.msg_controllen = sizeof ctl.buf;
    }
    if (sending && m.msg_control) {
        struct cmsghdr *c = CMSG_FIRSTHDR(&m);
        c->cmsg_level = SOL_SOCKET;
        c->cmsg_type = SCM_RIGHTS;
        c->cmsg_len = CMSG_LEN(sizeof(int));
        memcpy(CMSG_DATA(c), pass, sizeof(int));
    }
    ssize_t k =
        sending ? sendmsg(fd, &m, MSG_NOSIGNAL | flags) : recvmsg(fd, &m, MSG_CMSG_CLOEXEC | flags);
    if (k > 0 && sending && m.msg_control) *pass = -1;
    for (struct cmsghdr *c = !sending && k > 0 && m.msg_control ? CMSG_FIRSTHDR(&m) : NULL; c;
         c = CMSG_NXTHDR(&m, c)) {
        int got;
        if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SCM_RIGHTS ||
            c->cmsg_len != CMSG_LEN(sizeof(int)))
            continue;
        memcpy(&got, CMSG_DATA(c), sizeof got);
        if (*pass < 0)
            *pass = got;
        else
            close(got); /* one descriptor a request */
    }
    return k;
}

/* Sends or receives all n bytes, waiting at most timeout_ms (-1: forever) for each part to
 * move; 0, -1 on an error or the other end gone, or -3 when the wait ran out. pass: a
 * descriptor that goes with the bytes, or NULL (sock_move; receiving, *pass is -1 at the
 * start, and the caller closes what came, whatever the result). */
static int sock_all_within(int fd, void *buf, size_t n, int sending, int timeout_ms, int *pass)
{
    char *p = buf;
    while (n > 0) {
        struct pollfd pf = {fd, (short)(sending ? POLLOUT : POLLIN), 0};
        int ready = timeout_ms < 0 ? 1 : poll(&pf, 1, timeout_ms);
        if (ready < 0 && errno == EINTR) continue;
        if (ready == 0) return -3;
        if (ready < 0) return -1;
        /* with a bound, never block in the call: it moves what fits and poll waits again */
        ssize_t k = sock_move(fd, p, n, sending, timeout_ms < 0 ? 0 : MSG_DONTWAIT, pass);
        if (k < 0 && (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK)) continue;
        if (k <= 0) return -1;
        p += k;
        n -= (size_t)k;
    }
    return 0;
}

static int sock_all(int fd, void *buf, size_t n, int sending)
{
    return sock_all_within(fd, buf, n, sending, -1, NULL);
}

/* How long vbcl waits for the helper to take or give the next bytes before it ends it and
 * encodes the image itself: $VBCL_IMAGE_HELPER_TIMEOUT seconds, default 120. */
static int helper_timeout_ms(void)
{
    const char *env = getenv("VBCL_IMAGE_HELPER_TIMEOUT");
    char *end;
    long s = env ? strtol(env, &end, 10) : 0;
    return env && *env && !*end && s > 0 && s < 86400 ? (int)s * 1000 : 120000;
}

/* Ends the helper: closing the socket tells it to exit; then it is reaped. One that did not
 * answer in time (stopped, or stuck) is killed first, so that nothing waits for it. */
static void helper_stop(void)
{
    pthread_mutex_lock(&helper_lock);
    if (helper.fd >= 0) {
        close(helper.fd);
        helper.fd = -1;
        if (helper.stuck) kill(helper.pid, SIGKILL);
        while (waitpid(helper.pid, NULL, 0) < 0 && errno == EINTR) {
        }
    }
    pthread_mutex_unlock(&helper_lock);
}

/* Starts `vbcl --image-helper` with one end of a socket pair as its HELPER_FD; 0, or -1
 * when it cannot (no /proc/self/exe, no process, VBCL_IMAGE_HELPER=0). */
static int helper_start(void)
{
    const char *env = getenv("VBCL_IMAGE_HELPER");
    if (env && !strcmp(env, "0")) return -1;
    struct rlimit nofile; /* the helper's socket is descriptor HELPER_FD: it must be allowed */
    if (getrlimit(RLIMIT_NOFILE, &nofile) == 0 && nofile.rlim_cur <= HELPER_FD) return -1;
    int sv[2];
    if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv)) return -1;
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, sv[1], HELPER_FD); /* the copy keeps no CLOEXEC */
    char arg0[] = "vbcl", arg1[] = "--image-helper";
    char *argv[] = {arg0, arg1, NULL};
    pid_t pid;
    int rc = posix_spawn(&pid, "/proc/self/exe", &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    close(sv[1]);
    if (rc) {
        close(sv[0]);
        return -1;
    }
    helper.pid = pid;
    helper.fd = sv[0];
    atexit(helper_stop);
    return 0;
}

void image_preload(int thread)
{
    pthread_mutex_lock(&helper_lock);
    int started = helper.fd >= 0 || (!helper.tried && helper_start() == 0);
    helper.tried = 1;
    pthread_mutex_unlock(&helper_lock);
    if (!started && thread) preload_thread();
}

/* image_encode through the helper: 0, -1 with its message, or -2 when there is no helper
 * or it is gone (then the caller encodes here, the helper ended: it writes no more). */
static int helper_encode(const char *path, int file, int width, int height, const float *rgba,
                         float exposure, char *err, size_t errlen)
{
    pthread_mutex_lock(&helper_lock);
    int rc = -2, t = helper_timeout_ms(), s = -1;
    size_t plen = strlen(path), bytes = sizeof(float) * 4 * (size_t)width * (size_t)height;
    HelperRequest q = {HELPER_MAGIC, width, height, exposure, (uint32_t)plen};
    HelperReply a;
    char msg[4096];
    int pass = file; /* the copy of the file's descriptor that goes with the request */
    if (helper.fd >= 0 && !(s = sock_all_within(helper.fd, &q, sizeof q, 1, t, &pass)) &&
        !(s = sock_all_within(helper.fd, (void *)path, plen, 1, t, NULL)) &&
        !(s = sock_all_within(helper.fd, (void *)rgba, bytes, 1, t, NULL)) &&
        !(s = sock_all_within(helper.fd, &a, sizeof a, 0, t, NULL)) && a.err_len < sizeof msg &&
        !(s = sock_all_within(helper.fd, msg, a.err_len, 0, t, NULL))) {
        msg[a.err_len] = 0;
        if (a.rc) snprintf(err, errlen, "%s", msg);
        rc = a.rc ? -1 : 0;
    }
    if (s == -3) {
        helper.stuck = 1;
        diag_print("vbcl",
                   "the image helper (pid %ld) did not answer in %d s: it is ended, and vbcl "
                   "encodes %s itself",
                   (long)helper.pid, t / 1000, path);
    }
    int end = rc == -2 || helper.stuck;
    pthread_mutex_unlock(&helper_lock);
    if (end) helper_stop(); /* gone or stuck: not asked again */
    return rc;
}

/* `vbcl --image-helper`: loads the plugin, then encodes each image the socket on
 * HELPER_FD asks for into the file whose descriptor came with the request, and answers
 * with image_encode's result and message, until the socket closes. It neither syncs nor
 * renames the file: vbcl does (image_write.c). */
int image_helper_main(void)
{
    HelperRequest q;
    struct stat st;
    if (fstat(HELPER_FD, &st) || !S_ISSOCK(st.st_mode)) {
        fprintf(stderr, "vbcl: --image-helper is vbcl's own helper, not an option\n");
        return 2;
    }
    /* A file-size limit (ulimit -f) must fail the write with EFBIG, which the message
     * names, not kill the helper mid-write (main ignores it too; an ignored signal stays
     * ignored across the exec that started the helper). */
    signal(SIGXFSZ, SIG_IGN);
    plugin_load();
    for (;;) {
        int file = -1;
        if (sock_all_within(HELPER_FD, &q, sizeof q, 0, -1, &file)) {
            if (file >= 0) close(file);
            return 0; /* vbcl closed the socket: done */
        }
        if (file < 0 || q.magic != HELPER_MAGIC || q.width <= 0 || q.height <= 0 ||
            q.path_len == 0 || q.path_len > 4095 ||
            (size_t)q.width > SIZE_MAX / 16 / (size_t)q.height) {
            if (file >= 0) close(file);
            return 1;
        }
        char path[4096], err[1024] = "";
        size_t bytes = sizeof(float) * 4 * (size_t)q.width * (size_t)q.height;
        float *rgba = malloc(bytes);
        if (!rgba || sock_all(HELPER_FD, path, q.path_len, 0) ||
            sock_all(HELPER_FD, rgba, bytes, 0)) {
            free(rgba);
            close(file);
            return 1;
        }
        path[q.path_len] = 0;
        int rc = plugin.encode ? plugin.encode(path, file, q.width, q.height, rgba, q.exposure, err,
                                               sizeof err)
                               : plugin_missing(path, err, sizeof err);
        free(rgba);
        close(file);
        HelperReply a = {rc ? -1 : 0, rc ? (uint32_t)strlen(err) : 0u};
        if (sock_all(HELPER_FD, &a, sizeof a, 1) || sock_all(HELPER_FD, err, a.err_len, 1))
            return 1;
    }
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
    int ok = plugin.encode != NULL;
    pthread_mutex_unlock(&plugin_lock);
    return ok ? 0 : plugin_missing(path, err, errlen);
}

int image_encode(const char *path, int fd, int width, int height, const float *rgba, float exposure,
                 char *err, size_t errlen)
{
    pthread_mutex_lock(&plugin_lock);
    int here = plugin.state != PLUGIN_NONE; /* loaded, or loading, in this process */
    pthread_mutex_unlock(&plugin_lock);
    if (!here) {
        int rc = helper_encode(path, fd, width, height, rgba, exposure, err, errlen);
        if (rc != -2) return rc;
        /* whatever a helper wrote before it died or was ended goes: the file starts empty */
        if (ftruncate(fd, 0) != 0) {
            snprintf(err, errlen, "%s: cannot write: %s", path, strerror(errno));
            return -1;
        }
    }
    if (plugin_ready(path, err, errlen)) return -1;
    return plugin.encode(path, fd, width, height, rgba, exposure, err, errlen);
}

int image_read(const char *path, int *width, int *height, float **rgba, char *err, size_t errlen)
{
    if (plugin_ready(path, err, errlen)) return -1;
    return plugin.read(path, width, height, rgba, err, errlen);
}

int image_read_radiance(const char *path, int *width, int *height, float **rgba, char *err,
                        size_t errlen)
{
    if (plugin_ready(path, err, errlen)) return -1;
    return plugin.read_radiance(path, width, height, rgba, err, errlen);
}
