// How a row worker shades its band of rows [y0, y1) of a draw (Gpu::run_rows in gpu.cpp builds a
// RowShader and calls one of its three loops). Only gpu.cpp includes this file.
//
// The three loops, by what the pass has:
//  - all_rows: no work mask. Every live fragment runs, in blocks of W neighbours along each row.
//  - listed_rows: a work mask whose non-zero fragments the last pass that wrote it listed. Only
//    the listed fragments are visited; draw() already settled the idle ones.
//  - masked_rows: a work mask without a list. Each row is scanned; the working fragments are
//    gathered into batches of W (across rows), stretches of idle ones are settled at once.
// After a batch ran, its bookkeeping is the same in every loop: the outputs are stored, then
// per lane the loop iterations, the batch flag, the stencil write and the survivor list.
//
// The steps are forced inline ([[gnu::always_inline]]) but two: run_rows compiles as it did when
// it was written in one piece, where GCC kept only the store of the outputs and the run of a
// gathered batch as calls of their own (and inlined every other step). So the split costs no
// call in the inner loops.
#pragma once

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstring>
#include <vector>

#include "vgpu/fragment.h"
#include "vgpu/gpu_internal.h"

namespace vgpu::gpu_detail {

#define VGPU_ROW_STEP [[gnu::always_inline]] inline

// End of a stretch of live idle fragments from `from`: the first i < to with wk[i] != 0 or, when
// there is a stencil test, st[i] == 0. Eight bytes at a time, the row's hottest loop.
inline int stretch_end(const uint8_t* wk, const uint8_t* st, int from, int to) {
  for (int i = from; i < to; i += 8) {
    const int n = std::min(8, to - i);
    uint64_t stop = nonzero_bytes(load_bytes(wk + i, n));
    if (st) stop |= ~nonzero_bytes(load_bytes(st + i, n)) & kHighs;
    if (n < 8) stop |= kHighs << (8 * n);  // past the end
    if (stop) return std::min(to, i + std::countr_zero(stop) / 8);
  }
  return to;
}

// The fragments of a batch being gathered: lane i is fragment (px[i], py[i]), index
// pi[i] = py * tw + px, window position (fx[i], fy[i]). How many are pending is a plain local of
// the loop (kept in a register), passed beside it.
template <int W>
struct Gathered {
  int px[W], py[W];
  uint32_t pi[W];
  alignas(64) float fx[W], fy[W];
  // Adds a fragment; true once the batch is full.
  [[gnu::always_inline]] bool push(int& pending, int x, int y, uint32_t i) {
    px[pending] = x;
    py[pending] = y;
    pi[pending] = i;
    fx[pending] = float(x) + 0.5f;
    fy[pending] = float(y) + 0.5f;
    return ++pending == W;
  }
};

// Plan: Gpu::DrawPlan, Out: Gpu::Chunk (private to Gpu, hence template parameters).
template <class L, class Plan, class Out>
struct RowShader {
  static constexpr int W = L::width;
  using F = typename L::F;
  using M = typename L::M;

  const Program& p;
  const Rect& r;
  const Plan& plan;
  Out& out;  // counted in the worker's local Chunk, stored once at the end
  Fragments<L>& f;
  const Stencil* stencil_test;
  const Stencil* work_mask;
  bool work_masked;  // idle fragments count as masked (an early-z/stencil reject)
  F iota;
  int nout;
  bool idle_kill;  // the program discards idle fragments
  uint32_t tw;     // masks are as wide as the target; indices of fragments are y * tw + x
  alignas(64) float lanes_out[4][W];  // store()'s output registers, channel by channel

  RowShader(const Program& p_, const Rect& r_, const Plan& plan_, Out& out_, Fragments<L>& f_,
            const Stencil* stencil_test_, const Stencil* work_mask_, bool work_masked_)
      : p(p_),
        r(r_),
        plan(plan_),
        out(out_),
        f(f_),
        stencil_test(stencil_test_),
        work_mask(work_mask_),
        work_masked(work_masked_),
        iota([](auto i) { return float(i); }),
        nout(p_.outputs()),
        idle_kill(p_.idle_discards()),
        tw(uint32_t(plan_.out[0].width)) {}

