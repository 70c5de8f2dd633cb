// The recorded-program executor (vgpu/recorded_program.h) against the compiled functors: every
// kernel of the registry, recorded with its default uniforms, run both ways on the same hand-made
// texels at every lane family the Gpu runs (widths 1, 4, 8 and 16 in fp32; widths 1 and 8 in
// fp24 and fp16), on gf5700 where the kernel fits it and on gf6600 (dynamic branching, loops,
// several outputs). Outputs must agree bit for bit, and so must the discards (per fragment, from
// the stencil write, and the query count), with one exception: two NaNs are equal whatever their
// sign and payload. x86 propagates the first operand's NaN when both are NaN, and the compiler
// may swap the operands of a commutative add or multiply, so the NaN's sign depends on register
// allocation: the compiled functor itself gives NaN at width 1 and -NaN at width 16 on some of
// these texels (the count is printed). The counters are compared too: every one must agree but
// those a recording cannot give yet (issue 48: f.branch leaves no node, so a kernel with branches
// loses its idle-lane and batch-coherence counters); the differences are listed per kernel in the
// test's output.
//
// Here and not in tests/vgpu: the kernels' programs are in the kernels library, which test_vgpu
// does not link.
#include <doctest/doctest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "kernels/registry.h"
#include "tests/support/lane_widths.h"
#include "vgpu/recorded_program.h"
#include "vgpu/vgpu.h"

namespace {

// 37 x 7 fragments: two whole batches of 16 and a partial one per row at every width above 1.
constexpr int kW = 37, kH = 7;

// splitmix64: the same texels on every run and machine.
struct Rng {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  float uniform(float lo, float hi) {
    return lo + (hi - lo) * float(next() >> 40) / float(1 << 24);
  }
  int pick(int n) { return int(next() % uint64_t(n)); }
  // A value of the kinds the kernels' state holds, so their compares go both ways: ids and
  // flags (-1 to 3), coordinates, distances, directions, "no hit" (kFar), half-texel centres,
  // negatives, and now and then NaN, an infinity or a signed zero.
  float value() {
    switch (pick(16)) {
      case 0:
      case 1:
      case 2:
      case 3:
        return float(pick(5) - 1);
      case 4:
      case 5:
      case 6:
        return uniform(-1, 1);
      case 7:
      case 8:
      case 9:
        return uniform(0, float(kW));
      case 10:
        return kernels::kFar;
      case 11:
        return uniform(0, 1);
      case 12:
        return float(pick(kW)) + 0.5f;
      case 13:
        return -uniform(0, 10);
      case 14: {
        const float specials[] = {std::numeric_limits<float>::quiet_NaN(),
                                  std::numeric_limits<float>::infinity(),
                                  -std::numeric_limits<float>::infinity(), 0.0f, -0.0f};
        return specials[pick(5)];
      }
      default:
        return uniform(0, 64);
    }
  }
};

// One texture per unit, the size of the target (own-texel fetches take the emulator's fast
// path; dependent ones clamp): four channels but for a few one- and three-channel units, as the
// kernels' list, pointer and vertex textures are.
std::vector<vgpu::Texture> unit_textures() {
  std::vector<vgpu::Texture> t;
  for (int u = 0; u < vgpu::kMaxTextureUnits; ++u) {
    const int channels = u == 3 || u == 9 ? 1 : u == 6 || u == 12 ? 3 : 4;
    vgpu::Texture tex("unit" + std::to_string(u), kW, kH, channels);
    Rng r{uint64_t(1000 + u)};
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x)
        for (int c = 0; c < channels; ++c) tex.set(x, y, c, r.value());
    t.push_back(std::move(tex));
  }
  return t;
}

