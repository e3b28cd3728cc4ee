// image_io.cpp — the one C++ file: OpenImageIO behind the C interface of image_io.h. The
// vbcl binary loads it as a plugin (image_plugin.c); the tests and tools link it.
#include "image_io.h"

#include <OpenImageIO/imageio.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <unistd.h>
#include <vector>

using namespace OIIO;

static float srgb_encode(float v)
{
    if (!(v > 0.0f)) return 0.0f; // also NaN
    if (v >= 1.0f) return 1.0f;
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

extern "C" int image_write(const char *path, int width, int height, const float *rgba,
                           float exposure, char *err, size_t errlen)
{
    if (image_check_path(path, err, errlen)) return -1;
    if (image_is_native_format(path))
        return image_write_pfm(path, width, height, rgba, exposure, err, errlen);
    const char *dot = std::strrchr(path, '.'); // image_check_path found an extension
    std::string e(dot + 1);
    for (auto &ch : e) ch = (char)std::tolower((unsigned char)ch);
    std::string p(path);
    size_t slash = p.rfind('/');
    std::string dir = slash == std::string::npos ? "" : p.substr(0, slash + 1);
    std::string base = slash == std::string::npos ? p : p.substr(slash + 1);
    std::string tmp = dir + "." + base + ".tmp" + std::to_string((long)getpid()) + "." + e;

    const float scale = std::exp2(exposure);
    const size_t n = (size_t)width * (size_t)height;
    bool flt = image_is_float_format(path) != 0;
    std::vector<float> fpix;
    std::vector<unsigned char> bpix;
    if (flt)
        fpix.resize(n * 3);
    else
        bpix.resize(n * 3);
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            float v = rgba[4 * i + c] * scale;
            if (flt)
                fpix[3 * i + c] = v;
            else
                bpix[3 * i + c] = (unsigned char)std::lround(srgb_encode(v) * 255.0f);
        }

    auto out = ImageOutput::create(tmp);
    if (!out) {
        std::snprintf(err, errlen, "%s: cannot create a writer: %s", path,
                      OIIO::geterror().c_str());
        return -1;
    }
    ImageSpec spec(width, height, 3, flt ? TypeDesc::FLOAT : TypeDesc::UINT8);
    if (!flt)
        spec.attribute("oiio:ColorSpace", "sRGB");
    else
        spec.attribute("oiio:ColorSpace", "Linear");
    spec.attribute("Software", "vbcl");
    bool ok = out->open(tmp, spec);
    if (ok)
        ok = flt ? out->write_image(TypeDesc::FLOAT, fpix.data())
                 : out->write_image(TypeDesc::UINT8, bpix.data());
    if (ok) ok = out->close();
    if (!ok) {
        std::string msg = out->geterror();
        for (size_t at; (at = msg.find(tmp)) != std::string::npos;) // the name the user gave
            msg.replace(at, tmp.size(), path);
        out.reset();
        std::remove(tmp.c_str());
        std::snprintf(err, errlen, "%s: cannot write: %s", path, msg.c_str());
        return -1;
    }
    out.reset();
    if (std::rename(tmp.c_str(), path) != 0) {
        std::snprintf(err, errlen, "%s: cannot rename the finished image into place: %s", path,
                      std::strerror(errno));
        std::remove(tmp.c_str());
        return -1;
    }
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
