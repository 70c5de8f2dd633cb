// The fragment processor and pipeline state: passes, limits, queries, masks, statistics.
#include "vgpu/gpu.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstring>

namespace vgpu {

namespace {

// Batch flags per fragment: kTook took the branch, kIdle sat idle in it, 0 not shaded.
constexpr uint8_t kTook = kBranchTook, kIdle = kBranchIdle;

// Idle fragments in the 8x4 and the 32x32 tiles of a w x h flag map where no fragment took the
// branch: {in 8x4 tiles, in 32x32 tiles}. Eight flags are tested at once as one 64-bit word.
std::array<uint64_t, 2> idle_in_batches(const std::vector<uint8_t>& flags, int w, int h) {
  constexpr uint64_t took_bits = 0x0101010101010101ull * kTook;
  constexpr uint64_t idle_bits = 0x0101010101010101ull * kIdle;
  const int cols8 = (w + 7) / 8, cols32 = (w + 31) / 32;
  std::vector<uint64_t> idle8(static_cast<size_t>(cols8)), idle32(static_cast<size_t>(cols32));
  std::vector<uint8_t> busy8(static_cast<size_t>(cols8)), busy32(static_cast<size_t>(cols32));
  std::array<uint64_t, 2> total{0, 0};
  for (int y = 0; y < h; ++y) {
    const uint8_t* row = flags.data() + size_t(y) * size_t(w);
    for (int c = 0; c < cols8; ++c) {
      uint64_t v = 0;
      std::memcpy(&v, row + 8 * c, size_t(std::min(8, w - 8 * c)));  // the tail reads 0s
      busy8[size_t(c)] |= (v & took_bits) != 0;
      idle8[size_t(c)] += uint64_t(std::popcount(v & idle_bits));
    }
    const bool band8_end = y % 4 == 3 || y == h - 1;
    if (band8_end)
      for (int c = 0; c < cols8; ++c) {
        if (!busy8[size_t(c)]) total[0] += idle8[size_t(c)];
        busy32[size_t(c / 4)] |= busy8[size_t(c)];
        idle32[size_t(c / 4)] += idle8[size_t(c)];
        busy8[size_t(c)] = 0;
        idle8[size_t(c)] = 0;
      }
    if (y % 32 == 31 || y == h - 1)
      for (int c = 0; c < cols32; ++c) {
        if (!busy32[size_t(c)]) total[1] += idle32[size_t(c)];
        busy32[size_t(c)] = 0;
        idle32[size_t(c)] = 0;
      }
  }
  return total;
}

// End of a stretch of live idle fragments from `from`: the first i < to with wk[i] != 0 or, when
// there is a stencil test, st[i] == 0. Eight bytes at a time, the row's hottest loop.
int stretch_end(const uint8_t* wk, const uint8_t* st, int from, int to) {
  constexpr uint64_t ones = 0x0101010101010101ull, highs = 0x8080808080808080ull;
  int i = from;
  for (; i + 8 <= to; i += 8) {
    uint64_t w = 0, s = ~0ull;
    std::memcpy(&w, wk + i, 8);
    if (st) std::memcpy(&s, st + i, 8);
    if (w != 0 || ((s - ones) & ~s & highs) != 0) break;  // a set work byte or a zero stencil byte
  }
  while (i < to && wk[i] == 0 && (!st || st[i] != 0)) ++i;
  return i;
}

}  // namespace

struct Gpu::Chunk {
  uint64_t launched = 0, shaded = 0, masked = 0, discarded = 0, idle = 0;
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
  const Program::Analysis a = program.analyze();
  Counters c;
  c.program_loads = 1;
  c.program_bytes = uint64_t(a.instructions) * profile_.instruction_bytes;
  stats_.program(program.name(), program.paper_name(), a.instructions).counters += c;
  stats_.totals += c;
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
  Counters c;
  c.queries = 1;
  c.query_readbacks = 1;
  stats_.totals += c;
  if (program_) stats_.program(program_->name(), program_->paper_name(), 0).counters += c;
  if (!stats_.passes.empty()) stats_.passes.back().query_result = int64_t(query_count_);
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
void Gpu::run_rows(const Program& p, const Rect& r, int y0, int y1, uint64_t idle_branches,
                   uint8_t* flags, Chunk& result) const {
  constexpr int W = L::width;
  // Counted in a local and stored once: neighbouring chunks share cache lines, and other
  // threads are counting into them.
  Chunk out;
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

  // Where idle fragments' outputs come from: the passthrough unit's texel at the same place.
  struct CopyPlan {
    const float* src = nullptr;
    float* dst = nullptr;
    int width = 0, ch = 0;
    Format fmt = Format::fp32;
    bool exact = false;  // same format: already rounded, a plain copy
  };
  CopyPlan copies[kMaxOutputs];
  if (work_mask_ && !idle_kill)  // draw() checked that each passthrough is shaped like its target
    for (int o = 0; o < nout; ++o) {
      const Texture& src = *units_[p.passthrough(o)];
      Texture& dst = *targets_[o];
      copies[o] = {src.data().data(), dst.texel_mut(0, 0),
                   dst.width(),       dst.channels(),
                   dst.format(),      src.format() == dst.format() || dst.format() == Format::fp32};
    }
  // k live fragments from (x, y) on that skip the program: their outputs keep their previous
  // values, copied from the passthrough units (or nothing, for a program that discards them).
  // Returns how many are discarded.
  auto idle_run = [&](int x, int y, int k) -> uint64_t {
    const uint64_t n = uint64_t(k);
    if (work_masked_) {
      // Modeled as an early-z/stencil reject: masked, not shaded, never counted.
      out.shaded -= n;
      out.masked += n;
    } else {
      out.idle += idle_branches * n;  // an idle fragment takes none of the program's branches
    }
    if (idle_kill) return work_masked_ ? 0 : n;
    for (int o = 0; o < nout; ++o) {
      const CopyPlan& cp = copies[o];
      const size_t off = (size_t(y) * size_t(cp.width) + size_t(x)) * size_t(cp.ch);
      const size_t count = n * size_t(cp.ch);
      if (cp.exact)
        std::memcpy(cp.dst + off, cp.src + off, count * sizeof(float));
      else  // rounded as the program's own store would be: the source is a wider format
        for (size_t i = 0; i < count; ++i) cp.dst[off + i] = round_to(cp.fmt, cp.src[off + i]);
    }
    return 0;
  };

  for (int y = y0; y < y1; ++y) {
    const uint8_t* st = stencil_test_ ? stencil_test_->row(y) : nullptr;
    const uint8_t* wk = work_mask_ ? work_mask_->row(y) : nullptr;
    uint8_t* sw = stencil_write_ ? stencil_write_->row_mut(y) : nullptr;
    // This row's flags; fragment x sits at fl[x - r.x0].
    uint8_t* fl = flags ? flags + size_t(y - r.y0) * size_t(r.width()) : nullptr;
    for (int x = r.x0, n = 0; x < r.x1; x += n) {
      // A stretch of live idle fragments (the usual case late in a loop) is handled at once,
      // exactly as the per-block path below would (fragments are independent).
      if (wk && wk[x] == 0 && (!st || st[x] != 0)) {
        n = stretch_end(wk, st, x, r.x1) - x;
        out.launched += uint64_t(n);
        out.shaded += uint64_t(n);
        out.discarded += idle_run(x, y, n);
        if (sw) std::memset(sw + x, idle_kill ? 0 : 1, size_t(n));
        if (fl && !work_masked_) std::memset(fl + (x - r.x0), kIdle, size_t(n));
        continue;
      }
      n = std::min(W, r.x1 - x);
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
      // run: live fragments the host actually executes (all of them unless a work mask says idle).
      M run = live;
      if (wk) {
        for (int i = 0; i < n; ++i) bools[i] = wk[x + i] != 0;
        run = run && M(bools, stdx::element_aligned);
      }
      M kill(false);
      if (any(run)) {
        f.reset(iota + float(x) + 0.5f, F(float(y) + 0.5f), run, nout);
        p.run(f);
        kill = f.killed() && run;
        const M write = run && !kill;
        const bool every = all(write);  // W fragments, all in the rectangle, none killed
        for (int o = 0; o < nout; ++o) {
          Texture& t = *targets_[o];
          const Vec4<F>& v = f.output(o);
          v.x.copy_to(lanes_out[0], stdx::element_aligned);
          v.y.copy_to(lanes_out[1], stdx::element_aligned);
          v.z.copy_to(lanes_out[2], stdx::element_aligned);
          v.w.copy_to(lanes_out[3], stdx::element_aligned);
          const int ch = t.channels();
          const Format fmt = t.format();
          float* row = t.texel_mut(x, y);
          if (every && ch == 4 && fmt == Format::fp32) {
            // The common case: W whole fp32x4 texels, interleaved from the four registers.
            texels::join<W>(lanes_out, row);
            continue;
          }
          for (int i = 0; i < n; ++i) {
            if (!write[i]) continue;
            float* dst = row + i * ch;
            for (int c = 0; c < ch; ++c) dst[c] = round_to(fmt, lanes_out[c][i]);
          }
        }
      }
      int nkill = lanes_on(kill);
      if (wk)  // contiguous runs of live fragments the work mask leaves idle
        for (int i = 0; i < n;) {
          if (!live[i] || run[i]) {
            ++i;
            continue;
          }
          int j = i + 1;
          while (j < n && live[j] && !run[j]) ++j;
          nkill += int(idle_run(x + i, y, j - i));
          i = j;
        }
      if (fl) {
        const M idle = f.idle_lanes();
        for (int i = 0; i < n; ++i)
          fl[x - r.x0 + i] = !live[i] ? 0
                             : run[i] ? (idle[i] ? kIdle : kTook)
                                      : (work_masked_ ? 0 : kIdle);
      }
      out.discarded += uint64_t(nkill);
      if (sw)
        for (int i = 0; i < n; ++i)
          if (live[i]) sw[x + i] = (run[i] ? !kill[i] : !idle_kill) ? 1 : 0;
    }
  }
  result = out;
}

void Gpu::parallel_rows(const Rect& r, const std::function<void(int, int, Chunk&)>& body,
                        std::vector<Chunk>& chunks) {
  const int rows = r.height();
  // Enough chunks to balance uneven rows, few enough to keep scheduling cheap.
  const int nchunks = std::max(1, std::min(rows, threads() * 8));
  chunks.assign(size_t(nchunks), Chunk{});
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
  if (workers_.empty() || nchunks == 1 || r.area() < 4096) {
    job();
    return;
  }
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

  in_draw_ = true;
  std::vector<Chunk> chunks;
  const uint64_t idle_branches = uint64_t(a.branches);
  uint8_t* flags = nullptr;
  if (a.branches > 0) {
    batch_flags_.assign(size_t(rect.width()) * size_t(rect.height()), 0);
    flags = batch_flags_.data();
  } else {
    batch_flags_.clear();
  }
  const Format precision = precision_of(p);
  auto body = [&](int ya, int yb, Chunk& c) {
    // Reduced precision runs at width 1 (the scalar reference) or 8.
    if (precision == Format::fp16) {
      if (lanes_ == 1)
        run_rows<RoundedLanes<1, Format::fp16>>(p, rect, ya, yb, idle_branches, flags, c);
      else
        run_rows<RoundedLanes<8, Format::fp16>>(p, rect, ya, yb, idle_branches, flags, c);
      return;
    }
    if (precision == Format::fp24) {
      if (lanes_ == 1)
        run_rows<RoundedLanes<1, Format::fp24>>(p, rect, ya, yb, idle_branches, flags, c);
      else
        run_rows<RoundedLanes<8, Format::fp24>>(p, rect, ya, yb, idle_branches, flags, c);
      return;
    }
    switch (lanes_) {
      case 1:
        run_rows<SimdLanes<1>>(p, rect, ya, yb, idle_branches, flags, c);
        break;
      case 4:
        run_rows<SimdLanes<4>>(p, rect, ya, yb, idle_branches, flags, c);
        break;
      case 8:
        run_rows<SimdLanes<8>>(p, rect, ya, yb, idle_branches, flags, c);
        break;
      default:
        run_rows<SimdLanes<16>>(p, rect, ya, yb, idle_branches, flags, c);
        break;
    }
  };
  parallel_rows(rect, body, chunks);
  in_draw_ = false;

  Chunk sum;
  for (const Chunk& c : chunks) {
    sum.launched += c.launched;
    sum.shaded += c.shaded;
    sum.masked += c.masked;
    sum.discarded += c.discarded;
    sum.idle += c.idle;
  }
  // Static per-fragment costs times shaded fragments: identical at any width and thread count.
  Counters c = pass_counters(a, units_.data(), targets_, sum.launched, sum.shaded, sum.discarded);
  c.fragments_masked = sum.masked;
  c.lanes_idle = sum.idle;
  if (flags) {
    const std::array<uint64_t, 2> batch =
        idle_in_batches(batch_flags_, rect.width(), rect.height());
    c.idle_in_batch32 = batch[0];
    c.idle_in_batch1024 = batch[1];
  }
  // Arithmetic (every counted operation but the fetches) by the precision it ran at.
  const uint64_t alu = c.instructions - c.texture_fetches;
  if (precision == Format::fp24) c.alu_fp24 = alu;
  if (precision == Format::fp16) c.alu_fp16 = alu;
  if (query_active_) query_count_ += sum.shaded - sum.discarded;
  c.host_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  FrameStats::ProgramTotals& totals = stats_.program(pname, p.paper_name(), a.instructions);
  totals.counters += c;
  totals.instructions = a.instructions;
  stats_.totals += c;
  PassRecord rec{pname, rect.width(), rect.height(), c, -1};
  if (stats_.keep_pass_records) {
    stats_.passes.push_back(std::move(rec));
    return stats_.passes.back();
  }
  last_pass_ = std::move(rec);
  return last_pass_;
}

}  // namespace vgpu
