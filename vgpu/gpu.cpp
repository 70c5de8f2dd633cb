// The fragment processor and pipeline state: programs, units, targets, queries, and the pass
// itself (draw() plans it, run_rows() shades the fragments of a band of rows).
#include "vgpu/gpu.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstring>
#include <vector>

#include "vgpu/gpu_internal.h"

namespace vgpu {

using namespace gpu_detail;

namespace {

// End of a stretch of live idle fragments from `from`: the first i < to with wk[i] != 0 or, when
// there is a stencil test, st[i] == 0. Eight bytes at a time, the row's hottest loop.
int stretch_end(const uint8_t* wk, const uint8_t* st, int from, int to) {
  for (int i = from; i < to; i += 8) {
    const int n = std::min(8, to - i);
    uint64_t stop = nonzero_bytes(load_bytes(wk + i, n));
    if (st) stop |= ~nonzero_bytes(load_bytes(st + i, n)) & kHighs;
    if (n < 8) stop |= kHighs << (8 * n);  // past the end
    if (stop) return std::min(to, i + std::countr_zero(stop) / 8);
  }
  return to;
}

}  // namespace

// What one draw's row workers share: where outputs go, where idle fragments' outputs come from,
// and the batch-flag maps. Built once per draw on the calling thread.
struct Gpu::DrawPlan {
  struct Out {
    float* data = nullptr;  // the target's texels
    int width = 0, ch = 0;
    Format fmt = Format::fp32;
    const float* idle_src = nullptr;  // passthrough texels to copy for idle fragments, or null
    bool exact = false;               // same format: already rounded, a plain copy
  };
  Out out[kMaxOutputs];
  uint64_t idle_branches = 0;
  // Per fragment of the rectangle: kTook, kIdle or 0 (not shaded). Null: the program has no
  // branches.
  uint8_t* flags = nullptr;
  bool list_runs = false;       // collect Chunk::runs (for a PairRecord)
  bool list_survivors = false;  // collect Chunk::survivors (the stencil write's non-zero list)
  // The work mask's non-zero list (Stencil::nonzero_): only these fragments are visited. Set only
  // for a whole-target draw without stencil test; idle fragments are then settled in draw().
  const std::vector<uint32_t>* list = nullptr;
  uint8_t* stencil = nullptr;                   // the stencil write's bits, or null
  uint8_t *took8 = nullptr, *took32 = nullptr;  // tiles holding a kTook fragment
  int cols8 = 0, cols32 = 0;
  // A looping program: per texel of the target, the iterations its fragment ran (0 if none).
  uint32_t* loop_map = nullptr;
};

void Gpu::fail(const std::string& what) const {
  throw Error(what);
}

void Gpu::use_program(const Program& program) {
  if (in_draw_)
    fail(std::string("program '") + program.name() + "': no recursion (bind inside a pass)");
  program_ = &program;
  if (program.id() == loaded_program_) return;
  loaded_program_ = program.id();
  count_program_load(stats_, program, profile_);
}

void Gpu::bind_texture(int unit, const Texture& texture) {
  if (unit < 0 || unit >= kMaxTextureUnits)
    fail("texture unit " + std::to_string(unit) + " does not exist (0.." +
         std::to_string(kMaxTextureUnits - 1) + ")");
  check_texture(texture);
  units_[unit] = &texture;
}

void Gpu::unbind_textures() {
  units_.fill(nullptr);
}

void Gpu::set_targets(std::initializer_list<Texture*> targets) {
  targets_.assign(targets.begin(), targets.end());
  for (Texture* t : targets_) check_texture(*t);
}

void Gpu::clear(Texture& t, std::initializer_list<float> value) {
  if (int(value.size()) != t.channels())
    fail("clear of texture '" + t.name() + "': " + std::to_string(value.size()) + " values for " +
         std::to_string(t.channels()) + " channels");
  check_texture(t);
  t.fill(std::span<const float>(value.begin(), value.size()));
  Counters c;
  c.clears = 1;
  c.bytes_written = t.bytes();
  stats_.totals += c;
}

void Gpu::begin_query() {
  if (query_active_) fail("begin_query: a query is already active");
  query_active_ = true;
  query_count_ = 0;
}

uint64_t Gpu::end_query() {
  if (!query_active_) fail("end_query: no query is active");
  query_active_ = false;
  count_readback(stats_, program_, query_count_);
  return query_count_;
}

const PassRecord& Gpu::draw() {
  if (targets_.empty())
    fail(program_
             ? "program '" + std::string(program_->name()) + "': draw with no render target set"
             : std::string("draw: no render target set"));
  return draw(Rect{0, 0, targets_[0]->width(), targets_[0]->height()});
}

template <class L>
void Gpu::run_rows(const Program& p, const Rect& r, int y0, int y1, const DrawPlan& plan,
                   Chunk& result) const {
  constexpr int W = L::width;
  // Counted in a local and stored once: neighbouring chunks share cache lines, and other
  // threads are counting into them.
  Chunk out;
  out.runs = std::move(result.runs);
  out.survivors = std::move(result.survivors);
  using F = typename L::F;
  using M = typename L::M;
  BoundTexture views[kMaxTextureUnits];
  for (int u = 0; u < kMaxTextureUnits; ++u)
    if (units_[u])
      views[u] = {units_[u]->data().data(), units_[u]->width(), units_[u]->height(),
                  units_[u]->channels()};
  const bool dynamic = profile_.branching == Branching::dynamic;
  Fragments<L> f(views, dynamic, &out.idle, nullptr);
  const F iota([](auto i) { return float(i); });
  const int nout = p.outputs();
  const bool idle_kill = p.idle_discards();
  alignas(64) float lanes_out[4][W];
  bool bools[W] = {};

  auto flag_row = [&](int y) {
    return plan.flags ? plan.flags + size_t(y - r.y0) * size_t(r.width()) : nullptr;
  };
  // Batch flag of fragment (x, y) once it ran: kTook also marks its tiles (shared with the
  // chunks above and below, hence the atomic stores of the same value).
  auto flag_ran = [&](uint8_t* fl, int x, int y, bool idle) {
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
  };
  // k live fragments from (x, y) on that skip the program: their outputs keep their previous
  // values, copied from the passthrough units where the plan says so (or nothing, for a program
  // that discards them). Returns how many are discarded.
  auto idle_counts = [&](uint64_t n) -> uint64_t {
    if (work_masked_) {
      // Modeled as an early-z/stencil reject: masked, not shaded, never counted.
      out.shaded -= n;
      out.masked += n;
    } else {
      out.idle += plan.idle_branches * n;  // an idle fragment takes none of the program's branches
    }
    return idle_kill && !work_masked_ ? n : 0;
  };
  auto idle_run = [&](int x, int y, int k) -> uint64_t {
    const uint64_t n = uint64_t(k);
    if (idle_kill) return idle_counts(n);
    idle_counts(n);
    for (int o = 0; o < nout; ++o) {
      const DrawPlan::Out& cp = plan.out[o];
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
  };
  // Stores the program's outputs for the lanes in `write`; lane i is fragment (px[i], py[i]).
  // `row_run`: the W lanes are W neighbours of one row, all written.
  auto store = [&](const int* px, const int* py, int n, const M& write_mask, bool row_run) {
    bool write[W];
    write_mask.copy_to(write, stdx::element_aligned);
    for (int o = 0; o < nout; ++o) {
      const DrawPlan::Out& t = plan.out[o];
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
  };

  // Masks are as wide as the target; indices of fragments are y * tw + x.
  const uint32_t tw = uint32_t(plan.out[0].width);
  auto stencil_row = [&](int y) {
    return plan.stencil ? plan.stencil + size_t(y) * size_t(tw) : nullptr;
  };
  if (!work_mask_) {
    // Every live fragment runs: blocks of W neighbours along each row.
    int px[W], py[W];
    for (int y = y0; y < y1; ++y) {
      const uint8_t* st = stencil_test_ ? stencil_test_->row(y) : nullptr;
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
    result = std::move(out);
    return;
  }

  // With a work mask, the live fragments it marks are gathered into batches of W (across rows),
  // so a pass costs host time for the fragments that work, not for the screen; idle stretches
  // are handled at once, exactly as running them would (fragments are independent).
  // The batch being gathered: lane i is fragment (px[i], py[i]), index pi[i] = py * tw + px,
  // window position (fx[i], fy[i]).
  int px[W], py[W];
  uint32_t pi[W];
  alignas(64) float fx[W], fy[W];
  int pending = 0;
  auto push = [&](int x, int y, uint32_t i) {
    px[pending] = x;
    py[pending] = y;
    pi[pending] = i;
    fx[pending] = float(x) + 0.5f;
    fy[pending] = float(y) + 0.5f;
    return ++pending == W;
  };
  auto flush = [&] {
    if (pending == 0) return;
    const int n = pending;
    pending = 0;
    const M run = iota < float(n);
    // Unused lanes repeat lane 0's position: they fetch in range and are never stored.
    for (int i = n; i < W; ++i) fx[i] = fx[0], fy[i] = fy[0];
    f.reset(F([&](auto i) { return fx[i]; }), F([&](auto i) { return fy[i]; }), run, nout);
    p.run(f);
    const M kill = f.killed() && run;
    const M write = run && !kill;
    const bool row_run = n == W && pi[W - 1] - pi[0] == W - 1 && py[0] == py[W - 1];
    store(px, py, n, write, row_run && all(write));
    // Per-lane bookkeeping from plain arrays (one store per mask, not one extraction per lane).
    bool killed[W], idle[W];
    kill.copy_to(killed, stdx::element_aligned);
    f.idle_lanes().copy_to(idle, stdx::element_aligned);
    out.discarded += uint64_t(lanes_on(kill));
    if (plan.loop_map)
      for (int i = 0; i < n; ++i) plan.loop_map[pi[i]] = f.loop_count(i);
    if (plan.flags) {
      const bool whole_flags = r.x0 == 0 && r.y0 == 0 && uint32_t(r.x1) == tw;
      for (int i = 0; i < n; ++i)
        flag_ran(whole_flags ? plan.flags + (pi[i] - uint32_t(px[i])) : flag_row(py[i]), px[i],
                 py[i], idle[i]);
    }
    if (plan.stencil)
      for (int i = 0; i < n; ++i) plan.stencil[pi[i]] = killed[i] ? 0 : 1;
    if (plan.list_survivors) {
      uint32_t keep[W];
      int m = 0;
      for (int i = 0; i < n; ++i) {
        keep[m] = pi[i];
        m += killed[i] ? 0 : 1;
      }
      out.survivors.insert(out.survivors.end(), keep, keep + m);
    }
  };
  if (plan.list) {
    // Only the listed fragments of rows [y0, y1) are visited; draw() settled the idle ones'
    // outputs and stencil writes, here they are only counted.
    const uint32_t* b = std::lower_bound(plan.list->data(), plan.list->data() + plan.list->size(),
                                         uint32_t(y0) * tw);
    const uint32_t* e =
        std::lower_bound(b, plan.list->data() + plan.list->size(), uint32_t(y1) * tw);
    const uint64_t area = uint64_t(y1 - y0) * tw, nidle = area - uint64_t(e - b);
    out.launched += area;
    out.shaded += area;
    out.discarded += idle_counts(nidle);
    if (plan.flags && !work_masked_) out.idle_flags += nidle;  // flags unwritten
    // A W-aligned block of a row where at least half the fragments are listed runs in place, as
    // the hardware's own quads would (contiguous fetches and stores); sparser ones are gathered.
    bool on[W];
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
          if (push(int(*b - row0), y, *b)) flush();
        continue;
      }
      flush();  // the gathered fragments come first: survivors stay in ascending order
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
      b = k;
    }
    flush();
    result = std::move(out);
    return;
  }
  for (int y = y0; y < y1; ++y) {
    const uint8_t* st = stencil_test_ ? stencil_test_->row(y) : nullptr;
    const uint8_t* wk = work_mask_->row(y);
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
        if (push(x, y, uint32_t(y) * tw + uint32_t(x))) flush();
        ++x;
        continue;
      }
      // A stretch of live idle fragments (the usual case late in a loop).
      const int n = stretch_end(wk, st, x + 1, r.x1) - x;
      out.shaded += uint64_t(n - 1);
      out.discarded += idle_run(x, y, n);
      if (sw) std::memset(sw + x, idle_kill ? 0 : 1, size_t(n));
      if (fl && !work_masked_) {
        std::memset(fl + (x - r.x0), kIdle, size_t(n));
        out.idle_flags += uint64_t(n);
      }
      x += n;
    }
  }
  flush();
  result = std::move(out);
}

