// What a stream-tracer frame is asked for (RenderOptions), what it gives back (RenderResult) and
// what it shows an observer while it runs (PassObserver). No tracer code: the devices and the
// walkers include this without the tracer.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "host/model/formats.h"
#include "host/trace/user_stage.h"
#include "kernels/shader.h"
#include "vgpu/vgpu.h"

namespace host {

// What the host loop shows an observer (the HTML frame report, host/report/report.h): every pass
// with what it ran on, every occlusion-query result, and where iterations and traces begin.
class PassObserver {
 public:
  enum class TraceKind { primary, shadow, reflected };
  struct Pass {
    const vgpu::Program& program;
    const vgpu::PassRecord& record;
    const vgpu::Texture& target;
    // Per fragment of the drawn rectangle, row by row: vgpu::kBranchTook, kBranchIdle or 0 (not
    // shaded); empty when the program does not branch.
    std::span<const uint8_t> branch_flags;
    const vgpu::FrameStats& stats;  // the frame so far, this pass included
    // Per texel of the target, row by row: iterations of the program's loop each fragment ran;
    // empty without a loop (vgpu::Device::loop_iterations).
    std::span<const uint32_t> loop_iterations = {};
  };
  virtual ~PassObserver() = default;
  virtual void iteration(int iteration) = 0;  // 1-based
  virtual void trace_begin(TraceKind kind) = 0;
  virtual void trace_end() = 0;
  // Before a pass: the fragments with work to do (nullptr: every fragment). A counting pass may
  // write the same stencil, so this is the one moment it can be seen.
  virtual void pass_begin(const vgpu::Stencil* work) = 0;
  virtual void pass(const Pass& p) = 0;
  // After a counting pass: its query result and the stencil it wrote (nullptr: none).
  virtual void query(uint64_t result, const vgpu::Stencil* written,
                     const vgpu::FrameStats& stats) = 0;
};

// Where a walk stands (RenderOptions::walk_progress): the frame's passes so far, the rays the
// walk's last occlusion query counted and which query that was (the rays still walking, those
// with triangles left, the pixels a sampler marked; -1: a walk in batches runs its queries only
// when it replays them), the share of a walk in batches' pixels walked (-1: a walk pass by pass,
// whose rays finish at no rate known in advance), and from that share the walk's time left in ms
// (-1: not known).
struct WalkProgress {
  const char* rays = "rays";  // which walk: "primary rays", "shadow rays", "reflected rays"
  const char* query = "";     // the counting pass whose result rays_walking is (its kernel)
  uint64_t passes = 0;
  int64_t rays_walking = -1;
  double done = -1, left_ms = -1;
};

struct RenderOptions {
  int width = 256, height = 256;  // the paper's image size
  int bounces = 2;                // reflection iterations after the primary one (Fig. 1: 3 in all)
  kernels::ShadingModel shading = kernels::ShadingModel::phong;
  bool shadows = true;
  // How the shader's texture unit filters base-colour textures (kernels/base_color.h).
  vgpu::Filter texture_filter = vgpu::Filter::trilinear;
  std::string profile = "gf5700";
  // The device the passes run on: "vgpu" (the emulator) or "gl" (a real OpenGL driver, EGL
  // device gl_device: "auto" or an index).
  std::string device = "vgpu";
  std::string gl_device = "auto";
  // How the GL device waits for a query result: "block" (GL_QUERY_RESULT, the driver's wait),
  // "poll" (spin on GL_QUERY_RESULT_AVAILABLE) or "auto" (poll on a hardware driver, block on
  // a software one; see gl::GlDevice::ReadbackWait).
  std::string gl_readback = "auto";
  int threads = 0;  // 0: every host core
  int lanes = vgpu::kLanes;
  // Formats of the ray-state textures and of the arithmetic of the kernels writing them, per
  // group (host/model/formats.h; --precision sets them all, --formats one by one). The scene
  // textures stay fp32. fp16 cannot address texels past 1024 exactly, as on NV3x.
  Formats formats;
  // Early-z/stencil masks for finished rays (the paper's future work): masked fragments cost
  // nothing. Off: every fragment runs every pass, as on the paper's GeForce FX.
  bool masks = false;
  // Multiple render targets (the paper's future work, kernels/fused.h): the host loop runs
  // intersecciones + proximoTriangulo and traversal + actualizarVoxel as one pass each, writing
  // two targets. Needs a profile with max_outputs >= 2 (validate refuses it naming the fused
  // program and the limit, see mrt_refusal). Off: the paper's one-output multipass pipeline.
  bool mrt = false;
  // The kernels that walk the grid: false, the paper's multipass pipeline (one pass per voxel
  // step and per triangle); true, one looping program (kernels/looping_traversal.h, fp40 and
  // later) drawn again while rays walk, `steps_per_pass` loop iterations per pass.
  bool looping = false;
  int steps_per_pass = 32;
  // Emulator shortcut: skip host work for fragments whose result cannot change (finished rays);
  // their statistics are charged as if run. Off only to check that it changes nothing.
  bool host_shortcut = true;
  // Emulator shortcut: run the multipass grid walk batch by batch (8 neighbouring pixels through
  // every pass of the walk, their ray state in registers, vgpu/batch.h), then replay the pass
  // sequence for the statistics. Same images, AOVs and statistics as pass by pass (false). Used
  // where it applies: the vgpu at 8 lanes, with host_shortcut or masks, the multipass kernels,
  // no observer and no trace_pixel; elsewhere the walk runs pass by pass.
  bool batch_walk = true;
  // Beams over tiles (an extension, issue 35; docs/studies/groups.md): before the primary rays
  // walk the grid, passes of one fragment per beam_tile x beam_tile tile march each tile's beam
  // through empty space, and every pixel's ray starts where its tile's beam stopped. The same
  // hits, depths and images as without (only where each walk begins changes). Through the BVH,
  // each tile's beam descends to the first node it cannot narrow down and its rays start there;
  // through the kd-tree likewise (the nodes' boxes), and its rays restart there too; through the
  // two-level grid, the beams march over its coarse grid. Every structure, fp32 ray state
  // (validate says so); every engine.
  bool beams = false;
  int beam_tile = 8;
  // How the kd-tree and the two-level grid address their textures (kernels/lists.h, Addr):
  // linear, one float per pointer (entry k at k mod width, k div width), exact only to 2^23
  // entries in fp32 and 2^10 in fp16; or by (x, y), a texel's column and row in two channels, as
  // a card addresses a texture, to its largest texture. Automatic: linear where every index stays
  // within what fp32 addresses exactly (and within linear_address_limit, where set: tests lower
  // it so that a small structure crosses it), else (x, y). A narrower format that cannot hold a
  // linear index is refused, naming the one that can.
  enum class Addressing { automatic, linear, xy };
  Addressing addressing = Addressing::automatic;
  uint64_t linear_address_limit = 0;  // 0: the formats' own
  // Supersampling (host/trace/sampling.h): rays per pixel, a square from 1 to 256, on a
  // stratified, jittered grid drawn from sample_seed; the box filter resolves them. 1: one ray
  // through each pixel's centre, the paper's image.
  int spp = 1;
  uint64_t sample_seed = 1;
  // Adaptive supersampling (--aa adaptive): one ray through each pixel's centre, then levels of
  // 4, 16, ... up to spp samples (host/trace/sampling.h) only where a pixel's 4-neighbourhood
  // hit another surface (material, or a miss) or differs in colour by more than aa_threshold
  // (linear, per channel); a level's samples replace the pixel's earlier ones.
  bool adaptive = false;
  // The threshold (--aa-threshold; threshold() reads it): unset, 0.1, or with the budget
  // criterion 0.05 (the least score that can refine).
  std::optional<float> aa_threshold;
  float threshold() const {
    return aa_threshold.value_or(adaptive && aa_criterion == AaCriterion::budget ? 0.05f : 0.1f);
  }
  // What decides where adaptive supersampling refines (--aa-criterion): image (the surface keys
  // and the colour, marcarPixeles), object (the pixels' cones: the keys, the hit distances'
  // continuity against the cone's width, and the colour; kernels/cones.h) or budget (the cones'
  // evidence as a score, each level refining the highest scores above aa_threshold within a
  // share of the image's pixels that hit, and the second level keeping the first's samples;
  // kernels/cone_budget.h).
  enum class AaCriterion { image, object, budget };
  AaCriterion aa_criterion = AaCriterion::budget;
  // With the budget criterion: per level, the share of the image's pixels that hit that the
  // level may refine (the last share repeats for deeper levels), each in (0, 1].
  std::vector<float> aa_budget = {0.30f, 0.28f};
  // With the object criterion: the depth's second difference that marks, in cone widths.
  float cone_depth = 2.0f;
  // Adaptive undersampling (--aa undersample:K, 0: off): one ray through the centre of every
  // K-th pixel in x and y (and the last row and column), then of the pixels between lattice
  // pixels whose surfaces (host/trace/sampling.h) disagree; the rest are blended from the four
  // lattice pixels around them. One ray per traced pixel (spp 1).
  int undersample = 0;
  // Ray streams (glass, host/trace/stream/ray_streams.h) on a scene without glass: the paper's
  // reflections through the same streams, compaction and gather back. A scene with a
  // transmissive material always runs them.
  bool ray_streams = false;
  // Sampling that saves time (--compact, host/trace/stream/mark_streams.h): a gated sample
  // frame (--aa adaptive's levels, --aa undersample's lattice and gaps) traces its marked pixels
  // packed into a dense stream, its passes drawing only the rows they fill, and the colours
  // return to their pixels by a gather. The images are the gated frames'; off runs the gated
  // frames over the whole target, as before, to compare.
  bool compact = true;
  std::optional<glm::ivec2> trace_pixel;  // print every pass this pixel took part in
  std::ostream* trace_out = nullptr;
  bool keep_pass_records = false;
  // Called at the start of each ray-tracing iteration (1-based) with the iteration count.
  std::function<void(int iteration, int iterations)> progress;
  // Called within a walk, at most every progress_every_ms (host/trace/passes.cpp), from any of
  // the emulator's threads but never two at once.
  std::function<void(const WalkProgress&)> walk_progress;
  double progress_every_ms = 100;
  PassObserver* observer = nullptr;  // not owned
  // Stages replaced by kernels of one's own (host/trace/user_stage.h; the stream tracer runs
  // them on the emulator or a GL device, the CPU tracer refuses them).
  UserKernels user;
  // The recorded-program executor on whole frames (vgpu::Gpu::set_recorded, the emulator only):
  // the kernels named here ("all": every one) run as their recordings. The images are the same;
  // for measuring the executor (bench/bench_recorded.cpp) and checking it.
  std::vector<std::string> recorded_programs;
  // The emulator only: called with the frame's counters so far as each pass is counted; true
  // stops the frame with vgpu::BudgetError (vgpu::Gpu::set_stop_when). --accel auto's probes,
  // once their price so far prices them out (host::RunningPrice).
  std::function<bool(const vgpu::Counters&)> stop_when;
  // The combinations of these options that cannot run are refused in one place,
  // host::validate (host/trace/validate.h).
};

// Glass's ray streams (host/trace/stream/ray_streams.h): what one frame's streams held and cost,
// summed over its sample frames.
struct StreamLevel {
  uint64_t rays = 0;            // rays traced at this level (level 0: every pixel's)
  uint64_t chunks = 0;          // walks of W x H rays they took
  uint64_t reflected = 0;       // rays this level spawned for the next: reflected,
  uint64_t refracted = 0;       //   refracted,
  uint64_t total_internal = 0;  //   and of the reflected, total internal reflections
};
struct StreamStats {
  bool on = false;  // the frame ran as ray streams (a glass scene, or RenderOptions::ray_streams)
  std::vector<StreamLevel> levels;
  // Passes and bytes (read + written) by job: dividirRayos; the compaction (sumaPrefijos,
  // contarRayos, compactarRayos); copiarFilas (levels past one chunk); reunirHijos; the shadow
  // rays' continuation through glass (sombraVidrio and its counts).
  uint64_t split_passes = 0, split_bytes = 0;
  uint64_t compaction_passes = 0, compaction_bytes = 0;
  uint64_t copy_passes = 0, copy_bytes = 0;
  uint64_t gather_passes = 0, gather_bytes = 0;
  uint64_t shadow_passes = 0, shadow_bytes = 0;
  uint64_t shadow_continued = 0;  // shadow rays continued past a glass surface
};

// The dense streams of marked pixels (RenderOptions::compact): what one render packed, traced
// and gathered back.
struct CompactStats {
  bool on = false;         // some gated frame ran as a dense stream
  uint64_t packs = 0;      // sets of marks packed (one per adaptive level, two for undersampling)
  uint64_t frames = 0;     // gated frames traced as dense streams
  uint64_t live_rays = 0;  // marked pixels those frames traced (their primary rays)
  uint64_t slots = 0;      // fragments per pass those frames drew (whole rows), summed
  uint64_t pixels = 0;     // fragments per pass the gated frames would have drawn, summed
  // Passes and bytes (read + written) by job: sumaPrefijos over the marks; compactarMarcados;
  // reunirMarcados (colours, and the primary hits where a frame keeps them).
  uint64_t scan_passes = 0, scan_bytes = 0;
  uint64_t compaction_passes = 0, compaction_bytes = 0;
  uint64_t gather_passes = 0, gather_bytes = 0;
};

// Where each tile's rays started in a frame's first primary trace with beams (the report's tile
// map, docs/studies/groups.md): the beam texture's texels once the march or the descent is
// over, tile (x, y) at y * tiles_x + x, row 0 at the top of the image as the image's rows. Empty
// with beams off, or when no pass observer follows the frame (only the report and the pass-by-pass
// views read it).
struct BeamMap {
  int tiles_x = 0, tiles_y = 0, tile = 0;  // tiles across, down, and pixels per tile side
  bool tree = false;  // through the BVH or the kd-tree (a descent), else the grid (a march)
  // The grid: the ray parameter t where the tile's rays start; a tree: the node they start at.
  std::vector<float> start;
  // The grid: the march's steps (empty boxes crossed); a tree: the node's depth (the root 0).
  std::vector<float> steps;
  std::vector<uint8_t> missed;  // 1 where the whole tile missed the structure
};

struct RenderResult {
  int width = 0, height = 0;
  std::vector<float> rgb;     // width*height*3, linear, row 0 = top
  std::vector<float> depth;   // distance to the primary hit, 0 where the ray misses
  std::vector<float> hit_id;  // input triangle id of the primary hit, -1 where it misses
  vgpu::FrameStats stats;
  double render_ms = 0;
  int iterations = 0;             // ray-tracing iterations run (primary included)
  uint64_t rays_traced = 0;       // rays entering a trace (primary, reflected, shadow)
  uint64_t rays_unfinished = 0;   // rays stopped by the pass cap (only under reduced precision)
  bool batch_walk = false;        // the grid walks ran in batches (RenderOptions::batch_walk)
  uint64_t batch_walk_bytes = 0;  // the most host memory a batch walk's tallies held (WalkCounts)
  // Why a walk ran pass by pass (WalkCounts::passes_reason; empty: every walk ran in batches).
  std::string walk_reason;
  // Beams over tiles (RenderOptions::beams): beam passes, tiles marched, tiles that missed.
  uint64_t beam_passes = 0, beam_tiles = 0, beam_tiles_missed = 0;
  // Through the BVH or the kd-tree: the depth of the node each tile's rays started at (its
  // beam's stop, missed tiles included), summed over the tiles, and the deepest.
  uint64_t beam_depth_sum = 0, beam_depth_max = 0;
  bool beam_depths = false;  // counted: a tree's multipass descent, or the CPU tracer's
  BeamMap beam_map;
  int samples = 1;                  // sample frames rendered (RenderOptions::spp)
  uint64_t first_frame_passes = 0;  // passes of the first sample frame (the rest is sampling's)
  // Primary rays per pixel where they differ between pixels (--aa adaptive); empty: `samples`
  // in every pixel.
  std::vector<uint32_t> rays_per_pixel;
  // --aa-criterion budget: per level run, the threshold the budget's search found (the scores
  // above it refined), the pixels that hit the level could refine at most, and the counting
  // passes the search ran.
  struct BudgetLevel {
    float threshold = 0;
    uint64_t budget = 0, steps = 0;
  };
  std::vector<BudgetLevel> budget_levels;
  StreamStats streams;   // glass's ray streams; streams.on false: the paper's frame
  CompactStats compact;  // the sampling modes' dense streams; compact.on false: none ran
};

}  // namespace host
