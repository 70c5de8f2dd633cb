// The longest wait of one lane through a loop iteration (vgpu/span.h): in-order issue of the
// recorded body, fetches and operations counted along the schedule's end, and the counters a
// looping pass gets from it (the most iterations one fragment ran, times that chain).
#include <doctest/doctest.h>

#include "helpers.h"
#include "vgpu/span.h"
#include "vgpu/vgpu.h"

using namespace vgpu;

namespace {

// Two fetches an iteration: the second at the first's texel (dependent) or beside it.
struct TwoFetches {
  static constexpr const char* name = "two fetches";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  bool dependent = true;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    const Vec4<F> s = f.fetch_own(0);
    F u = s.x;
    f.loop(8, s.w > F(0.0f), [&](const M& act) {
      const F a = f.fetch(0, u, F(0.5f)).x;
      const F b = dependent ? f.fetch(0, a, F(0.5f)).x : f.fetch(0, u + F(1.0f), F(0.5f)).x;
      u = select(act, a + b, u);
      return act;
    });
    f.out(0) = {u, u, u, u};
  }
};

// Ten dependent additions an iteration, no fetch.
struct AddChain {
  static constexpr const char* name = "add chain";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    F y = f.x;
    f.loop(8, f.live(), [&](const M& act) {
      F z = y;
      for (int i = 0; i < 10; ++i) z = z + F(1.0f);
      y = select(act, z, y);
      return act;
    });
    f.out(0) = {y, y, y, y};
  }
};

struct NoLoop {
  static constexpr const char* name = "no loop";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(Fragments<L>& f) const {
    f.out(0) = f.fetch_own(0);
  }
};

}  // namespace

TEST_CASE("a fetch that waits for another fetch's texel counts both latencies") {
  KernelProgram<TwoFetches> p(TwoFetches{true});
  const LoopChain c = loop_chain(p.record());
  // fetch, fetch at its texel, add, select, the loop's mask: two latencies, four units.
  CHECK(c.fetches == 2);
  CHECK(c.operations == 4);
}

TEST_CASE("two fetches that do not wait for each other count one latency") {
  KernelProgram<TwoFetches> p(TwoFetches{false});
  const LoopChain c = loop_chain(p.record());
  // fetch, add, fetch (issued while the first is in flight), add, select, mask.
  CHECK(c.fetches == 1);
  CHECK(c.operations == 6);
}

TEST_CASE("a chain of additions counts one unit each, and the select and mask after it") {
  KernelProgram<AddChain> p;
  const LoopChain c = loop_chain(p.record());
  CHECK(c.fetches == 0);
  CHECK(c.operations == 10 + 1 + 1 + 1);  // issue of the first, ten results, select, mask
}

TEST_CASE("the weight of a fetch decides which path is the longest") {
  // Dependent fetches: 2 x 100 + 4 units. At a weight of 1 the fetches are ordinary operations
  // and the split changes with the schedule, but the total stays the schedule's length.
  KernelProgram<TwoFetches> p(TwoFetches{true});
  const LoopChain heavy = loop_chain(p.record(), 100);
  const LoopChain light = loop_chain(p.record(), 1);
  CHECK(heavy.fetches * 100 + heavy.operations == 204);
  CHECK(light.fetches + light.operations == 6);
}

TEST_CASE("a program without a loop has no chain, and analyze fills it for one with a loop") {
  KernelProgram<NoLoop> none;
  const LoopChain c = loop_chain(none.record());
  CHECK(c.fetches == 0);
  CHECK(c.operations == 0);
  CHECK(none.analyze().loop.chain_operations == 0);
  KernelProgram<TwoFetches> two(TwoFetches{true});
  const Program::Analysis a = two.analyze();
  CHECK(a.loop.chain_fetches == 2);
  CHECK(a.loop.chain_operations == 4);
}

TEST_CASE("a looping pass counts its longest lane's iterations and their chain, per pass") {
  // rtx4090: 8x4 batches. Tile 0 holds lanes needing 1, 3 and 7 iterations, tile 1 lanes
  // needing 2: the longest lane of the pass ran 7, whatever the batches and the host's lanes.
  Texture in("needed", 16, 1, 4);
  const float need[16] = {1, 3, 7, 0, 0, 0, 0, 0, 2, 2, 2, 2, 2, 2, 2, 2};
  for (int x = 0; x < 16; ++x) in.set(x, 0, 0, need[x]);
  KernelProgram<vgpu_test::CountTo> p;
  const Program::Analysis a = p.analyze();
  CHECK(a.loop.chain_fetches == 0);
  CHECK(a.loop.chain_operations == 5);  // add, select, compare, mask after the first issue
  for (int lanes : {1, 8})
    for (int threads : {1, 3}) {
      CAPTURE(lanes);
      CAPTURE(threads);
      Gpu gpu(profile("rtx4090"), threads, lanes);
      Texture out("out", 16, 1, 4);
      gpu.use_program(p);
      gpu.bind_texture(0, in);
      gpu.set_targets({&out});
      const PassRecord r = gpu.draw();
      CHECK(r.counters.loop_span_iterations == 7);
      CHECK(r.counters.loop_span_fetches == 0);
      CHECK(r.counters.loop_span_operations == 7 * 5);
      gpu.draw();  // a second pass adds its own longest lane
      CHECK(gpu.stats().totals.loop_span_iterations == 14);
    }
}
