// The acceleration structure a frame walks (--accel): the paper's uniform grid, or an extension
// built beside it (a two-level grid, a BVH, a kd-tree), made by one factory, make_accel (as
// pbrt-v4's CreateAccelerator), from one table of structures, kAccelRows (the end of this file:
// each row's kind, name, one-line description and build).
//
// Design: a small abstract base, Accel, with one subclass per structure (GridAccel, Grid2Accel,
// BvhAccel, KdAccel), each owning its structure. What every user asks of a structure (its name,
// its one-line summary, its build time, its list length, its scene box, how it follows a moved
// scene, its statistics) is a member, answered by the structure itself, so the command line,
// the statistics and --accel auto hold no switch on the kind. A learner reads one class per
// structure, top to bottom. The walks need the concrete structure: grid(), grid2(), bvh() and
// kd() give it (nullptr for the other kinds), and host/trace's table of walks, keyed by the same
// kinds (host/trace/structures.h: the stream walk, the CPU walk and the kernels each walk loads),
// gives the walk of a structure.
//
// Every structure is built in the scene's padded box (Scene::box()). A structure other than the
// grid reports, where the statistics name the grid, the one voxel that box is: resolution 1x1x1,
// every triangle listed once.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

#include "host/accel/accel_stats.h"
#include "host/accel/bvh.h"
#include "host/accel/grid.h"
#include "host/accel/grid2.h"
#include "host/accel/kdtree.h"
#include "host/scene/scene.h"

namespace host {

// The key of a structure's row in kAccelRows (the end of this file) and in host/trace's table of
// walks (host/trace/structures.h).
enum class AccelKind { grid, bvh, kdtree, grid2 };

// The name --accel spells (kAccelRows), e.g. "grid2".
std::string_view accel_name(AccelKind k);
// A row's name back to its kind; throws std::invalid_argument naming the text and the known
// names.
AccelKind parse_accel_kind(const std::string& text);
// Every row's name in the table's order, joined by ", " and the last by `last` (", " gives
// "grid, grid2, bvh, kdtree"; " or " gives "grid, grid2, bvh or kdtree").
std::string accel_names(std::string_view last = ", ");

// What the builders take: the uniform grid's resolution (the command line's --grid, already
// fitted to the profile: grid_spec_for) and the build threads (0: hardware concurrency).
struct AccelParams {
  GridSpec grid;
  unsigned threads = 0;
};

class Accel {
 public:
  virtual ~Accel() = default;
  Accel(const Accel&) = delete;
  Accel& operator=(const Accel&) = delete;

  AccelKind kind() const { return kind_; }
  std::string_view name() const { return accel_name(kind_); }
  // The padded scene box the structure was built in (Scene::box()): the diagonal every length
  // of the tracers derives from.
  const Bounds& box() const { return box_; }

  // The structure, for its walk: the one of this kind, nullptr for the others.
  virtual const Grid* grid() const { return nullptr; }
  virtual const Grid2* grid2() const { return nullptr; }
  virtual const Bvh* bvh() const { return nullptr; }
  virtual const KdTree* kd() const { return nullptr; }

  // The grid as the statistics report it ("grid", "grid_references", "grid_build_ms"): the
  // uniform grid's resolution, references and build time; for another structure the one voxel
  // its box is, listing every triangle, and the time taken to find the box.
  virtual glm::ivec3 grid_res() const { return glm::ivec3(1); }
  virtual uint64_t grid_references() const { return triangles_; }
  virtual double grid_build_ms() const { return box_ms_; }

  // The line --stats table prints under the scene's, e.g. "bvh: 1,234 nodes, ... (2.5 ms to
  // build)"; empty for the uniform grid (the scene's line gives its resolution).
  virtual std::string describe() const = 0;
  // The host's build of the structure (and of its box where that took a pass of its own), ms.
  virtual double build_ms() const = 0;
  // Entries of the triangle-list texture, which the formats must address (host/model/formats.h);
  // 0 for the uniform grid, whose lists the formats count themselves.
  virtual uint64_t list_entries() const = 0;
  // The structure's own statistics (accel_stats.h: the alternative of its kind), which the
  // report room writes as the statistics' "accel" object, after "structure".
  virtual AccelStats stats() const = 0;
  // The host's copy of the structure, bytes (its arrays' sizes: the pages it wrote): the memory model's
  // structure term (host/report/memory_json.h). The walk's textures are counted apart.
  virtual uint64_t host_bytes() const = 0;
  // A later frame of a moving scene (the same triangles, moved): the structure follows `scene`
  // as --update `how` says ("rebuild"; for a BVH also "refit" or "auto", see BvhAccel). Returns
  // what was done: "rebuild" or "refit".
  virtual std::string update(const Scene& scene, const std::string& how) = 0;

 protected:
  Accel(AccelKind kind, const Bounds& box, uint64_t triangles, double box_ms)
      : kind_(kind), box_(box), triangles_(triangles), box_ms_(box_ms) {}
  // A new box for a moved scene, timed.
  void find_box(const Scene& scene);

