// Supersampling (--spp N): where the samples of a pixel lie, the same for both engines. The
// stream tracer renders one sample frame per sample and accumulates them (the accumulation
// buffer of 2004), the CPU tracer averages the same rays per pixel.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace host {

inline constexpr int kMaxSpp = 256;

// Why `spp` is not a sample count --spp takes (empty: it is): a square from 1 to 256.
// Names the count, not the option.
std::string spp_refusal(int spp);

// Sample s (0 <= s < spp) within a pixel, in [0, 1)^2 from its top-left corner (x right, y
// down): the pixel split into n x n strata (n = sqrt(spp)), sample s in stratum (s mod n,
// s div n), placed at a uniform random point of it drawn from a splitmix64 stream seeded by
// `seed` and s (the same positions every run). spp 1: the pixel centre (0.5, 0.5), today's ray.
glm::vec2 sample_offset(int spp, int s, uint64_t seed);

// The levels of adaptive supersampling up to `spp` samples: the side n of each level's n x n
// grid, doubling from 2 and ending at sqrt(spp) (spp 16: 2, 4; spp 9: 2, 3; spp 1: none).
std::vector<int> adaptive_levels(int spp);

// Adaptive levels that keep the samples before them (--aa-criterion budget's levels, and
// cpu_adaptive_levels' kept levels; docs/studies/sampling.md, "One default for every scene"):
// per level, the offsets of the samples it adds. The first level adds its own n x n
// (sample_offset(n * n, k)); each later one adds one sample in each of its n x n strata that the
// samples before leave empty (the stratum's sample_offset), so that the set stays one sample to a
// stratum. The list stops before the first level whose earlier samples do not fall one to a
// stratum (a side that does not double, as spp 9's 2 then 3); spp 16: 4 offsets, then 12.
std::vector<std::vector<glm::vec2>> kept_level_samples(int spp, uint64_t seed);

// The sample offsets adaptive level `level` (of adaptive_levels(spp)) traces: `kept`'s (the
// kept_level_samples list, empty when levels do not keep) where it has the level, else the
// level's own n x n.
std::vector<glm::vec2> adaptive_level_offsets(int spp, size_t level,
                                              const std::vector<std::vector<glm::vec2>>& kept,
                                              uint64_t seed);

// The budget criterion's pixels that hit level `level` may refine: its share (the last one for
// deeper levels) of `hits`, rounded down.
uint64_t budget_pixels(const std::vector<float>& shares, size_t level, uint64_t hits);

// The primary rays a pixel took under adaptive supersampling when its final sample count is
// `samples` (1: the centre ray alone; n*n: every level up to side n, after the centre ray).
uint32_t adaptive_rays(int spp, int samples);
// The same where the first `kept` levels keep the samples before them (kept_level_samples(spp,
// seed).size() of them, --aa-criterion budget): a kept level after the first traces only its
// new samples (spp 16, 16 samples: 1 + 4 + 12 rays, not 1 + 4 + 16).
uint32_t adaptive_rays(int spp, int samples, size_t kept);

// --aa-criterion budget's search (kernels/cone_budget.h): the least threshold t >= floor (floor
// >= 0) with count(t) <= budget, where count(t) (one counting pass and occlusion query on a
// card: the pixels that hit scoring above t) falls as t rises and changes only at the pixels'
// scores. Positive floats order as their bit patterns, so a binary search over the bits ends on
// the exact threshold: the first score a ranking of the scores, highest first, leaves out. The
// threshold and how many counts the search asked for.
struct BudgetSearch {
  float threshold = 0;
  uint64_t counts = 0;
};
BudgetSearch budget_threshold(float floor, uint64_t budget,
                              const std::function<uint64_t(float)>& count);

// Undersampling's lattice (--aa undersample:K): whether pixel (x, y) of a W x H image is traced
// first (x a multiple of K or the last column, y likewise), and the lattice pixels around it
// (x0 <= x <= x1, y0 <= y <= y1).
bool on_lattice(int x, int y, int k, int width, int height);
glm::ivec4 lattice_cell(int x, int y, int k, int width, int height);  // x0, x1, y0, y1
// The lattice along one axis of n pixels, for loops over every pixel of the image (on_lattice
// and lattice_cell work per pixel): on[x] whether coordinate x is on it, nearest[x] the nearer
// of its cell's two lattice coordinates (the lower where tied), count how many are on it.
// Pixel (x, y) is on the lattice where both axes' on[] are.
struct LatticeAxis {
  std::vector<uint8_t> on;
  std::vector<int> nearest;
  uint64_t count = 0;
};
LatticeAxis lattice_axis(int n, int k);

// What marcarHuecos looks at for pixel (x, y) off the lattice, from the lattice pixels' colours
// and surface keys (row-major, width x height; only lattice pixels are read): the largest
// spread, over the three channels, of the lattice pixels its fill blends, and whether their
// keys differ. The pixel is traced when keys differ or spread > --aa-threshold.
struct GapTest {
  double spread = 0;
  bool keys_differ = false;
};
GapTest undersample_gap_test(const std::vector<glm::dvec3>& colour, const std::vector<int>& key,
                             int x, int y, int k, int width, int height);

// rellenarHuecos' colour for pixel (x, y) off the lattice (kernels/undersample.h, in double):
// the bilinear blend of its cell's lattice pixels, less the curvature correction along each axis
// (t(1 - t)/2 of the minmod of the lattice's second differences at the cell's two ends, where
// both are within threshold / 2 and the lattice pixels one step beyond the cell are in the
// image). Only lattice pixels of `colour` are read.
glm::dvec3 undersample_fill(const std::vector<glm::dvec3>& colour, int x, int y, int k, int width,
                            int height, double threshold);

}  // namespace host
