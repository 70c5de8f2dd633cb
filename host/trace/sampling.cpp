// Where the samples of a pixel lie (host/trace/sampling.h).
#include "host/trace/sampling.h"

#include <algorithm>
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

std::vector<int> adaptive_levels(int spp) {
  const int n = side_of(spp);
  std::vector<int> levels;
  for (int side = 2; side < n; side *= 2) levels.push_back(side);
  if (n > 1) levels.push_back(n);
  return levels;
}

uint32_t adaptive_rays(int spp, int samples) {
  uint32_t rays = 1;
  for (const int side : adaptive_levels(spp)) {
    if (side * side > samples) break;
    rays += uint32_t(side * side);
  }
  return rays;
}

bool on_lattice(int x, int y, int k, int width, int height) {
  return (x % k == 0 || x == width - 1) && (y % k == 0 || y == height - 1);
}

glm::ivec4 lattice_cell(int x, int y, int k, int width, int height) {
  const int x0 = x / k * k, y0 = y / k * k;
  return {x0, std::min(x0 + k, width - 1), y0, std::min(y0 + k, height - 1)};
}

}  // namespace host
