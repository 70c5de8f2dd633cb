// Benchmark: the sampling modes (--spp, --aa adaptive, --aa undersample) on bundled scenes, in
// one run: primary rays per pixel (mean, max), passes, the cost model's ms on gf5700 / gf6600 /
// h200, the emulator's render ms (median of runs), and the error against the CPU tracer's
// 256-sample image. scripts/docs/sampling.py runs it (--json) to write docs/studies/sampling.md.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/model/cost_model.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/sampling.h"
#include "host/trace/stream/stream_tracer.h"
#include "host/trace/validate.h"

namespace {

struct Mode {
  std::string label;
  int spp = 1;
  bool adaptive = false;
  float threshold = 0.1f;
  int undersample = 0;
  bool object = false;  // --aa-criterion object (kernels/cones.h)
  float cone_depth = 2.0f;
  // Dense streams (RenderOptions::compact); false: the gated frames over the whole target, as
  // before issue 35 (the same image, the old cost).
  bool compact = true;
  bool budget = false;                      // --aa-criterion budget (kernels/cone_budget.h)
  std::vector<float> shares{0.30f, 0.28f};  // its --aa-budget, per level
};

// The modes docs/studies/sampling.md charts; the first is the one-ray image the others are compared
// with.
std::vector<Mode> modes() {
  std::vector<Mode> m = {
      {"spp 1", 1},
      {"spp 4", 4},
      {"spp 16", 16},
      {"spp 64", 64},
      {"adaptive 16, T 0.05", 16, true, 0.05f},
      {"adaptive 16, T 0.1", 16, true, 0.1f},
      {"adaptive 16, T 0.2", 16, true, 0.2f},
      {"adaptive 64, T 0.1", 64, true, 0.1f},
      // --aa-criterion object (docs/studies/sampling.md's cones section; the
      // page's other tables leave them out).
      {"object 16, T 0.05", 16, true, 0.05f, 0, true},
      {"object 16, T 0.1", 16, true, 0.1f, 0, true},
      {"object 16, T 0.2", 16, true, 0.2f, 0, true},
      {"object 16, T 0.3", 16, true, 0.3f, 0, true},
      {"object 16, T 0.1, cones 1", 16, true, 0.1f, 0, true, 1.0f},
      {"object 16, T 0.1, cones 4", 16, true, 0.1f, 0, true, 4.0f},
      // --aa-criterion budget, its defaults (T 0.05, 30% then 28% of
      // the pixels that hit; the 4x4 level keeps the 2x2 samples).
      {"budget 16", 16, true, 0.05f, 0, false, 2.0f, true, true},
      // ... and other shares (docs/studies/sampling.md's cones section charts them).
      {"budget 10%/9%", 16, true, 0.05f, 0, false, 2.0f, true, true, {0.10f, 0.09f}},
      {"budget 15%/13%", 16, true, 0.05f, 0, false, 2.0f, true, true, {0.15f, 0.13f}},
      {"budget 18%/16%", 16, true, 0.05f, 0, false, 2.0f, true, true, {0.18f, 0.16f}},
      {"budget 20%/18%", 16, true, 0.05f, 0, false, 2.0f, true, true, {0.20f, 0.18f}},
      {"budget 25%/23%", 16, true, 0.05f, 0, false, 2.0f, true, true, {0.25f, 0.23f}},
      {"budget 35%/33%", 16, true, 0.05f, 0, false, 2.0f, true, true, {0.35f, 0.33f}},
      {"undersample 2", 1, false, 0.1f, 2},
      {"undersample 2, T 0.05", 1, false, 0.05f, 2},
      {"undersample 2, T 0.02", 1, false, 0.02f, 2},
      {"undersample 4", 1, false, 0.1f, 4}};
  // Each adaptive and undersampling mode again as gated frames over the whole target (the
  // object and budget criteria's modes only dense: their section compares rays, not time).
  const size_t n = m.size();
  for (size_t i = 0; i < n; ++i)
    if ((m[i].adaptive || m[i].undersample > 0) && !m[i].object && !m[i].budget) {
      Mode g = m[i];
      g.label += ", gated";
      g.compact = false;
      m.push_back(g);
    }
  return m;
}

// The render options of mode m over the bench's `base`.
host::RenderOptions mode_options(const Mode& m, const host::RenderOptions& base) {
  host::RenderOptions opt = base;
  opt.spp = m.spp;
  opt.adaptive = m.adaptive;
  opt.aa_threshold = m.threshold;
  opt.undersample = m.undersample;
  // The "adaptive" rows are the image criterion's (no longer the default).
  opt.aa_criterion = m.object   ? host::RenderOptions::AaCriterion::object
                     : m.budget ? host::RenderOptions::AaCriterion::budget
                                : host::RenderOptions::AaCriterion::image;
  opt.aa_budget = m.shares;
  opt.cone_depth = m.cone_depth;
  opt.compact = m.compact;
  return opt;
}

// An image as the PNG writer stores it: each channel clamped to [0, 1] and rounded to 8 bits,
// read back in [0, 1] (the error is the one a viewer of the files would see).
std::vector<double> as_8bit(const std::vector<float>& rgb) {
  std::vector<double> out(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i)
    out[i] = std::round(double(std::clamp(rgb[i], 0.0f, 1.0f)) * 255.0) / 255.0;
  return out;
}

double rms(const std::vector<double>& a, const std::vector<double>& b,
           const std::vector<uint8_t>* only = nullptr) {
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (only && !(*only)[i / 3]) continue;
    sum += (a[i] - b[i]) * (a[i] - b[i]);
    ++n;
  }
  return n ? std::sqrt(sum / double(n)) : 0.0;
}

