// The fragment processor and pipeline state: passes, limits, queries, masks, statistics.
#include "vgpu/gpu.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstring>
#include <vector>

namespace vgpu {

namespace {

// Batch flags per fragment: kTook took the branch, kIdle sat idle in it, 0 not shaded.
constexpr uint8_t kTook = kBranchTook, kIdle = kBranchIdle;

constexpr uint64_t kOnes = 0x0101010101010101ull, kHighs = 0x8080808080808080ull;

// The high bit of every non-zero byte of v.
constexpr uint64_t nonzero_bytes(uint64_t v) {
  return (((v & ~kHighs) + ~kHighs) | v) & kHighs;
}

// Up to eight bytes from p (n of them; the rest read as 0).
inline uint64_t load_bytes(const uint8_t* p, int n) {
  uint64_t v = 0;
  if (n >= 8) {
    std::memcpy(&v, p, 8);  // a fixed size: one load, no call
    return v;
  }
  for (int i = 0; i < n; ++i) v |= uint64_t(p[i]) << (8 * i);
  return v;
}

// Idle fragments in the 8x4 and the 32x32 tiles of the drawn rectangle where no fragment took
// the branch: {in 8x4 tiles, in 32x32 tiles}. That is every idle fragment (`idle_flags` of them)
// less those in tiles with work, so only the 32x32 tiles `took32` marks are scanned, eight
// fragments at a time. A fragment is idle when it passed the stencil test and the work mask
// left it idle (unless that counts as masked), or when it ran and its flag says so (the masks,
// not the flags, decide for fragments that did not run).
std::array<uint64_t, 2> idle_in_batches(const Rect& r, const uint8_t* flags, const Stencil* work,
                                        const Stencil* test, bool work_masked, uint64_t idle_flags,
                                        const uint8_t* took8, const uint8_t* took32) {
  const int w = r.width(), h = r.height();
  const int cols8 = (w + 7) / 8, cols32 = (w + 31) / 32, rows32 = (h + 31) / 32;
  std::array<uint64_t, 2> total{idle_flags, idle_flags};
  std::vector<uint64_t> idle8(
      static_cast<size_t>(cols8));  // per 8x4 tile of the current band of 4 rows
  for (int ty = 0; ty < rows32; ++ty)
    for (int tx = 0; tx < cols32; ++tx) {
      if (!took32[size_t(ty) * size_t(cols32) + size_t(tx)]) continue;
      const int c0 = tx * 4, c1 = std::min(cols8, c0 + 4);
      for (int band = ty * 8; band < std::min((h + 3) / 4, ty * 8 + 8); ++band) {
        for (int c = c0; c < c1; ++c) idle8[size_t(c)] = 0;
        for (int y = band * 4; y < std::min(h, band * 4 + 4); ++y) {
          const uint8_t* fl = flags + size_t(y) * size_t(w);
          const uint8_t* st = test ? test->row(r.y0 + y) + r.x0 : nullptr;
          const uint8_t* wk = work ? work->row(r.y0 + y) + r.x0 : nullptr;
          for (int c = c0; c < c1; ++c) {
            const int x = 8 * c, n = std::min(8, w - x);
            // Fragments of the rectangle that passed the stencil test.
            uint64_t live = st ? nonzero_bytes(load_bytes(st + x, n)) : kHighs;
            if (n < 8) live &= kHighs >> (8 * (8 - n));
            const uint64_t ran = wk ? nonzero_bytes(load_bytes(wk + x, n)) : kHighs;
            const uint64_t flagged_idle = ~nonzero_bytes(load_bytes(fl + x, n) ^ (kOnes * kIdle));
            const uint64_t idle = live & ((ran & flagged_idle) | (work_masked ? 0 : ~ran & kHighs));
            idle8[size_t(c)] += uint64_t(std::popcount(idle));
          }
        }
        for (int c = c0; c < c1; ++c) {
          const uint64_t n = idle8[size_t(c)];
          if (took8[size_t(band) * size_t(cols8) + size_t(c)]) total[0] -= n;
          total[1] -= n;
        }
      }
    }
  return total;
}

// The same counters for a pass under a listed mask (a whole-target draw, no stencil test), from
// the list instead of a scan of the tiles: there a tile's idle fragments are its fragments (or,
// when idle ones count as masked, its listed ones) less those that took the branch, so per-tile
// counts of listed and kTook fragments give them. `w` x `h`: the target, texel index y * w + x.
std::array<uint64_t, 2> idle_in_batches_listed(int w, int h, const uint8_t* flags,
                                               const std::vector<uint32_t>& listed,
                                               bool work_masked, uint64_t idle_flags) {
  const int cols8 = (w + 7) / 8, rows4 = (h + 3) / 4, cols32 = (w + 31) / 32;
  const int rows32 = (h + 31) / 32;
  // Per 8x4 and 32x32 tile: {listed, took}.
  thread_local std::vector<std::array<uint32_t, 2>> t8, t32;
  t8.assign(size_t(cols8) * size_t(rows4), {0, 0});
  t32.assign(size_t(cols32) * size_t(rows32), {0, 0});
  int y = 0;
  uint32_t row0 = 0;
  for (const uint32_t i : listed) {
    if (i - row0 >= uint32_t(w)) {
      y = int(i / uint32_t(w));
      row0 = uint32_t(y) * uint32_t(w);
    }
    const int x = int(i - row0);
    const uint32_t took = flags[i] == kTook ? 1 : 0;
    auto& a = t8[size_t(y / 4) * size_t(cols8) + size_t(x / 8)];
    auto& b = t32[size_t(y / 32) * size_t(cols32) + size_t(x / 32)];
    ++a[0], ++b[0];
    a[1] += took, b[1] += took;
  }
  std::array<uint64_t, 2> total{idle_flags, idle_flags};
  auto settle = [&](const std::vector<std::array<uint32_t, 2>>& t, int cols, int tw, int th,
                    uint64_t& sum) {
    for (size_t k = 0; k < t.size(); ++k) {
      if (t[k][1] == 0) continue;  // no fragment took the branch: its idle ones stay counted
      const int c = int(k % size_t(cols)), r = int(k / size_t(cols));
      const uint64_t area = uint64_t(std::min(tw, w - c * tw)) * uint64_t(std::min(th, h - r * th));
      sum -= (work_masked ? t[k][0] : area) - t[k][1];
    }
  };
  settle(t8, cols8, 8, 4, total[0]);
  settle(t32, cols32, 32, 32, total[1]);
  return total;
}

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

// A looping pass's batches: the profile's branch granularity as a tile of the drawn rectangle
// (2^k pixels: 2^ceil(k/2) wide, 2^floor(k/2) high, so 32 is 8x4 and 1024 is 32x32), aligned to
// its corner. A batch iterates as long as its busiest shaded fragment: every shaded fragment of
// it holds a lane slot for each of those iterations, active while it still loops. `iters`: per
// texel of the target (tw wide), the iterations each fragment ran. Per iteration k of the
// budget, the active and idle lanes of the batches still iterating go to active[k-1], idle[k-1].
LoopCounts loop_batches(const Rect& r, const uint32_t* iters, uint32_t tw, const Stencil* work,
                        const Stencil* test, bool work_masked, int granularity, int budget,
                        std::vector<uint64_t>& active, std::vector<uint64_t>& idle) {
  const int k = std::bit_width(unsigned(std::max(granularity, 1))) - 1;
  const int bw = 1 << ((k + 1) / 2), bh = 1 << (k / 2);
  active.assign(size_t(budget), 0);
  idle.assign(size_t(budget), 0);
  std::vector<uint64_t> exactly(size_t(budget) + 1);  // fragments of the batch with c iterations
  LoopCounts n;
  for (int ty = r.y0; ty < r.y1; ty += bh)
    for (int tx = r.x0; tx < r.x1; tx += bw) {
      std::fill(exactly.begin(), exactly.end(), 0);
      uint64_t lanes = 0;
      uint32_t most = 0;
      for (int y = ty; y < std::min(r.y1, ty + bh); ++y)
        for (int x = tx; x < std::min(r.x1, tx + bw); ++x) {
          if (test && test->get(x, y) == 0) continue;                 // masked before shading
          if (work_masked && work && work->get(x, y) == 0) continue;  // early-z: not shaded
          const uint32_t c = std::min(iters[size_t(y) * tw + size_t(x)], uint32_t(budget));
          ++lanes;
          ++exactly[c];
          n.iterations += c;
          most = std::max(most, c);
        }
      n.shaded += lanes;
      n.slots += lanes * most;
      n.batch_iterations += most;
      uint64_t out = exactly[0];  // fragments out of the loop before iteration j + 1
      for (uint32_t j = 0; j < most; ++j) {
        active[j] += lanes - out;
        idle[j] += out;
        out += exactly[j + 1];
      }
    }
  return n;
}

}  // namespace

struct Gpu::Chunk {
  uint64_t launched = 0, shaded = 0, masked = 0, discarded = 0, idle = 0;
  uint64_t idle_flags = 0;  // fragments flagged kIdle (for the batch counters)
  // Texel indices, ascending: the fragments that ran (DrawPlan::list_runs) and those whose
  // stencil write is 1 (DrawPlan::list_survivors).
  std::vector<uint32_t> runs, survivors;
  void reset() {
    std::vector<uint32_t> keep_runs = std::move(runs), keep_survivors = std::move(survivors);
    *this = Chunk{};
    runs = std::move(keep_runs);
    survivors = std::move(keep_survivors);
    runs.clear();
    survivors.clear();
  }
};

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

Gpu::Gpu(const Profile& profile, int threads, int lanes) : profile_(profile), lanes_(lanes) {
  if (lanes != 1 && lanes != 4 && lanes != 8 && lanes != 16)
    throw Error("lane width must be 1, 4, 8 or 16 (got " + std::to_string(lanes) + ")");
  if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { worker_loop(); });
}

