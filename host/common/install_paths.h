// Where vgpu-rt finds the files it reads at run time (the bundled scenes, the image module),
// wherever it was installed: always relative to the binary that holds this code (the vgpu-rt
// executable, the Python extension, or a program of another project that links the library),
// never through a path of the build or source folders compiled in. The build tree is laid out
// as an installed tree is where it matters (host/common/CMakeLists.txt makes the links), so the
// same lookup serves both.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace host {

// The folders that may hold the bundled scenes, in the order they are tried:
//   1. set_scenes_dir()'s folder, if one was set;
//   2. $VGPU_RT_SCENES, if set (a user's own collection, or an installed tree moved apart);
//   3. for the binary holding this code and then the running executable, when they differ:
//      <dir>/scenes (the pip-installed Python package), <dir>/<bin to data>/scenes (an installed
//      bin/ beside share/vgpu-rt/; the build tree's build/share/vgpu-rt links to scenes/), and
//      <dir>/<Python package to data>/scenes (the package cmake --install puts in lib/);
//   4. <prefix>/share/vgpu-rt/scenes for each prefix add_install_prefix() was given.
std::vector<std::filesystem::path> scenes_dir_candidates();
// The first candidate that is a folder, links resolved, or an empty path when none is.
std::filesystem::path scenes_dir();
// Makes `dir` the first candidate (a program that knows where its scenes are; empty unsets).
void set_scenes_dir(const std::filesystem::path& dir);

// The files that may be the image module (host/image), in the order they are tried: beside the
// binary holding this code and beside the executable, then in lib/vgpu-rt/ relative to each
// (as for the scenes), then in <prefix>/lib/vgpu-rt/ for each add_install_prefix().
std::vector<std::filesystem::path> image_module_candidates(const std::string& file_name);

// Adds an installed tree's prefix to search (returns true, so that it can initialize a
// variable). A program of another project is built elsewhere than the library it links: the
// CMake package (find_package(vgpu_rt)) defines VGPU_RT_INSTALL_PREFIX for it, and the inline
// variable below then registers the prefix before main() runs.
bool add_install_prefix(const std::filesystem::path& prefix);

// The folder of the binary (executable or shared object) that holds this code, and of the
// running executable (/proc/self/exe); empty where it cannot be told.
std::filesystem::path code_dir();
std::filesystem::path executable_dir();

}  // namespace host

#ifdef VGPU_RT_INSTALL_PREFIX
namespace host::detail {
inline const bool install_prefix_added = host::add_install_prefix(VGPU_RT_INSTALL_PREFIX);
}  // namespace host::detail
#endif
