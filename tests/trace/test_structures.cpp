// The table of structures, row by row: host/accel/accel.h's kAccelRows (each structure's name,
// description and build) and host/trace/structures.h's rows of walks (its stream walk, CPU walk
// and the kernels its walk loads), which every list of structures reads. A row added there is
// checked here without a line changed: its name parses back, its build gives its kind, and its
// two walks agree on the bunny and run its kernels. (The CLI's --accel help naming every row is
// tests/cli/test_cli_structures.cpp.)
#include <doctest/doctest.h>

#include <iterator>
#include <memory>
#include <set>
#include <string>

#include "host/accel/accel.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/stream/stream_tracer.h"
#include "host/trace/structures.h"
#include "tests/support/hit_compare.h"
#include "tests/support/structures.h"

TEST_CASE("the two halves of the table of structures list the same kinds in the same order") {
  const std::span<const host::WalkRow> walks = host::walk_rows();
  REQUIRE(walks.size() == std::size(host::kAccelRows));
  std::set<host::AccelKind> kinds;
  for (size_t i = 0; i < walks.size(); ++i) {
    CAPTURE(i);
    CHECK(walks[i].kind == host::kAccelRows[i].kind);
    CHECK(host::kAccelKinds[i] == host::kAccelRows[i].kind);
    CHECK(&host::walk_row(walks[i].kind) == &walks[i]);
    CHECK(&host::accel_row(walks[i].kind) == &host::kAccelRows[i]);
    kinds.insert(walks[i].kind);
  }
  CHECK(kinds.size() == walks.size());  // each kind once
  // The first row is the paper's grid, the default.
  CHECK(host::kAccelRows[0].kind == host::AccelKind::grid);
}

TEST_CASE("every row's name parses back to its kind, and the names are distinct") {
  std::set<std::string> names;
  for (const host::AccelRow& row : host::kAccelRows) {
    const std::string name(row.name);
    CAPTURE(name);
    CHECK(host::parse_accel_kind(name) == row.kind);
    CHECK(host::accel_name(row.kind) == row.name);
    CHECK_FALSE(row.description.empty());
    CHECK(host::accel_names().find(name) != std::string::npos);
    names.insert(name);
  }
  CHECK(names.size() == std::size(host::kAccelRows));
  CHECK(host::accel_names() == "grid, grid2, bvh, kdtree");
  CHECK(host::accel_names(" or ") == "grid, grid2, bvh or kdtree");
  CHECK_THROWS_WITH_AS(host::parse_accel_kind("octree"),
                       "unknown acceleration structure 'octree' (known: grid, grid2, bvh, kdtree)",
                       std::invalid_argument);
}

TEST_CASE("every row's build gives a structure of its kind on a small scene") {
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  const host::AccelParams params{host::GridSpec{glm::ivec3(8)}};
  for (const host::AccelRow& row : host::kAccelRows) {
    CAPTURE(std::string(row.name));
    const std::unique_ptr<host::Accel> a = row.build(scene, params);
    REQUIRE(a);
    CHECK(a->kind() == row.kind);
    CHECK(a->name() == row.name);
    CHECK(host::make_accel(row.kind, scene, params)->kind() == row.kind);
  }
}

namespace {

// Row `row`'s stream walk against its CPU walk on the bunny at 16x16: the same hit ids, and the
// multipass walk ran its row's step and intersection kernels and no other row's.
void check_walks(const host::WalkRow& row) {
  const test_support::Structures s = test_support::bundled_structures(row.kind, "bunny", 16, 16);
  REQUIRE(s.accel().kind() == row.kind);
  host::RenderOptions opt;
  opt.width = opt.height = 16;
  opt.threads = 2;
  opt.bounces = 0;
  opt.shadows = false;
  const host::RenderResult c = host::render_cpu(s.scene, s.accel(), s.camera, opt);
  const host::RenderResult k = host::StreamTracer(s.scene, s.accel(), opt).render(s.camera);
  CHECK(k.rays_unfinished == 0);
  CHECK(c.rays_traced == k.rays_traced);
  CHECK(test_support::check_ties(test_support::compare_ids(c, k)) == 0);
  int hits = 0;
  for (float id : k.hit_id) hits += id >= 0.0f;
  CHECK(hits > 16);  // the bunny is there
  for (const host::WalkRow& other : host::walk_rows()) {
    CAPTURE(std::string(host::accel_name(other.kind)));
    const bool ran = k.stats.find(other.kernels.steps[0]) != nullptr &&
                     k.stats.find(other.kernels.tests[0]) != nullptr;
    CHECK(ran == (other.kind == row.kind));
  }
}

}  // namespace

TEST_CASE("every row's stream walk renders the bunny with its CPU walk's hit ids and its kernels") {
  for (const host::WalkRow& row : host::walk_rows()) {
    CAPTURE(std::string(host::accel_name(row.kind)));
    CHECK_NOTHROW(check_walks(row));  // a row's walk given another kind's structure throws
  }
}
