// Benchmark data: every pixel's adaptive levels, so that rules of where to refine (--aa adaptive)
// can be tried offline without a render per rule. For each scene (128 x 128 by default, the
// CLI's defaults, as bench_sampling) the CPU tracer traces every pixel's centre ray and every
// level of --spp 16 (2 x 2, then 4 x 4) as if every pixel were refined (cpu_adaptive_levels),
// with the rays each traced, the 4 x 4 level that would keep the 2 x 2 samples and trace only
// the 12 others (its kept level), and the 256-sample reference. A rule then picks, per pixel, the
// last level it reaches: its image is that level's estimate, its rays the sum of its levels'.
// scripts/docs/sampling_rules.py reads the files and writes docs/studies/sampling.md's section on
// the rules it tried.
//
// Output in --out, per scene (N its place in --scenes, from 0): N.f32, float32 little-endian, per
// pixel (row-major, row 0 the top) the 22 values of `kFields`; and index.json: the size, the
// fields, and per scene its file and pixel spread (the angle between neighbouring pixels' rays,
// marcarConos' uniform).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/cpu/cpu_tracer.h"

namespace {

const std::vector<std::string> kFields = {
    "centre_r",    "centre_g", "centre_b", "key",        "reflected_key", "depth",
    "centre_rays", "l2_r",     "l2_g",     "l2_b",       "l2_rays",       "l4_r",
    "l4_g",        "l4_b",     "l4_rays",  "ref_r",      "ref_g",         "ref_b",
    "l4kept_r",    "l4kept_g", "l4kept_b", "l4kept_rays"};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "bench_mark_rules: every pixel's adaptive levels (--spp 16) and the reference, for trying "
      "rules of where to refine offline"};
  int size = 128, ref_spp = 256;
  std::vector<std::string> scenes = {"sphere",    "bunny",        "bunny-refl", "classic",
                                     "bunny-low", "bunny-mirror", "hop",        "sphere-alone",
                                     "teapot",    "textured"};
  std::string out_dir;
  app.add_option("--size", size, "Image width and height")->check(CLI::Range(4, 1024));
  app.add_option("--ref-spp", ref_spp, "Samples per pixel of the reference")
      ->check(CLI::Range(1, 1024));
  app.add_option("--scenes", scenes, "Bundled scene names or glTF files");
  app.add_option("--out", out_dir, "Folder for the files (it must exist)")
      ->required()
      ->check(CLI::ExistingDirectory);
  CLI11_PARSE(app, argc, argv);

  nlohmann::json index = {{"size", size}, {"ref_spp", ref_spp}, {"fields", kFields}};
  index["scenes"] = nlohmann::json::array();
  for (const std::string& name : scenes) {
    host::Scene scene;
    try {
      scene = host::load_scene(host::resolve_scene(name), host::with_images());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_mark_rules: scene %s: %s\n", name.c_str(), e.what());
      return 2;
    }
    std::fprintf(stderr, "bench_mark_rules: %s\n", name.c_str());
    const vgpu::Profile& gf6600 = vgpu::profile("gf6600");
    const host::Grid grid =
        host::build_grid(scene, host::grid_spec_for(host::GridSpec{}, scene, gf6600));
    const host::Camera camera = host::scene_camera(scene, 1.0f);
    host::RenderOptions opt;
    opt.width = opt.height = size;
    opt.profile = gf6600.name;
    opt.spp = 16;
    const host::CpuAdaptiveLevels lv =
        host::cpu_adaptive_levels(scene, host::GridAccel(grid), camera, opt);
    host::RenderOptions ref_opt = opt;
    ref_opt.spp = ref_spp;
    const host::RenderResult ref = host::render_cpu(scene, grid, camera, ref_opt);
    const size_t n = size_t(size) * size_t(size);
    std::vector<float> data;
    data.reserve(n * kFields.size());
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) data.push_back(lv.centre[i * 3 + size_t(c)]);
      data.push_back(float(lv.key[i]));
      data.push_back(float(lv.reflected_key[i]));
      data.push_back(lv.depth[i]);
      data.push_back(float(lv.centre_rays[i]));
      for (size_t l = 0; l < 2; ++l) {
        for (int c = 0; c < 3; ++c) data.push_back(lv.level[l][i * 3 + size_t(c)]);
        data.push_back(float(lv.level_rays[l][i]));
      }
      for (int c = 0; c < 3; ++c) data.push_back(ref.rgb[i * 3 + size_t(c)]);
      for (int c = 0; c < 3; ++c) data.push_back(lv.kept[1][i * 3 + size_t(c)]);
      data.push_back(float(lv.kept_rays[1][i]));
    }
    const std::string file = std::to_string(index["scenes"].size()) + ".f32";
    std::ofstream f(out_dir + "/" + file, std::ios::binary);
    f.write(reinterpret_cast<const char*>(data.data()),
            std::streamsize(data.size() * sizeof(float)));
    if (!f) {
      std::fprintf(stderr, "bench_mark_rules: %s/%s: could not be written\n", out_dir.c_str(),
                   file.c_str());
      return 1;
    }
    const float spread = 2.0f * std::tan(0.5f * camera.yfov) / float(size);
    index["scenes"].push_back({{"name", name}, {"file", file}, {"spread", spread}});
  }
  std::ofstream f(out_dir + "/index.json");
  f << index.dump(1) << "\n";
  if (!f) {
    std::fprintf(stderr, "bench_mark_rules: %s/index.json: could not be written\n",
                 out_dir.c_str());
    return 1;
  }
  return 0;
}
