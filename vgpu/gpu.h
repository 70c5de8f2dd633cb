// The virtual GPU: a 2004 programmable fragment pipeline as a small state machine.
//
//   gpu.use_program(p);             // counted as a program load when p differs from the last
//   gpu.bind_texture(0, rays);      // texture units: the only way a program reads memory
//   gpu.set_targets({&state_b});    // render-to-texture: one target on fp30, up to 4 on fp40
//   gpu.begin_query();              // occlusion query: counts fragments not discarded
//   gpu.draw();                     // one pass: the program runs on every fragment of a quad
//   uint64_t n = gpu.end_query();   // reading the count back is a CPU-GPU sync, counted
//
// The processor runs W fragments at a time as host SIMD lanes, rows split over threads; images
// and statistics are bit-identical for any thread count and any width. The profile's limits are
// enforced: a violation throws vgpu::Error naming the program.
#pragma once

#include <array>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <initializer_list>
#include <memory>
#include <mutex>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "vgpu/batch.h"
#include "vgpu/device.h"
#include "vgpu/recorded_program.h"

namespace vgpu {

// Batch flags of one fragment (Gpu::branch_flags): it took the program's branch, or sat idle in it.
inline constexpr uint8_t kBranchTook = 1, kBranchIdle = 2;

class Gpu final : public Device {
 public:
  // threads = 0: one per host core. lanes: 1 (scalar reference), 4, 8 or 16.
  explicit Gpu(const Profile& profile, int threads = 0, int lanes = kLanes);
  ~Gpu();
  Gpu(const Gpu&) = delete;
  Gpu& operator=(const Gpu&) = delete;

  const Profile& profile() const override { return profile_; }
  std::string description() const override { return "vgpu (emulator)"; }
  int threads() const { return int(workers_.size()) + 1; }
  int lanes() const { return lanes_; }
  // Arithmetic precision of the fragment units: fp32, or every operation rounded to fp24 (R300)
  // or fp16 (NV3x half). A program may ask for less (Program::set_precision); a pass computes
  // in the coarser of the two, as the profile allows (Profile::computes: R300 only has fp24).
  // Texture formats are set per texture.
  void set_precision(Format f) { precision_ = f; }
  Format precision() const { return precision_; }
  // Called with the statistics' totals as each pass is counted (batch walks' replayed passes
  // too); true stops the frame there: the pass throws BudgetError. Empty: never.
  void set_stop_when(std::function<bool(const Counters&)> stop) { stop_when_ = std::move(stop); }
  Format precision_of(const Program& p) const {
    return profile_.computes(coarser(precision_, p.precision()));
  }

  // The emulator's textures live in host memory: nothing to copy.
  void upload(const Texture&) override {}
  void download(Texture& t) override { count_download(stats_, t); }  // host memory: a count

  // The recorded-program executor on whole frames (vgpu/recorded_program.h): the programs named
  // here ("all": every one) run as their recordings instead of their compiled code, each
  // recording kept per program and made again when its uniforms or precision change. Counted as
  // the program itself (its name, loads and static counts); the images are the compiled code's.
  // For measuring the executor, and checking it, on the frames the project renders.
  void set_recorded(std::vector<std::string> names);
  // What runs for p: p, or its recording where set_recorded names it (host thread only).
  const Program& executing(const Program& p) const;

  // Pipeline state.
  void use_program(const Program& program) override;
  void bind_texture(int unit, const Texture& texture) override;
  void unbind_textures() override;
  void set_targets(std::initializer_list<Texture*> targets) override;
  // Early-z / stencil mask: fragments whose stencil is 0 are skipped before shading.
  bool has_stencil() const override { return true; }
  void set_stencil_test(const Stencil* stencil) override { stencil_test_ = stencil; }
  // After each pass, the stencil of every shaded fragment becomes 1 if it survived, 0 if killed.
  void set_stencil_write(Stencil* stencil) override { stencil_write_ = stencil; }

  // Emulator shortcut, not hardware: fragments whose work mask is 0 run no host code. They are
  // counted exactly as if shaded (the statistics use each program's static per-fragment counts),
  // their outputs are copied from the program's passthrough units and they are discarded if the
  // program says idle fragments are. The host marks a fragment idle only where the program's
  // result provably equals that (a finished ray) and the fragment takes none of the program's
  // f.branch() blocks (each counts it as an idle lane), so images and statistics do not change.
  void set_work_mask(const Stencil* work) override { work_mask_ = work; }
  // Model the same mask as an early-z/stencil test instead: idle fragments are charged as
  // masked (no shading, no fetches, no query count) while their state is still carried over.
  void set_work_mask_counts_as_masked(bool masked) override { work_masked_ = masked; }

  // glClear: every texel of t becomes value (channels() floats). Counted as a clear and its bytes.
  void clear(Texture& t, std::initializer_list<float> value) override;

  // One pass over rect (default: the whole first target).
  const PassRecord& draw() override;
  const PassRecord& draw(const Rect& rect) override;

  // Occlusion queries: begin, draw one or more passes, end returns the surviving fragments.
  // end_query() reads the result back (a synchronisation, counted as a query read-back).
  void begin_query() override;
  uint64_t end_query() override;

  // After a draw of a program that branches: per fragment of the drawn rectangle, row by row,
  // kBranchTook, kBranchIdle or 0 (not shaded). Empty after a draw of one that does not.
  std::span<const uint8_t> branch_flags() const override {
    return {batch_flags_.data(), flags_size_};
  }

