// Offline construction of the uniform grid (see grid.h): resolution parsing and the automatic
// rule, the grid over the scene's padded box (Scene::box()), exact triangle/voxel overlap, and the
// CSR voxel lists.
#include "host/accel/grid.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <thread>

#include "host/common/parallel.h"

namespace host {

namespace {

int parse_positive(std::string_view part, const std::string& text) {
  auto fail = [&](std::string_view why) {
    std::string msg = "grid resolution '";
    msg.append(text).append("': ").append(why).append(" (expected auto, N or AxBxC)");
    throw std::invalid_argument(msg);
  };
  if (part.empty()) fail("empty number");
  long value = 0;
  for (char c : part) {
    if (c < '0' || c > '9') {
      std::string why = "'";
      fail(why.append(part).append("' is not a positive integer"));
    }
    value = value * 10 + (c - '0');
    if (value > kMaxGridRes) fail("each count must be at most " + std::to_string(kMaxGridRes));
  }
  if (value == 0) fail("each count must be at least 1");
  return int(value);
}

// First guess of the voxel holding coordinate x along `axis`: floor((x - lo) / cell), clamped to
// [0, res - 1] (NaN gives 0). The division may round across a plane, so callers settle the guess
// against the exact boundaries, each with its own rule for points on a plane.
int voxel_guess(const Grid& g, int axis, double x) {
  const double f = std::floor((x - double(g.lo[axis])) / double(g.cell[axis]));
  return std::isnan(f) ? 0 : int(std::clamp(f, 0.0, double(g.res[axis] - 1)));
}

}  // namespace

GridSpec parse_grid_spec(const std::string& text) {
  if (text == "auto") return GridSpec{};
  std::vector<std::string_view> parts;
  std::string_view rest(text);
  for (;;) {
    size_t x = rest.find_first_of("xX");
    parts.push_back(rest.substr(0, x));
    if (x == std::string_view::npos) break;
    rest.remove_prefix(x + 1);
  }
  if (parts.size() != 1 && parts.size() != 3) {
    throw std::invalid_argument("grid resolution '" + text +
                                "': expected auto, N or AxBxC (three counts)");
  }
  GridSpec spec;
  for (int a = 0; a < 3; ++a) spec.res[a] = parse_positive(parts[parts.size() == 1 ? 0 : a], text);
  return spec;
}

glm::ivec3 auto_resolution(const Bounds& bounds, size_t triangles, double density) {
  if (bounds.empty() || triangles == 0) return glm::ivec3(1);
  const glm::dvec3 extent = glm::dvec3(bounds.hi) - glm::dvec3(bounds.lo);
  const double budget = density * double(triangles);  // voxels wanted
  bool active[3];
  glm::dvec3 r(1.0);
  for (int a = 0; a < 3; ++a) active[a] = extent[a] > 0.0;
  // Axes whose share comes out under one voxel get exactly one; the others share the budget.
  for (int round = 0; round < 3; ++round) {
    int axes = 0;
    double volume = 1.0;
    for (int a = 0; a < 3; ++a)
      if (active[a]) {
        ++axes;
        volume *= extent[a];
      }
    if (axes == 0) break;
    const double k = std::pow(budget / volume, 1.0 / axes);  // voxels per world unit
    bool changed = false;
    for (int a = 0; a < 3; ++a) {
      if (!active[a]) continue;
      r[a] = extent[a] * k;
      if (!(r[a] >= 1.0)) {
        active[a] = false;
        r[a] = 1.0;
        changed = true;
      }
    }
    if (!changed) break;
  }
  glm::ivec3 res;
  for (int a = 0; a < 3; ++a)
    res[a] = int(std::clamp(std::round(r[a]), 1.0, double(kMaxAutoGridRes)));
  return res;
}

glm::ivec3 Grid::voxel_of(glm::dvec3 p) const {
  glm::ivec3 v;
  for (int a = 0; a < 3; ++a) {
    const int last = res[a] - 1;
    int i = voxel_guess(*this, a, p[a]);
    // Settle against the exact boundaries: half-open slabs.
    while (i > 0 && p[a] < boundary(a, i)) --i;
    while (i < last && p[a] >= boundary(a, i + 1)) ++i;
    v[a] = i;
  }
  return v;
}

void Grid::voxel_box(glm::ivec3 v, glm::dvec3& box_lo, glm::dvec3& box_hi) const {
  for (int a = 0; a < 3; ++a) {
    box_lo[a] = boundary(a, v[a]);
    box_hi[a] = boundary(a, v[a] + 1);
  }
}

bool triangle_box_overlap(const glm::dvec3 tri[3], glm::dvec3 box_lo, glm::dvec3 box_hi) {
  // Box moved to [0, h]: smaller magnitudes, and a vertex on a box face becomes exactly 0 or h.
  const glm::dvec3 h = box_hi - box_lo;
  const glm::dvec3 v0 = tri[0] - box_lo, v1 = tri[1] - box_lo, v2 = tri[2] - box_lo;

  // Box face normals: the bounding boxes must overlap.
  for (int a = 0; a < 3; ++a) {
    if (std::max({v0[a], v1[a], v2[a]}) < 0.0 || std::min({v0[a], v1[a], v2[a]}) > h[a])
      return false;
  }
  // Strict comparisons: a projection that only touches the box's does not separate.
  auto separated = [&](glm::dvec3 axis) {
    const double p0 = glm::dot(axis, v0), p1 = glm::dot(axis, v1), p2 = glm::dot(axis, v2);
    double box_min = 0.0, box_max = 0.0;
    for (int c = 0; c < 3; ++c) (axis[c] > 0.0 ? box_max : box_min) += axis[c] * h[c];
    return std::max({p0, p1, p2}) < box_min || std::min({p0, p1, p2}) > box_max;
  };
  const glm::dvec3 edge[3] = {v1 - v0, v2 - v1, v0 - v2};
  for (const glm::dvec3& e : edge) {
    if (separated({0.0, e.z, -e.y}) ||  // e × x
        separated({-e.z, 0.0, e.x}) ||  // e × y
        separated({e.y, -e.x, 0.0}))    // e × z
      return false;
  }
  return !separated(glm::cross(edge[0], edge[1]));
}

namespace {

// Voxels i along `axis` whose closed slab [boundary(i), boundary(i+1)] meets [a, b]:
// first = smallest i with boundary(i+1) >= a, last = largest i with boundary(i) <= b, clamped.
void voxel_span(const Grid& g, int axis, double a, double b, int& first, int& last) {
  const int top = g.res[axis] - 1;
  int i = voxel_guess(g, axis, a);
  while (i > 0 && g.boundary(axis, i) >= a) --i;
  while (i < top && g.boundary(axis, i + 1) < a) ++i;
  first = i;
  i = voxel_guess(g, axis, b);
  while (i < top && g.boundary(axis, i + 1) <= b) ++i;
  while (i > 0 && g.boundary(axis, i) > b) --i;
  last = i;
}

// (voxel, triangle) pairs of one contiguous triangle range, triangles ascending.
struct References {
  std::vector<uint32_t> voxel, tri;
};

void insert_triangles(const Grid& g, const Scene& scene, size_t begin, size_t end,
                      References& out) {
  out.voxel.reserve((end - begin) * 2);
  out.tri.reserve((end - begin) * 2);
  for (size_t t = begin; t < end; ++t) {
    const glm::dvec3 v[3] = {glm::dvec3(scene.p0[t]), glm::dvec3(scene.p1[t]),
                             glm::dvec3(scene.p2[t])};
    const glm::dvec3 tlo = glm::min(glm::min(v[0], v[1]), v[2]);
    const glm::dvec3 thi = glm::max(glm::max(v[0], v[1]), v[2]);
    glm::ivec3 first, last;
    for (int a = 0; a < 3; ++a) voxel_span(g, a, tlo[a], thi[a], first[a], last[a]);
    auto push = [&](glm::ivec3 vox) {
      out.voxel.push_back(uint32_t(g.index(vox)));
      out.tri.push_back(uint32_t(t));
    };
    if (first == last) {  // bounding box inside one closed voxel: so is the triangle
      push(first);
      continue;
    }
    // Walk columns along the two minor axes of the normal; in each column the triangle's plane
    // narrows the range along the dominant axis d before the exact test.
    const glm::dvec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
    const glm::dvec3 an = glm::abs(n);
    const int d = an.x >= an.y ? (an.x >= an.z ? 0 : 2) : (an.y >= an.z ? 1 : 2);
    const int u = (d + 1) % 3, w = (d + 2) % 3;
    const double margin = 1e-6 * double(g.cell[d]);  // ≫ rounding of the plane evaluation
    for (int iu = first[u]; iu <= last[u]; ++iu) {
      const double u0 = std::max(g.boundary(u, iu), tlo[u]);
      const double u1 = std::min(g.boundary(u, iu + 1), thi[u]);
      for (int iw = first[w]; iw <= last[w]; ++iw) {
        const double w0 = std::max(g.boundary(w, iw), tlo[w]);
        const double w1 = std::min(g.boundary(w, iw + 1), thi[w]);
        int d0 = first[d], d1 = last[d];
        if (d1 > d0 && n[d] != 0.0) {
          // Plane n·(p - v0) = 0 solved for p_d at the column rectangle's corners.
          auto plane_d = [&](double pu, double pw) {
            return v[0][d] - (n[u] * (pu - v[0][u]) + n[w] * (pw - v[0][w])) / n[d];
          };
          const double c[4] = {plane_d(u0, w0), plane_d(u1, w0), plane_d(u0, w1), plane_d(u1, w1)};
          int p0, p1;
          voxel_span(g, d, std::min({c[0], c[1], c[2], c[3]}) - margin,
                     std::max({c[0], c[1], c[2], c[3]}) + margin, p0, p1);
          d0 = std::max(d0, p0);
          d1 = std::min(d1, p1);
        }
        for (int id = d0; id <= d1; ++id) {
          glm::ivec3 vox;
          vox[u] = iu;
          vox[w] = iw;
          vox[d] = id;
          glm::dvec3 box_lo, box_hi;
          g.voxel_box(vox, box_lo, box_hi);
          if (triangle_box_overlap(v, box_lo, box_hi)) push(vox);
        }
      }
    }
  }
}

}  // namespace

Grid build_grid(const Scene& scene, const GridSpec& spec, unsigned threads) {
  const auto t_begin = std::chrono::steady_clock::now();
  const Bounds bounds = scene.bounds();
  const glm::ivec3 res =
      spec.automatic() ? auto_resolution(bounds, scene.triangle_count()) : spec.res;
  const Bounds box = scene.box();  // padded, rounded outward to float
  Grid g = build_grid_in_box(scene, box.lo, box.hi, res, threads);
  g.build_ms = ms_since(t_begin);
  return g;
}

Grid build_grid_in_box(const Scene& scene, glm::vec3 lo, glm::vec3 hi, glm::ivec3 res,
                       unsigned threads) {
  const auto t_begin = std::chrono::steady_clock::now();
  const size_t n = scene.triangle_count();
  if (n > std::numeric_limits<uint32_t>::max())
    throw std::length_error("grid: more than 2^32 - 1 triangles");
  for (int a = 0; a < 3; ++a) {
    if (res[a] < 1 || res[a] > kMaxGridRes)
      throw std::invalid_argument("grid resolution " + std::to_string(res.x) + "x" +
                                  std::to_string(res.y) + "x" + std::to_string(res.z) +
                                  ": each count must be in [1, " + std::to_string(kMaxGridRes) +
                                  "]");
    if (!(hi[a] > lo[a])) throw std::invalid_argument("grid box: hi must exceed lo on every axis");
  }
  Grid g;
  g.lo = lo;
  g.hi = hi;
  g.res = res;
  g.cell = (g.hi - g.lo) / glm::vec3(g.res);

  // Contiguous triangle ranges per thread, merged in range order: deterministic output.
  unsigned workers = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
  workers = unsigned(std::clamp<size_t>(n / 4096, 1, workers));
  std::vector<References> refs(workers);
  std::vector<std::exception_ptr> errors(workers);
  {
    auto run = [&](unsigned k) {
      try {
        insert_triangles(g, scene, n * k / workers, n * (k + 1) / workers, refs[k]);
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

  // Counting sort by voxel. start[v + 1] counts voxel v, then becomes its write cursor (begin of
  // v); after the scatter it holds the end of v = begin of v + 1.
  const size_t voxels = g.voxels();
  g.start.assign(voxels + 1, 0);
  uint64_t total = 0;
  for (const References& r : refs) {
    total += r.voxel.size();
    for (uint32_t v : r.voxel) ++g.start[v + 1];
  }
  if (total > std::numeric_limits<uint32_t>::max())
    throw std::length_error("grid: more than 2^32 - 1 voxel references; lower the resolution");
  uint32_t running = 0;
  for (size_t v = 0; v < voxels; ++v) {
    const uint32_t count = g.start[v + 1];
    g.start[v + 1] = running;
    running += count;
  }
  g.tris.resize(total);
  for (References& r : refs) {
    for (size_t k = 0; k < r.voxel.size(); ++k) g.tris[g.start[r.voxel[k] + 1]++] = r.tri[k];
    r = References{};  // release as we go
  }
  g.build_ms = ms_since(t_begin);
  return g;
}

}  // namespace host
