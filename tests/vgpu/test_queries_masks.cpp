// Occlusion queries, the stencil test and write, and the work-mask shortcut: what a pass counts
// and what it skips.
#include <doctest/doctest.h>

#include <array>
#include <cstdint>
#include <string>
#include <utility>

#include "helpers.h"
#include "vgpu/vgpu.h"

using namespace vgpu;
using vgpu_test::fill_pattern;
using vgpu_test::same_bits;

namespace {

// Known pattern: the fragment at pixel (x, y) is discarded where (x + 2y) mod 3 == 0.
bool killed_at(int x, int y) {
  return (x + 2 * y) % 3 == 0;
}

struct KillPattern {
  static constexpr const char* name = "kill pattern";
  static constexpr const char* paper_name = "rayosEnGrilla";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const F k = floor(f.x) + F(2.0f) * floor(f.y);
    const F r = k - F(3.0f) * floor(k / F(3.0f));
    f.discard(r < F(0.5f));
    f.out(0) = {f.x, f.y, F(1.0f), F(1.0f)};
  }
};

uint64_t survivors(int w, int h, const Stencil* test = nullptr) {
  uint64_t n = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (!killed_at(x, y) && (!test || test->get(x, y))) ++n;
  return n;
}

}  // namespace

TEST_CASE("an occlusion query counts exactly the fragments that survive discard") {
  for (int lanes : {1, 8}) {
    CAPTURE(lanes);
    Gpu gpu(profile("gf5700"), 2, lanes);
    Texture out = gpu.make_texture("out", 41, 29, 4);
    KernelProgram<KillPattern> k;
    gpu.use_program(k);
    gpu.set_targets({&out});
    gpu.begin_query();
    const PassRecord& rec = gpu.draw();
    CHECK(rec.counters.fragments_discarded == 41 * 29 - survivors(41, 29));
    CHECK(gpu.end_query() == survivors(41, 29));
    CHECK(gpu.stats().passes.back().query_result == int64_t(survivors(41, 29)));
    // Discarded fragments write nothing.
    CHECK(out.get(0, 0, 2) == 0.0f);
    CHECK(out.get(1, 0, 2) == 1.0f);
    CHECK(out.get(1, 1, 2) == 0.0f);
    // Reading the count back is a synchronisation: counted, in the totals and for the program.
    CHECK(gpu.stats().totals.queries == 1);
    CHECK(gpu.stats().totals.query_readbacks == 1);
    CHECK(gpu.stats().find("kill pattern")->counters.query_readbacks == 1);
  }
}

TEST_CASE("a query spans every pass drawn between begin and end, and only those") {
  Gpu gpu(profile("gf6600"), 1);
  Texture out = gpu.make_texture("out", 20, 10, 4);
  KernelProgram<KillPattern> k;
  gpu.use_program(k);
  gpu.set_targets({&out});
  gpu.draw();  // outside the query
  gpu.begin_query();
  gpu.draw();
  gpu.draw(Rect{0, 0, 20, 5});
  const uint64_t n = gpu.end_query();
  CHECK(n == survivors(20, 10) + survivors(20, 5));
  CHECK(gpu.stats().passes[0].query_result == -1);
  gpu.begin_query();
  CHECK(gpu.end_query() == 0);  // a query around no pass
  CHECK(gpu.stats().totals.queries == 2);
  CHECK(gpu.stats().totals.query_readbacks == 2);
}

