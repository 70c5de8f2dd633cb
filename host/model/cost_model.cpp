// The cost model's arithmetic: per-pass bottleneck times plus fixed costs (see cost_model.h).
#include "host/model/cost_model.h"

#include <algorithm>
#include <cstdio>

namespace host {

CostParams defaults_for(const vgpu::Profile& profile) {
  CostParams p;
  p.pass_us = profile.pass_us;
  p.program_load_us = profile.program_load_us;
  p.readback_us = profile.readback_us;
  if (profile.branches_as_selects) p.branch_body_share = 0;  // no batch skips a body
  return p;
}

std::vector<std::pair<std::string, double>> CostBreakdown::items() const {
  return {{"arithmetic_ms", arithmetic_ms},
          {"texture_ms", texture_ms},
          {"memory_ms", memory_ms},
          {"per_pass_ms", per_pass_ms},
          {"program_load_ms", program_load_ms},
          {"bus_ms", bus_ms},
          {"readback_ms", readback_ms},
          {"download_ms", download_ms},
          {"wasted_ms", wasted_ms},
          {"l2_spill_ms", l2_spill_ms},
          {"fetch_wait_ms", fetch_wait_ms},
          {"loop_idle_ms", loop_idle_ms},
          {"loop_overhead_ms", loop_overhead_ms},
          {"latency_ms", latency_ms},
          {"total_ms", total_ms},
          {"arithmetic_demand_ms", arithmetic_demand_ms},
          {"texture_demand_ms", texture_demand_ms},
          {"memory_demand_ms", memory_demand_ms}};
}

namespace {

// The fragment work of `n` identical passes whose summed counters are c.
void add_passes(const vgpu::Counters& c, double n, const vgpu::Profile& hw, const CostParams& p,
                CostBreakdown& out) {
  if (n <= 0 || c.fragments_shaded == 0) return;
  const double hz = hw.core_mhz * 1e6;
  const double shaded = double(c.fragments_shaded) / n;
  const double fetches = double(c.texture_fetches) / n;
  const double ops = std::max(0.0, double(c.instructions) / n - fetches);  // fetches are TEX
  // A looping program: lanes already out of the loop still hold their slots while their batch
  // iterates. They are issued the body's instructions and fetches (ALU and texture-unit time)
  // but move no bytes; each lane slot also pays the profile's loop/break overhead.
  const double idle_fetches = double(c.loop_idle_fetches) / n;
  const double idle_ops = std::max(0.0, double(c.loop_idle_instructions) / n - idle_fetches);
  const double overhead_s =
      double(c.loop_lane_slots) / n * hw.loop_overhead_clocks / (hw.pipelines * hz);
  // Finished rays: fragments idle in the program's branch, or discarded by a counting program
  // (one branch per program, as every kernel has; a second branch would count them twice).
  const double idle = std::min(shaded, double(c.lanes_idle) / n);
  const double finished = std::min(shaded, idle + double(c.fragments_discarded) / n);
  // Dynamic branching: batches idle as a whole skip the branch body (counted by the vgpu per
  // 8x4 and 32x32 tile; the profile's granularity picks the tile).
  double skipped = 0;
  if (hw.branching == vgpu::Branching::dynamic) {
    const uint64_t batch = hw.branch_granularity >= 256 ? c.idle_in_batch1024 : c.idle_in_batch32;
    skipped = std::min(idle, double(batch) / n);
  }
  const double keep = 1.0 - p.branch_body_share * skipped / shaded;  // share of work still done

  const double packing = std::clamp(p.scalar_ops_per_instruction, 1.0, double(hw.alu_lanes));
  // Each operation at the rate of the precision the render ran it at (fp16 is the full rate).
  const double ops24 = std::min(ops, double(c.alu_fp24) / n);
  const double ops16 = std::min(ops - ops24, double(c.alu_fp16) / n);
  const double ops32 = ops - ops24 - ops16;
  const double rate_ops = ops32 / hw.rate(vgpu::Format::fp32) +
                          ops24 / hw.rate(vgpu::Format::fp24) + ops16 / hw.rate(vgpu::Format::fp16);
  // Idle loop lanes run at the rate the rest of the arithmetic ran at (the pass has one format).
  const double idle_rate_ops = ops > 0 ? idle_ops * rate_ops / ops : idle_ops;
  const double arith_s =
      (rate_ops * keep + idle_rate_ops) / packing / (hw.pipelines * hz * hw.alu_per_clock) +
      overhead_s;
  double tex_s = (fetches * keep + idle_fetches) / (hw.pipelines * hz * hw.texels_per_clock);
  double in_cache_s = tex_s;             // tex_s had the pass fitted in the profile's L2
  if (hw.texture_bytes_per_clock > 0) {  // idle loop lanes fetch texels of the average size
    const double per_fetch = fetches > 0 ? double(c.bytes_read) / n / fetches : 0.0;
    const double bytes = double(c.bytes_read) / n * keep + idle_fetches * per_fetch;
    // A pass larger than the cache finds what earlier passes wrote evicted (Profile::l2_bytes).
    const bool spills = hw.l2_bytes > 0 && hw.texture_spilled_bytes_per_clock > 0 &&
                        double(c.footprint_bytes) / n > hw.l2_bytes;
    in_cache_s = std::max(tex_s, bytes / (hw.texture_bytes_per_clock * hz));
    tex_s =
        spills ? std::max(tex_s, bytes / (hw.texture_spilled_bytes_per_clock * hz)) : in_cache_s;
  }
  double mem_s =
      (double(c.bytes_read) / n * keep + double(c.bytes_written) / n) / (hw.mem_gbps * 1e9);
  if (hw.output_bytes_per_clock > 0)
    mem_s = std::max(mem_s, double(c.bytes_written) / n / (hw.output_bytes_per_clock * hz));
  // A loop body's arithmetic between two of its fetches (an address computed from a fetched
  // texel) runs after one fetch returns and before the next issues: it does not overlap the
  // fetches of its own lane. Where the profile models latencies, that share of the arithmetic
  // time is added to the pass's bottleneck, at most the texture time it waits through. (The
  // share is of the active lanes' arithmetic; the idle lane slots issue the same body, so it
  // applies to theirs too, but not to the loop/break overhead, which sits between no fetches.)
  double wait_s = 0;
  if (hw.fetch_latency_clocks > 0 && c.loop_dependent_instructions > 0 && ops > 0) {
    const double share = std::min(1.0, double(c.loop_dependent_instructions) / n / ops);
    wait_s = std::min(tex_s, (arith_s - overhead_s) * share);
  }
  const double bottleneck_s = std::max({arith_s, tex_s, mem_s});
  const double work_s = bottleneck_s + wait_s;
  // A looping pass lasts at least as long as its longest lane: that lane's iterations of the
  // body's longest chain of dependent operations (vgpu/span.h). The work of the other lanes is
  // spread over the pipelines, so the pass takes about the sum (a greedy schedule's bound:
  // work over processors plus the span).
  const double span_s = (double(c.loop_span_fetches) * hw.fetch_latency_clocks +
                         double(c.loop_span_operations) * hw.operation_latency_clocks) /
                        n / hz;
  out.latency_ms += span_s * 1e3 * n;

  const double ms = 1e3 * n;
  out.arithmetic_demand_ms += arith_s * ms;
  out.texture_demand_ms += tex_s * ms;
  out.memory_demand_ms += mem_s * ms;
  out.l2_spill_ms += std::max(0.0, bottleneck_s - std::max({arith_s, in_cache_s, mem_s})) * ms;
  out.fetch_wait_ms += wait_s * ms;
  if (bottleneck_s == arith_s)
    out.arithmetic_ms += work_s * ms;
  else if (bottleneck_s == tex_s)
    out.texture_ms += work_s * ms;
  else
    out.memory_ms += work_s * ms;
  // Work units: a full fragment is 1, a skipping one 1 - body share.
  const double units = shaded - p.branch_body_share * skipped;
  const double finished_units = finished - p.branch_body_share * skipped;
  double wasted = units > 0 ? std::clamp(finished_units / units, 0.0, 1.0) : 0.0;
  if (c.loop_lane_slots > 0) {
    // Of a looping pass: the idle lanes' share of its bottleneck's demand.
    const double idle_arith = idle_rate_ops / packing / (hw.pipelines * hz * hw.alu_per_clock) +
                              overhead_s * double(c.loop_lanes_idle) / double(c.loop_lane_slots);
    const double idle_tex = idle_fetches / (hw.pipelines * hz * hw.texels_per_clock);
    const double idle_s = bottleneck_s == arith_s ? idle_arith
                          : bottleneck_s == tex_s ? idle_tex
                                                  : 0.0;
    const double share = work_s > 0 ? idle_s / work_s : 0.0;
    out.loop_idle_ms += work_s * ms * share;
    out.loop_overhead_ms += overhead_s * ms;
    wasted = std::clamp(wasted + share, 0.0, 1.0);
  }
  out.wasted_ms += work_s * ms * wasted;
}

}  // namespace

FixedCosts fixed_costs(const vgpu::Counters& t, const vgpu::Profile& hw, const CostParams& p) {
  FixedCosts f;
  f.per_pass_ms = 1e-3 * p.pass_us * double(t.passes);
  f.bus_ms = 1e3 * double(t.program_bytes) / (hw.bus_mbps * 1e6);
  f.program_load_ms = f.bus_ms + 1e-3 * p.program_load_us * double(t.program_loads);
  f.readback_ms = 1e-3 * p.readback_us * double(t.query_readbacks);
  return f;
}

CostBreakdown predict(const vgpu::FrameStats& stats, const vgpu::Profile& profile) {
  return predict(stats, profile, defaults_for(profile));
}

CostBreakdown predict(const vgpu::FrameStats& stats, const vgpu::Profile& hw, const CostParams& p) {
  CostBreakdown b;
  const vgpu::Counters& t = stats.totals;
  uint64_t recorded = 0;
  for (const vgpu::PassRecord& r : stats.passes) recorded += r.counters.passes;
  uint64_t pass_bytes_written = 0;
  if (!stats.passes.empty() && recorded == t.passes) {
    for (const vgpu::PassRecord& r : stats.passes) {
      add_passes(r.counters, double(r.counters.passes), hw, p, b);
      pass_bytes_written += r.counters.bytes_written;
    }
  } else {
    for (const auto& prog : stats.programs) {
      add_passes(prog.counters, double(prog.counters.passes), hw, p, b);
      pass_bytes_written += prog.counters.bytes_written;
    }
  }
  // Clears write whole textures without a program: the frame's bytes no pass wrote.
  if (t.bytes_written > pass_bytes_written) {
    const double clear_bytes = double(t.bytes_written - pass_bytes_written);
    double clear_ms = 1e3 * clear_bytes / (hw.mem_gbps * 1e9);
    if (hw.output_bytes_per_clock > 0)  // a clear writes through the ROPs too
      clear_ms =
          std::max(clear_ms, 1e3 * clear_bytes / (hw.output_bytes_per_clock * hw.core_mhz * 1e6));
    b.memory_ms += clear_ms;
    b.memory_demand_ms += clear_ms;
  }
  const FixedCosts f = fixed_costs(t, hw, p);
  b.per_pass_ms = f.per_pass_ms;
  b.bus_ms = f.bus_ms;
  b.program_load_ms = f.program_load_ms;
  b.readback_ms = f.readback_ms;
  if (hw.download_gbps > 0)
    b.download_ms = 1e-3 * hw.download_us * double(stats.downloads) +
                    1e3 * double(stats.download_bytes) / (hw.download_gbps * 1e9);
  if (hw.download_host_gbps > 0)  // the host then fills the frame's arrays from them
    b.download_ms += 1e3 * double(stats.download_bytes) / (hw.download_host_gbps * 1e9);
  b.total_ms = b.arithmetic_ms + b.texture_ms + b.memory_ms + b.latency_ms + b.per_pass_ms +
               b.program_load_ms + b.readback_ms + b.download_ms;
  return b;
}

UpdateCost predict_update(uint64_t uploaded_bytes, double build_ms, const vgpu::Profile& profile) {
  UpdateCost c;
  c.upload_ms = 1e3 * double(uploaded_bytes) / (profile.bus_mbps * 1e6);
  c.build_ms = build_ms;
  c.total_ms = c.upload_ms + c.build_ms;
  return c;
}

std::string describe(const CostBreakdown& c, const vgpu::Profile& profile) {
  char buf[1024];
  auto pct = [&](double v) { return c.total_ms > 0 ? 100.0 * v / c.total_ms : 0.0; };
  std::snprintf(
      buf, sizeof buf,
      "predicted %s: %.1f ms (cost model, docs/studies/table1.md)\n"
      "  pass work  arithmetic %.1f ms (%.0f%%), texture %.1f ms (%.0f%%), "
      "memory %.1f ms (%.0f%%)\n"
      "  fixed      per-pass %.1f ms (%.0f%%), program loads %.1f ms (%.0f%%), "
      "read-backs %.1f ms (%.0f%%)\n"
      "  of the pass work, on idle fragments (finished rays): %.1f ms (%.0f%% of the total)\n",
      profile.name.c_str(), c.total_ms, c.arithmetic_ms, pct(c.arithmetic_ms), c.texture_ms,
      pct(c.texture_ms), c.memory_ms, pct(c.memory_ms), c.per_pass_ms, pct(c.per_pass_ms),
      c.program_load_ms, pct(c.program_load_ms), c.readback_ms, pct(c.readback_ms), c.wasted_ms,
      pct(c.wasted_ms));
  std::string out = buf;
  if (c.loop_idle_ms > 0 || c.loop_overhead_ms > 0) {
    std::snprintf(buf, sizeof buf,
                  "  looping passes: lanes out of the loop while their batch iterates %.1f ms "
                  "(%.0f%%), loop overhead %.1f ms (%.0f%%)\n",
                  c.loop_idle_ms, pct(c.loop_idle_ms), c.loop_overhead_ms, pct(c.loop_overhead_ms));
    out += buf;
  }
  if (c.latency_ms > 0) {
    std::snprintf(buf, sizeof buf,
                  "  latency    each looping pass's longest lane %.1f ms (%.0f%%)\n", c.latency_ms,
                  pct(c.latency_ms));
    out += buf;
  }
  if (c.fetch_wait_ms > 0 || c.l2_spill_ms > 0) {
    std::snprintf(buf, sizeof buf,
                  "  of the pass work, loop arithmetic waiting on its fetches %.1f ms (%.0f%%), "
                  "passes larger than the L2 %.1f ms (%.0f%%)\n",
                  c.fetch_wait_ms, pct(c.fetch_wait_ms), c.l2_spill_ms, pct(c.l2_spill_ms));
    out += buf;
  }
  return out;
}

namespace {

// Every integer counter of a and b through f (host_ms is not a count and is dropped).
template <class Fn>
vgpu::Counters each_counter(const vgpu::Counters& a, const vgpu::Counters& b, Fn f) {
  vgpu::Counters r;
  for (const auto& [name, field] : vgpu::kCounterFields) r.*field = f(a.*field, b.*field);
  return r;
}
vgpu::Counters scaled(const vgpu::Counters& c, double f) {
  return each_counter(c, c, [f](uint64_t v, uint64_t) { return uint64_t(double(v) * f + 0.5); });
}
vgpu::Counters minus(const vgpu::Counters& a, const vgpu::Counters& b) {
  return each_counter(a, b, [](uint64_t x, uint64_t y) { return x > y ? x - y : 0; });
}
vgpu::Counters plus(const vgpu::Counters& a, const vgpu::Counters& b) {
  return each_counter(a, b, [](uint64_t x, uint64_t y) { return x + y; });
}

}  // namespace

const std::vector<MergedPair>& mrt_pairs() {
  // Voxel state and traversal state are RGBA fp32 textures: 16 bytes a texel (kernels/layout.h).
  static const std::vector<MergedPair> pairs = {{"intersections", "next triangle", 1, 16},
                                                {"traversal", "update voxel", 1, 16}};
  return pairs;
}

vgpu::FrameStats with_merged_passes(const vgpu::FrameStats& in,
                                    const std::vector<MergedPair>& pairs) {
  vgpu::FrameStats s = in;
  s.passes.clear();  // per-program totals from here on
  s.keep_pass_records = false;
  for (const MergedPair& m : pairs) {
    auto find = [&](const std::string& name) -> vgpu::FrameStats::ProgramTotals* {
      for (auto& p : s.programs)
        if (p.name == name) return &p;
      return nullptr;
    };
    vgpu::FrameStats::ProgramTotals* a = find(m.first);
    vgpu::FrameStats::ProgramTotals* b = find(m.second);
    if (!a || !b || a->counters.passes == 0 || b->counters.passes == 0) continue;
    const uint64_t k = std::min(a->counters.passes, b->counters.passes);  // passes that pair up
    const vgpu::Counters ma = scaled(a->counters, double(k) / double(a->counters.passes));
    const vgpu::Counters mb = scaled(b->counters, double(k) / double(b->counters.passes));
    vgpu::Counters c = plus(ma, mb);
    c.passes = k;
    c.fragments_launched = ma.fragments_launched;  // the same fragments, shaded once
    c.fragments_shaded = ma.fragments_shaded;
    c.fragments_masked = ma.fragments_masked;
    c.lanes_idle = std::max(ma.lanes_idle, mb.lanes_idle);                 // the same finished rays
    c.idle_in_batch32 = std::min(ma.idle_in_batch32, mb.idle_in_batch32);  // idle in both
    c.idle_in_batch1024 = std::min(ma.idle_in_batch1024, mb.idle_in_batch1024);
    const uint64_t shared = uint64_t(m.shared_fetches) * c.fragments_shaded;
    c.instructions -= std::min(c.instructions, shared);  // a fetch is one counted operation
    c.texture_fetches -= std::min(c.texture_fetches, shared);
    c.bytes_read -= std::min(c.bytes_read, uint64_t(m.shared_bytes) * c.fragments_shaded);
    c.footprint_bytes -= std::min(c.footprint_bytes, uint64_t(m.shared_bytes) * c.fragments_shaded);
    // One program for both: a load wherever either used to be loaded first in the pair.
    c.program_loads = std::min(k, std::max(ma.program_loads, mb.program_loads));
    const double bytes_per_load =
        (ma.program_loads ? double(ma.program_bytes) / double(ma.program_loads) : 0) +
        (mb.program_loads ? double(mb.program_bytes) / double(mb.program_loads) : 0);
    c.program_bytes = uint64_t(bytes_per_load * double(c.program_loads) + 0.5);
    a->counters = minus(a->counters, ma);
    b->counters = minus(b->counters, mb);
    s.totals = plus(minus(s.totals, plus(ma, mb)), c);
    s.totals.host_ms = in.totals.host_ms;
    vgpu::FrameStats::ProgramTotals merged;
    merged.name = m.first + " + " + m.second;
    merged.paper_name = a->paper_name + "+" + b->paper_name;
    merged.instructions = a->instructions + b->instructions - m.shared_fetches;
    merged.counters = c;
    s.programs.push_back(merged);
  }
  return s;
}

vgpu::FrameStats with_resident_programs(const vgpu::FrameStats& in) {
  vgpu::FrameStats s = in;
  for (auto& p : s.programs) {
    vgpu::Counters& c = p.counters;
    if (c.program_loads <= 1) continue;
    const uint64_t per_load = c.program_bytes / c.program_loads;
    s.totals.program_loads -= c.program_loads - 1;
    s.totals.program_bytes -= c.program_bytes - per_load;
    c.program_loads = 1;
    c.program_bytes = per_load;
  }
  return s;  // pass records carry no loads (use_program counts them per program), so they stay
}

std::vector<std::pair<std::string, vgpu::FrameStats>> what_ifs(const vgpu::FrameStats& stats) {
  const vgpu::FrameStats mrt = with_merged_passes(stats, mrt_pairs());
  return {{"mrt", mrt},
          {"resident programs", with_resident_programs(stats)},
          {"mrt + resident programs", with_resident_programs(mrt)}};
}

double full_frame_ms(const CostBreakdown& b, double scale) {
  return b.per_pass_ms + b.program_load_ms + b.readback_ms + b.latency_ms +
         scale * (b.arithmetic_ms + b.texture_ms + b.memory_ms + b.download_ms);
}

RunningPrice::RunningPrice(const vgpu::Profile& profile, double scale)
    : profile_(profile), params_(defaults_for(profile)), scale_(scale) {}

double RunningPrice::add(const vgpu::Counters& totals) {
  const vgpu::Counters pass = minus(totals, last_);
  last_ = totals;
  add_passes(pass, double(pass.passes), profile_, params_, work_);
  CostBreakdown so_far = work_;
  const FixedCosts f = fixed_costs(totals, profile_, params_);
  so_far.per_pass_ms = f.per_pass_ms;
  so_far.program_load_ms = f.program_load_ms;
  so_far.readback_ms = f.readback_ms;
  return full_frame_ms(so_far, scale_);
}

}  // namespace host
