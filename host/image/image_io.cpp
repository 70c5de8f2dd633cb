// Image files: path checks, atomic writes and comparisons. OpenImageIO itself lives in the image
// module (host/image/image_module.h), dlopen()ed here on the first image written or compared.
#include "host/image/image_io.h"

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <stdexcept>

#include "host/common/install_paths.h"
#include "host/common/memory.h"
#include "host/image/image_module.h"
#include "host/scene/scene.h"

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
  check_output_dir(path);
}

void check_output_dir(const std::string& path) {
  const fs::path dir = fs::absolute(fs::path(path)).parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(path + ": directory " + dir.string() + " does not exist");
  if (::access(dir.c_str(), W_OK) != 0)
    throw InputError(path + ": directory " + dir.string() + " is not writable");
}

namespace {

struct ImageModule {
  decltype(&vgpu_image_write) write = nullptr;
  decltype(&vgpu_image_compare) compare = nullptr;
  decltype(&vgpu_image_read) read = nullptr;
};

// Loads the module once, from the first of install_paths.h's candidates that loads (beside the
// binary, then an installed tree's lib/vgpu-rt/; the build writes it to build/lib/vgpu-rt/).
// Throws InputError naming `user` (the image being written or read) when it cannot.
const ImageModule& image_module(const std::string& user) {
  static std::once_flag once;
  static ImageModule m;
  static std::string error;
  std::call_once(once, [] {
    void* h = nullptr;
    std::string tried;
    for (const fs::path& p : image_module_candidates(VGPU_IMAGE_MODULE_NAME)) {
      std::error_code ec;
      if (!fs::exists(p, ec)) {
        tried += (tried.empty() ? "" : ", ") + p.string();
        continue;
      }
      if ((h = ::dlopen(p.c_str(), RTLD_NOW | RTLD_LOCAL))) break;
      const char* e = ::dlerror();
      if (error.empty() && e) error = e;
    }
    if (!h) {
      if (error.empty()) error = std::string(VGPU_IMAGE_MODULE_NAME) + " not found in " + tried;
      return;
    }
    m.write = reinterpret_cast<decltype(m.write)>(::dlsym(h, VGPU_IMAGE_WRITE));
    m.compare = reinterpret_cast<decltype(m.compare)>(::dlsym(h, VGPU_IMAGE_COMPARE));
    m.read = reinterpret_cast<decltype(m.read)>(::dlsym(h, VGPU_IMAGE_READ));
    if (!m.write || !m.compare || !m.read) {
      m = {};
      error = std::string(VGPU_IMAGE_MODULE_NAME) + " lacks its entry points";
    }
  });
  if (!m.write) throw InputError(user + ": cannot load the image module (" + error + ")");
  return m;
}

// The image module's first use, measured: the anonymous resident bytes before it, and after it
// those it added (image_library_bytes; its code is the process term's, file pages).
std::atomic<bool> g_used{false};
std::atomic<uint64_t> g_library_bytes{0};

class FirstUse {
 public:
  FirstUse() : first_(!g_used.exchange(true)), before_(first_ ? anon_resident_bytes() : 0) {}
  ~FirstUse() {
    if (!first_) return;
    const uint64_t now = anon_resident_bytes(), after = now > kept_ ? now - kept_ : 0;
    g_library_bytes = after > before_ ? after - before_ : 0;
  }
  // Bytes the call hands back to its caller (a decoded image's pixels): not the library's.
  void keep(uint64_t bytes) { kept_ = bytes; }
  FirstUse(const FirstUse&) = delete;
  FirstUse& operator=(const FirstUse&) = delete;

 private:
  bool first_;
  uint64_t before_, kept_ = 0;
};

}  // namespace

uint64_t image_library_bytes() {
  return g_library_bytes;
}

void write_image(const std::string& path, int width, int height, int channels,
                 const std::vector<float>& pixels) {
  check_image_path(path);
  const FirstUse use;
  const ImageModule& im = image_module(path);
  // Same extension, so the module picks the right writer for the temporary file.
  const fs::path p(path);
  std::string name = p.stem().string();
  name.insert(0, 1, '.');
  name += ".tmp" + std::to_string(::getpid()) + p.extension().string();
  const std::string tmp = (p.parent_path() / name).string();
  char err[512] = "";
  if (im.write(tmp.c_str(), width, height, channels, pixels.data(), err, sizeof err) != 0) {
    std::remove(tmp.c_str());
    throw InputError(path + ": " + err);
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw InputError(path + ": cannot write image: " + ec.message());
  }
}

ImagePixels decode_image(const std::vector<unsigned char>& bytes) {
  FirstUse use;
  const ImageModule& im = image_module("an image");
  ImagePixels out;
  auto alloc = [](void* ctx, size_t count) -> float* {
    auto& v = static_cast<ImagePixels*>(ctx)->pixels;
    v.assign(count, 0.0f);
    return v.data();
  };
  char err[512] = "";
  if (im.read(bytes.data(), bytes.size(), alloc, &out, &out.width, &out.height, &out.channels, err,
              sizeof err) != 0)
    throw std::runtime_error(err);
  use.keep(out.pixels.capacity() * sizeof(float));
  return out;
}

ImageComparison compare_images(const std::string& a, const std::string& b, double threshold) {
  const FirstUse use;
  const ImageModule& im = image_module(a);
  VgpuImageComparison r{};
  char err[512] = "";
  if (im.compare(a.c_str(), b.c_str(), threshold, &r, err, sizeof err) != 0) throw InputError(err);
  ImageComparison c;
  c.width = r.width;
  c.height = r.height;
  c.channels = r.channels;
  c.threshold = threshold;
  c.rms_error = r.rms_error;
  c.psnr = r.psnr;
  c.max_error = r.max_error;
  c.differing_share = r.failing_pixels / (double(r.width) * r.height);
  return c;
}

}  // namespace host