TEST_CASE("the stencil test skips fragments before shading and counts them as masked") {
  for (int lanes : {1, 4, 16}) {
    CAPTURE(lanes);
    Gpu gpu(profile("gf5700"), 1, lanes);
    Texture out = gpu.make_texture("out", 37, 11, 4);
    Stencil test(37, 11, 0);
    for (int y = 0; y < 11; ++y)
      for (int x = 0; x < 37; ++x) test.set(x, y, (x / 3 + y) % 2);
    KernelProgram<KillPattern> k;
    gpu.use_program(k);
    gpu.set_targets({&out});
    gpu.set_stencil_test(&test);
    gpu.begin_query();
    const Counters c = gpu.draw().counters;
    CHECK(gpu.end_query() == survivors(37, 11, &test));
    CHECK(c.fragments_launched == 37 * 11);
    CHECK(c.fragments_masked == 37 * 11 - test.count());
    CHECK(c.fragments_shaded == test.count());
    CHECK(c.fragments_discarded == test.count() - survivors(37, 11, &test));
    CHECK(c.instructions == test.count() * uint64_t(k.analyze().instructions));
    CHECK(c.bytes_written == survivors(37, 11, &test) * 16);
    for (int y = 0; y < 11; ++y)
      for (int x = 0; x < 37; ++x) {
        CAPTURE(x);
        CAPTURE(y);
        CHECK(out.get(x, y, 3) == (test.get(x, y) && !killed_at(x, y) ? 1.0f : 0.0f));
      }
  }
}

TEST_CASE("the stencil write records which shaded fragments survived") {
  Gpu gpu(profile("gf6600"), 3, 8);
  Texture out = gpu.make_texture("out", 90, 70, 4);
  KernelProgram<KillPattern> k;
  gpu.use_program(k);
  gpu.set_targets({&out});
  Stencil test(90, 70, 1), written(90, 70, 7);
  for (int x = 0; x < 90; ++x) test.set(x, 3, 0);  // row 3 masked
  gpu.set_stencil_test(&test);
  gpu.set_stencil_write(&written);
  gpu.draw();
  for (int y = 0; y < 70; ++y)
    for (int x = 0; x < 90; ++x) {
      const uint8_t want = y == 3 ? 7 : killed_at(x, y) ? 0 : 1;  // masked: left untouched
      if (written.get(x, y) != want) {
        FAIL_CHECK("stencil at (" << x << ", " << y << ") is " << int(written.get(x, y)));
        return;
      }
    }
  // Testing and writing one stencil narrows the mask pass after pass, as the ray tracer does.
  gpu.set_stencil_test(&written);
  gpu.begin_query();
  // Survivors of the first pass stay live, killed ones are masked; row 3 (7) was never written.
  const Counters c = gpu.draw().counters;
  CHECK(c.fragments_shaded == survivors(90, 70) - survivors(90, 4) + survivors(90, 3) + 90);
  CHECK(gpu.end_query() == survivors(90, 70));
  CHECK(written.count() == survivors(90, 70));
}

namespace {

// One step of a walk: active fragments (w > 0) move and count w down; finished ones pass their
// state through unchanged, which is what lets the host mark them idle.
struct Step {
  static constexpr const char* name = "step";
  static constexpr const char* paper_name = "traversal";
  static constexpr int outputs = 1;
  static constexpr std::array<int, 1> passthrough{0};
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> s = f.fetch_own(0);
    const Vec4<F> g = f.fetch_own(1);
    const auto active = s.w > F(0.0f);
    Vec4<F> o = s;
    if (f.branch(active)) {
      o.x = select(active, s.x + g.x * F(0.5f), s.x);
      o.y = select(active, s.y * g.y - g.z, s.y);
      o.z = select(active, min(s.z, g.w), s.z);
      o.w = select(active, s.w - F(1.0f), s.w);
    }
    f.out(0) = o;
  }
};

// The same step, but finished fragments are discarded (they leave the query's count).
struct StepOrKill {
  static constexpr const char* name = "step or kill";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  static constexpr bool idle_discards = true;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> s = f.fetch_own(0);
    const auto active = s.w > F(0.0f);
    f.discard(!active);
    f.out(0) = {s.x + F(1.0f), s.y, s.z, s.w - F(1.0f)};
  }
};

struct Walk {
  Texture state;
  Stencil written;
  Counters totals;
  uint64_t last_query = 0;
};

