/* fileio.c — files written whole or not at all (temporary file + rename). */
#include "fileio.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The temporary name for path: ".NAME.tmpPID" beside it. Returns 0, or -1 if too long. */
static int temp_name(const char *path, char *tmp, size_t n)
{
    const char *slash = strrchr(path, '/');
    int dirlen = slash ? (int)(slash - path + 1) : 0;
    int k = snprintf(tmp, n, "%.*s.%s.tmp%ld", dirlen, path, path + dirlen, (long)getpid());
    return k < 0 || (size_t)k >= n ? -1 : 0;
}

int file_write_stream(const char *path, void (*write)(FILE *f, const void *ctx), const void *ctx,
                      char *err, size_t errlen)
{
    char tmp[4200];
    if (temp_name(path, tmp, sizeof tmp)) {
        snprintf(err, errlen, "%s: path too long", path);
        return -1;
    }
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        snprintf(err, errlen, "%s: cannot write: %s", path, strerror(errno));
        return -1;
    }
    errno = 0;
    write(f, ctx);
    int ok = !ferror(f);
    int saved = errno;
    if (fclose(f) != 0 && ok) {
        ok = 0;
        saved = errno;
    }
    if (ok && rename(tmp, path) != 0) {
        ok = 0;
        saved = errno;
    }
    if (!ok) {
        snprintf(err, errlen, "%s: cannot write: %s", path, strerror(saved ? saved : EIO));
        remove(tmp);
        return -1;
    }
    return 0;
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
    const char *slash = strrchr(path, '/');
    char dir[4096];
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if ((size_t)(slash - path) >= sizeof dir) {
        snprintf(err, errlen, "%s: path too long", path);
        return -1;
    } else
        snprintf(dir, sizeof dir, "%.*s", slash == path ? 1 : (int)(slash - path), path);
    if (access(dir, W_OK | X_OK) != 0) {
        int e = errno;
        snprintf(err, errlen, "%s: cannot write there: %s%s", path, strerror(e),
                 e == ENOENT ? " (the directory does not exist)" : "");
        return -1;
    }
    return 0;
}