  // ---- Rows of the plan's per-fragment maps

  VGPU_ROW_STEP uint8_t* flag_row(int y) const {
    return plan.flags ? plan.flags + size_t(y - r.y0) * size_t(r.width()) : nullptr;
  }
  VGPU_ROW_STEP uint8_t* stencil_row(int y) const {
    return plan.stencil ? plan.stencil + size_t(y) * size_t(tw) : nullptr;
  }

  // Batch flag of fragment (x, y) once it ran: kTook also marks its tiles (shared with the
  // chunks above and below, hence the atomic stores of the same value).
  VGPU_ROW_STEP void flag_ran(uint8_t* fl, int x, int y, bool idle) {
    if (!fl) return;
    fl[x - r.x0] = idle ? kIdle : kTook;
    if (idle) {
      ++out.idle_flags;
      return;
    }
    const size_t dx = size_t(x - r.x0), dy = size_t(y - r.y0);
    std::atomic_ref<uint8_t>(plan.took8[(dy / 4) * size_t(plan.cols8) + dx / 8])
        .store(1, std::memory_order_relaxed);
    std::atomic_ref<uint8_t>(plan.took32[(dy / 32) * size_t(plan.cols32) + dx / 32])
        .store(1, std::memory_order_relaxed);
  }

  // ---- Idle fragments: n live fragments that skip the program

  // Counts them; returns how many are discarded.
  VGPU_ROW_STEP uint64_t idle_counts(uint64_t n) {
    if (work_masked) {
      // Modeled as an early-z/stencil reject: masked, not shaded, never counted.
      out.shaded -= n;
      out.masked += n;
    } else {
      out.idle += plan.idle_branches * n;  // an idle fragment takes none of the program's branches
    }
    return idle_kill && !work_masked ? n : 0;
  }
  // k live fragments from (x, y) on: their outputs keep their previous values, copied from the
  // passthrough units where the plan says so (or nothing, for a program that discards them).
  // Returns how many are discarded.
  VGPU_ROW_STEP uint64_t idle_run(int x, int y, int k) {
    const uint64_t n = uint64_t(k);
    if (idle_kill) return idle_counts(n);
    idle_counts(n);
    for (int o = 0; o < nout; ++o) {
      const auto& cp = plan.out[o];
      if (!cp.idle_src) continue;  // the target already holds these texels (PairRecord)
      const size_t off = (size_t(y) * size_t(cp.width) + size_t(x)) * size_t(cp.ch);
      const size_t count = n * size_t(cp.ch);
      if (cp.exact)
        std::memcpy(cp.data + off, cp.idle_src + off, count * sizeof(float));
      else  // rounded as the program's own store would be: the source is a wider format
        for (size_t i = 0; i < count; ++i)
          cp.data[off + i] = round_to(cp.fmt, cp.idle_src[off + i]);
    }
    return 0;
  }

  // ---- After a batch ran

