// Each structure's typed statistics (Accel::stats(), host/accel/accel_stats.h): the alternative
// of its kind, every field the structure's own count. The report room writes them as JSON
// (tests/report/test_stats_parts_json.cpp checks the keys).
#include <doctest/doctest.h>

#include <memory>
#include <string>
#include <variant>

#include "host/accel/accel.h"
#include "host/scene/gltf_loader.h"

TEST_CASE("each structure hands up its own statistics, every field its structure's count") {
  const host::Scene s = host::load_scene(host::resolve_scene("bunny-low"));
  const host::AccelParams params{host::GridSpec{glm::ivec3(5, 6, 7)}};
  for (host::AccelKind kind : host::kAccelKinds) {
    CAPTURE(std::string(host::accel_name(kind)));
    const std::unique_ptr<host::Accel> a = host::make_accel(kind, s, params);
    const host::AccelStats st = a->stats();
    if (const host::Grid* g = a->grid()) {
      const auto& x = std::get<host::GridStats>(st);
      CHECK(x.voxels == glm::ivec3(5, 6, 7));
      CHECK(x.references == g->references());
      CHECK(x.build_ms == g->build_ms);
    } else if (const host::Grid2* g2 = a->grid2()) {
      const auto& x = std::get<host::Grid2Stats>(st);
      CHECK(x.coarse == g2->coarse.res);
      CHECK(x.crowded_cells == g2->crowded);
      CHECK(x.sub_cells == g2->sub_cells());
      CHECK(x.list_entries == g2->lists.size());
      CHECK(x.references == g2->references);
      CHECK(x.max_list == g2->max_list);
      CHECK(x.build_ms == g2->build_ms);
    } else if (const host::Bvh* b = a->bvh()) {
      const auto& x = std::get<host::BvhStats>(st);
      CHECK(x.nodes == b->nodes.size());
      CHECK(x.leaves == b->leaves);
      CHECK(x.depth == b->depth);
      CHECK(x.max_leaf == b->max_leaf);
      CHECK(x.references == b->references());
      CHECK(x.sah_cost == b->sah_cost);
      CHECK(x.build_ms == b->build_ms);
    } else {
      const host::KdTree* k = a->kd();
      REQUIRE(k != nullptr);
      const auto& x = std::get<host::KdTreeStats>(st);
      CHECK(x.nodes == k->nodes.size());
      CHECK(x.leaves == k->leaves);
      CHECK(x.empty_leaves == k->empty_leaves);
      CHECK(x.depth == k->depth);
      CHECK(x.max_leaf == k->max_leaf);
      CHECK(x.references == k->references());
      CHECK(x.sah_cost == k->sah_cost);
      CHECK(x.build_ms == k->build_ms);
    }
  }
}
