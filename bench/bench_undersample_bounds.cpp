// Benchmark: how far undersampling's choice of traced pixels can go (--aa undersample:2). On
// each scene the CPU tracer renders every pixel once; the lattice's fill (host/trace/sampling.h,
// the same as rellenarHuecos) is then evaluated for every other pixel, so that one run tells,
// for any choice of gaps to trace, which pixels would change. Per scene and threshold T:
//   - the lattice's share of the pixels, and the rays left to a third of them (the budget);
//   - the pixels the fill changes (by more than 1/255, 8-bit) if no gap were traced;
//   - the floor: what no choice of gaps within the budget can avoid (the changed gaps beyond it);
//   - the best after tracing every gap whose lattice pixels hit different surfaces (the key
//     marks, which catch silhouettes);
//   - marcarHuecos' own rule at T (keys, or colour spread > T), and its ranking (keys first, then
//     spread, largest first) cut at exactly a third of the rays.
// scripts/docs/sampling.py runs it (--json) for docs/studies/sampling.md's section on these bounds.
// --images DIR also writes, per scene and threshold, the one-ray image, the rule's image and the
// CPU tracer's undersample:2 image as PFM files (tests/bench compares them itself).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/sampling.h"

namespace {

constexpr int kStep = 2;  // the K

// A channel as the PNG stores it: clamped to [0, 1], 8 bits.
double as_8bit(double v) {
  return std::round(std::clamp(v, 0.0, 1.0) * 255.0) / 255.0;
}

// A PFM file (portable float map: "PF", width, height, -1 for little-endian, then RGB floats
// row by row from the bottom row up).
bool write_pfm(const std::string& path, int w, int h, const std::vector<float>& rgb) {
  std::ofstream f(path, std::ios::binary);
  f << "PF\n" << w << " " << h << "\n-1.0\n";
  for (int y = h - 1; y >= 0; --y)
    f.write(reinterpret_cast<const char*>(rgb.data() + size_t(y) * size_t(w) * 3),
            std::streamsize(size_t(w) * 3 * sizeof(float)));
  return bool(f);
}

std::vector<float> to_floats(const std::vector<glm::dvec3>& c) {
  std::vector<float> rgb;
  rgb.reserve(c.size() * 3);
  for (const glm::dvec3& p : c)
    for (int k = 0; k < 3; ++k) rgb.push_back(float(p[k]));
  return rgb;
}

bool changes(const glm::dvec3& a, const glm::dvec3& b) {
  for (int c = 0; c < 3; ++c)
    if (std::fabs(as_8bit(a[c]) - as_8bit(b[c])) > 1.0 / 255.0 + 1e-9) return true;
  return false;
}

struct Bound {
  std::string scene;
  double threshold = 0;
  double lattice = 0, budget = 0;          // shares of the pixels
  double keys = 0;                         // gaps the key marks trace
  double fill_changes = 0;                 // gaps the fill changes, none traced
  double floor = 0;                        // changed pixels no choice within the budget avoids
  double after_keys = 0;                   // the best choice once the key marks are traced
  double rule_rays = 0, rule_changed = 0;  // marcarHuecos at T
  double ranked_changed = 0;               // its ranking cut at a third of the rays
  double pixels_per_triangle = 0;          // pixels that hit a surface / distinct triangles hit
  bool rule_matches_tracer = false;        // the rule's image is render_cpu's undersample:2 (1e-5)
};

// The one-ray render every threshold's figures start from: its colours, surface keys (the
// material hit, -1 for none) and pixels per triangle hit.
struct FullRender {
  std::vector<glm::dvec3> colour;
  std::vector<int> key;
  double pixels_per_triangle = 0;
};

FullRender full_render(const host::Scene& scene, const host::Grid& grid, const host::Camera& camera,
                       const host::RenderOptions& opt) {
  const host::RenderResult full = host::render_cpu(scene, grid, camera, opt);
  const size_t n = size_t(opt.width) * size_t(opt.height);
  FullRender r;
  r.colour.resize(n);
  r.key.resize(n);
  std::set<int> triangles;
  size_t hits = 0;
  for (size_t i = 0; i < n; ++i) {
    r.colour[i] = {full.rgb[i * 3], full.rgb[i * 3 + 1], full.rgb[i * 3 + 2]};
    const int tri = int(full.hit_id[i]);
    r.key[i] = tri < 0 ? -1 : int(scene.material[size_t(tri)]);
    if (tri >= 0) {
      triangles.insert(tri);
      ++hits;
    }
  }
  r.pixels_per_triangle = triangles.empty() ? 0 : double(hits) / double(triangles.size());
  return r;
}

// `images`: a path prefix for the three images (empty: none written); throws std::runtime_error
// if one cannot be written.
Bound bound(const std::string& name, const host::Scene& scene, const host::Grid& grid,
            const host::Camera& camera, const host::RenderOptions& opt, const FullRender& full,
            double threshold, const std::string& images) {
  const int W = opt.width, H = opt.height;
  const size_t n = size_t(W) * size_t(H);
  const std::vector<glm::dvec3>& colour = full.colour;
  const std::vector<int>& key = full.key;
  struct Gap {
    host::GapTest test;
    bool changed;
  };
  std::vector<Gap> gaps;
  size_t lattice = 0;
  std::vector<glm::dvec3> rule_image = colour;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (host::on_lattice(x, y, kStep, W, H)) {
        ++lattice;
        continue;
      }
      const size_t i = size_t(y) * size_t(W) + size_t(x);
      const glm::dvec3 f = host::undersample_fill(colour, x, y, kStep, W, H, threshold);
      const host::GapTest t = host::undersample_gap_test(colour, key, x, y, kStep, W, H);
      gaps.push_back({t, changes(f, colour[i])});
      if (!t.keys_differ && !(t.spread > threshold)) rule_image[i] = f;
    }
  Bound b;
  b.scene = name;
  b.threshold = threshold;
  b.pixels_per_triangle = full.pixels_per_triangle;
  const long third = long(n / 3);
  const long budget = third - long(lattice);
  b.lattice = double(lattice) / double(n);
  b.budget = double(budget) / double(n);
  size_t fill_changes = 0, keyed = 0, changed_after_keys = 0, rule_rays = lattice, rule_changed = 0;
  for (const Gap& g : gaps) {
    fill_changes += g.changed;
    keyed += g.test.keys_differ;
    if (!g.test.keys_differ) changed_after_keys += g.changed;
    if (g.test.keys_differ || g.test.spread > threshold)
      ++rule_rays;
    else
      rule_changed += g.changed;
  }
  b.fill_changes = double(fill_changes) / double(n);
  b.keys = double(keyed) / double(n);
  b.floor = double(std::max(0L, long(fill_changes) - budget)) / double(n);
  b.after_keys =
      double(std::max(0L, long(changed_after_keys) - std::max(0L, budget - long(keyed)))) /
      double(n);
  b.rule_rays = double(rule_rays) / double(n);
  b.rule_changed = double(rule_changed) / double(n);
  // The rule's ranking: key marks first, then the colour spread, largest first; the first
  // `budget` gaps are traced.
  std::stable_sort(gaps.begin(), gaps.end(), [](const Gap& p, const Gap& q) {
    if (p.test.keys_differ != q.test.keys_differ) return p.test.keys_differ;
    return p.test.spread > q.test.spread;
  });
  size_t ranked_changed = 0;
  for (size_t i = size_t(std::max(0L, budget)); i < gaps.size(); ++i)
    ranked_changed += gaps[i].changed;
  b.ranked_changed = double(ranked_changed) / double(n);
  // The rule's image here against the CPU tracer's own undersample:2 (the same pixels).
  host::RenderOptions u = opt;
  u.undersample = kStep;
  u.aa_threshold = float(threshold);
  const host::RenderResult under = host::render_cpu(scene, grid, camera, u);
  b.rule_matches_tracer = true;
  for (size_t i = 0; i < n && b.rule_matches_tracer; ++i)
    for (int c = 0; c < 3; ++c)
      // The tracer blends its double colours, this its float image's: equal to float rounding.
      if (std::fabs(double(under.rgb[i * 3 + size_t(c)]) - rule_image[i][c]) > 1e-5)
        b.rule_matches_tracer = false;
  if (!images.empty()) {
    const std::vector<float>& tracer = under.rgb;
    for (const auto& [suffix, rgb] :
         {std::pair{"_full.pfm", to_floats(colour)}, std::pair{"_rule.pfm", to_floats(rule_image)},
          std::pair{"_tracer.pfm", tracer}})
      if (!write_pfm(images + suffix, W, H, rgb))
        throw std::runtime_error(images + suffix + ": could not be written");
  }
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "bench_undersample_bounds: how far any choice of traced pixels can take "
      "--aa undersample:2 (the CPU tracer's images, 8-bit)"};
  int size = 256;
  std::vector<std::string> scenes = {"sphere",    "bunny",        "bunny-refl", "classic",
                                     "bunny-low", "bunny-mirror", "hop",        "sphere-alone",
                                     "teapot",    "textured"};
  std::vector<double> thresholds = {0.1, 0.05, 0.02};
  std::string json_path, images_dir;
  app.add_option("--size", size, "Image width and height")->check(CLI::Range(8, 2048));
  app.add_option("--scenes", scenes, "Bundled scene names or glTF files");
  app.add_option("--thresholds", thresholds, "--aa-threshold values")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--json", json_path, "Also write the figures to this JSON file");
  app.add_option("--images", images_dir,
                 "Also write each scene and threshold's one-ray, rule and tracer images to this "
                 "folder, as N_full.pfm, N_rule.pfm and N_tracer.pfm (N: the row, from 0)");
  CLI11_PARSE(app, argc, argv);

  std::vector<Bound> rows;
  for (const std::string& name : scenes) {
    host::Scene scene;
    try {
      scene = host::load_scene(host::resolve_scene(name), host::with_images());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_undersample_bounds: scene %s: %s\n", name.c_str(), e.what());
      return 2;
    }
    const vgpu::Profile& gf6600 = vgpu::profile("gf6600");
    const host::Grid grid =
        host::build_grid(scene, host::grid_spec_for(host::GridSpec{}, scene, gf6600));
    const host::Camera camera = host::scene_camera(scene, 1.0f);
    host::RenderOptions opt;
    opt.width = opt.height = size;
    opt.profile = gf6600.name;
    const FullRender full = full_render(scene, grid, camera, opt);
    for (const double t : thresholds) {
      std::fprintf(stderr, "bench_undersample_bounds: %s, T %g\n", name.c_str(), t);
      const std::string images =
          images_dir.empty() ? "" : images_dir + "/" + std::to_string(rows.size());
      try {
        rows.push_back(bound(name, scene, grid, camera, opt, full, t, images));
      } catch (const std::runtime_error& e) {
        std::fprintf(stderr, "bench_undersample_bounds: %s\n", e.what());
        return 1;
      }
    }
  }
  std::printf("%dx%d, K = %d; shares of the pixels; changed: by more than 1/255 (8-bit)\n", size,
              size, kStep);
  std::printf("%-13s %5s %8s %8s %7s %9s %8s %10s %13s %14s %9s\n", "scene", "T", "lattice",
              "budget", "keys", "fill chg", "floor", "after keys", "rule rays/chg", "ranked at 1/3",
              "px / tri");
  for (const Bound& b : rows)
    std::printf(
        "%-13s %5.2f %7.2f%% %7.2f%% %6.2f%% %8.2f%% %7.2f%% %9.2f%% %6.3f/%5.2f%% "
        "%13.2f%% %9.1f%s\n",
        b.scene.c_str(), b.threshold, 100 * b.lattice, 100 * b.budget, 100 * b.keys,
        100 * b.fill_changes, 100 * b.floor, 100 * b.after_keys, b.rule_rays, 100 * b.rule_changed,
        100 * b.ranked_changed, b.pixels_per_triangle,
        b.rule_matches_tracer ? "" : "  (rule's image differs from render_cpu's!)");
  bool all_match = true;
  for (const Bound& b : rows) all_match = all_match && b.rule_matches_tracer;
  if (!json_path.empty()) {
    nlohmann::json bounds = nlohmann::json::array();
    for (const Bound& b : rows)
      bounds.push_back({{"scene", b.scene},
                        {"threshold", b.threshold},
                        {"lattice", b.lattice},
                        {"budget", b.budget},
                        {"keys", b.keys},
                        {"fill_changes", b.fill_changes},
                        {"floor", b.floor},
                        {"after_keys", b.after_keys},
                        {"rule_rays", b.rule_rays},
                        {"rule_changed", b.rule_changed},
                        {"ranked_changed", b.ranked_changed},
                        {"pixels_per_triangle", b.pixels_per_triangle},
                        {"rule_matches_tracer", b.rule_matches_tracer}});
    std::ofstream f(json_path);
    f << nlohmann::json{{"size", size}, {"k", kStep}, {"bounds", bounds}}.dump(1) << "\n";
    if (!f) {
      std::fprintf(stderr, "bench_undersample_bounds: %s: could not be written\n",
                   json_path.c_str());
      return 1;
    }
  }
  return all_match ? 0 : 1;
}