  // Stores the program's outputs for the lanes in `write`; lane i is fragment (px[i], py[i]).
  // `row_run`: the W lanes are W neighbours of one row, all written.
  void store(const int* px, const int* py, int n, const M& write_mask, bool row_run) {
    bool write[W];
    write_mask.copy_to(write, stdx::element_aligned);
    for (int o = 0; o < nout; ++o) {
      const auto& t = plan.out[o];
      const Vec4<F>& v = f.output(o);
      v.x.copy_to(lanes_out[0], stdx::element_aligned);  // the channels the target has
      if (t.ch > 1) v.y.copy_to(lanes_out[1], stdx::element_aligned);
      if (t.ch > 2) v.z.copy_to(lanes_out[2], stdx::element_aligned);
      if (t.ch > 3) v.w.copy_to(lanes_out[3], stdx::element_aligned);
      auto at = [&](int i) {
        return t.data + (size_t(py[i]) * size_t(t.width) + size_t(px[i])) * size_t(t.ch);
      };
      if (row_run && t.ch == 4 && t.fmt == Format::fp32) {
        // The common case: W whole fp32x4 texels, interleaved from the four registers.
        texels::join<W>(lanes_out, at(0));
        continue;
      }
      if (t.ch == 4 && t.fmt == Format::fp32) {
        // Gathered lanes: interleaved once, then one 16-byte texel per written lane.
        alignas(64) float texels_out[4 * W];
        texels::join<W>(lanes_out, texels_out);
        for (int i = 0; i < n; ++i)
          if (write[i]) std::memcpy(at(i), texels_out + 4 * i, 4 * sizeof(float));
        continue;
      }
      if (t.fmt == Format::fp32) {  // already exact: no rounding
        for (int i = 0; i < n; ++i) {
          if (!write[i]) continue;
          float* dst = at(i);
          for (int c = 0; c < t.ch; ++c) dst[c] = lanes_out[c][i];
        }
        continue;
      }
      for (int i = 0; i < n; ++i) {
        if (!write[i]) continue;
        float* dst = at(i);
        for (int c = 0; c < t.ch; ++c) dst[c] = round_to(t.fmt, lanes_out[c][i]);
      }
    }
  }

  // ---- No work mask: blocks of W neighbours along each row

  VGPU_ROW_STEP void all_rows(int y0, int y1) {
    int px[W], py[W];
    bool bools[W] = {};
    for (int y = y0; y < y1; ++y) {
      const uint8_t* st = stencil_test ? stencil_test->row(y) : nullptr;
      uint8_t* sw = stencil_row(y);
      uint8_t* fl = flag_row(y);
      for (int x = r.x0; x < r.x1; x += W) {
        const int n = std::min(W, r.x1 - x);
        out.launched += uint64_t(n);
        // live: fragments in the quad that pass the stencil test.
        M live = iota < float(n);
        if (st) {
          for (int i = 0; i < n; ++i) bools[i] = st[x + i] != 0;
          live = live && M(bools, stdx::element_aligned);
        }
        const int nlive = lanes_on(live);
        out.masked += uint64_t(n - nlive);
        out.shaded += uint64_t(nlive);
        if (nlive == 0) continue;
        f.reset(iota + float(x) + 0.5f, F(float(y) + 0.5f), live, nout);
        p.run(f);
        const M kill = f.killed() && live;
        const M write = live && !kill;
        for (int i = 0; i < W; ++i) px[i] = x + i, py[i] = y;
        store(px, py, n, write, all(write));  // all(write): W fragments, none killed
        out.discarded += uint64_t(lanes_on(kill));
        bool lv[W], killed[W], idle[W];
        live.copy_to(lv, stdx::element_aligned);
        kill.copy_to(killed, stdx::element_aligned);
        f.idle_lanes().copy_to(idle, stdx::element_aligned);
        for (int i = 0; i < n; ++i) {
          if (!lv[i]) continue;
          if (plan.loop_map) plan.loop_map[uint32_t(y) * tw + uint32_t(x + i)] = f.loop_count(i);
          flag_ran(fl, x + i, y, idle[i]);
          if (sw) sw[x + i] = killed[i] ? 0 : 1;
          if (plan.list_survivors && !killed[i])
            out.survivors.push_back(uint32_t(y) * tw + uint32_t(x + i));
        }
      }
    }
  }

  // ---- With a work mask: gathered batches

