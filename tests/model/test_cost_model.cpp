// Tests for host/cost_model: known counters give the hand-computed time of every term; more
// passes never predict less; masked fragments and skipped branches lower the arithmetic; the
// what-if transforms keep the work and drop passes or loads.
#include <doctest/doctest.h>

#include "host/accel/grid.h"
#include "host/model/cost_model.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"

namespace {

// A small made-up card with round numbers: 4 pipes at 100 MHz, 1 GB/s, 1000 MB/s bus.
vgpu::Profile card() {
  vgpu::Profile p;
  p.name = "test";
  p.pipelines = 4;
  p.core_mhz = 100;
  p.mem_gbps = 1;
  p.bus_mbps = 1000;
  p.precision = vgpu::Format::fp32;
  p.alu_lanes = 4;
  p.alu_per_clock = 1;
  p.fp32_rate = 0.5;
  p.texels_per_clock = 1;
  p.branching = vgpu::Branching::none;
  return p;
}

host::CostParams params() {
  host::CostParams c;
  c.scalar_ops_per_instruction = 3;
  c.branch_body_share = 0.75;
  c.pass_us = 10;
  c.program_load_us = 20;
  c.readback_us = 40;
  return c;
}

// `passes` passes of one program over 4000 fragments each: 31 counted operations (one of them a
// 16-byte fetch) and a 16-byte write per fragment; `idle` fragments a pass are finished rays.
vgpu::Counters kernel_passes(uint64_t passes, uint64_t idle = 1000, uint64_t masked = 0) {
  vgpu::Counters c;
  c.passes = passes;
  c.fragments_launched = 4000 * passes;
  c.fragments_masked = masked * passes;
  c.fragments_shaded = c.fragments_launched - c.fragments_masked;
  c.lanes_idle = (idle - masked) * passes;
  c.instructions = 31 * c.fragments_shaded;
  c.texture_fetches = c.fragments_shaded;
  c.bytes_read = 16 * c.fragments_shaded;
  c.bytes_written = 16 * c.fragments_shaded;
  c.program_loads = passes;
  c.program_bytes = 496 * passes;  // 31 instructions x 16 bytes
  return c;
}

vgpu::FrameStats frame(const vgpu::Counters& k, uint64_t readbacks = 1,
                       uint64_t clear_bytes = 100000) {
  vgpu::FrameStats s;
  s.keep_pass_records = false;
  s.program("kernel", "kernel", 31).counters = k;
  s.totals = k;
  s.totals.queries = s.totals.query_readbacks = readbacks;
  s.totals.clears = 1;
  s.totals.bytes_written += clear_bytes;
  return s;
}

}  // namespace

TEST_CASE("Known counters give the hand-computed time of every term") {
  const host::CostBreakdown b = host::predict(frame(kernel_passes(2)), card(), params());
  // Per pass: 4000 x 30 operations / 3 per instruction = 40000 instructions over
  // 4 pipes x 1e8 Hz x 0.5 (fp32) = 200 us; texture 4000 / 4e8 = 10 us;
  // memory 128000 B / 1e9 B/s = 128 us.
  CHECK(b.arithmetic_demand_ms == doctest::Approx(0.400));
  CHECK(b.texture_demand_ms == doctest::Approx(0.020));
  CHECK(b.memory_demand_ms == doctest::Approx(0.256 + 0.100));  // passes + the clear
  CHECK(b.arithmetic_ms == doctest::Approx(0.400));             // both passes ALU bound
  CHECK(b.texture_ms == doctest::Approx(0.0));
  CHECK(b.memory_ms == doctest::Approx(0.100));                   // the clear: 100000 B / 1 GB/s
  CHECK(b.per_pass_ms == doctest::Approx(0.020));                 // 2 x 10 us
  CHECK(b.program_load_ms == doctest::Approx(0.000992 + 0.040));  // 992 B at 1000 MB/s + 2 x 20 us
  CHECK(b.readback_ms == doctest::Approx(0.040));
  CHECK(b.wasted_ms == doctest::Approx(0.100));  // a quarter of the fragments were finished
  CHECK(b.total_ms == doctest::Approx(0.400 + 0.100 + 0.020 + 0.040992 + 0.040));
}

