/* image_path.c — what image_io.h can say of a path without OpenImageIO: whether vbcl
 * writes its format, whether that format keeps linear floats, and whether vbcl writes it
 * without OpenImageIO. */
#include "image_io.h"

#include <ctype.h>
#include <stdio.h>
#include <string.h>

/* The formats vbcl writes, by extension. */
typedef struct ImageFormat {
    const char *ext;
    int linear; /* keeps linear floats (else 8-bit sRGB) */
    int native; /* written by vbcl itself (image_pfm.c), not by OpenImageIO */
} ImageFormat;

static const ImageFormat formats[] = {
    {"png", 0, 0},  {"jpg", 0, 0}, {"jpeg", 0, 0}, {"tif", 0, 0},
    {"tiff", 0, 0}, {"exr", 1, 0}, {"pfm", 1, 1},
};

/* The extension of path's file name in lower case ("" without one), cut to fit ext. */
static void image_ext(const char *path, char *ext, size_t n)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    size_t k = 0;
    if (dot && !(slash && dot < slash))
        for (const char *c = dot + 1; *c && k + 1 < n; c++)
            ext[k++] = (char)tolower((unsigned char)*c);
    ext[k] = '\0';
}

/* path's format, or NULL when vbcl writes none by its extension (put in e). */
static const ImageFormat *image_format(const char *path, char *e, size_t n)
{
    image_ext(path, e, n);
    for (size_t i = 0; i < sizeof formats / sizeof formats[0]; i++)
        if (!strcmp(e, formats[i].ext)) return &formats[i];
    return NULL;
}

int image_check_path(const char *path, char *err, size_t errlen)
{
    char e[256];
    if (image_format(path, e, sizeof e)) return 0;
    snprintf(err, errlen,
             "%s: unknown image format \"%s\" (expected .png, .jpg, .tif, .exr or .pfm)", path, e);
    return -1;
}

int image_is_float_format(const char *path)
{
    char e[256];
    const ImageFormat *f = image_format(path, e, sizeof e);
    return f && f->linear;
}

int image_is_native_format(const char *path)
{
    char e[256];
    const ImageFormat *f = image_format(path, e, sizeof e);
    return f && f->native;
}
