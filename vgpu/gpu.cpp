// The fragment processor and pipeline state: programs, units, targets, queries, and the pass
// itself (draw() plans it, run_rows() shades the fragments of a band of rows).
#include "vgpu/gpu.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstring>
#include <vector>

#include "vgpu/gpu_internal.h"
#include "vgpu/row_shader.h"

namespace vgpu {

using namespace gpu_detail;

// What one draw's row workers share: where outputs go, where idle fragments' outputs come from,
// and the batch-flag maps. Built once per draw on the calling thread.
struct Gpu::DrawPlan {
  struct Out {
    float* data = nullptr;  // the target's texels
    int width = 0, ch = 0;
    Format fmt = Format::fp32;
    const float* idle_src = nullptr;  // passthrough texels to copy for idle fragments, or null
    bool exact = false;               // same format: already rounded, a plain copy
  };
  Out out[kMaxOutputs];
  uint64_t idle_branches = 0;
  // Per fragment of the rectangle: kTook, kIdle or 0 (not shaded). Null: the program has no
  // branches.
  uint8_t* flags = nullptr;
  bool list_runs = false;       // collect Chunk::runs (for a PairRecord)
  bool list_survivors = false;  // collect Chunk::survivors (the stencil write's non-zero list)
  // The work mask's non-zero list (Stencil::nonzero_): only these fragments are visited. Set only
  // for a whole-target draw without stencil test; idle fragments are then settled in draw().
  const std::vector<uint32_t>* list = nullptr;
  uint8_t* stencil = nullptr;                   // the stencil write's bits, or null
  uint8_t *took8 = nullptr, *took32 = nullptr;  // tiles holding a kTook fragment
  int cols8 = 0, cols32 = 0;
  // A looping program: per texel of the target, the iterations its fragment ran (0 if none).
  uint32_t* loop_map = nullptr;

