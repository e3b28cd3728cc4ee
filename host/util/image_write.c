/* image_write.c — image_write: the image encoded in memory (image_encode, or image_pfm.c
 * for PFM), then written whole or not at all by this process (fileio.h). */
#include "image_io.h"

#include "fileio.h"

#include <stdlib.h>

int image_write(const char *path, int width, int height, const float *rgba, float exposure,
                char *err, size_t errlen)
{
    if (image_check_path(path, err, errlen)) return -1;
    if (image_is_native_format(path))
        return image_write_pfm(path, width, height, rgba, exposure, err, errlen);
    unsigned char *bytes;
    size_t n;
    if (image_encode(path, width, height, rgba, exposure, &bytes, &n, err, errlen)) return -1;
    int rc = file_write_whole(path, bytes, n, err, errlen);
    free(bytes);
    return rc;
}
