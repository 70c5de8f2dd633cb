// How the host issues one pass on a device (host/trace/passes.h): bindings, masks, the draw,
// the occlusion query of a counting pass, and what the observer and --trace-pixel see.
#include "host/trace/passes.h"

#include <algorithm>
#include <cstdio>

#include "vgpu/record.h"

namespace host {

vgpu::Texture entry_texture(vgpu::Device& gpu, const std::string& name, size_t count, int channels,
                            const std::string& what, bool xy) {
  const int maxs = gpu.profile().max_texture_size;
  // About square: the width is the smallest power of two whose square holds the entries, so a
  // GL driver whose textures stop at 16384 texels (llvmpipe) takes what one long row of 32768
  // (the h200 profile's limit) did not. The H200 ran the same frames in the same GPU time with
  // either layout (docs/studies/structures.md, "Tried: the structures' textures laid out square").
  size_t side = 1;
  while (side * side < std::max<size_t>(count, 1)) side *= 2;
  const int w = int(std::min<size_t>(side, size_t(maxs)));
  const size_t h = (std::max<size_t>(count, 1) + size_t(w) - 1) / size_t(w);
  if (h > size_t(maxs)) {
    // A profile whose largest texture holds them (the smallest such), for the advice.
    std::string fits;
    int fits_size = 0;
    for (const vgpu::Profile& p : vgpu::profiles())
      if (size_t(p.max_texture_size) * size_t(p.max_texture_size) >= count &&
          (fits.empty() || p.max_texture_size < fits_size)) {
        fits = p.name;
        fits_size = p.max_texture_size;
      }
    throw vgpu::LimitError(
        what + ": " + std::to_string(count) + " entries; profile " + gpu.profile().name +
        " holds at most " + std::to_string(size_t(maxs) * size_t(maxs)) + " in one " +
        std::to_string(maxs) + "x" + std::to_string(maxs) + " texture" +
        (fits.empty() ? std::string(", and no profile holds more")
                      : " (--profile " + fits + "'s " + std::to_string(fits_size) + "x" +
                            std::to_string(fits_size) + " textures hold them)"));
  }
  if (!xy && count >= (size_t(1) << 24))
    throw vgpu::LimitError(what + ": " + std::to_string(count) +
                           " entries; indices are exact floats only below 2^24");
  return gpu.make_texture(name, w, int(h), channels);
}

using vgpu::Stencil;
using vgpu::Texture;

void PassRunner::set_work(const Stencil* work) {
  if (!gpu_.has_stencil()) return;
  gpu_.set_stencil_test(nullptr);
  gpu_.set_work_mask(opt_.masks || opt_.host_shortcut ? work : nullptr);
  gpu_.set_work_mask_counts_as_masked(opt_.masks);
}

const vgpu::PassRecord& PassRunner::pass(const vgpu::Program& p,
                                         std::initializer_list<const Texture*> in, Texture& out,
                                         const Stencil* work) {
  return pass(p, in, {&out}, work);
}

const vgpu::PassRecord& PassRunner::pass(const vgpu::Program& p,
                                         std::initializer_list<const Texture*> in,
                                         std::initializer_list<Texture*> outs,
                                         const Stencil* work) {
  return pass(p, std::span<const Texture* const>(in.begin(), in.size()), outs, work);
}

const vgpu::PassRecord& PassRunner::pass(const vgpu::Program& p, std::span<const Texture* const> in,
                                         std::initializer_list<Texture*> outs,
                                         const Stencil* work) {
  gpu_.use_program(p);
  gpu_.unbind_textures();
  int unit = 0;
  for (const Texture* t : in) gpu_.bind_texture(unit++, *t);
  gpu_.set_targets(outs);
  set_work(work);
  const bool traced = traces_pixel(work);
  if (opt_.observer) opt_.observer->pass_begin(work);
  const vgpu::PassRecord& rec = rect ? gpu_.draw(*rect) : gpu_.draw();
  // The observer sees the first target (a fused pass's other targets are the same pass).
  if (opt_.observer)
    opt_.observer->pass(
        {p, rec, **outs.begin(), gpu_.branch_flags(), gpu_.stats(), gpu_.loop_iterations()});
  if (traced && !p.idle_discards()) {
    const int x = opt_.trace_pixel->x, y = opt_.trace_pixel->y;
    for (const Texture* out : outs) {
      const float* t = out->texel(x, y);
      char line[256];
      int n = std::snprintf(line, sizeof line, "  %-22s %-24s -> %-14s (", p.paper_name(), p.name(),
                            out->name().c_str());
      for (int c = 0; c < out->channels(); ++c)
        n += std::snprintf(line + n, sizeof line - size_t(n), "%s%g", c ? ", " : "", t[c]);
      *opt_.trace_out << line << ")\n";
    }
  }
  return rec;
}

void PassRunner::trace_targets(const vgpu::Program& p, std::initializer_list<const Texture*> outs) {
  const int x = opt_.trace_pixel->x, y = opt_.trace_pixel->y;
  for (const Texture* t : outs) {
    const float* v = t->texel(x, y);
    char line[256];
    std::snprintf(line, sizeof line, "  %-22s %-24s -> %-14s (%g, %g, %g, %g)\n", p.paper_name(),
                  p.name(), t->name().c_str(), v[0], v[1], v[2], v[3]);
    *opt_.trace_out << line;
  }
}

bool PassRunner::traces_pixel(const Stencil* work) const {
  return opt_.trace_pixel && opt_.trace_out &&
         (!work || work->get(opt_.trace_pixel->x, opt_.trace_pixel->y) != 0);
}

uint64_t PassRunner::count(const vgpu::Program& p, const Texture& in, const Stencil* work,
                           Stencil* write) {
  const bool traced = traces_pixel(work);
  // The masks are the emulator's (its work mask, or stencils under --masks on).
  if (gpu_.has_stencil()) gpu_.set_stencil_write(write);
  gpu_.begin_query();
  pass(p, {&in}, counter_, work);
  const uint64_t n = gpu_.end_query();
  if (gpu_.has_stencil()) gpu_.set_stencil_write(nullptr);
  if (opt_.observer) opt_.observer->query(n, write, gpu_.stats());
  report_rays(p.name(), n);
  if (traced) {
    char line[160];
    const char* mine = !write                                                 ? ""
                       : write->get(opt_.trace_pixel->x, opt_.trace_pixel->y) ? "counted"
                                                                              : "discarded";
    std::snprintf(line, sizeof line, "  %-22s %-24s    query: %llu rays; this one %s\n",
                  p.paper_name(), p.name(), static_cast<unsigned long long>(n), mine);
    *opt_.trace_out << line;
  }
  return n;
}

// One report at most every progress_every_ms, one thread at a time (a report under way makes
// the others skip theirs). A callback that throws (a full disk under stderr, an allocation) must
// not fail the frame: progress stops for the rest of it.
void PassRunner::report(WalkProgress w, std::chrono::steady_clock::time_point now) {
  const std::unique_lock lk(progress_mu_, std::try_to_lock);
  if (!lk.owns_lock() || progress_failed_ ||
      now - last_report_ < std::chrono::duration<double, std::milli>(opt_.progress_every_ms))
    return;
  last_report_ = now;
  w.rays = walking;
  w.passes = gpu_.stats().totals.passes;  // a batch walk's own come with its replay
  try {
    opt_.walk_progress(w);
  } catch (...) {
    progress_failed_ = true;
  }
}

void PassRunner::report_rays(const char* query, uint64_t rays) {
  if (!opt_.walk_progress) return;
  WalkProgress w;
  w.query = query;
  w.rays_walking = int64_t(rays);
  report(w, std::chrono::steady_clock::now());
}

void PassRunner::report_batches(int done, int total, std::chrono::steady_clock::time_point start) {
  if (!opt_.walk_progress || total <= 0) return;
  const auto now = std::chrono::steady_clock::now();
  WalkProgress w;
  w.done = double(done) / double(total);
  const double ms = std::chrono::duration<double, std::milli>(now - start).count();
  if (done > 0) w.left_ms = ms * double(total - done) / double(done);
  report(w, now);
}

uint32_t PassRunner::own_only_units(const vgpu::Program& p) {
  auto cached = std::find_if(own_only_.begin(), own_only_.end(),
                             [&](const auto& e) { return e.first == &p; });
  if (cached != own_only_.end()) return cached->second;
  const vgpu::Recording rec = p.record();
  uint32_t own = 0, other = 0;
  for (const vgpu::RecNode& n : rec.nodes) {
    if (n.op == vgpu::Op::fetch_own) own |= 1u << n.unit;
    if (n.op == vgpu::Op::fetch) other |= 1u << n.unit;
  }
  own_only_.emplace_back(&p, own & ~other);
  return own & ~other;
}

}  // namespace host
