// What a fragment program sees: W fragments at once, their window positions, texture units to
// fetch through, output registers to write, discard and branch. Nothing else: a program cannot
// address another fragment's texel (no scatter) and cannot start a pass (no recursion).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "vgpu/lanes.h"
#include "vgpu/record.h"

namespace vgpu {

// A texture as bound to a texture unit for one pass.
struct BoundTexture {
  const float* data = nullptr;  // channels floats per texel, row-major
  int width = 0, height = 0, channels = 0;
  // Emulator shortcut (vgpu/batch.h): the texels of this batch's own fragments, held in registers
  // between passes, channel-major (4 x W floats). Set only where the program reads the unit at
  // its own texel alone; fetches then come from here instead of `data`.
  const float* lanes = nullptr;
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

// The counting run's record of a program's data-dependent loops (Fragments::loop).
struct LoopTally {
  int loops = 0;               // f.loop() calls
  int max_iterations = 0;      // the largest iteration budget one was given
  int body_instructions = 0;   // static instructions of the bodies, once each
  FetchTally body_fetches;     // fetches per iteration of the bodies, per unit
  bool branch_inside = false;  // an f.branch() inside a body (not supported)
  // The longest chain of dependent operations through one iteration (vgpu/span.h): its fetches
  // and its other operations. Filled by Program::analyze from the recording.
  int chain_fetches = 0;
  int chain_operations = 0;
  // Of body_instructions, the operations between two fetches of an iteration (vgpu/span.h's
  // loop_dependent_operations). Filled by Program::analyze from the recording.
  int dependent_operations = 0;
};

// Transposes between texels (4 channels each, contiguous) and registers (one per channel), for
// W consecutive fragments. Width 8 and 16 use in-lane shuffles of 8-float vectors (GCC/Clang
// vector extensions); other widths a per-lane loop. Pure data movement: bits are unchanged.
namespace texels {

using V8 = float __attribute__((vector_size(32)));

inline V8 load8(const float* p) {
  V8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// a0 = [texel 0 | texel 4], a1 = [1 | 5], a2 = [2 | 6], a3 = [3 | 7] (xyzw each): the in-lane
// 4x4 transpose into x0..x7, y.., z.., w.. (split8 and gather8 share it).
[[gnu::always_inline]] inline void transpose4x4_lanes(V8 a0, V8 a1, V8 a2, V8 a3, float* x,
                                                      float* y, float* z, float* w) {
  const V8 u0 = __builtin_shufflevector(a0, a1, 0, 8, 1, 9, 4, 12, 5, 13);
  const V8 u1 = __builtin_shufflevector(a0, a1, 2, 10, 3, 11, 6, 14, 7, 15);
  const V8 u2 = __builtin_shufflevector(a2, a3, 0, 8, 1, 9, 4, 12, 5, 13);
  const V8 u3 = __builtin_shufflevector(a2, a3, 2, 10, 3, 11, 6, 14, 7, 15);
  const V8 vx = __builtin_shufflevector(u0, u2, 0, 1, 8, 9, 4, 5, 12, 13);
  const V8 vy = __builtin_shufflevector(u0, u2, 2, 3, 10, 11, 6, 7, 14, 15);
  const V8 vz = __builtin_shufflevector(u1, u3, 0, 1, 8, 9, 4, 5, 12, 13);
  const V8 vw = __builtin_shufflevector(u1, u3, 2, 3, 10, 11, 6, 7, 14, 15);
  std::memcpy(x, &vx, sizeof vx);
  std::memcpy(y, &vy, sizeof vy);
  std::memcpy(z, &vz, sizeof vz);
  std::memcpy(w, &vw, sizeof vw);
}

// p: 8 texels xyzw. Out: x0..x7, y0..y7, z0..z7, w0..w7.
inline void split8(const float* p, float* x, float* y, float* z, float* w) {
  const V8 l0 = load8(p), l1 = load8(p + 8), l2 = load8(p + 16), l3 = load8(p + 24);
  // a0 = [texel 0 | texel 4], a1 = [1 | 5], a2 = [2 | 6], a3 = [3 | 7]: then in-lane 4x4.
  const V8 a0 = __builtin_shufflevector(l0, l2, 0, 1, 2, 3, 8, 9, 10, 11);
  const V8 a1 = __builtin_shufflevector(l0, l2, 4, 5, 6, 7, 12, 13, 14, 15);
  const V8 a2 = __builtin_shufflevector(l1, l3, 0, 1, 2, 3, 8, 9, 10, 11);
  const V8 a3 = __builtin_shufflevector(l1, l3, 4, 5, 6, 7, 12, 13, 14, 15);
  transpose4x4_lanes(a0, a1, a2, a3, x, y, z, w);
}

// The inverse: x0..x7, y.., z.., w.. into 8 texels xyzw at p.
inline void join8(const float* x, const float* y, const float* z, const float* w, float* p) {
  const V8 vx = load8(x), vy = load8(y), vz = load8(z), vw = load8(w);
  const V8 u0 = __builtin_shufflevector(vx, vy, 0, 8, 1, 9, 4, 12, 5, 13);
  const V8 u1 = __builtin_shufflevector(vx, vy, 2, 10, 3, 11, 6, 14, 7, 15);
  const V8 u2 = __builtin_shufflevector(vz, vw, 0, 8, 1, 9, 4, 12, 5, 13);
  const V8 u3 = __builtin_shufflevector(vz, vw, 2, 10, 3, 11, 6, 14, 7, 15);
  const V8 b0 = __builtin_shufflevector(u0, u2, 0, 1, 8, 9, 4, 5, 12, 13);    // [0 | 4]
  const V8 b1 = __builtin_shufflevector(u0, u2, 2, 3, 10, 11, 6, 7, 14, 15);  // [1 | 5]
  const V8 b2 = __builtin_shufflevector(u1, u3, 0, 1, 8, 9, 4, 5, 12, 13);    // [2 | 6]
  const V8 b3 = __builtin_shufflevector(u1, u3, 2, 3, 10, 11, 6, 7, 14, 15);  // [3 | 7]
  const V8 s0 = __builtin_shufflevector(b0, b1, 0, 1, 2, 3, 8, 9, 10, 11);
  const V8 s1 = __builtin_shufflevector(b2, b3, 0, 1, 2, 3, 8, 9, 10, 11);
  const V8 s2 = __builtin_shufflevector(b0, b1, 4, 5, 6, 7, 12, 13, 14, 15);
  const V8 s3 = __builtin_shufflevector(b2, b3, 4, 5, 6, 7, 12, 13, 14, 15);
  std::memcpy(p, &s0, sizeof s0);
  std::memcpy(p + 8, &s1, sizeof s1);
  std::memcpy(p + 16, &s2, sizeof s2);
  std::memcpy(p + 24, &s3, sizeof s3);
}

// W texels xyzw at p into lanes[c][i] (channel c of fragment i).
template <int W>
inline void split(const float* p, float (&lanes)[4][W]) {
  if constexpr (W % 8 == 0) {
    for (int g = 0; g < W; g += 8)
      split8(p + 4 * g, lanes[0] + g, lanes[1] + g, lanes[2] + g, lanes[3] + g);
  } else {
    for (int i = 0; i < W; ++i)
      for (int c = 0; c < 4; ++c) lanes[c][i] = p[4 * i + c];
  }
}

template <int W>
inline void join(const float (&lanes)[4][W], float* p) {
  if constexpr (W % 8 == 0) {
    for (int g = 0; g < W; g += 8)
      join8(lanes[0] + g, lanes[1] + g, lanes[2] + g, lanes[3] + g, p + 4 * g);
  } else {
    for (int i = 0; i < W; ++i)
      for (int c = 0; c < 4; ++c) p[4 * i + c] = lanes[c][i];
  }
}

// Eight texels of four floats from eight addresses into x0..x7, y.., z.., w..: one 16-byte load
// each, then the same in-lane transpose as split8.
inline void gather8(const float* const* p, float* x, float* y, float* z, float* w) {
  using V4 = float __attribute__((vector_size(16)));
  V4 t[8];
  for (int i = 0; i < 8; ++i) std::memcpy(&t[i], p[i], sizeof(V4));
  const V8 a0 = __builtin_shufflevector(t[0], t[4], 0, 1, 2, 3, 4, 5, 6, 7);
  const V8 a1 = __builtin_shufflevector(t[1], t[5], 0, 1, 2, 3, 4, 5, 6, 7);
  const V8 a2 = __builtin_shufflevector(t[2], t[6], 0, 1, 2, 3, 4, 5, 6, 7);
  const V8 a3 = __builtin_shufflevector(t[3], t[7], 0, 1, 2, 3, 4, 5, 6, 7);
  transpose4x4_lanes(a0, a1, a2, a3, x, y, z, w);
}

// Texel indices (first float of each texel) of lanes at clamped texel coordinates u[i], v[i]
// (floats in [0, w - 1] x [0, h - 1]): truncated like the scalar path, clamped again as integers.
// W a multiple of 8; the caller checked that w * h * ch fits in 32 bits.
template <int W>
inline void indices(int width, int height, int ch, const float* u, const float* v, int32_t* idx) {
  using V8i = int32_t __attribute__((vector_size(32)));
  const V8i wm = V8i{} + (width - 1), hm = V8i{} + (height - 1);
  for (int g = 0; g < W; g += 8) {
    V8i iu = __builtin_convertvector(load8(u + g), V8i);
    V8i iv = __builtin_convertvector(load8(v + g), V8i);
    iu = iu < wm ? iu : wm;
    iv = iv < hm ? iv : hm;
    const V8i i = (iv * width + iu) * ch;
    std::memcpy(idx + g, &i, sizeof i);
  }
}

// Texels of a texture of 3 or 4 channels (w x h, rows of w * ch floats) at clamped texel
// coordinates u[i], v[i] into lanes[c][i] (W a multiple of 8); channel 3 of a 3-channel texture is
// left undefined. Each texel is one 16-byte load; the last texel of a 3-channel texture, whose 16
// bytes would run past the end, is read from a padded copy.
template <int W>
inline void gather(const float* d, int width, int height, int ch, const float* u, const float* v,
                   float (&lanes)[4][W]) {
  static_assert(W % 8 == 0);
  const int64_t size = int64_t(width) * height * ch;
  // Clamped fetches of triangle id -1 (no triangle) land on the last texel often.
  alignas(16) float tail[4] = {};
  if (ch == 3)
    for (int c = 0; c < 3; ++c) tail[c] = d[size - 3 + c];
  int32_t idx[W];
  indices<W>(width, height, ch, u, v, idx);
  const float* p[W];
  for (int i = 0; i < W; ++i) p[i] = int64_t(idx[i]) + 4 <= size ? d + idx[i] : tail;
  for (int g = 0; g < W; g += 8)
    gather8(p + g, lanes[0] + g, lanes[1] + g, lanes[2] + g, lanes[3] + g);
}

}  // namespace texels

template <class L>
class Fragments {
 public:
  using F = typename L::F;
  using M = typename L::M;
  static constexpr int W = L::width;

