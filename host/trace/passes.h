// How the host issues one pass: program, textures, targets and masks set on the device, the
// draw, and what the observer and --trace-pixel are told. The host loop and every walk use it.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <initializer_list>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "host/trace/render_options.h"
#include "vgpu/device.h"

namespace host {

// What the walks of one frame counted.
struct WalkCounts {
  uint64_t rays_traced = 0;      // rays entering a trace
  uint64_t rays_unfinished = 0;  // rays stopped by a walk's pass cap (reduced precision)
  bool batch_walk = false;       // a walk of this frame ran in batches (host/trace/walks/walk.h)
  // The most host memory one batch walk's tallies held (every thread's and their sum), bytes:
  // the memory model's walk term (host/report/memory_json.h).
  uint64_t batch_bytes = 0;
  // Whether the frame's walks may run in batches, decided once, at its first walk, from the
  // options and the device (walk::frame_batch_refusal); empty: they may.
  bool batch_decided = false;
  std::string batch_refusal;
  // Why a walk of this frame ran pass by pass: the frame's refusal, or the first walk whose
  // programs or bindings a batch cannot keep in registers (empty: every walk ran in batches).
  std::string passes_reason;
  // Beams over tiles (--beams on, host/trace/walks/grid_beams.h): passes of rayosHaz, tiles
  // marched (over the frame's primary traces) and tiles whose whole beam missed the grid.
  uint64_t beam_passes = 0, beam_tiles = 0, beam_tiles_missed = 0;
  // Through the BVH or the kd-tree: the levels every tile's beam descended, summed over the
  // tiles, and the most one took (the descent's queries give both: after pass k they count the
  // tiles k or more levels down).
  uint64_t beam_depth_sum = 0, beam_depth_max = 0;
  bool beam_depths = false;  // the descent counted them (not the looping descent: one pass)
  BeamMap beam_map;          // the frame's first primary trace's tiles, when an observer follows it
};

// The state a batch walk hands back to the textures and masks: each ping-pong pair of state
// textures with its current member, and the masks the walk leaves.
struct WriteBack {
  static constexpr int kMax = 4;
  std::array<std::array<vgpu::Texture*, 2>, kMax> pairs{};
  std::array<int, kMax> current{};
  int npairs = 0;
  std::array<vgpu::Stencil*, kMax> masks{};
  int nmasks = 0;
};

// A static texture of `count` entries of `channels`, entry k at (k mod width, k div width), its
// width a power of two, for a structure's nodes or lists; throws vgpu::LimitError, "WHAT: N
// entries; ...", naming a profile whose textures hold them, when the profile's largest texture
// cannot, or (linear addresses, `xy` false) when an index would pass 2^24 (no longer an exact
// float).
vgpu::Texture entry_texture(vgpu::Device& gpu, const std::string& name, size_t count, int channels,
                            const std::string& what, bool xy = false);

class PassRunner {
 public:
  // `counter` is the colour target of counting passes (only their query result matters).
  PassRunner(vgpu::Device& gpu, const RenderOptions& options, vgpu::Texture& counter)
      : gpu_(gpu), opt_(options), counter_(counter) {}

  vgpu::Device& device() const { return gpu_; }
  const RenderOptions& options() const { return opt_; }

  // One pass of p over the whole target (outs[i] is the program's output i), on the fragments
  // `work` leaves (nullptr: all). The same finished-ray mask either skips fragments on the
  // modeled hardware (--masks on) or only saves the emulator's host work (every fragment is
  // charged).
  const vgpu::PassRecord& pass(const vgpu::Program& p,
                               std::initializer_list<const vgpu::Texture*> in, vgpu::Texture& out,
                               const vgpu::Stencil* work = nullptr);
  const vgpu::PassRecord& pass(const vgpu::Program& p,
                               std::initializer_list<const vgpu::Texture*> in,
                               std::initializer_list<vgpu::Texture*> outs,
                               const vgpu::Stencil* work = nullptr);
  // The same with the units in a list made at run time (a kernel of one's own binds the
  // stage's textures it names, host/trace/user_stage.h).
  const vgpu::PassRecord& pass(const vgpu::Program& p, std::span<const vgpu::Texture* const> in,
                               std::initializer_list<vgpu::Texture*> outs,
                               const vgpu::Stencil* work = nullptr);
  // A counting pass inside an occlusion query: the fragments p does not discard; those are
  // marked in `write` (nullptr: none).
  uint64_t count(const vgpu::Program& p, const vgpu::Texture& in, const vgpu::Stencil* work,
                 vgpu::Stencil* write);
  // The work mask of the next draw, as pass() sets it (for a walk that draws by itself).
  void set_work(const vgpu::Stencil* work);
  // Whether --trace-pixel output is on and the traced pixel takes part in a pass under `work`
  // (no mask, or the finished-ray mask says its ray is not done).
  bool traces_pixel(const vgpu::Stencil* work) const;
  // Prints the traced pixel's texel of each target after a pass of p.
  void trace_targets(const vgpu::Program& p, std::initializer_list<const vgpu::Texture*> outs);

  // The units p reads only at the fragment's own texel (Op::fetch_own in its recording, never
  // Op::fetch): those may come from a batch's registers. Worked out once per program.
  uint32_t own_only_units(const vgpu::Program& p);

  // Progress within a walk (RenderOptions::walk_progress), at most every progress_every_ms:
  // after a counting pass, the rays it counted; a walk in batches, the share of its tiles walked
  // since `start` (thread-safe: a report already under way makes the others skip theirs).
  void report_rays(const char* query, uint64_t rays);
  void report_batches(int done, int total, std::chrono::steady_clock::time_point start);

  // The rays the walk under way walks, as progress names them ("rays" between walks).
  const char* walking = "rays";

  WalkCounts counts;  // this frame's; the host loop resets it
  // The rows every pass and count draws (a dense stream of marked pixels fills only its first
  // rows: host/trace/stream/mark_streams.h); nullopt: the whole target.
  std::optional<vgpu::Rect> rect;

 private:
  vgpu::Device& gpu_;
  const RenderOptions& opt_;
  vgpu::Texture& counter_;
  std::vector<std::pair<const vgpu::Program*, uint32_t>> own_only_;
  // The last progress report, and the lock that lets one thread report at a time.
  void report(WalkProgress w, std::chrono::steady_clock::time_point now);
  bool progress_failed_ = false;
  std::mutex progress_mu_;
  std::chrono::steady_clock::time_point last_report_{};
};

}  // namespace host
