// The paper's pipeline on the virtual GPU: static textures uploaded once (initialization), then
// per frame: generate rays -> enter the grid -> alternate traversal and intersection passes
// steered by occlusion-query counts -> shade (one pass per light, shadow rays through the same
// kernels) -> reflected rays through the same pipeline, up to a maximum number of iterations.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "host/accel/accel.h"
#include "host/accel/grid.h"
#include "host/model/formats.h"
#include "host/scene/scene.h"
#include "host/trace/grid_spec.h"
#include "host/trace/ping_pong.h"
#include "host/trace/render_options.h"
#include "kernels/kernels.h"
#include "vgpu/vgpu.h"

namespace host {

class StreamTracer {
 public:
  // Initialization, timed apart from rendering: the static textures (scene and grid) are built
  // and checked against the profile's limits. Throws vgpu::Error naming the limit.
  StreamTracer(const Scene& scene, const Grid& grid, const RenderOptions& options);
  // The same with the structure `accel` (of any kind; the tracer keeps none of it but its box).
  StreamTracer(const Scene& scene, const Accel& accel, const RenderOptions& options);
  ~StreamTracer();
  RenderResult render(const Camera& camera);

  // What a scene update sent to video memory.
  struct Upload {
    uint64_t bytes = 0;
    std::vector<std::string> textures;  // names of the textures uploaded again
  };
  // Between frames of a moving scene (--frames, issue 23): `scene` (the same file posed at
  // another time) and its rebuilt `grid` replace those the tracer was made with, on the same
  // device. The static textures are rewritten in place where the new scene and grid fit them,
  // and each one whose texels changed is uploaded again, whole; the uniforms that depend on
  // them are set. Both must outlive the next render, as at construction. Throws vgpu::Error
  // past the profile's limits, as the constructor does.
  Upload update(const Scene& scene, const Grid& grid);
  // The same with the structure `accel`, of the kind the tracer was made with, updated for the
  // new scene (Accel::update).
  Upload update(const Scene& scene, const Accel& accel);
  // Bytes of the static textures (the scene's and the grid's), all uploaded at initialization.
  uint64_t static_bytes() const;
  double init_ms() const { return init_ms_; }
  vgpu::Device& device() { return *gpu_; }
  uint64_t texture_bytes() const;  // static + dynamic textures, as the modeled card holds them
  // Whether the structure's textures are addressed by (x, y) (RenderOptions::addressing).
  bool addresses_by_xy() const;

