// The run-time lookup of install_paths.h. VGPU_RT_BIN_TO_DATA and VGPU_RT_BIN_TO_LIB are the
// relative paths from the install tree's bin/ to its share/vgpu-rt/ and lib/vgpu-rt/ folders
// (CMake computes them from GNUInstallDirs), and VGPU_RT_PYTHON_TO_DATA / VGPU_RT_PYTHON_TO_LIB
// from the installed Python package's folder: relative, so an installed tree can be moved.
#include "host/common/install_paths.h"

#include <dlfcn.h>

#include <cstdlib>
#include <mutex>

namespace host {

namespace fs = std::filesystem;

namespace {

std::mutex& dir_mutex() {
  static std::mutex m;
  return m;
}

fs::path& scenes_override() {
  static fs::path p;
  return p;
}

std::vector<fs::path>& prefixes() {
  static std::vector<fs::path> p;
  return p;
}

// The folders to search from: the code's binary, then the executable (when it is another).
std::vector<fs::path> base_dirs() {
  std::vector<fs::path> out;
  for (const fs::path& d : {code_dir(), executable_dir()}) {
    if (d.empty()) continue;
    bool seen = false;
    for (const fs::path& o : out) {
      std::error_code ec;
      seen = seen || o == d || fs::equivalent(o, d, ec);
    }
    if (!seen) out.push_back(d);
  }
  return out;
}

}  // namespace

fs::path code_dir() {
  Dl_info info{};
  if (::dladdr(reinterpret_cast<const void*>(&code_dir), &info) == 0 || !info.dli_fname ||
      !*info.dli_fname)
    return {};
  std::error_code ec;
  const fs::path p = fs::canonical(info.dli_fname, ec);
  // The main executable may be reported by the name it was started with: then the executable's
  // own folder (executable_dir) stands for it.
  return ec ? fs::path() : p.parent_path();
}

fs::path executable_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

std::vector<fs::path> scenes_dir_candidates() {
  std::vector<fs::path> out;
  {
    std::lock_guard lock(dir_mutex());
    if (!scenes_override().empty()) out.push_back(scenes_override());
  }
  if (const char* env = std::getenv("VGPU_RT_SCENES"); env && *env) out.emplace_back(env);
  for (const fs::path& d : base_dirs()) {
    out.push_back(d / "scenes");
    out.push_back((d / VGPU_RT_BIN_TO_DATA / "scenes").lexically_normal());
    out.push_back((d / VGPU_RT_PYTHON_TO_DATA / "scenes").lexically_normal());
  }
  std::lock_guard lock(dir_mutex());
  for (const fs::path& p : prefixes()) out.push_back(p / VGPU_RT_PREFIX_TO_DATA / "scenes");
  return out;
}

fs::path scenes_dir() {
  for (const fs::path& d : scenes_dir_candidates()) {
    std::error_code ec;
    if (!fs::is_directory(d, ec)) continue;
    // Links resolved: the build folder's share/vgpu-rt/scenes is the source tree's scenes/.
    const fs::path real = fs::canonical(d, ec);
    return ec ? d : real;
  }
  return {};
}

bool add_install_prefix(const fs::path& prefix) {
  std::lock_guard lock(dir_mutex());
  prefixes().push_back(prefix);
  return true;
}

void set_scenes_dir(const fs::path& dir) {
  std::lock_guard lock(dir_mutex());
  scenes_override() = dir;
}

std::vector<fs::path> image_module_candidates(const std::string& file_name) {
  std::vector<fs::path> out;
  const std::vector<fs::path> bases = base_dirs();
  for (const fs::path& d : bases) out.push_back(d / file_name);
  for (const fs::path& d : bases) {
    out.push_back((d / VGPU_RT_BIN_TO_LIB / file_name).lexically_normal());
    out.push_back((d / VGPU_RT_PYTHON_TO_LIB / file_name).lexically_normal());
  }
  std::lock_guard lock(dir_mutex());
  for (const fs::path& p : prefixes()) out.push_back(p / VGPU_RT_PREFIX_TO_LIB / file_name);
  return out;
}

}  // namespace host
