// Tests for host/accel/accel.h (one interface over the four structures, made by make_accel) and
// Scene::box (the padded box every structure is built in).
#include <doctest/doctest.h>

#include <memory>
#include <string>

#include "host/accel/accel.h"
#include "host/scene/gltf_loader.h"

namespace {

host::Scene bunny() {
  return host::load_scene(host::resolve_scene("bunny"));
}

bool same_box(const host::Bounds& a, glm::vec3 lo, glm::vec3 hi) {
  return a.lo == lo && a.hi == hi;
}

}  // namespace

TEST_CASE("the scene's box is the uniform grid's, and a scene without triangles gets [-1, 1]") {
  const host::Scene s = bunny();
  const host::Bounds box = s.box();
  const host::Grid g = host::build_grid(s, host::GridSpec{glm::ivec3(3)});
  CHECK(same_box(box, g.lo, g.hi));
  const host::Bounds b = s.bounds();
  for (int a = 0; a < 3; ++a) {
    CHECK(box.lo[a] < b.lo[a]);
    CHECK(box.hi[a] > b.hi[a]);
  }
  CHECK(same_box(host::Scene{}.box(), glm::vec3(-1.0f), glm::vec3(1.0f)));
}

TEST_CASE("make_accel builds each kind in the scene's box, with its name, summary and lists") {
  const host::Scene s = bunny();
  const host::Bounds box = s.box();
  for (host::AccelKind kind : host::kAccelKinds) {
    CAPTURE(std::string(host::accel_name(kind)));
    const std::unique_ptr<host::Accel> a = host::make_accel(kind, s, {});
    CHECK(a->kind() == kind);
    CHECK(a->name() == host::accel_name(kind));
    CHECK(same_box(a->box(), box.lo, box.hi));
    // Exactly the structure of its kind is there.
    CHECK((a->grid() != nullptr) == (kind == host::AccelKind::grid));
    CHECK((a->grid2() != nullptr) == (kind == host::AccelKind::grid2));
    CHECK((a->bvh() != nullptr) == (kind == host::AccelKind::bvh));
    CHECK((a->kd() != nullptr) == (kind == host::AccelKind::kdtree));
    CHECK(a->build_ms() >= 0.0);
    if (kind == host::AccelKind::grid) {
      CHECK(a->describe().empty());  // the scene's line gives the grid
      CHECK(a->list_entries() == 0);
      CHECK(a->grid_res() == a->grid()->res);
    } else {
      // The statistics' grid is the one voxel of the box, listing every triangle.
      CHECK(a->grid_res() == glm::ivec3(1));
      CHECK(a->grid_references() == s.triangle_count());
      CHECK(a->describe().find(" ms to build)") != std::string::npos);
      CHECK(a->list_entries() > 0);
    }
  }
  CHECK(host::make_accel(host::AccelKind::kdtree, s, {})->describe().rfind("kd-tree: ", 0) == 0);
  CHECK(host::make_accel(host::AccelKind::grid2, s, {})->describe().rfind("two-level grid: ", 0) ==
        0);
}

TEST_CASE("an updated structure is the one made anew for the moved scene") {
  host::Scene s = bunny();
  for (host::AccelKind kind : host::kAccelKinds) {
    CAPTURE(std::string(host::accel_name(kind)));
    host::Scene moved = s;
    for (auto* p : {&moved.p0, &moved.p1, &moved.p2})
      for (glm::vec3& v : *p) v += glm::vec3(0.5f, 0.0f, -0.25f);
    const host::AccelParams params{host::GridSpec{glm::ivec3(8)}};
    const std::unique_ptr<host::Accel> a = host::make_accel(kind, s, params);
    CHECK(a->update(moved, "rebuild") == "rebuild");
    const std::unique_ptr<host::Accel> fresh = host::make_accel(kind, moved, params);
    CHECK(same_box(a->box(), fresh->box().lo, fresh->box().hi));
    CHECK(a->grid_res() == fresh->grid_res());
    CHECK(a->grid_references() == fresh->grid_references());
    CHECK(a->list_entries() == fresh->list_entries());
  }
  // A BVH may be refitted instead: the same topology, moved boxes.
  host::Scene moved = s;
  for (glm::vec3& v : moved.p0) v.y += 0.01f;
  const std::unique_ptr<host::Accel> bvh = host::make_accel(host::AccelKind::bvh, s, {});
  const size_t nodes = bvh->bvh()->nodes.size();
  CHECK(bvh->update(moved, "refit") == "refit");
  CHECK(bvh->bvh()->nodes.size() == nodes);
  CHECK(same_box(bvh->box(), moved.box().lo, moved.box().hi));
}
