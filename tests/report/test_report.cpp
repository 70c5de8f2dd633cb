// Tests of the frame recorder and its outputs (host/report): its per-pass counts add up to the
// frame's statistics, a kept pixel's history is what --trace-pixel prints, the per-pixel maps
// agree with the passes, and the CSV, the HTML report and the stats diff are written as stated.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "host/accel/accel.h"
#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/report/counters_json.h"
#include "host/report/report.h"
#include "host/report/stats_json.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/scene/scene.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/support/lane_widths.h"

namespace {

struct Frame {
  host::RenderResult result;
  std::string trace;  // --trace-pixel output, when asked for
};

// sphere.gltf at 48x40 (not a multiple of the 8x4 and 32x32 tiles) with the recorder attached.
Frame render(host::FrameRecorder& rec, bool masks, std::optional<glm::ivec2> trace_pixel = {},
             int threads = 2, int lanes = vgpu::kLanes, bool looping = false) {
  static const host::Scene scene = host::load_scene(host::resolve_scene("sphere"));
  host::RenderOptions opt;
  if (looping) {  // the looping kernels need a profile with loops
    opt.looping = true;
    opt.profile = "h200";
  }
  opt.width = 48;
  opt.height = 40;
  opt.masks = masks;
  opt.threads = threads;
  opt.lanes = lanes;
  opt.observer = &rec;
  opt.keep_pass_records = true;  // the device's own record of every pass, to check against
  std::ostringstream trace;
  if (trace_pixel) {
    opt.trace_pixel = trace_pixel;
    opt.trace_out = &trace;
  }
  const host::Grid grid = host::build_grid(
      scene, host::grid_spec_for(host::GridSpec{}, scene, vgpu::profile(opt.profile)));
  host::StreamTracer tracer(scene, grid, opt);
  const host::Camera cam = host::scene_camera(scene, 1.2f);
  Frame f{tracer.render(cam), ""};
  rec.finish(f.result.stats);
  f.trace = trace.str();
  return f;
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("vgpu_test_report_" + name)).string();
}

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

}  // namespace

TEST_CASE("the recorder's passes plus what lies between them sum to the frame's statistics") {
  for (bool masks : {false, true}) {
    CAPTURE(masks);
    host::FrameRecorder rec(48, 40, masks, 0);
    const Frame f = render(rec, masks);
    const vgpu::FrameStats& s = f.result.stats;
    vgpu::Counters sum = rec.tail();
    for (const auto& p : rec.passes()) {
      sum += p.counters;
      sum += p.before;
      sum += p.after;
    }
    CHECK(sum.same_counts(s.totals));
    CHECK(rec.passes().size() == s.totals.passes);
  }
}

