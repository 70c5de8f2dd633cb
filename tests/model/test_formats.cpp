// Tests for host/formats: --precision / --formats parsing, and --precision auto's choice per
// group from the scene's integer ranges, with its reasons.
#include <doctest/doctest.h>

#include <memory>
#include <stdexcept>

#include "host/accel/accel.h"
#include "host/accel/bvh.h"
#include "host/accel/grid.h"
#include "host/model/formats.h"
#include "host/scene/gltf_loader.h"

using host::Group;
using vgpu::Format;

TEST_CASE("--precision sets every group and --formats overrides texels and arithmetic by group") {
  const host::Scene scene = host::load_scene(VGPU_SCENES_DIR "/sphere.gltf");
  const host::Grid grid = host::build_grid(scene, host::parse_grid_spec("8"));
  const vgpu::Profile& fx = vgpu::profile("gf5700");
  const host::Formats all16 =
      host::resolve(host::parse_format_request("fp16", ""), scene, grid, fx);
  for (Group g : host::kGroups) {
    CHECK(all16[g] == Format::fp16);
    CHECK(all16.arithmetic(g) == Format::fp16);
  }
  const host::Formats mixed = host::resolve(
      host::parse_format_request("fp32", "colour=fp16/fp32,voxel=fp24"), scene, grid, fx);
  CHECK(mixed[Group::colour] == Format::fp16);
  CHECK(mixed.arithmetic(Group::colour) == Format::fp32);
  CHECK(mixed[Group::voxel] == Format::fp24);
  CHECK(mixed.arithmetic(Group::voxel) == Format::fp24);
  CHECK(mixed[Group::rays] == Format::fp32);
  CHECK(mixed.finest() == Format::fp32);
  CHECK(mixed.why[size_t(Group::voxel)] == "set by --formats");
}

TEST_CASE("bad --precision and --formats values are refused naming the option and the part") {
  CHECK_THROWS_WITH_AS(host::parse_format_request("fp8", ""),
                       doctest::Contains("--precision (or auto): expected fp32, fp24 or fp16"),
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(host::parse_format_request("fp32", "vox=fp16"),
                       doctest::Contains("GROUP one of rays, traversal, voxel, hits, colour"),
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(host::parse_format_request("fp32", "rays"), doctest::Contains("got 'rays'"),
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(host::parse_format_request("fp32", "hits=fp32/half"),
                       doctest::Contains("--formats hits (arithmetic)"), std::invalid_argument);
}

TEST_CASE("exact texel addresses end at 1023 in fp16 and 65535 in fp24") {
  CHECK(host::exact_addresses(Format::fp16) == 1023);
  CHECK(host::exact_addresses(Format::fp24) == 65535);
  // Just past the limit the texel centre id + 1/2 has no form of its own.
  CHECK(vgpu::round_fp16(1023.5f) == 1023.5f);
  CHECK(vgpu::round_fp16(1024.5f) != 1024.5f);
  CHECK(vgpu::round_fp24(65535.5f) == 65535.5f);
  CHECK(vgpu::round_fp24(65536.5f) != 65536.5f);
}

TEST_CASE("auto keeps the bunny's voxel state at fp32 on the FX 5700 and says why") {
  const host::Scene scene = host::load_scene(VGPU_SCENES_DIR "/bunny.gltf");
  const host::Grid grid = host::build_grid(scene, host::parse_grid_spec("auto"));
  const host::IntegerRanges r = host::integer_ranges(scene, grid);
  CHECK(r.list_entries > 1024);
  const host::Formats fx = host::auto_formats(scene, grid, vgpu::profile("gf5700"));
  CHECK(fx[Group::voxel] == Format::fp32);
  CHECK(fx.why[size_t(Group::voxel)] == "list positions reach " +
                                            std::to_string(r.list_entries - 1) +
                                            "; fp16 addresses texels exactly only to 1023");
  CHECK(fx[Group::rays] == Format::fp32);
  CHECK(fx[Group::traversal] == Format::fp32);
  CHECK(fx[Group::hits] == Format::fp32);
  CHECK(fx[Group::colour] == Format::fp16);             // texels: colour and weights
  CHECK(fx.arithmetic(Group::colour) == Format::fp32);  // the shader's shadow test
  CHECK(fx[Group::queries] == Format::fp16);
  // The R300 has one format.
  const host::Formats ati = host::auto_formats(scene, grid, vgpu::profile("r300"));
  for (Group g : host::kGroups) CHECK(ati.arithmetic(g) == Format::fp24);
}

TEST_CASE("auto gives the voxel state fp16 where every list position is an exact address") {
  // 948 triangles in one voxel: 950 list entries, every position and id below 1024.
  const host::Scene scene = host::load_scene(VGPU_SCENES_DIR "/bunny-low.gltf");
  const host::Grid grid = host::build_grid(scene, host::parse_grid_spec("1"));
  const host::IntegerRanges r = host::integer_ranges(scene, grid);
  REQUIRE(r.list_entries - 1 <= 1023);
  REQUIRE(r.triangles - 1 <= 1023);
  const host::Formats f = host::auto_formats(scene, grid, vgpu::profile("gf5700"));
  CHECK(f[Group::voxel] == Format::fp16);
  CHECK(f.why[size_t(Group::voxel)].find("within fp16's exact addresses") != std::string::npos);
}

TEST_CASE("auto counts the BVH's list positions, not the one-voxel grid's, with --accel bvh") {
  // bunny-low with the one-voxel grid the CLI builds beside a BVH: the grid's single list fits
  // fp16's exact addresses, but the voxel state walks the BVH's lists (a -1 after every leaf),
  // whose positions pass 1023.
  const host::Scene scene = host::load_scene(VGPU_SCENES_DIR "/bunny-low.gltf");
  const host::Grid box = host::build_grid(scene, host::parse_grid_spec("1"));
  const host::Bvh bvh = host::build_bvh(scene);
  REQUIRE(host::integer_ranges(scene, box).list_entries - 1 <= 1023);
  const host::IntegerRanges r = host::integer_ranges(scene, box, bvh.lists.size());
  CHECK(r.list_entries == bvh.lists.size());
  REQUIRE(r.list_entries - 1 > 1023);
  const uint64_t entries = bvh.lists.size();
  const host::Formats f = host::auto_formats(scene, box, vgpu::profile("gf5700"), entries);
  CHECK(f[Group::voxel] == Format::fp32);
  CHECK(f.why[size_t(Group::voxel)] == "list positions reach " + std::to_string(entries - 1) +
                                           "; fp16 addresses texels exactly only to 1023");
  // resolve passes the count on to auto, and leaves explicit formats alone.
  CHECK(host::resolve(host::parse_format_request("auto", ""), scene, box, vgpu::profile("gf5700"),
                      entries)[Group::voxel] == Format::fp32);
  CHECK(host::resolve(host::parse_format_request("fp16", ""), scene, box, vgpu::profile("gf5700"),
                      entries)[Group::voxel] == Format::fp16);
  // The CLI's way, from the structure (host::make_accel): the same formats and reasons.
  const std::unique_ptr<host::Accel> accel = host::make_accel(host::AccelKind::bvh, scene, {});
  CHECK(accel->list_entries() == entries);
  const host::Formats g =
      host::resolve(host::parse_format_request("auto", ""), scene, *accel, vgpu::profile("gf5700"));
  CHECK(g.why == f.why);
  for (Group grp : host::kGroups) CHECK(g[grp] == f[grp]);
}