 private:
  struct State;
  // Refuses (LimitError, naming the scene) a frame whose textures outgrow the profile's board
  // memory (vgpu::Profile::memory_mib), advising the profile with the least memory that holds
  // them. Checked once they are made: the static ones written, the per-pixel ones not yet
  // touched (their pages cost nothing until a pass writes them, vgpu/texture.h).
  void check_memory() const;
  // One ray stream (primary, shadow or reflected) through the grid: the walk of
  // host/trace/walks/grid_walk.h.
  void trace(vgpu::Texture& origins, vgpu::Texture& rays, bool primary, const Camera& cam);
  // One frame of the paper's pipeline with the rays `generate` makes: trace, shade, reflect,
  // up to 1 + bounces iterations (iteration_number counts them over the sample frames, for the
  // observer and --trace-pixel). Leaves the colour in the current result texture; with `aovs`,
  // the primary hits' depth and id go into res.
  // `marks` (if any) is the ray generator's input; with `keep_hits`, guardarImpactos writes
  // the primary hits' surface keys into the current marks texture.
  void frame(const Camera& cam, const vgpu::Program& generate, RenderResult& res, bool aovs,
             int& iteration_number, const vgpu::Texture* marks = nullptr, bool keep_hits = false);
  // frame() as ray streams (a glass scene, or RenderOptions::ray_streams;
  // host/trace/stream/ray_streams.h): level 0 is the primary frame; each later level traces and
  // shades, chunk by chunk, the rays the level before spawned (compacted), and the colours
  // return to the pixels level by level. Same arguments and results as frame().
  void stream_frame(const Camera& cam, const vgpu::Program& generate, RenderResult& res, bool aovs,
                    int& iteration_number, const vgpu::Texture* marks, bool keep_hits);
  // Ray generation (generadorRayos, or generadorRayosMuestra for a sample frame): every ray
  // starts at the eye (the origins pair starts over at A), `generate` writes the directions into
  // the current rays texture (reading `marks` if given), and the current result is cleared to
  // black.
  void generate_rays(const Camera& cam, const vgpu::Program& generate, const vgpu::Texture* marks);
  // The walk: one ray stream (primary or reflected) through the acceleration structure, told
  // to the observer as one trace. Leaves each ray's nearest hit in the current intersections.
  void walk_rays(vgpu::Texture& origins, vgpu::Texture& rays, bool primary, const Camera& cam);
  // After the primary walk: guardarImpactos (with `keep_hits`) writes the hits' surface keys
  // into the current marks; with `aovs`, the hits' depth and id go into res. `dense_marks`: the
  // frame traced those marks' pixels as a dense stream, whose hits are gathered back first.
  void primary_hits(RenderResult& res, bool aovs, bool keep_hits,
                    const vgpu::Texture* dense_marks = nullptr);
  // Whether adaptive supersampling decides by the pixels' cones (--aa-criterion object, or
  // budget: their scores).
  bool cones() const {
    return opt_.adaptive && opt_.aa_criterion != RenderOptions::AaCriterion::image;
  }
  bool budget() const {
    return opt_.adaptive && opt_.aa_criterion == RenderOptions::AaCriterion::budget;
  }
  // Reflection origin (inicioReflejo): from the rays and their hits, the hit points and the
  // surface record into `surface`, which the shader reads and the next rays start from.
  void reflection_origin(const vgpu::Texture& origins, const vgpu::Texture& rays,
                         vgpu::Texture& surface);
  // Reflection: rayosReflejados counts the rays the shader reflected (marking them in the
  // walk's mask); false when none was. Otherwise direccionReflejo writes their directions into
  // `next_rays`, the next iteration's rays.
  bool reflect(const vgpu::Texture& rays, const vgpu::Texture& surface, vgpu::Texture& next_rays);
  // Shading, one light at a time (the paper's per-light loop): for each light, rayosSombra makes
  // the shadow rays from `surface` (inicioReflejo's record) and trace() walks them, then the
  // shader pass adds that light's share. The colour ping-pongs through `col`: its current
  // texture holds the colour so far (or a spawned ray's weight), each shader pass writes the
  // next one and swaps, so at the end col.current() holds the result. frame() and
  // stream_frame() both shade through here.
  void shade_lights(const Camera& cam, vgpu::Texture& surface, vgpu::Texture& rays,
                    vgpu::Texture& origins, PingPong<vgpu::Texture*>& col);
  // One shader pass: its binding list, written once (with the base-colour textures when the
  // scene is textured).
  void shader_pass(const vgpu::Texture& surface, const vgpu::Texture& rays,
                   const vgpu::Texture& colour, const vgpu::Texture& shadow,
                   const vgpu::Texture& origins, vgpu::Texture& out);
  // ... with a shader of one's own (RenderOptions::user).
  void user_shader_pass(const vgpu::Texture& surface, const vgpu::Texture& rays,
                        const vgpu::Texture& colour, const vgpu::Texture& shadow,
                        const vgpu::Texture& origins, vgpu::Texture& out);
  // The primary hits' depths and input triangle ids into res, from `hits` (pixel layout).
  void download_aovs(RenderResult& res, vgpu::Texture& hits);
  // The sampling modes and their resolve (host/trace/stream/sampling_modes.cpp).
  // acumularMuestras: the current frame's colours (gated: only in the pixels `marks` flags, if
  // given) added into the sum of the sample frames; the sum ping-pongs.
  void accumulate_samples(const vgpu::Texture* marks);
  // The same after a gated frame, which may have traced its marked pixels as a dense stream
  // (then acumularDensos, `restart` as AccumulateSamples' uniform).
  void accumulate_gated(const vgpu::Texture* marks, bool restart);
  // One adaptive level with dense streams: the `marked` pixels' n samples each, packed into
  // as few frames as W x H slots allow, their colours added into the sums.
  // `offsets`: the level's samples; `restart`: the first replaces the pixels' earlier sums (a
  // kept level adds to them).
  void dense_level(const Camera& cam, RenderResult& res, int& iteration_number, uint64_t marked,
                   const std::vector<glm::vec2>& offsets, bool restart);
  // --aa-criterion budget, one level (kernels/cone_budget.h): puntuarConos scores the
  // candidates, pixelesPuntuados counts the pixels that hit above a value (the image's hits at
  // the first level, into `hits`), the binary search finds the least threshold whose count fits
  // the level's share of them, cortarPuntajes marks the scores above it.
  void budget_marks(size_t level, uint64_t& hits, RenderResult& res);
  // The sampling resolve, the last stage of a frame with several samples per pixel: `resolve`
  // (resolverMuestras, the box filter, or rellenarHuecos, the undersampling fill) turns the
  // sum of the sample frames into the pixels' colours, in the next result texture, which
  // becomes current (render() downloads it).
  void resolve_samples(const vgpu::Program& resolve);
  // --spp N (N > 1): N sample frames (generadorRayosMuestra, each through its sub-pixel
  // offset), each added into the sum (acumularMuestras), then resolverMuestras box-filters the
  // sum into the current result texture.
  void render_samples(const Camera& cam, RenderResult& res, int& iteration_number);
  // --aa adaptive (RenderOptions::adaptive): the centre frame, then levels of samples where the
  // marks say; leaves the resolved colour in the current result texture.
  void render_adaptive(const Camera& cam, RenderResult& res, int& iteration_number);
  // --aa undersample:K (RenderOptions::undersample): the lattice frame, the gaps' frame, the fill.
  void render_undersampled(const Camera& cam, RenderResult& res, int& iteration_number);

  // The scene's textures: triangle i at texel (i mod width, i div width); new textures when the
  // triangles outgrow them. With `uploaded`, changed textures are uploaded and named there.
  uint64_t write_scene(std::vector<std::string>* uploaded);
  // The uniforms that depend on the scene's texture width and the grid's size.
  void set_uniforms();

  const Scene* scene_;
  Bounds box_;  // the scene box the structure was built in (Accel::box)
  AccelKind accel_kind_;
  RenderOptions opt_;
  std::unique_ptr<vgpu::Device> gpu_;
  std::unique_ptr<State> s_;
  double init_ms_ = 0;
};

// Names of the shading models as the CLI spells them.
kernels::ShadingModel parse_shading(const std::string& name);

}  // namespace host