  AccelKind kind_;
  Bounds box_;
  uint64_t triangles_;  // the scene's, at the last build
  double box_ms_;       // time taken by Scene::box()
};

// Builds the structure of `kind` over the scene (in Scene::box()): its row's build. Throws what
// the builder throws (std::invalid_argument, std::length_error).
std::unique_ptr<Accel> make_accel(AccelKind kind, const Scene& scene, const AccelParams& params);

// The paper's uniform grid (grid.h). Its box is the grid's.
class GridAccel : public Accel {
 public:
  // A grid built elsewhere (tests put voxel planes at chosen coordinates: build_grid_in_box).
  explicit GridAccel(Grid grid, unsigned threads = 0);
  // Its row's build: the grid at params.grid's resolution.
  static std::unique_ptr<Accel> build(const Scene& scene, const AccelParams& params);
  const Grid* grid() const override { return &grid_; }
  glm::ivec3 grid_res() const override { return grid_.res; }
  uint64_t grid_references() const override { return grid_.references(); }
  double grid_build_ms() const override { return grid_.build_ms; }
  std::string describe() const override { return {}; }
  double build_ms() const override { return grid_.build_ms; }
  uint64_t list_entries() const override { return 0; }
  AccelStats stats() const override;
  uint64_t host_bytes() const override;
  // Rebuilt at the first build's resolution (so the voxel pointers keep their texture).
  std::string update(const Scene& scene, const std::string& how) override;

 private:
  Grid grid_;
  unsigned threads_;
};

// The two-level grid (grid2.h).
class Grid2Accel : public Accel {
 public:
  Grid2Accel(const Scene& scene, Grid2 g2, unsigned threads = 0, double box_ms = 0.0);
  // Its row's build, in the scene's box (found first, and timed).
  static std::unique_ptr<Accel> build(const Scene& scene, const AccelParams& params);
  const Grid2* grid2() const override { return &g2_; }
  std::string describe() const override;
  double build_ms() const override { return g2_.build_ms; }  // its coarse grid finds the box
  uint64_t list_entries() const override;
  AccelStats stats() const override;
  uint64_t host_bytes() const override;
  std::string update(const Scene& scene, const std::string& how) override;

 private:
  Grid2 g2_;
  unsigned threads_;
};

// The BVH (bvh.h), in `box` (the scene's).
class BvhAccel : public Accel {
 public:
  BvhAccel(const Scene& scene, Bvh bvh, const Bounds& box, double box_ms = 0.0);
  // Its row's build, in the scene's box (found first, and timed).
  static std::unique_ptr<Accel> build(const Scene& scene, const AccelParams& params);
  const Bvh* bvh() const override { return &bvh_; }
  std::string describe() const override;
  double build_ms() const override { return box_ms_ + bvh_.build_ms; }
  uint64_t list_entries() const override { return bvh_.lists.size(); }
  AccelStats stats() const override;
  uint64_t host_bytes() const override;
  // --update refit keeps the topology and moves the boxes (refit_bvh); auto refits until the
  // refitted tree's SAH cost passes kRefitLimit times the last build's, then builds again;
  // rebuild builds again.
  std::string update(const Scene& scene, const std::string& how) override;
  // --update auto rebuilds when the refitted BVH's SAH cost (expected node visits and triangle
  // tests per ray) has grown past this factor of its last build's.
  static constexpr double kRefitLimit = 1.25;

 private:
  Bvh bvh_;
  double built_sah_;  // the SAH cost of the last build (not refit)
};

// The kd-tree (kdtree.h). Its box is the tree's root box.
class KdAccel : public Accel {
 public:
  KdAccel(const Scene& scene, KdTree kd, double box_ms = 0.0);
  // Its row's build, in the scene's box (found first, and timed).
  static std::unique_ptr<Accel> build(const Scene& scene, const AccelParams& params);
  const KdTree* kd() const override { return &kd_; }
  std::string describe() const override;
  double build_ms() const override { return box_ms_ + kd_.build_ms; }
  uint64_t list_entries() const override { return kd_.lists.size(); }
  AccelStats stats() const override;
  uint64_t host_bytes() const override;
  std::string update(const Scene& scene, const std::string& how) override;

 private:
  KdTree kd_;
};

// The structures, one row each: the one table every list of structures comes from. To add a
// structure: add a row here (and its AccelKind), write its Accel subclass (with its statistics,
// an alternative of accel_stats.h's AccelStats, which the report room writes), its walk and its
// CPU walk, and give it its row in host/trace/structures.cpp (the same kinds in the same order,
// which a static_assert there checks); nothing else lists structures. The order is the one
// --accel's help, --accel auto's candidates and the tests' sweeps take; the first row is the
// paper's structure (the default), the others are extensions.
struct AccelRow {
  AccelKind kind;
  std::string_view name;         // as --accel spells it
  std::string_view description;  // --accel's help, in parentheses after the name
  std::unique_ptr<Accel> (*build)(const Scene& scene, const AccelParams& params);
};
inline constexpr AccelRow kAccelRows[] = {
    {AccelKind::grid, "grid", "the paper's uniform grid", &GridAccel::build},
    {AccelKind::grid2, "grid2",
     "a two-level grid: crowded cells of a coarse grid hold a grid of their own",
     &Grid2Accel::build},
    {AccelKind::bvh, "bvh", "a SAH bounding volume hierarchy walked stackless", &BvhAccel::build},
    {AccelKind::kdtree, "kdtree", "a SAH kd-tree walked by kd-restart", &KdAccel::build},
};
// The kinds, in the table's order.
inline constexpr auto kAccelKinds = [] {
  std::array<AccelKind, std::size(kAccelRows)> kinds{};
  for (size_t i = 0; i < kinds.size(); ++i) kinds[i] = kAccelRows[i].kind;
  return kinds;
}();
// The row of `kind`.
const AccelRow& accel_row(AccelKind kind);

}  // namespace host