  F x, y;  // window position: pixel centres (x + 0.5, y + 0.5), the render target's texel space

  // texRECT(unit, (u, v)): nearest texel floor(u), floor(v), clamped at the edges. Channels a
  // texture lacks read as (0, 0, 0, 1).
  [[gnu::always_inline]] Vec4<F> fetch(int unit, const F& u, const F& v) const {
    const BoundTexture& t = units_[unit];
    if constexpr (L::counting) {
      ++OpCounter::ops;
      ++tally_->per_unit[unit];
      return {F(0.0f), F(0.0f), F(0.0f), F(1.0f)};
    } else if constexpr (L::recording) {
      // The own texel (u, v are this fragment's x, y) is the common case a printer can say so.
      const bool own = u.id == x.id && v.id == y.id;
      const int t = own ? Recorder::current->push({Op::fetch_own, -1, -1, -1, unit})
                        : Recorder::current->push({Op::fetch, u.id, v.id, -1, unit});
      auto ch = [&](int c) {
        return F::node(Recorder::current->push({Op::channel, t, -1, -1, c}));
      };
      return {ch(0), ch(1), ch(2), ch(3)};
    } else {
      if (t.lanes) {  // resident in registers (a batch's own texels: vgpu/batch.h)
        Vec4<F> r;
        r.x.copy_from(t.lanes, stdx::element_aligned);
        r.y.copy_from(t.lanes + W, stdx::element_aligned);
        r.z.copy_from(t.lanes + 2 * W, stdx::element_aligned);
        r.w.copy_from(t.lanes + 3 * W, stdx::element_aligned);
        return r;
      }
      const F fu = floor(u), fv = floor(v);
      const float u0 = fu[0], v0 = fv[0];
      if (t.channels == 4 && u0 >= 0.0f && u0 + float(W - 1) <= float(t.width - 1) && v0 >= 0.0f &&
          v0 <= float(t.height - 1) && all(fu == F([](auto i) { return float(i); }) + u0) &&
          all(fv == F(v0))) {
        // The common case, a fragment's own texel: W consecutive fp32x4 texels inside one row.
        // Nothing to clamp; one base address and a transpose instead of per-lane loads.
        alignas(64) float lanes[4][W];
        texels::split<W>(t.data + (int64_t(v0) * t.width + int64_t(u0)) * 4, lanes);
        Vec4<F> r;
        r.x.copy_from(lanes[0], stdx::vector_aligned);
        r.y.copy_from(lanes[1], stdx::vector_aligned);
        r.z.copy_from(lanes[2], stdx::vector_aligned);
        r.w.copy_from(lanes[3], stdx::vector_aligned);
        return r;
      }
      return fetch_clamped(t, fu, fv);
    }
  }
  // The texel of this fragment's own pixel in a texture the size of the render target.
  [[gnu::always_inline]] Vec4<F> fetch_own(int unit) const { return fetch(unit, x, y); }

