// The batch fast path of a walk (included by host/trace/walks/walk.h, which defines the pass
// keys and the device walker it uses; not a header of its own). An emulator shortcut, not
// modelled hardware: each batch of 8 neighbouring pixels runs through every pass of the walk
// with its ray state in registers (vgpu/batch.h), and the device then replays the pass sequence,
// charging each pass from what the batches tallied for it, so that statistics, program loads
// and query read-backs come out as a pass-by-pass walk's (docs/architecture.md, section 3b).
//   BatchWalker     one batch through every pass, tallying each pass for the replay;
//   CheckWalker     every pass site once, to check the bindings allow a batch walk;
//   run_in_batches  the batches over the threads, then the replay.
#pragma once

#ifndef VGPU_WALK_H_INSIDE
#error "include host/trace/walks/walk.h, which includes this after the types it needs"
#endif

namespace host::walk {

// What one pass of a walk knows about a program, worked out once per walk.
struct ProgramInfo {
  const vgpu::Program* program = nullptr;
  // What runs for it: the program, or its recording where the emulator runs recordings
  // (vgpu::Gpu::set_recorded), made once per walk.
  const vgpu::Program* run = nullptr;
  vgpu::Format precision = vgpu::Format::fp32;
  int branches = 0;       // f.branch() calls: the batch counters are kept for it
  uint32_t own_only = 0;  // units the program reads only at the fragment's own texel
  bool idle_discards = false;
  std::array<int, vgpu::kMaxOutputs> passthrough{};
};

// The batch counters of one pass within one 32x32 tile: its 8x4 tiles holding a fragment that
// took a branch, the fragments that took one, and those that ran (in all and per 8x4 tile).
struct TileAcc {
  uint32_t took_tiles = 0;  // bit j: 8x4 tile j (row-major, 4 per row) holds a took fragment
  uint32_t took = 0, ran = 0;
  std::array<uint8_t, 32> ran_in{};
  bool touched = false;
};

// Runs the walk for one batch of pixels (8 neighbours of a row): every pass runs the program on
// the lanes its work mask leaves (vgpu::run_batch), with the ray state in registers; queries
// return the lanes that survive. Tallies every pass (by PassKey) for the replay. The bindings of
// a pass depend only on its site and parity: they are resolved once per walker (a Plan).
class BatchWalker {
 public:
  using Count = uint8_t;  // lanes as bits
  static bool any(Count c) { return c != 0; }

  BatchWalker(const vgpu::Gpu& gpu, const std::vector<ProgramInfo>& programs, bool work_masked,
              int width, int height)
      : programs_(programs),
        dynamic_(gpu.profile().branching == vgpu::Branching::dynamic),
        work_masked_(work_masked),
        width_(width),
        height_(height) {}

  struct Entry {
    vgpu::PassTally tally;
    TileAcc acc;
  };
  Keyed<Entry> entries;

  void begin(int x0, int y, int n) {
    x0_ = x0;
    y_ = y;
    n_ = n;
    valid_ = uint8_t((1u << n) - 1);
    tile8x4_ = (y % 32) / 4 * 4 + (x0 % 32) / 8;  // the 8x4 tile of its 32x32 tile it lies in
    loaded_ = 0;
    masks_loaded_ = 0;
  }
  void fill(const Stencil& m, uint8_t v) { set_mask(mask_id(m), v ? valid_ : 0); }
  void copy(const Stencil& to, const Stencil& from) {
    set_mask(mask_id(to), mask_bits(mask_id(from)));
  }
  void traced(Count) {}      // the replay counts rays
  void unfinished(Count) {}  // likewise
  void pass(const PassKey& key, const vgpu::Program& p, std::initializer_list<const Texture*> in,
            std::initializer_list<Texture*> out, const Stencil* work) {
    Plan& plan = plans_[size_t(key.site)][key.parity];
    if (!plan.info)
      build(plan, p, in.begin(), int(in.size()), out.begin(), int(out.size()), work, nullptr);
    run(key, plan);
  }
  Count count(const PassKey& key, const vgpu::Program& p, const Texture& in, const Stencil* work,
              Stencil* write) {
    Plan& plan = plans_[size_t(key.site)][key.parity];
    if (!plan.info) {
      const Texture* input = &in;
      build(plan, p, &input, 1, nullptr, 0, work, write);
    }
    return run(key, plan);
  }

