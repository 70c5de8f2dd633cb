// The acceleration structures behind one interface (accel.h): the table's look-ups, and each
// structure's build, summary, statistics and update for a moved scene.
#include "host/accel/accel.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iterator>
#include <stdexcept>
#include <string>
#ifdef __GLIBC__  // defined by the C library's headers above
#include <malloc.h>
#endif

#include "host/common/memory.h"
#include "host/common/parallel.h"

namespace host {

namespace {

Bounds box_of(glm::vec3 lo, glm::vec3 hi) {
  Bounds b;
  b.lo = lo;
  b.hi = hi;
  return b;
}

// "SUMMARY (X.X ms to build)", as --stats table prints a structure's line.
std::string with_build_ms(const std::string& summary, double ms) {
  char tail[64];
  std::snprintf(tail, sizeof tail, " (%.1f ms to build)", ms);
  return summary + tail;
}

}  // namespace

void Accel::find_box(const Scene& scene) {
  const auto t0 = std::chrono::steady_clock::now();
  box_ = scene.box();
  box_ms_ = ms_since(t0);
  triangles_ = scene.triangle_count();
}

// --- The table (accel.h: kAccelRows) ---

const AccelRow& accel_row(AccelKind kind) {
  for (const AccelRow& row : kAccelRows)
    if (row.kind == kind) return row;
  throw std::logic_error("no row in kAccelRows for acceleration structure kind " +
                         std::to_string(int(kind)));
}

std::string_view accel_name(AccelKind k) {
  return accel_row(k).name;
}

AccelKind parse_accel_kind(const std::string& text) {
  for (const AccelRow& row : kAccelRows)
    if (text == row.name) return row.kind;
  throw std::invalid_argument("unknown acceleration structure '" + text +
                              "' (known: " + accel_names() + ")");
}

std::string accel_names(std::string_view last) {
  std::string names;
  for (size_t i = 0; i < std::size(kAccelRows); ++i) {
    if (i > 0) names += i + 1 < std::size(kAccelRows) ? ", " : last;
    names += kAccelRows[i].name;
  }
  return names;
}

std::unique_ptr<Accel> make_accel(AccelKind kind, const Scene& scene, const AccelParams& params) {
  std::unique_ptr<Accel> accel = accel_row(kind).build(scene, params);
#ifdef __GLIBC__
  // The build's freed temporaries (a two-level grid's sub-grids, a tree's splits) back to the
  // system, so that the process holds what the memory model counts (host/report/memory_json.h).
  ::malloc_trim(0);
#endif
  return accel;
}

namespace {

// The structures other than the uniform grid are built in the scene's box, found first (and
// timed: their build time includes it).
Bounds timed_box(const Scene& scene, double& box_ms) {
  const auto t0 = std::chrono::steady_clock::now();
  const Bounds box = scene.box();
  box_ms = ms_since(t0);
  return box;
}

}  // namespace

// --- The uniform grid ---

GridAccel::GridAccel(Grid grid, unsigned threads)
    : Accel(AccelKind::grid, box_of(grid.lo, grid.hi), grid.references(), 0.0),
      grid_(std::move(grid)),
      threads_(threads) {}

std::unique_ptr<Accel> GridAccel::build(const Scene& scene, const AccelParams& params) {
  return std::make_unique<GridAccel>(build_grid(scene, params.grid, params.threads),
                                     params.threads);
}

namespace {
uint64_t grid_bytes(const Grid& g) {
  return vector_bytes(g.start) + vector_bytes(g.tris);
}
}  // namespace

uint64_t GridAccel::host_bytes() const {
  return grid_bytes(grid_);
}

uint64_t Grid2Accel::host_bytes() const {
  return grid_bytes(g2_.coarse) + vector_bytes(g2_.sub_res) + vector_bytes(g2_.first) +
         vector_bytes(g2_.sub_lo) + vector_bytes(g2_.sub_cell) + vector_bytes(g2_.list_start) +
         vector_bytes(g2_.cell_of) + vector_bytes(g2_.lists);
}

uint64_t BvhAccel::host_bytes() const {
  return vector_bytes(bvh_.nodes) + vector_bytes(bvh_.lists);
}

uint64_t KdAccel::host_bytes() const {
  return vector_bytes(kd_.nodes) + vector_bytes(kd_.lists);
}

AccelStats GridAccel::stats() const {
  return GridStats{
      .voxels = grid_.res, .references = grid_.references(), .build_ms = grid_.build_ms};
}

std::string GridAccel::update(const Scene& scene, const std::string&) {
  grid_ = build_grid(scene, GridSpec{grid_.res}, threads_);
  box_ = box_of(grid_.lo, grid_.hi);
  return "rebuild";
}

// --- The two-level grid ---

Grid2Accel::Grid2Accel(const Scene& scene, Grid2 g2, unsigned threads, double box_ms)
    : Accel(AccelKind::grid2, box_of(g2.coarse.lo, g2.coarse.hi), scene.triangle_count(), box_ms),
      g2_(std::move(g2)),
      threads_(threads) {}

std::unique_ptr<Accel> Grid2Accel::build(const Scene& scene, const AccelParams& params) {
  double box_ms = 0;
  timed_box(scene, box_ms);
  return std::make_unique<Grid2Accel>(scene, build_grid2(scene, params.threads), params.threads,
                                      box_ms);
}

std::string Grid2Accel::describe() const {
  char line[256];
  std::snprintf(line, sizeof line,
                "two-level grid: coarse %dx%dx%d, %d crowded cells, %zu sub-cells, %llu "
                "references",
                g2_.coarse.res.x, g2_.coarse.res.y, g2_.coarse.res.z, g2_.crowded, g2_.sub_cells(),
                static_cast<unsigned long long>(g2_.references));
  return with_build_ms(line, g2_.build_ms);
}

uint64_t Grid2Accel::list_entries() const {
  // Its textures address the lists and the sub-cells alike.
  return std::max<uint64_t>(g2_.lists.size(), g2_.sub_cells());
}

AccelStats Grid2Accel::stats() const {
  return Grid2Stats{.coarse = g2_.coarse.res,
                    .crowded_cells = g2_.crowded,
                    .sub_cells = g2_.sub_cells(),
                    .list_entries = g2_.lists.size(),
                    .references = g2_.references,
                    .max_list = g2_.max_list,
                    .build_ms = g2_.build_ms};
}

std::string Grid2Accel::update(const Scene& scene, const std::string&) {
  find_box(scene);
  g2_ = build_grid2(scene, threads_);
  return "rebuild";
}

// --- The BVH ---

BvhAccel::BvhAccel(const Scene& scene, Bvh bvh, const Bounds& box, double box_ms)
    : Accel(AccelKind::bvh, box, scene.triangle_count(), box_ms),
      bvh_(std::move(bvh)),
      built_sah_(bvh_.sah_cost) {}

std::unique_ptr<Accel> BvhAccel::build(const Scene& scene, const AccelParams&) {
  double box_ms = 0;
  const Bounds box = timed_box(scene, box_ms);
  return std::make_unique<BvhAccel>(scene, build_bvh(scene), box, box_ms);
}

std::string BvhAccel::describe() const {
  return with_build_ms(host::describe(bvh_), bvh_.build_ms);
}

AccelStats BvhAccel::stats() const {
  return BvhStats{.nodes = bvh_.nodes.size(),
                  .leaves = bvh_.leaves,
                  .depth = bvh_.depth,
                  .max_leaf = bvh_.max_leaf,
                  .references = bvh_.references(),
                  .sah_cost = bvh_.sah_cost,
                  .build_ms = bvh_.build_ms};
}

std::string BvhAccel::update(const Scene& scene, const std::string& how) {
  find_box(scene);
  if (how != "rebuild") {
    Bvh refitted = bvh_;
    refit_bvh(refitted, scene);
    if (how == "refit" || refitted.sah_cost <= kRefitLimit * built_sah_) {
      bvh_ = std::move(refitted);
      return "refit";
    }
  }
  bvh_ = build_bvh(scene);
  built_sah_ = bvh_.sah_cost;
  return "rebuild";
}

// --- The kd-tree ---

KdAccel::KdAccel(const Scene& scene, KdTree kd, double box_ms)
    : Accel(AccelKind::kdtree, box_of(kd.lo, kd.hi), scene.triangle_count(), box_ms),
      kd_(std::move(kd)) {}

std::unique_ptr<Accel> KdAccel::build(const Scene& scene, const AccelParams&) {
  double box_ms = 0;
  const Bounds box = timed_box(scene, box_ms);
  return std::make_unique<KdAccel>(scene, build_kdtree(scene, box.lo, box.hi), box_ms);
}

std::string KdAccel::describe() const {
  return with_build_ms(host::describe(kd_), kd_.build_ms);
}

AccelStats KdAccel::stats() const {
  return KdTreeStats{.nodes = kd_.nodes.size(),
                     .leaves = kd_.leaves,
                     .empty_leaves = kd_.empty_leaves,
                     .depth = kd_.depth,
                     .max_leaf = kd_.max_leaf,
                     .references = kd_.references(),
                     .sah_cost = kd_.sah_cost,
                     .build_ms = kd_.build_ms};
}

std::string KdAccel::update(const Scene& scene, const std::string&) {
  find_box(scene);
  kd_ = build_kdtree(scene, box_.lo, box_.hi);
  return "rebuild";
}

}  // namespace host