  // Output register i (COLOR0..): written to render target i where the fragment survives.
  // Every register reads as zero until written.
  Vec4<F>& out(int i) {
    if (i >= cleared_) clear_outputs(kMaxOutputs);  // a register past the program's outputs
    return out_[i];
  }

  // Kills the fragments where m holds: they write nothing and an occlusion query skips them.
  void discard(const M& m) { kill_ = kill_ || m; }

  // A conditional block: `if (f.branch(m)) { ... }`. Fragments where m is false sit idle in the
  // block (counted as divergence). Without dynamic branching (fp30) the block always runs, under
  // masks, for every fragment; with it, a batch where no live fragment takes it skips the block.
  // Either way the kernel must write its results through select(m, ...).
  bool branch(const M& m) {
    if constexpr (L::counting) {
      ++*idle_;  // the counting run tallies branch() calls
      if (in_loop_ && loop_tally_) loop_tally_->branch_inside = true;
      return true;
    } else if constexpr (L::recording) {
      return true;  // recorded straight-line: both sides run, results go through select
    } else {
      *idle_ += uint64_t(lanes_on(live_ && !m));
      idle_any_ = idle_any_ || (live_ && !m);
      return !dynamic_ || any(live_ && m);
    }
  }

  // A data-dependent loop, the fp40 LOOP/BRK shape:
  //   while (any(active) && iterations < max_iterations) active = active && body(active);
  // `body(active)` returns the lanes that go on; it must write its results through
  // select(active, ...) so lanes that left keep their values (they ride along in the batch).
  // Returns the lanes still looping when the budget ran out. Each fragment's own iteration count
  // (the iterations it was active in) is kept for the statistics: the fragment processor turns
  // them into per-batch counts at the profile's branch granularity, so the host's lane width
  // changes no statistic. The counting run runs the body once: its static instructions and
  // fetches per iteration. The body may not use f.branch() (its selects are the branches).
  template <class Body>
  M loop(int max_iterations, M active, Body&& body) {
    if constexpr (L::counting) {
      const uint64_t ops0 = OpCounter::ops;
      const FetchTally f0 = *tally_;
      in_loop_ = true;
      const M more = body(active);
      in_loop_ = false;
      if (loop_tally_) {
        LoopTally& t = *loop_tally_;
        ++t.loops;
        t.max_iterations = std::max(t.max_iterations, max_iterations);
        t.body_instructions += int(OpCounter::ops - ops0);
        for (int u = 0; u < kMaxTextureUnits; ++u)
          t.body_fetches.per_unit[size_t(u)] +=
              uint16_t(tally_->per_unit[size_t(u)] - f0.per_unit[size_t(u)]);
      }
      return more;
    } else if constexpr (L::recording) {
      // The body twice: the second iteration's operands tell which values the first one
      // carries (RecLoop); the printer writes one GLSL loop from the first.
      Recording& rec = *Recorder::current;
      RecLoop lp;
      lp.begin = int(rec.nodes.size());
      lp.max_iterations = max_iterations;
      lp.entry = active.id;
      const M more = body(active);
      const M next = M::node(Recorder::emit(Op::mask_and, active.id, more.id));
      lp.mid = int(rec.nodes.size());
      const M more2 = body(next);
      const M after = M::node(Recorder::emit(Op::mask_and, next.id, more2.id));
      lp.end = int(rec.nodes.size());
      rec.loops.push_back(lp);
      return after;
    } else {
      active = active && live_;
      bool on[W];
      for (int k = 0; k < max_iterations && any(active); ++k) {
        active.copy_to(on, stdx::element_aligned);
        for (int i = 0; i < W; ++i) loop_count_[size_t(i)] += on[i] ? 1u : 0u;
        active = active && body(active);
      }
      return active;
    }
  }
  // Iterations lane i spent in this batch's loop (0 without one).
  uint32_t loop_count(int i) const { return loop_count_[size_t(i)]; }
  // The counting run's loop record (Program::analyze).
  void set_loop_tally(LoopTally* t) { loop_tally_ = t; }

