// The own kernel at kernel level (hand-made texels, every output channel, the counters), then a
// frame rendered through the installed host library, its scene and image module found through
// the install prefix.
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "host/cli/render.h"
#include "toon.h"
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