// The sum above holds whatever the recorder attributes to which pass (before and after are
// differences of the running totals). Here each pass's program load, clears, query and
// read-back, and its useful and idle fragments, come from the pass sequence itself: a load
// wherever the program changes, the frame's clears before generate rays (origins) and before
// each trace's entry pass (intersection and voxel state, the primary trace also the result),
// a query and a read-back after each counting pass; and the fragments with work to do from the
// device's own query results (rays walking after the last rayosEnGrilla, rays testing after the
// last rayosIntersectando).
TEST_CASE("each pass's program load, clears, read-back and useful fragments are its own") {
  namespace k = kernels;
  const uint64_t n = 48 * 40;
  const uint64_t clear_bytes = n * 4 * sizeof(float);  // every cleared texture: 4 x fp32 texels
  const uint64_t instruction_bytes = vgpu::profile("gf5700").instruction_bytes;
  for (bool masks : {false, true}) {
    CAPTURE(masks);
    host::FrameRecorder rec(48, 40, masks, 0);
    const Frame f = render(rec, masks);
    const vgpu::FrameStats& s = f.result.stats;
    const auto& passes = rec.passes();
    REQUIRE(passes.size() == s.passes.size());  // the device's own record of every pass
    REQUIRE(passes.size() > 20);
    uint64_t walking = 0, testing = 0;  // the last rayosEnGrilla / rayosIntersectando results
    size_t loads = 0, clears = 0, readbacks = 0, masked_passes = 0, entries = 0;
    for (size_t i = 0; i < passes.size(); ++i) {
      const auto& p = passes[i];
      const std::string& prev = i ? passes[i - 1].program : std::string();
      CAPTURE(i);
      CAPTURE(p.program);
      REQUIRE(p.program == s.passes[i].program);
      const bool counting = p.program == k::RaysInGrid::name ||
                            p.program == k::RaysIntersecting::name ||
                            p.program == k::ReflectedRays::name;
      const bool entry =
          p.program == k::InitTraversal::name || p.program == k::ResetTraversal::name;
      if (entry) {  // a trace begins with its entry pass
        REQUIRE(entries < rec.traces().size());
        CHECK(rec.traces()[entries].first_pass == int(i));
        ++entries;
      }
      // Before the pass: a program load where the program changes, and the frame's clears.
      vgpu::Counters before;
      if (p.program != prev) {
        const vgpu::FrameStats::ProgramTotals* prog = s.find(p.program);
        REQUIRE(prog != nullptr);
        before.program_loads = 1;
        before.program_bytes = uint64_t(prog->instructions) * instruction_bytes;
      }
      before.clears = p.program == k::GenerateRays::name    ? 1
                      : p.program == k::InitTraversal::name ? 3
                      : entry                               ? 2
                                                            : 0;
      before.bytes_written = before.clears * clear_bytes;
      // After it: a counting pass's query and its read-back, nothing else.
      vgpu::Counters after;
      after.queries = after.query_readbacks = counting;
      CHECK(p.before.same_counts(before));
      CHECK(p.after.same_counts(after));
      CHECK(p.counters.passes == 1);
      CHECK(p.counters.program_loads + p.counters.clears + p.counters.query_readbacks == 0);
      CHECK(p.query == (counting ? s.passes[i].query_result : -1));
      loads += p.before.program_loads;
      clears += p.before.clears;
      readbacks += p.after.query_readbacks;
      // The fragments with work: rays walking for the walk's passes over the grid mask, rays
      // testing for the triangle loop's; every fragment for the others (a trace's first
      // rayosEnGrilla, right after its entry pass, counts every ray).
      const bool after_entry = prev == k::InitTraversal::name || prev == k::ResetTraversal::name;
      const bool grid_mask =
          (p.program == k::RaysInGrid::name && !after_entry) || p.program == k::UpdateVoxel::name ||
          p.program == k::Traversal::name ||
          (p.program == k::RaysIntersecting::name && prev == k::UpdateVoxel::name);
      const bool isect_mask =
          p.program == k::Intersections::name || p.program == k::NextTriangle::name ||
          (p.program == k::RaysIntersecting::name && prev == k::NextTriangle::name);
      const uint64_t useful = grid_mask ? walking : isect_mask ? testing : n;
      masked_passes += grid_mask || isect_mask;
      CHECK((p.work_mask >= 0) == (grid_mask || isect_mask));
      CHECK(p.counters.fragments_launched == n);
      CHECK(p.useful == useful);
      if (masks) {  // fragments without work are masked (early z), not shaded
        CHECK(p.counters.fragments_shaded == useful);
        CHECK(p.counters.fragments_masked == n - useful);
        CHECK(p.idle == 0);
      } else {  // every fragment runs; those without work idle
        CHECK(p.counters.fragments_shaded == n);
        CHECK(p.counters.fragments_masked == 0);
        CHECK(p.idle == n - useful);
      }
      if (p.program == k::RaysInGrid::name) walking = uint64_t(s.passes[i].query_result);
      if (p.program == k::RaysIntersecting::name) testing = uint64_t(s.passes[i].query_result);
    }
    // Nothing after the last pass, and the counts above are the frame's.
    CHECK(rec.tail().same_counts(vgpu::Counters{}));
    CHECK(loads == s.totals.program_loads);
    CHECK(clears == s.totals.clears);
    CHECK(readbacks == s.totals.query_readbacks);
    CHECK(entries == rec.traces().size());
    CHECK(entries >= 3);  // primary, its shadow rays and a reflected trace at least
    CHECK(masked_passes > 10);
    CHECK(loads > entries);
  }
}

