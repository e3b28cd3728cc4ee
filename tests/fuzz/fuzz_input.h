/* fuzz_input.h — what the libFuzzer harnesses share: the parsers read files, so each input
 * is written to a per-process file in /dev/shm (or /tmp) with the extension they expect. */
#ifndef VBCL_FUZZ_INPUT_H
#define VBCL_FUZZ_INPUT_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <unistd.h>

/* Writes data to a file named for this process with extension ext; returns its path in a
 * static buffer, or NULL. */
static inline const char *fuzz_input_file(const uint8_t *data, size_t size, const char *ext)
{
    static char path[256];
    const char *dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    snprintf(path, sizeof path, "%s/vbcl-fuzz-%d%s", dir, (int)getpid(), ext);
    FILE *f = fopen(path, "wb");
    if (!f) return NULL;
    size_t n = size ? fwrite(data, 1, size, f) : 0;
    int bad = fclose(f) != 0 || n != size;
    return bad ? NULL : path;
}

#endif