  const M& live() const { return live_; }
  // Live fragments idle in some branch of this batch (for the batch-coherence counters).
  const M& idle_lanes() const { return idle_any_; }

  // Set up by the fragment processor.
  Fragments(const BoundTexture* units, bool dynamic, uint64_t* idle, FetchTally* tally)
      : units_(units), dynamic_(dynamic), idle_(idle), tally_(tally) {}
  // outputs: registers cleared now (the program's); the rest are cleared on first use.
  void reset(const F& px, const F& py, const M& live, int outputs = kMaxOutputs) {
    x = px;
    y = py;
    live_ = live;
    kill_ = M(false);
    idle_any_ = M(false);
    cleared_ = 0;
    clear_outputs(outputs);
    loop_count_.fill(0);
  }
  const M& killed() const { return kill_; }
  const Vec4<F>& output(int i) const { return out_[i]; }

 private:
  const BoundTexture* units_;
  bool dynamic_;
  uint64_t* idle_;
  FetchTally* tally_;
  M live_{false}, kill_{false}, idle_any_{false};
  std::array<Vec4<F>, kMaxOutputs> out_;
  int cleared_ = 0;  // out_[0, cleared_) hold zero or what the program wrote in this batch
  std::array<uint32_t, W> loop_count_{};
  LoopTally* loop_tally_ = nullptr;
  bool in_loop_ = false;

