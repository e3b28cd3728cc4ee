/* fileio.h — files written whole or not at all: the bytes go to a temporary file in the
 * target's directory, which is renamed into place once complete. */
#ifndef VBCL_FILEIO_H
#define VBCL_FILEIO_H

#include <stddef.h>
#include <stdio.h>

/* Writes path whole or not at all: write(f, ctx) fills a temporary file (".NAME.tmpPID" in
 * path's directory; a write error shows in ferror(f)), which is renamed into place once
 * complete. Returns 0, or -1 with a message in err (no temporary file is left behind). */
int file_write_stream(const char *path, void (*write)(FILE *f, const void *ctx), const void *ctx,
                      char *err, size_t errlen);

/* Writes the n bytes at data to path under a temporary name (".NAME.tmpPID" in path's
 * directory) and renames it into place, so that path is only ever replaced by a complete
 * file. Returns 0, or -1 with a message in err (no temporary file is left behind). */
int file_write_whole(const char *path, const void *data, size_t n, char *err, size_t errlen);

/* Returns 0 when path's directory exists and is writable (a check before long work whose
 * result goes to path), else -1 with a message in err. */
int file_check_dir(const char *path, char *err, size_t errlen);

#endif