  // Runs the gathered fragments (if any) and empties the batch. Unused lanes repeat lane 0's
  // position: they fetch in range and are never stored.
  void flush(Gathered<W>& g, int& pending) {
    if (pending == 0) return;
    const int n = pending;
    pending = 0;
    const M run = iota < float(n);
    if constexpr (W > 1)  // (at width 1 the batch is always full)
      for (int i = n; i < W; ++i) g.fx[i] = g.fx[0], g.fy[i] = g.fy[0];
    f.reset(F([&](auto i) { return g.fx[i]; }), F([&](auto i) { return g.fy[i]; }), run, nout);
    p.run(f);
    const M kill = f.killed() && run;
    const M write = run && !kill;
    const bool row_run = n == W && g.pi[W - 1] - g.pi[0] == W - 1 && g.py[0] == g.py[W - 1];
    store(g.px, g.py, n, write, row_run && all(write));
    // Per-lane bookkeeping from plain arrays (one store per mask, not one extraction per lane).
    bool killed[W], idle[W];
    kill.copy_to(killed, stdx::element_aligned);
    f.idle_lanes().copy_to(idle, stdx::element_aligned);
    out.discarded += uint64_t(lanes_on(kill));
    if (plan.loop_map)
      for (int i = 0; i < n; ++i) plan.loop_map[g.pi[i]] = f.loop_count(i);
    if (plan.flags) {
      const bool whole_flags = r.x0 == 0 && r.y0 == 0 && uint32_t(r.x1) == tw;
      for (int i = 0; i < n; ++i)
        flag_ran(whole_flags ? plan.flags + (g.pi[i] - uint32_t(g.px[i])) : flag_row(g.py[i]),
                 g.px[i], g.py[i], idle[i]);
    }
    if (plan.stencil)
      for (int i = 0; i < n; ++i) plan.stencil[g.pi[i]] = killed[i] ? 0 : 1;
    if (plan.list_survivors) {
      uint32_t keep[W];
      int m = 0;
      for (int i = 0; i < n; ++i) {
        keep[m] = g.pi[i];
        m += killed[i] ? 0 : 1;
      }
      out.survivors.insert(out.survivors.end(), keep, keep + m);
    }
  }

  // ---- A work mask with a list

  // Runs in place the listed fragments [b, k) of the W-aligned block [x0, x1) of row y (row0:
  // y * tw), as the hardware's own quads would (contiguous fetches and stores).
  VGPU_ROW_STEP void run_block(const uint32_t* b, const uint32_t* k, int y, uint32_t row0, int x0,
                               int x1) {
    bool on[W];
    for (int i = 0; i < W; ++i) on[i] = false;
    for (const uint32_t* q = b; q != k; ++q) on[*q - uint32_t(y) * tw - uint32_t(x0)] = true;
    const M run(on, stdx::element_aligned);
    f.reset(iota + float(x0) + 0.5f, F(float(y) + 0.5f), run, nout);
    p.run(f);
    const M kill = f.killed() && run;
    const M write = run && !kill;
    int bx[W], by[W];
    for (int i = 0; i < W; ++i) bx[i] = x0 + i, by[i] = y;
    store(bx, by, x1 - x0, write, all(write));
    out.discarded += uint64_t(lanes_on(kill));
    bool killed[W], idle[W];
    kill.copy_to(killed, stdx::element_aligned);
    f.idle_lanes().copy_to(idle, stdx::element_aligned);
    uint8_t* fl = flag_row(y);
    if (plan.loop_map)
      for (int i = 0; i < x1 - x0; ++i)
        if (on[i]) plan.loop_map[row0 + uint32_t(x0 + i)] = f.loop_count(i);
    if (fl) {  // flag_ran, with each 8x4 tile of the block marked once
      int marked = -1;
      for (int i = 0; i < x1 - x0; ++i) {
        if (!on[i]) continue;
        if (idle[i]) {
          fl[x0 + i] = kIdle;
          ++out.idle_flags;
        } else if ((x0 + i) / 8 != marked) {
          flag_ran(fl, x0 + i, y, false);
          marked = (x0 + i) / 8;
        } else {
          fl[x0 + i] = kTook;
        }
      }
    }
    if (plan.stencil)
      for (int i = 0; i < x1 - x0; ++i)
        if (on[i]) plan.stencil[row0 + uint32_t(x0 + i)] = killed[i] ? 0 : 1;
    if (plan.list_survivors) {
      uint32_t keep[W];
      int m = 0;
      for (int i = 0; i < x1 - x0; ++i) {
        keep[m] = row0 + uint32_t(x0 + i);
        m += on[i] && !killed[i] ? 1 : 0;
      }
      out.survivors.insert(out.survivors.end(), keep, keep + m);
    }
  }

