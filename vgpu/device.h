// The device interface the host loop drives: a 2004 fragment pipeline's operations and nothing
// more (textures, texture units, render targets, a program, a pass, clears, occlusion queries).
// Two devices implement it: the virtual GPU (vgpu::Gpu, which emulates and counts) and the GL
// device (gl::GlDevice, the same passes on a real OpenGL driver). The host does not know which.
#pragma once

#include <initializer_list>
#include <span>
#include <stdexcept>
#include <string>

#include "vgpu/profile.h"
#include "vgpu/program.h"
#include "vgpu/stats.h"
#include "vgpu/texture.h"

namespace vgpu {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// An input that outgrows a limit: of the card (its largest texture), or of how a structure
// addresses its textures. The user's to change (another profile, structure or scene), so the
// command line exits 2 with its line, as for a bad file.
struct LimitError : Error {
  using Error::Error;
};
// A frame stopped by its budget (Gpu::set_stop_when): a probe already priced out of a choice
// (--accel auto).
struct BudgetError : Error {
  using Error::Error;
};

// A rectangle of the render target in pixels: [x0, x1) x [y0, y1).
struct Rect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  uint64_t area() const { return uint64_t(width()) * uint64_t(height()); }
};

class Device {
 public:
  virtual ~Device() = default;
  virtual const Profile& profile() const = 0;
  // Which device this is, for statistics and logs ("vgpu", or the GL renderer's name).
  virtual std::string description() const = 0;

  // Video memory: a texture the profile can hold (throws Error past max_texture_size). Its
  // texels start at zero; the host writes them into the Texture and calls upload().
  Texture make_texture(std::string name, int width, int height, int channels,
                       Format format = Format::fp32) const;
  void check_texture(const Texture& t) const;
  // Host -> device: t's texels as the host wrote them. Device -> host: t's texels as the last
  // pass or clear left them, into t (the emulator's textures live on the host: both are no-ops).
  virtual void upload(const Texture& t) = 0;
  virtual void download(Texture& t) = 0;

  // Pipeline state.
  virtual void use_program(const Program& program) = 0;
  virtual void bind_texture(int unit, const Texture& texture) = 0;
  virtual void unbind_textures() = 0;
  virtual void set_targets(std::initializer_list<Texture*> targets) = 0;

  // Stencil masks (early-z for finished rays, the paper's future work) and the emulator's work
  // mask. A device without them (the GL device) throws on a non-null mask.
  virtual bool has_stencil() const = 0;
  virtual void set_stencil_test(const Stencil* stencil) = 0;
  virtual void set_stencil_write(Stencil* stencil) = 0;
  virtual void set_work_mask(const Stencil* work) = 0;
  virtual void set_work_mask_counts_as_masked(bool masked) = 0;

  // glClear: every texel of t becomes value (channels() floats). Counted as a clear and its bytes.
  virtual void clear(Texture& t, std::initializer_list<float> value) = 0;

  // One pass over rect (default: the whole first target).
  virtual const PassRecord& draw() = 0;
  virtual const PassRecord& draw(const Rect& rect) = 0;

  // Occlusion queries: begin, draw one or more passes, end returns the surviving fragments.
  // end_query() reads the result back (a synchronisation, counted as a query read-back).
  virtual void begin_query() = 0;
  virtual uint64_t end_query() = 0;

  // Per fragment of the last pass's rectangle, row by row, whether it took the program's branch
  // (vgpu::Gpu: kBranchTook, kBranchIdle, 0), for the frame report's occupancy; empty on a
  // device that does not see fragments (the GL device) or after a program without a branch.
  virtual std::span<const uint8_t> branch_flags() const { return {}; }
  // Per texel of the last pass's first target, row by row: the iterations its fragment was
  // active in the program's loop (0 where none ran), for the frame report; empty after a program
  // without a loop, or on a device that does not see fragments (the GL device).
  virtual std::span<const uint32_t> loop_iterations() const { return {}; }

  // The frame's statistics so far (a device that measures asynchronously settles them first).
  virtual FrameStats& stats() = 0;
};

// The checks every device makes before a pass, so both refuse the same programs with the same
// words: the profile's output and instruction limits, targets alike in size, no read/write
// hazard, every fetched unit bound, the rectangle inside the target.
void check_pass(const Profile& profile, const Program& program, const Program::Analysis& a,
                const Texture* const* units, const std::vector<Texture*>& targets,
                const Rect& rect);
// The rules of those a program breaks whatever it is bound to, each refusal one line naming the
// rule, the profile and both numbers (check_pass makes them first): a data-dependent loop where the
// profile has none or past its loop count, more outputs, more instructions, and a texture unit
// past the profile's texture_units.
void check_program(const Profile& profile, const Program& program, const Program::Analysis& a);
// The texture-unit rule alone, for a program of `units` units (units 0 .. units - 1) that may
// not be made yet (one past kMaxTextureUnits cannot be): the line check_program throws.
void check_texture_units(const Profile& profile, const std::string& program, int units);

// A pass's static counters (identical on every device): fragments launched and shaded, the
// instructions, fetches and bytes the program's counting run implies, bytes written by the
// fragments not discarded.
Counters pass_counters(const Program::Analysis& a, const Texture* const* units,
                       const std::vector<Texture*>& targets, uint64_t launched, uint64_t shaded,
                       uint64_t discarded);

// A looping pass (Program::Analysis::loop): its shaded fragments' active iterations, the lane
// slots its batches issued (shaded fragments x the batch's iterations) and the batches'
// iterations. add_loop_counters turns a pass_counters() result into the looping pass's: the
// body's instructions, fetches and bytes once per active iteration, the loop counters set.
struct LoopCounts {
  uint64_t shaded = 0, iterations = 0, slots = 0, batch_iterations = 0;
  uint64_t most = 0;  // the most iterations one shaded fragment ran
};
void add_loop_counters(Counters& c, const Program::Analysis& a, const Texture* const* units,
                       const LoopCounts& n);

// What a program load and a query read-back add to the statistics, on every device.
void count_program_load(FrameStats& stats, const Program& program, const Profile& profile);
void count_readback(FrameStats& stats, const Program* program, uint64_t result);
// What reading a texture back to the host adds (Device::download), on every device.
void count_download(FrameStats& stats, const Texture& t);

}  // namespace vgpu
