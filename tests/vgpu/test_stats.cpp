// Statistics: exact counts for known passes, program loads, and the JSON and table reports.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "helpers.h"
#include "tests/support/known_pass.h"
#include "vgpu/vgpu.h"

using namespace vgpu;
using test_support::Add3;
using test_support::Known;
using test_support::known_pass;

namespace {

// Two outputs of different shapes: 16 + 4 bytes per surviving fragment into fp32x4 and fp16x2.
struct Split {
  static constexpr const char* name = "split";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 2;
  template <class L>
  void operator()(Fragments<L>& f) const {
    const auto v = f.fetch_own(0);
    f.out(0) = v;
    f.out(1) = {v.x * v.y, v.z, v.w, v.w};
  }
};

// Own texels of unit 0 and unit 2 (one texture bound to both in the test) and two fetches of
// texel (0, 0) of unit 1.
struct Gather {
  static constexpr const char* name = "gather";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const auto a = f.fetch_own(0), b = f.fetch_own(2);
    const auto t = f.fetch(1, F(0.0f), F(0.0f)), u = f.fetch(1, F(0.0f), F(0.0f));
    f.out(0) = {a.x + b.x, t.y + u.y, a.z, b.w};
  }
};

}  // namespace

TEST_CASE("a 64x64 pass of three fp32x4 fetches counts 12288 fetches and 196608 bytes read") {
  for (int lanes : {1, 8, 16})
    for (int threads : {1, 2}) {
      CAPTURE(lanes);
      CAPTURE(threads);
      const Counters c = known_pass(threads, lanes).pass;
      CHECK(c.passes == 1);
      CHECK(c.fragments_launched == 4096);
      CHECK(c.fragments_shaded == 4096);
      CHECK(c.fragments_masked == 0);
      CHECK(c.fragments_discarded == 0);
      CHECK(c.lanes_idle == 0);
      CHECK(c.texture_fetches == 12288);
      CHECK(c.bytes_read == 196608);
      CHECK(c.bytes_written == 4096 * 16);
      CHECK(c.instructions == 5 * 4096);  // static count x shaded fragments
      CHECK(c.program_loads == 0);        // the load belongs to use_program, not the pass
      CHECK(c.host_ms >= 0.0);
    }
}

TEST_CASE("fp16 textures halve the bytes written and read") {
  const Counters half_target = known_pass(1, 8, Format::fp16).pass;
  CHECK(half_target.bytes_written == 4096 * 8);
  CHECK(half_target.bytes_read == 196608);
  const Counters half_sources = known_pass(1, 8, Format::fp32, Format::fp16).pass;
  CHECK(half_sources.bytes_read == 196608 / 2);
  CHECK(half_sources.bytes_written == 4096 * 16);
  const Counters fp24 = known_pass(1, 8, Format::fp24, Format::fp24).pass;  // 32-bit texels
  CHECK(fp24.bytes_read == 196608);
  CHECK(fp24.bytes_written == 4096 * 16);
}

TEST_CASE("multiple render targets add their texel sizes to the bytes written") {
  Gpu gpu(profile("gf6600"), 1);
  Texture in = gpu.make_texture("in", 10, 10, 4), o0 = gpu.make_texture("o0", 10, 10, 4),
          o1 = gpu.make_texture("o1", 10, 10, 2, Format::fp16);
  KernelProgram<Split> split;
  gpu.use_program(split);
  gpu.bind_texture(0, in);
  gpu.set_targets({&o0, &o1});
  const Counters c = gpu.draw(Rect{0, 0, 10, 5}).counters;
  CHECK(c.bytes_written == 50 * (16 + 4));
  CHECK(c.bytes_read == 50 * 16);
  CHECK(c.instructions == 50 * 2);  // a fetch and a multiply
}