TEST_CASE("Texel-byte and output-byte rates bound a pass where a profile gives them") {
  // Two passes of 4000 fragments reading and writing 16 B each: 64000 B a pass.
  vgpu::Profile hw = card();
  hw.mem_gbps = 1000;  // memory out of the way: 128 ns a pass
  const host::CostBreakdown before = host::predict(frame(kernel_passes(2), 1, 0), hw, params());
  CHECK(before.arithmetic_ms == doctest::Approx(0.400));  // ALU bound, as above
  // 4 texel bytes a clock at 100 MHz: 64000 B / 4e8 B/s = 160 us a pass, still under the ALU.
  hw.texture_bytes_per_clock = 4;
  const host::CostBreakdown tex = host::predict(frame(kernel_passes(2), 1, 0), hw, params());
  CHECK(tex.texture_demand_ms == doctest::Approx(0.320));
  CHECK(tex.arithmetic_ms == doctest::Approx(0.400));
  // 1 output byte a clock: 64000 B / 1e8 B/s = 640 us a pass, now the bound (memory term).
  hw.output_bytes_per_clock = 1;
  const host::CostBreakdown rop = host::predict(frame(kernel_passes(2), 1, 0), hw, params());
  CHECK(rop.memory_ms == doctest::Approx(1.280));
  CHECK(rop.arithmetic_ms == doctest::Approx(0.0));
  CHECK(rop.total_ms == doctest::Approx(1.280 + 0.020 + 0.040992 + 0.040));
}

TEST_CASE("a pass whose footprint is larger than the profile's L2 fetches at the spilled rate") {
  // Two passes of 4000 fragments reading and writing 16 B each: a footprint of 128000 B a pass.
  vgpu::Counters k = kernel_passes(2);
  k.footprint_bytes = 2 * 128000;
  vgpu::Profile hw = card();
  hw.mem_gbps = 1000;              // memory out of the way
  hw.texture_bytes_per_clock = 1;  // 64000 B at 1e8 B/s: 640 us a pass, over the ALU's 200
  const host::CostBreakdown none = host::predict(frame(k, 1, 0), hw, params());
  CHECK(none.texture_ms == doctest::Approx(1.280));
  CHECK(none.l2_spill_ms == 0.0);
  hw.l2_bytes = 128000;  // the footprint just fits: the in-cache rate
  hw.texture_spilled_bytes_per_clock = 0.5;
  const host::CostBreakdown fits = host::predict(frame(k, 1, 0), hw, params());
  CHECK(fits.texture_ms == doctest::Approx(1.280));
  CHECK(fits.l2_spill_ms == 0.0);
  hw.l2_bytes = 127999;  // one byte over: 0.5 B a clock, 1280 us a pass
  const host::CostBreakdown spills = host::predict(frame(k, 1, 0), hw, params());
  CHECK(spills.texture_ms == doctest::Approx(2.560));
  CHECK(spills.l2_spill_ms == doctest::Approx(1.280));
  CHECK(spills.total_ms == doctest::Approx(fits.total_ms + 1.280));
  // Averaged per pass: the same footprint over four passes is 64000 B a pass, inside the L2.
  vgpu::Counters four = kernel_passes(4);
  four.footprint_bytes = k.footprint_bytes;
  CHECK(host::predict(frame(four, 1, 0), hw, params()).l2_spill_ms == 0.0);
  // The spill is what the pass takes beyond its next bound: in the cache at 4 B a clock the
  // pass would take the ALU's 200 us; spilled at 2 B a clock, 320 us: 120 us of spill a pass.
  hw.texture_bytes_per_clock = 4;
  hw.texture_spilled_bytes_per_clock = 2;
  const host::CostBreakdown alu = host::predict(frame(k, 1, 0), hw, params());
  CHECK(alu.texture_ms == doctest::Approx(0.640));
  CHECK(alu.l2_spill_ms == doctest::Approx(0.240));
}

TEST_CASE(
    "a loop body's arithmetic between two of its fetches adds to the pass's bottleneck where the "
    "profile models latencies, at most the texture time") {
  // Two passes: 4000 x 30 operations (200 us at the ALU) and 64000 B (640 us at 1 B a clock) a
  // pass; half the operations sit between two fetches: 100 us of arithmetic that waits.
  vgpu::Counters k = kernel_passes(2);
  k.loop_dependent_instructions = 2 * 60000;
  vgpu::Profile hw = card();
  hw.mem_gbps = 1000;
  hw.texture_bytes_per_clock = 1;
  const host::CostBreakdown none = host::predict(frame(k, 1, 0), hw, params());
  CHECK(none.texture_ms == doctest::Approx(1.280));  // no latencies modelled: overlapped
  CHECK(none.fetch_wait_ms == 0.0);
  hw.fetch_latency_clocks = 400;
  const host::CostBreakdown b = host::predict(frame(k, 1, 0), hw, params());
  CHECK(b.fetch_wait_ms == doctest::Approx(0.200));
  CHECK(b.texture_ms == doctest::Approx(1.480));
  CHECK(b.total_ms == doctest::Approx(none.total_ms + 0.200));
  // Texture at 8 B a clock: 80 us a pass, under the ALU's 200; the wait is at most those 80.
  hw.texture_bytes_per_clock = 8;
  const host::CostBreakdown alu = host::predict(frame(k, 1, 0), hw, params());
  CHECK(alu.fetch_wait_ms == doctest::Approx(0.160));
  CHECK(alu.arithmetic_ms == doctest::Approx(0.560));
}

