// Data-dependent loops (Fragments::loop): each fragment's iterations, the per-batch lane
// counters at the profile's branch granularity, the same statistics at every lane width and
// thread count, and the profile's limits (no loops on fp30, the loop count limit, the
// executed-instruction limit), each refusal naming the program.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "helpers.h"
#include "vgpu/vgpu.h"

using namespace vgpu;
using doctest::Contains;
using vgpu_test::CountTo;

namespace {

// A loop whose body has `ops` additions.
struct LongBody {
  static constexpr const char* name = "long body";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  int budget = 255;
  int ops = 300;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    F s = f.x;
    f.loop(budget, f.live(), [&](const M&) {
      for (int i = 0; i < ops; ++i) s = s + F(1.0f);
      return M(false);
    });
    f.out(0) = {s, s, s, s};
  }
};

// CountTo with a fetch of unit 1's texel (iteration, 0) in its body.
struct FetchInLoop {
  static constexpr const char* name = "fetch in loop";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    const F n = f.fetch_own(0).x;
    F c = F(0.0f), s = F(0.0f);
    f.loop(16, n > F(0.0f), [&](const M& active) {
      s = vgpu::select(active, s + f.fetch(1, c, F(0.0f)).x, s);
      c = vgpu::select(active, c + F(1.0f), c);
      return c < n;
    });
    f.out(0) = {c, s, F(0.0f), F(0.0f)};
  }
};

// A loop body with a branch in it.
struct BranchInLoop {
  static constexpr const char* name = "branch in loop";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    F s = f.x;
    f.loop(4, f.live(), [&](const M& active) {
      if (f.branch(active)) s = select(active, s + F(1.0f), s);
      return M(false);
    });
    f.out(0) = {s, s, s, s};
  }
};

Texture row(const std::vector<float>& n) {
  Texture t("needed", int(n.size()), 1, 4);
  for (size_t i = 0; i < n.size(); ++i) t.set(int(i), 0, 0, n[i]);
  return t;
}

PassRecord draw_count(Gpu& gpu, const KernelProgram<CountTo>& p, const Texture& in, Texture& out) {
  gpu.use_program(p);
  gpu.bind_texture(0, in);
  gpu.set_targets({&out});
  return gpu.draw();
}

