// The fragment processor: SIMD widths against the scalar reference, thread counts against one
// thread, window positions, divergence in f.branch(), and the counting run.
#include <doctest/doctest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "helpers.h"
#include "vgpu/vgpu.h"

using namespace vgpu;
using vgpu_test::fill_pattern;
using vgpu_test::same_bits;

namespace {

// Arithmetic, min/max, sqrt/floor/rsqrt, selects, a divergent branch holding a fetch, a dependent
// (clamped) fetch and a data-dependent discard: every path the fragment processor has.
struct Mixed {
  static constexpr const char* name = "mixed";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  float scale = 40.0f;  // uniform
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> a = f.fetch_own(0);
    const Vec4<F> b = f.fetch_own(1);
    const Vec4<F> c = f.fetch(2, a.x * F(scale) + f.x, b.y * F(scale));
    const F s = a.x * b.x - a.y / (abs(b.z) + F(0.25f));
    const F m = min(a.z, b.w) + max(c.x, a.w) - min(b.x, a.x) * max(a.y, c.y);
    const F r = sqrt(abs(s)) + floor(c.y * F(3.0f));
    const auto hit = s > F(0.0f) || c.z == F(0.0f);
    Vec4<F> o{s, m, r, c.w};
    if (f.branch(hit)) {
      const F t = rsqrt(abs(m) + F(1.0f)) * c.x;
      const Vec4<F> d = f.fetch(0, f.y, f.x);
      o.x = select(hit, t + d.y, o.x);
      o.w = select(hit, o.w - d.z, o.w);
    }
    f.discard(c.x < F(-0.5f) && !(a.w > F(0.9f)));
    f.out(0) = o;
  }
};

struct Run {
  Texture out;
  Stencil written;
  Counters counters;
};

// One pass of Mixed over a 131x37 target (rows of 131: a partial batch at every width).
Run run_mixed(const std::string& prof, int threads, int lanes, const Rect* rect,
              bool stencil_test) {
  Gpu gpu(profile(prof), threads, lanes);
  Texture a = gpu.make_texture("a", 131, 37, 4);
  Texture b = gpu.make_texture("b", 131, 37, 4, Format::fp16);
  Texture c = gpu.make_texture("c", 23, 17, 3, Format::fp24);
  fill_pattern(a, 1);
  fill_pattern(b, 2);
  fill_pattern(c, 3);
  Run r{gpu.make_texture("out", 131, 37, 4), Stencil(131, 37, 9), {}};
  fill_pattern(r.out, 4);  // discarded and masked fragments keep these values
  Stencil test(131, 37, 1);
  for (int y = 0; y < 37; ++y)
    for (int x = 0; x < 131; ++x) test.set(x, y, (x * 7 + y * 3) % 5 != 0);
  KernelProgram<Mixed> mixed;
  gpu.use_program(mixed);
  gpu.bind_texture(0, a);
  gpu.bind_texture(1, b);
  gpu.bind_texture(2, c);
  gpu.set_targets({&r.out});
  if (stencil_test) gpu.set_stencil_test(&test);
  gpu.set_stencil_write(&r.written);
  r.counters = (rect ? gpu.draw(*rect) : gpu.draw()).counters;
  return r;
}

// Lanes of the same value as each width's min and max see them.
template <int W>
void check_min_max_at_width() {
  using F = typename vgpu::SimdLanes<W>::F;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto bits = [](float v) { return std::bit_cast<uint32_t>(v); };
  CAPTURE(W);
  // MIN = a < b ? a : b, MAX = a > b ? a : b (ARB_fragment_program), lane by lane.
  CHECK(lane(min(F(nan), F(1.0f)), W - 1) == 1.0f);
  CHECK(std::isnan(lane(min(F(1.0f), F(nan)), W - 1)));
  CHECK(lane(max(F(nan), F(1.0f)), W - 1) == 1.0f);
  CHECK(std::isnan(lane(max(F(1.0f), F(nan)), W - 1)));
  CHECK(bits(lane(min(F(0.0f), F(-0.0f)), 0)) == bits(-0.0f));
  CHECK(bits(lane(min(F(-0.0f), F(0.0f)), 0)) == bits(0.0f));
  CHECK(bits(lane(max(F(-0.0f), F(0.0f)), 0)) == bits(0.0f));
  CHECK(bits(lane(max(F(0.0f), F(-0.0f)), 0)) == bits(-0.0f));
  CHECK(lane(min(F(2.0f), F(-3.0f)), 0) == -3.0f);
  CHECK(lane(max(F(2.0f), F(-3.0f)), 0) == 2.0f);
}

}  // namespace