struct Family {
  int lanes;
  vgpu::Format precision;
};
// Every lane family Gpu::draw picks: SimdLanes<1, 4, 8, 16>, RoundedLanes<1 and 8> at fp24 and
// fp16 (the counting and recording families are checked apart).
constexpr Family kFamilies[] = {{1, vgpu::Format::fp32}, {4, vgpu::Format::fp32},
                                {8, vgpu::Format::fp32}, {16, vgpu::Format::fp32},
                                {1, vgpu::Format::fp24}, {8, vgpu::Format::fp24},
                                {1, vgpu::Format::fp16}, {8, vgpu::Format::fp16}};

struct Pass {
  std::vector<vgpu::Texture> outs;
  vgpu::Stencil survived;  // 1 where the fragment survived, 0 where it was discarded
  uint64_t query = 0;
  vgpu::PassRecord rec;
};

// One pass of p over kW x kH targets (cleared to a value no kernel writes, so a discarded
// fragment shows), inside an occlusion query, writing the stencil.
Pass draw(const vgpu::Program& p, const vgpu::Profile& profile, Family fam,
          const std::vector<vgpu::Texture>& units) {
  vgpu::Gpu gpu(profile, 1, fam.lanes);
  gpu.set_precision(fam.precision);
  Pass r;
  r.survived = vgpu::Stencil(kW, kH, 7);
  for (int o = 0; o < p.outputs(); ++o) {
    r.outs.emplace_back("out" + std::to_string(o), kW, kH, 4);
    const float fill[4] = {-123.25f, 456.5f, -789.75f, float(o) + 0.125f};
    r.outs.back().fill(fill);
  }
  gpu.use_program(p);
  gpu.unbind_textures();
  const vgpu::Program::Analysis a = p.analyze();
  for (int u = 0; u < vgpu::kMaxTextureUnits; ++u)
    if (a.fetches.per_unit[size_t(u)]) gpu.bind_texture(u, units[size_t(u)]);
  switch (p.outputs()) {
    case 1:
      gpu.set_targets({&r.outs[0]});
      break;
    case 2:
      gpu.set_targets({&r.outs[0], &r.outs[1]});
      break;
    case 3:
      gpu.set_targets({&r.outs[0], &r.outs[1], &r.outs[2]});
      break;
    default:
      gpu.set_targets({&r.outs[0], &r.outs[1], &r.outs[2], &r.outs[3]});
      break;
  }
  gpu.set_stencil_write(&r.survived);
  gpu.begin_query();
  r.rec = gpu.draw();
  r.query = gpu.end_query();
  return r;
}

// The first texel channel where two targets differ in bits (two NaNs do not: see the top),
// as text; empty if none. nan_signs counts the channels that are NaN in both, with other bits.
std::string first_difference(const vgpu::Texture& a, const vgpu::Texture& b, int& nan_signs) {
  const std::span<const float> da = a.data(), db = b.data();
  for (size_t i = 0; i < da.size(); ++i)
    if (std::bit_cast<uint32_t>(da[i]) != std::bit_cast<uint32_t>(db[i])) {
      if (std::isnan(da[i]) && std::isnan(db[i])) {
        ++nan_signs;
        continue;
      }
      const size_t texel = i / 4;
      return "texel (" + std::to_string(texel % kW) + ", " + std::to_string(texel / kW) +
             ") channel " + std::to_string(i % 4) + ": functor " + std::to_string(da[i]) +
             ", recorded " + std::to_string(db[i]);
    }
  return {};
}

bool same_recording(const vgpu::Recording& a, const vgpu::Recording& b) {
  if (a.nodes.size() != b.nodes.size() || a.outputs != b.outputs || a.kill != b.kill ||
      a.loops.size() != b.loops.size())
    return false;
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    const vgpu::RecNode &x = a.nodes[i], &y = b.nodes[i];
    if (x.op != y.op || x.a != y.a || x.b != y.b || x.c != y.c || x.unit != y.unit ||
        std::bit_cast<uint32_t>(x.value) != std::bit_cast<uint32_t>(y.value))
      return false;
  }
  for (size_t i = 0; i < a.loops.size(); ++i) {
    const vgpu::RecLoop &x = a.loops[i], &y = b.loops[i];
    if (x.begin != y.begin || x.mid != y.mid || x.end != y.end ||
        x.max_iterations != y.max_iterations || x.entry != y.entry)
      return false;
  }
  return true;
}

}  // namespace

