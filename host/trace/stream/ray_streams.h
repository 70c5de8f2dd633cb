// Glass's ray streams on the virtual GPU (issue 25): the ray tree flattened into one stream per
// level, without recursion or scatter. The passes around the host loop's trace and shade:
// dividirRayos (the shares), the compaction (sumaPrefijos + contarRayos + compactarRayos), the
// chunk copies (copiarFilas) and the colour's way back (reunirHijos), and the shadow rays'
// continuation through glass (sombraVidrio). docs/studies/materials.md, "Glass on the virtual GPU".
#pragma once

#include <cstdint>
#include <deque>
#include <initializer_list>
#include <string>
#include <vector>

#include "host/scene/scene.h"
#include "host/trace/passes.h"
#include "host/trace/ping_pong.h"
#include "host/trace/render_options.h"
#include "kernels/kernels.h"
#include "vgpu/vgpu.h"

namespace host {

// Whether a scene needs ray streams: a material transmits light.
bool scene_has_glass(const Scene& scene);
// The colour texture's alpha under ray streams: the share of a ray's weight its surface does not
// shade itself, 1 - (1 - t)(1 - a), so the paper's shader adds w (1 - t)(1 - a) C. Exactly a for
// an opaque material.
float unshaded_share(const Material& m);

// The statistics (StreamStats, render_options.h) as the table's lines print them; the report
// room writes them as the statistics' "streams" object (host/report/stats_parts_json.h).
std::string describe(const StreamStats& s);

class RayStreams {
 public:
  // One level of the ray tree: element i at (i mod W, i div W) of its textures, W the image's
  // width; a chunk (what one walk traces) every H rows.
  struct Level {
    uint64_t n = 0;  // rays
    int chunks = 0;  // ceil(n / (W H))
    // Written by compactarRayos (levels 1 and later; level 0 is the primary frame's textures).
    vgpu::Texture origins, rays, weight;
    vgpu::Texture surface, split, colour, gathered;  // inicioReflejo's, dividirRayos', shaded
    PingPong<vgpu::Texture> scan;           // sumaPrefijos' passes; current() holds the sums
    const vgpu::Texture* shaded = nullptr;  // the level's own colours (colour, or a pass's target)
    const vgpu::Texture* total = nullptr;   // with the children's added (reunirHijos)
  };

  RayStreams(vgpu::Device& gpu, const RenderOptions& opt, bool glass);

  // Level k sized for n rays (textures grown or shrunk to whole chunks).
  Level& level(int k, uint64_t n);

  // One pass over `rect` of `out` (default: all of it), told to the observer like
  // PassRunner::pass; added to `passes` and `bytes` (bytes read and written).
  const vgpu::PassRecord& pass(PassRunner& r, const vgpu::Program& p,
                               std::initializer_list<const vgpu::Texture*> in, vgpu::Texture& out,
                               const vgpu::Rect* rect, uint64_t& passes, uint64_t& bytes);
  // contarRayos over the n elements of a stream texture, chunk by chunk (the counter target is
  // W x H): how many have `channel` >= threshold.
  uint64_t count(PassRunner& r, const vgpu::Texture& in, uint64_t n, int channel, float threshold,
                 uint64_t& passes, uint64_t& bytes);
  // copiarFilas: chunk c of a tall texture into a W x H one, or back (to_tall).
  void copy_chunk(PassRunner& r, const vgpu::Texture& from, vgpu::Texture& to, int c, bool to_tall);

  // After level k is traced and split: the scan of its spawn counts, the counts by kind (into
  // the statistics) and the gather of level k + 1's origins, rays and weights. Returns level
  // k + 1's ray count (0: nothing spawned; the level is not made).
  // `rays` holds level k's directions (level 0: the primary rays), `statics` the vertices 0-2
  // and normals 0-2.
  uint64_t compact(PassRunner& r, int k, const vgpu::Texture& rays,
                   const vgpu::Texture* const (&statics)[6]);
  // reunirHijos from the deepest level up; level 0's pass writes `pixels`.
  void gather_back(PassRunner& r, int deepest, vgpu::Texture& pixels);

