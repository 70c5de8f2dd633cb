// The texture unit's filters (vgpu/sampler.h): nearest, bilinear and trilinear over a mip chain
// packed in one texture, the three wrap modes, the level of detail, and what each filter costs
// in fetches; scalar and SIMD lanes agree.
#include <doctest/doctest.h>

#include <array>
#include <cstring>
#include <vector>

#include "helpers.h"
#include "vgpu/sampler.h"
#include "vgpu/vgpu.h"

using namespace vgpu;

namespace {

// out(0) = unit 0 sampled at unit 1's own texel (s, t, rho): a 4x4 level 0 at (0, 0), a 2x2
// level 1 at (4, 0) and a 1x1 level 2 at (4, 2) of a 5x4 texture.
struct SampleChain {
  static constexpr const char* name = "sample_chain";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  Filter filter = Filter::nearest;
  Wrap wrap_s = Wrap::repeat, wrap_t = Wrap::repeat;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> c = f.fetch_own(1);
    const MipLevel<F> l0{F(0.0f), F(0.0f), F(4.0f), F(4.0f)};
    const MipLevel<F> l1{F(4.0f), F(0.0f), F(2.0f), F(2.0f)};
    const MipLevel<F> l2{F(4.0f), F(2.0f), F(1.0f), F(1.0f)};
    const F ws{float(wrap_s)}, wt{float(wrap_t)};
    if (filter == Filter::nearest) {
      f.out(0) = sample_nearest(f, 0, l0, c.x, c.y, ws, wt);
    } else if (filter == Filter::bilinear) {
      f.out(0) = sample_bilinear(f, 0, l0, c.x, c.y, ws, wt);
    } else {
      F level, frac;
      level_of_detail(c.z, F(3.0f), level, frac);
      auto pick = [&](const F& k) {
        return MipLevel<F>{select(k == F(0.0f), l0.x, select(k == F(1.0f), l1.x, l2.x)),
                           select(k == F(0.0f), l0.y, select(k == F(1.0f), l1.y, l2.y)),
                           select(k == F(0.0f), l0.w, select(k == F(1.0f), l1.w, l2.w)),
                           select(k == F(0.0f), l0.h, select(k == F(1.0f), l1.h, l2.h))};
      };
      f.out(0) = sample_trilinear(f, 0, pick(level), pick(min(level + F(1.0f), F(2.0f))), frac, c.x,
                                  c.y, ws, wt);
    }
  }
};

// Level 0 texel (i, j) = (i, j, 10 j + i, 1); level 1 all `l1`, level 2 `l2` (every channel).
Texture chain(float l1 = 50.0f, float l2 = 90.0f) {
  Texture t("chain", 5, 4, 4);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const float texel[4] = {float(i), float(j), float(10 * j + i), 1.0f};
      for (int c = 0; c < 4; ++c) t.set(i, j, c, texel[c]);
    }
  for (int j = 0; j < 2; ++j)
    for (int c = 0; c < 4; ++c) t.set(4, j, c, l1);
  for (int c = 0; c < 4; ++c) t.set(4, 2, c, l2);
  return t;
}

struct Run {
  std::vector<std::array<float, 4>> texels;
  uint64_t fetches = 0;  // the pass's texture fetches
};

// Samples `source` at every (s, t, rho) with the given filter and wraps.
Run sample(const Texture& source, const std::vector<std::array<float, 3>>& at, Filter filter,
           Wrap ws = Wrap::repeat, Wrap wt = Wrap::repeat, int lanes = kLanes) {
  Gpu gpu(profile("gf5700"), 1, lanes);
  Texture coords = gpu.make_texture("coords", int(at.size()), 1, 4);
  for (size_t i = 0; i < at.size(); ++i)
    for (int c = 0; c < 3; ++c) coords.set(int(i), 0, c, at[i][size_t(c)]);
  Texture out = gpu.make_texture("out", int(at.size()), 1, 4);
  KernelProgram<SampleChain> program;
  program.kernel.filter = filter;
  program.kernel.wrap_s = ws;
  program.kernel.wrap_t = wt;
  gpu.use_program(program);
  gpu.bind_texture(0, source);
  gpu.bind_texture(1, coords);
  gpu.set_targets({&out});
  Run r;
  r.fetches = gpu.draw().counters.texture_fetches;
  r.texels.resize(at.size());
  for (size_t i = 0; i < at.size(); ++i)
    for (int c = 0; c < 4; ++c) r.texels[i][size_t(c)] = out.get(int(i), 0, c);
  return r;
}