TEST_CASE("a pass's footprint counts each texture once, at most its size, and its drawn targets") {
  Gpu gpu(profile("gf6600"), 1);
  // in: 10x10 fp32x4, 1600 B, on units 0 and 2; table: 2x2 fp32x4, 64 B; out: 10x10 fp32x4.
  Texture in = gpu.make_texture("in", 10, 10, 4), table = gpu.make_texture("table", 2, 2, 4),
          out = gpu.make_texture("out", 10, 10, 4);
  KernelProgram<Gather> gather;
  gpu.use_program(gather);
  gpu.bind_texture(0, in);
  gpu.bind_texture(1, table);
  gpu.bind_texture(2, in);
  gpu.set_targets({&out});
  // 10x8 = 80 fragments: 2 x 80 x 16 = 2560 B fetched of in, capped at its 1600 B; 2 x 80 x 16
  // of table, capped at 64 B; 80 x 16 = 1280 B of the target.
  const Counters c = gpu.draw(Rect{0, 0, 10, 8}).counters;
  CHECK(c.bytes_read == 80 * 4 * 16);
  CHECK(c.footprint_bytes == 1600 + 64 + 1280);
  // 2x2 = 4 fragments: 128 B of in, the 64 B table, 64 B of the target.
  CHECK(gpu.draw(Rect{0, 0, 2, 2}).counters.footprint_bytes == 128 + 64 + 64);
}

TEST_CASE("a frame stops with BudgetError at the first pass its stop condition holds for") {
  Gpu gpu(profile("gf6600"), 1);
  Texture in = gpu.make_texture("in", 4, 4, 4), out = gpu.make_texture("out", 4, 4, 4);
  KernelProgram<vgpu_test::Copy> copy;
  gpu.use_program(copy);
  gpu.bind_texture(0, in);
  gpu.set_targets({&out});
  uint64_t seen = 0;  // the passes the condition was asked about
  gpu.set_stop_when([&](const Counters& t) {
    seen = t.passes;
    return t.fragments_shaded > 2 * 16;
  });
  gpu.draw();
  gpu.draw();
  CHECK(seen == 2);
  CHECK_THROWS_AS(gpu.draw(), BudgetError);  // the third pass: 48 fragments
  CHECK(seen == 3);
  CHECK(gpu.stats().totals.passes == 3);  // counted, then stopped
  try {
    gpu.draw();
    FAIL("the fourth pass ran");
  } catch (const Error& e) {  // a vgpu::Error, naming the passes
    CHECK(std::string(e.what()).find("after 4 passes") != std::string::npos);
  }
  gpu.set_stop_when({});
  gpu.draw();
  CHECK(gpu.stats().totals.passes == 5);
}

TEST_CASE("a program load is counted only when the program changes, at 16 bytes an instruction") {
  Gpu gpu(profile("gf5700"), 1);
  KernelProgram<Add3> add3;
  KernelProgram<vgpu_test::Copy> copy;
  gpu.use_program(add3);
  gpu.use_program(add3);
  CHECK(gpu.stats().totals.program_loads == 1);
  CHECK(gpu.stats().totals.program_bytes == 5 * 16);
  gpu.use_program(copy);
  gpu.use_program(add3);
  gpu.use_program(add3);
  CHECK(gpu.stats().totals.program_loads == 3);
  CHECK(gpu.stats().totals.program_bytes == (5 + 1 + 5) * 16);
  CHECK(gpu.stats().find("add3")->counters.program_loads == 2);
  CHECK(gpu.stats().find("add3")->counters.program_bytes == 2 * 5 * 16);
  CHECK(gpu.stats().find("copy")->counters.program_loads == 1);
  CHECK(gpu.stats().find("copy")->instructions == 1);
  // A second program object of the same kernel is another program: loading it counts.
  KernelProgram<Add3> again;
  gpu.use_program(again);
  CHECK(gpu.stats().totals.program_loads == 4);
}

