// Batches (vgpu/batch.h): run_batch on eight fragments of a row with hand-made texels. Live lanes
// get the program's output, idle lanes the passthrough unit's texel, discarded lanes keep the
// target's texel; the lane bits and idle count say what each lane did; a unit resident in a
// slot reads what memory holds; fp16 targets round; and the whole agrees with Gpu::draw() under
// a work mask, the emulator's normal path.
#include <doctest/doctest.h>

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>

#include "vgpu/batch.h"
#include "vgpu/vgpu.h"

using namespace vgpu;

namespace {

constexpr int kX0 = 8, kY = 2;  // the batch: fragments (8..15, 2) of a 24x4 target

// Unit 0: the state (passthrough of the output), read at the own texel; unit 1: a 3-channel
// texture read at the own texel (its w reads 1); unit 2: read at the right-hand neighbour (any
// coordinates: never resident). Lanes with state w > 0 take the branch; state z < 0 discards.
template <bool kIdleDiscards>
struct Toy {
  static constexpr const char* name = kIdleDiscards ? "toy (idle discards)" : "toy";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  static constexpr std::array<int, 1> passthrough{0};
  static constexpr bool idle_discards = kIdleDiscards;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> a = f.fetch_own(0);
    const Vec4<F> g = f.fetch_own(1);
    const Vec4<F> nb = f.fetch(2, f.x + F(1.0f), f.y);
    const auto take = a.w > F(0.0f);
    Vec4<F> o{a.x * F(2.0f), a.y + f.x, a.z + g.z, g.w};
    if (f.branch(take)) {
      o.x = select(take, a.x + g.x, o.x);
      o.w = select(take, a.w - F(1.0f) + nb.x, o.w);
    }
    f.discard(a.z < F(0.0f));
    f.out(0) = o;
  }
};

// Hand-made texels. State at (x, y), lane i = x - kX0: x = 1 + 0.3 i + y (no fp16 value), y =
// 10 i, z = 0.5 i but -1 at lane 4 of the batch's row (discarded), w = 3 on even lanes (they take
// the branch), 0 on odd ones.
float state_at(int x, int y, int c) {
  const int i = x - kX0;
  const float v[4] = {1.0f + 0.3f * float(i) + float(y), 10.0f * float(i),
                      i == 4 && y == kY ? -1.0f : 0.5f * float(i), i % 2 == 0 ? 3.0f : 0.0f};
  return v[c];
}
float extra_at(int x, int y, int c) {  // unit 1, 3 channels
  const float v[3] = {0.25f * float(x), -float(x) - float(y), 100.0f + float(x)};
  return v[c];
}
float right_at(int x, int y, int c) {  // unit 2, read one texel to the right
  return 1000.0f + float(x) + 0.125f * float(c) + 10.0f * float(y);
}
float old_at(int x, int y, int c) {  // the target before the pass
  return -7.0f - float(x) - 0.5f * float(y) - 0.0625f * float(c);
}

struct Textures {
  Texture state{"state", 24, 4, 4}, extra{"extra", 24, 4, 3}, right{"right", 24, 4, 4};
  Texture target;
  explicit Textures(Format target_format = Format::fp32)
      : target("target", 24, 4, 4, target_format) {
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 24; ++x)
        for (int c = 0; c < 4; ++c) {
          state.set(x, y, c, state_at(x, y, c));
          right.set(x, y, c, right_at(x, y, c));
          target.set(x, y, c, old_at(x, y, c));
          if (c < 3) extra.set(x, y, c, extra_at(x, y, c));
        }
  }
};

BoundTexture bound(const Texture& t, const Slot* resident = nullptr) {
  return {t.data().data(), t.width(), t.height(), t.channels(),
          resident ? &resident->v[0][0] : nullptr};
}

// What the program writes at lane i (fp32 arithmetic, in the program's order of operations).
std::array<float, 4> program_output(int i) {
  const int x = kX0 + i;
  const float ax = state_at(x, kY, 0), ay = state_at(x, kY, 1), az = state_at(x, kY, 2),
              aw = state_at(x, kY, 3);
  const float fx = float(i) + float(kX0) + 0.5f;
  const bool take = aw > 0.0f;
  return {take ? ax + extra_at(x, kY, 0) : ax * 2.0f, ay + fx, az + extra_at(x, kY, 2),
          take ? aw - 1.0f + right_at(x + 1, kY, 0) : 1.0f};
}

struct BatchResult {
  BatchRun run;
  Slot out;
};