constexpr Filter kFilters[] = {Filter::nearest, Filter::bilinear, Filter::trilinear};
const char* filter_name(Filter f) {
  return f == Filter::nearest ? "nearest" : f == Filter::bilinear ? "bilinear" : "trilinear";
}

}  // namespace

TEST_CASE("a texel fetch at a texel's centre returns the texel for every filter") {
  const Texture t = chain();
  std::vector<std::array<float, 3>> at;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) at.push_back({(i + 0.5f) / 4.0f, (j + 0.5f) / 4.0f, 1.0f});
  for (Filter filter : kFilters) {
    CAPTURE(filter_name(filter));
    const Run r = sample(t, at, filter);
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        CAPTURE(i);
        CAPTURE(j);
        const auto& got = r.texels[size_t(4 * j + i)];
        CHECK(got[0] == float(i));
        CHECK(got[1] == float(j));
        CHECK(got[2] == float(10 * j + i));
        CHECK(got[3] == 1.0f);
      }
  }
}

TEST_CASE("bilinear halfway between two texels returns their mean") {
  const Texture t = chain();
  // Between texels (1, 2) and (2, 2) in s; between (3, 0) and (3, 1) in t.
  const Run r = sample(t, {{2.0f / 4.0f, 2.5f / 4.0f, 1.0f}, {3.5f / 4.0f, 1.0f / 4.0f, 1.0f}},
                       Filter::bilinear);
  CHECK(r.texels[0][0] == 1.5f);
  CHECK(r.texels[0][1] == 2.0f);
  CHECK(r.texels[0][2] == 21.5f);
  CHECK(r.texels[1][0] == 3.0f);
  CHECK(r.texels[1][1] == 0.5f);
  CHECK(r.texels[1][2] == 8.0f);
  // A quarter of the way: weights 3/4 and 1/4.
  const Run q = sample(t, {{1.75f / 4.0f, 0.5f / 4.0f, 1.0f}}, Filter::bilinear);
  CHECK(q.texels[0][0] == 1.25f);
}

TEST_CASE("trilinear blends the two levels around the level of detail by its fraction") {
  // Every level constant: level 0's texel at the centre of texel (1, 1) is (1, 1, 11, 1).
  const Texture t = chain(51.0f, 91.0f);
  const float s = 1.5f / 4.0f;
  const Run r = sample(t,
                       {{s, s, 1.0f},     // lambda 0: level 0
                        {s, s, 1.5f},     // halfway (piecewise-linear log2) to level 1
                        {s, s, 2.0f},     // lambda 1: level 1
                        {s, s, 3.0f},     // halfway from level 1 to level 2
                        {s, s, 4.0f},     // lambda 2: the last level
                        {s, s, 1000.0f},  // past the chain: the last level
                        {s, s, 0.25f}},   // magnified: level 0
                       Filter::trilinear);
  CHECK(r.texels[0][2] == 11.0f);
  CHECK(r.texels[1][2] == 31.0f);  // (11 + 51) / 2
  CHECK(r.texels[2][2] == 51.0f);
  CHECK(r.texels[3][2] == 71.0f);  // (51 + 91) / 2
  CHECK(r.texels[4][2] == 91.0f);
  CHECK(r.texels[5][2] == 91.0f);
  CHECK(r.texels[6][2] == 11.0f);
}

