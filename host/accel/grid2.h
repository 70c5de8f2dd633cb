// The two-level grid ("grilla de dos niveles", an extension; Jevans & Wyvill 1989, Kalojanov,
// Billeter & Slusallek 2011): a coarse uniform grid over the scene box whose crowded cells hold
// a uniform grid of their own, at the paper's automatic resolution for the cell's triangles.
// Every coarse cell has a sub-grid (1x1x1 where it is not crowded), so a walk is always a coarse
// cell and a sub-cell in it; kernels/grid2.h walks it, kernels/layout.h gives its textures.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "host/accel/grid.h"
#include "host/scene/scene.h"

namespace host {

// The coarse grid aims at kGrid2CoarseDensity cells per triangle (the uniform grid's rule with a
// lower density: Kalojanov et al.'s top level is coarse); a cell listing more than
// kGrid2Crowded triangles is crowded and gets a sub-grid (grid2_sub_resolution).
inline constexpr double kGrid2CoarseDensity = 0.25;
inline constexpr uint32_t kGrid2Crowded = 8;
// A sub-grid has at most kGrid2SubBudget sub-cells per triangle of its cell.
inline constexpr double kGrid2SubBudget = 64.0;

// The sub-grid resolution of a crowded cell `cell` whose `triangles` occupy `occupied`
// (grid2_occupied, below): the grid's automatic resolution for the occupied
// part (auto_resolution, kGridDensity), its voxel size carried over the whole cell (so a small
// object in a large cell, the teapot in a stadium, is cut as finely as if it filled the cell),
// each axis at most kMaxAutoGridRes, scaled down evenly to at most kGrid2SubBudget sub-cells
// per triangle. An axis the triangles occupy flat keeps auto_resolution's count.
glm::ivec3 grid2_sub_resolution(const Bounds& cell, const Bounds& occupied, size_t triangles);
// The part of `cell` the triangles of `part` occupy: the union of the bounding boxes of those
// whose centroid lies in the cell (a floor reaching across many cells belongs to none of them),
// clipped to the cell; the whole cell where no centroid lies in it.
Bounds grid2_occupied(const Scene& part, const Bounds& cell);

struct Grid2 {
  // The coarse grid: the padded scene box (the uniform grid's), its resolution and cell size,
  // and the triangles of each coarse cell (only their count is used after the build).
  Grid coarse;
  // Per coarse cell c (Grid::index order): the sub-grid's resolution and its first sub-cell;
  // the sub-cells of c are first[c] .. first[c] + res.x res.y res.z - 1, x fastest.
  std::vector<glm::ivec3> sub_res;
  std::vector<uint32_t> first;
  // Per coarse cell: the sub-grid's box minimum and sub-cell size as its build cut it (float,
  // world space); the kernels recompute them from the coarse grid's uniforms.
  std::vector<glm::vec3> sub_lo, sub_cell;
  // Per sub-cell k: the first entry of its list in `lists` and its coarse cell.
  std::vector<int32_t> list_start;
  std::vector<uint32_t> cell_of;
  // Triangle ids of each sub-cell, ascending, closed by -1; entry 0 is a -1 every empty
  // sub-cell shares.
  std::vector<int32_t> lists;
  int crowded = 0;          // coarse cells with a sub-grid of more than one cell
  int max_list = 0;         // longest sub-cell list
  uint64_t references = 0;  // (sub-cell, triangle) pairs
  double build_ms = 0;

  size_t cells() const { return coarse.voxels(); }
  size_t sub_cells() const { return list_start.size(); }
  size_t memory_bytes() const {
    return cells() * 16 + sub_cells() * 8 + lists.size() * sizeof(int32_t);
  }
  // Sub-cell boundary i along `axis` of coarse cell c (Grid::index), world space, in double
  // from the float fields as Grid::boundary is.
  double sub_boundary(size_t c, int axis, int i) const {
    return double(sub_lo[c][axis]) + double(i) * double(sub_cell[c][axis]);
  }
};

// Builds the two-level grid over the uniform grid's padded box. `threads` as build_grid's; the
// result is the same for any count.
Grid2 build_grid2(const Scene& scene, unsigned threads = 0);

}  // namespace host
