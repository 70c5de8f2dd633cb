// OpenImageIO glue: atomic image writes and image comparison.
#include "host/image_io.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "host/scene.h"

namespace host {

namespace fs = std::filesystem;

static std::string lower_ext(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

void check_image_path(const std::string& path) {
  check_output_path(path, {".png", ".exr"});
}

void check_output_path(const std::string& path, const std::vector<std::string>& extensions) {
  const std::string e = lower_ext(path);
  if (std::find(extensions.begin(), extensions.end(), e) == extensions.end()) {
    std::string known;
    for (const std::string& k : extensions) known += (known.empty() ? "" : " or ") + k;
    throw InputError(path + ": unsupported extension '" + e + "' (use " + known + ")");
  }
  const fs::path dir = fs::absolute(fs::path(path)).parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(path + ": directory " + dir.string() + " does not exist");
  if (::access(dir.c_str(), W_OK) != 0)
    throw InputError(path + ": directory " + dir.string() + " is not writable");
}

void write_image(const std::string& path, int width, int height, int channels,
                 const std::vector<float>& pixels) {
  check_image_path(path);
  const bool png = lower_ext(path) == ".png";
  OIIO::ImageSpec spec(width, height, channels,
                       png ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
  // Same extension, so OpenImageIO picks the right writer for the temporary file.
  const fs::path p(path);
  std::string name = p.stem().string();
  name.insert(0, 1, '.');
  name += ".tmp" + std::to_string(::getpid()) + p.extension().string();
  const std::string tmp = (p.parent_path() / name).string();
  auto out = OIIO::ImageOutput::create(tmp);
  if (!out) throw InputError(path + ": cannot create an image writer: " + OIIO::geterror());
  bool ok = out->open(tmp, spec);
  if (ok) ok = out->write_image(OIIO::TypeDesc::FLOAT, pixels.data());
  if (ok) ok = out->close();
  if (!ok) {
    std::string err = out->geterror();
    std::remove(tmp.c_str());
    for (char& c : err)
      if (c == '\n') c = ' ';
    throw InputError(path + ": cannot write image: " + err);
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw InputError(path + ": cannot write image: " + ec.message());
  }
}

ImageComparison compare_images(const std::string& a, const std::string& b, double threshold) {
  OIIO::ImageBuf A(a), B(b);
  if (!A.read(0, 0, true, OIIO::TypeDesc::FLOAT))
    throw InputError(a + ": cannot read image: " + A.geterror());
  if (!B.read(0, 0, true, OIIO::TypeDesc::FLOAT))
    throw InputError(b + ": cannot read image: " + B.geterror());
  const OIIO::ImageSpec &sa = A.spec(), &sb = B.spec();
  if (sa.width != sb.width || sa.height != sb.height || sa.nchannels != sb.nchannels)
    throw InputError(b + ": size " + std::to_string(sb.width) + "x" + std::to_string(sb.height) +
                     "x" + std::to_string(sb.nchannels) + " differs from " + a + " (" +
                     std::to_string(sa.width) + "x" + std::to_string(sa.height) + "x" +
                     std::to_string(sa.nchannels) + ")");
  const auto r = OIIO::ImageBufAlgo::compare(A, B, float(threshold), float(threshold));
  ImageComparison c;
  c.width = sa.width;
  c.height = sa.height;
  c.channels = sa.nchannels;
  c.threshold = threshold;
  c.rms_error = r.rms_error;
  c.psnr = r.PSNR;
  c.max_error = r.maxerror;
  c.differing_share = double(r.nfail) / (double(sa.width) * sa.height);
  return c;
}

}  // namespace host
