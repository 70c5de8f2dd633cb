// Benchmark: the stream tracer on the paper's scenes at 256x256 — render ms (initialization
// apart; median of repetitions), passes and fragments, single- and multi-threaded — and peak
// resident memory. `bench_render million` renders a one-million-triangle sphere instead.
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"

namespace {

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;  // Linux reports KiB
}

// A UV sphere of about `target` triangles, radius 1 at the origin, with a camera and a light.
host::Scene sphere_scene(size_t target) {
  host::Scene s;
  s.name = "sphere-" + std::to_string(target);
  const int rings = int(std::sqrt(double(target) / 2.0));
  const int segs = int(target / (2 * size_t(rings)));
  auto at = [&](int i, int j) {
    const double th = M_PI * i / rings, ph = 2 * M_PI * j / segs;
    return glm::vec3(float(std::sin(th) * std::cos(ph)), float(std::cos(th)),
                     float(std::sin(th) * std::sin(ph)));
  };
  s.materials.push_back({glm::vec3(0.8f, 0.3f, 0.3f), 0.0f});
  uint32_t id = 0;
  auto tri = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    const uint32_t this_id = id++;
    if (glm::length(glm::cross(b - a, c - a)) == 0.0f) {
      ++s.dropped_degenerate;
      return;
    }
    s.add_triangle(a, b, c, glm::normalize(a), glm::normalize(b), glm::normalize(c), 0, this_id);
  };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segs; ++j) {
      tri(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      tri(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  s.input_triangles = id;
  s.lights.push_back({glm::vec3(3, 4, 5), glm::vec3(1.0f)});
  return s;
}

struct Run {
  double ms;
  host::RenderResult r;
};

void bench(const std::string& label, const host::Scene& scene, int bounces, int threads, int reps) {
  host::RenderOptions opt;
  const host::Grid grid = host::build_grid(
      scene, host::grid_spec_for(host::GridSpec{}, scene, vgpu::profile(opt.profile)));
  opt.bounces = bounces;
  opt.threads = threads;
  host::StreamTracer tracer(scene, grid, opt);
  const host::Camera cam = host::scene_camera(scene);
  std::vector<double> ms;
  host::RenderResult last;
  for (int i = 0; i < reps; ++i) {
    last = tracer.render(cam);
    ms.push_back(last.render_ms);
  }
  std::sort(ms.begin(), ms.end());
  const auto& t = last.stats.totals;
  std::printf("%-26s %7zu %3d %7d %10.1f %8.1f %8llu %12llu %12llu %10.1f %9.1f\n", label.c_str(),
              scene.triangle_count(), bounces, threads, ms[ms.size() / 2],
              tracer.init_ms() + grid.build_ms, static_cast<unsigned long long>(t.passes),
              static_cast<unsigned long long>(t.fragments_launched),
              static_cast<unsigned long long>(last.rays_traced),
              double(tracer.texture_bytes()) / 1e6, peak_rss_mb());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const int reps = 3;
  const int ncores = int(std::max(1u, std::thread::hardware_concurrency()));
  std::printf("%-26s %7s %3s %7s %10s %8s %8s %12s %12s %10s %9s\n", "scene", "tris", "bnc",
              "threads", "render ms", "init ms", "passes", "fragments", "rays", "tex MB",
              "peak MB");
  if (argc > 1 && std::strcmp(argv[1], "million") == 0) {
    const host::Scene s = sphere_scene(1'000'000);
    bench("sphere 1M, primary", s, 0, ncores, 1);
    return 0;
  }
  const std::vector<std::string> names = argc > 1 ? std::vector<std::string>(argv + 1, argv + argc)
                                                  : std::vector<std::string>{"bunny"};
  for (const std::string& name : names) {
    const host::Scene s = host::load_scene(host::resolve_scene(name), host::with_images());
    for (int threads : {1, ncores}) {
      bench(name + ", primary only", s, 0, threads, reps);
      bench(name + ", 3 reflections", s, 3, threads, reps);
    }
  }
  return 0;
}