// One run of Toy on the batch: units 0 and 1 resident in slots (or read from memory).
template <bool kIdleDiscards>
BatchResult run_toy(const Textures& t, uint8_t live, bool dynamic, bool resident = true,
                    Format precision = Format::fp32) {
  const KernelProgram<Toy<kIdleDiscards>> toy;
  Slot state, extra;
  state.load(t.state, kX0, kY, kBatchWidth);
  extra.load(t.extra, kX0, kY, kBatchWidth);
  BatchResult r;
  r.out.load(t.target, kX0, kY, kBatchWidth);
  const BoundTexture units[3] = {bound(t.state, resident ? &state : nullptr),
                                 bound(t.extra, resident ? &extra : nullptr), bound(t.right)};
  const BatchOutput out{&r.out, kIdleDiscards ? nullptr : &state};
  r.run = run_batch(toy, precision, dynamic, units, &out, 1, live, kX0, kY);
  return r;
}

bool same_bits(const Slot& a, const Slot& b) {
  return std::memcmp(a.v, b.v, sizeof a.v) == 0;
}

constexpr uint8_t kLive = 0b0111'1011;  // lanes 2 and 7 idle (their work mask is 0)

}  // namespace

TEST_CASE("run_batch writes live lanes, gives idle lanes the passthrough, leaves discarded ones") {
  const Textures t;
  for (bool dynamic : {false, true}) {
    CAPTURE(dynamic);
    const BatchResult r = run_toy<false>(t, kLive, dynamic);
    // Live: 0, 1, 3, 4, 5, 6. Of those the even ones take the branch, 4 is discarded.
    CHECK(r.run.took == 0b0101'0001);
    CHECK(r.run.idle == 0b0010'1010);
    CHECK(r.run.killed == 0b0001'0000);
    CHECK(r.run.lanes_idle == 3);
    for (int i = 0; i < kBatchWidth; ++i)
      for (int c = 0; c < 4; ++c) {
        CAPTURE(i);
        CAPTURE(c);
        const int x = kX0 + i;
        const float want = i == 2 || i == 7 ? state_at(x, kY, c)  // idle: the passthrough
                           : i == 4         ? old_at(x, kY, c)    // discarded: untouched
                                            : program_output(i)[size_t(c)];
        CHECK(r.out.v[c][i] == want);
      }
  }
}

TEST_CASE("run_batch counts lanes idle in a branch that no live lane takes, at fp30 and fp40") {
  const Textures t;
  const uint8_t odd = 0b1010'1010;  // lanes 1, 3, 5, 7: w = 0, none takes the branch
  for (bool dynamic : {false, true}) {
    CAPTURE(dynamic);
    const BatchResult r = run_toy<false>(t, odd, dynamic);
    CHECK(r.run.took == 0);
    CHECK(r.run.idle == odd);
    CHECK(r.run.killed == 0);
    CHECK(r.run.lanes_idle == 4);
    for (int i = 0; i < kBatchWidth; ++i)
      for (int c = 0; c < 4; ++c) {
        CAPTURE(i);
        CAPTURE(c);
        const bool live = (odd >> i) & 1;
        CHECK(r.out.v[c][i] == (live ? program_output(i)[size_t(c)] : state_at(kX0 + i, kY, c)));
      }
  }
  // No live lane at all: every lane copies its passthrough texel and nothing is counted.
  const BatchResult none = run_toy<false>(t, 0, true);
  CHECK(none.run.took == 0);
  CHECK(none.run.idle == 0);
  CHECK(none.run.killed == 0);
  CHECK(none.run.lanes_idle == 0);
  for (int i = 0; i < kBatchWidth; ++i)
    for (int c = 0; c < 4; ++c) CHECK(none.out.v[c][i] == state_at(kX0 + i, kY, c));
}

TEST_CASE("a program whose idle fragments are discarded leaves idle lanes' texels as they were") {
  const Textures t;
  const BatchResult r = run_toy<true>(t, kLive, false);
  CHECK(r.run.took == 0b0101'0001);
  CHECK(r.run.idle == 0b0010'1010);
  CHECK(r.run.killed == 0b0001'0000);  // idle lanes are not among the killed: they did not run
  CHECK(r.run.lanes_idle == 3);
  for (int i = 0; i < kBatchWidth; ++i)
    for (int c = 0; c < 4; ++c) {
      CAPTURE(i);
      CAPTURE(c);
      const bool untouched = i == 2 || i == 7 || i == 4;
      CHECK(r.out.v[c][i] == (untouched ? old_at(kX0 + i, kY, c) : program_output(i)[size_t(c)]));
    }
}

TEST_CASE("a unit resident in a slot reads what the same texture in memory holds") {
  const Textures t;
  // A slot holds the batch's own texels, channel-major; channels the texture lacks read as
  // (0, 0, 0, 1), as fetches do; lanes past n repeat lane 0.
  Slot extra;
  extra.load(t.extra, kX0, kY, 5);
  CHECK(extra.texture == &t.extra);
  for (int i = 0; i < kBatchWidth; ++i) {
    CAPTURE(i);
    const int x = kX0 + (i < 5 ? i : 0);
    for (int c = 0; c < 3; ++c) CHECK(extra.v[c][i] == extra_at(x, kY, c));
    CHECK(extra.v[3][i] == 1.0f);
  }
  for (bool dynamic : {false, true})
    for (Format precision : {Format::fp32, Format::fp24, Format::fp16})
      for (uint8_t live : {kLive, uint8_t(0xff), uint8_t(0b1000'0001)}) {
        CAPTURE(dynamic);
        CAPTURE(format_name(precision));
        CAPTURE(int(live));
        const BatchResult in_slots = run_toy<false>(t, live, dynamic, true, precision);
        const BatchResult in_memory = run_toy<false>(t, live, dynamic, false, precision);
        CHECK(same_bits(in_slots.out, in_memory.out));
        CHECK(in_slots.run.took == in_memory.run.took);
        CHECK(in_slots.run.idle == in_memory.run.idle);
        CHECK(in_slots.run.killed == in_memory.run.killed);
        CHECK(in_slots.run.lanes_idle == in_memory.run.lanes_idle);
      }
  // The slot is what is read: change it and the output follows.
  const KernelProgram<Toy<false>> toy;
  Slot state, out;
  state.load(t.state, kX0, kY, kBatchWidth);
  extra.load(t.extra, kX0, kY, kBatchWidth);
  out.load(t.target, kX0, kY, kBatchWidth);
  state.v[1][3] = 0.5f;  // lane 3's y
  const BoundTexture units[3] = {bound(t.state, &state), bound(t.extra, &extra), bound(t.right)};
  const BatchOutput o{&out, &state};
  run_batch(toy, Format::fp32, false, units, &o, 1, 0xff, kX0, kY);
  CHECK(out.v[1][3] == 0.5f + (3.0f + float(kX0) + 0.5f));
  CHECK(out.v[1][1] == program_output(1)[1]);
}

TEST_CASE("an fp16 target rounds the outputs and the fp32 passthrough copies of a batch") {
  const Textures t(Format::fp16);
  const BatchResult r = run_toy<false>(t, kLive, true);
  CHECK(r.out.texture->format() == Format::fp16);
  int rounded = 0;  // values that fp16 changes: the rounding must matter somewhere
  for (int i = 0; i < kBatchWidth; ++i)
    for (int c = 0; c < 4; ++c) {
      CAPTURE(i);
      CAPTURE(c);
      const int x = kX0 + i;
      const float exact = i == 2 || i == 7 ? state_at(x, kY, c) : program_output(i)[size_t(c)];
      if (i == 4) {  // discarded: the fp16 texel the target held
        CHECK(r.out.v[c][i] == round_to(Format::fp16, old_at(x, kY, c)));
        continue;
      }
      CHECK(r.out.v[c][i] == round_to(Format::fp16, exact));
      rounded += round_to(Format::fp16, exact) != exact;
    }
  CHECK(rounded >= 4);
  CHECK(r.out.v[0][2] != state_at(kX0 + 2, kY, 0));  // idle lane 2's copy was rounded
}

TEST_CASE("run_batch on a row gives what Gpu::draw gives under a work mask, texel for texel") {
  for (const char* prof : {"gf5700", "gf6600"})
    for (Format precision : {Format::fp32, Format::fp24, Format::fp16})
      for (Format target_format : {Format::fp32, Format::fp16})
        for (bool idle_discards : {false, true})
          for (int lanes : {8, 1})
            for (uint8_t live : {kLive, uint8_t(0xff), uint8_t(0b1010'1010)}) {
              CAPTURE(std::string(prof));
              CAPTURE(format_name(precision));
              CAPTURE(format_name(target_format));
              CAPTURE(idle_discards);
              CAPTURE(lanes);
              CAPTURE(int(live));
              const Textures t(target_format);
              Gpu gpu(profile(prof), 1, lanes);
              gpu.set_precision(precision);
              const KernelProgram<Toy<false>> keep;
              const KernelProgram<Toy<true>> drop;
              const Program& p = idle_discards ? static_cast<const Program&>(drop) : keep;
              // The batch.
              const bool dynamic = gpu.profile().branching == Branching::dynamic;
              const Format computes = gpu.precision_of(p);
              const BatchResult b = idle_discards
                                        ? run_toy<true>(t, live, dynamic, true, computes)
                                        : run_toy<false>(t, live, dynamic, true, computes);
              // The same fragments drawn: a copy of the target, the work mask's row from `live`.
              Texture target = t.target;
              Stencil work(24, 4, 0);
              for (int i = 0; i < kBatchWidth; ++i) work.set(kX0 + i, kY, (live >> i) & 1);
              gpu.use_program(p);
              gpu.bind_texture(0, t.state);
              gpu.bind_texture(1, t.extra);
              gpu.bind_texture(2, t.right);
              gpu.set_targets({&target});
              gpu.set_work_mask(&work);
              const Counters c = gpu.draw(Rect{kX0, kY, kX0 + kBatchWidth, kY + 1}).counters;
              for (int i = 0; i < kBatchWidth; ++i)
                for (int ch = 0; ch < 4; ++ch) {
                  CAPTURE(i);
                  CAPTURE(ch);
                  const float drawn = target.get(kX0 + i, kY, ch);
                  CHECK(std::bit_cast<uint32_t>(b.out.v[ch][i]) == std::bit_cast<uint32_t>(drawn));
                }
              // What a replay charges from the batch's bits (Gpu::replay): idle fragments count
              // as shaded, idle in every branch, and discarded where the program says so.
              const int idle = std::popcount(uint8_t(~live));
              CHECK(c.fragments_shaded == 8);
              CHECK(c.fragments_discarded ==
                    uint64_t(std::popcount(b.run.killed) + (idle_discards ? idle : 0)));
              CHECK(c.lanes_idle == b.run.lanes_idle + uint64_t(idle));
              const auto flags = gpu.branch_flags();
              REQUIRE(flags.size() == 8);
              for (int i = 0; i < kBatchWidth; ++i) {
                CAPTURE(i);
                CHECK(flags[size_t(i)] == ((b.run.took >> i) & 1 ? kBranchTook : kBranchIdle));
              }
            }
}

TEST_CASE("slots load a batch's texels channel-major and store back only its n texels") {
  const Textures t;
  for (int n : {8, 5, 1}) {
    CAPTURE(n);
    Slot s;
    s.load(t.state, kX0, kY, n);
    CHECK(s.texture == &t.state);
    for (int i = 0; i < kBatchWidth; ++i)
      for (int c = 0; c < 4; ++c) {
        CAPTURE(i);
        CAPTURE(c);
        CHECK(s.v[c][i] == state_at(kX0 + (i < n ? i : 0), kY, c));
      }
    // Back into a copy whose texels differ everywhere: only (kX0 .. kX0 + n - 1, kY) change.
    Texture copy = t.target;
    for (int i = 0; i < kBatchWidth; ++i)
      for (int c = 0; c < 4; ++c) s.v[c][i] = float(100 * i + c);
    s.store(copy, copy.texel_mut(0, 0), kX0, kY, n);
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 24; ++x)
        for (int c = 0; c < 4; ++c) {
          CAPTURE(x);
          CAPTURE(y);
          CAPTURE(c);
          const bool stored = y == kY && x >= kX0 && x < kX0 + n;
          CHECK(copy.get(x, y, c) == (stored ? float(100 * (x - kX0) + c) : old_at(x, y, c)));
        }
  }
  // A 3-channel texture: the fourth channel reads 1 and is not stored.
  Slot s;
  s.load(t.extra, kX0, kY, kBatchWidth);
  Texture copy = t.extra;
  for (int i = 0; i < kBatchWidth; ++i) {
    CHECK(s.v[3][i] == 1.0f);
    for (int c = 0; c < 4; ++c) s.v[c][i] = -float(i + c);
  }
  s.store(copy, copy.texel_mut(0, 0), kX0, kY, kBatchWidth);
  for (int x = 0; x < 24; ++x)
    for (int c = 0; c < 3; ++c) {
      CAPTURE(x);
      CAPTURE(c);
      const bool stored = x >= kX0 && x < kX0 + kBatchWidth;
      CHECK(copy.get(x, kY, c) == (stored ? -float(x - kX0 + c) : extra_at(x, kY, c)));
      CHECK(copy.get(x, kY + 1, c) == extra_at(x, kY + 1, c));
    }
}