  // The shadow rays of one light after their first trace (its hits in `hits`): while some stop
  // on glass, continue them (sombraVidrio, then `trace(origins, rays)` again, which returns the
  // new hits), at most 8 glass surfaces. Returns the texture whose w is each ray's
  // transmittance (the shader's kShadow).
  template <class Trace>
  const vgpu::Texture& shadows_through_glass(PassRunner& r, const vgpu::Texture& surface,
                                             const vgpu::Texture& shadow_rays,
                                             const vgpu::Texture* hits, Trace&& trace);

  // Bytes of every texture the streams hold (the glass texture, the levels' and chunks' state).
  uint64_t texture_bytes() const;
  vgpu::Texture& work(int i) { return work_[i]; }  // W x H chunk textures (multi-chunk levels)
  const vgpu::Texture& glass() const { return glass_; }
  vgpu::Texture& glass_mut() { return glass_; }
  void set_scene(const kernels::SceneUniforms& scene, float offset);
  bool glass_scene() const { return glass_scene_; }
  StreamStats stats;  // this render's; the tracer resets it

 private:
  vgpu::Device& gpu_;
  const RenderOptions& opt_;
  int W_, H_;
  bool glass_scene_;
  vgpu::Texture glass_;       // per triangle: a, t, ior (kernels/layout.h)
  std::deque<Level> levels_;  // a deque: a level's textures never move (pointers, GL ids)
  vgpu::Texture work_[7];     // chunk: origins, rays, weight, surface, split, colour A, colour B
  vgpu::Texture shadow_origins_[2], shadow_rays_[2];
  vgpu::Texture counter_;  // contarRayos' target (W x H)

 public:
  vgpu::KernelProgram<kernels::SplitRays> split;
  vgpu::KernelProgram<kernels::ScanStream> scan;
  vgpu::KernelProgram<kernels::CountStream> counter;
  vgpu::KernelProgram<kernels::CompactStream> compactor;
  vgpu::KernelProgram<kernels::CopyRows> copier;
  vgpu::KernelProgram<kernels::GatherChildren> gatherer;
  vgpu::KernelProgram<kernels::ShadowGlass> shadow_glass;
};

template <class Trace>
const vgpu::Texture& RayStreams::shadows_through_glass(PassRunner& r, const vgpu::Texture& surface,
                                                       const vgpu::Texture& shadow_rays,
                                                       const vgpu::Texture* hits, Trace&& trace) {
  // Round k reads the origins and rays round k - 1 wrote (round 1: the surface record and the
  // shadow rays) and the hits of their trace.
  const vgpu::Texture* origins = &surface;
  const vgpu::Texture* rays = &shadow_rays;
  constexpr int kMaxGlass = 8;  // docs/studies/materials.md: past 8 glass surfaces, blocked
  for (int round = 1;; ++round) {
    kernels::ShadowGlass& k = shadow_glass.kernel;
    k.first = round == 1;
    k.last = round == kMaxGlass;
    vgpu::Texture& o = shadow_origins_[round & 1];
    vgpu::Texture& d = shadow_rays_[round & 1];
    if (o.width() != W_ || o.height() != H_) {
      o = gpu_.make_texture("shadow origins " + std::to_string(round & 1), W_, H_, 4,
                            opt_.formats[Group::rays]);
      d = gpu_.make_texture("shadow rays " + std::to_string(round & 1), W_, H_, 4,
                            opt_.formats[Group::rays]);
    }
    k.part = 0;
    pass(r, shadow_glass, {origins, rays, hits, &glass_}, o, nullptr, stats.shadow_passes,
         stats.shadow_bytes);
    k.part = 1;
    pass(r, shadow_glass, {origins, rays, hits, &glass_}, d, nullptr, stats.shadow_passes,
         stats.shadow_bytes);
    if (k.last) return o;
    const uint64_t going =
        count(r, d, uint64_t(W_) * uint64_t(H_), 3, 0.0f, stats.shadow_passes, stats.shadow_bytes);
    if (going == 0) return o;
    stats.shadow_continued += going;
    hits = trace(o, d);
    origins = &o;
    rays = &d;
  }
}

}  // namespace host
