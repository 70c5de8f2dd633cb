// Tests for host/accel/grid2 (the two-level grid): the layout the kernels read (each coarse
// cell's sub-grid, its sub-cells in order, each sub-cell's list closed by -1), exact lists
// against a brute-force overlap test, crowded cells cut at the grid's automatic resolution, and
// the same structure for any thread count.
#include <doctest/doctest.h>

#include <algorithm>
#include <vector>

#include "host/accel/grid.h"
#include "host/accel/grid2.h"
#include "host/scene/gltf_loader.h"

namespace {

// The triangles a sub-cell lists, read from the arrays as the kernels do.
std::vector<uint32_t> listed(const host::Grid2& g, size_t k) {
  std::vector<uint32_t> out;
  for (int32_t e = g.list_start[k]; g.lists[size_t(e)] >= 0; ++e)
    out.push_back(uint32_t(g.lists[size_t(e)]));
  return out;
}

bool same(const host::Grid2& a, const host::Grid2& b) {
  return a.coarse.res == b.coarse.res && a.coarse.tris == b.coarse.tris && a.sub_res == b.sub_res &&
         a.first == b.first && a.list_start == b.list_start && a.cell_of == b.cell_of &&
         a.lists == b.lists && a.sub_lo == b.sub_lo && a.sub_cell == b.sub_cell;
}

}  // namespace

TEST_CASE("a two-level grid lists in each sub-cell exactly the triangles overlapping its box") {
  const host::Scene s = host::load_scene(host::resolve_scene("bunny-low"));
  const host::Grid2 g = host::build_grid2(s, 2);
  const host::Grid& c = g.coarse;
  REQUIRE(g.crowded > 0);
  REQUIRE(g.lists.at(0) == -1);
  REQUIRE(g.first.size() == g.cells());
  size_t k = 0;
  uint64_t refs = 0;
  for (size_t v = 0; v < g.cells(); ++v) {
    CAPTURE(v);
    REQUIRE(g.first[v] == k);  // sub-cells in cell order, none skipped
    const glm::ivec3 r = g.sub_res[v];
    const auto in_cell = c.triangles_in(v);
    if (in_cell.size() > host::kGrid2Crowded) {
      // The cell's box as the build cuts it: its far faces the next cell's near ones.
      const glm::ivec3 xyz(int(v % size_t(c.res.x)), int(v / size_t(c.res.x) % size_t(c.res.y)),
                           int(v / (size_t(c.res.x) * size_t(c.res.y))));
      host::Bounds box;
      for (int a = 0; a < 3; ++a) {
        box.lo[a] = float(c.boundary(a, xyz[a]));
        box.hi[a] = xyz[a] + 1 == c.res[a] ? c.hi[a] : float(c.boundary(a, xyz[a] + 1));
      }
      CHECK(g.sub_lo[v] == box.lo);
      host::Scene part;
      for (uint32_t t : in_cell) {
        part.p0.push_back(s.p0[t]);
        part.p1.push_back(s.p1[t]);
        part.p2.push_back(s.p2[t]);
      }
      CHECK(r == host::grid2_sub_resolution(box, host::grid2_occupied(part, box), in_cell.size()));
    } else {
      CHECK(r == glm::ivec3(1));
    }
    for (int z = 0; z < r.z; ++z)
      for (int y = 0; y < r.y; ++y)
        for (int x = 0; x < r.x; ++x, ++k) {
          CHECK(g.cell_of[k] == v);
          const glm::ivec3 sc(x, y, z);
          glm::dvec3 lo, hi;
          for (int a = 0; a < 3; ++a) {
            lo[a] = g.sub_boundary(v, a, sc[a]);
            hi[a] = g.sub_boundary(v, a, sc[a] + 1);
          }
          // Brute force over the coarse cell's triangles (a triangle outside the cell cannot
          // overlap its sub-cells); a cell that is not cut lists the coarse cell's own.
          std::vector<uint32_t> want;
          for (uint32_t t : in_cell) {
            const glm::dvec3 tri[3] = {glm::dvec3(s.p0[t]), glm::dvec3(s.p1[t]),
                                       glm::dvec3(s.p2[t])};
            if (r == glm::ivec3(1) || host::triangle_box_overlap(tri, lo, hi)) want.push_back(t);
          }
          const std::vector<uint32_t> got = listed(g, k);
          CHECK(got == want);
          CHECK(int(got.size()) <= g.max_list);
          if (got.empty()) CHECK(g.list_start[k] == 0);  // the shared -1
          refs += got.size();
        }
  }
  CHECK(k == g.sub_cells());
  CHECK(refs == g.references);
}