TEST_CASE("Texture downloads cost their fixed part and their bytes where a profile prices them") {
  vgpu::FrameStats s = frame(kernel_passes(2));
  s.downloads = 2;
  s.download_bytes = 3000000;
  vgpu::Profile hw = card();
  CHECK(host::predict(s, hw, params()).download_ms == doctest::Approx(0.0));  // not modelled
  hw.download_gbps = 1;  // 3 MB at 1 GB/s: 3 ms
  hw.download_us = 250;  // and 0.25 ms each
  const host::CostBreakdown b = host::predict(s, hw, params());
  CHECK(b.download_ms == doctest::Approx(3.5));
  const host::CostBreakdown without = host::predict(frame(kernel_passes(2)), hw, params());
  CHECK(b.total_ms == doctest::Approx(without.total_ms + 3.5));
}

TEST_CASE("the host's pass over what a frame read back adds its bytes at the profile's host rate") {
  vgpu::FrameStats s = frame(kernel_passes(2));
  s.downloads = 2;
  s.download_bytes = 3000000;
  vgpu::Profile hw = card();
  hw.download_host_gbps = 2;  // alone: priced even where the transfer is not
  CHECK(host::predict(s, hw, params()).download_ms == doctest::Approx(1.5));
  hw.download_gbps = 1;  // 3 MB at 1 GB/s: 3 ms, then 1.5 ms on the host
  hw.download_us = 250;  // and 0.25 ms each
  const host::CostBreakdown b = host::predict(s, hw, params());
  CHECK(b.download_ms == doctest::Approx(5.0));
  const host::CostBreakdown without = host::predict(frame(kernel_passes(2)), hw, params());
  CHECK(b.total_ms == doctest::Approx(without.total_ms + 5.0));
}

TEST_CASE("Pass records and per-program totals predict the same for identical passes") {
  vgpu::FrameStats s = frame(kernel_passes(2));
  const host::CostBreakdown totals = host::predict(s, card(), params());
  s.keep_pass_records = true;
  for (int i = 0; i < 2; ++i) {
    vgpu::Counters one = kernel_passes(1);
    one.program_loads = 0;  // loads are counted by use_program, not by the pass
    one.program_bytes = 0;
    s.passes.push_back({"kernel", 64, 64, one, -1});
  }
  const host::CostBreakdown records = host::predict(s, card(), params());
  CHECK(records.total_ms == doctest::Approx(totals.total_ms));
  CHECK(records.wasted_ms == doctest::Approx(totals.wasted_ms));
}

TEST_CASE("More passes never predict less time") {
  double last = 0;
  for (uint64_t n = 1; n <= 64; n *= 2) {
    const double t = host::predict(frame(kernel_passes(n), n), card(), params()).total_ms;
    CHECK(t > last);
    last = t;
  }
  // A pass whose every fragment is masked still costs its fixed cost.
  const vgpu::FrameStats one = frame(kernel_passes(1));
  vgpu::FrameStats two = one;
  two.totals.passes += 1;
  two.totals.fragments_launched += 4000;
  two.totals.fragments_masked += 4000;
  two.programs[0].counters.passes += 1;
  two.programs[0].counters.fragments_launched += 4000;
  two.programs[0].counters.fragments_masked += 4000;
  CHECK(host::predict(two, card(), params()).total_ms >
        host::predict(one, card(), params()).total_ms);
}

TEST_CASE("Masked fragments reduce the arithmetic term") {
  const auto all = host::predict(frame(kernel_passes(4, 3000, 0)), card(), params());
  const auto masked = host::predict(frame(kernel_passes(4, 3000, 3000)), card(), params());
  CHECK(masked.arithmetic_demand_ms == doctest::Approx(all.arithmetic_demand_ms / 4));
  CHECK(masked.arithmetic_ms < all.arithmetic_ms);
  CHECK(masked.wasted_ms == doctest::Approx(0.0));  // the finished rays were all masked
  CHECK(masked.total_ms < all.total_ms);
}