  // Any texel coordinates: clamp in float first (NaN goes to 0), then convert (no undefined
  // conversions), then one load per lane and channel (the scalar reference). Widths 8 and 16
  // compute the indices as vectors and load 3- and 4-channel texels whole (texels::gather).
  [[gnu::noinline]] static Vec4<F> fetch_clamped(const BoundTexture& t, F fu, F fv) {
    const F wmax = F(float(t.width - 1)), hmax = F(float(t.height - 1));
    fu = select(fu >= F(0.0f), fu, F(0.0f));
    fv = select(fv >= F(0.0f), fv, F(0.0f));
    fu = select(fu <= wmax, fu, wmax);
    fv = select(fv <= hmax, fv, hmax);
    const float* d = t.data;
    const int ch = t.channels;
    if constexpr (W % 8 == 0 && std::is_same_v<L, SimdLanes<W>>) {
      if (int64_t(t.width) * t.height * ch < (int64_t(1) << 31)) {
        alignas(64) float au[W], av[W];
        fu.copy_to(au, stdx::vector_aligned);
        fv.copy_to(av, stdx::vector_aligned);
        if (ch >= 3) {
          alignas(64) float lanes[4][W];
          texels::gather<W>(d, t.width, t.height, ch, au, av, lanes);
          Vec4<F> r;
          r.x.copy_from(lanes[0], stdx::vector_aligned);
          r.y.copy_from(lanes[1], stdx::vector_aligned);
          r.z.copy_from(lanes[2], stdx::vector_aligned);
          r.w = ch == 4 ? F(lanes[3], stdx::vector_aligned) : F(1.0f);
          return r;
        }
        int32_t idx[W];
        texels::indices<W>(t.width, t.height, ch, au, av, idx);
        Vec4<F> r{F([&](auto i) { return d[idx[i]]; }), F(0.0f), F(0.0f), F(1.0f)};
        if (ch > 1) r.y = F([&](auto i) { return d[idx[i] + 1]; });
        return r;
      }
    }
    std::array<int64_t, W> idx;
    // Clamped again as integers: a reduced-precision wmax may round past the last texel.
    for (int i = 0; i < W; ++i)
      idx[i] = (std::min<int64_t>(int64_t(fv[i]), t.height - 1) * t.width +
                std::min<int64_t>(int64_t(fu[i]), t.width - 1)) *
               ch;
    Vec4<F> r{F(0.0f), F(0.0f), F(0.0f), F(1.0f)};
    r.x = F([&](auto i) { return d[idx[i]]; });
    if (ch > 1) r.y = F([&](auto i) { return d[idx[i] + 1]; });
    if (ch > 2) r.z = F([&](auto i) { return d[idx[i] + 2]; });
    if (ch > 3) r.w = F([&](auto i) { return d[idx[i] + 3]; });
    return r;
  }

  void clear_outputs(int n) {
    for (; cleared_ < n; ++cleared_) out_[cleared_] = {F(0.0f), F(0.0f), F(0.0f), F(0.0f)};
  }
};

}  // namespace vgpu
