// A pass's counters: the batch counters (idle lanes in 8x4 and 32x32 tiles, loop batches), the
// statistics settle() makes of them, and replay() of a pass a batch walk ran already.
#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <vector>

#include "vgpu/gpu.h"
#include "vgpu/gpu_internal.h"

namespace vgpu {
namespace gpu_detail {

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
  std::array<uint64_t, 2> total{idle_flags, idle_flags};
  // One band of 32 rows at a time (the list is in row order: the passes list their survivors
  // row by row), its 8x4 and 32x32 tiles' {listed, took} counted, settled and cleared before the
  // next band: a pass costs its list and the bands it touches, not a scan of every tile of the
  // target (at 1024x1024 a walk's late passes list a few hundred rays and were paid 32k tiles
  // each, serially). A tile where no fragment took the branch keeps its idle ones counted.
  thread_local std::vector<std::array<uint32_t, 2>> t8, t32;
  t8.assign(size_t(cols8) * 8, {0, 0});
  t32.assign(size_t(cols32), {0, 0});
  auto settle = [&](int band) {
    for (int r = 0; r < 8 && band * 8 + r < rows4; ++r)
      for (int c = 0; c < cols8; ++c) {
        std::array<uint32_t, 2>& e = t8[size_t(r) * size_t(cols8) + size_t(c)];
        if (e[1] != 0) {
          const uint64_t area =
              uint64_t(std::min(8, w - c * 8)) * uint64_t(std::min(4, h - (band * 8 + r) * 4));
          total[0] -= (work_masked ? e[0] : area) - e[1];
        }
        e = {0, 0};
      }
    for (int c = 0; c < cols32; ++c) {
      std::array<uint32_t, 2>& e = t32[size_t(c)];
      if (e[1] != 0) {
        const uint64_t area =
            uint64_t(std::min(32, w - c * 32)) * uint64_t(std::min(32, h - band * 32));
        total[1] -= (work_masked ? e[0] : area) - e[1];
      }
      e = {0, 0};
    }
  };
  // The counts do not depend on the order: a list out of row order (none is today) is counted
  // from a sorted copy.
  std::vector<uint32_t> sorted;
  const std::vector<uint32_t>* in = &listed;
  if (!std::is_sorted(listed.begin(), listed.end())) {
    sorted = listed;
    std::sort(sorted.begin(), sorted.end());
    in = &sorted;
  }
  int band = -1;
  for (const uint32_t i : *in) {
    const int y = int(i / uint32_t(w)), x = int(i % uint32_t(w));
    if (y / 32 != band) {
      if (band >= 0) settle(band);
      band = y / 32;
    }
    const uint32_t took = flags[i] == kTook ? 1 : 0;
    std::array<uint32_t, 2>& a = t8[size_t(y / 4 - band * 8) * size_t(cols8) + size_t(x / 8)];
    std::array<uint32_t, 2>& b = t32[size_t(x / 32)];
    ++a[0], ++b[0];
    a[1] += took, b[1] += took;
  }
  if (band >= 0) settle(band);
  return total;
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
      n.most = std::max(n.most, uint64_t(most));
      uint64_t out = exactly[0];  // fragments out of the loop before iteration j + 1
      for (uint32_t j = 0; j < most; ++j) {
        active[j] += lanes - out;
        idle[j] += out;
        out += exactly[j + 1];
      }
    }
  return n;
}

}  // namespace gpu_detail

// A pass that a batch walk ran already (Gpu::replay_next): nothing runs, and the statistics
// come out as the fragment processor's would. The walk ran the fragments of the work mask
// (every fragment without one); the others are idle, settled as run_rows's listed path settles
// them; the tally's tile sums give the batch counters as idle_in_batches_listed does.
const PassRecord& Gpu::replay(const Program& p, const Program::Analysis& a, const Rect& rect,
                              const PassTally& t, std::chrono::steady_clock::time_point t0) {
  const Texture& target = *targets_[0];
  if (stencil_test_ || rect.x0 != 0 || rect.y0 != 0 || rect.x1 != target.width() ||
      rect.y1 > target.height() || a.loop.loops > 0)
    fail("program '" + std::string(p.name()) +
         "': a replayed pass must cover whole rows from the top of the target, without stencil "
         "test or loop");
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
  if (stop_when_ && stop_when_(stats_.totals))
    throw BudgetError("the frame stopped after " + std::to_string(stats_.totals.passes) +
                      " passes: over its budget");
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
