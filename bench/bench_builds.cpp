// Benchmark: the kd-tree's build with its events sorted once (KdEvents::presorted, the default)
// against the build that sorts every node's events again (KdEvents::per_node, the reference), on
// one host thread, in one run: median ms of --reps builds each, their ratio, and whether the two
// trees are the same (they must be). Scenes are names (scenes/) or glTF paths; default bunny,
// teapot and bunny-refl.
//
// Usage: bench_builds [--reps N] [SCENE ...]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "host/accel/kdtree.h"
#include "host/scene/gltf_loader.h"

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

bool same(const host::KdTree& a, const host::KdTree& b) {
  if (a.nodes.size() != b.nodes.size() || a.lists != b.lists || a.sah_cost != b.sah_cost)
    return false;
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    const host::KdNode &x = a.nodes[i], &y = b.nodes[i];
    if (x.split != y.split || x.axis != y.axis || x.right != y.right || x.count != y.count)
      return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 5;
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--reps" && i + 1 < argc) {
      reps = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--help" || a == "-h") {
      std::puts(
          "Usage: bench_builds [--reps N] [SCENE ...]\n"
          "The kd-tree build, events sorted once against sorted per node (median ms).");
      return 0;
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
    const host::Grid box = host::build_grid(scene, host::GridSpec{glm::ivec3(1)});
    std::vector<double> ms[2];
    host::KdTree trees[2];
    for (int r = 0; r < reps; ++r)
      for (int m = 0; m < 2; ++m) {  // alternated, so that drift falls on both alike
        host::KdSpec spec;
        spec.events = m == 0 ? host::KdEvents::per_node : host::KdEvents::presorted;
        const auto t0 = std::chrono::steady_clock::now();
        trees[m] = host::build_kdtree(scene, box.lo, box.hi, spec);
        ms[m].push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count());
      }
    const double slow = median(ms[0]), fast = median(ms[1]);
    const bool ok = same(trees[0], trees[1]);
    all_same = all_same && ok;
    std::printf("%-28s %10zu %12.1f %12.1f %6.2fx %s\n", name.c_str(), scene.triangle_count(), slow,
                fast, slow / fast, ok ? "yes" : "NO");
    std::fflush(stdout);
  }
  return all_same ? 0 : 1;
}