  // The batch's final state into the textures and masks: each ping-pong pair gets the walk's
  // current texel in both textures (a pass-by-pass walk leaves the other one equal to it or
  // one pass older, and no pass reads it before rewriting it whole).
  struct Pair {
    const Texture* t[2];
    float* data[2];
  };
  struct MaskOut {
    const Stencil* mask;
    uint8_t* bits;
  };
  void finish(const Pair* pairs, const int* current, int npairs, const MaskOut* masks, int nmasks) {
    for (int k = 0; k < npairs; ++k) {
      const vgpu::Slot& v = slots_[size_t(loaded(texture_id(*pairs[k].t[current[k]])))];
      for (int b = 0; b < 2; ++b) v.store(*pairs[k].t[b], pairs[k].data[b], x0_, y_, n_);
    }
    for (int k = 0; k < nmasks; ++k) {
      const uint8_t bits = mask_bits(mask_id(*masks[k].mask));
      uint8_t* row = masks[k].bits + size_t(y_) * size_t(width_) + size_t(x0_);
      for (int i = 0; i < n_; ++i) row[i] = (bits >> i) & 1;
    }
  }

  // The batch counters of the tile (tx, ty) (32x32 pixels) whose batches just ran: per pass of a
  // program with branches, the idle fragments of its 8x4 tiles and of itself holding a
  // fragment that took a branch (what Gpu::draw()'s idle_in_batches subtracts).
  void settle_tile(int tx, int ty) {
    for (const PassKey& key : touched_) {
      Entry& e = entries.at(key);
      TileAcc& a = e.acc;
      uint64_t near8 = 0;
      for (uint32_t m = a.took_tiles; m; m &= m - 1) {
        const int j = std::countr_zero(m);
        const int x = tx * 32 + (j % 4) * 8, y = ty * 32 + (j / 4) * 4;
        near8 += work_masked_
                     ? a.ran_in[size_t(j)]
                     : uint64_t(std::min(8, width_ - x)) * uint64_t(std::min(4, height_ - y));
      }
      e.tally.idle_near_took8x4 += near8 - a.took;
      if (a.took > 0) {
        const uint64_t area =
            uint64_t(std::min(32, width_ - tx * 32)) * uint64_t(std::min(32, height_ - ty * 32));
        e.tally.idle_near_took32x32 += (work_masked_ ? a.ran : area) - a.took;
      }
      a = TileAcc{};
    }
    touched_.clear();
  }

 private:
  static constexpr int kSlots = 16, kMasks = 4;
  // One pass's bindings as slot and mask numbers.
  struct Plan {
    const ProgramInfo* info = nullptr;
    std::array<vgpu::BoundTexture, vgpu::kMaxTextureUnits> units{};  // resident: into a slot
    uint32_t reads = 0;  // slots loaded before the pass runs
    std::array<vgpu::BatchOutput, vgpu::kMaxOutputs> outputs{};
    int nout = 0;
    int work = -1, write = -1;  // mask numbers
  };

