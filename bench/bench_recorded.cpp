// Benchmark: the recorded-program executor (vgpu/recorded_program.h) on whole frames, against the
// compiled functors. A 256x256 frame of the bunny (2 bounces, shadows, phong, the uniform grid)
// rendered six ways, alternating so that a noisy machine slows them alike: compiled; with the grid
// walk's traversal kernel as its recording; with the three kernels of the walk's inner loop
// recorded; with every kernel recorded (vgpu::Gpu::set_recorded); and with a shader of one's own
// (tests/support/user_stages.h's toon) compiled, then recorded as a kernel written outside the
// build is (host::recorded_stage: its stage uniforms named, set by the frame). Prints each
// frame's render ms (median of the repetitions), its ratio to the frame it is the recording of,
// and whether its image is that frame's bit for bit.
//   bench_recorded [--reps N] [--threads N] [--scene NAME] [--size WxH]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "host/trace/user_stage.h"
#include "tests/support/user_stages.h"

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 5, threads = 1, w = 256, h = 256;
  std::string scene_name = "bunny";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string o = argv[i], v = argv[i + 1];
    if (o == "--reps")
      reps = std::max(1, std::atoi(v.c_str()));
    else if (o == "--threads")
      threads = std::max(1, std::atoi(v.c_str()));
    else if (o == "--scene")
      scene_name = v;
    else if (o == "--size" && std::sscanf(v.c_str(), "%dx%d", &w, &h) == 2)
      ;
    else {
      std::fprintf(stderr,
                   "bench_recorded: unknown option %s (--reps N, --threads N, --scene NAME, "
                   "--size WxH)\n",
                   o.c_str());
      return 2;
    }
  }
  const host::Scene scene = host::load_scene(host::resolve_scene(scene_name));
  if (scene.lights.size() != 1) {
    std::fprintf(stderr, "bench_recorded: %s has %zu lights; the recorded shader here takes one\n",
                 scene_name.c_str(), scene.lights.size());
    return 2;
  }
  const host::Grid grid =
      host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile("gf5700")));
  const host::Camera cam = host::scene_camera(scene, float(w) / float(h));

  // shader: 0 the project's, 1 toon compiled, 2 toon recorded; base: the frame compared with.
  struct Variant {
    const char* label;
    int shader;
    std::vector<std::string> recorded;
    size_t base;
    std::vector<double> ms;
    host::RenderResult first;
  };
  std::vector<Variant> variants = {
      {"compiled", 0, {}, 0, {}, {}},
      {"traversal recorded", 0, {"traversal"}, 0, {}, {}},
      {"walk loop recorded", 0, {"traversal", "intersections", "next triangle"}, 0, {}, {}},
      {"every kernel recorded", 0, {"all"}, 0, {}, {}},
      {"toon shader compiled", 1, {}, 4, {}, {}},
      {"toon shader recorded", 2, {}, 4, {}, {}},
  };
  std::printf("bench_recorded: %s %dx%d, 2 bounces, shadows, grid; %d thread%s, %d repetitions\n",
              scene_name.c_str(), w, h, threads, threads > 1 ? "s" : "", reps);
  for (int r = 0; r < reps; ++r)
    for (Variant& v : variants) {
      host::RenderOptions opt;
      opt.width = w;
      opt.height = h;
      opt.threads = threads;
      opt.recorded_programs = v.recorded;
      // A shader of one's own, as a functor or as a kernel from outside the build is: recorded
      // once, its stage uniforms named.
      if (v.shader == 1) opt.user.shader = host::user_stage<test_support::Toon>();
      if (v.shader == 2) opt.user.shader = host::recorded_stage(test_support::Toon{});
      host::StreamTracer tracer(scene, grid, opt);
      host::RenderResult res = tracer.render(cam);
      v.ms.push_back(res.render_ms);
      if (r == 0) v.first = std::move(res);
      std::fprintf(stderr, "\r  repetition %d/%d", r + 1, reps);
    }
  std::fprintf(stderr, "\n");
  std::printf("%-24s %10s %-22s %8s %11s %7s\n", "frame", "render ms", "against", "ratio",
              "same image", "passes");
  for (const Variant& v : variants) {
    const Variant& b = variants[v.base];
    const double m = median(v.ms);
    std::printf("%-24s %10.1f %-22s %7.2fx %11s %7llu\n", v.label, m, b.label, m / median(b.ms),
                same_bits(v.first.rgb, b.first.rgb) ? "yes" : "NO",
                static_cast<unsigned long long>(v.first.stats.totals.passes));
  }
  return 0;
}