// Three ping-pong passes of K over a 75x61 state, with or without the work mask.
template <class K>
Walk walk(const std::string& prof, int threads, int lanes, bool work_mask,
          Format target_format = Format::fp32, bool stencil_test = true) {
  Gpu gpu(profile(prof), threads, lanes);
  Texture a = gpu.make_texture("a", 75, 61, 4), b = gpu.make_texture("b", 75, 61, 4, target_format);
  Texture g = gpu.make_texture("g", 75, 61, 4);
  fill_pattern(a, 11);
  fill_pattern(g, 12);
  // w: 3, 2, 1, 0 or -1 steps left (NaN and the other specials in w count as finished).
  uint64_t seed = 13;
  for (int y = 0; y < 61; ++y)
    for (int x = 0; x < 75; ++x)
      if (vgpu_test::mix(seed) % 7 != 0) a.set(x, y, 3, float(int(vgpu_test::mix(seed) % 5) - 1));
  Stencil test(75, 61, 1), work(75, 61), written(75, 61, 5);
  for (int x = 0; x < 75; ++x) test.set(x, 7, 0);
  KernelProgram<K> k;
  gpu.use_program(k);
  gpu.bind_texture(1, g);
  if (stencil_test) gpu.set_stencil_test(&test);
  gpu.set_stencil_write(&written);
  Walk r;
  Texture* src = &a;
  Texture* dst = &b;
  for (int pass = 0; pass < 3; ++pass) {
    for (int y = 0; y < 61; ++y)
      for (int x = 0; x < 75; ++x) work.set(x, y, src->get(x, y, 3) > 0.0f);
    gpu.set_work_mask(work_mask ? &work : nullptr);
    gpu.bind_texture(0, *src);
    gpu.set_targets({dst});
    gpu.begin_query();
    gpu.draw();
    r.last_query = gpu.end_query();
    std::swap(src, dst);
  }
  r.state = *src;
  r.written = written;
  r.totals = gpu.stats().totals;
  return r;
}

// A walk with a host shortcut against the walk that shaded every fragment: same bits, counts.
void check_same_walk(const Walk& fast, const Walk& full) {
  CHECK(same_bits(fast.state, full.state));
  CHECK(same_bits(fast.written, full.written));
  CHECK(fast.last_query == full.last_query);
  CHECK(fast.totals.same_counts(full.totals));
}

}  // namespace

TEST_CASE("the work-mask shortcut gives the same images and counters as shading every fragment") {
  for (const char* prof : {"gf5700", "gf6600"})
    for (int lanes : {1, 8})
      for (int threads : {1, 3}) {
        CAPTURE(prof);
        CAPTURE(lanes);
        CAPTURE(threads);
        const Walk full = walk<Step>(prof, threads, lanes, false);
        const Walk fast = walk<Step>(prof, threads, lanes, true);
        CHECK(full.totals.lanes_idle > 0);
        check_same_walk(fast, full);
      }
}

TEST_CASE("the work-mask shortcut discards idle fragments of a program that discards them") {
  for (int lanes : {1, 16}) {
    CAPTURE(lanes);
    const Walk full = walk<StepOrKill>("gf6600", 2, lanes, false);
    const Walk fast = walk<StepOrKill>("gf6600", 2, lanes, true);
    CHECK(full.totals.fragments_discarded > 0);
    CHECK(fast.last_query == full.last_query);
    CHECK(same_bits(fast.written, full.written));
    CHECK(same_bits(fast.state, full.state));
    CHECK(fast.totals.same_counts(full.totals));
  }
}

TEST_CASE("passthrough copies round to the render target's format, as the program's stores do") {
  // fp32 state a, fp16 state b: the first pass stores into fp16.
  for (int lanes : {1, 8}) {
    CAPTURE(lanes);
    const Walk full = walk<Step>("gf6600", 1, lanes, false, Format::fp16);
    const Walk fast = walk<Step>("gf6600", 1, lanes, true, Format::fp16);
    CHECK(same_bits(fast.state, full.state));
    CHECK(fast.totals.same_counts(full.totals));
  }
}