TEST_CASE("a crowded cell's sub-grid cuts a small occupied part as finely as a full cell") {
  host::Bounds cell, occ;
  cell.lo = glm::vec3(0.0f);
  cell.hi = glm::vec3(10.0f, 1.0f, 10.0f);
  // Filling the cell: auto_resolution's own count (400 voxels over 10x1x10: 20x2x20 would be
  // 800; cbrt(400 / 100) = 1.587 per unit gives 16x2x16).
  CHECK(host::grid2_sub_resolution(cell, cell, 100) == host::auto_resolution(cell, 100));
  CHECK(host::grid2_sub_resolution(cell, cell, 100) == glm::ivec3(16, 2, 16));
  // A unit cube of it occupied: 7 voxels per unit (cbrt 400 = 7.37), carried over the cell:
  // 70x7x70 = 34,300 sub-cells, over the budget of 64 x 100 = 6,400: scaled by
  // cbrt(6400 / 34300) = 0.5714 to 40x4x40.
  occ.lo = glm::vec3(2.0f, 0.0f, 2.0f);
  occ.hi = glm::vec3(3.0f, 1.0f, 3.0f);
  CHECK(host::grid2_sub_resolution(cell, occ, 100) == glm::ivec3(40, 4, 40));
  // Flat along y (a floor piece): y keeps auto_resolution's single cell.
  occ.hi.y = 0.0f;
  CHECK(host::grid2_sub_resolution(cell, occ, 100).y == 1);
}

TEST_CASE("the occupied part of a cell leaves out triangles whose centroid lies outside it") {
  host::Bounds cell;
  cell.lo = glm::vec3(0.0f);
  cell.hi = glm::vec3(10.0f);
  host::Scene part;
  // A small triangle inside (centroid (2, 3, 4)) and a huge floor triangle crossing the cell
  // whose centroid (33.3, 0.5, 33.3) lies outside it.
  part.p0 = {{1, 2, 3}, {-50, 0.5f, -50}};
  part.p1 = {{3, 3, 4}, {150, 0.5f, -50}};
  part.p2 = {{2, 4, 5}, {-50, 0.5f, 200}};
  const host::Bounds occ = host::grid2_occupied(part, cell);
  CHECK(occ.lo == glm::vec3(1, 2, 3));
  CHECK(occ.hi == glm::vec3(3, 4, 5));
  // The floor alone: the whole cell.
  part.p0.erase(part.p0.begin());
  part.p1.erase(part.p1.begin());
  part.p2.erase(part.p2.begin());
  const host::Bounds all = host::grid2_occupied(part, cell);
  CHECK(all.lo == cell.lo);
  CHECK(all.hi == cell.hi);
}

TEST_CASE("a two-level grid's coarse grid is the uniform grid at the low density, padded alike") {
  const host::Scene s = host::load_scene(host::resolve_scene("bunny-low"));
  const host::Grid2 g = host::build_grid2(s);
  const host::Grid box = host::build_grid(s, host::GridSpec{glm::ivec3(1)});
  CHECK(g.coarse.lo == box.lo);
  CHECK(g.coarse.hi == box.hi);
  CHECK(g.coarse.res ==
        host::auto_resolution(s.bounds(), s.triangle_count(), host::kGrid2CoarseDensity));
}

TEST_CASE("a two-level grid is the same for 1, 2 and 3 build threads") {
  const host::Scene s = host::load_scene(host::resolve_scene("teapot"));
  const host::Grid2 a = host::build_grid2(s, 1);
  CHECK(same(a, host::build_grid2(s, 2)));
  CHECK(same(a, host::build_grid2(s, 3)));
}

TEST_CASE("a scene without triangles gives one coarse cell with an empty list") {
  const host::Scene s;
  const host::Grid2 g = host::build_grid2(s);
  CHECK(g.cells() == 1);
  CHECK(g.sub_cells() == 1);
  CHECK(g.list_start[0] == 0);
  CHECK(g.lists == std::vector<int32_t>{-1});
  CHECK(g.crowded == 0);
}