TEST_CASE(
    "the per-pixel cost maps and the wavefront hold each pixel's passes as --trace-pixel prints "
    "them") {
  // Off the 8x4 and 32x32 tile grids and off the diagonal (a transposed index reads another
  // pixel): on the sphere, at its rim and off it.
  const glm::ivec2 pixels[] = {{21, 17}, {30, 12}, {9, 33}, {44, 3}};
  uint64_t stepped = 0, tested = 0, idled = 0;
  for (const glm::ivec2 px : pixels) {
    CAPTURE(px.x);
    CAPTURE(px.y);
    host::FrameRecorder rec(48, 40, false, 0);
    const Frame f = render(rec, false, px);
    // The passes the pixel took part in, by paper name, one line each; a trace begins with its
    // entry pass (initTraversal, reinicializarTraversal), which runs on every pixel.
    std::vector<std::string> kernels_run;
    std::vector<size_t> trace_steps;  // traversal passes per trace
    std::istringstream lines(f.trace);
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind("  ", 0) != 0) continue;  // "pixel X,Y:", "iteration N:"
      std::istringstream words(line);
      std::string paper;
      words >> paper;
      kernels_run.push_back(paper);
      if (paper == kernels::InitTraversal::paper_name ||
          paper == kernels::ResetTraversal::paper_name)
        trace_steps.push_back(0);
      if (paper == kernels::Traversal::paper_name) {
        REQUIRE(!trace_steps.empty());
        ++trace_steps.back();
      }
    }
    const auto ran = [&](const char* paper) {
      return uint64_t(std::count(kernels_run.begin(), kernels_run.end(), paper));
    };
    const size_t i = size_t(px.y) * 48 + size_t(px.x);
    REQUIRE(rec.voxel_steps().size() == 48 * 40);
    CHECK(rec.voxel_steps()[i] == ran(kernels::Traversal::paper_name));
    CHECK(rec.triangle_tests()[i] == ran(kernels::Intersections::paper_name));
    // Every pass without a work mask runs on every pixel: the passes it sat out are the idle ones.
    CHECK(rec.idle_passes()[i] == f.result.stats.totals.passes - kernels_run.size());
    REQUIRE(trace_steps.size() == rec.traces().size());
    REQUIRE(rec.wavefront().size() == rec.traces().size());
    for (size_t tr = 0; tr < trace_steps.size(); ++tr) {
      CAPTURE(tr);
      CHECK(rec.wavefront()[tr][i] == trace_steps[tr]);
    }
    stepped += rec.voxel_steps()[i];
    tested += rec.triangle_tests()[i];
    idled += rec.idle_passes()[i];
  }
  CHECK(stepped > 0);
  CHECK(tested > 0);
  CHECK(idled > 0);
}

TEST_CASE("the per-pixel cost maps add up to the useful fragments of their kernels") {
  host::FrameRecorder rec(48, 40, false, 0);
  const Frame f = render(rec, false);
  const vgpu::FrameStats& s = f.result.stats;
  REQUIRE(rec.passes().size() == s.passes.size());
  uint64_t trav = 0, isect = 0, idle = 0;
  for (const auto& p : rec.passes()) {
    if (p.program == kernels::Traversal::name) trav += p.useful;
    if (p.program == kernels::Intersections::name) isect += p.useful;
    if (p.work_mask >= 0) idle += p.idle;
  }
  uint64_t v = 0, t = 0, i = 0;
  for (size_t k = 0; k < rec.voxel_steps().size(); ++k) {
    v += rec.voxel_steps()[k];
    t += rec.triangle_tests()[k];
    i += rec.idle_passes()[k];
  }
  CHECK(v == trav);
  CHECK(t == isect);
  CHECK(i == idle);
  CHECK(v > 0);
  CHECK(t > 0);
  // The wavefront: the rays walking after step k of a trace are those with more than k steps,
  // so its counts are the device's query results (its own pass records, not the recorder's),
  // one rayosEnGrilla before the first step and one after each, the last 0.
  REQUIRE(rec.traces().size() >= 3);
  REQUIRE(rec.wavefront().size() == rec.traces().size());
  size_t checked = 0;
  for (size_t tr = 0; tr < rec.traces().size(); ++tr) {
    CAPTURE(tr);
    std::vector<int64_t> queries;
    for (size_t k = 0; k < rec.passes().size(); ++k)
      if (rec.passes()[k].trace == int(tr) && s.passes[k].program == kernels::RaysInGrid::name)
        queries.push_back(s.passes[k].query_result);
    REQUIRE(queries.size() == size_t(rec.traces()[tr].steps) + 1);
    CHECK(queries.back() == 0);
    for (size_t k = 0; k < queries.size(); ++k) {
      CAPTURE(k);
      int64_t walking = 0;
      for (uint16_t st : rec.wavefront()[tr]) walking += st > k;
      CHECK(walking == queries[k]);
      ++checked;
    }
  }
  CHECK(rec.traces()[0].steps > 10);  // the primary rays cross the grid
  CHECK(checked > rec.traces().size() + 10);
}

