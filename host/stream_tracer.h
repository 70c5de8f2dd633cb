// The paper's pipeline on the virtual GPU: static textures uploaded once (initialization), then
// per frame: generate rays -> enter the grid -> alternate traversal and intersection passes
// steered by occlusion-query counts -> shade (one pass per light, shadow rays through the same
// kernels) -> reflected rays through the same pipeline, up to a maximum number of iterations.
#pragma once

#include <functional>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "host/formats.h"
#include "host/grid.h"
#include "host/scene.h"
#include "kernels/kernels.h"
#include "vgpu/vgpu.h"

namespace host {

// Lengths both tracers derive from the grid diagonal, as fractions of it (the stream tracer's
// uniforms take float(k) * diagonal in float, the CPU tracer k * diagonal in double).
inline constexpr double kSlackOfDiagonal = 1e-5;   // GridUniforms::t_slack (in-voxel rule)
inline constexpr double kOffsetOfDiagonal = 1e-4;  // ReflectionOrigin::offset (origin lift)
inline constexpr double kAttenOfDiagonal = 0.5;    // Shader::atten_dist

// What the host loop shows an observer (the HTML frame report, host/report.h): every pass with
// what it ran on, every occlusion-query result, and where iterations and traces begin.
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

struct RenderOptions {
  int width = 256, height = 256;  // the paper's image size
  int bounces = 2;                // reflection iterations after the primary one (Fig. 1: 3 in all)
  kernels::ShadingModel shading = kernels::ShadingModel::phong;
  bool shadows = true;
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
  // group (host/formats.h; --precision sets them all, --formats one by one). The scene textures
  // stay fp32. fp16 cannot address texels past 1024 exactly, as on NV3x.
  Formats formats;
  // Early-z/stencil masks for finished rays (the paper's future work): masked fragments cost
  // nothing. Off: every fragment runs every pass, as on the paper's GeForce FX.
  bool masks = false;
  // Multiple render targets (the paper's future work, kernels/fused.h): the host loop runs
  // intersecciones + proximoTriangulo and traversal + actualizarVoxel as one pass each, writing
  // two targets. Needs a profile with max_outputs >= 2 (the constructor throws naming the fused
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
  std::optional<glm::ivec2> trace_pixel;  // print every pass this pixel took part in
  std::ostream* trace_out = nullptr;
  bool keep_pass_records = false;
  // Called at the start of each ray-tracing iteration (1-based) with the iteration count.
  std::function<void(int iteration, int iterations)> progress;
  PassObserver* observer = nullptr;  // not owned
};

struct RenderResult {
  int width = 0, height = 0;
  std::vector<float> rgb;     // width*height*3, linear, row 0 = top
  std::vector<float> depth;   // distance to the primary hit, 0 where the ray misses
  std::vector<float> hit_id;  // input triangle id of the primary hit, -1 where it misses
  vgpu::FrameStats stats;
  double render_ms = 0;
  int iterations = 0;            // ray-tracing iterations run (primary included)
  uint64_t rays_traced = 0;      // rays entering a trace (primary, reflected, shadow)
  uint64_t rays_unfinished = 0;  // rays stopped by the pass cap (only under reduced precision)
  bool batch_walk = false;       // the grid walks ran in batches (RenderOptions::batch_walk)
};

class StreamTracer {
 public:
  // Initialization, timed apart from rendering: the static textures (scene and grid) are built
  // and checked against the profile's limits. Throws vgpu::Error naming the limit.
  StreamTracer(const Scene& scene, const Grid& grid, const RenderOptions& options);
  ~StreamTracer();
  RenderResult render(const Camera& camera);
  double init_ms() const { return init_ms_; }
  vgpu::Device& device() { return *gpu_; }
  uint64_t texture_bytes() const;  // static + dynamic textures, as the modeled card holds them

 private:
  struct State;
  void trace(vgpu::Texture& origins, vgpu::Texture& rays, bool primary, const Camera& cam);
  const vgpu::PassRecord& pass(const vgpu::Program& p,
                               std::initializer_list<const vgpu::Texture*> in, vgpu::Texture& out,
                               const vgpu::Stencil* work = nullptr);
  // A pass writing several render targets (MRT): outs[i] is the program's output i.
  const vgpu::PassRecord& pass(const vgpu::Program& p,
                               std::initializer_list<const vgpu::Texture*> in,
                               std::initializer_list<vgpu::Texture*> outs,
                               const vgpu::Stencil* work = nullptr);
  // The multipass walk through the grid, written once for every way it runs: X executes each
  // pass and query (StreamTracer::DeviceWalker pass by pass on the device, or as the replay of
  // a batch walk; BatchWalker one batch of pixels at a time; CheckWalker checks the bindings).
  struct Cursor;
  struct DeviceWalker;
  template <class X>
  void walk_multipass(X& x, Cursor& c);
  // The walk batch by batch (RenderOptions::batch_walk) and the replay of its passes; false
  // where it does not apply (the walk then runs pass by pass).
  bool walk_in_batches(Cursor& c);
  // The looping variant of the walk (RenderOptions::looping): the looping program's passes.
  void walk_looping(vgpu::Texture& origins, vgpu::Texture& rays, uint64_t walking);
  uint64_t count(const vgpu::Program& p, const vgpu::Texture& in, const vgpu::Stencil* work,
                 vgpu::Stencil* write);
  // Whether --trace-pixel output is on and the traced pixel takes part in a pass under `work`
  // (no mask, or the finished-ray mask says its ray is not done).
  bool traces_pixel(const vgpu::Stencil* work) const;

  const Scene& scene_;
  const Grid& grid_;
  RenderOptions opt_;
  std::unique_ptr<vgpu::Device> gpu_;
  std::unique_ptr<State> s_;
  double init_ms_ = 0;
};

// The grid spec to build for a profile: an automatic resolution is shrunk in x and y until the
// voxel pointer texture (sizeX*sizeY by sizeZ texels) fits the profile's largest texture; an
// explicit one is kept (and refused at initialization if it does not fit).
GridSpec grid_spec_for(const GridSpec& spec, const Scene& scene, const vgpu::Profile& profile);

// Why RenderOptions::mrt cannot run with this profile and these formats (empty: it can): a
// fused program writes more outputs than the profile allows, or computes in one arithmetic
// format where its two kernels' groups differ (host/formats.h). Names the fused program.
std::string mrt_refusal(const vgpu::Profile& profile, const Formats& formats);

// The fused programs --mrt on runs (kernels/fused.h), by statistics name.
std::vector<std::string> mrt_programs();

// Names of the shading models as the CLI spells them.
kernels::ShadingModel parse_shading(const std::string& name);

}  // namespace host