// The share of pixels whose largest channel difference exceeds `by`.
double changed(const std::vector<double>& a, const std::vector<double>& b, double by) {
  size_t n = 0;
  for (size_t p = 0; p < a.size() / 3; ++p) {
    double d = 0;
    for (int c = 0; c < 3; ++c) d = std::max(d, std::fabs(a[p * 3 + c] - b[p * 3 + c]));
    n += d > by;
  }
  return double(n) / double(a.size() / 3);
}

struct Row {
  std::string scene, mode;
  double rays_mean = 0, rays_max = 0, rms = 0, edge_rms = 0;
  uint64_t passes = 0, rays_traced = 0;
  double gf5700 = 0, gf6600 = 0, h200 = 0, emulator_ms = 0;
  // Of gf6600's and h200's ms: the fixed costs (passes, program loads, query read-backs).
  double gf6600_fixed = 0, h200_fixed = 0;
  double changed_255 = 0, changed_005 = 0;  // against the one-ray image
  size_t edge_pixels = 0;
};

// The cost model's ms on the three cards, and the fixed costs of two of them.
void price(Row& row, const vgpu::FrameStats& stats, const vgpu::Profile& gf5700,
           const vgpu::Profile& gf6600, const vgpu::Profile& h200) {
  const host::CostBreakdown c6600 = host::predict(stats, gf6600);
  const host::CostBreakdown c200 = host::predict(stats, h200);
  row.gf5700 = host::predict(stats, gf5700).total_ms;
  row.gf6600 = c6600.total_ms;
  row.h200 = c200.total_ms;
  row.gf6600_fixed = c6600.per_pass_ms + c6600.program_load_ms + c6600.readback_ms;
  row.h200_fixed = c200.per_pass_ms + c200.program_load_ms + c200.readback_ms;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= s.size()) {
    const size_t comma = s.find(',', start);
    const size_t end = comma == std::string::npos ? s.size() : comma;
    if (end > start) out.push_back(s.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

int usage(const char* why) {
  std::fprintf(stderr,
               "bench_sampling: %s\nusage: bench_sampling [--size N] [--reps N] [--scenes "
               "a,b,...] [--modes prefix,...] [--ref-spp N] [--json FILE]\n",
               why);
  return 2;
}

// Every mode's options at `size` on `profile`, checked before any scene is loaded
// (host::validate); false, with one line per refusal on stderr, where one cannot run.
bool modes_run(int size, const vgpu::Profile& profile) {
  bool run = true;
  for (const Mode& m : modes()) {
    host::RenderOptions base;
    base.width = base.height = size;
    base.profile = profile.name;
    for (const host::Refusal& r : host::validate(mode_options(m, base), profile)) {
      std::fprintf(stderr, "bench_sampling: %s: %s\n", m.label.c_str(), r.why.c_str());
      run = false;
    }
  }
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  int size = 128, reps = 3, ref_spp = 256;
  std::string json_path;
  std::vector<std::string> scenes = {"sphere", "bunny", "bunny-refl", "classic"};
  std::vector<std::string> prefixes;  // --modes: only the modes whose label starts so
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) return usage(("option " + a + " needs a value").c_str());
    const std::string v = argv[++i];
    char* end = nullptr;
    const long n = std::strtol(v.c_str(), &end, 10);
    const bool number = !v.empty() && *end == '\0';
    if (a == "--size" && number && n >= 4 && n <= 1024) {
      size = int(n);
    } else if (a == "--reps" && number && n >= 1 && n <= 100) {
      reps = int(n);
    } else if (a == "--ref-spp" && number && (n == 0 || host::spp_refusal(int(n)).empty())) {
      ref_spp = int(n);
    } else if (a == "--scenes" && !split(v).empty()) {
      scenes = split(v);
    } else if (a == "--modes" && !split(v).empty()) {
      prefixes = split(v);
    } else if (a == "--json") {
      json_path = v;
    } else {
      return usage(("bad option or value: " + a + " " + v).c_str());
    }
  }

  std::vector<Row> rows;
  const vgpu::Profile& gf5700 = vgpu::profile("gf5700");
  const vgpu::Profile& gf6600 = vgpu::profile("gf6600");
  const vgpu::Profile& h200 = vgpu::profile("h200");
  if (!modes_run(size, gf6600)) return 2;
  for (const std::string& name : scenes) {
    host::Scene scene;
    try {
      scene = host::load_scene(host::resolve_scene(name), host::with_images());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_sampling: scene %s: %s\n", name.c_str(), e.what());
      return 2;
    }
    // The CLI's defaults (2 bounces, Phong, shadows, grid auto), on gf6600.
    const host::Grid grid =
        host::build_grid(scene, host::grid_spec_for(host::GridSpec{}, scene, gf6600));
    const host::Camera camera = host::scene_camera(scene, 1.0f);
    host::RenderOptions base;
    base.width = base.height = size;
    base.profile = gf6600.name;
    host::RenderOptions ref_opt = base;
    ref_opt.spp = ref_spp;
    // --ref-spp 0: no reference (the changed pixels alone); the error columns are then 0.
    std::vector<double> ref(size_t(size) * size_t(size) * 3, 0.0);
    if (ref_spp > 0) {
      std::fprintf(stderr, "bench_sampling: %s: reference (CPU tracer, %d samples)\n", name.c_str(),
                   ref_spp);
      ref = as_8bit(host::render_cpu(scene, grid, camera, ref_opt).rgb);
    }
    std::vector<double> one;
    std::vector<uint8_t> edges;
    size_t edge_pixels = 0;
    for (const Mode& m : modes()) {
      // The one-ray image always runs: the others' changed pixels are counted against it.
      const bool wanted = prefixes.empty() || m.label == "spp 1" ||
                          std::any_of(prefixes.begin(), prefixes.end(), [&](const std::string& p) {
                            return m.label.rfind(p, 0) == 0;
                          });
      if (!wanted) continue;
      std::fprintf(stderr, "bench_sampling: %s: %s\n", name.c_str(), m.label.c_str());
      const host::RenderOptions opt = mode_options(m, base);
      host::StreamTracer tracer(scene, grid, opt);
      host::RenderResult r;
      std::vector<double> ms;
      for (int k = 0; k < reps; ++k) {
        r = tracer.render(camera);
        ms.push_back(r.render_ms);
      }
      std::sort(ms.begin(), ms.end());
      const std::vector<double> img = as_8bit(r.rgb);
      if (one.empty()) {
        // Edge pixels: where the one-ray image differs from the reference by more than 0.05 in
        // some channel (the pixels aliasing spoils).
        one = img;
        edges.assign(img.size() / 3, 0);
        for (size_t p = 0; p < edges.size(); ++p)
          for (int c = 0; c < 3; ++c)
            if (ref_spp > 0 && std::fabs(one[p * 3 + c] - ref[p * 3 + c]) > 0.05) edges[p] = 1;
        edge_pixels = size_t(std::count(edges.begin(), edges.end(), 1));
      }
      Row row;
      row.scene = name;
      row.mode = m.label;
      if (r.rays_per_pixel.empty()) {
        row.rays_mean = row.rays_max = r.samples;
      } else {
        double sum = 0;
        for (const uint32_t n : r.rays_per_pixel) {
          sum += n;
          row.rays_max = std::max(row.rays_max, double(n));
        }
        row.rays_mean = sum / double(r.rays_per_pixel.size());
      }
      row.rms = rms(img, ref);
      row.edge_rms = rms(img, ref, &edges);
      row.edge_pixels = edge_pixels;
      row.passes = r.stats.totals.passes;
      row.rays_traced = r.rays_traced;
      price(row, r.stats, gf5700, gf6600, h200);
      row.emulator_ms = ms[ms.size() / 2];
      row.changed_255 = changed(img, one, 1.0 / 255.0 + 1e-9);
      row.changed_005 = changed(img, one, 0.05);
      rows.push_back(row);
    }
  }

  // One table per scene, then the targets.
  for (const std::string& name : scenes) {
    const Row* first = nullptr;
    for (const Row& r : rows)
      if (r.scene == name) {
        if (!first) {
          first = &r;
          std::printf("\n%s, %dx%d, %zu edge pixels; reference: CPU tracer, %d samples\n",
                      name.c_str(), size, size, r.edge_pixels, ref_spp);
          std::printf("%-20s %9s %9s %8s %8s %10s %12s %12s %10s %10s %8s %8s\n", "mode", "rays/px",
                      "max", "RMS", "edge RMS", "passes", "gf5700 ms", "gf6600 ms", "h200 ms",
                      "emul. ms", ">1/255", ">0.05");
        }
        std::printf(
            "%-20s %9.3f %9.0f %8.4f %8.4f %10llu %12.0f %12.0f %10.1f %10.1f %7.2f%% "
            "%7.2f%%\n",
            r.mode.c_str(), r.rays_mean, r.rays_max, r.rms, r.edge_rms,
            (unsigned long long)r.passes, r.gf5700, r.gf6600, r.h200, r.emulator_ms,
            100 * r.changed_255, 100 * r.changed_005);
      }
  }
  std::printf(
      "\n(>1/255, >0.05: pixels that differ from the spp 1 image by more than that in "
      "some channel; emulator ms: median of %d runs)\n",
      reps);
  std::printf("\nTargets\n");
  for (const std::string& name : scenes) {
    const Row *u16 = nullptr, *best = nullptr;
    for (const Row& r : rows)
      if (r.scene == name && r.mode == "spp 16") u16 = &r;
    for (const Row& r : rows)
      if (r.scene == name && r.mode.rfind("adaptive 16", 0) == 0 && u16 &&
          r.rms <= 1.5 * u16->rms && r.rays_mean <= 0.35 * 16 && (!best || r.rms < best->rms))
        best = &r;
    if (!u16 || ref_spp == 0)
      ;  // no spp 16 image, or no reference to measure the error against
    else if (best)
      std::printf("%s: adaptive met (%s: RMS %.2fx spp 16's with %.0f%% of its rays)\n",
                  name.c_str(), best->mode.c_str(), best->rms / u16->rms,
                  100 * best->rays_mean / 16);
    else
      std::printf("%s: adaptive not met\n", name.c_str());
    for (const Row& r : rows)
      if (r.scene == name && r.mode.rfind("undersample 2", 0) == 0)
        std::printf(
            "%s: %s: %.3f rays per pixel, %.2f%% of pixels changed by > 1/255, "
            "%.2f%% by > 0.05\n",
            name.c_str(), r.mode.c_str(), r.rays_mean, 100 * r.changed_255, 100 * r.changed_005);
  }

  if (!json_path.empty()) {
    std::ofstream f(json_path);
    f << "{\"size\": " << size << ", \"reps\": " << reps << ", \"ref_spp\": " << ref_spp
      << ", \"rows\": [\n";
    for (size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      char line[1024];
      std::snprintf(line, sizeof line,
                    "{\"scene\": \"%s\", \"mode\": \"%s\", \"rays_mean\": %.6g, \"rays_max\": "
                    "%.6g, \"rms\": %.6g, \"edge_rms\": %.6g, \"edge_pixels\": %zu, \"passes\": "
                    "%llu, \"rays_traced\": %llu, \"gf5700\": %.6g, \"gf6600\": %.6g, \"h200\": "
                    "%.6g, \"emulator_ms\": %.6g, \"changed_255\": %.6g, \"changed_005\": %.6g, "
                    "\"gf6600_fixed\": %.6g, \"h200_fixed\": %.6g}",
                    r.scene.c_str(), r.mode.c_str(), r.rays_mean, r.rays_max, r.rms, r.edge_rms,
                    r.edge_pixels, (unsigned long long)r.passes, (unsigned long long)r.rays_traced,
                    r.gf5700, r.gf6600, r.h200, r.emulator_ms, r.changed_255, r.changed_005,
                    r.gf6600_fixed, r.h200_fixed);
      f << line << (i + 1 < rows.size() ? ",\n" : "\n");
    }
    f << "]}\n";
    if (!f) {
      std::fprintf(stderr, "bench_sampling: %s: could not be written\n", json_path.c_str());
      return 1;
    }
  }
  return 0;
}
