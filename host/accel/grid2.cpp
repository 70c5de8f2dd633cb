// The two-level grid's host build (see grid2.h): the coarse grid at a low density, then one
// uniform grid per crowded cell over the cell's box, built from the cell's triangles alone.
#include "host/accel/grid2.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <stdexcept>
#include <thread>

#include "host/common/parallel.h"

namespace host {

glm::ivec3 grid2_sub_resolution(const Bounds& cell, const Bounds& occupied, size_t triangles) {
  const glm::ivec3 r = auto_resolution(occupied, triangles);
  glm::dvec3 res(1.0);
  for (int a = 0; a < 3; ++a) {
    const double occ = double(occupied.hi[a]) - double(occupied.lo[a]);
    const double ext = double(cell.hi[a]) - double(cell.lo[a]);
    res[a] = occ > 0.0
                 ? std::clamp(ext / (occ / double(r[a])), double(r[a]), double(kMaxAutoGridRes))
                 : double(r[a]);
  }
  const double cells = res.x * res.y * res.z, budget = kGrid2SubBudget * double(triangles);
  if (cells > budget) res *= std::cbrt(budget / cells);
  glm::ivec3 out;
  for (int a = 0; a < 3; ++a)
    out[a] = int(std::clamp(std::round(res[a]), 1.0, double(kMaxAutoGridRes)));
  return out;
}

Bounds grid2_occupied(const Scene& part, const Bounds& cell) {
  Bounds occ;
  for (size_t t = 0; t < part.triangle_count(); ++t) {
    const glm::vec3 centre = (part.p0[t] + part.p1[t] + part.p2[t]) / 3.0f;
    if (glm::any(glm::lessThan(centre, cell.lo)) || glm::any(glm::greaterThan(centre, cell.hi)))
      continue;
    for (const glm::vec3& p : {part.p0[t], part.p1[t], part.p2[t]}) occ.extend(p);
  }
  if (occ.empty()) return cell;
  occ.lo = glm::max(occ.lo, cell.lo);
  occ.hi = glm::min(occ.hi, cell.hi);
  return occ;
}

Grid2 build_grid2(const Scene& scene, unsigned threads) {
  const auto t_begin = std::chrono::steady_clock::now();
  Grid2 g;
  const glm::ivec3 res =
      auto_resolution(scene.bounds(), scene.triangle_count(), kGrid2CoarseDensity);
  g.coarse = build_grid(scene, GridSpec{res}, threads);
  const Grid& c = g.coarse;
  const size_t cells = c.voxels();

  // Crowded cells, each built alone (its own scene of its triangles, ids mapped back); the
  // cells are shared out in contiguous ranges and kept per cell, so the order is fixed.
  std::vector<size_t> crowded;
  for (size_t v = 0; v < cells; ++v)
    if (c.start[v + 1] - c.start[v] > kGrid2Crowded) crowded.push_back(v);
  g.sub_res.assign(cells, glm::ivec3(1));
  g.sub_lo.resize(cells);
  g.sub_cell.resize(cells);
  for (size_t v = 0; v < cells; ++v) {
    const glm::ivec3 xyz(int(v % size_t(c.res.x)), int(v / size_t(c.res.x) % size_t(c.res.y)),
                         int(v / (size_t(c.res.x) * size_t(c.res.y))));
    for (int a = 0; a < 3; ++a) g.sub_lo[v][a] = float(c.boundary(a, xyz[a]));
    g.sub_cell[v] = c.cell;
  }
  std::vector<Grid> sub(crowded.size());
  unsigned workers = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
  workers = unsigned(std::clamp<size_t>(crowded.size(), 1, workers));
  std::vector<std::exception_ptr> errors(workers);
  {
    auto run = [&](unsigned k) {
      try {
        for (size_t i = crowded.size() * k / workers; i < crowded.size() * (k + 1) / workers; ++i) {
          const size_t v = crowded[i];
          Scene part;
          for (uint32_t t : c.triangles_in(v)) {
            part.p0.push_back(scene.p0[t]);
            part.p1.push_back(scene.p1[t]);
            part.p2.push_back(scene.p2[t]);
          }
          // The cell's box as the coarse grid cuts it, rounded to float; its far faces are the
          // next cell's near ones (the last cell's, the grid box's).
          glm::vec3 lo = g.sub_lo[v], hi;
          const glm::ivec3 xyz(int(v % size_t(c.res.x)), int(v / size_t(c.res.x) % size_t(c.res.y)),
                               int(v / (size_t(c.res.x) * size_t(c.res.y))));
          for (int a = 0; a < 3; ++a)
            hi[a] = xyz[a] + 1 == c.res[a] ? c.hi[a] : float(c.boundary(a, xyz[a] + 1));
          Bounds box;
          box.lo = lo;
          box.hi = hi;
          const Bounds occupied = grid2_occupied(part, box);
          sub[i] = build_grid_in_box(part, lo, hi,
                                     grid2_sub_resolution(box, occupied, part.triangle_count()), 1);
          // Back to the scene's triangle ids (ascending, as the cell lists them).
          const std::span<const uint32_t> ids = c.triangles_in(v);
          for (uint32_t& t : sub[i].tris) t = ids[t];
        }
      } catch (...) {
        errors[k] = std::current_exception();
      }
    };
    std::vector<std::jthread> pool;
    for (unsigned k = 1; k < workers; ++k) pool.emplace_back(run, k);
    run(0);
  }
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);

  // The textures' arrays: every cell's sub-cells in cell order, the lists after entry 0's -1,
  // reserved whole (no array grows by doubling), each sub-grid freed once copied.
  size_t sub_cells = 0, entries = 1;
  for (size_t v = 0, k = 0; v < cells; ++v) {
    const bool own = k < crowded.size() && crowded[k] == v;
    const size_t n = own ? sub[k].voxels() : 1;
    sub_cells += n;
    entries += n + (own ? sub[k].tris.size() : c.triangles_in(v).size());
    k += own;
  }
  g.list_start.reserve(sub_cells);
  g.cell_of.reserve(sub_cells);
  g.lists.reserve(entries);
  g.first.resize(cells);
  g.lists.push_back(-1);
  auto add_list = [&](std::span<const uint32_t> tris, uint32_t cell) {
    g.cell_of.push_back(cell);
    if (tris.empty()) {
      g.list_start.push_back(0);
      return;
    }
    g.list_start.push_back(int32_t(g.lists.size()));
    for (uint32_t t : tris) g.lists.push_back(int32_t(t));
    g.lists.push_back(-1);
    g.references += tris.size();
    g.max_list = std::max(g.max_list, int(tris.size()));
  };
  size_t next_crowded = 0;
  for (size_t v = 0; v < cells; ++v) {
    g.first[v] = uint32_t(g.list_start.size());
    if (next_crowded < crowded.size() && crowded[next_crowded] == v) {
      const Grid s = std::move(sub[next_crowded++]);  // freed once copied
      g.sub_res[v] = s.res;
      g.sub_lo[v] = s.lo;
      g.sub_cell[v] = s.cell;
      g.crowded += s.voxels() > 1;
      for (size_t k = 0; k < s.voxels(); ++k) add_list(s.triangles_in(k), uint32_t(v));
    } else {
      add_list(c.triangles_in(v), uint32_t(v));
    }
    if (g.lists.size() > size_t(std::numeric_limits<int32_t>::max()))
      throw std::length_error("two-level grid: more than 2^31 list entries");
  }
  g.build_ms = ms_since(t_begin);
  return g;
}

}  // namespace host