  // Only the listed fragments of rows [y0, y1) are visited; draw() settled the idle ones'
  // outputs and stencil writes, here they are only counted.
  VGPU_ROW_STEP void listed_rows(int y0, int y1) {
    const uint32_t* b = std::lower_bound(plan.list->data(), plan.list->data() + plan.list->size(),
                                         uint32_t(y0) * tw);
    const uint32_t* e =
        std::lower_bound(b, plan.list->data() + plan.list->size(), uint32_t(y1) * tw);
    const uint64_t area = uint64_t(y1 - y0) * tw, nidle = area - uint64_t(e - b);
    out.launched += area;
    out.shaded += area;
    out.discarded += idle_counts(nidle);
    if (plan.flags && !work_masked) out.idle_flags += nidle;  // flags unwritten
    // A W-aligned block of a row where at least half the fragments are listed runs in place;
    // sparser ones are gathered.
    Gathered<W> g;
    int pending = 0;
    int y = 0;
    uint32_t row0 = 0;  // y * tw: a division only where the list changes rows
    while (b != e) {
      if (*b - row0 >= tw) {
        y = int(*b / tw);
        row0 = uint32_t(y) * tw;
      }
      const int x0 = int(*b - row0) / W * W, x1 = std::min(int(tw), x0 + W);
      const uint32_t* k = b;
      while (k != e && *k < row0 + uint32_t(x1)) ++k;
      if (2 * (k - b) < W) {
        for (; b != k; ++b)
          if (g.push(pending, int(*b - row0), y, *b)) flush(g, pending);
        continue;
      }
      flush(g, pending);  // the gathered fragments come first: survivors stay in ascending order
      run_block(b, k, y, row0, x0, x1);
      b = k;
    }
    flush(g, pending);
  }

  // ---- A work mask without a list

  // Every row is scanned: the working fragments join the batch; a stretch of live idle
  // fragments is handled at once, exactly as running them would (fragments are independent).
  VGPU_ROW_STEP void masked_rows(int y0, int y1) {
    Gathered<W> g;
    int pending = 0;
    for (int y = y0; y < y1; ++y) {
      const uint8_t* st = stencil_test ? stencil_test->row(y) : nullptr;
      const uint8_t* wk = work_mask->row(y);
      uint8_t* sw = stencil_row(y);
      uint8_t* fl = flag_row(y);
      out.launched += uint64_t(r.width());
      for (int x = r.x0; x < r.x1;) {
        if (st && st[x] == 0) {  // masked: not shaded, its flag stays 0
          ++out.masked;
          ++x;
          continue;
        }
        ++out.shaded;
        if (wk[x] != 0) {  // runs, in the next batch
          if (plan.list_runs) out.runs.push_back(uint32_t(y) * tw + uint32_t(x));
          if (g.push(pending, x, y, uint32_t(y) * tw + uint32_t(x))) flush(g, pending);
          ++x;
          continue;
        }
        // A stretch of live idle fragments (the usual case late in a loop).
        const int n = stretch_end(wk, st, x + 1, r.x1) - x;
        out.shaded += uint64_t(n - 1);
        out.discarded += idle_run(x, y, n);
        if (sw) std::memset(sw + x, idle_kill ? 0 : 1, size_t(n));
        if (fl && !work_masked) {
          std::memset(fl + (x - r.x0), kIdle, size_t(n));
          out.idle_flags += uint64_t(n);
        }
        x += n;
      }
    }
    flush(g, pending);
  }
};

#undef VGPU_ROW_STEP

}  // namespace vgpu::gpu_detail