Gpu::~Gpu() {
  {
    std::lock_guard lk(mu_);
    stop_ = true;
  }
  cv_work_.notify_all();
  for (auto& w : workers_) w.join();
}

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

void Gpu::parallel_rows(const Rect& r, uint64_t work,
                        const std::function<void(int, int, Chunk&)>& body,
                        std::vector<Chunk>& chunks) {
  const int rows = r.height();
  // Enough chunks to balance uneven rows, few enough to keep scheduling cheap; a pass that
  // visits few fragments runs on the calling thread (waking workers would cost more).
  const bool small = work < 4096;
  const int nchunks = small ? 1 : std::max(1, std::min(rows, threads() * 8));
  chunks.resize(size_t(nchunks));
  for (Chunk& c : chunks) c.reset();
  std::atomic<int> next{0};
  const std::function<void()> job = [&] {
    for (;;) {
      const int k = next.fetch_add(1);
      if (k >= nchunks) return;
      const int ya = r.y0 + int(int64_t(rows) * k / nchunks);
      const int yb = r.y0 + int(int64_t(rows) * (k + 1) / nchunks);
      body(ya, yb, chunks[size_t(k)]);
    }
  };
  if (workers_.empty() || nchunks == 1) {
    job();
    return;
  }
  run_on_workers(job);
}

