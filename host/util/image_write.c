/* image_write.c — image_write: the file written whole or not at all (fileio.h), its
 * temporary filled through its descriptor by the encoder (image_encode: OpenImageIO, in the
 * image helper process or here), or by image_pfm.c for PFM; this process syncs the
 * temporary and renames it into place. */
#include "image_io.h"

#include "fileio.h"

/* The image that encode_into writes. */
typedef struct Image {
    const char *path;
    int width, height;
    const float *rgba;
    float exposure;
} Image;

static int encode_into(int fd, void *ctx, char *err, size_t errlen)
{
    const Image *im = ctx;
    return image_encode(im->path, fd, im->width, im->height, im->rgba, im->exposure, err, errlen);
}

int image_write(const char *path, int width, int height, const float *rgba, float exposure,
                char *err, size_t errlen)
{
    if (image_check_path(path, err, errlen)) return -1;
    if (image_is_native_format(path))
        return image_write_pfm(path, width, height, rgba, exposure, err, errlen);
    Image im = {path, width, height, rgba, exposure};
    return file_write_fd(path, encode_into, &im, err, errlen);
}
