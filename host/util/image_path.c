/* image_path.c — what image_io.h can say of a path without OpenImageIO: whether vbcl
 * writes its format, whether that format keeps linear floats, and whether vbcl writes it
 * without OpenImageIO. */
#include "image_io.h"

#include <ctype.h>
#include <stdio.h>
#include <string.h>

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

int image_check_path(const char *path, char *err, size_t errlen)
{
    char e[256];
    image_ext(path, e, sizeof e);
    if (!strcmp(e, "png") || !strcmp(e, "jpg") || !strcmp(e, "jpeg") || !strcmp(e, "tif") ||
        !strcmp(e, "tiff") || !strcmp(e, "exr") || !strcmp(e, "pfm"))
        return 0;
    snprintf(err, errlen,
             "%s: unknown image format \"%s\" (expected .png, .jpg, .tif, .exr or .pfm)", path, e);
    return -1;
}

int image_is_float_format(const char *path)
{
    char e[256];
    image_ext(path, e, sizeof e);
    return !strcmp(e, "exr") || !strcmp(e, "pfm");
}

int image_is_native_format(const char *path)
{
    char e[256];
    image_ext(path, e, sizeof e);
    return !strcmp(e, "pfm");
}
