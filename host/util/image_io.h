/* image_io.h — the C interface to OpenImageIO: write a linear float RGB image as PNG,
 * JPEG or TIFF (8-bit sRGB) or EXR (linear float), whole or not at all; read images. PFM
 * (linear float) vbcl writes itself, without OpenImageIO (image_pfm.c). */
#ifndef VBCL_IMAGE_IO_H
#define VBCL_IMAGE_IO_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Returns 0 when path's extension names a format vbcl writes, else -1 with a message. */
int image_check_path(const char *path, char *err, size_t errlen);

/* Whether path's format keeps linear floats (EXR, PFM); the others are 8-bit sRGB. */
int image_is_float_format(const char *path);

/* Whether vbcl writes path's format itself (PFM), with no need of OpenImageIO. */
int image_is_native_format(const char *path);

/* Writes a PFM as image_write does (the same scaling; whole or not at all, by fileio.h). */
int image_write_pfm(const char *path, int width, int height, const float *rgba, float exposure,
                    char *err, size_t errlen);

/* Makes OpenImageIO ready for the image writes to come while the program goes on: in the
 * vbcl binary, which loads it as a plugin (image_plugin.c) rather than at start-up, by
 * starting the helper process that will encode the images (`vbcl --image-helper`; once a
 * run), or, where it cannot start and `thread` is set, by loading the plugin on a thread
 * of its own (vbcl asks for that once its devices are open: the dynamic loader serves one
 * thread at a time, and the OpenCL driver's own loading would wait for it). Only the vbcl
 * binary has it; programs linked with image_io.cpp have OpenImageIO from the start. */
void image_preload(int thread);

/* Waits until a load on a thread of this process (image_preload's fallback) has ended (at
 * once if none is under way): vbcl renders only then, since PoCL's first launch of each
 * kernel loads the kernel's code through the same dynamic loader and would wait for
 * OpenImageIO's 260 libraries anyway, inside the render's timing. The helper process
 * loads them beside the render, in a loader of its own. */
void image_preload_wait(void);

/* The helper process's main (vbcl --image-helper, started by image_preload): loads the
 * plugin and encodes the images vbcl sends it, each into the descriptor of the file that
 * came with the request, answering with the result and its message only, until vbcl closes
 * the socket. Returns the exit status. */
int image_helper_main(void);

/* Writes rgba (4 floats per pixel, linear radiance, alpha ignored) scaled by 2^exposure.
 * 8-bit formats get the sRGB transfer curve, clamped; EXR keeps linear floats. The file is
 * written through fileio.h, whole or not at all: a temporary file in the same directory,
 * which the encoder writes through its descriptor (image_encode; PFM by image_pfm.c), every
 * write checked, then synced and renamed into place by this process, so an existing file is
 * replaced only by a complete image, and a failed write leaves no temporary. Returns 0, or
 * -1 with a message naming path and the cause ("No space left on device"). */
int image_write(const char *path, int width, int height, const float *rgba, float exposure,
                char *err, size_t errlen);

/* Encodes rgba as image_write would write it in path's format (PNG, JPEG, TIFF or EXR, by
 * the extension) into fd, an empty file open for reading and writing, from offset 0, at
 * offsets of its own (pwrite: the descriptor's file offset is neither used nor moved).
 * Neither syncs nor closes fd; path only names the format and the image in messages. In
 * the vbcl binary the encoding runs in the image helper process, which gets a copy of fd
 * over its socket, or on the plugin loaded here (image_plugin.c). Returns 0, or -1 with a
 * message: "PATH: cannot write: CAUSE" when a write failed (as fileio.h says it), else
 * "PATH: cannot encode the image: ..." and the like. */
int image_encode(const char *path, int fd, int width, int height, const float *rgba, float exposure,
                 char *err, size_t errlen);

/* Reads an image as floats, 4 channels per pixel (missing channels 0, alpha 1), values as
 * stored (8-bit images give encoded values in [0, 1]). *rgba is malloc'ed. */
int image_read(const char *path, int *width, int *height, float **rgba, char *err, size_t errlen);

/* The most texels image_read_radiance reads: 2^28 (16384 x 16384, 4 GiB of floats). */
#define IMAGE_RADIANCE_MAX_TEXELS ((size_t)1 << 28)

/* Reads an image as linear radiance, 4 floats per pixel (r, g, b, 1), row 0 the top: a grey
 * image spread over r, g and b; decoded by what OpenImageIO says of its colour space: "sRGB"
 * (PNG, JPEG) by the sRGB curve, "Rec709" (PNM) by the Rec. 709 curve, "GammaCorrectedG"
 * raised to G, "Linear" (EXR, HDR) as stored; integer pixels of no stated colour space as
 * sRGB, float ones as stored. Values are not checked (NaN, negative). An image of no texels
 * or more than IMAGE_RADIANCE_MAX_TEXELS is refused. *rgba is malloc'ed. Returns 0, or -1
 * with a message naming path. */
int image_read_radiance(const char *path, int *width, int *height, float **rgba, char *err,
                        size_t errlen);

#ifdef __cplusplus
}
#endif

#endif
