/* image_pfm.c — the Portable Float Map (.pfm), the one format vbcl writes itself: linear
 * float RGB with no compression and no metadata, which pbrt, Mitsuba, OpenImageIO and
 * numpy all read. It needs no OpenImageIO, so a render to .pfm runs on a machine that has
 * only an OpenCL driver (a GPU node, a container), and pays no library load. */
#include "image_io.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The header says "-1.0": little-endian floats, written byte by byte whatever the host's
 * order. Rows go from the bottom of the image to the top, as the format has them. */
int image_write_pfm(const char *path, int width, int height, const float *rgba, float exposure,
                    char *err, size_t errlen)
{
    const char *slash = strrchr(path, '/');
    size_t dirlen = slash ? (size_t)(slash - path) + 1 : 0;
    size_t n = strlen(path) + 48;
    char *tmp = malloc(n);
    unsigned char *row = malloc((size_t)width * 12);
    if (!tmp || !row) {
        free(tmp);
        free(row);
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    /* A hidden name in the same directory, renamed into place when complete. */
    snprintf(tmp, n, "%.*s.%s.tmp%ld.pfm", (int)dirlen, path, path + dirlen, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        snprintf(err, errlen, "%s: cannot write: %s", path, strerror(errno));
        free(tmp);
        free(row);
        return -1;
    }
    const float scale = exp2f(exposure);
    int ok = fprintf(f, "PF\n%d %d\n-1.0\n", width, height) > 0;
    for (int y = height - 1; ok && y >= 0; y--) {
        for (int x = 0; x < width; x++)
            for (int c = 0; c < 3; c++) {
                float v = rgba[4 * ((size_t)y * (size_t)width + (size_t)x) + (size_t)c] * scale;
                unsigned int u;
                memcpy(&u, &v, sizeof u);
                unsigned char *b = row + 12 * (size_t)x + 4 * (size_t)c;
                b[0] = (unsigned char)u;
                b[1] = (unsigned char)(u >> 8);
                b[2] = (unsigned char)(u >> 16);
                b[3] = (unsigned char)(u >> 24);
            }
        ok = fwrite(row, 12, (size_t)width, f) == (size_t)width;
    }
    int saved = errno;
    if (fclose(f) != 0 && ok) {
        ok = 0;
        saved = errno;
    }
    if (!ok) {
        snprintf(err, errlen, "%s: cannot write: %s", path, strerror(saved));
        remove(tmp);
    } else if (rename(tmp, path) != 0) {
        snprintf(err, errlen, "%s: cannot rename the finished image into place: %s", path,
                 strerror(errno));
        remove(tmp);
        ok = 0;
    }
    free(tmp);
    free(row);
    return ok ? 0 : -1;
}
