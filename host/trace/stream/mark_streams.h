// Sampling that saves time (issue 35): a gated sample frame's marked pixels as a dense stream.
// The adaptive levels and the undersampling lattice and gaps trace a few of the pixels; rather
// than run every pass of the frame over the whole target (the unmarked pixels idle), the marked
// pixels are packed into the first rows of the frame's textures by the stream reduction glass's
// ray streams use (sumaPrefijos over the marks, then compactarMarcados' binary search), the
// frame draws only those rows, and reunirMarcados brings each pixel's colour (and, where the
// frame keeps them, its primary hit) back. The same rays as the gated frame's, so the same image.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "host/trace/passes.h"
#include "host/trace/ping_pong.h"
#include "host/trace/render_options.h"
#include "kernels/kernels.h"
#include "vgpu/vgpu.h"

namespace host {

// The statistics (CompactStats, render_options.h) as the table's line prints them; the report
// room writes them as the statistics' "compact" object (host/report/stats_parts_json.h).
std::string describe(const CompactStats& s);

class MarkStreams {
 public:
  MarkStreams(vgpu::Device& gpu, const RenderOptions& opt);

  // Whether the dense streams run bit for bit as the gated frames: the rays' and the colour's
  // arithmetic are the finest the profile has (their kernels also address the stream), and it
  // addresses every slot of a W x H stream exactly (fp24: 2^16 pixels, fp32: 2^22). Where not,
  // the gated frames run over the whole target.
  static bool fits(const vgpu::Profile& profile, const RenderOptions& opt);

  // Packs the pixels `marks` flags (x > 0; `n` of them, as counted): the scan of the flags, then
  // the dense stream's pixel centres.
  void pack(PassRunner& r, const vgpu::Texture& marks, uint64_t n);
  // The sample offsets (host/trace/sampling.h, in [0, 1)) of the samples the next frames trace,
  // into the jitter table.
  void set_samples(const std::vector<glm::vec2>& offsets);
  // How many samples of every packed pixel one frame's stream holds (W H slots at most).
  int samples_per_frame() const;
  // The next frame traces samples [k0, k1) of the table for every packed pixel.
  void frame_begins(int k0, int k1);
  // The rows the frame's stream fills (at least one): every pass of the frame draws them.
  vgpu::Rect rect() const;
  const vgpu::Texture& pixels() const { return pixels_; }
  const vgpu::Texture& jitters() const { return jitters_; }
  // acumularDensos: each packed pixel adds the frame's colour (`dense`) of its sample k (within
  // the frame) to its sum (`restart`: instead of it).
  void accumulate(PassRunner& r, const vgpu::Texture& sum, const vgpu::Texture& marks,
                  const vgpu::Texture& dense, int k, bool restart, vgpu::Texture& out);
  // reunirMarcados: `dense`'s texel of each packed pixel's slot (its first sample) into `out`
  // (pixel layout), the others `fallback`. Draws the whole target (r.rect must be unset).
  void gather(PassRunner& r, const vgpu::Texture& marks, const vgpu::Texture& dense,
              vgpu::Texture& out, glm::vec4 fallback);

  vgpu::KernelProgram<kernels::GenerateDenseRays> generate;
  CompactStats stats;  // this render's; the tracer resets it
  uint64_t texture_bytes() const;

 private:
  vgpu::Device& gpu_;
  int W_, H_;
  uint64_t n_ = 0;                // pixels packed
  uint64_t count_ = 0;            // the frame's live slots
  PingPong<vgpu::Texture> scan_;  // current(): the inclusive sums of the last marks packed
  vgpu::Texture pixels_;          // slot j: (x + 0.5, y + 0.5, 0, 1) of the j-th marked pixel
  vgpu::Texture jitters_;         // entry k: sample k's offset from the pixel's centre
  vgpu::KernelProgram<kernels::ScanStream> scanner_;
  vgpu::KernelProgram<kernels::CompactMarks> compactor_;
  vgpu::KernelProgram<kernels::GatherMarked> gatherer_;
  vgpu::KernelProgram<kernels::AccumulateDense> accumulator_;
};

}  // namespace host
