// image_io.cpp — the one C++ file: OpenImageIO behind the C interface of image_io.h
// (image_encode, image_read, image_read_radiance). The vbcl binary loads it as a plugin
// (image_plugin.c); the tests and tools link it.
#include "image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <vector>

using namespace OIIO;

static float srgb_encode(float v)
{
    if (!(v > 0.0f)) return 0.0f; // also NaN
    if (v >= 1.0f) return 1.0f;
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

extern "C" int image_encode(const char *path, int width, int height, const float *rgba,
                            float exposure, unsigned char **bytes, size_t *nbytes, char *err,
                            size_t errlen)
{
    *bytes = nullptr;
    *nbytes = 0;
    if (image_check_path(path, err, errlen)) return -1;
    const float scale = std::exp2(exposure);
    const size_t n = (size_t)width * (size_t)height;
    bool flt = image_is_float_format(path) != 0;
    std::vector<float> fpix;
    std::vector<unsigned char> bpix;
    try {
        if (flt)
            fpix.resize(n * 3);
        else
            bpix.resize(n * 3);
    } catch (const std::bad_alloc &) {
        std::snprintf(err, errlen, "%s: out of memory for a %dx%d image", path, width, height);
        return -1;
    }
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            float v = rgba[4 * i + c] * scale;
            if (flt)
                fpix[3 * i + c] = v;
            else
                bpix[3 * i + c] = (unsigned char)std::lround(srgb_encode(v) * 255.0f);
        }

    // The writer is chosen by path's extension and writes into memory (an I/O proxy), never
    // to path: the caller writes the bytes (fileio.h), checking every write.
    auto out = ImageOutput::create(path);
    if (!out || !out->supports("ioproxy")) {
        std::snprintf(err, errlen, "%s: cannot create a writer: %s", path,
                      out ? "it cannot write into memory" : OIIO::geterror().c_str());
        return -1;
    }
    std::vector<unsigned char> buf;
    Filesystem::IOVecOutput proxy(buf);
    void *proxy_ptr = &proxy;
    ImageSpec spec(width, height, 3, flt ? TypeDesc::FLOAT : TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", flt ? "Linear" : "sRGB");
    spec.attribute("Software", "vbcl");
    spec.attribute("oiio:ioproxy", TypeDesc::PTR, &proxy_ptr);
    // TIFF's Exif directory cannot go through a proxy (OpenImageIO 2.4: "failed
    // TIFFWriteCustomDirectory() of the Exif data", and a file cut short), and vbcl has no
    // Exif data to write.
    spec.attribute("tiff:write_exif", 0);
    bool ok = out->open(path, spec);
    if (ok)
        ok = flt ? out->write_image(TypeDesc::FLOAT, fpix.data())
                 : out->write_image(TypeDesc::UINT8, bpix.data());
    if (ok) ok = out->close();
    // A writer may report an error and still return true: the image is not trusted then.
    std::string msg = out->geterror();
    if (!ok || !msg.empty() || buf.empty()) {
        std::snprintf(err, errlen, "%s: cannot encode the image: %s", path,
                      msg.empty() ? "the writer failed" : msg.c_str());
        return -1;
    }
    *bytes = (unsigned char *)std::malloc(buf.size());
    if (!*bytes) {
        std::snprintf(err, errlen, "%s: out of memory for the encoded image", path);
        return -1;
    }
    std::memcpy(*bytes, buf.data(), buf.size());
    *nbytes = buf.size();
    return 0;
}

// The decoding an image's colour space calls for, by what OpenImageIO says of it: "sRGB" (PNG,
// JPEG) the sRGB curve (DECODE_SRGB), "Rec709" (PNM) the Rec. 709 curve (DECODE_REC709),
// "GammaCorrectedG" a power G, "Linear" (EXR, HDR) or any other name none (a power 1); an image
// it says nothing of is sRGB when its pixels are integers, linear when they are floats.
enum { DECODE_SRGB = -1, DECODE_REC709 = -2 };
static float decode_power(const ImageSpec &spec)
{
    std::string cs = spec.get_string_attribute("oiio:ColorSpace");
    for (char &ch : cs) ch = (char)std::tolower((unsigned char)ch);
    if (cs.find("srgb") != std::string::npos) return DECODE_SRGB;
    if (cs.find("rec709") != std::string::npos) return DECODE_REC709;
    if (cs.rfind("gammacorrected", 0) == 0) {
        float g = (float)std::atof(cs.c_str() + 14);
        return g > 0.0f ? g : 1.0f;
    }
    if (cs.empty() && !spec.format.is_floating_point()) return DECODE_SRGB;
    return 1.0f;
}

// v decoded as decode_power's p says.
static float decode(float v, float p)
{
    if (p == DECODE_SRGB) return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
    if (p == DECODE_REC709)
        return v < 0.081f ? v / 4.5f : std::pow((v + 0.099f) / 1.099f, 1.0f / 0.45f);
    return p == 1.0f || !(v > 0.0f) ? v : std::pow(v, p);
}

extern "C" int image_read_radiance(const char *path, int *width, int *height, float **rgba,
                                   char *err, size_t errlen)
{
    auto in = ImageInput::open(path);
    if (!in) {
        std::snprintf(err, errlen, "%s: cannot read: %s", path, OIIO::geterror().c_str());
        return -1;
    }
    const ImageSpec &spec = in->spec();
    int w = spec.width, h = spec.height, nc = spec.nchannels;
    if (w < 1 || h < 1 || nc < 1 || (size_t)w * (size_t)h > IMAGE_RADIANCE_MAX_TEXELS) {
        std::snprintf(err, errlen, "%s: %d x %d texels: expected 1 to %zu texels", path, w, h,
                      (size_t)IMAGE_RADIANCE_MAX_TEXELS);
        return -1;
    }
    float power = decode_power(spec);
    std::vector<float> pix;
    try {
        pix.resize((size_t)w * h * nc);
    } catch (const std::bad_alloc &) {
        std::snprintf(err, errlen, "%s: out of memory for a %dx%d image", path, w, h);
        return -1;
    }
    if (!in->read_image(0, 0, 0, nc, TypeDesc::FLOAT, pix.data())) {
        std::snprintf(err, errlen, "%s: cannot read: %s", path, in->geterror().c_str());
        return -1;
    }
    in->close();
    float *out = (float *)std::malloc(sizeof(float) * 4 * (size_t)w * h);
    if (!out) {
        std::snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    int grey = nc < 3; // Y, or Y and A
    for (size_t i = 0; i < (size_t)w * h; i++) {
        for (int c = 0; c < 3; c++) {
            out[4 * i + c] = decode(pix[i * nc + (grey ? 0 : c)], power);
        }
        out[4 * i + 3] = 1.0f;
    }
    *width = w;
    *height = h;
    *rgba = out;
    return 0;
}

extern "C" int image_read(const char *path, int *width, int *height, float **rgba, char *err,
                          size_t errlen)
{
    auto in = ImageInput::open(path);
    if (!in) {
        std::snprintf(err, errlen, "%s: cannot read: %s", path, OIIO::geterror().c_str());
        return -1;
    }
    const ImageSpec &spec = in->spec();
    int w = spec.width, h = spec.height, nc = spec.nchannels;
    std::vector<float> pix((size_t)w * h * nc);
    if (!in->read_image(0, 0, 0, nc, TypeDesc::FLOAT, pix.data())) {
        std::snprintf(err, errlen, "%s: cannot read: %s", path, in->geterror().c_str());
        return -1;
    }
    in->close();
    float *out = (float *)std::malloc(sizeof(float) * 4 * (size_t)w * h);
    if (!out) {
        std::snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    for (size_t i = 0; i < (size_t)w * h; i++)
        for (int c = 0; c < 4; c++)
            out[4 * i + c] = c < nc ? pix[i * nc + c] : (c == 3 ? 1.0f : 0.0f);
    *width = w;
    *height = h;
    *rgba = out;
    return 0;
}
