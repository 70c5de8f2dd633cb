// The memory model's terms (host/report/memory_json.h): each is the exact byte count of what a
// frame holds (texels, triangles, the structure's arrays, the frame read back), so that their sum
// can be set against the process's peak (docs/studies/scale.md, "Memory").
#include <doctest/doctest.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "host/accel/accel.h"
#include "host/report/memory_json.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "vgpu/texture.h"

namespace {

host::RenderOptions small(int w, int h) {
  host::RenderOptions opt;
  opt.width = w;
  opt.height = h;
  opt.profile = "h200";
  opt.threads = 2;
  return opt;
}

}  // namespace

TEST_CASE(
    "texture storage counts four bytes a channel of every texture alive, whatever its format") {
  const uint64_t before = vgpu::Texture::storage_bytes();
  std::optional<vgpu::Texture> t;
  t.emplace("half", 16, 8, 3, vgpu::Format::fp16);
  CHECK(t->bytes() == 16 * 8 * 3 * 2);  // the card's, by format
  CHECK(vgpu::Texture::storage_bytes() - before == 16 * 8 * 3 * 4);
  CHECK(vgpu::Texture::peak_storage_bytes() >= before + 16 * 8 * 3 * 4);
  {
    const vgpu::Texture copy = *t;  // a copy holds texels of its own
    CHECK(vgpu::Texture::storage_bytes() - before == 2 * 16 * 8 * 3 * 4);
    vgpu::Texture moved = std::move(*t);  // a move hands them over
    CHECK(vgpu::Texture::storage_bytes() - before == 2 * 16 * 8 * 3 * 4);
  }
  t.reset();
  CHECK(vgpu::Texture::storage_bytes() == before);
  vgpu::Texture::reset_peak_storage();
  CHECK(vgpu::Texture::peak_storage_bytes() == before);
}

TEST_CASE("the memory model's scene and structure terms are the bytes of their arrays") {
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  const uint64_t n = scene.triangle_count();
  REQUIRE(n > 0);
  REQUIRE(scene.uv0.empty());
  // Three corners and three normals of 3 floats, a material index and an input id.
  CHECK(scene.host_bytes() == n * (6 * 12 + 2 * 4) +
                                  scene.materials.size() * sizeof(host::Material) +
                                  scene.lights.size() * sizeof(host::PointLight));
  const host::AccelParams params{host::grid_spec_for({}, scene, vgpu::profile("h200"))};
  const auto grid = host::make_accel(host::AccelKind::grid, scene, params);
  CHECK(grid->host_bytes() == (grid->grid()->voxels() + 1) * 4 + grid->grid_references() * 4);
  const auto bvh = host::make_accel(host::AccelKind::bvh, scene, params);
  CHECK(bvh->host_bytes() ==
        bvh->bvh()->nodes.size() * sizeof(host::BvhNode) + bvh->bvh()->lists.size() * 4);
  const auto kd = host::make_accel(host::AccelKind::kdtree, scene, params);
  CHECK(kd->host_bytes() ==
        kd->kd()->nodes.size() * sizeof(host::KdNode) + kd->kd()->lists.size() * 4);
  const auto g2 = host::make_accel(host::AccelKind::grid2, scene, params);
  const host::Grid2& g = *g2->grid2();
  CHECK(g2->host_bytes() == (g.coarse.start.size() + g.coarse.tris.size()) * 4 +
                                g.cells() * (12 + 4 + 12 + 12) + g.sub_cells() * (4 + 4) +
                                g.lists.size() * 4);
}

TEST_CASE(
    "a frame's memory terms hold its textures' texels, its read-back frame and its batch walk's "
    "tallies, and a frame without shadows holds no shadow rays") {
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  host::RenderOptions opt = small(40, 24);
  opt.bounces = 0;
  const host::AccelParams params{host::grid_spec_for({}, scene, vgpu::profile(opt.profile))};
  const auto accel = host::make_accel(host::AccelKind::kdtree, scene, params);
  const host::Camera cam = host::scene_camera(scene, 40.0f / 24.0f);
  vgpu::Texture::reset_peak_storage();
  const uint64_t before = vgpu::Texture::storage_bytes();
  std::optional<host::StreamTracer> with(std::in_place, scene, *accel, opt);
  const host::RenderResult r = with->render(cam);
  const host::MemoryTerms m = host::memory_terms(scene, *accel, &*with, r);
  // h200 holds every group in fp32: the emulator's texels are the card's bytes, but for the
  // counting passes' target, fp16 on the card (2 bytes a texel, 4 in the emulator).
  CHECK(m.texture_storage - before == m.textures + 40 * 24 * 2);
  CHECK(m.frame == 40 * 24 * (3 + 1 + 1) * 4);  // colour, depth and hit ids, floats
  CHECK(r.batch_walk);
  CHECK(m.walk_tallies > 0);
  CHECK(m.scene == scene.host_bytes());
  CHECK(m.structure == accel->host_bytes());
  CHECK(m.predicted() == m.process + m.image_library + m.scene + m.structure + m.texture_storage +
                             m.frame + m.walk_tallies);
  opt.shadows = false;
  const host::StreamTracer without(scene, *accel, opt);
  // The shadow rays' texture: 4 fp32 channels per pixel, one texel without shadows.
  CHECK(with->texture_bytes() - without.texture_bytes() == (40 * 24 - 1) * 16);
  with.reset();
}

TEST_CASE(
    "a frame whose textures outgrow a 2004 board's memory is refused in one line naming the "
    "scene, the figures and a profile that holds them") {
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  host::RenderOptions opt = small(1536, 1536);  // 16 fp32 bytes a texel, 473 MiB in all
  opt.profile = "gf6600";
  const host::AccelParams params{host::grid_spec_for({}, scene, vgpu::profile(opt.profile))};
  const auto accel = host::make_accel(host::AccelKind::grid, scene, params);
  try {
    const host::StreamTracer tracer(scene, *accel, opt);
    FAIL("no refusal");
  } catch (const vgpu::LimitError& e) {
    const std::string what = e.what();
    CHECK(what.find(scene.source + ": the frame's textures need ") == 0);
    CHECK(what.find("profile gf6600's board holds 256 MiB") != std::string::npos);
    CHECK(what.find("(--profile rtx4090's 24576 MiB hold them)") != std::string::npos);
    CHECK(what.find('\n') == std::string::npos);
  }
}