TEST_CASE("Dynamic branching skips the branch body of batches idle as a whole") {
  vgpu::Profile fx = card();
  vgpu::Profile nv4 = card();
  nv4.branching = vgpu::Branching::dynamic;
  nv4.branch_granularity = 1024;
  host::CostParams p = params();
  p.branch_body_share = 1;  // a skipping batch skips the whole program
  vgpu::Counters k = kernel_passes(2, 3000);
  k.idle_in_batch1024 = k.lanes_idle;  // every finished ray sits in an all-idle batch
  k.idle_in_batch32 = 0;               // (the warp-sized count is not the 6600's)
  const vgpu::FrameStats s = frame(k);
  const auto both_sides = host::predict(s, fx, p);
  const auto branching = host::predict(s, nv4, p);
  CHECK(branching.arithmetic_demand_ms == doctest::Approx(both_sides.arithmetic_demand_ms / 4));
  CHECK(branching.wasted_ms == doctest::Approx(0.0));
  CHECK(both_sides.wasted_ms == doctest::Approx(0.75 * both_sides.arithmetic_ms));
}

TEST_CASE("Merging a pair of kernels into one MRT pass drops passes and loads, keeps the work") {
  vgpu::FrameStats s;
  s.keep_pass_records = false;
  vgpu::Counters a = kernel_passes(10), b = kernel_passes(10);
  s.program("intersections", "intersecciones", 31).counters = a;
  s.program("next triangle", "proximoTriangulo", 31).counters = b;
  s.totals = a;
  s.totals += b;
  const vgpu::FrameStats m =
      host::with_merged_passes(s, {{"intersections", "next triangle", 1, 16}});
  CHECK(m.totals.passes == 10);
  CHECK(m.totals.program_loads == 10);
  CHECK(m.totals.fragments_shaded == a.fragments_shaded);
  CHECK(m.totals.instructions == a.instructions + b.instructions - a.fragments_shaded);
  CHECK(m.totals.bytes_read == a.bytes_read + b.bytes_read - 16 * a.fragments_shaded);
  CHECK(m.totals.bytes_written == a.bytes_written + b.bytes_written);
  CHECK(host::predict(m, card(), params()).total_ms < host::predict(s, card(), params()).total_ms);

  const vgpu::FrameStats r = host::with_resident_programs(s);
  CHECK(r.totals.program_loads == 2);
  CHECK(r.totals.program_bytes == 2 * 496);
  CHECK(r.totals.passes == s.totals.passes);
}

TEST_CASE(
    "the fitted fixed costs reproduce Table 1's Bunny3 on both cards at the Table 1 settings") {
  // scripts/docs/table1.py's settings: 256x256, 2 bounces, phong, no shadow rays, a 15^3 grid. If
  // the kernels or the host loop change their counts, this fails: refit (table1.py --fit).
  const host::Scene scene = host::load_scene(VGPU_SCENES_DIR "/bunny.gltf");
  REQUIRE(scene.camera.has_value());
  const host::Grid grid = host::build_grid(scene, host::parse_grid_spec("15"));
  host::RenderOptions opt;
  opt.shadows = false;
  opt.threads = 2;
  host::StreamTracer tracer(scene, grid, opt);
  const host::RenderResult r = tracer.render(*scene.camera);
  const double fx = host::predict(r.stats, vgpu::profile("gf5700")).total_ms;
  const double g6 = host::predict(r.stats, vgpu::profile("gf6600")).total_ms;
  MESSAGE("Bunny3 predicted: GeForce FX 5700 " << fx << " ms (paper 5075), GeForce 6600 " << g6
                                               << " ms (paper 1079)");
  CHECK(fx == doctest::Approx(5075).epsilon(0.01));
  CHECK(g6 == doctest::Approx(1079).epsilon(0.01));
}

TEST_CASE("arithmetic is charged at the rate of the precision it ran at") {
  vgpu::Counters k = kernel_passes(2);
  const double fp32 = host::predict(frame(k), card(), params()).arithmetic_demand_ms;
  CHECK(fp32 == doctest::Approx(0.400));            // as above: 0.5 of the fp16 rate
  k.alu_fp16 = k.instructions - k.texture_fetches;  // every operation in half precision
  CHECK(host::predict(frame(k), card(), params()).arithmetic_demand_ms == doctest::Approx(0.200));
  k.alu_fp16 = (k.instructions - k.texture_fetches) / 2;  // half of them
  CHECK(host::predict(frame(k), card(), params()).arithmetic_demand_ms == doctest::Approx(0.300));
  k.alu_fp16 = 0;
  k.alu_fp24 = k.instructions - k.texture_fetches;
  vgpu::Profile r3 = card();
  r3.fp24_rate = 1;  // an fp24 part: full speed
  CHECK(host::predict(frame(k), r3, params()).arithmetic_demand_ms == doctest::Approx(0.200));
  r3.fp24_rate = 0.5;  // fp24 on fp32 units
  CHECK(host::predict(frame(k), r3, params()).arithmetic_demand_ms == doctest::Approx(0.400));
}

