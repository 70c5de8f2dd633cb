// --accel auto: which structure to walk, chosen by the cost model. Each candidate structure is
// built and a probe frame (the same options at a quarter of the size in x and y, at least 16x16)
// is rendered with it on the emulator; the cost model predicts the full frame from the probe's
// statistics on the profile asked for: the per-pass, program-load and read-back costs and the
// looping passes' longest lanes (latency) as measured (they follow the pass count and the
// longest walk, which the image size hardly changes), the fragment work (arithmetic, texture,
// memory, downloads) scaled by the pixel ratio, a pass's L2 spill judged at the full frame's
// size: every term of the model's total, so that a probe of the whole frame is priced at its
// predict().total_ms. The candidates priced within
// kAutoProbeBand of the cheapest are probed again at half the size in x and y, and the cheapest
// of those is taken.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "host/accel/accel.h"
#include "host/scene/scene.h"
#include "host/trace/render_options.h"

namespace host {

// The quarter-size probes misjudge how two structures compare in the full frame, most where a
// walk's longest rays grow with the image: the bunny's primary rays on gf6600 priced the
// two-level grid 6% under the grid from 64x64 probes, and it is 12% over at 256x256: 17% between
// the two. So every candidate priced within this band of the cheapest is probed again at half
// the size. Measured on the 13 bundled and uneven scenes, primary rays and full frames, both
// walks, on gf6600, h200 and h100 at 256x256 (docs/studies/structures.md, "--accel auto"): all
// 156 picks within 3.1% of the cheapest structure's frame. The band protects against the
// quarter-size probes' misjudgment; the half-size probes' own is the error left.
inline constexpr double kAutoProbeBand = 0.20;

struct AccelChoice {
  AccelKind kind = AccelKind::grid;
  int probe_width = 0, probe_height = 0;  // the first probes' size (every candidate)
  // The second probes' size (0 where half the size is no larger than the first probes).
  int refine_width = 0, refine_height = 0;
  // Per candidate, the full frame on options.profile: from the second probe where it had one,
  // else from the first; coarse_ms from the first probes alone.
  std::map<std::string, double> predicted_ms, coarse_ms;
  std::vector<std::string> refined;  // the candidates probed again, in order
  // The candidates whose probe stopped once its price so far (RunningPrice: its passes so far,
  // each priced as predict prices it) priced it out (the first round:
  // over the band of the cheapest so far; the second: over the cheapest second price so far).
  // Their price in predicted_ms (and coarse_ms, for a first-round stop) is just over what they
  // were known to pass: a lower bound, never equal to a band edge or the pick's price. Stopping
  // never changes the pick, the band or the other prices; a probe that would have outgrown a
  // limit later is reported stopped, not refused. The emulator's probes only
  // (RenderOptions::stop_when).
  std::vector<std::string> stopped;
  std::map<std::string, uint64_t> probe_passes;  // the first probes' passes (those not stopped)
  double probe_ms = 0;  // host wall time of both rounds of probes (the builds before them apart)
  std::string why;      // one sentence
};

// What a frame's walks did, from its statistics: useful fragments (those with work, not idle in
// the branch) of the walk's step passes and intersection passes, alone or fused. A looping walk
// does both in one program: its loop iterations instead.
struct WalkWork {
  uint64_t voxel_steps = 0;      // grid, grid2: traversal (cell step) passes' walking fragments
  uint64_t nodes_visited = 0;    // bvh: recorridoBVH passes' walking fragments (one node each)
  uint64_t triangle_tests = 0;   // either: intersection passes' testing fragments
  uint64_t loop_iterations = 0;  // looping kernels: iterations run (a node, voxel or triangle each)
  // kd-restart: walks begun again from the root (the CPU tracer's CpuStats::restarts). Every
  // ray entering the tree reaches a leaf once, then once more per restart, and cargarHojaKd
  // runs once per leaf reached; so restarts = its loading fragments - rays traced. Only where
  // cargarHojaKd runs as a pass of its own (multipass, --mrt off); -1 elsewhere.
  int64_t restarts = -1;
};
// `rays_traced`: the frame's rays entering a walk (RenderResult::rays_traced), for restarts.
WalkWork walk_work(const vgpu::FrameStats& stats, uint64_t rays_traced = 0);

// The candidates (built by the caller), each with the formats it renders with. A candidate the
// profile's limits refuse (vgpu::Error) drops out; throws vgpu::Error if none is left.
struct AccelCandidate {
  const Accel* accel;  // not owned
  Formats formats;
};
// stop_early false runs every probe to its end (the same pick; for the tests).
AccelChoice choose_accel(const Scene& scene, const std::vector<AccelCandidate>& candidates,
                         const RenderOptions& options, const Camera& camera,
                         bool stop_early = true);

// --beams auto: beams are kept only where the primary trace with beams is predicted at least this
// share cheaper than without. The probes price the primary trace exactly (they are it), so the
// margin only keeps near ties off (stadium: 1.00x), where the beam passes and the texture they
// need buy nothing, and leaves room for what the probes leave out (--spp's jittered frames).
inline constexpr double kAutoBeamsMargin = 0.02;

// --beams auto's choice, made once at initialization from two probe frames of the primary trace
// alone (bounces 0, shadows off, one sample) at the frame's full size, beams off and on, priced
// by the cost model on options.profile.
struct BeamsChoice {
  bool on = false;
  bool probed = false;  // false: beams could not run here, so off without probes
  int probe_width = 0, probe_height = 0;
  double off_ms = 0, on_ms = 0;  // the primary trace's predicted time without and with beams
  double probe_ms = 0;           // host wall time of the probes
  // The probes' own modeled time (off_ms + on_ms): what deciding would cost where the probes ran
  // on the card ahead of the frame.
  double probe_model_ms = 0;
  std::string why;  // one sentence
};
// `options` as the frame would run with beams off; `engine` the command line's (stream, cpu or
// gl: the probes run on the frame's device; the GL device counts the emulator's statistics). Beams
// off without probes wherever `--beams on` would be refused (another structure than the grid, or
// host::validate with beams: non-fp32 ray state, dense streams) and on the cpu engine,
// whose frame has no passes to price; `why` then says which.
BeamsChoice choose_beams(const Scene& scene, const Accel& accel, const RenderOptions& options,
                         const Camera& camera, std::string_view engine);

}  // namespace host
