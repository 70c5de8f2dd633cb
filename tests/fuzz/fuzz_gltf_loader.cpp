// libFuzzer target: every input is written to a file and loaded with host::load_scene, then as a
// host::AnimatedScene posed at two times of each of its first animations. InputError
// is the only acceptable failure; any other exception, crash, sanitizer report, hang or runaway
// allocation is a loader bug. Build and run with scripts/ci/fuzz.sh.
#include <unistd.h>

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "host/scene/animation.h"
#include "host/scene/gltf_loader.h"

namespace {

// A private directory, so relative buffer URIs in the input only find the input itself.
const std::string& scratch_dir() {
  static const std::string dir = [] {
    char name[] = "/tmp/vgpu_fuzz_gltf_XXXXXX";
    if (!mkdtemp(name)) std::abort();
    return std::string(name);
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The loader sniffs the content; the suffix only varies what the file is called.
  const bool text = size > 0 && (data[0] == '{' || std::isspace(data[0]));
  const std::string path = scratch_dir() + (text ? "/input.gltf" : "/input.glb");
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  try {
    // A lower triangle cap than the default keeps legal-but-huge instancing within -rss_limit_mb.
    host::load_scene(path, host::LoadOptions{1'000'000});
  } catch (const host::InputError&) {
  }
  try {
    // The same file with its animations read and each posed mid-way and past its end, then all
    // of them together, as the CLI plays them by default (UnsupportedFeature is an InputError,
    // and so is a clash of two animations on one node's path).
    const host::AnimatedScene a(path, host::LoadOptions{1'000'000});
    for (size_t i = 0; i < a.animations().size() && i < 4; ++i) {
      a.at(i, 0.5 * (a.animations()[i].start + a.animations()[i].end));
      a.at(i, a.animations()[i].end + 1.0);
    }
    if (a.clash(a.all()).empty())
      a.at(a.all(), 0.5 * (a.span(a.all()).first + a.span(a.all()).second));
  } catch (const host::InputError&) {
  }
  std::remove(path.c_str());
  return 0;
}