  int texture_id(const Texture& t) {
    for (int k = 0; k < ntextures_; ++k)
      if (slots_[size_t(k)].texture == &t) return k;
    if (ntextures_ == kSlots)
      throw vgpu::Error("batch walk: more than " + std::to_string(kSlots) + " textures");
    slots_[size_t(ntextures_)].texture = &t;
    return ntextures_++;
  }
  int mask_id(const Stencil& m) {
    for (int k = 0; k < nmasks_; ++k)
      if (masks_[size_t(k)] == &m) return k;
    if (nmasks_ == kMasks) throw vgpu::Error("batch walk: more than 4 masks");
    masks_[size_t(nmasks_)] = &m;
    return nmasks_++;
  }
  // Slot k holding this batch's texels (loaded from the texture on first use).
  int loaded(int k) {
    if (!((loaded_ >> k) & 1)) {
      slots_[size_t(k)].load(*slots_[size_t(k)].texture, x0_, y_, n_);
      loaded_ |= 1u << k;
    }
    return k;
  }
  uint8_t mask_bits(int k) {
    if (!((masks_loaded_ >> k) & 1)) {
      uint8_t bits = 0;
      const uint8_t* row = masks_[size_t(k)]->row(y_) + x0_;
      for (int i = 0; i < n_; ++i) bits |= uint8_t((row[i] != 0 ? 1u : 0u) << i);
      mask_bits_[size_t(k)] = bits;
      masks_loaded_ |= 1u << k;
    }
    return mask_bits_[size_t(k)];
  }
  void set_mask(int k, uint8_t bits) {
    mask_bits_[size_t(k)] = bits;
    masks_loaded_ |= 1u << k;
  }
  const ProgramInfo& info(const vgpu::Program& p) const {
    for (const ProgramInfo& i : programs_)
      if (i.program == &p) return i;
    throw vgpu::Error(std::string("program '") + p.name() + "' is not part of the batch walk");
  }
  void build(Plan& plan, const vgpu::Program& p, const Texture* const* in, int nin,
             Texture* const* out, int nout, const Stencil* work, const Stencil* write) {
    const ProgramInfo& pi = info(p);
    for (int u = 0; u < nin; ++u) {
      const Texture& t = *in[u];
      float* lanes = nullptr;
      if ((pi.own_only >> u) & 1) {
        const int k = texture_id(t);
        plan.reads |= 1u << k;
        lanes = &slots_[size_t(k)].v[0][0];
      }
      plan.units[size_t(u)] = {t.data().data(), t.width(), t.height(), t.channels(), lanes};
    }
    // A query's counter target is never read: its slot is not kept (nout 0).
    plan.nout = nout;
    for (int o = 0; o < nout; ++o) {
      const int k = texture_id(*out[o]);
      plan.reads |= 1u << k;  // a discarded fragment keeps the target's texel
      plan.outputs[size_t(o)].slot = &slots_[size_t(k)];
      if (!pi.idle_discards) {
        const int src = texture_id(*in[pi.passthrough[size_t(o)]]);
        plan.reads |= 1u << src;
        plan.outputs[size_t(o)].idle_source = &slots_[size_t(src)];
      }
    }
    plan.work = work ? mask_id(*work) : -1;
    plan.write = write ? mask_id(*write) : -1;
    plan.info = &pi;
  }

  Count run(const PassKey& key, const Plan& plan) {
    for (uint32_t need = plan.reads & ~loaded_; need; need &= need - 1)
      loaded(std::countr_zero(need));
    const ProgramInfo& pi = *plan.info;
    const uint8_t live = plan.work >= 0 ? uint8_t(mask_bits(plan.work) & valid_) : valid_;
    const vgpu::BatchRun r = vgpu::run_batch(*pi.run, pi.precision, dynamic_, plan.units.data(),
                                             plan.outputs.data(), plan.nout, live, x0_, y_);
    const uint8_t survivors = uint8_t(live & ~r.killed);
    if (plan.write >= 0)
      set_mask(plan.write, uint8_t((survivors | (pi.idle_discards ? 0 : ~live)) & valid_));
    Entry& e = entries.at(key);
    vgpu::PassTally& t = e.tally;
    const int ran = std::popcount(live);
    t.ran += uint64_t(ran);
    t.killed += uint64_t(std::popcount(r.killed));
    t.lanes_idle += r.lanes_idle;
    t.flagged_idle += uint64_t(std::popcount(r.idle));
    if (pi.branches > 0 && ran > 0) {
      TileAcc& a = e.acc;
      if (!a.touched) {
        a.touched = true;
        touched_.push_back(key);
      }
      const int j = tile8x4_;
      a.ran += uint32_t(ran);
      a.ran_in[size_t(j)] = uint8_t(a.ran_in[size_t(j)] + ran);
      if (r.took) {
        a.took += uint32_t(std::popcount(r.took));
        a.took_tiles |= 1u << j;
      }
    }
    return survivors;
  }

  const std::vector<ProgramInfo>& programs_;
  bool dynamic_, work_masked_;
  int width_, height_;
  int x0_ = 0, y_ = 0, n_ = 0;
  uint8_t valid_ = 0;
  int tile8x4_ = 0;
  std::array<vgpu::Slot, kSlots> slots_;
  int ntextures_ = 0;
  uint32_t loaded_ = 0;
  std::array<const Stencil*, kMasks> masks_{};
  std::array<uint8_t, kMasks> mask_bits_{};
  int nmasks_ = 0;
  uint32_t masks_loaded_ = 0;
  std::array<std::array<Plan, 8>, kMaxSites> plans_;
  std::vector<PassKey> touched_;
};

// Visits every pass site of the walk once (each query says "some" the first time its site asks
// and "none" after), noting every pass's program and bindings.
class CheckWalker {
 public:
  using Count = int;
  static bool any(Count c) { return c > 0; }
  struct Seen {
    const vgpu::Program* program;
    std::vector<const Texture*> in;
    std::vector<const Texture*> out;
  };
  std::vector<Seen> seen;

