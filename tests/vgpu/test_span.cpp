// The longest wait of one lane through a loop iteration (vgpu/span.h): in-order issue of the
// recorded body, fetches and operations counted along the schedule's end, and the counters a
// looping pass gets from it (the most iterations one fragment ran, times that chain); and the
// arithmetic between two fetches of an iteration (loop_dependent_operations).
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

// Two paths an iteration that meet at the end: one fetch (from the carried coordinate), and
// twenty dependent additions; their sum is selected and the loop's mask follows.
struct FetchOrTwenty {
  static constexpr const char* name = "fetch or twenty";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    const Vec4<F> s = f.fetch_own(0);
    F u = s.x;
    f.loop(8, s.w > F(0.0f), [&](const M& act) {
      const F a = f.fetch(0, u, F(0.5f)).x;
      F z = u;
      for (int i = 0; i < 20; ++i) z = z + F(1.0f);
      u = select(act, a + z, u);
      return act;
    });
    f.out(0) = {u, u, u, u};
  }
};

// One iteration: a fetch at u + 1 (an address from no fetch), two operations on its texel that
// make the next fetch's address, that fetch, and two operations after it that feed no fetch.
// through_select: the address is select(a > 0, a * 2 + 1, u) instead, a fetch made on one side.
struct ChaseAddress {
  static constexpr const char* name = "chase address";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  bool through_select = false;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    const Vec4<F> s = f.fetch_own(0);
    F u = s.x;
    f.loop(4, s.w > F(0.0f), [&](const M& act) {
      const F a = f.fetch(1, u + F(1.0f), F(0.5f)).x;
      const F next =
          through_select ? select(a > F(0.0f), a * F(2.0f) + F(1.0f), u) : a * F(2.0f) + F(1.0f);
      const F b = f.fetch(1, next, F(0.5f)).x;
      u = select(act, b + F(3.0f), u);
      return act;
    });
    f.out(0) = {u, u, u, u};
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

TEST_CASE(
    "the weight of a fetch decides which of two paths is the longest: one fetch against twenty "
    "additions, the winner flips past a weight of 21") {
  // Issue in order from time 0, one unit each: the fetch issues at 1 and is ready at 1 + W; the
  // first addition issues at 2 (after the fetch), each next one when its operand is ready, the
  // twentieth ready at 22. The sum issues at max(22, 1 + W); it, the select and the mask are one
  // unit each. W > 21: the end waits for the fetch, 1 fetch and 4 units (its issue, the sum,
  // the select, the mask). W < 21: it waits for the additions, no fetch and 25 units.
  KernelProgram<FetchOrTwenty> p;
  const Recording r = p.record();
  for (const int w : {22, 50, 100}) {
    CAPTURE(w);
    const LoopChain c = loop_chain(r, w);
    CHECK(c.fetches == 1);
    CHECK(c.operations == 4);
  }
  for (const int w : {1, 10, 20}) {
    CAPTURE(w);
    const LoopChain c = loop_chain(r, w);
    CHECK(c.fetches == 0);
    CHECK(c.operations == 25);
  }
}

TEST_CASE("a looping pass with a fetch on its longest path counts a fetch per iteration") {
  // FetchOrTwenty at the default weight (100): 1 fetch and 4 units an iteration; every lane with
  // w > 0 runs all 8 iterations (its body keeps the mask), the lanes with w = 0 none.
  Texture in("start", 16, 1, 4);
  for (int x = 0; x < 16; ++x) in.set(x, 0, 3, x % 4 == 1 ? 1.0f : 0.0f);
  KernelProgram<FetchOrTwenty> p;
  const Program::Analysis a = p.analyze();
  CHECK(a.loop.chain_fetches == 1);
  CHECK(a.loop.chain_operations == 4);
  for (int lanes : {1, 8}) {
    CAPTURE(lanes);
    Gpu gpu(profile("rtx4090"), 1, lanes);
    Texture out("out", 16, 1, 4);
    gpu.use_program(p);
    gpu.bind_texture(0, in);
    gpu.set_targets({&out});
    const PassRecord rec = gpu.draw();
    CHECK(rec.counters.loop_span_iterations == 8);
    CHECK(rec.counters.loop_span_fetches == 8);
    CHECK(rec.counters.loop_span_operations == 8 * 4);
    // Every iteration of the 4 running lanes fetched its texel: 32 fetches in the loop, and
    // one fetch_own per fragment before it.
    CHECK(rec.counters.texture_fetches == 16 + 4 * 8);
  }
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

TEST_CASE("the arithmetic between two fetches of an iteration is counted once per iteration") {
  // ChaseAddress: u + 1 feeds a fetch but waits on none; a * 2 + 1 waits on the first fetch and
  // feeds the second (2 operations); b + 3 and the select wait on a fetch and feed none.
  KernelProgram<ChaseAddress> p;
  CHECK(loop_dependent_operations(p.record()) == 2);
  CHECK(p.analyze().loop.dependent_operations == 2);
  // TwoFetches: the second fetch's address is the first's texel itself, no operation between.
  CHECK(loop_dependent_operations(KernelProgram<TwoFetches>(TwoFetches{true}).record()) == 0);
  CHECK(loop_dependent_operations(KernelProgram<NoLoop>().record()) == 0);
  // Through a select, the fetch is made on the select's side alone: the compare (its mask) and
  // the select wait and feed it; a * 2 + 1, only through the select's value, is not counted.
  CHECK(loop_dependent_operations(KernelProgram<ChaseAddress>(ChaseAddress{true}).record()) == 2);
  // Lanes with w > 0 run all 4 iterations (the body keeps the mask): 3 of 8 fragments.
  Texture start("start", 8, 1, 4), table("table", 16, 1, 4);
  for (int x = 0; x < 8; ++x) start.set(x, 0, 3, x % 3 == 0 ? 1.0f : 0.0f);
  for (int lanes : {1, 8})
    for (int threads : {1, 3}) {
      CAPTURE(lanes);
      CAPTURE(threads);
      Gpu gpu(profile("rtx4090"), threads, lanes);
      Texture out("out", 8, 1, 4);
      gpu.use_program(p);
      gpu.bind_texture(0, start);
      gpu.bind_texture(1, table);
      gpu.set_targets({&out});
      const Counters c = gpu.draw().counters;
      CHECK(c.loop_iterations == 3 * 4);
      CHECK(c.loop_dependent_instructions == 3 * 4 * 2);
    }
}
