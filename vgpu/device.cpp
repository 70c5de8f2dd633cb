// What every device shares: texture limits, the checks before a pass and its static counters.
#include "vgpu/device.h"

#include <algorithm>
#include <array>

namespace vgpu {

Texture Device::make_texture(std::string name, int width, int height, int channels,
                             Format format) const {
  Texture t(std::move(name), std::max(width, 1), std::max(height, 1), channels, format);
  if (width <= 0 || height <= 0) throw Error("texture '" + t.name() + "' has an empty size");
  check_texture(t);
  return t;
}

void Device::check_texture(const Texture& t) const {
  const Profile& pr = profile();
  const int m = pr.max_texture_size;
  if (t.width() > m || t.height() > m)
    throw Error("texture '" + t.name() + "' is " + std::to_string(t.width()) + "x" +
                std::to_string(t.height()) + " texels; profile " + pr.name + " allows at most " +
                std::to_string(m) + "x" + std::to_string(m));
}

void check_texture_units(const Profile& profile, const std::string& program, int units) {
  if (units > profile.texture_units)
    throw Error("program '" + program + "' reads texture unit " + std::to_string(units - 1) + " (" +
                std::to_string(units) + " units); profile " + profile.name + " has " +
                std::to_string(profile.texture_units) +
                " texture units (GL_MAX_TEXTURE_IMAGE_UNITS)");
}

void check_program(const Profile& profile, const Program& p, const Program::Analysis& a) {
  const std::string pname = p.name();
  auto fail = [](const std::string& what) { throw Error(what); };
  // Loops first: a looping program cannot run at all on a profile without them.
  const LoopTally& lp = a.loop;
  if (lp.loops > 0) {
    if (profile.branching != Branching::dynamic || profile.max_loop_iterations <= 0)
      fail("program '" + pname + "' has a data-dependent loop of up to " +
           std::to_string(lp.max_iterations) + " iterations; profile " + profile.name + " (" +
           profile.cg_profile + ") has no dynamic branching or loops (0 iterations)");
    if (lp.loops > 1)
      fail("program '" + pname + "' has " + std::to_string(lp.loops) +
           " loops; the vgpu models one loop per program");
    if (lp.branch_inside)
      fail("program '" + pname + "' branches inside its loop body; write the body with selects");
    if (lp.max_iterations > profile.max_loop_iterations)
      fail("program '" + pname + "' loops up to " + std::to_string(lp.max_iterations) +
           " iterations; profile " + profile.name + " allows " +
           std::to_string(profile.max_loop_iterations) + " (loop count limit)");
    const int64_t executed =
        int64_t(a.instructions) + int64_t(lp.max_iterations - 1) * int64_t(lp.body_instructions);
    if (executed > int64_t(profile.max_instructions))
      fail("program '" + pname + "' executes up to " + std::to_string(executed) +
           " instructions per fragment (" + std::to_string(lp.body_instructions) +
           " in its loop body x " + std::to_string(lp.max_iterations) + " iterations); profile " +
           profile.name + " allows " + std::to_string(profile.max_instructions));
  }
  if (p.outputs() > profile.max_outputs)
    fail("program '" + pname + "' writes " + std::to_string(p.outputs()) + " outputs; profile " +
         profile.name + " allows " + std::to_string(profile.max_outputs) +
         " (no multiple render targets)");
  if (a.instructions > profile.max_instructions)
    fail("program '" + pname + "' has " + std::to_string(a.instructions) +
         " instructions; profile " + profile.name + " allows " +
         std::to_string(profile.max_instructions));
  int units = 0;
  for (int u = 0; u < kMaxTextureUnits; ++u)
    if (a.fetches.per_unit[size_t(u)]) units = u + 1;
  check_texture_units(profile, pname, units);
}

void check_pass(const Profile& profile, const Program& p, const Program::Analysis& a,
                const Texture* const* units, const std::vector<Texture*>& targets,
                const Rect& rect) {
  const std::string pname = p.name();
  auto fail = [](const std::string& what) { throw Error(what); };
  check_program(profile, p, a);
  if (int(targets.size()) != p.outputs())
    fail("program '" + pname + "' writes " + std::to_string(p.outputs()) + " outputs but " +
         std::to_string(targets.size()) + " render targets are set");
  const Texture& t0 = *targets[0];
  for (const Texture* t : targets) {
    if (t->width() != t0.width() || t->height() != t0.height())
      fail("program '" + pname + "': render targets differ in size");
    for (int u = 0; u < kMaxTextureUnits; ++u)
      if (units[u] == t)
        fail("program '" + pname + "' reads texture '" + t->name() + "' (unit " +
             std::to_string(u) + ") while rendering to it: read/write hazard, use ping-pong");
  }
  for (int u = 0; u < kMaxTextureUnits; ++u)
    if (a.fetches.per_unit[u] && !units[u])
      fail("program '" + pname + "' fetches from texture unit " + std::to_string(u) +
           ", which has no texture bound");
  if (rect.x0 < 0 || rect.y0 < 0 || rect.x1 > t0.width() || rect.y1 > t0.height() ||
      rect.x0 > rect.x1 || rect.y0 > rect.y1)
    fail("program '" + pname + "': drawn rectangle outside the render target");
}

namespace {

// Counters::footprint_bytes' read part: per distinct texture, the bytes fetched from it (each unit
// u fetched fetches[u] texels) or its size, whichever is less.
uint64_t read_footprint(const Texture* const* units,
                        const std::array<uint64_t, kMaxTextureUnits>& fetches) {
  std::array<const Texture*, kMaxTextureUnits> seen{};
  std::array<uint64_t, kMaxTextureUnits> bytes{};
  size_t distinct = 0;
  for (int u = 0; u < kMaxTextureUnits; ++u) {
    if (!fetches[size_t(u)]) continue;
    size_t i = 0;
    while (i < distinct && seen[i] != units[u]) ++i;
    if (i == distinct) seen[distinct++] = units[u];
    bytes[i] += fetches[size_t(u)] * uint64_t(units[u]->bytes_per_texel());
  }
  uint64_t sum = 0;
  for (size_t i = 0; i < distinct; ++i) sum += std::min(bytes[i], seen[i]->bytes());
  return sum;
}

std::array<uint64_t, kMaxTextureUnits> fetched(const FetchTally& per_fragment, uint64_t fragments) {
  std::array<uint64_t, kMaxTextureUnits> n{};
  for (size_t u = 0; u < n.size(); ++u) n[u] = uint64_t(per_fragment.per_unit[u]) * fragments;
  return n;
}

}  // namespace

Counters pass_counters(const Program::Analysis& a, const Texture* const* units,
                       const std::vector<Texture*>& targets, uint64_t launched, uint64_t shaded,
                       uint64_t discarded) {
  Counters c;
  c.passes = 1;
  c.fragments_launched = launched;
  c.fragments_shaded = shaded;
  c.fragments_discarded = discarded;
  c.instructions = shaded * uint64_t(a.instructions);
  uint64_t read_per_frag = 0;
  for (int u = 0; u < kMaxTextureUnits; ++u)
    if (a.fetches.per_unit[u])
      read_per_frag += uint64_t(a.fetches.per_unit[u]) * uint64_t(units[u]->bytes_per_texel());
  c.texture_fetches = shaded * uint64_t(a.fetches.total());
  c.bytes_read = shaded * read_per_frag;
  uint64_t write_per_frag = 0;
  for (const Texture* t : targets) write_per_frag += uint64_t(t->bytes_per_texel());
  c.bytes_written = (shaded - discarded) * write_per_frag;
  c.footprint_bytes = read_footprint(units, fetched(a.fetches, shaded)) + launched * write_per_frag;
  return c;
}

void add_loop_counters(Counters& c, const Program::Analysis& a, const Texture* const* units,
                       const LoopCounts& n) {
  const LoopTally& lp = a.loop;
  const uint64_t body = uint64_t(lp.body_instructions), fetches = uint64_t(lp.body_fetches.total());
  uint64_t bytes = 0;
  for (int u = 0; u < kMaxTextureUnits; ++u)
    if (lp.body_fetches.per_unit[size_t(u)])
      bytes +=
          uint64_t(lp.body_fetches.per_unit[size_t(u)]) * uint64_t(units[u]->bytes_per_texel());
  // pass_counters charged the body once per shaded fragment; it runs once per active iteration.
  c.instructions = c.instructions - n.shaded * body + n.iterations * body;
  c.texture_fetches = c.texture_fetches - n.shaded * fetches + n.iterations * fetches;
  c.bytes_read = c.bytes_read - n.shaded * bytes + n.iterations * bytes;
  // The footprint's read part again, the body's fetches once per active iteration.
  std::array<uint64_t, kMaxTextureUnits> per_unit = fetched(a.fetches, n.shaded);
  for (size_t u = 0; u < per_unit.size(); ++u)
    per_unit[u] = per_unit[u] - n.shaded * lp.body_fetches.per_unit[u] +
                  n.iterations * lp.body_fetches.per_unit[u];
  c.footprint_bytes = c.footprint_bytes - read_footprint(units, fetched(a.fetches, n.shaded)) +
                      read_footprint(units, per_unit);
  c.loop_iterations = n.iterations;
  c.loop_lane_slots = n.slots;
  c.loop_lanes_idle = n.slots - n.iterations;
  c.loop_batch_iterations = n.batch_iterations;
  c.loop_idle_instructions = c.loop_lanes_idle * body;
  c.loop_idle_fetches = c.loop_lanes_idle * fetches;
  c.loop_span_iterations = n.most;
  c.loop_span_fetches = n.most * uint64_t(lp.chain_fetches);
  c.loop_span_operations = n.most * uint64_t(lp.chain_operations);
  c.loop_dependent_instructions = n.iterations * uint64_t(lp.dependent_operations);
}

void count_program_load(FrameStats& stats, const Program& program, const Profile& profile) {
  const Program::Analysis a = program.analyze();
  Counters c;
  c.program_loads = 1;
  c.program_bytes = uint64_t(a.instructions) * profile.instruction_bytes;
  stats.program(program.name(), program.paper_name(), a.instructions).counters += c;
  stats.totals += c;
}

void count_readback(FrameStats& stats, const Program* program, uint64_t result) {
  Counters c;
  c.queries = 1;
  c.query_readbacks = 1;
  stats.totals += c;
  if (program) stats.program(program->name(), program->paper_name(), 0).counters += c;
  if (!stats.passes.empty()) stats.passes.back().query_result = int64_t(result);
}

void count_download(FrameStats& stats, const Texture& t) {
  ++stats.downloads;
  stats.download_bytes += uint64_t(t.width()) * uint64_t(t.height()) * t.bytes_per_texel();
}

}  // namespace vgpu