// After a pass that carried idle fragments over from passthrough units: each source and target
// now agree except at the fragments that ran: `runs`, or those the row chunks listed when
// `chunk_runs`; neither: no record.
void Gpu::track_pairs(const Program& p, const std::shared_ptr<const std::vector<uint32_t>>& runs,
                      bool chunk_runs) {
  for (int o = 0; o < p.outputs(); ++o) {
    const Texture& dst = *targets_[o];
    const Texture& src = *units_[p.passthrough(o)];
    // Forget every record about either texture, then note the new one.
    std::erase_if(pairs_, [&](const PairRecord& r) {
      return r.a == &src || r.b == &src || r.a == &dst || r.b == &dst;
    });
    if ((!runs && !chunk_runs) || src.format() != dst.format()) continue;
    PairRecord rec{&src, &dst, src.uid_, src.version_, dst.uid_, dst.version_, {}};
    if (runs) {
      rec.differ = runs;
    } else {
      size_t n = 0;
      for (const Chunk& c : chunks_) n += c.runs.size();
      auto differ = std::make_shared<std::vector<uint32_t>>();
      differ->reserve(n);
      for (const Chunk& c : chunks_) differ->insert(differ->end(), c.runs.begin(), c.runs.end());
      rec.differ = std::move(differ);
    }
    pairs_.push_back(std::move(rec));
  }
}