  // The steps of draw(), in the order it takes them (a nested type: they reach the Gpu's state).
  static void check(const Gpu& g, const Program& p, const Program::Analysis& a, const Rect& rect);
  void set_flags(Gpu& g, const Rect& rect, bool use_list);
  void set_outputs(Gpu& g, const Program& p, bool carries, bool whole);
  void settle_listed_idle(Gpu& g, const Program& p, const std::vector<uint32_t>& listed);
  void shade(const Gpu& g, const Program& p, const Rect& rect, int ya, int yb, Chunk& c) const;
  static Chunk sum(const std::vector<Chunk>& chunks);
};

void Gpu::fail(const std::string& what) const {
  throw Error(what);
}

void Gpu::set_recorded(std::vector<std::string> names) {
  recorded_ = std::move(names);
  mirrors_.clear();
}

const Program& Gpu::executing(const Program& p) const {
  if (recorded_.empty() ||
      (std::find(recorded_.begin(), recorded_.end(), "all") == recorded_.end() &&
       std::find(recorded_.begin(), recorded_.end(), p.name()) == recorded_.end()))
    return p;
  Mirror& m = mirrors_[p.id()];
  const std::span<const std::byte> bytes = p.uniform_bytes();
  if (!m.program || m.precision != p.precision() ||
      !std::equal(bytes.begin(), bytes.end(), m.uniforms.begin(), m.uniforms.end())) {
    m.program = RecordedProgram::of(p);
    m.uniforms.assign(bytes.begin(), bytes.end());
    m.precision = p.precision();
  }
  return *m.program;
}

void Gpu::use_program(const Program& program) {
  if (in_draw_)
    fail(std::string("program '") + program.name() + "': no recursion (bind inside a pass)");
  bound_ = program_ = &program;  // draw() swaps in its recording where set_recorded names it
  if (program.id() == loaded_program_) return;
  loaded_program_ = program.id();
  count_program_load(stats_, program, profile_);
}

void Gpu::bind_texture(int unit, const Texture& texture) {
  if (unit < 0 || unit >= kMaxTextureUnits)
    fail("texture unit " + std::to_string(unit) + " does not exist (0.." +
         std::to_string(kMaxTextureUnits - 1) + ")");
  check_texture(texture);
  units_[unit] = &texture;
}

void Gpu::unbind_textures() {
  units_.fill(nullptr);
}

void Gpu::set_targets(std::initializer_list<Texture*> targets) {
  targets_.assign(targets.begin(), targets.end());
  for (Texture* t : targets_) check_texture(*t);
}

void Gpu::clear(Texture& t, std::initializer_list<float> value) {
  if (int(value.size()) != t.channels())
    fail("clear of texture '" + t.name() + "': " + std::to_string(value.size()) + " values for " +
         std::to_string(t.channels()) + " channels");
  check_texture(t);
  // A frame-sized clear (16 MB at 1024x1024) is split over the threads like a pass: serial, it
  // was half of a 16-thread frame's host work outside the passes.
  const std::span<const float> texel(value.begin(), value.size());
  ++t.version_;
  parallel_blocks(size_t(t.height()), size_t(65536 / t.width()) + 1,
                  [&](size_t y0, size_t y1) { t.fill_rows(texel, int(y0), int(y1)); });
  Counters c;
  c.clears = 1;
  c.bytes_written = t.bytes();
  stats_.totals += c;
}

void Gpu::begin_query() {
  if (query_active_) fail("begin_query: a query is already active");
  query_active_ = true;
  query_count_ = 0;
}

uint64_t Gpu::end_query() {
  if (!query_active_) fail("end_query: no query is active");
  query_active_ = false;
  count_readback(stats_, program_, query_count_);
  return query_count_;
}

const PassRecord& Gpu::draw() {
  if (targets_.empty())
    fail(program_
             ? "program '" + std::string(program_->name()) + "': draw with no render target set"
             : std::string("draw: no render target set"));
  return draw(Rect{0, 0, targets_[0]->width(), targets_[0]->height()});
}

// One row worker's share of a pass: rows [y0, y1) of r, at lane family L (row_shader.h walks
// the rows; the loop depends on the masks the pass has).
template <class L>
void Gpu::run_rows(const Program& p, const Rect& r, int y0, int y1, const DrawPlan& plan,
                   Chunk& result) const {
  // Counted in a local and stored once: neighbouring chunks share cache lines, and other
  // threads are counting into them.
  Chunk out;
  out.runs = std::move(result.runs);
  out.survivors = std::move(result.survivors);
  BoundTexture views[kMaxTextureUnits];
  for (int u = 0; u < kMaxTextureUnits; ++u)
    if (units_[u])
      views[u] = {units_[u]->data().data(), units_[u]->width(), units_[u]->height(),
                  units_[u]->channels()};
  const bool dynamic = profile_.branching == Branching::dynamic;
  Fragments<L> f(views, dynamic, &out.idle, nullptr);
  RowShader<L, DrawPlan, Chunk> rows(p, r, plan, out, f, stencil_test_, work_mask_, work_masked_);
  if (!work_mask_)
    rows.all_rows(y0, y1);
  else if (plan.list)
    rows.listed_rows(y0, y1);
  else
    rows.masked_rows(y0, y1);
  result = std::move(out);
}

// After a pass that carried idle fragments over from passthrough units: each source and target
// now agree except at the fragments that ran: `runs`, or those the row chunks listed when
// `chunk_runs`; neither: no record.
void Gpu::track_pairs(const Program& p, const std::shared_ptr<const std::vector<uint32_t>>& runs,
                      bool chunk_runs) {
  for (int o = 0; o < p.outputs(); ++o) {
    const Texture& dst = *targets_[o];
    const Texture& src = *units_[p.passthrough(o)];
    // Forget every record about either texture, then note the new one.
    std::erase_if(pairs_, [&](const PairRecord& r) {
      return r.a == &src || r.b == &src || r.a == &dst || r.b == &dst;
    });
    if ((!runs && !chunk_runs) || src.format() != dst.format()) continue;
    PairRecord rec{&src, &dst, src.uid_, src.version_, dst.uid_, dst.version_, {}};
    if (runs) {
      rec.differ = runs;
    } else {
      size_t n = 0;
      for (const Chunk& c : chunks_) n += c.runs.size();
      auto differ = std::make_shared<std::vector<uint32_t>>();
      differ->reserve(n);
      for (const Chunk& c : chunks_) differ->insert(differ->end(), c.runs.begin(), c.runs.end());
      rec.differ = std::move(differ);
    }
    pairs_.push_back(std::move(rec));
  }
}

// Refuses a pass the profile or the bound state cannot run: the profile's checks, masks shaped
// like the target, and for a work mask, passthrough units that can stand in for idle fragments.
void Gpu::DrawPlan::check(const Gpu& g, const Program& p, const Program::Analysis& a,
                          const Rect& rect) {
  const std::string pname = p.name();
  check_pass(g.profile_, p, a, g.units_.data(), g.targets_, rect);
  const Texture& t0tex = *g.targets_[0];
  auto check_mask = [&](const Stencil* s, const char* what) {
    if (s && (s->width() != t0tex.width() || s->height() != t0tex.height()))
      g.fail("program '" + pname + "': " + what + " size differs from the render target");
  };
  check_mask(g.stencil_test_, "stencil");
  check_mask(g.stencil_write_, "stencil");
  check_mask(g.work_mask_, "work mask");
  if (!g.work_mask_ || p.idle_discards()) return;
  if (!p.has_passthrough())
    g.fail("program '" + pname + "' declares no passthrough, so it cannot skip idle fragments");
  for (int o = 0; o < p.outputs(); ++o) {
    const Texture* src = g.units_[p.passthrough(o)];
    if (!src || src->width() != g.targets_[o]->width() ||
        src->height() != g.targets_[o]->height() || src->channels() != g.targets_[o]->channels())
      g.fail("program '" + pname + "': passthrough unit " + std::to_string(p.passthrough(o)) +
             " does not hold a texture shaped like render target " + std::to_string(o));
  }
}

// A program that branches: the batch-flag map and the tiles that took the branch. Complete after
// the pass (branch flags are a per-fragment map): masked fragments stay 0. Under a listed mask
// every fragment but the listed ones is idle (those overwrite their flag when they run): one
// fill with the right value.
void Gpu::DrawPlan::set_flags(Gpu& g, const Rect& rect, bool use_list) {
  const size_t n = size_t(rect.width()) * size_t(rect.height());
  const uint8_t base = use_list && !g.work_masked_ ? kIdle : 0;
  if (use_list && g.flags_ran_ && g.flags_base_ == base && g.batch_flags_.size() == n) {
    // The buffer holds `base` but where the last listed pass ran: reset those only.
    for (const uint32_t i : *g.flags_ran_) g.batch_flags_[i] = base;
  } else {
    g.batch_flags_.assign(n, base);
  }
  g.flags_ran_.reset();  // set again after the pass, if it is listed
  g.flags_base_ = base;
  g.flags_size_ = n;
  flags = g.batch_flags_.data();
  cols8 = (rect.width() + 7) / 8;
  cols32 = (rect.width() + 31) / 32;
  g.took8_.assign(size_t(cols8) * size_t((rect.height() + 3) / 4), 0);
  g.took32_.assign(size_t(cols32) * size_t((rect.height() + 31) / 32), 0);
  took8 = g.took8_.data();
  took32 = g.took32_.data();
}

// Where each output goes and, when idle fragments carry their outputs over (`carries`), where
// those come from. Where the last pass between the same two textures left them equal outside
// the fragments it ran (a PairRecord; every fragment drawn, no stencil test, same format), only
// the texels that differ and are idle now are copied, here; the row workers copy nothing.
void Gpu::DrawPlan::set_outputs(Gpu& g, const Program& p, bool carries, bool whole) {
  auto same = [](const Texture* t, const Texture* r, uint64_t uid, uint64_t version) {
    return t == r && t->uid_ == uid && t->version_ == version;
  };
  for (int o = 0; o < p.outputs(); ++o) {
    Texture& dst = *g.targets_[o];
    out[o] = {nullptr, dst.width(), dst.channels(), dst.format(), nullptr, false};
    if (!carries) continue;
    const Texture& src = *g.units_[p.passthrough(o)];
    out[o].idle_src = src.data().data();
    out[o].exact = src.format() == dst.format() || dst.format() == Format::fp32;
    if (!whole || src.format() != dst.format()) continue;
    list_runs = !list;  // the list is the run set
    for (auto rec = g.pairs_.begin(); rec != g.pairs_.end(); ++rec)
      if ((same(&src, rec->a, rec->uid_a, rec->version_a) &&
           same(&dst, rec->b, rec->uid_b, rec->version_b)) ||
          (same(&src, rec->b, rec->uid_b, rec->version_b) &&
           same(&dst, rec->a, rec->uid_a, rec->version_a))) {
        out[o].idle_src = nullptr;
        const size_t ch = size_t(dst.channels());
        const uint8_t* bits = g.work_mask_->bits_.data();
        float* dd = dst.data_.data();
        const float* sd = src.data_.data();
        // The texels that differ, copied where idle (the mask is as wide as the target); a long
        // list over the threads (each texel is written once, by whichever thread takes it).
        const std::vector<uint32_t>& differ = *rec->differ;
        auto copy = [&](size_t k0, size_t k1) {
          if (ch == 4) {  // a fixed-size copy: inlined
            for (size_t k = k0; k < k1; ++k)
              if (const uint32_t i = differ[k]; bits[i] == 0)
                std::memcpy(dd + size_t(i) * 4, sd + size_t(i) * 4, 4 * sizeof(float));
          } else {
            for (size_t k = k0; k < k1; ++k)
              if (const uint32_t i = differ[k]; bits[i] == 0)
                std::memcpy(dd + size_t(i) * ch, sd + size_t(i) * ch, ch * sizeof(float));
          }
        };
        g.parallel_blocks(differ.size(), 32768, copy);
        g.pairs_.erase(rec);  // used up: if the pass fails, no record claims the textures agree
        break;
      }
  }
}

// Under a listed work mask, idle fragments are settled before the pass: the texels between
// listed ones get the passthrough's value (where no PairRecord spared that) and the stencil
// write its idle value.
void Gpu::DrawPlan::settle_listed_idle(Gpu& g, const Program& p,
                                       const std::vector<uint32_t>& listed) {
  for (int o = 0; o < p.outputs(); ++o) {
    Out& cp = out[o];
    if (!cp.idle_src) continue;
    float* dst = g.targets_[o]->data_.data();
    const size_t ch = size_t(cp.ch), n = size_t(cp.width) * size_t(g.targets_[o]->height());
    auto copy = [&](size_t from, size_t to) {  // texels [from, to)
      if (cp.exact)
        std::memcpy(dst + from * ch, cp.idle_src + from * ch, (to - from) * ch * sizeof(float));
      else
        for (size_t i = from * ch; i < to * ch; ++i) dst[i] = round_to(cp.fmt, cp.idle_src[i]);
    };
    size_t next = 0;
    for (const uint32_t i : listed) {
      if (i > next) copy(next, i);
      next = size_t(i) + 1;
    }
    if (n > next) copy(next, n);
    cp.idle_src = nullptr;
  }
  if (!g.stencil_write_) return;
  const uint8_t value = p.idle_discards() ? 0 : 1;
  std::vector<uint8_t>& bits = g.stencil_write_->bits_;
  const auto* nz = g.stencil_write_->listed_version_ == g.stencil_write_->version_
                       ? g.stencil_write_->nonzero_.get()
                       : nullptr;
  if (value == 0 && nz && nz->size() < bits.size() / 16) {
    // Only the listed pixels are non-zero: clear those (the usual case, a query pass narrowing
    // the mask it reads).
    for (const uint32_t i : *nz) bits[i] = 0;
  } else {
    std::memset(bits.data(), value, bits.size());
  }
}

// One row worker's rows [ya, yb): run_rows at the lanes the Gpu runs and the program's precision.
void Gpu::DrawPlan::shade(const Gpu& g, const Program& p, const Rect& rect, int ya, int yb,
                          Chunk& c) const {
  const DrawPlan& plan = *this;
  const Format precision = g.precision_of(p);
  // Reduced precision runs at width 1 (the scalar reference) or 8.
  if (precision == Format::fp16) {
    if (g.lanes_ == 1)
      g.run_rows<RoundedLanes<1, Format::fp16>>(p, rect, ya, yb, plan, c);
    else
      g.run_rows<RoundedLanes<8, Format::fp16>>(p, rect, ya, yb, plan, c);
    return;
  }
  if (precision == Format::fp24) {
    if (g.lanes_ == 1)
      g.run_rows<RoundedLanes<1, Format::fp24>>(p, rect, ya, yb, plan, c);
    else
      g.run_rows<RoundedLanes<8, Format::fp24>>(p, rect, ya, yb, plan, c);
    return;
  }
  switch (g.lanes_) {
    case 1:
      g.run_rows<SimdLanes<1>>(p, rect, ya, yb, plan, c);
      break;
    case 4:
      g.run_rows<SimdLanes<4>>(p, rect, ya, yb, plan, c);
      break;
    case 8:
      g.run_rows<SimdLanes<8>>(p, rect, ya, yb, plan, c);
      break;
    default:
      g.run_rows<SimdLanes<16>>(p, rect, ya, yb, plan, c);
      break;
  }
}

// The row chunks' counts, summed (their run and survivor lists stay with them).
Gpu::Chunk Gpu::DrawPlan::sum(const std::vector<Chunk>& chunks) {
  Chunk sum;
  for (const Chunk& c : chunks) {
    sum.launched += c.launched;
    sum.shaded += c.shaded;
    sum.masked += c.masked;
    sum.discarded += c.discarded;
    sum.idle += c.idle;
    sum.idle_flags += c.idle_flags;
  }
  return sum;
}

// One pass: check it, plan it (DrawPlan's steps), shade its rows on the workers, then keep what
// the next passes reuse (lists, PairRecords) and count it (the batch and loop counters).
const PassRecord& Gpu::draw(const Rect& rect) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!program_) fail("draw: no program bound");
  // The recording of the program as it is now (its uniforms may change after use_program).
  if (!recorded_.empty()) program_ = &executing(*bound_);
  const Program& p = *program_;
  const std::string pname = p.name();
  if (in_draw_) fail("program '" + pname + "': no recursion (a pass started inside a pass)");
  const Program::Analysis a = p.analyze();
  DrawPlan::check(*this, p, a, rect);
  const Texture& t0tex = *targets_[0];

  looped_ = false;  // until this pass runs a loop
  if (const PassTally* t = std::exchange(replay_, nullptr)) return replay(p, a, rect, *t, t0);

  in_draw_ = true;
  std::vector<Chunk>& chunks = chunks_;
  DrawPlan plan;
  plan.idle_branches = uint64_t(a.branches);
  // Under a work mask whose non-zero pixels the last pass that wrote it listed, only those run
  // (a whole-target draw without stencil test).
  const bool whole = !stencil_test_ && rect.x0 == 0 && rect.y0 == 0 && rect.x1 == t0tex.width() &&
                     rect.y1 == t0tex.height();
  const bool use_list = work_mask_ && whole && work_mask_->listed_version_ == work_mask_->version_;
  if (a.branches > 0)
    plan.set_flags(*this, rect, use_list);
  else
    flags_size_ = 0;  // no branches: no flags (the buffer keeps its contents for later)
  // The masks as they were before the pass, for the batch counters: a pass may write the mask
  // it tests (a query pass counting into the stencil it reads).
  Stencil work_before, test_before;
  const Stencil* work_view = work_mask_;
  const Stencil* test_view = stencil_test_;
  const bool looping = a.loop.loops > 0;
  looped_ = looping;
  if (looping) {
    loop_map_.assign(size_t(t0tex.width()) * size_t(t0tex.height()), 0);
    plan.loop_map = loop_map_.data();
  }
  // (a listed pass's branch counters read only the flags; the loop counters read the mask)
  if ((plan.flags || looping) && (!use_list || looping) && stencil_write_ &&
      stencil_write_ == work_mask_)
    work_view = &(work_before = *work_mask_);
  if ((plan.flags || looping) && stencil_write_ && stencil_write_ == stencil_test_)
    test_view = &(test_before = *stencil_test_);
  // Idle fragments keep their previous outputs, copied from the passthrough units.
  const bool carries = work_mask_ && !p.idle_discards();
  // Held here: this pass may write the mask and give it a new list.
  std::shared_ptr<const std::vector<uint32_t>> listed;
  if (use_list) {
    listed = work_mask_->nonzero_;
    plan.list = listed.get();
  }
  plan.set_outputs(*this, p, carries, whole);
  if (plan.list) plan.settle_listed_idle(*this, p, *listed);
  // The stencil write's non-zero list is known after the pass when every fragment's value is:
  // the fragments that ran and survived (idle ones, if any, are discarded).
  plan.list_survivors = stencil_write_ && whole && (!work_mask_ || p.idle_discards());
  if (stencil_write_) {
    plan.stencil = stencil_write_->bits_.data();
    ++stencil_write_->version_;
  }
  // Pass writes: one version step per target (the row workers write through plan.out).
  for (int o = 0; o < p.outputs(); ++o) plan.out[o].data = targets_[o]->texel_mut(0, 0);
  auto body = [&](int ya, int yb, Chunk& c) { plan.shade(*this, p, rect, ya, yb, c); };
  parallel_rows(rect, plan.list ? uint64_t(plan.list->size()) : rect.area(), body, chunks);
  in_draw_ = false;

  // What the next passes reuse: the flags this pass wrote, the textures it left equal, the
  // stencil write's non-zero list.
  if (plan.flags && plan.list) flags_ran_ = listed;  // the only flags this pass wrote
  if (carries) track_pairs(p, listed, plan.list_runs);
  if (plan.list_survivors) {
    size_t n = 0;
    for (const Chunk& c : chunks) n += c.survivors.size();
    auto nz = std::make_shared<std::vector<uint32_t>>();
    nz->reserve(n);
    for (const Chunk& c : chunks) nz->insert(nz->end(), c.survivors.begin(), c.survivors.end());
    stencil_write_->nonzero_ = std::move(nz);
    stencil_write_->listed_version_ = stencil_write_->version_;
  }

  // The counters: the chunks' sums, the loop batches, the branch batches.
  const Chunk sum = DrawPlan::sum(chunks);
  std::vector<uint64_t> loop_active, loop_idle;
  LoopCounts loop_n;
  if (looping) {
    loop_n = loop_batches(rect, plan.loop_map, uint32_t(t0tex.width()), work_view, test_view,
                          work_masked_, profile_.branch_granularity, a.loop.max_iterations,
                          loop_active, loop_idle);
    if (loop_n.shaded != sum.shaded) fail("program '" + pname + "': loop batches miscounted");
  }
  std::array<uint64_t, 2> batch{};
  if (plan.flags)
    batch =
        // From the list where it is short; otherwise a scan of the tiles (eight flags a step),
        // where under a listed mask the flags alone decide (no stencil test; fragments off the
        // list hold kIdle, or 0 where that counts as masked), as if every fragment ran.
        plan.list && plan.list->size() * 16 < rect.area()
            ? idle_in_batches_listed(rect.width(), rect.height(), plan.flags, *plan.list,
                                     work_masked_, sum.idle_flags)
            : idle_in_batches(rect, plan.flags, plan.list ? nullptr : work_view, test_view,
                              work_masked_, sum.idle_flags, plan.took8, plan.took32);
  return settle(p, a, rect, sum, plan.flags ? &batch : nullptr, looping ? &loop_n : nullptr,
                std::move(loop_active), std::move(loop_idle), t0, 0.0);
}

}  // namespace vgpu