TEST_CASE("wrap modes: repeat, clamp to edge and mirrored repeat pick the texel each names") {
  const Texture t = chain();
  // Texel columns -2, -1, 4, 5 and 9 of a 4-texel level (row 0), nearest.
  const std::vector<std::array<float, 3>> at = {{-1.5f / 4, 0.1f, 1},
                                                {-0.5f / 4, 0.1f, 1},
                                                {4.5f / 4, 0.1f, 1},
                                                {5.5f / 4, 0.1f, 1},
                                                {9.5f / 4, 0.1f, 1}};
  struct Case {
    Wrap wrap;
    std::array<float, 5> columns;
  };
  for (const Case& c :
       {Case{Wrap::repeat, {2, 3, 0, 1, 1}}, Case{Wrap::clamp_to_edge, {0, 0, 3, 3, 3}},
        Case{Wrap::mirrored_repeat, {1, 0, 3, 2, 1}}}) {
    CAPTURE(int(c.wrap));
    const Run r = sample(t, at, Filter::nearest, c.wrap, Wrap::clamp_to_edge);
    for (size_t k = 0; k < at.size(); ++k) {
      CAPTURE(k);
      CHECK(r.texels[k][0] == c.columns[k]);
    }
  }
  // Bilinear at s = 0 lies halfway between column -1 and column 0: repeat blends the last
  // column with the first, clamp and mirror read column 0 twice.
  const std::vector<std::array<float, 3>> edge = {{0.0f, 0.5f / 4, 1}};
  CHECK(sample(t, edge, Filter::bilinear, Wrap::repeat, Wrap::repeat).texels[0][0] == 1.5f);
  CHECK(sample(t, edge, Filter::bilinear, Wrap::clamp_to_edge, Wrap::repeat).texels[0][0] == 0.0f);
  CHECK(sample(t, edge, Filter::bilinear, Wrap::mirrored_repeat, Wrap::repeat).texels[0][0] ==
        0.0f);
  // t wraps on its own: row -1 under repeat is row 3.
  const Run rows =
      sample(t, {{0.5f / 4, -0.5f / 4, 1}}, Filter::nearest, Wrap::clamp_to_edge, Wrap::repeat);
  CHECK(rows.texels[0][1] == 3.0f);
}

TEST_CASE("filters cost 1, 4 and 8 texel fetches per sample, counted in the pass statistics") {
  const Texture t = chain();
  const std::vector<std::array<float, 3>> at(10, {0.3f, 0.6f, 1.7f});
  for (Filter filter : kFilters) {
    CAPTURE(filter_name(filter));
    const Run r = sample(t, at, filter);
    // Each fragment: its own coordinates, then the filter's texels.
    CHECK(r.fetches == at.size() * (1 + kFilterTexels[int(filter)]));
  }
}

TEST_CASE("every filter and wrap samples the same bits at every lane width as the scalar path") {
  const Texture t = chain();
  std::vector<std::array<float, 3>> at;
  uint64_t state = 7;
  for (int k = 0; k < 67; ++k) {
    auto r = [&] { return float(int64_t(vgpu_test::mix(state) >> 40) % 4000) / 1000.0f - 1.5f; };
    at.push_back({r(), r(), r() * 3.0f + 4.5f});
  }
  for (Filter filter : kFilters)
    for (Wrap w : {Wrap::repeat, Wrap::clamp_to_edge, Wrap::mirrored_repeat}) {
      CAPTURE(filter_name(filter));
      CAPTURE(int(w));
      const Run scalar = sample(t, at, filter, w, w, 1);
      for (int lanes : {4, 8, 16}) {
        CAPTURE(lanes);
        const Run simd = sample(t, at, filter, w, w, lanes);
        CHECK(std::memcmp(simd.texels.data(), scalar.texels.data(),
                          scalar.texels.size() * sizeof scalar.texels[0]) == 0);
        CHECK(simd.fetches == scalar.fetches);
      }
    }
}
