// The GL device: the vgpu::Device operations on a real OpenGL 3.3 driver (headless, EGL).
// Textures become GL textures (RGBA32F and the 1-4 channel fp32/fp16 formats; each deleted at the
// device's next call after its id names no texture: destroyed, moved from or assigned over),
// texture units sampler units read with texelFetch, a program the GLSL printed from its
// functor's recording
// (vgpu/glsl.h), a pass one triangle over the rectangle into a framebuffer with the targets
// attached, a query GL_SAMPLES_PASSED. Every pass is also timed (GL_TIME_ELAPSED) and counted
// (a GL_SAMPLES_PASSED of its own for its discards); those results are collected without
// stalling, when the statistics are read. Counters are the emulator's where a driver can know
// them; lanes_idle and the batch counters are the emulator's SIMD model and stay 0 here.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "vgpu/device.h"
#include "vgpu/glsl.h"

namespace gl {

class Context;

class GlDevice final : public vgpu::Device {
 public:
  // How the host waits for an occlusion query's result: `block` asks GL for GL_QUERY_RESULT
  // (the driver decides how to wait: NVIDIA's may sleep and wake up late after a long pass),
  // `poll` flushes and spins on GL_QUERY_RESULT_AVAILABLE (a CPU core busy, no wake-up delay),
  // `automatic` polls on a hardware driver and blocks on a software one (whose rasterizer
  // threads need the core a poll would spin on).
  enum class ReadbackWait { block, poll, automatic };

  // device: "auto" or an EGL device index (gl::Context). Throws gl::Unavailable.
  GlDevice(const vgpu::Profile& profile, const std::string& device = "auto",
           ReadbackWait wait = ReadbackWait::automatic);
  ~GlDevice() override;

  const vgpu::Profile& profile() const override { return profile_; }
  std::string description() const override;
  const Context& context() const { return *ctx_; }

  void upload(const vgpu::Texture& t) override;
  void download(vgpu::Texture& t) override;
  void use_program(const vgpu::Program& program) override;
  void bind_texture(int unit, const vgpu::Texture& texture) override;
  void unbind_textures() override;
  void set_targets(std::initializer_list<vgpu::Texture*> targets) override;
  bool has_stencil() const override { return false; }
  void set_stencil_test(const vgpu::Stencil* stencil) override;
  void set_stencil_write(vgpu::Stencil* stencil) override;
  void set_work_mask(const vgpu::Stencil* work) override;
  void set_work_mask_counts_as_masked(bool) override {}
  void clear(vgpu::Texture& t, std::initializer_list<float> value) override;
  const vgpu::PassRecord& draw() override;
  const vgpu::PassRecord& draw(const vgpu::Rect& rect) override;
  void begin_query() override;
  uint64_t end_query() override;
  vgpu::FrameStats& stats() override;

