// image_io.cpp — the one C++ file: OpenImageIO behind the C interface of image_io.h
// (image_encode, image_read, image_read_radiance). image_encode has OpenImageIO write the
// image straight into a descriptor that its caller opened (fileio.h's temporary), through an
// I/O proxy that pwrite()s at offsets of its own. The vbcl binary loads this file as a plugin
// (image_plugin.c), in its image helper process or in itself; the tests and tools link it.
#include "image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <string>
#include <vector>

#include <unistd.h>

using namespace OIIO;

static float srgb_encode(float v)
{
    if (!(v > 0.0f)) return 0.0f; // also NaN
    if (v >= 1.0f) return 1.0f;
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

// OpenImageIO's output onto a descriptor. Each write goes to the proxy's own offset
// (pwrite), never to the descriptor's file offset, which every process holding the same
// open file shares (vbcl and its image helper); a short or interrupted write goes on with
// the rest, and the first error's errno is kept for the message. The file is empty at the
// start, so its size is the end of the furthest write. OpenImageIO may call pread and
// pwrite from several threads: the bookkeeping is under a lock.
class FdOutput final : public Filesystem::IOProxy
{
  public:
    explicit FdOutput(int fd) : IOProxy("", Write), m_fd(fd) {}
    const char *proxytype() const override { return "vbcl_fd"; }
    bool seek(int64_t offset) override
    {
        if (offset < 0) return false;
        m_pos = offset;
        return true;
    }
    size_t write(const void *buf, size_t n) override
    {
        size_t k = pwrite(buf, n, m_pos);
        m_pos += (int64_t)k;
        return k;
    }
    size_t read(void *buf, size_t n) override
    {
        size_t k = pread(buf, n, m_pos);
        m_pos += (int64_t)k;
        return k;
    }
    size_t pwrite(const void *buf, size_t n, int64_t offset) override
    {
        const char *p = (const char *)buf;
        size_t done = 0;
        while (done < n) {
            ssize_t k = ::pwrite(m_fd, p + done, n - done, (off_t)(offset + (int64_t)done));
            if (k < 0 && errno == EINTR) continue;
            if (k <= 0) {
                failed(k < 0 ? errno : EIO);
                break;
            }
            done += (size_t)k;
        }
        std::lock_guard<std::mutex> lock(m_lock);
        m_end = std::max(m_end, offset + (int64_t)done);
        return done;
    }
    size_t pread(void *buf, size_t n, int64_t offset) override
    {
        char *p = (char *)buf;
        size_t done = 0;
        while (done < n) {
            ssize_t k = ::pread(m_fd, p + done, n - done, (off_t)(offset + (int64_t)done));
            if (k < 0 && errno == EINTR) continue;
            if (k < 0) failed(errno);
            if (k <= 0) break; // the end of the file, or an error
            done += (size_t)k;
        }
        return done;
    }
    size_t size() const override
    {
        std::lock_guard<std::mutex> lock(m_lock);
        return (size_t)m_end;
    }
    // The errno of the first failed write or read, 0 if none.
    int failure() const
    {
        std::lock_guard<std::mutex> lock(m_lock);
        return m_errno;
    }

  private:
    void failed(int e)
    {
        std::lock_guard<std::mutex> lock(m_lock);
        if (!m_errno) m_errno = e;
    }
    int m_fd;
    mutable std::mutex m_lock;
    int64_t m_end = 0;
    int m_errno = 0;
};

extern "C" int image_encode(const char *path, int fd, int width, int height, const float *rgba,
                            float exposure, char *err, size_t errlen)
{
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

    // The writer is chosen by path's extension and writes into fd through the proxy, never
    // to path: the caller syncs, closes and renames the file (fileio.h). The proxy outlives
    // the writer, whose destructor may still write.
    FdOutput proxy(fd);
    void *proxy_ptr = &proxy;
    auto out = ImageOutput::create(path);
    if (!out || !out->supports("ioproxy")) {
        std::snprintf(err, errlen, "%s: cannot create a writer: %s", path,
                      out ? "it cannot write through an I/O proxy" : OIIO::geterror().c_str());
        return -1;
    }
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
    out.reset();
    // A failed write (a full disk, a file-size limit) is the file's fault, named as fileio.h
    // names it; anything else is the encoder's.
    if (int e = proxy.failure()) {
        std::snprintf(err, errlen, "%s: cannot write: %s", path, std::strerror(e));
        return -1;
    }
    if (!ok || !msg.empty() || proxy.size() == 0) {
        std::snprintf(err, errlen, "%s: cannot encode the image: %s", path,
                      msg.empty() ? "the writer failed" : msg.c_str());
        return -1;
    }
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
