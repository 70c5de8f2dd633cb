// The helpers every walk shares (host/trace/walks/accel_walk.h): the check that a format addresses
// a structure's nodes and lists exactly, and the static textures' rewrite between frames.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "host/trace/walks/accel_walk.h"
#include "vgpu/gpu.h"

namespace {

std::string refusal(const host::Formats& fm, std::initializer_list<host::AddressUse> uses) {
  try {
    host::check_addresses(fm, "toy", uses);
  } catch (const vgpu::Error& e) {
    return e.what();
  }
  return {};
}

}  // namespace

TEST_CASE("a format that cannot address a structure's entries is refused naming group and need") {
  host::Formats fm = host::Formats::all(vgpu::Format::fp32);
  fm.set(host::Group::voxel, vgpu::Format::fp16, vgpu::Format::fp32);
  // fp16 addresses 0 .. 1023 exactly: 1024 entries (positions 0 .. 1023) fit, 1025 do not.
  CHECK(refusal(fm, {{1024, host::Group::voxel, "list positions"}}).empty());
  CHECK(refusal(fm, {{1025, host::Group::traversal, "node indices"}}).empty());
  CHECK(refusal(fm, {{1025, host::Group::voxel, "list positions"}}) ==
        "toy: list positions reach 1024; the voxel group's fp16 addresses texels exactly only to "
        "1023 (give it fp24 or fp32: --formats voxel=fp32)");
  // The texels' format and the arithmetic are both checked.
  fm.set(host::Group::voxel, vgpu::Format::fp32, vgpu::Format::fp24);
  CHECK(refusal(fm, {{65536, host::Group::voxel, "list positions"}}).empty());
  // Past fp24's 65535 the advice names fp32 alone; the first use refused wins.
  CHECK(refusal(fm, {{10, host::Group::traversal, "node indices"},
                     {70000, host::Group::voxel, "list positions"},
                     {1u << 20, host::Group::voxel, "more"}}) ==
        "toy: list positions reach 69999; the voxel group's fp24 addresses texels exactly only to "
        "65535 (give it fp32: --formats voxel=fp32)");
}

TEST_CASE("between frames only the static textures whose texels changed are uploaded again") {
  vgpu::Gpu gpu(vgpu::profile("gf6600"), 1);
  vgpu::Texture a = gpu.make_texture("a", 2, 1, 1), b = gpu.make_texture("b", 4, 1, 1);
  const std::vector<float> a1{1, 2}, b1{3, 4, 5, 6}, b2{3, 4, 5, 7};
  // At construction (no list to name them in) the texels are set and nothing is counted.
  CHECK(host::replace_texels(gpu, {{&a, &a1}, {&b, &b1}}, nullptr) == 0);
  CHECK(a.get(1, 0) == 2.0f);
  CHECK(b.get(3, 0) == 6.0f);
  std::vector<std::string> uploaded;
  CHECK(host::replace_texels(gpu, {{&a, &a1}, {&b, &b1}}, &uploaded) == 0);
  CHECK(uploaded.empty());
  CHECK(host::replace_texels(gpu, {{&a, &a1}, {&b, &b2}}, &uploaded) == b.bytes());
  CHECK(uploaded == std::vector<std::string>{"b"});
  CHECK(b.get(3, 0) == 7.0f);
  CHECK(host::holds(b, 4));
  CHECK_FALSE(host::holds(b, 5));
}

TEST_CASE(
    "a texture just made takes its structure's texels in place; a kept one through a copy that "
    "uploads it again only where a texel changed") {
  vgpu::Gpu gpu(vgpu::profile("gf6600"), 1);
  vgpu::Texture t = gpu.make_texture("t", 4, 1, 1);
  {
    // Made: the writer's texels are the texture's own (no copy beside them), kept as written.
    host::StaticTexels w(t, true);
    CHECK(w.span().data() == t.texel(0, 0));
    for (size_t i = 0; i < 4; ++i) w[i] = float(i + 1);
    std::vector<std::string> uploaded;
    CHECK(host::replace_texels(gpu, {&w}, &uploaded) == t.bytes());  // a new texture: uploaded
    CHECK(uploaded == std::vector<std::string>{"t"});
  }
  CHECK(t.get(3, 0) == 4.0f);
  {
    // Kept between frames: a copy, compared; the same texels upload nothing.
    host::StaticTexels w(t, false);
    CHECK(w.span().data() != t.texel(0, 0));
    CHECK(w[2] == 3.0f);
    std::vector<std::string> uploaded;
    CHECK(host::replace_texels(gpu, {&w}, &uploaded) == 0);
    CHECK(uploaded.empty());
  }
  {
    host::StaticTexels w(t, false);
    w[0] = 9.0f;
    CHECK(t.get(0, 0) == 1.0f);  // not written until kept
    std::vector<std::string> uploaded;
    CHECK(host::replace_texels(gpu, {&w}, &uploaded) == t.bytes());
    CHECK(t.get(0, 0) == 9.0f);
  }
}

TEST_CASE("past fp32's linear reach the refusal advises addressing textures by (x, y)") {
  // No format addresses more than fp32's 2^23 - 1 exactly by a linear index: the advice is (x,
  // y) addressing (--addressing linear forces this check), and the refusal is a limit of the
  // input (vgpu::LimitError: the command line exits 2).
  const host::Formats fm = host::Formats::all(vgpu::Format::fp32);
  CHECK(refusal(fm, {{8388608, host::Group::traversal, "node indices"}}).empty());
  CHECK(refusal(fm, {{8388609, host::Group::traversal, "node indices"}}) ==
        "toy: node indices reach 8388608; the traversal group's fp32 addresses texels exactly "
        "only to 8388607 (address its textures by (x, y): --addressing auto or xy)");
  CHECK_THROWS_AS(host::check_addresses(fm, "toy", {{8388609, host::Group::voxel, "lists"}}),
                  vgpu::LimitError);
}