  std::span<const uint32_t> loop_iterations() const override {
    return looped_ ? std::span<const uint32_t>(loop_map_) : std::span<const uint32_t>();
  }

  FrameStats& stats() override { return stats_; }
  const FrameStats& stats() const { return stats_; }

  // Emulator shortcut for walks run batch by batch (vgpu/batch.h,
  // host/trace/walks/batch_walk.h): the next draw() runs no fragment and charges the pass as
  // `t` says its fragments ran (t must outlive that draw). Every check a draw makes is still made;
  // the targets and the stencil write hold what the walk left there.
  void replay_next(const PassTally& t) { replay_ = &t; }
  // body(item, slot) for items [0, n) on the calling thread and the workers; slot <
  // threads() is the running thread's own (for per-thread accumulators).
  void parallel_for(int n, const std::function<void(int, int)>& body);
  // body(begin, end) over [0, n) split into blocks, four per thread, on the calling thread and
  // the workers; below `serial_below` items one call on the calling thread (waking the workers
  // would cost more). Blocks are disjoint: host work that writes each item once (a clear's rows,
  // a read-back, a copy list) gives the same result on any thread count.
  void parallel_blocks(size_t n, size_t serial_below,
                       const std::function<void(size_t, size_t)>& body);

 private:
  struct Chunk;
  struct DrawPlan;
  template <class L>
  void run_rows(const Program& p, const Rect& r, int y0, int y1, const DrawPlan& plan,
                Chunk& out) const;
  void parallel_rows(const Rect& r, uint64_t work,
                     const std::function<void(int, int, Chunk&)>& body, std::vector<Chunk>& chunks);
  const PassRecord& replay(const Program& p, const Program::Analysis& a, const Rect& rect,
                           const PassTally& t, std::chrono::steady_clock::time_point t0);
  const PassRecord& settle(const Program& p, const Program::Analysis& a, const Rect& rect,
                           const Chunk& sum, const std::array<uint64_t, 2>* batch,
                           const LoopCounts* loop, std::vector<uint64_t> loop_active,
                           std::vector<uint64_t> loop_idle,
                           std::chrono::steady_clock::time_point t0, double extra_ms);
  void track_pairs(const Program& p, const std::shared_ptr<const std::vector<uint32_t>>& runs,
                   bool chunk_runs);
  void run_on_workers(const std::function<void()>& job);
  void worker_loop();
  [[noreturn]] void fail(const std::string& what) const;

  Profile profile_;
  int lanes_;
  Format precision_ = Format::fp32;
  std::function<bool(const Counters&)> stop_when_;
  const Program* bound_ = nullptr;    // the program bound
  const Program* program_ = nullptr;  // what runs: bound_, or its recording
  std::vector<std::string> recorded_;
  struct Mirror {
    std::vector<std::byte> uniforms;
    Format precision = Format::fp32;
    std::unique_ptr<RecordedProgram> program;
  };
  mutable std::unordered_map<uint32_t, Mirror> mirrors_;
  const PassTally* replay_ = nullptr;
  uint32_t loaded_program_ = 0;
  std::array<const Texture*, kMaxTextureUnits> units_{};
  std::vector<Texture*> targets_;
  const Stencil* stencil_test_ = nullptr;
  Stencil* stencil_write_ = nullptr;
  const Stencil* work_mask_ = nullptr;
  bool work_masked_ = false;
  bool in_draw_ = false;
  // Per fragment of the drawn rectangle, for the batch counters: took the branch, idle in it, or
  // not shaded (gpu.cpp). Rebuilt by every draw of a program that branches; the first
  // flags_size_ bytes are the map (0: the last draw's program has no branches).
  std::vector<uint8_t> batch_flags_;
  size_t flags_size_ = 0;
  // Where the buffer is known to hold flags_base_ everywhere but at flags_ran_ (the fragments a
  // listed pass ran): the next listed pass of the same size resets only those.
  std::shared_ptr<const std::vector<uint32_t>> flags_ran_;
  uint8_t flags_base_ = 0;
  // Tiles (8x4, 32x32) of the drawn rectangle where some fragment took the branch.
  std::vector<uint8_t> took8_, took32_;
  std::vector<uint32_t> loop_map_;  // a looping pass: iterations per texel of the target
  bool looped_ = false;             // the last pass ran a loop (loop_map_ is its)
  // Emulator bookkeeping: two textures known to hold the same texels everywhere except at
  // `differ` (texel indices, ascending), as a pass with a work mask leaves its passthrough source
  // and its target. The next pass between them copies only those texels for its idle fragments.
  struct PairRecord {
    const Texture *a = nullptr, *b = nullptr;
    uint64_t uid_a = 0, version_a = 0, uid_b = 0, version_b = 0;
    std::shared_ptr<const std::vector<uint32_t>> differ;  // shared with a mask's list
  };
  std::vector<PairRecord> pairs_;
  std::vector<Chunk> chunks_;  // per row chunk of a draw, kept for their run lists' capacity
  bool query_active_ = false;
  uint64_t query_count_ = 0;
  FrameStats stats_;
  PassRecord last_pass_;

  // Thread pool: the calling thread works too.
  std::vector<std::thread> workers_;
  std::mutex mu_;
  std::condition_variable cv_work_, cv_done_;
  const std::function<void()>* job_ = nullptr;
  uint64_t job_serial_ = 0;
  int busy_ = 0;
  bool stop_ = false;
};

}  // namespace vgpu
