/* fileio.c — files written whole or not at all: a temporary file beside the target, every
 * write checked, flushed and synced, closed with its result checked, then renamed into
 * place; a failure or a fatal signal during the write removes the temporary. */
#include "fileio.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The temporaries being written now, for the signal handler: a slot is live while its
 * file exists under its name (writes from several threads each hold one). */
#define TEMP_SLOTS 16
static struct {
    char path[4200];
    volatile sig_atomic_t live;
} temps[TEMP_SLOTS];
static pthread_mutex_t temps_lock = PTHREAD_MUTEX_INITIALIZER;
static unsigned temps_serial; /* tells apart the temporaries of one process */

/* The signals that remove the temporaries, and the action each had before (a handler of
 * a library, such as LLVM's in an OpenCL compiler, or the default). */
static const int temps_sigs[] = {SIGINT, SIGTERM, SIGHUP};
static struct sigaction temps_old[3];

/* Removes the live temporaries, then gives the signal to the action it had before (which
 * kills the process for the default), once this handler returns (async-signal-safe:
 * unlink, sigaction, raise). */
static void temps_on_signal(int sig)
{
    for (int i = 0; i < TEMP_SLOTS; i++)
        if (temps[i].live) unlink(temps[i].path);
    for (int i = 0; i < 3; i++)
        if (temps_sigs[i] == sig) sigaction(sig, &temps_old[i], NULL);
    raise(sig);
}

/* Installs the handler once for each of the three signals that are not ignored (under
 * nohup SIGHUP stays ignored). Called with temps_lock held. */
static void temps_install(void)
{
    static int done;
    if (done) return;
    done = 1;
    for (int i = 0; i < 3; i++) {
        if (sigaction(temps_sigs[i], NULL, &temps_old[i]) ||
            (!(temps_old[i].sa_flags & SA_SIGINFO) && temps_old[i].sa_handler == SIG_IGN))
            continue;
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = temps_on_signal;
        sigemptyset(&sa.sa_mask);
        sigaction(temps_sigs[i], &sa, NULL);
    }
}

/* Takes a slot and names the temporary for path in it: ".NAME.tmpPID.N" beside path.
 * Returns the slot, or -1 with a message in err (path too long, or every slot taken). */
static int temp_begin(const char *path, char *err, size_t errlen)
{
    const char *slash = strrchr(path, '/');
    int dirlen = slash ? (int)(slash - path + 1) : 0;
    pthread_mutex_lock(&temps_lock);
    temps_install();
    int slot = -1;
    for (int i = 0; i < TEMP_SLOTS && slot < 0; i++)
        if (!temps[i].live) slot = i;
    if (slot >= 0) {
        int k = snprintf(temps[slot].path, sizeof temps[slot].path, "%.*s.%s.tmp%ld.%u", dirlen,
                         path, path + dirlen, (long)getpid(), temps_serial++);
        if (k < 0 || (size_t)k >= sizeof temps[slot].path) {
            snprintf(err, errlen, "%s: path too long", path);
            slot = -1;
        } else
            temps[slot].live = 1; /* before the file exists: a signal then unlinks nothing */
    } else
        snprintf(err, errlen, "%s: cannot write: too many files being written at once", path);
    pthread_mutex_unlock(&temps_lock);
    return slot;
}

/* Removes the slot's temporary (unless it was renamed: keep) and frees the slot. */
static void temp_end(int slot, int keep)
{
    if (!keep) unlink(temps[slot].path);
    pthread_mutex_lock(&temps_lock);
    temps[slot].live = 0;
    pthread_mutex_unlock(&temps_lock);
}

/* path's directory into dir ("." for a bare name); 0, or -1 when it does not fit. */
static int dir_of(const char *path, char *dir, size_t n)
{
    const char *slash = strrchr(path, '/');
    if (!slash) return snprintf(dir, n, ".") < 0 ? -1 : 0;
    if ((size_t)(slash - path) >= n) return -1;
    snprintf(dir, n, "%.*s", slash == path ? 1 : (int)(slash - path), path);
    return 0;
}

/* Makes the rename of a file in path's directory durable (best effort: some filesystems
 * cannot sync a directory). */
