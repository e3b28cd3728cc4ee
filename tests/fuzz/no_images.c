/* no_images.c — the fuzz harnesses' image_read_radiance: the scene parser reads an
 * environment's image through it (host/scene/scene_environment.c), and the harnesses link no
 * OpenImageIO. An arbitrary input never reads an image: every "file" is refused, as a file
 * OpenImageIO cannot read would be, after the keys around it are checked. */
#include <stdio.h>

#include "image_io.h"

int image_read_radiance(const char *path, int *width, int *height, float **rgba, char *err,
                        size_t errlen)
{
    *width = *height = 0;
    *rgba = NULL;
    snprintf(err, errlen, "%s: cannot read: the fuzz harness reads no images", path);
    return -1;
}
