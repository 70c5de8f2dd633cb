// Benchmark: the kd-tree's build with its events sorted once (KdEvents::presorted, the default)
// against the build that sorts every node's events again (KdEvents::per_node, the reference), on
// one host thread, in one run: median ms of --reps builds each (KdTree::build_ms), their ratio,
// and whether the two trees are the same (they must be).
//
// Usage: bench_builds [--reps N] [SCENE ...]
//   SCENE: a bundled scene's name (scenes/) or a glTF path; default bunny, teapot, bunny-refl.
// Exit codes: 0 the trees are the same everywhere, 1 they differ somewhere, 2 bad arguments or a
// scene that does not load (one line on stderr).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "host/accel/kdtree.h"
#include "host/scene/gltf_loader.h"

namespace {

constexpr const char* kUsage =
    "Usage: bench_builds [--reps N] [SCENE ...]\n"
    "The kd-tree's build, events sorted once against sorted per node: median ms of N builds each\n"
    "(default 5), their ratio, and whether the trees are the same. SCENE is a bundled scene's\n"
    "name or a glTF path (default: bunny teapot bunny-refl). Exit 0: the same trees; 1: they\n"
    "differ; 2: bad arguments or a scene that does not load.\n";

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

int refuse(const std::string& why) {
  std::fprintf(stderr, "bench_builds: %s\n%s", why.c_str(), kUsage);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 5;
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (a == "--reps") {
      if (i + 1 == argc) return refuse("--reps needs a count");
      const std::string n = argv[++i];
      char* end = nullptr;
      const long v = std::strtol(n.c_str(), &end, 10);
      if (n.empty() || *end != '\0' || v < 1 || v > 1000)
        return refuse("--reps " + n + ": not a count from 1 to 1000");
      reps = int(v);
    } else if (!a.empty() && a[0] == '-') {
      return refuse(a + ": not an option");
    } else {
      scenes.push_back(a);
    }
  }
  if (scenes.empty()) scenes = {"bunny", "teapot", "bunny-refl"};
  std::printf("%-28s %10s %12s %12s %7s %s\n", "scene", "triangles", "per node ms", "presorted ms",
              "ratio", "same tree");
  bool all_same = true;
  for (const std::string& name : scenes) {
    host::Scene scene;
    try {
      scene = host::load_scene(host::resolve_scene(name));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_builds: %s\n", e.what());
      return 2;
    }
    const auto box = scene.box();
    std::vector<double> ms[2];
    host::KdTree trees[2];
    for (int r = 0; r < reps; ++r)
      for (int m = 0; m < 2; ++m) {  // alternated, so that drift falls on both alike
        host::KdSpec spec;
        spec.events = m == 0 ? host::KdEvents::per_node : host::KdEvents::presorted;
        trees[m] = host::build_kdtree(scene, box.lo, box.hi, spec);
        ms[m].push_back(trees[m].build_ms);
      }
    const double slow = median(ms[0]), fast = median(ms[1]);
    const bool ok = host::same_tree(trees[0], trees[1]);
    all_same = all_same && ok;
    std::printf("%-28s %10zu %12.1f %12.1f %6.2fx %s\n", name.c_str(), scene.triangle_count(), slow,
                fast, slow / fast, ok ? "yes" : "NO");
    std::fflush(stdout);
  }
  return all_same ? 0 : 1;
}