TEST_CASE("min and max treat NaN and signed zeros the same way at every lane width") {
  check_min_max_at_width<1>();
  check_min_max_at_width<4>();
  check_min_max_at_width<8>();
  check_min_max_at_width<16>();
}

TEST_CASE("SIMD widths 4, 8 and 16 match the scalar reference bit for bit, partial batches too") {
  const Rect partial{3, 2, 130, 35};  // 127 wide: no width divides it
  for (const char* prof : {"gf5700", "gf6600"})
    for (const Rect* rect : {static_cast<const Rect*>(nullptr), &partial})
      for (bool stencil : {false, true}) {
        CAPTURE(prof);
        CAPTURE(rect != nullptr);
        CAPTURE(stencil);
        const Run ref = run_mixed(prof, 1, 1, rect, stencil);
        // The pass must exercise every path for the comparison to mean something.
        CHECK(ref.counters.fragments_discarded > 0);
        CHECK(ref.counters.lanes_idle > 0);
        CHECK(ref.counters.fragments_shaded > ref.counters.fragments_discarded);
        CHECK((ref.counters.fragments_masked > 0) == stencil);
        for (int lanes : {4, 8, 16}) {
          CAPTURE(lanes);
          const Run r = run_mixed(prof, 1, lanes, rect, stencil);
          CHECK(same_bits(r.out, ref.out));
          CHECK(same_bits(r.written, ref.written));
          CHECK(r.counters.same_counts(ref.counters));
        }
      }
}

TEST_CASE("1, 2, 3 and 7 threads give bit-identical images and identical counters") {
  const Rect partial{3, 2, 130, 35};
  for (const char* prof : {"gf5700", "gf6600"})
    for (const Rect* rect : {static_cast<const Rect*>(nullptr), &partial})
      for (int lanes : {1, 8}) {
        CAPTURE(prof);
        CAPTURE(lanes);
        CAPTURE(rect != nullptr);
        const Run ref = run_mixed(prof, 1, lanes, rect, true);
        for (int threads : {2, 3, 7}) {
          CAPTURE(threads);
          const Run r = run_mixed(prof, threads, lanes, rect, true);
          CHECK(same_bits(r.out, ref.out));
          CHECK(same_bits(r.written, ref.written));
          CHECK(r.counters.same_counts(ref.counters));
        }
      }
  CHECK(Gpu(profile("gf5700"), 3).threads() == 3);
  CHECK(Gpu(profile("gf5700"), 0).threads() >= 1);
}

namespace {

// out(0) = (x, y) window position of the fragment.
struct Position {
  static constexpr const char* name = "position";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(Fragments<L>& f) const {
    f.out(0) = {f.x, f.y, f.x * f.y, typename L::F(1.0f)};
  }
};

}  // namespace

TEST_CASE("fragments see their pixel centres and only the drawn rectangle is written") {
  for (int lanes : {1, 4, 8, 16}) {
    CAPTURE(lanes);
    Gpu gpu(profile("gf5700"), 1, lanes);
    Texture out = gpu.make_texture("out", 21, 6, 4);
    out.fill(std::array{-1.0f, -1.0f, -1.0f, -1.0f});
    KernelProgram<Position> pos;
    gpu.use_program(pos);
    gpu.set_targets({&out});
    const PassRecord& rec = gpu.draw(Rect{2, 1, 19, 5});
    CHECK(rec.width == 17);
    CHECK(rec.height == 4);
    CHECK(rec.counters.fragments_launched == 68);
    CHECK(rec.counters.fragments_shaded == 68);
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 21; ++x) {
        const bool inside = x >= 2 && x < 19 && y >= 1 && y < 5;
        CAPTURE(x);
        CAPTURE(y);
        CHECK(out.get(x, y, 0) == (inside ? float(x) + 0.5f : -1.0f));
        CHECK(out.get(x, y, 1) == (inside ? float(y) + 0.5f : -1.0f));
        CHECK(out.get(x, y, 3) == (inside ? 1.0f : -1.0f));
      }
  }
}