// job() on the calling thread and on every worker, until all have returned.
void Gpu::run_on_workers(const std::function<void()>& job) {
  {
    std::lock_guard lk(mu_);
    job_ = &job;
    ++job_serial_;
    busy_ = int(workers_.size());
  }
  cv_work_.notify_all();
  job();
  std::unique_lock lk(mu_);
  cv_done_.wait(lk, [&] { return busy_ == 0; });
  job_ = nullptr;
}

void Gpu::worker_loop() {
  uint64_t seen = 0;
  std::unique_lock lk(mu_);
  for (;;) {
    cv_work_.wait(lk, [&] { return stop_ || job_serial_ != seen; });
    if (stop_) return;
    seen = job_serial_;
    const std::function<void()>* job = job_;
    lk.unlock();
    (*job)();
    lk.lock();
    if (--busy_ == 0) cv_done_.notify_one();
  }
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

// A pass that a batch walk ran already (Gpu::replay_next): nothing runs, and the statistics
// come out as the fragment processor's would. The walk ran the fragments of the work mask
// (every fragment without one); the others are idle, settled as run_rows's listed path settles
// them; the tally's tile sums give the batch counters as idle_in_batches_listed does.
const PassRecord& Gpu::replay(const Program& p, const Program::Analysis& a, const Rect& rect,
                              const PassTally& t, std::chrono::steady_clock::time_point t0) {
  const Texture& target = *targets_[0];
  if (stencil_test_ || rect.x0 != 0 || rect.y0 != 0 || rect.x1 != target.width() ||
      rect.y1 != target.height() || a.loop.loops > 0)
    fail("program '" + std::string(p.name()) +
         "': a replayed pass must cover the whole target, without stencil test or loop");
  const uint64_t area = rect.area();
  if (t.ran > area || (!work_mask_ && t.ran != area))
    fail("program '" + std::string(p.name()) + "': replayed tally does not fit the pass");
  const uint64_t idle = area - t.ran;
  Chunk sum;
  sum.launched = area;
  sum.shaded = area;
  sum.discarded = t.killed;
  sum.idle = t.lanes_idle;
  sum.idle_flags = t.flagged_idle;
  if (work_masked_) {  // idle fragments: rejected by the early-z test, never shaded
    sum.shaded -= idle;
    sum.masked += idle;
  } else {
    sum.idle += uint64_t(a.branches) * idle;
    if (p.idle_discards()) sum.discarded += idle;
    if (a.branches > 0) sum.idle_flags += idle;
  }
  flags_size_ = 0;  // no per-fragment map: nothing ran here
  flags_ran_.reset();
  // The walk left the targets and the stencil written: whatever the emulator knew of them is old.
  for (Texture* target_tex : targets_) ++target_tex->version_;
  if (stencil_write_) ++stencil_write_->version_;
  const std::array<uint64_t, 2> batch{sum.idle_flags - t.idle_near_took8x4,
                                      sum.idle_flags - t.idle_near_took32x32};
  return settle(p, a, rect, sum, a.branches > 0 ? &batch : nullptr, nullptr, {}, {}, t0, t.host_ms);
}

void Gpu::parallel_for(int n, const std::function<void(int, int)>& body) {
  std::atomic<int> next{0}, slot{0};
  const std::function<void()> job = [&] {
    const int mine = slot.fetch_add(1);
    for (;;) {
      const int k = next.fetch_add(1);
      if (k >= n) return;
      body(k, mine);
    }
  };
  if (workers_.empty() || n <= 1) {
    job();
    return;
  }
  run_on_workers(job);
}

// The statistics of a pass from what its fragments did: static per-fragment costs times the
// fragments shaded (identical at any width and thread count), the batch and loop counters.
const PassRecord& Gpu::settle(const Program& p, const Program::Analysis& a, const Rect& rect,
                              const Chunk& sum, const std::array<uint64_t, 2>* batch,
                              const LoopCounts* loop, std::vector<uint64_t> loop_active,
                              std::vector<uint64_t> loop_idle,
                              std::chrono::steady_clock::time_point t0, double extra_ms) {
  const std::string pname = p.name();
  const bool looping = loop != nullptr;
  const Format precision = precision_of(p);
  Counters c = pass_counters(a, units_.data(), targets_, sum.launched, sum.shaded, sum.discarded);
  c.fragments_masked = sum.masked;
  c.lanes_idle = sum.idle;
  if (looping) add_loop_counters(c, a, units_.data(), *loop);
  if (batch) {
    c.idle_in_batch32 = (*batch)[0];
    c.idle_in_batch1024 = (*batch)[1];
  }
  // Arithmetic (every counted operation but the fetches) by the precision it ran at.
  const uint64_t alu = c.instructions - c.texture_fetches;
  if (precision == Format::fp24) c.alu_fp24 = alu;
  if (precision == Format::fp16) c.alu_fp16 = alu;
  if (query_active_) query_count_ += sum.shaded - sum.discarded;
  c.host_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() +
      extra_ms;

  FrameStats::ProgramTotals& totals = stats_.program(pname, p.paper_name(), a.instructions);
  totals.counters += c;
  totals.instructions = a.instructions;
  if (looping) {
    totals.loop_budget = std::max(totals.loop_budget, a.loop.max_iterations);
    totals.loop_body_instructions = a.loop.body_instructions;
    auto add = [](std::vector<uint64_t>& to, const std::vector<uint64_t>& v) {
      if (to.size() < v.size()) to.resize(v.size(), 0);
      for (size_t i = 0; i < v.size(); ++i) to[i] += v[i];
    };
    add(totals.loop_active, loop_active);
    add(totals.loop_idle, loop_idle);
  }
  stats_.totals += c;
  PassRecord rec{pname, rect.width(), rect.height(), c, -1};
  rec.loop_active = std::move(loop_active);
  rec.loop_idle = std::move(loop_idle);
  if (stats_.keep_pass_records) {
    stats_.passes.push_back(std::move(rec));
    return stats_.passes.back();
  }
  last_pass_ = std::move(rec);
  return last_pass_;
}

}  // namespace vgpu
