// What a fragment program sees: W fragments at once, their window positions, texture units to
// fetch through, output registers to write, discard and branch. Nothing else: a program cannot
// address another fragment's texel (no scatter) and cannot start a pass (no recursion).
#pragma once

#include <array>
#include <cstdint>

#include "vgpu/lanes.h"

namespace vgpu {

// A texture as bound to a texture unit for one pass.
struct BoundTexture {
  const float* data = nullptr;  // channels floats per texel, row-major
  int width = 0, height = 0, channels = 0;
};

inline constexpr int kMaxTextureUnits = 16;  // fp30/fp40 texture image units
inline constexpr int kMaxOutputs = 8;

// Per-pass fetch bookkeeping of the counting run: fetches per fragment, per unit.
struct FetchTally {
  std::array<uint16_t, kMaxTextureUnits> per_unit{};
  int total() const {
    int t = 0;
    for (auto n : per_unit) t += n;
    return t;
  }
};

template <class L>
class Fragments {
 public:
  using F = typename L::F;
  using M = typename L::M;
  static constexpr int W = L::width;

  F x, y;  // window position: pixel centres (x + 0.5, y + 0.5), the render target's texel space

  // texRECT(unit, (u, v)): nearest texel floor(u), floor(v), clamped at the edges. Channels a
  // texture lacks read as (0, 0, 0, 1).
  Vec4<F> fetch(int unit, const F& u, const F& v) const {
    const BoundTexture& t = units_[unit];
    if constexpr (L::counting) {
      ++OpCounter::ops;
      ++tally_->per_unit[unit];
      return {F(0.0f), F(0.0f), F(0.0f), F(1.0f)};
    } else {
      // Clamp in float first (NaN goes to 0), then convert: no undefined conversions.
      const F wmax = F(float(t.width - 1)), hmax = F(float(t.height - 1));
      F fu = floor(u), fv = floor(v);
      fu = select(fu >= F(0.0f), fu, F(0.0f));
      fv = select(fv >= F(0.0f), fv, F(0.0f));
      fu = select(fu <= wmax, fu, wmax);
      fv = select(fv <= hmax, fv, hmax);
      std::array<int, W> idx;
      for (int i = 0; i < W; ++i) idx[i] = (int(fv[i]) * t.width + int(fu[i])) * t.channels;
      const float* d = t.data;
      Vec4<F> r{F(0.0f), F(0.0f), F(0.0f), F(1.0f)};
      r.x = F([&](auto i) { return d[idx[i]]; });
      if (t.channels > 1) r.y = F([&](auto i) { return d[idx[i] + 1]; });
      if (t.channels > 2) r.z = F([&](auto i) { return d[idx[i] + 2]; });
      if (t.channels > 3) r.w = F([&](auto i) { return d[idx[i] + 3]; });
      return r;
    }
  }
  // The texel of this fragment's own pixel in a texture the size of the render target.
  Vec4<F> fetch_own(int unit) const { return fetch(unit, x, y); }

  // Output register i (COLOR0..): written to render target i where the fragment survives.
  Vec4<F>& out(int i) { return out_[i]; }

  // Kills the fragments where m holds: they write nothing and an occlusion query skips them.
  void discard(const M& m) { kill_ = kill_ || m; }

  // A conditional block: `if (f.branch(m)) { ... }`. Fragments where m is false sit idle in the
  // block (counted as divergence). Without dynamic branching (fp30) the block always runs, under
  // masks, for every fragment; with it, a batch where no live fragment takes it skips the block.
  // Either way the kernel must write its results through select(m, ...).
  bool branch(const M& m) {
    if constexpr (L::counting) {
      ++*idle_;  // the counting run tallies branch() calls
      return true;
    } else {
      *idle_ += uint64_t(lanes_on(live_ && !m));
      return !dynamic_ || any(live_ && m);
    }
  }

  const M& live() const { return live_; }

  // Set up by the fragment processor.
  Fragments(const BoundTexture* units, bool dynamic, uint64_t* idle, FetchTally* tally)
      : units_(units), dynamic_(dynamic), idle_(idle), tally_(tally) {}
  void reset(const F& px, const F& py, const M& live) {
    x = px;
    y = py;
    live_ = live;
    kill_ = M(false);
    for (auto& o : out_) o = {F(0.0f), F(0.0f), F(0.0f), F(0.0f)};
  }
  const M& killed() const { return kill_; }
  const Vec4<F>& output(int i) const { return out_[i]; }

 private:
  const BoundTexture* units_;
  bool dynamic_;
  uint64_t* idle_;
  FetchTally* tally_;
  M live_{false}, kill_{false};
  std::array<Vec4<F>, kMaxOutputs> out_;
};

}  // namespace vgpu