namespace {

// A branch taken where x < 10; `runs` counts how often the block executes for a batch.
struct LeftBranch {
  static constexpr const char* name = "left branch";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  int* runs = nullptr;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const auto left = f.x < F(10.0f);
    Vec4<F> o{F(1.0f), F(0.0f), F(0.0f), F(0.0f)};
    if (f.branch(left)) {
      if constexpr (!L::counting) ++*runs;
      o.x = select(left, F(2.0f), o.x);
    }
    f.out(0) = o;
  }
};

}  // namespace

TEST_CASE("f.branch counts the live fragments idle in the block at every width") {
  for (const char* prof : {"gf5700", "gf6600"})
    for (int lanes : {1, 4, 8, 16}) {
      CAPTURE(prof);
      CAPTURE(lanes);
      Gpu gpu(profile(prof), 1, lanes);
      Texture out = gpu.make_texture("out", 32, 4, 4);
      int runs = 0;
      KernelProgram<LeftBranch> k;
      k.kernel.runs = &runs;
      gpu.use_program(k);
      gpu.set_targets({&out});
      CHECK(gpu.draw().counters.lanes_idle == 22 * 4);  // x = 10..31 on 4 rows
      CHECK(out.get(9, 3) == 2.0f);
      CHECK(out.get(10, 3) == 1.0f);
      // Masked fragments are not live, so they are not idle either: columns 20..23 masked.
      Stencil test(32, 4, 1);
      for (int y = 0; y < 4; ++y)
        for (int x = 20; x < 24; ++x) test.set(x, y, 0);
      gpu.set_stencil_test(&test);
      CHECK(gpu.draw().counters.lanes_idle == 18 * 4);
    }
}

TEST_CASE("the batch counters count idle fragments only in 8x4 and 32x32 tiles idle as a whole") {
  // 64 x 40 target, branch taken where x < 10. 8x4 tiles: x 0..7 and 8..15 hold takers, the
  // other 6 tile columns are idle (48 x 40 = 1920 fragments). 32x32 tiles: x 32..63 is idle,
  // rows 0..31 and the partial tile of rows 32..39 (32 x 40 = 1280).
  for (int lanes : {1, 8, 16})
    for (int threads : {1, 3}) {
      CAPTURE(lanes);
      CAPTURE(threads);
      Gpu gpu(profile("gf6600"), threads, lanes);
      Texture out = gpu.make_texture("out", 64, 40, 4);
      int runs = 0;
      KernelProgram<LeftBranch> k;
      k.kernel.runs = &runs;
      gpu.use_program(k);
      gpu.set_targets({&out});
      const Counters c = gpu.draw().counters;
      CHECK(c.lanes_idle == 54 * 40);
      CHECK(c.idle_in_batch32 == 1920);
      CHECK(c.idle_in_batch1024 == 1280);
      // Masked fragments (stencil 0) neither take the branch nor count as idle.
      Stencil test(64, 40, 1);
      for (int y = 0; y < 40; ++y)
        for (int x = 56; x < 64; ++x) test.set(x, y, 0);  // tile column x 56..63 all masked
      gpu.set_stencil_test(&test);
      const Counters m = gpu.draw().counters;
      CHECK(m.lanes_idle == 46 * 40);
      CHECK(m.idle_in_batch32 == 1600);   // 5 idle tile columns (x 16..55) x 40 rows x 8
      CHECK(m.idle_in_batch1024 == 960);  // x 32..55 in both row tiles: 24 x 40
      // Tiles start at the drawn rectangle's corner: x 8..63 gives 8x4 tiles from x 8 (x 8..15
      // busy) and 32x32 tiles from x 8 (x 8..39 busy).
      gpu.set_stencil_test(nullptr);
      const Counters part = gpu.draw(Rect{8, 0, 64, 40}).counters;
      CHECK(part.lanes_idle == 54 * 40);
      CHECK(part.idle_in_batch32 == 48 * 40);
      CHECK(part.idle_in_batch1024 == 24 * 40);
    }
}

