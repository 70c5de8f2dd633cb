// The own kernel at kernel level (hand-made texels, every output channel, the counters), then a
// frame rendered through the installed host library, its scene and image module found through
// the install prefix, and one with the own shading kernel in place of vgpu-rt's.
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "host/cli/render.h"
#include "host/trace/user_stage.h"
#include "toon.h"
#include "toon_shader.h"
#include "vgpu/gpu.h"

TEST_CASE("the toon kernel bands each channel, inks dark texels and passes alpha through") {
  vgpu::Gpu gpu(vgpu::profile("gf5700"), 1);
  vgpu::Texture in = gpu.make_texture("colour", 3, 1, 4);
  // Texel 0: bands of 0.25; texel 1: below the ink threshold; texel 2: values on band edges.
  const float texels[3][4] = {
      {0.3f, 0.6f, 0.9f, 0.7f}, {0.05f, 0.9f, 0.9f, 0.2f}, {0.5f, 0.25f, 1.0f, 1.0f}};
  for (int x = 0; x < 3; ++x)
    for (int c = 0; c < 4; ++c) in.set(x, 0, c, texels[x][c]);
  gpu.upload(in);
  vgpu::Texture out = gpu.make_texture("toon", 3, 1, 4);
  vgpu::KernelProgram<Toon> toon;  // its constructor checks the target flags (vgpu/abi.h)
  gpu.use_program(toon);
  gpu.bind_texture(0, in);
  gpu.set_targets({&out});
  gpu.draw();
  const float expected[3][4] = {
      {0.25f, 0.5f, 0.75f, 0.7f}, {0.0f, 0.0f, 0.0f, 0.2f}, {0.5f, 0.25f, 1.0f, 1.0f}};
  for (int x = 0; x < 3; ++x)
    for (int c = 0; c < 4; ++c) {
      CAPTURE(x);
      CAPTURE(c);
      CHECK(out.get(x, 0, c) == expected[x][c]);
    }
  // Counted as any kernel: one pass of three fragments, one fetch each.
  const vgpu::FrameStats& stats = gpu.stats();
  CHECK(stats.totals.passes == 1);
  CHECK(stats.totals.fragments_launched == 3);
  CHECK(stats.totals.texture_fetches == 3);
}

TEST_CASE("a kernel compiled here has the library's lane types") {
  CHECK_NOTHROW(vgpu::check_abi(VGPU_ABI_HERE));
  CHECK(vgpu::describe(VGPU_ABI_HERE) == vgpu::describe(vgpu::library_abi()));
}

TEST_CASE("the host library renders a bundled scene found through the install prefix") {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("own_kernel_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  cli::RenderArgs a;
  a.scene = "bunny";
  a.size = "32x32";
  a.out = (dir / "bunny.png").string();
  a.quiet = true;
  a.stats = "none";
  CHECK(cli::run_render(a, false) == 0);
  CHECK(std::filesystem::file_size(dir / "bunny.png") > 100);
  std::filesystem::remove_all(dir);
}

TEST_CASE("the toon shader bands a lit hit, adds the ambient term and blends by the stage's rule") {
  vgpu::Gpu gpu(vgpu::profile("gf5700"), 1);
  // Two fragments: 0 hits triangle 1 at the origin, lit from straight above; 1 misses.
  auto texture = [&](const char* name, int w, std::initializer_list<std::array<float, 4>> texels) {
    vgpu::Texture t = gpu.make_texture(name, w, 1, 4);
    int x = 0;
    for (const auto& v : texels) {
      for (int c = 0; c < 4; ++c) t.set(x, 0, c, v[size_t(c)]);
      ++x;
    }
    gpu.upload(t);
    return t;
  };
  const vgpu::Texture surface = texture("surface", 2, {{0, 0, 0, 1}, {0, 0, 0, -1}});
  const vgpu::Texture rays = texture("rays", 2, {{0, -1, 0, 1e30f}, {0, 0, -1, 1e30f}});
  const vgpu::Texture result = texture("result", 2, {{0.1f, 0.2f, 0.3f, 1}, {0.4f, 0.5f, 0.6f, 1}});
  // The scene's textures: two triangles, triangle i at texel i (scene_width 2).
  const vgpu::Texture colors = texture("colors", 2, {{1, 1, 1, 0}, {0.5f, 0.25f, 1, 0.5f}});
  const vgpu::Texture normals = texture("normals0", 2, {{1, 0, 0, 0}, {0, 2, 0, 0}});
  vgpu::Texture out = gpu.make_texture("toon shading", 2, 1, 4);
  vgpu::KernelProgram<ToonShader> toon;
  toon.kernel.stage.scene_width = 2;
  toon.kernel.stage.light = {0, 10, 0};
  gpu.use_program(toon);
  int unit = 0;
  for (const vgpu::Texture* t : {&surface, &rays, &result, &colors, &normals})
    gpu.bind_texture(unit++, *t);
  gpu.set_targets({&out});
  gpu.draw();
  // Fragment 0: lambert 1, band 1, plus ambient 0.1: k = 1.1 x w (1 - a) = 0.55; weight w a.
  // Fragment 1: the result passes through; no reflected ray.
  const float expected[2][4] = {{0.1f + 0.5f * 0.55f, 0.2f + 0.25f * 0.55f, 0.3f + 0.55f, 0.5f},
                                {0.4f, 0.5f, 0.6f, 0.0f}};
  for (int x = 0; x < 2; ++x)
    for (int c = 0; c < 4; ++c) {
      CAPTURE(x);
      CAPTURE(c);
      CHECK(out.get(x, 0, c) == doctest::Approx(expected[x][c]).epsilon(1e-6));
    }
  // Not the first light: no ambient (band 1 alone: k = 0.5); not the last: the weight passes on.
  toon.kernel.stage.first_light = 0;
  toon.kernel.stage.last_light = 0;
  gpu.draw();
  CHECK(out.get(0, 0, 0) == doctest::Approx(0.1f + 0.5f * 0.5f).epsilon(1e-6));
  CHECK(out.get(0, 0, 3) == 1.0f);
  CHECK(out.get(1, 0, 3) == 1.0f);
  CHECK(gpu.stats().totals.texture_fetches == 2 * 2 * 5);
}

TEST_CASE("the host library renders a frame with the toon shader in place of its own") {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("own_shader_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  cli::RenderArgs a;
  a.scene = "bunny";
  a.size = "32x32";
  a.out = (dir / "toon.png").string();
  a.quiet = true;
  a.stats = "none";
  cli::RenderOutcome theirs;  // vgpu-rt's own shader first
  CHECK(cli::run_render(a, false, &theirs) == 0);
  a.user.shader = host::user_stage<ToonShader>();
  cli::RenderOutcome outcome;
  CHECK(cli::run_render(a, false, &outcome) == 0);
  CHECK(std::filesystem::file_size(dir / "toon.png") > 100);
  // Its passes are the shader's, under its own name.
  const vgpu::FrameStats::ProgramTotals* toon = outcome.result.stats.find("toon shading");
  const vgpu::FrameStats::ProgramTotals* shader = theirs.result.stats.find("shader");
  REQUIRE(toon != nullptr);
  REQUIRE(shader != nullptr);
  CHECK(toon->counters.passes == shader->counters.passes);
  CHECK(outcome.result.stats.totals.passes == theirs.result.stats.totals.passes);
  CHECK(outcome.result.stats.find("shader") == nullptr);
  CHECK(outcome.result.rgb != theirs.result.rgb);
  std::filesystem::remove_all(dir);
}