  // Waits for every pass issued so far (glFinish) and settles their counters and times.
  void finish();
  ReadbackWait readback_wait() const { return wait_; }  // block or poll, never automatic
  // The host's time in the device's calls since it was made, by call (a frame's share: the
  // difference of two readings). What a frame's wall time holds besides them is the host's own
  // work between calls. draw is all of draw() but the settle below: the program's counting run
  // and checks, printing and linking its GLSL where it must, making the textures and framebuffers
  // it meets first, and the GL calls. download, upload and clear include making a texture they
  // meet first (glTexImage2D). settle is stats(), finish() and draw()'s bound on the queries in
  // flight collecting the passes' timer queries, which waits for the GPU to finish them, as a
  // download waits for the passes that write its texture.
  struct HostTimes {
    // wait_ms: waiting for occlusion-query results in end_query() (the read-backs).
    double draw_ms = 0, wait_ms = 0, download_ms = 0, upload_ms = 0, clear_ms = 0, settle_ms = 0;
    uint64_t textures_made = 0, framebuffers_made = 0, programs_linked = 0;
    // GL textures, and the framebuffers they were attached to, deleted because their texture's
    // id names no texture any more (vgpu::Texture::IdSink), at the device's next call after.
    uint64_t textures_freed = 0, framebuffers_freed = 0;
    // Draws (and link()s) whose program's uniforms differ from its last draw's: its GLSL printed
    // (variants_printed: its first, or a set none kept has) or found among those kept
    // (variants_reused).
    uint64_t variants_printed = 0, variants_reused = 0;
  };
  const HostTimes& host_times() const { return times_; }
  // The GL textures the device holds now: one per live texture it has met.
  size_t textures_held() const { return textures_.size(); }
  // From now on, write each program the driver links to `dir` (which must exist): its GLSL
  // source (NN_name.glsl) and the driver's program binary (NN_name.bin, glGetProgramBinary:
  // NVIDIA's holds the compiled assembly as text, instruction and register counts included).
  void dump_programs_to(const std::string& dir) { dump_dir_ = dir; }
  // What the driver made of program p's GLSL, compiled and linked now as the first draw with it
  // would be (tests ask this of every kernel): the location the driver gave each sampler the
  // GLSL declares (-1: the driver found it unused and dropped it) and each output out0, out1,
  // ... (glGetFragDataLocation; -1: the driver knows no such output). Throws vgpu::Error with
  // the driver's log if the GLSL does not compile or link.
  struct Linked {
    std::vector<int> samplers, outputs;
  };
  Linked link(const vgpu::Program& p);

 private:
  struct GlTexture;
  struct GlProgram;
  struct Pending;
  struct Retired;
  GlTexture& texture(const vgpu::Texture& t);
  void free_retired();  // deletes the GL objects of the ids retired since the last call
  GlProgram& program_for(const vgpu::Program& p);
  unsigned framebuffer_for(const std::vector<vgpu::Texture*>& targets);
  void settle(size_t keep);

  vgpu::Profile profile_;
  ReadbackWait wait_ = ReadbackWait::block;
  HostTimes times_;
  std::unique_ptr<Context> ctx_;
  std::unique_ptr<Retired> retired_;  // subscribed to vgpu::Texture's retired ids
  unsigned vao_ = 0, clear_fbo_ = 0;
  std::map<uint64_t, std::unique_ptr<GlTexture>> textures_;
  std::map<std::string, std::unique_ptr<GlProgram>> compiled_;  // by source text
  // A program's GLSL for one set of uniform values: printing it records the program again (tens
  // to hundreds of us for a large kernel), so each program keeps the GLSL of the last
  // kRecordedVariants sets it printed, the oldest printed going first (a scan's offsets, a
  // sample frame's jitters: a frame repeats them; a program drawn with more distinct sets than
  // that in a cycle prints every one, as before).
  struct Variant {
    std::vector<std::byte> uniforms;
    vgpu::GlslProgram glsl;
    GlProgram* gl = nullptr;
  };
  static constexpr size_t kRecordedVariants = 64;
  struct Recorded {
    std::vector<std::unique_ptr<Variant>> variants;  // oldest first
    Variant* current = nullptr;                      // the one drawn last
  };
  std::map<uint32_t, Recorded> recorded_;  // by program id
  std::map<std::vector<uint64_t>, unsigned> fbos_;
  const vgpu::Program* program_ = nullptr;
  uint32_t loaded_program_ = 0;
  std::array<const vgpu::Texture*, vgpu::kMaxTextureUnits> units_{};
  std::vector<vgpu::Texture*> targets_;
  bool query_active_ = false;
  size_t query_first_ = 0;  // first pending pass inside the active query
  std::vector<Pending> pending_;
  std::vector<unsigned> free_samples_, free_times_;  // query objects, one pool per target
  vgpu::FrameStats stats_;
  vgpu::PassRecord last_pass_;
  std::string dump_dir_;  // dump_programs_to; empty: no dumps
  int dumped_ = 0;
  void dump(unsigned program, const std::string& name, const std::string& source);
};

}  // namespace gl