TEST_CASE("a kept pixel's history holds the states --trace-pixel prints, in order") {
  const glm::ivec2 px{21, 17};  // off the sample grid: kept because it is traced
  host::FrameRecorder rec(48, 40, false, 16, {px});
  const Frame f = render(rec, false, px);
  const auto& pixels = rec.history_pixels();
  const size_t k = size_t(std::find(pixels.begin(), pixels.end(), px) - pixels.begin());
  REQUIRE(k < pixels.size());
  CHECK(pixels.size() == 3 * 3 + 1);  // x in {0, 16, 32}, y in {0, 16, 32}, and px
  // Every "-> target (a, b, c, d)" line, as floats.
  std::vector<float> printed;
  std::istringstream lines(f.trace);
  for (std::string line; std::getline(lines, line);) {
    const size_t open = line.find(" (", line.find("->"));
    if (line.find("->") == std::string::npos || open == std::string::npos) continue;
    std::istringstream nums(line.substr(open + 2));
    for (std::string n; std::getline(nums, n, ',');) printed.push_back(std::stof(n));
  }
  const std::vector<float>& kept = rec.history_states()[k];
  REQUIRE(printed.size() == kept.size());
  REQUIRE(printed.size() > 40);
  for (size_t i = 0; i < kept.size(); ++i) {
    CAPTURE(i);
    CHECK(printed[i] == doctest::Approx(kept[i]).epsilon(1e-5));
  }
}

TEST_CASE("the stats CSV has a header and one row per pass, and the report carries the data") {
  host::FrameRecorder rec(48, 40, false);
  const Frame f = render(rec, false);
  const std::string csv = temp_path("passes.csv"), html = temp_path("frame.html");
  host::write_stats_csv(csv, rec);
  std::istringstream rows(slurp(csv));
  std::string header, line;
  std::getline(rows, header);
  CHECK(header.rfind("index,kernel,paper_name,iteration", 0) == 0);
  size_t n = 0;
  while (std::getline(rows, line)) {
    CHECK(line.rfind(std::to_string(n) + ",", 0) == 0);
    ++n;
  }
  CHECK(n == f.result.stats.totals.passes);

  nlohmann::ordered_json run = host::frame_counters_json(f.result.stats);
  host::write_report(html, rec, f.result, run);
  const std::string page = slurp(html);
  CHECK(page.find("@REPORT_DATA@") == std::string::npos);
  CHECK(page.find("/*@CHART_JS@*/") == std::string::npos);
  CHECK(page.find("\"mask_count\":") != std::string::npos);
  std::remove(csv.c_str());
  std::remove(html.c_str());
}

TEST_CASE("an output in a missing directory or with the wrong extension is refused up front") {
  CHECK_THROWS_WITH_AS(host::check_output_path("/no/such/dir/r.html", {".html"}),
                       doctest::Contains("does not exist"), host::InputError);
  CHECK_THROWS_WITH_AS(host::check_output_path(temp_path("r.htm"), {".html"}),
                       doctest::Contains("unsupported extension '.htm'"), host::InputError);
  CHECK_NOTHROW(host::check_output_path(temp_path("r.HTML"), {".html"}));
}

TEST_CASE("diff shows each counter of two stats files, B - A and B / A, and refuses other JSON") {
  const std::string a = temp_path("a.json"), b = temp_path("b.json"), bad = temp_path("bad.json");
  std::ofstream(a) << R"({"masks": false, "totals": {"passes": 10, "fragments_shaded": 400},
    "kernels": [{"name": "traversal", "paper_name": "traversal", "passes": 4}]})";
  std::ofstream(b) << R"({"masks": true, "totals": {"passes": 10, "fragments_shaded": 100},
    "kernels": [{"name": "traversal", "paper_name": "traversal", "passes": 4},
                {"name": "shader", "paper_name": "shader", "passes": 1}]})";
  std::ofstream(bad) << R"({"scene": "x"})";
  const std::string d = host::diff_stats(a, b);
  CHECK(d.find("differs: masks false -> true") != std::string::npos);
  CHECK(d.find("-300") != std::string::npos);                    // fragments_shaded, B - A
  CHECK(d.find("0.250") != std::string::npos);                   // fragments_shaded, B / A
  CHECK(d.find("kernel shader (shader)") != std::string::npos);  // only B ran it
  CHECK_THROWS_WITH_AS(host::diff_stats(a, bad), doctest::Contains("not a vgpu-rt --stats-json"),
                       host::InputError);
  CHECK_THROWS_WITH_AS(host::diff_stats(temp_path("none.json"), a),
                       doctest::Contains("cannot open"), host::InputError);
  for (const std::string& p : {a, b, bad}) std::remove(p.c_str());
}

