// Benchmark: the stream engine's host time against the project's CPU tracer, scene by scene, at
// 1 and 2 threads (render ms, initialization apart, median of repetitions). The stream engine
// runs its grid walk both ways (RenderOptions::batch_walk): pass by pass over the target, and in
// batches of 8 pixels through every pass (the default); the three renders alternate, so a noisy
// machine slows them alike. The scenes: bunny (primary rays), bunny-refl (2 bounces), a
// 2000-triangle fan whose centre crowds one voxel column, and a generated 320k-triangle terrain;
// 256x256, no shadows. Also the work the stream engine cannot skip: its passes and the fragments
// that ran (fragment-steps, counted with the finished-ray mask as an early-z test). Figures in
// docs/studies/speed.md.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/stream/stream_tracer.h"

namespace {

struct Case {
  std::string label;
  host::Scene scene;
  host::Grid grid;
  host::Camera camera;
  int bounces = 0;
  int reps = 5;
};

host::Camera look(glm::vec3 pos, glm::vec3 fwd, float yfov) {
  host::Camera c;
  c.position = pos;
  c.forward = glm::normalize(fwd);
  const glm::vec3 up(0, 1, 0);
  c.up = glm::normalize(up - glm::dot(up, c.forward) * c.forward);
  c.yfov = yfov;
  return c;
}

host::Grid auto_grid(const host::Scene& s) {
  return host::build_grid(s, host::grid_spec_for(host::GridSpec{}, s, vgpu::profile("gf5700")));
}

Case scene_file(const std::string& name, int bounces) {
  Case c;
  c.label = name + (bounces ? ", " + std::to_string(bounces) + " bounces" : ", primary");
  c.scene = host::load_scene(host::resolve_scene(name), host::with_images());
  c.grid = auto_grid(c.scene);
  c.camera = host::scene_camera(c.scene);
  c.bounces = bounces;
  return c;
}

// The stability suite's fan (tests/trace/stability_cases.h, case 9) with n triangles: every one
// shares the centre vertex on the voxel edge x = y = 2 of a 4x4x4 grid over [0, 4]^3, so the
// voxel column around it lists all of them.
Case crowded_fan(int n) {
  Case c;
  c.label = "fan " + std::to_string(n) + ", crowded voxel";
  c.scene.materials = {{{0.8f, 0.8f, 0.8f}, 0.0f}};
  const double r = 1.7, pi = 3.14159265358979323846;
  const glm::vec3 ct(2, 2, 1.5f);
  for (int k = 0; k < n; ++k) {
    const double a0 = 2 * pi * k / n, a1 = 2 * pi * (k + 1) / n;
    c.scene.add_flat_triangle(
        ct, ct + glm::vec3(float(r * std::cos(a0)), float(r * std::sin(a0)), 0),
        ct + glm::vec3(float(r * std::cos(a1)), float(r * std::sin(a1)), 0), 0, uint32_t(k));
  }
  c.scene.input_triangles = uint32_t(n);
  c.scene.lights.push_back({glm::vec3(2, 2, 8), glm::vec3(1.0f)});
  c.grid = host::build_grid_in_box(c.scene, glm::vec3(0), glm::vec3(4), glm::ivec3(4), 1);
  c.camera = look({2, 2, 9}, {0, 0, -1}, 0.5f);
  c.reps = 3;
  return c;
}

// A rolling heightfield of 2 * side^2 triangles over [-1, 1]^2, seen from above at an angle.
Case terrain(int side) {
  Case c;
  c.scene.materials = {{{0.4f, 0.6f, 0.3f}, 0.0f}};
  auto h = [](float x, float z) {
    return 0.08f * std::sin(7.0f * x) * std::cos(5.0f * z) +
           0.03f * std::sin(23.0f * x + 11.0f * z);
  };
  auto p = [&](int i, int j) {
    const float x = -1.0f + 2.0f * float(i) / float(side),
                z = -1.0f + 2.0f * float(j) / float(side);
    return glm::vec3(x, h(x, z), z);
  };
  uint32_t id = 0;
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j) {
      c.scene.add_flat_triangle(p(i, j), p(i, j + 1), p(i + 1, j + 1), 0, id++);
      c.scene.add_flat_triangle(p(i, j), p(i + 1, j + 1), p(i + 1, j), 0, id++);
    }
  c.scene.input_triangles = id;
  c.label = "terrain " + std::to_string(id / 1000) + "k";
  c.scene.lights.push_back({glm::vec3(1, 3, 2), glm::vec3(1.0f)});
  c.grid = auto_grid(c.scene);
  c.camera = look({0, 1.4f, 2.2f}, {0, -0.55f, -1}, 0.8f);
  c.reps = 3;
  return c;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::function<Case()>> makers = {
      [] { return scene_file("bunny", 0); }, [] { return scene_file("bunny-refl", 2); },
      [] { return crowded_fan(2000); }, [] { return terrain(400); }};
  // `bench_speed quick`: the first case only; `bench_speed case K`: case K (0-based) only.
  const bool quick = argc > 1 && std::strcmp(argv[1], "quick") == 0;
  const int only = argc > 2 && std::strcmp(argv[1], "case") == 0 ? std::atoi(argv[2]) : -1;
  std::printf("%-26s %6s %7s %10s %10s %8s %9s %9s %6s %8s\n", "scene (256x256, no shadows)",
              "tris", "threads", "passes ms", "batches ms", "cpu ms", "batch/cpu", "pass/batch",
              "passes", "ran");
  for (size_t k = 0; k < (quick ? 1 : makers.size()); ++k) {
    if (only >= 0 && int(k) != only) continue;
    const Case c = makers[k]();
    // The work the stream engine cannot skip: its passes, and the fragments that ran (the
    // shaded ones when the finished-ray mask is an early-z test instead of a host shortcut).
    uint64_t passes = 0, ran = 0;
    {
      host::RenderOptions opt;
      opt.bounces = c.bounces;
      opt.shadows = false;
      opt.masks = true;
      const vgpu::Counters t =
          host::StreamTracer(c.scene, c.grid, opt).render(c.camera).stats.totals;
      passes = t.passes;
      ran = t.fragments_shaded;
    }
    for (int threads : {1, 2}) {
      host::RenderOptions opt;
      opt.bounces = c.bounces;
      opt.shadows = false;
      opt.threads = threads;
      host::RenderOptions by_pass = opt;
      by_pass.batch_walk = false;
      host::StreamTracer batched(c.scene, c.grid, opt), passwise(c.scene, c.grid, by_pass);
      std::vector<double> batch_ms, pass_ms, cpu_ms;
      for (int i = 0; i < c.reps; ++i) {
        pass_ms.push_back(passwise.render(c.camera).render_ms);
        batch_ms.push_back(batched.render(c.camera).render_ms);
        cpu_ms.push_back(host::render_cpu(c.scene, c.grid, c.camera, opt).render_ms);
      }
      const double b = median(batch_ms), p = median(pass_ms), u = median(cpu_ms);
      std::printf("%-26s %6zu %7d %10.1f %10.1f %8.1f %8.2fx %8.2fx %6llu %7.2fM\n",
                  c.label.c_str(), c.scene.triangle_count(), threads, p, b, u, b / u, p / b,
                  static_cast<unsigned long long>(passes), double(ran) / 1e6);
      std::fflush(stdout);
    }
  }
  return 0;
}