TEST_CASE(
    "every kernel's recording, run by the recorded-program executor, gives the compiled "
    "functor's outputs and discards bit for bit at every lane width and precision") {
  const std::vector<vgpu::Texture> units = unit_textures();
  const auto programs = kernels::all_programs(kernels::Programs::with_looping);
  // kernel -> counters that differed between the functor's passes and the recording's
  std::map<std::string, std::set<std::string>> counter_diffs;
  int kernels_checked = 0, passes_identical = 0, passes = 0, nan_signs = 0;
  // How much of the kernels the texels reach: passes that discarded some fragments and kept
  // others, and per looping kernel the most loop iterations a fragment ran.
  int mixed_discards = 0;
  std::map<std::string, uint64_t> most_iterations;
  // What a recording loses today (issue 48): a kernel's f.branch() blocks, with them the
  // counters of the lanes idle in them.
  const std::set<std::string> branch_counters = {"lanes_idle", "idle_in_batch32",
                                                 "idle_in_batch1024"};
  for (const auto& p : programs) {
    const std::string name = p->name();
    CAPTURE(name);
    const auto rp = vgpu::RecordedProgram::of(*p);
    const bool branches = p->analyze().branches > 0;
    bool any_profile = false;
    for (const char* profile_name : {"gf5700", "gf6600"}) {
      const std::string profile_shown(profile_name);  // CAPTURE keeps a reference
      CAPTURE(profile_shown);
      const vgpu::Profile& profile = vgpu::profile(profile_name);
      for (const Family fam : kFamilies) {
        if (!test_support::kernel_width_built(fam.lanes)) continue;  // the functor's side
        CAPTURE(fam.lanes);
        CAPTURE(vgpu::format_name(fam.precision));
        Pass want;
        try {
          want = draw(*p, profile, fam, units);
        } catch (const vgpu::Error& e) {
          // The profile refuses the kernel (outputs, loops, length): it must refuse its recording.
          CHECK_THROWS_AS(draw(*rp, profile, fam, units), vgpu::Error);
          break;
        }
        any_profile = true;
        const Pass got = draw(*rp, profile, fam, units);
        ++passes;
        bool same = true;
        for (int o = 0; o < p->outputs(); ++o) {
          CAPTURE(o);
          const std::string diff =
              first_difference(want.outs[size_t(o)], got.outs[size_t(o)], nan_signs);
          CHECK_MESSAGE(diff.empty(), diff);
          same = same && diff.empty();
        }
        bool stencil_same = true;
        for (int y = 0; y < kH; ++y)
          for (int x = 0; x < kW; ++x)
            stencil_same = stencil_same && want.survived.get(x, y) == got.survived.get(x, y);
        CHECK(stencil_same);
        CHECK(got.query == want.query);
        CHECK(got.rec.counters.fragments_discarded == want.rec.counters.fragments_discarded);
        if (same && stencil_same && got.query == want.query) ++passes_identical;
        if (want.query > 0 && want.query < uint64_t(kW * kH)) ++mixed_discards;
        if (want.rec.counters.loop_iterations > 0) {
          uint64_t most = 0;
          for (size_t k = 0; k < want.rec.loop_active.size(); ++k)
            if (want.rec.loop_active[k] > 0) most = k + 1;
          most_iterations[name] = std::max(most_iterations[name], most);
        }
        for (const auto& [field, member] : vgpu::kCounterFields)
          if (want.rec.counters.*member != got.rec.counters.*member) {
            // A copy: clang 14 lambdas (CAPTURE's) cannot capture a structured binding.
            const std::string field_shown(field);
            CAPTURE(field_shown);
            CHECK((branches && branch_counters.count(field)));
            std::string d = field;
            d += " (" + std::to_string(want.rec.counters.*member) + " functor, " +
                 std::to_string(got.rec.counters.*member) + " recorded on " + profile_name + ")";
            auto& s = counter_diffs[name];
            bool seen = false;  // once per counter: the first profile and family that showed it
            for (const std::string& k : s) seen = seen || k.rfind(std::string(field) + " ", 0) == 0;
            if (!seen) s.insert(d);
          }
      }
    }
    CHECK(any_profile);
    ++kernels_checked;
  }
  std::string report =
      "recorded-program executor: " + std::to_string(kernels_checked) + " kernels, " +
      std::to_string(passes_identical) + " of " + std::to_string(passes) +
      " passes bit-identical (" + std::to_string(nan_signs) +
      " output channels NaN in both with other sign bits); " + std::to_string(mixed_discards) +
      " passes discarded some fragments and kept others; loops ran up to";
  for (const auto& [kernel, most] : most_iterations) {
    // Appended piece by piece (GCC 12 warns, wrongly, of an overflow in " " + to_string(...)).
    report += ' ';
    report += std::to_string(most);
    report += " iterations (";
    report += kernel;
    report += ')';
  }
  report += "; counters that differ:";
  for (const auto& [kernel, diffs] : counter_diffs) {
    report += "\n  " + kernel + ":";
    for (const std::string& d : diffs) report += " " + d + ";";
  }
  MESSAGE(report);
  CHECK(kernels_checked == int(programs.size()));
  CHECK(passes_identical == passes);
}