TEST_CASE("a counts-only recorder (the CSV's) records the same passes and keeps no pixels") {
  host::FrameRecorder full(48, 40, false), counts(48, 40, false, 8, {}, false);
  render(full, false);
  render(counts, false);
  REQUIRE(counts.passes().size() == full.passes().size());
  for (size_t i = 0; i < full.passes().size(); ++i) {
    CAPTURE(i);
    CHECK(counts.passes()[i].useful == full.passes()[i].useful);
    CHECK(counts.passes()[i].idle == full.passes()[i].idle);
    CHECK(counts.passes()[i].query == full.passes()[i].query);
    CHECK(counts.passes()[i].work_mask == -1);
  }
  CHECK(counts.masks().empty());
  CHECK(counts.voxel_steps().empty());
  CHECK(counts.history_pixels().empty());
  CHECK(!full.masks().empty());
}

TEST_CASE("what the recorder sees is the same for any thread count and lane width") {
  host::FrameRecorder a(48, 40, false), b(48, 40, false);
  render(a, false, {}, 1, 1);
  render(b, false, {}, 3, test_support::kernel_width_built(16) ? 16 : 8);
  REQUIRE(a.passes().size() == b.passes().size());
  for (size_t i = 0; i < a.passes().size(); ++i) {
    CAPTURE(i);
    CHECK(a.passes()[i].counters.same_counts(b.passes()[i].counters));
    CHECK(a.passes()[i].useful == b.passes()[i].useful);
    CHECK(a.passes()[i].work_mask == b.passes()[i].work_mask);
  }
  CHECK(a.masks() == b.masks());
  CHECK(a.voxel_steps() == b.voxel_steps());
  CHECK(a.triangle_tests() == b.triangle_tests());
  CHECK(a.wavefront() == b.wavefront());
  CHECK(a.history_states() == b.history_states());
  REQUIRE(a.occupancy().size() == b.occupancy().size());
  for (size_t k = 0; k < a.occupancy().size(); ++k) {
    CAPTURE(a.occupancy()[k].first);
    CHECK(a.occupancy()[k].second.tile8x4 == b.occupancy()[k].second.tile8x4);
    CHECK(a.occupancy()[k].second.tile32x32 == b.occupancy()[k].second.tile32x32);
  }
}

TEST_CASE("the loop iterations map adds up to the looping kernels' iterations, pixel by pixel") {
  host::FrameRecorder rec(48, 40, false, 0);
  const Frame f = render(rec, false, {}, 2, vgpu::kLanes, true);
  const vgpu::FrameStats& s = f.result.stats;
  uint64_t sum = 0;
  for (const uint32_t v : rec.loop_iterations()) sum += v;
  REQUIRE(s.totals.loop_iterations > 0);
  CHECK(sum == s.totals.loop_iterations);
  // Rays through the sphere walk and test more than rays past it.
  const auto [lo, hi] =
      std::minmax_element(rec.loop_iterations().begin(), rec.loop_iterations().end());
  CHECK(*hi > *lo);
  // A multipass frame has none.
  host::FrameRecorder multi(48, 40, false, 0);
  render(multi, false);
  for (const uint32_t v : multi.loop_iterations()) CHECK(v == 0);
}

TEST_CASE(
    "the stats JSON counts beams on every engine, the CPU tracer's steps too, and only "
    "with beams on") {
  const host::Scene scene = host::load_scene(host::resolve_scene("sphere-alone"));
  const std::unique_ptr<host::Accel> accel =
      host::make_accel(host::AccelKind::grid, scene, host::AccelParams{});
  const std::string path = "sphere-alone.gltf", words = "-";
  host::RenderResult r;
  r.width = r.height = 16;
  r.beam_passes = 7;
  r.beam_tiles = 4;
  r.beam_tiles_missed = 1;
  host::CpuStats cpu;
  cpu.beam_steps = 11;
  for (const std::string engine : {"stream", "gl", "cpu"})
    for (const bool beams : {false, true}) {
      CAPTURE(engine);
      CAPTURE(beams);
      host::RenderOptions opt;
      opt.width = opt.height = 16;
      opt.beams = beams;
      const nlohmann::ordered_json j =
          host::frame_stats_json({scene, path, engine, nullptr, *accel, nullptr, opt, r, cpu, words,
                                  words, words, words, 0.0});
      REQUIRE(j.contains("beams") == beams);
      if (!beams) continue;
      const auto& b = j["beams"];
      CHECK(b["passes"] == 7);
      CHECK(b["tiles"] == 4);
      CHECK(b["tiles_missed"] == 1);
      CHECK(b.contains("steps") == (engine == "cpu"));
      if (engine == "cpu") CHECK(b["steps"] == 11);
    }
}
