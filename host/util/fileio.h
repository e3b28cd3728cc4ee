/* fileio.h — files written whole or not at all: the bytes go to a temporary file in the
 * target's directory, which is renamed into place once complete and on the disk. */
#ifndef VBCL_FILEIO_H
#define VBCL_FILEIO_H

#include <stddef.h>
#include <stdio.h>

/* Writes path whole or not at all: write(f, ctx) fills a temporary file (".NAME.tmpPID.N"
 * in path's directory; a write error shows in ferror(f)), which is flushed, synced to the
 * disk, closed and renamed into place, each step checked. Returns 0, or -1 with a message
 * naming path and the cause in err ("No space left on device", "File too large"); then the
 * temporary is gone and an older file at path is untouched. SIGINT, SIGTERM and SIGHUP
 * during the write remove the temporary before the process dies of them (the handler is
 * installed at the first write, where the signal's action is the default). */
int file_write_stream(const char *path, void (*write)(FILE *f, const void *ctx), const void *ctx,
                      char *err, size_t errlen);

/* Writes path as file_write_stream does, the temporary filled through its descriptor:
 * fill(fd, ctx, err, errlen) writes it (opened for reading and writing; another process
 * may write it too, given the descriptor) and returns 0, or -1 with a message in err, which
 * is then file_write_fd's message. The sync, close and rename follow, each checked
 * ("PATH: cannot write: CAUSE"); on any failure the temporary is removed. */
int file_write_fd(const char *path, int (*fill)(int fd, void *ctx, char *err, size_t errlen),
                  void *ctx, char *err, size_t errlen);

/* Writes the n bytes at data to path as file_write_stream does. */
int file_write_whole(const char *path, const void *data, size_t n, char *err, size_t errlen);

/* Returns 0 when path's directory exists and is writable (a check before long work whose
 * result goes to path), else -1 with a message in err. */
int file_check_dir(const char *path, char *err, size_t errlen);

#endif
