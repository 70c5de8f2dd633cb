// Which acceleration structure a frame walks (--accel): the paper's uniform grid, or an
// extension built beside it. The grid is always there: it gives every structure the padded
// scene box (and the lengths derived from its diagonal); with another structure it is one voxel.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include "host/accel/bvh.h"
#include "host/accel/grid.h"
#include "host/accel/grid2.h"
#include "host/accel/kdtree.h"

namespace host {

enum class AccelKind { grid, bvh, kdtree, grid2 };
inline constexpr AccelKind kAccelKinds[] = {AccelKind::grid, AccelKind::grid2, AccelKind::bvh,
                                            AccelKind::kdtree};

inline std::string_view accel_name(AccelKind k) {
  return k == AccelKind::grid    ? "grid"
         : k == AccelKind::grid2 ? "grid2"
         : k == AccelKind::bvh   ? "bvh"
                                 : "kdtree";
}

// "grid", "grid2", "bvh" or "kdtree"; throws std::invalid_argument naming the text and the
// known names.
inline AccelKind parse_accel_kind(const std::string& text) {
  for (AccelKind k : kAccelKinds)
    if (text == accel_name(k)) return k;
  throw std::invalid_argument("unknown acceleration structure '" + text +
                              "' (known: grid, grid2, bvh, kdtree)");
}

// The structures of one scene, not owned: `grid` always; `bvh`, `kd` or `grid2` where kind
// names it.
struct Accel {
  AccelKind kind = AccelKind::grid;
  const Grid* grid = nullptr;
  const Bvh* bvh = nullptr;
  const KdTree* kd = nullptr;
  const Grid2* grid2 = nullptr;
};

}  // namespace host