TEST_CASE("with dynamic branching a batch where no live fragment takes a branch skips it") {
  for (int lanes : {1, 4, 8, 16}) {
    CAPTURE(lanes);
    for (const char* prof : {"gf5700", "gf6600"}) {
      CAPTURE(prof);
      Gpu gpu(profile(prof), 1, lanes);
      Texture out = gpu.make_texture("out", 32, 4, 4);
      int runs = 0;
      KernelProgram<LeftBranch> k;
      k.kernel.runs = &runs;
      gpu.use_program(k);
      gpu.set_targets({&out});
      gpu.draw();
      const int batches_per_row = 32 / lanes;
      const int taking_per_row = (10 + lanes - 1) / lanes;  // batches holding some x < 10
      // fp30 runs both sides of every conditional; fp40 skips the block where it can.
      CHECK(runs == 4 * (std::string(prof) == "gf5700" ? batches_per_row : taking_per_row));
    }
  }
}

namespace {

struct Add3 {
  static constexpr const char* name = "add3";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(Fragments<L>& f) const {
    auto a = f.fetch_own(0), b = f.fetch_own(1), c = f.fetch_own(2);
    f.out(0) = {a.x + b.x * c.x, a.y, b.y, c.y};
  }
};

// A uniform loop bound: the instruction count follows the uniform.
struct Lights {
  static constexpr const char* name = "lights";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  int lights = 1;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> n = f.fetch_own(0);
    F sum(0.0f);
    for (int i = 0; i < lights; ++i) {
      const auto lit = n.x > F(float(i));
      if (f.branch(lit)) sum = select(lit, sum + n.y * n.z, sum);
    }
    f.out(0) = {sum, sum, sum, F(1.0f)};
  }
};

}  // namespace

TEST_CASE("the counting run derives instructions, fetches and branches from the kernel code") {
  const KernelProgram<Add3> add3;
  const Program::Analysis a = add3.analyze();
  CHECK(a.instructions == 5);  // 3 fetches, one multiply, one add
  CHECK(a.fetches.total() == 3);
  CHECK(a.fetches.per_unit[0] == 1);
  CHECK(a.fetches.per_unit[1] == 1);
  CHECK(a.fetches.per_unit[2] == 1);
  CHECK(a.fetches.per_unit[3] == 0);
  CHECK(a.branches == 0);

  KernelProgram<Lights> lights;
  lights.kernel.lights = 1;
  const Program::Analysis one = lights.analyze();
  lights.kernel.lights = 3;
  const Program::Analysis three = lights.analyze();
  CHECK(one.instructions == 1 + 4);  // the fetch; per light a compare, multiply, add, select
  CHECK(three.instructions == 1 + 3 * 4);
  CHECK(one.branches == 1);
  CHECK(three.branches == 3);
  CHECK(three.fetches.total() == 1);
}

TEST_CASE("branch_flags says per fragment whether it took the branch, sat idle or was not shaded") {
  for (int lanes : {1, 8}) {
    CAPTURE(lanes);
    Gpu gpu(profile("gf6600"), 2, lanes);
    Texture out = gpu.make_texture("out", 24, 6, 4);
    int runs = 0;
    KernelProgram<LeftBranch> k;
    k.kernel.runs = &runs;
    Stencil test(24, 6, 1);
    test.set(3, 2, 0);
    test.set(15, 5, 0);
    gpu.use_program(k);
    gpu.set_targets({&out});
    gpu.set_stencil_test(&test);
    gpu.draw();
    const std::span<const uint8_t> flags = gpu.branch_flags();
    REQUIRE(flags.size() == 24 * 6);
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 24; ++x) {
        CAPTURE(x);
        CAPTURE(y);
        const uint8_t want = !test.get(x, y) ? 0 : x < 10 ? kBranchTook : kBranchIdle;
        CHECK(flags[size_t(y) * 24 + x] == want);
      }
    KernelProgram<vgpu_test::Copy> plain;  // no branch
    Texture in = gpu.make_texture("in", 24, 6, 4);
    gpu.use_program(plain);
    gpu.bind_texture(0, in);
    gpu.draw();
    CHECK(gpu.branch_flags().empty());
  }
}
