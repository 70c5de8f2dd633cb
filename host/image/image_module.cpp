// The image module: OpenImageIO reads (textures), writes and comparisons behind the C interface of
// host/image/image_module.h. Built as libvgpu-image.so and loaded on first use by
// host/image/image_io.cpp.
#include "host/image/image_module.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <unistd.h>
#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/lsan_interface.h>
#endif

#include <cstdio>
#include <string>

namespace {

// Points file descriptor 2 at /dev/null for its lifetime (flushing stderr first and after).
class QuietStderr {
 public:
  QuietStderr() {
    std::fflush(stderr);
    saved_ = ::dup(2);
    const int null = ::open("/dev/null", O_WRONLY);
    if (saved_ >= 0 && null >= 0) ::dup2(null, 2);
    if (null >= 0) ::close(null);
  }
  ~QuietStderr() {
    std::fflush(stderr);
    if (saved_ >= 0) {
      ::dup2(saved_, 2);
      ::close(saved_);
    }
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  int saved_ = -1;
};

int fail(std::string reason, char* err, size_t err_size) {
  for (char& c : reason)
    if (c == '\n') c = ' ';
  if (err_size > 0) std::snprintf(err, err_size, "%s", reason.c_str());
  return -1;
}

}  // namespace

extern "C" int vgpu_image_write(const char* path, int width, int height, int channels,
                                const float* pixels, char* err, size_t err_size) {
  const std::string p(path);
  const bool png = p.size() >= 4 && (p.compare(p.size() - 4, 4, ".png") == 0 ||
                                     p.compare(p.size() - 4, 4, ".PNG") == 0);
  OIIO::ImageSpec spec(width, height, channels,
                       png ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
  // Outputs must be byte-identical from run to run (hashable, cacheable): OpenImageIO stamps the
  // write time (EXR capDate) unless DateTime is set, so it is set empty.
  spec.attribute("DateTime", "");
  auto out = OIIO::ImageOutput::create(p);
  if (!out) return fail("cannot create an image writer: " + OIIO::geterror(), err, err_size);
  bool ok = out->open(p, spec);
  if (ok) ok = out->write_image(OIIO::TypeDesc::FLOAT, pixels);
  if (ok) ok = out->close();
  if (!ok) return fail("cannot write image: " + out->geterror(), err, err_size);
  return 0;
}

extern "C" int vgpu_image_compare(const char* a, const char* b, double threshold,
                                  VgpuImageComparison* out, char* err, size_t err_size) {
  OIIO::ImageBuf A(a), B(b);
  if (!A.read(0, 0, true, OIIO::TypeDesc::FLOAT))
    return fail(std::string(a) + ": cannot read image: " + A.geterror(), err, err_size);
  if (!B.read(0, 0, true, OIIO::TypeDesc::FLOAT))
    return fail(std::string(b) + ": cannot read image: " + B.geterror(), err, err_size);
  const OIIO::ImageSpec &sa = A.spec(), &sb = B.spec();
  if (sa.width != sb.width || sa.height != sb.height || sa.nchannels != sb.nchannels)
    return fail(std::string(b) + ": size " + std::to_string(sb.width) + "x" +
                    std::to_string(sb.height) + "x" + std::to_string(sb.nchannels) +
                    " differs from " + a + " (" + std::to_string(sa.width) + "x" +
                    std::to_string(sa.height) + "x" + std::to_string(sa.nchannels) + ")",
                err, err_size);
  const auto r = OIIO::ImageBufAlgo::compare(A, B, float(threshold), float(threshold));
  *out = {sa.width, sa.height, sa.nchannels, double(r.nfail), r.rms_error, r.PSNR, r.maxerror};
  return 0;
}

extern "C" int vgpu_image_read(const unsigned char* bytes, size_t n,
                               float* (*alloc)(void* ctx, size_t count), void* ctx, int* width,
                               int* height, int* channels, char* err, size_t err_size) {
  // The format from the content, not from a name: glTF's mimeType and file extensions may lie.
  const char* format = nullptr;
  if (n >= 8 && bytes[0] == 0x89 && bytes[1] == 'P' && bytes[2] == 'N' && bytes[3] == 'G')
    format = "memory.png";
  else if (n >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF)
    format = "memory.jpg";
  if (!format) return fail("not a PNG or JPEG image", err, err_size);
  // libpng prints its errors on stderr before OpenImageIO returns them: the caller's one-line
  // message would get a second line. stderr is quiet while decoding.
  const QuietStderr quiet;
#if defined(__SANITIZE_ADDRESS__)
  // OpenImageIO 2.4 leaks the error text of a PNG that fails to read (ImageInput::geterror
  // called from PNGInput::PngReadCallback keeps it): the sanitizer build does not leak-check
  // allocations made inside the decode.
  const __lsan::ScopedDisabler no_leak_check;
#endif
  OIIO::Filesystem::IOMemReader mem(bytes, n);
  auto in = OIIO::ImageInput::open(format, nullptr, &mem);
  if (!in) return fail("cannot decode: " + OIIO::geterror(), err, err_size);
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth != 1)
    return fail("not a 2D image", err, err_size);
  *width = spec.width;
  *height = spec.height;
  *channels = spec.nchannels;
  float* out = alloc(ctx, size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
  if (!out) return fail("out of memory", err, err_size);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, out))
    return fail("cannot decode: " + in->geterror(), err, err_size);
  return 0;
}