TEST_CASE("passes are recorded one by one and summed per program and per frame") {
  Gpu gpu(profile("gf5700"), 1);
  Texture a = gpu.make_texture("a", 16, 8, 4), b = gpu.make_texture("b", 16, 8, 4);
  KernelProgram<Add3> add3;
  KernelProgram<vgpu_test::Copy> copy;
  gpu.use_program(add3);
  gpu.bind_texture(0, a);
  gpu.bind_texture(1, a);
  gpu.bind_texture(2, a);
  gpu.set_targets({&b});
  gpu.draw();
  gpu.draw(Rect{0, 0, 4, 4});
  gpu.unbind_textures();
  gpu.use_program(copy);
  gpu.bind_texture(0, b);
  gpu.set_targets({&a});
  gpu.draw();
  const FrameStats& s = gpu.stats();
  REQUIRE(s.passes.size() == 3);
  CHECK(s.passes[0].program == "add3");
  CHECK(s.passes[1].width == 4);
  CHECK(s.passes[1].counters.fragments_shaded == 16);
  CHECK(s.passes[2].program == "copy");
  REQUIRE(s.programs.size() == 2);
  CHECK(s.programs[0].name == "add3");  // in order of first use
  CHECK(s.programs[0].paper_name == "intersecciones");
  CHECK(s.programs[0].instructions == 5);
  CHECK(s.programs[0].counters.passes == 2);
  CHECK(s.programs[0].counters.texture_fetches == 3 * (128 + 16));
  CHECK(s.programs[1].counters.texture_fetches == 128);
  CHECK(s.totals.passes == 3);
  CHECK(s.totals.fragments_shaded == 128 + 16 + 128);
  CHECK(s.totals.instructions == 5 * (128 + 16) + 128);
  CHECK(s.totals.bytes_read == 16 * (3 * (128 + 16) + 128));
  CHECK(s.find("nothing") == nullptr);

  Counters sum;
  for (const PassRecord& p : s.passes) sum += p.counters;
  sum.program_loads = s.totals.program_loads;
  sum.program_bytes = s.totals.program_bytes;
  CHECK(sum.same_counts(s.totals));

  // Without pass records a long render keeps only the totals; draw still reports the pass.
  gpu.stats().clear();
  CHECK(gpu.stats().totals.passes == 0);
  CHECK(gpu.stats().programs.empty());
  gpu.stats().keep_pass_records = false;
  CHECK(gpu.draw().counters.fragments_shaded == 128);
  CHECK(gpu.stats().passes.empty());
  CHECK(gpu.stats().totals.passes == 1);
}

TEST_CASE("same_counts compares every integer counter and ignores host time") {
  Counters a, b;
  a.bytes_read = 7;
  a.host_ms = 1.0;
  b.bytes_read = 7;
  b.host_ms = 2.0;
  CHECK(a.same_counts(b));
  b.query_readbacks = 1;
  CHECK_FALSE(a.same_counts(b));
  a += b;
  CHECK(a.bytes_read == 14);
  CHECK(a.query_readbacks == 1);
  CHECK(a.host_ms == 3.0);
}

TEST_CASE("the table report has a row for every program and the total") {
  Gpu gpu(profile("gf6600"), 1);
  Texture a = gpu.make_texture("a", 8, 8, 4), b = gpu.make_texture("b", 8, 8, 4);
  KernelProgram<Add3> add3;
  KernelProgram<vgpu_test::Copy> copy;
  KernelProgram<vgpu_test::Lookup> lookup;
  for (const Program* p : {static_cast<const Program*>(&add3), static_cast<const Program*>(&copy),
                           static_cast<const Program*>(&lookup)}) {
    gpu.use_program(*p);
    for (int u = 0; u < 3; ++u) gpu.bind_texture(u, a);
    gpu.set_targets({&b});
    gpu.draw();
  }
  const std::string table = gpu.stats().to_table();
  for (const char* name : {"add3", "intersecciones", "copy", "lookup", "total", "kernel"}) {
    CAPTURE(name);
    CHECK(table.find(name) != std::string::npos);
  }
  int lines = 0;
  for (char ch : table) lines += ch == '\n';
  CHECK(lines == 1 + 3 + 1);  // header, programs, total
}

TEST_CASE("the table's name columns widen to the longest name, so every row stays aligned") {
  vgpu::FrameStats s;
  s.program("intersections + next triangle", "intersecciones+proximoTriangulo", 148)
      .counters.passes = 3;
  s.program("copy", "copia", 2).counters.passes = 12345;
  s.totals.passes = 12348;
  const std::string table = s.to_table();
  std::vector<size_t> widths;
  size_t from = 0;
  for (size_t nl; (nl = table.find('\n', from)) != std::string::npos; from = nl + 1)
    widths.push_back(nl - from);
  REQUIRE(widths.size() == 4);                    // header, two programs, total
  for (size_t w : widths) CHECK(w == widths[0]);  // fixed-width columns: equal rows, aligned
}