TEST_CASE(
    "in a real render fp16 operations cost half of fp32's on the FX 5700, the same on the 6600") {
  // Per counted operation: fp16 and fp32 renders run different pass counts (stuck fp16 rays).
  const host::Scene scene = host::load_scene(VGPU_SCENES_DIR "/bunny.gltf");
  const host::Grid grid = host::build_grid(scene, host::parse_grid_spec("8"));
  host::RenderOptions opt;
  opt.width = opt.height = 32;
  opt.bounces = 0;
  opt.threads = 2;
  auto demand = [&](vgpu::Format f, const char* part) {
    opt.formats = host::Formats::all(f);
    host::StreamTracer tracer(scene, grid, opt);
    const host::RenderResult r = tracer.render(*scene.camera);
    const double ops = double(r.stats.totals.instructions - r.stats.totals.texture_fetches);
    return host::predict(r.stats, vgpu::profile(part)).arithmetic_demand_ms / ops;
  };
  CHECK(demand(vgpu::Format::fp16, "gf5700") ==
        doctest::Approx(demand(vgpu::Format::fp32, "gf5700") / 2).epsilon(0.02));
  CHECK(demand(vgpu::Format::fp16, "gf6600") ==
        doctest::Approx(demand(vgpu::Format::fp32, "gf6600")).epsilon(0.02));
}

TEST_CASE("A looping pass pays for its idle lane slots and its loop overhead") {
  vgpu::Profile hw = card();
  hw.loop_overhead_clocks = 2;
  vgpu::Counters k = kernel_passes(1, 0);
  // 4000 fragments in batches that issued 8000 lane slots; 6000 active iterations are in the
  // counts above, the 2000 idle slots were issued the body: 31 operations, 1 fetch each.
  k.loop_lane_slots = 8000;
  k.loop_iterations = 6000;
  k.loop_lanes_idle = 2000;
  k.loop_idle_instructions = 2000 * 31;
  k.loop_idle_fetches = 2000;
  const host::CostBreakdown b = host::predict(frame(k), hw, params());
  // Active work 200 us as above; idle lanes 2000 x 30 operations / 3 per instruction over
  // 4 pipes x 1e8 Hz x 0.5 = 100 us; overhead 8000 slots x 2 clocks / (4 x 1e8 Hz) = 40 us.
  CHECK(b.arithmetic_demand_ms == doctest::Approx(0.340));
  CHECK(b.texture_demand_ms == doctest::Approx(0.015));         // (4000 + 2000) fetches / 4e8
  CHECK(b.memory_demand_ms == doctest::Approx(0.128 + 0.100));  // idle lanes move no bytes
  CHECK(b.loop_overhead_ms == doctest::Approx(0.040));
  CHECK(b.loop_idle_ms == doctest::Approx(0.110));  // 100 us + the idle slots' 10 us overhead
  CHECK(b.wasted_ms == doctest::Approx(0.110));
  CHECK(b.arithmetic_ms == doctest::Approx(0.340));
}

TEST_CASE("A looping pass adds its longest lane's fetch and operation latencies to its work") {
  vgpu::Profile hw = card();
  vgpu::Counters k = kernel_passes(1, 0);
  // The longest lane ran 10 iterations of a body whose longest chain waits through 2 fetches
  // and 30 operation units: 20 fetch latencies and 300 operation units in all.
  k.loop_span_iterations = 10;
  k.loop_span_fetches = 20;
  k.loop_span_operations = 300;
  const host::CostBreakdown without = host::predict(frame(k), hw, params());
  CHECK(without.latency_ms == 0.0);  // a profile that does not model latencies
  hw.fetch_latency_clocks = 400;
  hw.operation_latency_clocks = 5;
  const host::CostBreakdown b = host::predict(frame(k), hw, params());
  // (20 x 400 + 300 x 5) clocks at 1e8 Hz = 95 us, on top of the pass's work.
  CHECK(b.latency_ms == doctest::Approx(0.095));
  CHECK(b.total_ms == doctest::Approx(without.total_ms + 0.095));
  CHECK(b.arithmetic_ms == doctest::Approx(without.arithmetic_ms));
  CHECK(b.texture_ms == doctest::Approx(without.texture_ms));
  CHECK(b.memory_ms == doctest::Approx(without.memory_ms));
}
