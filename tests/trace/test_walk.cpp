// The walk machinery of host/trace/walks/walk.h on a walk that is not the grid's: a toy pass
// sequence (count each pixel's counter down to zero, one step per pass, steered by a query) with
// its own sites gets batch walks and their replay from run_walk, with the textures, query counts
// and statistics of the same walk run pass by pass.
#include <doctest/doctest.h>

#include <cstring>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "host/report/counters_json.h"
#include "host/trace/walks/walk.h"
#include "kernels/common.h"
#include "tests/support/stats_json.h"

namespace {

using vgpu::Stencil;
using vgpu::Texture;

// Steps each busy pixel's counter (x) down by one; y counts the steps taken. A finished pixel
// keeps its texel (passthrough), as the grid walk's kernels do.
struct CountDown {
  static constexpr const char* name = "count down";
  static constexpr const char* paper_name = "cuentaRegresiva (test)";
  static constexpr int outputs = 1;
  static constexpr std::array<const char*, 1> units{"counter"};
  static constexpr std::array<int, 1> passthrough{0};
  template <class L>
  void operator()(kernels::Fragments<L>& f) const {
    using F = typename L::F;
    const kernels::Vec4<F> c = f.fetch_own(0);
    const auto busy = c.x > F(0.0f);
    kernels::Vec4<F> next = c;
    if (f.branch(busy))
      next = kernels::select(busy, kernels::Vec4<F>{c.x - F(1.0f), c.y + F(1.0f), c.z, c.w}, c);
    f.out(0) = next;
  }
};

// Discards the pixels whose counter reached zero, so a query counts the busy ones.
struct StillCounting {
  static constexpr const char* name = "still counting";
  static constexpr const char* paper_name = "contando (test)";
  static constexpr int outputs = 1;
  static constexpr bool idle_discards = true;
  static constexpr std::array<const char*, 1> units{"counter"};
  template <class L>
  void operator()(kernels::Fragments<L>& f) const {
    using F = typename L::F;
    const kernels::Vec4<F> c = f.fetch_own(0);
    f.discard(c.x <= F(0.0f));
    f.out(0) = {F(1.0f), F(0.0f), F(0.0f), F(0.0f)};
  }
};

// The toy walk: two sites of its own, one ping-pong pair, one mask.
struct CountdownWalk {
  enum Site : int { kStart, kStep, kBusy };
  Texture counter[2];
  Stencil busy;
  vgpu::KernelProgram<CountDown> step;
  vgpu::KernelProgram<StillCounting> still;
  int steps_seen = 0;

  struct Cursor {
    int cur;
  };
  template <class X>
  void walk(X& x, Cursor& c) {
    auto key = [&c](int s, Site site) { return host::walk::PassKey{s, -1, site, uint8_t(c.cur)}; };
    x.fill(busy, 1);
    auto n = x.count(key(-1, kStart), still, counter[c.cur], nullptr, &busy);
    x.traced(n);
    for (int s = 0; X::any(n); ++s) {
      x.pass(key(s, kStep), step, {&counter[c.cur]}, {&counter[c.cur ^ 1]}, &busy);
      c.cur ^= 1;
      n = x.count(key(s, kBusy), still, counter[c.cur], &busy, &busy);
    }
  }
  host::WriteBack write_back(const Cursor& c) const {
    host::WriteBack wb;
    wb.npairs = 1;
    wb.pairs[0] = {const_cast<Texture*>(&counter[0]), const_cast<Texture*>(&counter[1])};
    wb.current[0] = c.cur;
    wb.nmasks = 1;
    wb.masks[0] = const_cast<Stencil*>(&busy);
    return wb;
  }
};

struct Run {
  Texture result;
  host::WalkCounts counts;
  std::string stats;  // the frame's statistics JSON without wall-clock fields
};

// 37x21 pixels (partial batches and tiles), counters from 0 to 12 in a pattern no tile repeats.
Run run_countdown(bool batches, int threads, bool masks) {
  host::RenderOptions opt;
  opt.width = 37;
  opt.height = 21;
  opt.batch_walk = batches;
  opt.masks = masks;
  vgpu::Gpu gpu(vgpu::profile("gf6600"), threads, vgpu::kBatchWidth);
  CountdownWalk w;
  for (int i = 0; i < 2; ++i)
    w.counter[i] = gpu.make_texture(i ? "counter B" : "counter A", opt.width, opt.height, 4);
  for (int y = 0; y < opt.height; ++y)
    for (int x = 0; x < opt.width; ++x)
      w.counter[0].texel_mut(x, y)[0] = float((x * 7 + y * 3) % 13);
  w.busy = Stencil(opt.width, opt.height, 1);
  Texture target = gpu.make_texture("query target", opt.width, opt.height, 1);
  host::PassRunner r(gpu, opt, target);
  CountdownWalk::Cursor c{0};
  host::walk::run_walk(r, w, c);
  return {w.counter[c.cur], r.counts,
          test_support::without_times(host::frame_counters_json(gpu.stats())).dump()};
}

}  // namespace

TEST_CASE("a walk of its own runs in batches with the textures and statistics of pass by pass") {
  for (const bool masks : {false, true}) {
    CAPTURE(masks);
    const Run passes = run_countdown(false, 1, masks);
    CHECK_FALSE(passes.counts.batch_walk);
    // Known answer: every counter reached 0 after exactly its starting value in steps; the
    // longest counter (12) took 12 steps, so the walk drew 12 step passes and 13 queries.
    for (int y = 0; y < 21; ++y)
      for (int x = 0; x < 37; ++x) {
        const float* t = passes.result.texel(x, y);
        REQUIRE(t[0] == 0.0f);
        REQUIRE(t[1] == float((x * 7 + y * 3) % 13));
      }
    CHECK(passes.counts.rays_traced == uint64_t(37 * 21 - 61));  // 61 pixels start at 0
    CHECK(passes.stats.find("\"passes\":25") != std::string::npos);
    for (const int threads : {1, 2}) {
      CAPTURE(threads);
      const Run b = run_countdown(true, threads, masks);
      CHECK(b.counts.batch_walk);
      CHECK(b.counts.rays_traced == passes.counts.rays_traced);
      CHECK(std::memcmp(b.result.data().data(), passes.result.data().data(),
                        passes.result.data().size() * sizeof(float)) == 0);
      CHECK(b.stats == passes.stats);
    }
  }
}
