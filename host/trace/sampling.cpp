// Where the samples of a pixel lie (host/trace/sampling.h).
#include "host/trace/sampling.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace host {

namespace {

int side_of(int spp) {
  int n = 1;
  while (n * n < spp) ++n;
  return n;
}

// splitmix64 (Steele, Lea & Flood 2014): one 64-bit step.
uint64_t splitmix(uint64_t& s) {
  uint64_t z = (s += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// A float in [0, 1) with 24 random bits (exact in float).
float unit(uint64_t& s) {
  return float(splitmix(s) >> 40) / float(1 << 24);
}

}  // namespace

std::string spp_refusal(int spp) {
  if (spp < 1 || spp > kMaxSpp)
    return std::to_string(spp) + " samples per pixel: they go from 1 to " + std::to_string(kMaxSpp);
  const int n = side_of(spp);
  if (n * n != spp)
    return std::to_string(spp) +
           " samples per pixel: not a square (the samples form an n x n grid: 1, 4, 9, 16, ..., "
           "256)";
  return {};
}

glm::vec2 sample_offset(int spp, int s, uint64_t seed) {
  if (spp <= 1) return {0.5f, 0.5f};
  const int n = side_of(spp);
  uint64_t state = seed * 0x100000001b3ull + uint64_t(s);
  const float u = unit(state), v = unit(state);
  // (i + u) / n rounds below 1 for every u < 1 and n <= 16.
  return {(float(s % n) + u) / float(n), (float(s / n) + v) / float(n)};
}

namespace {

// adaptive_levels' sides one at a time, without building the list (adaptive_rays runs once per
// pixel): the first level's side, then the one after `side`; 0 when there is none.
int first_side(int n) {
  return n > 1 ? 2 : 0;
}
int next_side(int side, int n) {
  return side >= n ? 0 : std::min(side * 2, n);
}

}  // namespace

std::vector<int> adaptive_levels(int spp) {
  const int n = side_of(spp);
  std::vector<int> levels;
  for (int side = first_side(n); side > 0; side = next_side(side, n)) levels.push_back(side);
  return levels;
}

std::vector<std::vector<glm::vec2>> kept_level_samples(int spp, uint64_t seed) {
  std::vector<std::vector<glm::vec2>> added;
  std::vector<glm::vec2> held;  // every sample so far
  for (const int side : adaptive_levels(spp)) {
    const int m = side * side;
    std::vector<uint8_t> taken(size_t(m), 0);
    for (const glm::vec2 o : held) {
      uint8_t& t = taken[size_t(int(o.y * float(side)) * side + int(o.x * float(side)))];
      if (t) return added;  // two earlier samples in one stratum
      t = 1;
    }
    std::vector<glm::vec2> level;
    for (int k = 0; k < m; ++k)
      if (!taken[size_t(k)]) level.push_back(sample_offset(m, k, seed));
    held.insert(held.end(), level.begin(), level.end());
    added.push_back(level);
  }
  return added;
}

uint32_t adaptive_rays(int spp, int samples) {
  return adaptive_rays(spp, samples, 0);
}

std::vector<glm::vec2> adaptive_level_offsets(int spp, size_t level,
                                              const std::vector<std::vector<glm::vec2>>& kept,
                                              uint64_t seed) {
  if (level < kept.size()) return kept[level];
  const int side = adaptive_levels(spp)[level], m = side * side;
  std::vector<glm::vec2> offsets;
  for (int k = 0; k < m; ++k) offsets.push_back(sample_offset(m, k, seed));
  return offsets;
}

uint64_t budget_pixels(const std::vector<float>& shares, size_t level, uint64_t hits) {
  return uint64_t(std::floor(double(shares[std::min(level, shares.size() - 1)]) * double(hits)));
}

uint32_t adaptive_rays(int spp, int samples, size_t kept) {
  uint32_t rays = 1;
  int before = 0;  // the samples the pixel held before the level
  const int n = side_of(spp);
  size_t l = 0;
  for (int side = first_side(n); side > 0; side = next_side(side, n), ++l) {
    const int m = side * side;
    if (m > samples) break;
    rays += uint32_t(l > 0 && l < kept ? m - before : m);
    before = m;
  }
  return rays;
}

BudgetSearch budget_threshold(float floor, uint64_t budget,
                              const std::function<uint64_t(float)>& count) {
  BudgetSearch r{floor, 1};
  if (count(floor) <= budget) return r;
  // An upper end that fits (scores are colour steps: rarely above 1).
  float hi = std::max(1.0f, 2.0f * floor);
  for (++r.counts; count(hi) > budget; ++r.counts) hi *= 2.0f;
  auto lo_bits = std::bit_cast<uint32_t>(floor), hi_bits = std::bit_cast<uint32_t>(hi);
  while (hi_bits - lo_bits > 1) {
    const uint32_t mid = lo_bits + (hi_bits - lo_bits) / 2;
    ++r.counts;
    (count(std::bit_cast<float>(mid)) <= budget ? hi_bits : lo_bits) = mid;
  }
  r.threshold = std::bit_cast<float>(hi_bits);
  return r;
}

bool on_lattice(int x, int y, int k, int width, int height) {
  return (x % k == 0 || x == width - 1) && (y % k == 0 || y == height - 1);
}

glm::ivec4 lattice_cell(int x, int y, int k, int width, int height) {
  const int x0 = x / k * k, y0 = y / k * k;
  return {x0, std::min(x0 + k, width - 1), y0, std::min(y0 + k, height - 1)};
}

LatticeAxis lattice_axis(int n, int k) {
  LatticeAxis a;
  a.on.resize(size_t(std::max(n, 0)));
  a.nearest.resize(a.on.size());
  for (int x = 0; x < n; ++x) {
    a.on[size_t(x)] = x % k == 0 || x == n - 1;
    a.count += a.on[size_t(x)];
    const int x0 = x / k * k, x1 = std::min(x0 + k, n - 1);  // lattice_cell's along the axis
    a.nearest[size_t(x)] = x - x0 <= x1 - x ? x0 : x1;
  }
  return a;
}

GapTest undersample_gap_test(const std::vector<glm::dvec3>& colour, const std::vector<int>& key,
                             int x, int y, int k, int width, int height) {
  const glm::ivec4 c = lattice_cell(x, y, k, width, height);
  const size_t w = size_t(width);
  const size_t corner[4] = {size_t(c.z) * w + size_t(c.x), size_t(c.z) * w + size_t(c.y),
                            size_t(c.w) * w + size_t(c.x), size_t(c.w) * w + size_t(c.y)};
  // Only the corners the fill blends: on a lattice row (column) that row's (column's) two.
  const bool use[4] = {true, x != c.x, y != c.z, x != c.x && y != c.z};
  glm::dvec3 lo = colour[corner[0]], hi = lo;
  GapTest t;
  for (int q = 1; q < 4; ++q) {
    if (!use[q]) continue;
    t.keys_differ = t.keys_differ || key[corner[q]] != key[corner[0]];
    lo = glm::min(lo, colour[corner[q]]);
    hi = glm::max(hi, colour[corner[q]]);
  }
  const glm::dvec3 spread = hi - lo;
  t.spread = std::max({spread.x, spread.y, spread.z});
  return t;
}

namespace {

// The one of a and b of smaller magnitude, 0 where their signs differ (rellenarHuecos' limiter).
double minmod(double a, double b) {
  return a * b > 0.0 ? (std::fabs(a) < std::fabs(b) ? a : b) : 0.0;
}
// ... and 0 unless both are within the limit (kernels/undersample.h: gentle_bend).
double gentle_bend(double a, double b, double limit) {
  return std::max(std::fabs(a), std::fabs(b)) <= limit ? minmod(a, b) : 0.0;
}

}  // namespace

glm::dvec3 undersample_fill(const std::vector<glm::dvec3>& colour, int x, int y, int k, int width,
                            int height, double threshold) {
  const glm::ivec4 q = lattice_cell(x, y, k, width, height);
  auto at = [&](int px, int py) { return colour[size_t(py) * size_t(width) + size_t(px)]; };
  const double tx = q.y > q.x ? double(x - q.x) / double(q.y - q.x) : 0.0;
  const double ty = q.w > q.z ? double(y - q.z) / double(q.w - q.z) : 0.0;
  // The correction along an axis needs the lattice pixels one step beyond the cell.
  const bool along_x = q.x - k >= 0 && q.y + k <= width - 1 && q.y - q.x == k;
  const bool along_y = q.z - k >= 0 && q.w + k <= height - 1 && q.w - q.z == k;
  const double limit = threshold * 0.5;
  auto bend = [limit](const glm::dvec3& o, const glm::dvec3& a, const glm::dvec3& b,
                      const glm::dvec3& p, double t) {
    glm::dvec3 r;
    for (int ch = 0; ch < 3; ++ch)
      r[ch] = t * (1.0 - t) * 0.5 *
              gentle_bend(o[ch] - 2.0 * a[ch] + b[ch], a[ch] - 2.0 * b[ch] + p[ch], limit);
    return r;
  };
  glm::dvec3 top = at(q.x, q.z) + (at(q.y, q.z) - at(q.x, q.z)) * tx;
  glm::dvec3 bottom = at(q.x, q.w) + (at(q.y, q.w) - at(q.x, q.w)) * tx;
  if (along_x) {
    top -= bend(at(q.x - k, q.z), at(q.x, q.z), at(q.y, q.z), at(q.y + k, q.z), tx);
    bottom -= bend(at(q.x - k, q.w), at(q.x, q.w), at(q.y, q.w), at(q.y + k, q.w), tx);
  }
  glm::dvec3 c = top + (bottom - top) * ty;
  if (along_y) {
    const glm::dvec3 left =
        bend(at(q.x, q.z - k), at(q.x, q.z), at(q.x, q.w), at(q.x, q.w + k), ty);
    const glm::dvec3 right =
        bend(at(q.y, q.z - k), at(q.y, q.z), at(q.y, q.w), at(q.y, q.w + k), ty);
    c -= left + (right - left) * tx;
  }
  return c;
}

}  // namespace host