const PassRecord& Gpu::draw(const Rect& rect) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!program_) fail("draw: no program bound");
  const Program& p = *program_;
  const std::string pname = p.name();
  if (in_draw_) fail("program '" + pname + "': no recursion (a pass started inside a pass)");

  const Program::Analysis a = p.analyze();
  check_pass(profile_, p, a, units_.data(), targets_, rect);
  const Texture& t0tex = *targets_[0];
  auto check_mask = [&](const Stencil* s, const char* what) {
    if (s && (s->width() != t0tex.width() || s->height() != t0tex.height()))
      fail("program '" + pname + "': " + what + " size differs from the render target");
  };
  check_mask(stencil_test_, "stencil");
  check_mask(stencil_write_, "stencil");
  check_mask(work_mask_, "work mask");
  if (work_mask_ && !p.idle_discards()) {
    if (!p.has_passthrough())
      fail("program '" + pname + "' declares no passthrough, so it cannot skip idle fragments");
    for (int o = 0; o < p.outputs(); ++o) {
      const Texture* src = units_[p.passthrough(o)];
      if (!src || src->width() != targets_[o]->width() || src->height() != targets_[o]->height() ||
          src->channels() != targets_[o]->channels())
        fail("program '" + pname + "': passthrough unit " + std::to_string(p.passthrough(o)) +
             " does not hold a texture shaped like render target " + std::to_string(o));
    }
  }

  looped_ = false;  // until this pass runs a loop
  if (const PassTally* t = std::exchange(replay_, nullptr)) return replay(p, a, rect, *t, t0);

  in_draw_ = true;
  std::vector<Chunk>& chunks = chunks_;
  DrawPlan plan;
  plan.idle_branches = uint64_t(a.branches);
  // Under a work mask whose non-zero pixels the last pass that wrote it listed, only those run
  // (a whole-target draw without stencil test).
  const bool whole = !stencil_test_ && rect.x0 == 0 && rect.y0 == 0 && rect.x1 == t0tex.width() &&
                     rect.y1 == t0tex.height();
  const bool use_list = work_mask_ && whole && work_mask_->listed_version_ == work_mask_->version_;
  if (a.branches > 0) {
    // Complete after the pass (branch flags are a per-fragment map): masked fragments stay 0.
    // Under a listed mask every fragment but the listed ones is idle (those overwrite their flag
    // when they run): one fill with the right value.
    const size_t n = size_t(rect.width()) * size_t(rect.height());
    const uint8_t base = use_list && !work_masked_ ? kIdle : 0;
    if (use_list && flags_ran_ && flags_base_ == base && batch_flags_.size() == n) {
      // The buffer holds `base` but where the last listed pass ran: reset those only.
      for (const uint32_t i : *flags_ran_) batch_flags_[i] = base;
    } else {
      batch_flags_.assign(n, base);
    }
    flags_ran_.reset();  // set again after the pass, if it is listed
    flags_base_ = base;
    flags_size_ = n;
    plan.flags = batch_flags_.data();
    plan.cols8 = (rect.width() + 7) / 8;
    plan.cols32 = (rect.width() + 31) / 32;
    took8_.assign(size_t(plan.cols8) * size_t((rect.height() + 3) / 4), 0);
    took32_.assign(size_t(plan.cols32) * size_t((rect.height() + 31) / 32), 0);
    plan.took8 = took8_.data();
    plan.took32 = took32_.data();
  } else {
    flags_size_ = 0;  // no branches: no flags (the buffer keeps its contents for later)
  }
  // The masks as they were before the pass, for the batch counters: a pass may write the mask
  // it tests (a query pass counting into the stencil it reads).
  Stencil work_before, test_before;
  const Stencil* work_view = work_mask_;
  const Stencil* test_view = stencil_test_;
  const bool looping = a.loop.loops > 0;
  looped_ = looping;
  if (looping) {
    loop_map_.assign(size_t(t0tex.width()) * size_t(t0tex.height()), 0);
    plan.loop_map = loop_map_.data();
  }
  // (a listed pass's branch counters read only the flags; the loop counters read the mask)
  if ((plan.flags || looping) && (!use_list || looping) && stencil_write_ &&
      stencil_write_ == work_mask_)
    work_view = &(work_before = *work_mask_);
  if ((plan.flags || looping) && stencil_write_ && stencil_write_ == stencil_test_)
    test_view = &(test_before = *stencil_test_);
  // Idle fragments keep their previous outputs, copied from the passthrough units. Where the
  // last pass between the same two textures left them equal outside the fragments it ran (a
  // PairRecord; every fragment drawn, no stencil test, same format), only the texels that
  // differ and are idle now are copied, here; the row workers copy nothing.
  const bool carries = work_mask_ && !p.idle_discards();
  auto same = [](const Texture* t, const Texture* r, uint64_t uid, uint64_t version) {
    return t == r && t->uid_ == uid && t->version_ == version;
  };
  // Under a work mask whose non-zero pixels the last pass that wrote it listed, only those run.
  // Held here: this pass may write the mask and give it a new list.
  std::shared_ptr<const std::vector<uint32_t>> listed;
  if (use_list) {
    listed = work_mask_->nonzero_;
    plan.list = listed.get();
  }
  for (int o = 0; o < p.outputs(); ++o) {
    Texture& dst = *targets_[o];
    plan.out[o] = {nullptr, dst.width(), dst.channels(), dst.format(), nullptr, false};
    if (!carries) continue;
    const Texture& src = *units_[p.passthrough(o)];
    plan.out[o].idle_src = src.data().data();
    plan.out[o].exact = src.format() == dst.format() || dst.format() == Format::fp32;
    if (!whole || src.format() != dst.format()) continue;
    plan.list_runs = !plan.list;  // the list is the run set
    for (auto rec = pairs_.begin(); rec != pairs_.end(); ++rec)
      if ((same(&src, rec->a, rec->uid_a, rec->version_a) &&
           same(&dst, rec->b, rec->uid_b, rec->version_b)) ||
          (same(&src, rec->b, rec->uid_b, rec->version_b) &&
           same(&dst, rec->a, rec->uid_a, rec->version_a))) {
        plan.out[o].idle_src = nullptr;
        const size_t ch = size_t(dst.channels());
        const uint8_t* bits = work_mask_->bits_.data();
        float* dd = dst.data_.data();
        const float* sd = src.data_.data();
        if (ch == 4) {                           // a fixed-size copy: inlined
          for (const uint32_t i : *rec->differ)  // the mask is as wide as the target
            if (bits[i] == 0) std::memcpy(dd + i * 4, sd + i * 4, 4 * sizeof(float));
        } else {
          for (const uint32_t i : *rec->differ)
            if (bits[i] == 0) std::memcpy(dd + i * ch, sd + i * ch, ch * sizeof(float));
        }
        pairs_.erase(rec);  // used up: if the pass fails, no record claims the textures agree
        break;
      }
  }
  if (plan.list) {
    // Idle fragments are settled here: the texels between listed ones get the passthrough's
    // value (where no PairRecord spared that) and the stencil write its idle value.
    for (int o = 0; o < p.outputs(); ++o) {
      DrawPlan::Out& cp = plan.out[o];
      if (!cp.idle_src) continue;
      float* dst = targets_[o]->data_.data();
      const size_t ch = size_t(cp.ch), n = size_t(cp.width) * size_t(targets_[o]->height());
      auto copy = [&](size_t from, size_t to) {  // texels [from, to)
        if (cp.exact)
          std::memcpy(dst + from * ch, cp.idle_src + from * ch, (to - from) * ch * sizeof(float));
        else
          for (size_t i = from * ch; i < to * ch; ++i) dst[i] = round_to(cp.fmt, cp.idle_src[i]);
      };
      size_t next = 0;
      for (const uint32_t i : *listed) {
        if (i > next) copy(next, i);
        next = size_t(i) + 1;
      }
      if (n > next) copy(next, n);
      cp.idle_src = nullptr;
    }
    if (stencil_write_) {
      const uint8_t value = p.idle_discards() ? 0 : 1;
      std::vector<uint8_t>& bits = stencil_write_->bits_;
      const auto* nz = stencil_write_->listed_version_ == stencil_write_->version_
                           ? stencil_write_->nonzero_.get()
                           : nullptr;
      if (value == 0 && nz && nz->size() < bits.size() / 16) {
        // Only the listed pixels are non-zero: clear those (the usual case, a query pass
        // narrowing the mask it reads).
        for (const uint32_t i : *nz) bits[i] = 0;
      } else {
        std::memset(bits.data(), value, bits.size());
      }
    }
  }
  // The stencil write's non-zero list is known after the pass when every fragment's value is:
  // the fragments that ran and survived (idle ones, if any, are discarded).
  plan.list_survivors = stencil_write_ && whole && (!work_mask_ || p.idle_discards());
  if (stencil_write_) {
    plan.stencil = stencil_write_->bits_.data();
    ++stencil_write_->version_;
  }
  // Pass writes: one version step per target (the row workers write through plan.out).
  for (int o = 0; o < p.outputs(); ++o) plan.out[o].data = targets_[o]->texel_mut(0, 0);
  const Format precision = precision_of(p);
  auto body = [&](int ya, int yb, Chunk& c) {
    // Reduced precision runs at width 1 (the scalar reference) or 8.
    if (precision == Format::fp16) {
      if (lanes_ == 1)
        run_rows<RoundedLanes<1, Format::fp16>>(p, rect, ya, yb, plan, c);
      else
        run_rows<RoundedLanes<8, Format::fp16>>(p, rect, ya, yb, plan, c);
      return;
    }
    if (precision == Format::fp24) {
      if (lanes_ == 1)
        run_rows<RoundedLanes<1, Format::fp24>>(p, rect, ya, yb, plan, c);
      else
        run_rows<RoundedLanes<8, Format::fp24>>(p, rect, ya, yb, plan, c);
      return;
    }
    switch (lanes_) {
      case 1:
        run_rows<SimdLanes<1>>(p, rect, ya, yb, plan, c);
        break;
      case 4:
        run_rows<SimdLanes<4>>(p, rect, ya, yb, plan, c);
        break;
      case 8:
        run_rows<SimdLanes<8>>(p, rect, ya, yb, plan, c);
        break;
      default:
        run_rows<SimdLanes<16>>(p, rect, ya, yb, plan, c);
        break;
    }
  };
  parallel_rows(rect, plan.list ? uint64_t(plan.list->size()) : rect.area(), body, chunks);
  in_draw_ = false;
  if (plan.flags && plan.list) flags_ran_ = listed;  // the only flags this pass wrote
  if (carries) track_pairs(p, listed, plan.list_runs);
  if (plan.list_survivors) {
    size_t n = 0;
    for (const Chunk& c : chunks) n += c.survivors.size();
    auto nz = std::make_shared<std::vector<uint32_t>>();
    nz->reserve(n);
    for (const Chunk& c : chunks) nz->insert(nz->end(), c.survivors.begin(), c.survivors.end());
    stencil_write_->nonzero_ = std::move(nz);
    stencil_write_->listed_version_ = stencil_write_->version_;
  }

  Chunk sum;
  for (const Chunk& c : chunks) {
    sum.launched += c.launched;
    sum.shaded += c.shaded;
    sum.masked += c.masked;
    sum.discarded += c.discarded;
    sum.idle += c.idle;
    sum.idle_flags += c.idle_flags;
  }
  std::vector<uint64_t> loop_active, loop_idle;
  LoopCounts loop_n;
  if (looping) {
    loop_n = loop_batches(rect, plan.loop_map, uint32_t(t0tex.width()), work_view, test_view,
                          work_masked_, profile_.branch_granularity, a.loop.max_iterations,
                          loop_active, loop_idle);
    if (loop_n.shaded != sum.shaded) fail("program '" + pname + "': loop batches miscounted");
  }
  std::array<uint64_t, 2> batch{};
  if (plan.flags)
    batch =
        // From the list where it is short; otherwise a scan of the tiles (eight flags a step),
        // where under a listed mask the flags alone decide (no stencil test; fragments off the
        // list hold kIdle, or 0 where that counts as masked), as if every fragment ran.
        plan.list && plan.list->size() * 16 < rect.area()
            ? idle_in_batches_listed(rect.width(), rect.height(), plan.flags, *plan.list,
                                     work_masked_, sum.idle_flags)
            : idle_in_batches(rect, plan.flags, plan.list ? nullptr : work_view, test_view,
                              work_masked_, sum.idle_flags, plan.took8, plan.took32);
  return settle(p, a, rect, sum, plan.flags ? &batch : nullptr, looping ? &loop_n : nullptr,
                std::move(loop_active), std::move(loop_idle), t0, 0.0);
}

}  // namespace vgpu
