// The kernels under the rounded lane family (Gpu::set_precision, vgpu/precision.h) on hand-made
// texels, with the outcome written down per format: exact where the case needs no more bits
// than the format has, the known failure where it needs more. fp16 holds integers to 2048 but a
// texel centre id + 1/2 only below 1024; fp24 holds integers to 131072, centres below 65536.
#include <doctest/doctest.h>

#include <vector>

#include "kernel_pass.h"

using kernels::kNone;
using ktest::Texture;
using vgpu::Format;

namespace {

// A one-row triangle list `n` entries long whose entry k holds k + 0.25 (distinct from every
// neighbour, so a fetch one texel off shows), and a voxel state pointing at `pos` - 1.
Texture counting_list(int n) {
  Texture t("triangle lists", n, 1, 1);
  for (int k = 0; k < n; ++k) t.set(k, 0, 0, float(k) + 0.25f);
  return t;
}

// What next triangle reads for a ray at list position pos - 1 when computing in `precision`.
glm::vec4 next_from(int pos, int list_width, Format precision) {
  kernels::NextTriangle k;
  k.lists =
      ktest::grid_uniforms(glm::vec3(0.0f), glm::vec3(1.0f), glm::vec3(1.0f), float(list_width));
  const Texture lists = counting_list(list_width);
  const Texture vs = ktest::texels("voxel state", 1, 1, {{float(pos - 1), 0, 0, 0}});
  vgpu::Gpu gpu(ktest::gf5700(), 1, 1);
  gpu.set_precision(precision);
  return ktest::at(ktest::run(gpu, k, {&vs, &lists}, 1, 1), 0, 0);
}

}  // namespace

TEST_CASE("next triangle reads the right list entry below 1024 at fp16 and below 65536 at fp24") {
  for (Format f : {Format::fp32, Format::fp24, Format::fp16}) {
    CAPTURE(vgpu::format_name(f));
    for (int pos : {1, 2, 511, 1000, 1001, 1023}) {
      CAPTURE(pos);
      // The entry holds pos + 1/4: rounded to the format on its way into the register.
      CHECK(next_from(pos, 2048, f) == glm::vec4(float(pos), 0, 0, vgpu::round_to(f, pos + 0.25f)));
    }
  }
  for (int pos : {1024, 1501, 2047}) {
    CAPTURE(pos);
    CHECK(next_from(pos, 2048, Format::fp24) ==
          glm::vec4(float(pos), 0, 0, vgpu::round_to(Format::fp24, pos + 0.25f)));
  }
}

TEST_CASE("next triangle at fp16 reads the neighbouring entry for odd positions past 1024") {
  // Known failure: pos + 1/2 = 1501.5 has no fp16 form and rounds to even, 1502, so the fetch
  // lands one texel on. Even positions round back onto themselves and still read right.
  CHECK(next_from(1501, 2048, Format::fp16).w == vgpu::round_to(Format::fp16, 1502.25f));
  CHECK(next_from(1025, 2048, Format::fp16).w == vgpu::round_to(Format::fp16, 1026.25f));
  CHECK(next_from(1500, 2048, Format::fp16).w == vgpu::round_to(Format::fp16, 1500.25f));
}

TEST_CASE(
    "update voxel finds the list of voxel (X, Y, Z) exactly at fp24 and fp16 on a small grid") {
  // 3 x 4 x 2 voxels: pointer texels (X*4 + Y, Z), all far below every format's limit.
  Texture pointers("voxel pointers", 12, 2, 1);
  for (int z = 0; z < 2; ++z)
    for (int x = 0; x < 12; ++x) pointers.set(x, z, 0, float(1 + x + 12 * z));
  const Texture lists = counting_list(32);
  kernels::UpdateVoxel k;
  k.grid = ktest::grid_uniforms(glm::vec3(0.0f), glm::vec3(1.0f), {3, 4, 2}, 32);
  const Texture trav =
      ktest::texels("traversal", 3, 1, {{2, 3, 1, 0.5f}, {0, 0, 0, 0}, {1, 2, 0, 7}});
  const Texture vs =
      ktest::texels("voxel state", 3, 1, {{0, 0, 0, kNone}, {0, 0, 0, kNone}, {0, 0, 0, kNone}});
  for (Format f : {Format::fp32, Format::fp24, Format::fp16}) {
    CAPTURE(vgpu::format_name(f));
    vgpu::Gpu gpu(ktest::gf5700(), 1, 1);
    gpu.set_precision(f);
    const Texture out = ktest::run(gpu, k, {&trav, &vs, &pointers, &lists}, 3, 1);
    // Voxel (2, 3, 1): texel (11, 1) holds 24, entry 24 holds 24.25.
    CHECK_TEXEL(out, 0, 0, glm::vec4(24, 0, 0, vgpu::round_to(f, 24.25f)));
    CHECK_TEXEL(out, 1, 0, glm::vec4(1, 0, 0, vgpu::round_to(f, 1.25f)));
    CHECK_TEXEL(out, 2, 0, glm::vec4(7, 0, 0, vgpu::round_to(f, 7.25f)));
  }
}

TEST_CASE(
    "a program's own precision lowers its pass only, and a part computes no finer than it can") {
  const Texture lists = counting_list(2048);
  const Texture vs = ktest::texels("voxel state", 1, 1, {{1500.0f, 0, 0, 0}});
  kernels::NextTriangle k;
  k.lists = ktest::grid_uniforms(glm::vec3(0.0f), glm::vec3(1.0f), glm::vec3(1.0f), 2048);
  vgpu::KernelProgram<kernels::NextTriangle> p(k);
  Texture out("out", 1, 1, 4);
  {
    vgpu::Gpu gpu(ktest::gf5700(), 1, 1);  // fp32 arithmetic, the program asks for fp16
    p.set_precision(Format::fp16);
    CHECK(gpu.precision_of(p) == Format::fp16);
    const vgpu::PassRecord rec = ktest::draw(gpu, p, {&vs, &lists}, out);
    CHECK(out.get(0, 0, 3) == vgpu::round_to(Format::fp16, 1502.25f));  // the odd-position failure
    CHECK(rec.counters.alu_fp16 == rec.counters.instructions - rec.counters.texture_fetches);
    CHECK(rec.counters.alu_fp24 == 0);
  }
  {
    vgpu::Gpu gpu(vgpu::profile("r300"), 1, 1);  // R300 has only fp24: fp32 and fp16 run there
    for (Format asked : {Format::fp32, Format::fp16}) {
      p.set_precision(asked);
      CHECK(gpu.precision_of(p) == Format::fp24);
      const vgpu::PassRecord rec = ktest::draw(gpu, p, {&vs, &lists}, out);
      CHECK(out.get(0, 0, 3) == vgpu::round_to(Format::fp24, 1501.25f));
      CHECK(rec.counters.alu_fp24 == rec.counters.instructions - rec.counters.texture_fetches);
    }
  }
}