template <class K>
std::string refusal(const Profile& profile, const K& k) {
  Gpu gpu(profile, 1, 1);
  KernelProgram<K> p(k);
  Texture in("in", 4, 1, 4), out("out", 4, 1, 4);
  gpu.use_program(p);
  gpu.bind_texture(0, in);
  gpu.set_targets({&out});
  try {
    gpu.draw();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("a looping pass's footprint holds the texels its body fetched on every iteration") {
  Gpu gpu(profile("gf6600"), 1, 8);
  KernelProgram<FetchInLoop> p;
  const Texture in = row({1, 3, 7});                        // 11 iterations in all
  const Texture wide = row(std::vector<float>(64, 1.0f));   // 64 texels, 1024 B
  const Texture narrow = row(std::vector<float>(8, 1.0f));  // 8 texels, 128 B
  Texture out("out", 3, 1, 4);
  gpu.use_program(p);
  gpu.bind_texture(0, in);
  gpu.bind_texture(1, wide);
  gpu.set_targets({&out});
  const Counters c = gpu.draw().counters;
  CHECK(c.loop_iterations == 11);
  CHECK(c.bytes_read == 3 * 16 + 11 * 16);
  // in's 48 B, 11 body fetches of 16 B from wide, the target's 48 B.
  CHECK(c.footprint_bytes == 48 + 11 * 16 + 48);
  gpu.bind_texture(1, narrow);  // 176 B fetched from a texture of 128
  CHECK(gpu.draw().counters.footprint_bytes == 48 + 128 + 48);
}

TEST_CASE("the counting run gives a loop body's static instructions and its budget") {
  KernelProgram<CountTo> p;
  const Program::Analysis a = p.analyze();
  // fetch, n > 0, then the body once: c + 1, select, c < n.
  CHECK(a.instructions == 5);
  CHECK(a.loop.loops == 1);
  CHECK(a.loop.body_instructions == 3);
  CHECK(a.loop.body_fetches.total() == 0);
  CHECK(a.loop.max_iterations == 16);
}

TEST_CASE("lanes needing 1, 3 and 7 iterations in one batch give exact loop counters") {
  Gpu gpu(profile("gf6600"), 1, 8);  // branch granularity 1024: the 3 fragments are one batch
  KernelProgram<CountTo> p;
  const Texture in = row({1, 3, 7});
  Texture out("out", 3, 1, 4);
  const PassRecord rec = draw_count(gpu, p, in, out);
  for (int x = 0; x < 3; ++x) {
    CAPTURE(x);
    CHECK(out.get(x, 0, 0) == in.get(x, 0, 0));
    CHECK(out.get(x, 0, 1) == in.get(x, 0, 0));
    CHECK(out.get(x, 0, 2) == 0.0f);
    CHECK(out.get(x, 0, 3) == 0.0f);
  }
  const Counters& c = rec.counters;
  CHECK(c.fragments_shaded == 3);
  CHECK(c.loop_iterations == 11);         // 1 + 3 + 7
  CHECK(c.loop_batch_iterations == 7);    // the batch runs as long as its slowest lane
  CHECK(c.loop_lane_slots == 21);         // 3 lanes x 7 iterations
  CHECK(c.loop_lanes_idle == 10);         // 0 + 1 + 1 + 2 x 4
  CHECK(c.loop_idle_instructions == 30);  // 10 idle lane slots x 3 body instructions
  CHECK(c.loop_idle_fetches == 0);
  CHECK(c.instructions == 3 * 2 + 11 * 3);  // per fragment fetch + compare, body per iteration
  CHECK(c.texture_fetches == 3);
  CHECK(rec.loop_active == std::vector<uint64_t>{3, 2, 2, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0});
  CHECK(rec.loop_idle == std::vector<uint64_t>{0, 1, 1, 2, 2, 2, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0});
  const FrameStats::ProgramTotals* t = gpu.stats().find("count to");
  REQUIRE(t);
  CHECK(t->loop_budget == 16);
  CHECK(t->loop_body_instructions == 3);
  CHECK(t->loop_active == rec.loop_active);
  CHECK(t->loop_idle == rec.loop_idle);
  CHECK_MESSAGE(gpu.stats().to_table().find(
                    "count to: loop of 16 iterations a pass, 7 batch iterations, 21 lane slots, "
                    "11 active, 10 idle (47.6%); longest lanes 7 iterations, waiting through 0 "
                    "fetches and 35 operations") != std::string::npos,
                gpu.stats().to_table());
}

TEST_CASE("the iteration budget stops every lane and the counters stop with it") {
  Gpu gpu(profile("gf6600"), 1, 4);
  KernelProgram<CountTo> p;
  p.kernel.budget = 4;
  const Texture in = row({1, 3, 7});
  Texture out("out", 3, 1, 4);
  const PassRecord rec = draw_count(gpu, p, in, out);
  CHECK(out.get(0, 0, 0) == 1.0f);
  CHECK(out.get(1, 0, 0) == 3.0f);
  CHECK(out.get(2, 0, 0) == 4.0f);  // cut at the budget
  CHECK(rec.counters.loop_iterations == 8);
  CHECK(rec.counters.loop_lane_slots == 12);
  CHECK(rec.counters.loop_lanes_idle == 4);
  CHECK(rec.loop_active == std::vector<uint64_t>{3, 2, 2, 1});
  CHECK(rec.loop_idle == std::vector<uint64_t>{0, 1, 1, 2});
}

TEST_CASE("loop batches follow the profile's branch granularity, not the host's lanes") {
  // rtx4090: 32-pixel batches, 8x4 tiles. Tile 0 holds 1, 3, 7 and five fragments that never
  // enter the loop; tile 1 eight fragments needing 2.
  const Texture in = row({1, 3, 7, 0, 0, 0, 0, 0, 2, 2, 2, 2, 2, 2, 2, 2});
  std::vector<PassRecord> recs;
  for (int lanes : {1, 4, 8, 16})
    for (int threads : {1, 3}) {
      CAPTURE(lanes);
      CAPTURE(threads);
      Gpu gpu(profile("rtx4090"), threads, lanes);
      KernelProgram<CountTo> p;
      Texture out("out", 16, 1, 4);
      recs.push_back(draw_count(gpu, p, in, out));
      for (int x = 0; x < 16; ++x) CHECK(out.get(x, 0, 0) == in.get(x, 0, 0));
    }
  const PassRecord& r = recs.front();
  CHECK(r.counters.loop_iterations == 27);
  CHECK(r.counters.loop_lane_slots == 8 * 7 + 8 * 2);
  CHECK(r.counters.loop_lanes_idle == 72 - 27);
  CHECK(r.counters.loop_batch_iterations == 7 + 2);
  CHECK(r.loop_active == std::vector<uint64_t>{11, 10, 2, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0});
  CHECK(r.loop_idle == std::vector<uint64_t>{5, 6, 6, 7, 7, 7, 7, 0, 0, 0, 0, 0, 0, 0, 0, 0});
  for (const PassRecord& o : recs) {
    CHECK(o.counters.same_counts(r.counters));
    CHECK(o.loop_active == r.loop_active);
    CHECK(o.loop_idle == r.loop_idle);
  }
}

TEST_CASE("a looping program is refused on profiles without data-dependent loops, by name") {
  for (const char* name : {"gf5700", "r300"}) {
    CAPTURE(name);
    const std::string e = refusal(profile(name), CountTo{});
    CHECK_MESSAGE(e.find("program 'count to'") != std::string::npos, e);
    CHECK_MESSAGE(e.find("no dynamic branching or loops") != std::string::npos, e);
    CHECK_MESSAGE(e.find(name) != std::string::npos, e);
  }
  CHECK(refusal(profile("gf6600"), CountTo{}).empty());
}

TEST_CASE("a loop past the profile's iteration limit is refused, by name") {
  CountTo k;
  k.budget = 256;
  const std::string e = refusal(profile("gf6600"), k);
  CHECK_MESSAGE(e.find("program 'count to' loops up to 256 iterations") != std::string::npos, e);
  CHECK_MESSAGE(e.find("gf6600 allows 255") != std::string::npos, e);
  k.budget = 255;
  CHECK(refusal(profile("gf6600"), k).empty());
}

TEST_CASE("a loop past the executed-instruction limit is refused, by name") {
  // 300 + 300 x 254 = 76500 executed instructions > gf6600's 65536.
  const std::string e = refusal(profile("gf6600"), LongBody{});
  CHECK_MESSAGE(
      e.find("program 'long body' executes up to 76500 instructions") != std::string::npos, e);
  LongBody ok;
  ok.budget = 200;  // 300 x 200 = 60000
  CHECK(refusal(profile("gf6600"), ok).empty());
}

TEST_CASE("a branch inside a loop body is refused, by name") {
  const std::string e = refusal(profile("gf6600"), BranchInLoop{});
  CHECK_MESSAGE(
      e.find("program 'branch in loop' branches inside its loop body") != std::string::npos, e);
}
