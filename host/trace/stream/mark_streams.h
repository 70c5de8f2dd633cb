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
#include <nlohmann/json.hpp>
#include <string>

#include "host/trace/passes.h"
#include "host/trace/ping_pong.h"
#include "host/trace/render_options.h"
#include "kernels/kernels.h"
#include "vgpu/vgpu.h"

namespace host {

// The statistics as --stats-json writes them ("compact") and as the table's line prints them.
nlohmann::ordered_json to_json(const CompactStats& s);
std::string describe(const CompactStats& s);

class MarkStreams {
 public:
  MarkStreams(vgpu::Device& gpu, const RenderOptions& opt);

  // Whether the profile's arithmetic addresses every pixel of the image exactly (fp24: 2^17
  // pixels, fp32: 2^24); where it does not, the gated frames run over the whole target.
  static bool fits(const vgpu::Profile& profile, int width, int height);

  // Packs the pixels `marks` flags (x > 0; `n` of them, as counted): the scan of the flags, then
  // the dense stream's pixel centres. Frames traced after it draw rect()'s rows.
  void pack(PassRunner& r, const vgpu::Texture& marks, uint64_t n);
  // The rows the packed stream fills (at least one).
  vgpu::Rect rect() const;
  uint64_t live() const { return n_; }
  const vgpu::Texture& pixels() const { return pixels_; }
  // reunirMarcados: `dense`'s texel of each marked pixel's slot into `out` (pixel layout), the
  // others `fallback`. Draws the whole target (r.rect must be unset).
  void gather(PassRunner& r, const vgpu::Texture& marks, const vgpu::Texture& dense,
              vgpu::Texture& out, glm::vec4 fallback);
  // A gated frame of the packed pixels begins: counted.
  void frame_begins();

  vgpu::KernelProgram<kernels::GenerateDenseRays> generate;
  CompactStats stats;  // this render's; the tracer resets it
  uint64_t texture_bytes() const;

 private:
  vgpu::Device& gpu_;
  int W_, H_;
  uint64_t n_ = 0;
  PingPong<vgpu::Texture> scan_;  // current(): the inclusive sums of the last marks packed
  vgpu::Texture pixels_;          // slot j: (x + 0.5, y + 0.5, 0, 1) of the j-th marked pixel
  vgpu::KernelProgram<kernels::ScanStream> scanner_;
  vgpu::KernelProgram<kernels::CompactMarks> compactor_;
  vgpu::KernelProgram<kernels::GatherMarked> gatherer_;
};

}  // namespace host
