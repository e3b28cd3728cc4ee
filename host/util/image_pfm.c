/* image_pfm.c — the Portable Float Map (.pfm), the one format vbcl writes itself: linear
 * float RGB with no compression and no metadata, which pbrt, Mitsuba, OpenImageIO and
 * numpy all read. It needs no OpenImageIO, so a render to .pfm runs on a machine that has
 * only an OpenCL driver (a GPU node, a container), and pays no library load. */
#include "image_io.h"

#include "fileio.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct Pfm {
    int width, height;
    const float *rgba;
    float scale;
    unsigned char *row; /* one row's bytes */
} Pfm;

/* The header says "-1.0": little-endian floats, written byte by byte whatever the host's
 * order. Rows go from the bottom of the image to the top, as the format has them. */
static void write_pfm(FILE *f, const void *ctx)
{
    const Pfm *p = ctx;
    fprintf(f, "PF\n%d %d\n-1.0\n", p->width, p->height);
    for (int y = p->height - 1; y >= 0 && !ferror(f); y--) {
        const float *src = p->rgba + 4 * (size_t)y * (size_t)p->width;
        for (int x = 0; x < p->width; x++)
            for (int c = 0; c < 3; c++) {
                float v = src[4 * (size_t)x + (size_t)c] * p->scale;
                unsigned int u;
                memcpy(&u, &v, sizeof u);
                unsigned char *b = p->row + 12 * (size_t)x + 4 * (size_t)c;
                b[0] = (unsigned char)u;
                b[1] = (unsigned char)(u >> 8);
                b[2] = (unsigned char)(u >> 16);
                b[3] = (unsigned char)(u >> 24);
            }
        fwrite(p->row, 12, (size_t)p->width, f);
    }
}

int image_write_pfm(const char *path, int width, int height, const float *rgba, float exposure,
                    char *err, size_t errlen)
{
    Pfm p = {width, height, rgba, exp2f(exposure), malloc((size_t)width * 12)};
    if (!p.row) {
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    int rc = file_write_stream(path, write_pfm, &p, err, errlen);
    free(p.row);
    return rc;
}