TEST_CASE(
    "recording a recorded program gives back its recording node for node, and the same GLSL as "
    "the functor") {
  for (const auto& p : kernels::all_programs(kernels::Programs::with_looping)) {
    const std::string name(p->name());  // CAPTURE keeps a reference
    CAPTURE(name);
    const auto rp = vgpu::RecordedProgram::of(*p);
    const vgpu::Recording again = rp->record();
    CHECK(same_recording(rp->recording(), again));
    CHECK(vgpu::to_glsl(*rp, again, true).source == vgpu::to_glsl(*p, true).source);
  }
}

TEST_CASE(
    "the counting run of a recorded program finds the functor's fetches and loop, and an "
    "instruction count that differs only by what the recording folded away") {
  std::string report = "counting run, functor vs recorded (instructions, branches):";
  for (const auto& p : kernels::all_programs(kernels::Programs::with_looping)) {
    const std::string name = p->name();
    CAPTURE(name);
    const auto rp = vgpu::RecordedProgram::of(*p);
    const vgpu::Program::Analysis a = p->analyze(), b = rp->analyze();
    CHECK(a.fetches.per_unit == b.fetches.per_unit);
    CHECK(a.loop.loops == b.loop.loops);
    CHECK(a.loop.max_iterations == b.loop.max_iterations);
    CHECK(a.loop.body_fetches.per_unit == b.loop.body_fetches.per_unit);
    CHECK(a.loop.chain_fetches == b.loop.chain_fetches);
    CHECK(a.loop.chain_operations == b.loop.chain_operations);
    // A recording holds no f.branch() and no mask operation with a constant operand: never
    // more instructions than the functor, never a branch.
    CHECK(b.instructions <= a.instructions);
    CHECK(b.loop.body_instructions <= a.loop.body_instructions);
    CHECK(b.branches == 0);
    if (a.instructions != b.instructions || a.branches != b.branches ||
        a.loop.body_instructions != b.loop.body_instructions)
      report += "\n  " + name + ": instructions " + std::to_string(a.instructions) + " vs " +
                std::to_string(b.instructions) + ", branches " + std::to_string(a.branches) +
                " vs " + std::to_string(b.branches) + ", loop body instructions " +
                std::to_string(a.loop.body_instructions) + " vs " +
                std::to_string(b.loop.body_instructions);
  }
  MESSAGE(report);
}
