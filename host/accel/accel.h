// Which acceleration structure a frame walks (--accel): the paper's uniform grid, or an
// extension built beside it. The grid is always there: it gives every structure the padded
// scene box (and the lengths derived from its diagonal); with another structure it is one voxel.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include "host/accel/bvh.h"
#include "host/accel/grid.h"

namespace host {

enum class AccelKind { grid, bvh };

inline std::string_view accel_name(AccelKind k) {
  return k == AccelKind::grid ? "grid" : "bvh";
}

// "grid" or "bvh"; throws std::invalid_argument naming the text and the known names.
inline AccelKind parse_accel_kind(const std::string& text) {
  if (text == "grid") return AccelKind::grid;
  if (text == "bvh") return AccelKind::bvh;
  throw std::invalid_argument("unknown acceleration structure '" + text +
                              "' (known: grid, bvh, auto)");
}

// The structures of one scene, not owned: `grid` always; `bvh` where kind is bvh.
struct Accel {
  AccelKind kind = AccelKind::grid;
  const Grid* grid = nullptr;
  const Bvh* bvh = nullptr;
};

}  // namespace host