  void fill(const Stencil&, uint8_t) {}
  void copy(const Stencil&, const Stencil&) {}
  void traced(Count) {}
  void unfinished(Count) {}
  void pass(const PassKey&, const vgpu::Program& p, std::initializer_list<const Texture*> in,
            std::initializer_list<Texture*> out, const Stencil*) {
    seen.push_back({&p, {in.begin(), in.end()}, {out.begin(), out.end()}});
  }
  Count count(const PassKey& key, const vgpu::Program& p, const Texture& in, const Stencil*,
              Stencil*) {
    seen.push_back({&p, {&in}, {}});
    return asked_[size_t(key.site)]++ == 0 ? 1 : 0;
  }

 private:
  std::array<int, kMaxSites> asked_{};
};

// Why no walk of a frame with these options on this device can run in batches; empty: they may,
// where each walk's programs and bindings allow (run_in_batches checks those). Decided once per
// frame, at its first walk, and recorded with the statistics (RenderResult::walk_reason).
inline std::string frame_batch_refusal(const RenderOptions& opt, const vgpu::Device& device) {
  const auto* gpu = dynamic_cast<const vgpu::Gpu*>(&device);
  if (!opt.batch_walk) return "--walk passes";
  if (!gpu) return "not the emulator";
  if (gpu->lanes() != vgpu::kBatchWidth)
    return "--lanes " + std::to_string(gpu->lanes()) + " (a batch is " +
           std::to_string(vgpu::kBatchWidth) + " lanes)";
  if (opt.observer) return "a pass observer follows every pass (--report, --stats-csv)";
  if (opt.trace_pixel) return "--trace-pixel prints every pass";
  if (!opt.masks && !opt.host_shortcut) return "no mask skips finished rays";
  return "";
}

// The walk batch by batch, then the replay of its passes on the device; false where it does not
// apply, with the reason in r.counts.passes_reason (the frame's: frame_batch_refusal; the walk's:
// a program with a loop, or a binding a batch cannot keep in registers).
template <class Walk>
bool run_in_batches(PassRunner& r, Walk& walk, typename Walk::Cursor& c) {
  const RenderOptions& opt = r.options();
  WalkCounts& counts = r.counts;
  if (!counts.batch_decided) {
    counts.batch_refusal = frame_batch_refusal(opt, r.device());
    counts.batch_decided = true;
  }
  const auto passes = [&](const std::string& why) {
    if (counts.passes_reason.empty()) counts.passes_reason = why;
    return false;
  };
  if (!counts.batch_refusal.empty()) return passes(counts.batch_refusal);
  auto* gpu = static_cast<vgpu::Gpu*>(&r.device());
  const auto t0 = std::chrono::steady_clock::now();
  // The walk's passes and bindings: a batch keeps a texture in registers where every program
  // reads it at the fragment's own texel; a texture the walk writes must be read so everywhere.
  CheckWalker check;
  {
    typename Walk::Cursor probe = c;
    walk.walk(check, probe);
  }
  std::vector<ProgramInfo> programs;
  std::vector<const Texture*> written;
  for (const CheckWalker::Seen& p : check.seen)
    for (const Texture* t : p.out) written.push_back(t);
  for (const CheckWalker::Seen& p : check.seen) {
    auto it = std::find_if(programs.begin(), programs.end(),
                           [&](const ProgramInfo& i) { return i.program == p.program; });
    if (it == programs.end()) {
      ProgramInfo i;
      i.program = p.program;
      i.run = &gpu->executing(*p.program);
      i.precision = gpu->precision_of(*p.program);
      const vgpu::Program::Analysis a = p.program->analyze();
      if (a.loop.loops > 0) return passes(std::string(p.program->name()) + " loops");
      i.branches = a.branches;
      i.idle_discards = p.program->idle_discards();
      if (!i.idle_discards && !p.program->has_passthrough())
        return passes(std::string(p.program->name()) +
                      " keeps idle fragments without a passthrough");
      for (int o = 0; o < p.program->outputs(); ++o)
        i.passthrough[size_t(o)] = i.idle_discards ? -1 : p.program->passthrough(o);
      i.own_only = r.own_only_units(*p.program);
      programs.push_back(i);
      it = programs.end() - 1;
    }
    for (size_t u = 0; u < p.in.size(); ++u) {
      const Texture& t = *p.in[u];
      const bool sized = t.width() == opt.width && t.height() == opt.height;
      const bool own = (it->own_only >> u) & 1;
      if (own && !sized)
        return passes(std::string(p.program->name()) + " reads " + p.program->unit_name(int(u)) +
                      " from a texture of another size than the frame");
      if (!own && std::find(written.begin(), written.end(), &t) != written.end())
        return passes(std::string(p.program->name()) + " reads " + p.program->unit_name(int(u)) +
                      ", which the walk writes, at another texel than its own");
    }
    if (!it->idle_discards)
      for (size_t o = 0; o < p.out.size(); ++o) {
        const size_t u = size_t(it->passthrough[o]);
        if (u >= p.in.size() || !((it->own_only >> u) & 1))
          return passes(std::string(p.program->name()) + " passes through a unit it reads at " +
                        "another texel than its own");
      }
  }

  // The batches, 32x32 pixel tiles at a time (the batch counters' largest tile), over the
  // threads; every batch writes only its own pixels' texels.
  const WriteBack wb = walk.write_back(c);
  std::array<BatchWalker::Pair, WriteBack::kMax> pairs{};
  for (int k = 0; k < wb.npairs; ++k)
    for (int b = 0; b < 2; ++b) {
      pairs[size_t(k)].t[b] = wb.pairs[size_t(k)][size_t(b)];
      pairs[size_t(k)].data[b] = wb.pairs[size_t(k)][size_t(b)]->texel_mut(0, 0);
    }
  std::array<BatchWalker::MaskOut, WriteBack::kMax> masks{};
  for (int k = 0; k < wb.nmasks; ++k)
    masks[size_t(k)] = {wb.masks[size_t(k)], wb.masks[size_t(k)]->row_mut(0)};
  // A dense stream's walk (PassRunner::rect) covers only the rows it fills.
  const int W = opt.width, H = r.rect ? r.rect->y1 : opt.height;
  const int tiles_x = (W + 31) / 32, tiles_y = (H + 31) / 32;
  std::vector<std::unique_ptr<BatchWalker>> walkers;
  for (int k = 0; k < gpu->threads(); ++k)
    walkers.push_back(std::make_unique<BatchWalker>(*gpu, programs, opt.masks, W, H));
  // An error on a worker thread (a binding the check let through) reaches the caller.
  std::mutex failed_mu;
  std::exception_ptr failed;
  std::atomic<int> tiles_done{0};
  gpu->parallel_for(tiles_x * tiles_y, [&](int tile, int slot) {
    try {
      BatchWalker& x = *walkers[size_t(slot)];
      const int tx = tile % tiles_x, ty = tile / tiles_x;
      for (int y = ty * 32; y < std::min(H, ty * 32 + 32); ++y)
        for (int x0 = tx * 32; x0 < std::min(W, tx * 32 + 32); x0 += vgpu::kBatchWidth) {
          x.begin(x0, y, std::min(vgpu::kBatchWidth, W - x0));
          typename Walk::Cursor b = c;
          walk.walk(x, b);
          const WriteBack done = walk.write_back(b);
          x.finish(pairs.data(), done.current.data(), done.npairs, masks.data(), done.nmasks);
        }
      x.settle_tile(tx, ty);
      r.report_batches(++tiles_done, tiles_x * tiles_y, t0);
    } catch (...) {
      const std::lock_guard lk(failed_mu);
      if (!failed) failed = std::current_exception();
    }
  });
  if (failed) std::rethrow_exception(failed);
  Keyed<vgpu::PassTally> tallies;
  uint64_t ran = 0, bytes = 0;
  for (const auto& w : walkers) bytes += w->entries.bytes();
  for (auto& w : walkers)
    w->entries.for_each([&](const PassKey& key, const BatchWalker::Entry& e) {
      tallies.at(key) += e.tally;
      ran += e.tally.ran;
    });
  // The walk's host time, shared out by the fragments each pass ran.
  const double ms = ms_since(t0);
  tallies.for_each([&](const PassKey&, vgpu::PassTally& t) {
    t.host_ms = ran ? ms * double(t.ran) / double(ran) : 0.0;
  });
  r.counts.batch_bytes = std::max(r.counts.batch_bytes, bytes + tallies.bytes());
  // The same walk on the device, each pass charged from its tally: the statistics, the program
  // loads and the query read-backs come out as a pass-by-pass walk's.
  DeviceWalker replay{r, &tallies};
  walk.walk(replay, c);
  r.counts.batch_walk = true;
  return true;
}

}  // namespace host::walk