static void sync_dir(const char *path)
{
    char dir[4096];
    if (dir_of(path, dir, sizeof dir)) return;
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        fsync(fd);
        close(fd);
    }
}

/* What fills a temporary: write through a FILE (file_write_stream), or fill through its
 * descriptor (file_write_fd), with ctx. */
typedef struct Filler {
    void (*write)(FILE *f, const void *ctx);
    int (*fill)(int fd, void *ctx, char *err, size_t errlen);
    const void *ctx;
    void *fill_ctx;
} Filler;

/* Fills the temporary's descriptor fd as w says. Returns 0; an errno (the first error of
 * the writes and the flush of what is buffered); or -1 when the filler failed with its own
 * message in err. The descriptor stays open (*f, when one was made, holds it). */
static int fill_temp(int fd, FILE **f, const Filler *w, char *err, size_t errlen)
{
    if (w->fill) return w->fill(fd, w->fill_ctx, err, errlen) ? -1 : 0;
    if (!(*f = fdopen(fd, "wb"))) return errno ? errno : EIO;
    errno = 0;
    w->write(*f, w->ctx);
    if (ferror(*f)) return errno ? errno : EIO;
    return fflush(*f) != 0 ? (errno ? errno : EIO) : 0;
}

/* Writes path whole or not at all, its temporary filled as w says. */
static int write_temp(const char *path, const Filler *w, char *err, size_t errlen)
{
    int slot = temp_begin(path, err, errlen);
    if (slot < 0) return -1;
    const char *tmp = temps[slot].path;
    /* read and write: an encoder may read back what it wrote */
    int fd = open(tmp, O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno == EEXIST) { /* left by a killed process of the same id */
        unlink(tmp);
        fd = open(tmp, O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    }
    if (fd < 0) {
        int e = errno;
        temp_end(slot, 0);
        snprintf(err, errlen, "%s: cannot write: %s", path, strerror(e));
        return -1;
    }
    /* The first error wins: the filling (a short write, the flush of what is buffered),
     * the sync to the disk (where a full disk or quota may show only now), the close. */
    FILE *f = NULL;
    int saved = fill_temp(fd, &f, w, err, errlen);
    if (!saved && fsync(fd) != 0 && errno != EINVAL) saved = errno;
    if ((f ? fclose(f) : close(fd)) != 0 && !saved) saved = errno ? errno : EIO;
    if (!saved && rename(tmp, path) != 0) saved = errno;
    temp_end(slot, !saved);
    if (saved > 0) snprintf(err, errlen, "%s: cannot write: %s", path, strerror(saved));
    if (saved) return -1;
    sync_dir(path);
    return 0;
}

int file_write_stream(const char *path, void (*write)(FILE *f, const void *ctx), const void *ctx,
                      char *err, size_t errlen)
{
    Filler w = {write, NULL, ctx, NULL};
    return write_temp(path, &w, err, errlen);
}

int file_write_fd(const char *path, int (*fill)(int fd, void *ctx, char *err, size_t errlen),
                  void *ctx, char *err, size_t errlen)
{
    Filler w = {NULL, fill, NULL, ctx};
    return write_temp(path, &w, err, errlen);
}

/* The bytes of file_write_whole. */
typedef struct Bytes {
    const void *data;
    size_t n;
} Bytes;

static void write_bytes(FILE *f, const void *ctx)
{
    const Bytes *b = ctx;
    fwrite(b->data, 1, b->n, f);
}

int file_write_whole(const char *path, const void *data, size_t n, char *err, size_t errlen)
{
    Bytes b = {data, n};
    return file_write_stream(path, write_bytes, &b, err, errlen);
}

int file_check_dir(const char *path, char *err, size_t errlen)
{
    char dir[4096];
    if (dir_of(path, dir, sizeof dir)) {
        snprintf(err, errlen, "%s: path too long", path);
        return -1;
    }
    if (access(dir, W_OK | X_OK) != 0) {
        int e = errno;
        snprintf(err, errlen, "%s: cannot write there: %s%s", path, strerror(e),
                 e == ENOENT ? " (the directory does not exist)" : "");
        return -1;
    }
    return 0;
}