TEST_CASE("without a stencil test, stretches of idle fragments give the same images and counters") {
  // The emulator copies whole idle stretches of a row at once when no stencil test is bound.
  for (Format target : {Format::fp32, Format::fp16})
    for (int lanes : {1, 8, 16})
      for (int threads : {1, 3}) {
        CAPTURE(lanes);
        CAPTURE(threads);
        const Walk full = walk<Step>("gf5700", threads, lanes, false, target, false);
        const Walk fast = walk<Step>("gf5700", threads, lanes, true, target, false);
        CHECK(full.totals.lanes_idle > 0);
        CHECK(same_bits(fast.state, full.state));
        CHECK(same_bits(fast.written, full.written));
        CHECK(fast.last_query == full.last_query);
        CHECK(fast.totals.same_counts(full.totals));
        const Walk kfull = walk<StepOrKill>("gf6600", threads, lanes, false, target, false);
        const Walk kfast = walk<StepOrKill>("gf6600", threads, lanes, true, target, false);
        CHECK(kfull.totals.fragments_discarded > 0);
        CHECK(same_bits(kfast.state, kfull.state));
        CHECK(same_bits(kfast.written, kfull.written));
        CHECK(kfast.last_query == kfull.last_query);
        CHECK(kfast.totals.same_counts(kfull.totals));
      }
}

namespace {

enum class MaskSource { none, gpu, host };

// The stream tracer's loop in small: a query pass (StepOrKill keeps the fragments whose walk is
// not finished, as rayosEnGrilla keeps the rays still walking) writes the mask it tests (the Gpu
// then knows the mask's non-zero pixels and the next pass visits only those), a step pass runs
// under it.
// MaskSource::host rewrites the mask from the host before each step (the Gpu must scan it);
// none runs every fragment.
Walk query_walk(int threads, int lanes, MaskSource source) {
  Gpu gpu(profile("gf6600"), threads, lanes);
  Texture a = gpu.make_texture("a", 75, 61, 4), b = gpu.make_texture("b", 75, 61, 4);
  Texture g = gpu.make_texture("g", 75, 61, 4), counter = gpu.make_texture("c", 75, 61, 1);
  fill_pattern(a, 21);
  fill_pattern(g, 22);
  uint64_t seed = 23;
  for (int y = 0; y < 61; ++y)
    for (int x = 0; x < 75; ++x) a.set(x, y, 3, float(int(vgpu_test::mix(seed) % 6) - 1));
  KernelProgram<StepOrKill> active;
  KernelProgram<Step> step;
  Stencil mask(75, 61, 1);
  Walk r;
  Texture* src = &a;
  Texture* dst = &b;
  for (int pass = 0; pass < 5; ++pass) {
    gpu.use_program(active);
    gpu.bind_texture(0, *src);
    gpu.set_targets({&counter});
    gpu.set_work_mask(source == MaskSource::none || pass == 0 ? nullptr : &mask);
    gpu.set_stencil_write(&mask);
    gpu.begin_query();
    gpu.draw();
    r.last_query += gpu.end_query();
    gpu.set_stencil_write(nullptr);
    if (source == MaskSource::host)
      for (int y = 0; y < 61; ++y)
        for (int x = 0; x < 75; ++x) mask.set(x, y, mask.get(x, y));
    gpu.use_program(step);
    gpu.bind_texture(0, *src);
    gpu.bind_texture(1, g);
    gpu.set_targets({dst});
    gpu.set_work_mask(source == MaskSource::none ? nullptr : &mask);
    gpu.draw();
    gpu.unbind_textures();
    std::swap(src, dst);
  }
  return {*src, mask, gpu.stats().totals, r.last_query};
}

}  // namespace

TEST_CASE("passes under a mask the Gpu wrote visit its listed fragments with the same results") {
  for (int lanes : {1, 4, 8, 16})
    for (int threads : {1, 3}) {
      CAPTURE(lanes);
      CAPTURE(threads);
      const Walk full = query_walk(threads, lanes, MaskSource::none);
      const Walk listed = query_walk(threads, lanes, MaskSource::gpu);
      const Walk scanned = query_walk(threads, lanes, MaskSource::host);
      CHECK(full.totals.lanes_idle > 0);
      CHECK(full.last_query > 0);
      check_same_walk(listed, full);
      check_same_walk(scanned, full);
    }
}
