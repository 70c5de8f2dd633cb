// The stream ray tracer's host loop, the paper's pipeline: rays, the walk through the grid,
// shading with shadow rays, reflections; the walk itself is host/trace/walks/grid_walk.cpp.
#include "host/trace/stream/stream_tracer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <mutex>
#include <stdexcept>

#include "host/common/parallel.h"
#include "host/trace/diagonal.h"
#include "host/trace/passes.h"
#include "host/trace/sampling.h"
#include "host/trace/stream/atlas_upload.h"
#include "host/trace/stream/devices.h"
#include "host/trace/stream/mark_streams.h"
#include "host/trace/stream/ray_streams.h"
#include "host/trace/stream/stream_state.h"
#include "host/trace/structures.h"
#include "host/trace/textures.h"
#include "host/trace/validate.h"
#include "host/trace/walks/grid_walk.h"

namespace host {

using namespace kernels;
using vgpu::Format;
using vgpu::KernelProgram;
using vgpu::Stencil;
using vgpu::Texture;

kernels::ShadingModel parse_shading(const std::string& name) {
  if (name == "diffuse") return ShadingModel::diffuse;
  if (name == "phong") return ShadingModel::phong;
  if (name == "phong-atten") return ShadingModel::phong_atten;
  throw std::invalid_argument("unknown shading model '" + name +
                              "' (known: diffuse, phong, phong-atten)");
}

StreamTracer::StreamTracer(const Scene& scene, const Grid& grid, const RenderOptions& options)
    : StreamTracer(scene, GridAccel(grid), options) {}

StreamTracer::StreamTracer(const Scene& scene, const Accel& accel, const RenderOptions& options)
    : scene_(&scene), box_(accel.box()), accel_kind_(accel.kind()), opt_(options) {
  const auto t0 = std::chrono::steady_clock::now();
  gpu_ = make_device(opt_);
  s_ = std::make_unique<State>();
  State& s = *s_;
  vgpu::Device& gpu = *gpu_;
  // The options this frame cannot run, as the command line refuses them (host/trace/validate.h):
  // vgpu::Error, or std::invalid_argument for a sample count.
  throw_refusals(validate(opt_, gpu.profile(), nullptr, &scene));
  // Each program computes in its group's arithmetic format (formats.h: which kernel is where);
  // the walk's programs are set by the walk.
  const Formats& fm = opt_.formats;
  for (auto [prog, g] :
       std::initializer_list<std::pair<vgpu::Program*, Group>>{{&s.generate, Group::rays},
                                                               {&s.origin, Group::rays},
                                                               {&s.direction, Group::rays},
                                                               {&s.shadow, Group::rays},
                                                               {&s.shader, Group::colour},
                                                               {&s.reflected, Group::colour}})
    prog->set_precision(fm.arithmetic(g));
  // Kernels of one's own compute as the stage they replace.
  if (opt_.user.shader) opt_.user.shader->program().set_precision(fm.arithmetic(Group::colour));
  if (opt_.user.camera) opt_.user.camera->program().set_precision(fm.arithmetic(Group::rays));
  const bool sums = opt_.spp > 1 || opt_.undersample > 0;
  const bool marking = (opt_.adaptive && opt_.spp > 1) || opt_.undersample > 0;

  // Ray streams: a scene with glass needs them; --ray-streams on runs the paper's reflections
  // through them.
  const bool glass = scene_has_glass(scene);
  if (glass || opt_.ray_streams) s.streams = std::make_unique<RayStreams>(gpu, opt_, glass);

  // Scene textures: triangle i at texel (i mod width, i div width).
  write_scene(nullptr);

  // Base-colour textures (kernels/base_color.h): the texture atlas upload (atlas_upload.h).
  if (!scene.textures.empty()) {
    upload_texture_atlas(gpu, scene, s.v[0].width(), s.v[0].height(), s.base);
    s.textured = true;
  }

  // The acceleration structure's textures and walk: its row's (host/trace/structures.h).
  const float t_slack = float(kSlackOfDiagonal) * glm::length(box_.hi - box_.lo);
  s.walk = walk_row(accel.kind()).stream_walk(gpu, accel, opt_, float(s.v[0].width()), t_slack);

  // Video memory gets the static textures at initialization (and again, where they change,
  // between frames of a moving scene: update()).
  for (const Texture* t : {&s.v[0], &s.v[1], &s.v[2], &s.n[0], &s.n[1], &s.n[2], &s.colors})
    gpu.upload(*t);
  if (marking) gpu.upload(s.materials);
  if (s.streams) gpu.upload(s.streams->glass());
  s.walk->upload(gpu);

  // Dynamic textures: one texel per pixel.
  const int W = opt_.width, H = opt_.height;
  for (int i = 0; i < 2; ++i) {
    const std::string sfx = i ? " B" : " A";
    s.rays[i] = gpu.make_texture("rays" + sfx, W, H, 4, fm[Group::rays]);
    s.origins[i] = gpu.make_texture("origins" + sfx, W, H, 4, fm[Group::rays]);
    s.isect[i] = gpu.make_texture("intersection" + sfx, W, H, 4, fm[Group::hits]);
    s.result[i] = gpu.make_texture("result" + sfx, W, H, 4, fm[Group::colour]);
  }
  // The shadow rays, one per pixel where the frame casts them; a frame without shadows makes
  // none, and holds one texel in their place.
  s.shadow_rays = gpu.make_texture("shadow rays", opt_.shadows ? W : 1, opt_.shadows ? H : 1, 4,
                                   fm[Group::rays]);
  // Counting passes need a colour target; only their query result matters.
  s.counter = gpu.make_texture("counter", W, H, 1, Format::fp16);
  if (sums)
    for (int i = 0; i < 2; ++i)
      s.sum[i] = gpu.make_texture(std::string("sample sum ") + (i ? "B" : "A"), W, H, 4,
                                  fm[Group::colour]);
  if (marking) {
    for (int i = 0; i < 2; ++i)
      s.marks[i] = gpu.make_texture(std::string("marks ") + (i ? "B" : "A"), W, H, 4, Format::fp32);
    s.mark.kernel.threshold = opt_.threshold();
    s.mark_cones.kernel.threshold = opt_.threshold();
    s.mark_cones.kernel.depth_cones = opt_.cone_depth;
    s.score_cones.kernel.threshold = opt_.threshold();
    s.score_cones.kernel.depth_cones = opt_.cone_depth;
    const LatticeUniforms lattice{float(std::max(opt_.undersample, 1)), float(W), float(H)};
    s.mark_lattice.kernel.lattice = lattice;
    s.mark_gaps.kernel.lattice = lattice;
    s.mark_gaps.kernel.threshold = opt_.threshold();
    s.fill.kernel.lattice = lattice;
    s.fill.kernel.threshold = opt_.threshold();
  }
  s.grid_mask = Stencil(W, H, 1);
  s.isect_mask = Stencil(W, H, 1);
  s.walk->make_state(gpu, {{&s.v[0], &s.v[1], &s.v[2]}, &s.isect, &s.grid_mask, &s.isect_mask});
  s.runner = std::make_unique<PassRunner>(gpu, opt_, s.counter);
  // Sampling that saves time: the gated frames as dense streams of their marked pixels, where
  // the ray streams do not already move the rays (glass) and --trace-pixel does not follow one.
  if (marking && opt_.compact && !s.streams && !opt_.trace_pixel &&
      MarkStreams::fits(gpu.profile(), opt_))
    s.dense = std::make_unique<MarkStreams>(gpu, opt_);

  check_memory();

  s.shader.kernel.model = opt_.shading;
  s.shader.kernel.shadows = opt_.shadows;
  set_uniforms();
  gpu.stats().keep_pass_records = opt_.keep_pass_records;
  init_ms_ = ms_since(t0);
}

StreamTracer::~StreamTracer() = default;

void StreamTracer::check_memory() const {
  const vgpu::Profile& p = gpu_->profile();
  const uint64_t need = texture_bytes(), mib = uint64_t(1) << 20;
  if (p.memory_mib == 0 || need <= uint64_t(p.memory_mib) * mib) return;
  // The profile with the least memory that holds them, for the advice.
  const vgpu::Profile* fits = nullptr;
  for (const vgpu::Profile& q : vgpu::profiles())
    if (q.memory_mib > 0 && uint64_t(q.memory_mib) * mib >= need &&
        (!fits || q.memory_mib < fits->memory_mib))
      fits = &q;
  const auto in_mib = [&](uint64_t b) { return std::to_string((b + mib - 1) / mib) + " MiB"; };
  throw vgpu::LimitError(scene_->source + ": the frame's textures need " + in_mib(need) +
                         "; profile " + p.name + "'s board holds " +
                         in_mib(uint64_t(p.memory_mib) * mib) +
                         (fits ? " (--profile " + fits->name + "'s " +
                                     in_mib(uint64_t(fits->memory_mib) * mib) + " hold them)"
                               : std::string(", and no profile holds more")));
}

uint64_t StreamTracer::write_scene(std::vector<std::string>* uploaded) {
  State& s = *s_;
  vgpu::Device& gpu = *gpu_;
  const Scene& scene = *scene_;
  const bool marking = (opt_.adaptive && opt_.spp > 1) || opt_.undersample > 0;
  const size_t ntri = scene.triangle_count();
  if (!uploaded || uint64_t(s.v[0].width()) * uint64_t(s.v[0].height()) < ntri) {
    const int maxs = gpu.profile().max_texture_size;
    const int sw = int(std::min<size_t>(std::max<size_t>(ntri, 1), size_t(maxs)));
    const size_t sh = (ntri + sw - 1) / sw;
    if (sh > size_t(maxs))
      throw vgpu::Error("scene has " + std::to_string(ntri) + " triangles; profile " +
                        gpu.profile().name + " holds at most " +
                        std::to_string(size_t(maxs) * maxs) + " in one " + std::to_string(maxs) +
                        "x" + std::to_string(maxs) + " texture");
    for (int c = 0; c < 3; ++c) {
      s.v[c] = gpu.make_texture("vertices" + std::to_string(c), sw, int(sh), 3);
      s.n[c] = gpu.make_texture("normals" + std::to_string(c), sw, int(sh), 3);
    }
    s.colors = gpu.make_texture("colors", sw, int(sh), 4);
    if (s.streams) s.streams->glass_mut() = gpu.make_texture("glass", sw, int(sh), 4);
    if (marking) s.materials = gpu.make_texture("triangle materials", sw, int(sh), 1);
  }
  // Texel i is triangle i (row-major, rows of the texture's width); texels past the last
  // triangle keep what they held (never read).
  uint64_t bytes = 0;
  auto write = [&](Texture& t, auto&& texel) {
    std::vector<float> texels(t.data().begin(), t.data().end());
    const size_t channels = size_t(t.channels());
    for (size_t i = 0; i < ntri; ++i) texel(i, texels.data() + i * channels);
    if (t.replace(texels) && uploaded) {
      gpu.upload(t);
      bytes += t.bytes();
      uploaded->push_back(t.name());
    }
  };
  const std::vector<glm::vec3>* P[3] = {&scene.p0, &scene.p1, &scene.p2};
  const std::vector<glm::vec3>* N[3] = {&scene.n0, &scene.n1, &scene.n2};
  for (int c = 0; c < 3; ++c) {
    write(s.v[c], [&](size_t i, float* t) {
      for (int k = 0; k < 3; ++k) t[k] = (*P[c])[i][k];
    });
    write(s.n[c], [&](size_t i, float* t) {
      for (int k = 0; k < 3; ++k) t[k] = (*N[c])[i][k];
    });
  }
  write(s.colors, [&](size_t i, float* t) {
    const Material& m = scene.materials[scene.material[i]];
    t[0] = m.color.r, t[1] = m.color.g, t[2] = m.color.b;
    t[3] = s.streams ? unshaded_share(m) : m.reflect;
  });
  if (s.streams)
    write(s.streams->glass_mut(), [&](size_t i, float* t) {
      const Material& m = scene.materials[scene.material[i]];
      t[0] = m.reflect, t[1] = m.transmission, t[2] = m.ior, t[3] = 0.0f;
    });
  if (marking) write(s.materials, [&](size_t i, float* t) { t[0] = float(scene.material[i]); });
  return bytes;
}

void StreamTracer::set_uniforms() {
  State& s = *s_;
  const float diag = glm::length(box_.hi - box_.lo);
  const SceneUniforms su{float(s.v[0].width())};
  s.shader.kernel.scene = su;
  s.shader.kernel.atten_dist = float(kAttenOfDiagonal) * diag;
  s.origin.kernel.scene = su;
  s.origin.kernel.offset = float(kOffsetOfDiagonal) * diag;
  s.direction.kernel.scene = su;
  s.keep.kernel.scene = su;
  s.keep_cones.kernel.scene = su;
  s.keep_reflected.kernel.scene = su;
  s.shader.kernel.texture.on = s.textured;
  s.shader.kernel.texture.filter = opt_.texture_filter;
  if (s.streams) {
    s.streams->set_scene(su, float(kOffsetOfDiagonal) * diag);
    s.shader.kernel.shadow_transmittance = s.streams->glass_scene() && opt_.shadows;
  }
}

StreamTracer::Upload StreamTracer::update(const Scene& scene, const Grid& grid) {
  return update(scene, GridAccel(grid));
}

StreamTracer::Upload StreamTracer::update(const Scene& scene, const Accel& accel) {
  if (accel.kind() != accel_kind_)
    throw std::invalid_argument("StreamTracer::update: the tracer walks a " +
                                std::string(accel_name(accel_kind_)) + ", not a " +
                                std::string(accel.name()));
  scene_ = &scene;
  box_ = accel.box();
  Upload up;
  up.bytes += write_scene(&up.textures);
  up.bytes += s_->walk->rebuild(*gpu_, accel, float(s_->v[0].width()), up.textures);
  set_uniforms();
  return up;
}

uint64_t StreamTracer::static_bytes() const {
  uint64_t b = s_->walk->static_bytes();
  for (const Texture* t :
       {&s_->v[0], &s_->v[1], &s_->v[2], &s_->n[0], &s_->n[1], &s_->n[2], &s_->colors})
    b += t->bytes();
  if ((opt_.adaptive && opt_.spp > 1) || opt_.undersample > 0) b += s_->materials.bytes();
  if (s_->streams) b += s_->streams->glass().bytes();
  return b;
}

bool StreamTracer::addresses_by_xy() const {
  return s_->walk->addresses_by_xy();
}

uint64_t StreamTracer::texture_bytes() const {
  uint64_t b = s_->walk->texture_bytes();
  for (const Texture* t : {&s_->v[0], &s_->v[1], &s_->v[2], &s_->n[0], &s_->n[1], &s_->n[2],
                           &s_->colors, &s_->shadow_rays, &s_->counter})
    b += t->bytes();
  for (int i = 0; i < 2; ++i)
    for (const Texture* t : {&s_->rays[i], &s_->origins[i], &s_->isect[i], &s_->result[i]})
      b += t->bytes();
  if (opt_.spp > 1 || opt_.undersample > 0) b += s_->sum[0].bytes() + s_->sum[1].bytes();
  if ((opt_.adaptive && opt_.spp > 1) || opt_.undersample > 0)
    b += s_->marks[0].bytes() + s_->marks[1].bytes() + s_->materials.bytes();
  if (s_->textured)
    for (const Texture* t : {&s_->base.uvs01, &s_->base.uvs2, &s_->base.table, &s_->base.atlas})
      b += t->bytes();
  if (s_->streams) b += s_->streams->texture_bytes();  // grows with the frame's levels
  if (s_->dense) b += s_->dense->texture_bytes();
  return b;
}

void StreamTracer::trace(Texture& origins, Texture& rays, bool primary, const Camera& cam) {
  s_->walk->trace(*s_->runner, origins, rays, primary, cam.position);
}

RenderResult StreamTracer::render(const Camera& cam) {
  const auto t0 = std::chrono::steady_clock::now();
  vgpu::Device& gpu = *gpu_;
  State& s = *s_;
  gpu.stats().clear();
  PassRunner& r = *s.runner;
  r.counts = {};
  if (s.streams) s.streams->stats = {};
  if (s.dense) s.dense->stats = {};
  const int W = opt_.width, H = opt_.height;
  RenderResult res;
  res.width = W;
  res.height = H;

  // generadorRayos: one primary ray per pixel; every primary ray starts at the eye.
  GenerateRays& g = s.generate.kernel;
  g.forward = cam.forward;
  g.right = glm::normalize(glm::cross(cam.forward, cam.up));
  g.up = glm::cross(g.right, cam.forward);
  g.tan_half_fov = std::tan(0.5f * cam.yfov);
  g.aspect = float(W) / float(H);
  g.width = float(W);
  g.height = float(H);
  // The shader's ray differentials: the neighbouring pixels' rays (kernels/base_color.h).
  s.shader.kernel.texture.right = g.right;
  s.shader.kernel.texture.up = g.up;
  s.shader.kernel.texture.spread = 2.0f * g.tan_half_fov / float(H);
  s.mark_cones.kernel.spread = s.shader.kernel.texture.spread;  // the cones' width per distance
  s.score_cones.kernel.spread = s.shader.kernel.texture.spread;
  if (opt_.trace_pixel && opt_.trace_out)
    *opt_.trace_out << "pixel " << opt_.trace_pixel->x << "," << opt_.trace_pixel->y << ":\n";
  int iteration_number = 0;
  // The sample frames' generator takes the same camera (its jitter and gate are set per frame).
  static_cast<GenerateRays&>(s.sample_generate.kernel) = g;
  if (s.dense) static_cast<GenerateRays&>(s.dense->generate.kernel) = g;
  // One frame of the pipeline (frame()), or a sampling mode's frames, each mode ending in the
  // sampling resolve (resolve_samples) that combines its sample frames into the pixels.
  if (opt_.undersample > 0) {
    render_undersampled(cam, res, iteration_number);
  } else if (opt_.spp <= 1) {
    frame(cam, s.generate, res, true, iteration_number);
  } else if (opt_.adaptive) {
    render_adaptive(cam, res, iteration_number);
  } else {
    render_samples(cam, res, iteration_number);
  }

  Texture& out = s.result.current();
  gpu.download(out);
  res.rgb.resize(size_t(W) * H * 3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const float* t = out.texel(x, y);
      for (int c = 0; c < 3; ++c) res.rgb[(size_t(y) * W + x) * 3 + c] = t[c];
    }
  res.stats = gpu.stats();
  if (opt_.spp <= 1 && opt_.undersample == 0) res.first_frame_passes = res.stats.totals.passes;
  res.rays_traced = r.counts.rays_traced;
  res.rays_unfinished = r.counts.rays_unfinished;
  res.batch_walk = r.counts.batch_walk;
  res.batch_walk_bytes = r.counts.batch_bytes;
  res.walk_reason = r.counts.passes_reason;
  res.beam_passes = r.counts.beam_passes;
  res.beam_tiles = r.counts.beam_tiles;
  res.beam_tiles_missed = r.counts.beam_tiles_missed;
  res.beam_depth_sum = r.counts.beam_depth_sum;
  res.beam_depth_max = r.counts.beam_depth_max;
  res.beam_depths = r.counts.beam_depths;
  res.beam_map = std::move(r.counts.beam_map);
  if (s.streams) res.streams = s.streams->stats;
  if (s.dense) res.compact = s.dense->stats;
  res.render_ms = ms_since(t0);
  return res;
}

void StreamTracer::frame(const Camera& cam, const vgpu::Program& generate, RenderResult& res,
                         bool aovs, int& iteration_number, const Texture* marks, bool keep_hits) {
  if (s_->streams) {
    stream_frame(cam, generate, res, aovs, iteration_number, marks, keep_hits);
    return;
  }
  State& s = *s_;
  // A gated frame whose marks were packed (MarkStreams::pack, frame_begins) traces the dense
  // stream: every pass draws its rows; the colours stay there for the caller's gather
  // (acumularDensos).
  const bool dense = marks && s.dense;
  if (dense) s.runner->rect = s.dense->rect();
  generate_rays(cam, generate, marks);
  // Each iteration is one ray stream (the primary rays, then each bounce's reflected rays):
  // the walk, inicioReflejo, the shading per light, then the reflected rays of the next one.
  const int iterations = 1 + std::max(0, opt_.bounces);
  for (int it = 0; it < iterations; ++it) {
    const int number = ++iteration_number;  // 1-based, counted over the sample frames
    if (opt_.trace_pixel && opt_.trace_out) *opt_.trace_out << "iteration " << number << ":\n";
    res.iterations = std::max(res.iterations, it + 1);
    if (opt_.progress) opt_.progress(it + 1, iterations);
    if (opt_.observer) opt_.observer->iteration(number);
    Texture& rays = s.rays.current();
    Texture& origins = s.origins.current();
    walk_rays(origins, rays, it == 0, cam);
    if (it == 0) primary_hits(res, aovs, keep_hits, dense ? marks : nullptr);
    // guardarReflejos (--aa-criterion object): the first reflected rays' surface keys. The
    // criterion is adaptive sampling's, whose centre frame (the one keeping hits) is never dense.
    if (it == 1 && keep_hits && cones()) {
      s.runner->pass(s.keep_reflected, {&s.marks.current(), &s.isect.current(), &s.materials},
                     s.marks.next());
      s.marks.swap();
    }
    Texture& surface = s.origins.next();  // the hit points: the next iteration's origins
    reflection_origin(origins, rays, surface);
    PingPong<Texture*> col(&s.result.current(), &s.result.next());
    shade_lights(cam, surface, rays, origins, col);
    if (col.which() == 1) s.result.swap();  // the shading's last pass wrote result.next()
    if (it + 1 == iterations) break;
    if (!reflect(rays, surface, s.rays.next())) break;
    s.rays.swap();
    s.origins.swap();
  }
  s.runner->rect.reset();
}

void StreamTracer::generate_rays(const Camera& cam, const vgpu::Program& generate,
                                 const Texture* marks) {
  State& s = *s_;
  // Each frame's origins start over at A (the other pairs go on from where the last frame
  // left them).
  s.origins.make_current(0);
  gpu_->clear(s.origins.current(), {cam.position.x, cam.position.y, cam.position.z, 0});
  // Beams over tiles march the same rays: the generator's camera, and a sample frame's jitter.
  if (&generate == &s.sample_generate) {
    const GenerateSampleRays& k = s.sample_generate.kernel;
    s.walk->set_camera(k, k.jitter_x - 0.5f, k.jitter_y - 0.5f);
  } else {
    s.walk->set_camera(s.generate.kernel, 0.0f, 0.0f);
  }
  if (opt_.user.camera) {
    // A camera of one's own (host/trace/user_stage.h): the generator's camera and this frame's
    // sample position as its uniforms (never a gated frame: validate refuses those modes).
    const GenerateRays& g = s.generate.kernel;
    kernels::CameraStage u;
    u.eye = cam.position;
    u.forward = g.forward;
    u.right = g.right;
    u.up = g.up;
    u.tan_half_fov = g.tan_half_fov;
    u.aspect = g.aspect;
    u.width = g.width;
    u.height = g.height;
    if (&generate == &s.sample_generate) {
      u.jitter_x = s.sample_generate.kernel.jitter_x;
      u.jitter_y = s.sample_generate.kernel.jitter_y;
    }
    opt_.user.camera->bind(u);
    s.runner->pass(opt_.user.camera->program(), std::span<const Texture* const>{},
                   {&s.rays.current()});
  } else if (marks && s.dense) {
    // generadorRayosDensos: each slot's sample through its packed pixel.
    s.runner->pass(s.dense->generate, {&s.dense->pixels(), &s.dense->jitters()}, s.rays.current());
  } else if (marks)
    s.runner->pass(generate, {marks}, s.rays.current());
  else
    s.runner->pass(generate, {}, s.rays.current());
  gpu_->clear(s.result.current(), {0, 0, 0, 1});
}

void StreamTracer::walk_rays(Texture& origins, Texture& rays, bool primary, const Camera& cam) {
  if (opt_.observer)
    opt_.observer->trace_begin(primary ? PassObserver::TraceKind::primary
                                       : PassObserver::TraceKind::reflected);
  s_->runner->walking = primary ? "primary rays" : "reflected rays";
  trace(origins, rays, primary, cam);
  s_->runner->walking = "rays";
  if (opt_.observer) opt_.observer->trace_end();
}

void StreamTracer::primary_hits(RenderResult& res, bool aovs, bool keep_hits,
                                const Texture* dense_marks) {
  State& s = *s_;
  // guardarImpactos: the primary hits' surface keys (--aa adaptive, undersampling's lattice),
  // before later traces overwrite the intersections. With --aa-criterion object, guardarConos
  // also keeps the hit distances (kernels/cones.h).
  const vgpu::Program& keep = cones() ? static_cast<const vgpu::Program&>(s.keep_cones) : s.keep;
  Texture* hits = &s.isect.current();
  if (dense_marks && (aovs || keep_hits)) {
    // A dense stream's hits go back to their pixels first (reunirMarcados, the unmarked pixels
    // no hit), into the intersection pair's other texture, which the walk rewrites before
    // reading.
    const std::optional<vgpu::Rect> rows = s.runner->rect;
    s.runner->rect.reset();
    s.dense->gather(*s.runner, *dense_marks, s.isect.current(), s.isect.next(),
                    {kFar, 0, 0, kNone});
    hits = &s.isect.next();
    if (keep_hits) s.runner->pass(keep, {hits, &s.materials}, s.marks.current());
    s.runner->rect = rows;
  } else if (keep_hits) {
    s.runner->pass(keep, {hits, &s.materials}, s.marks.current());
  }
  if (aovs) download_aovs(res, *hits);
}

void StreamTracer::reflection_origin(const Texture& origins, const Texture& rays,
                                     Texture& surface) {
  State& s = *s_;
  s.runner->pass(s.origin, {&origins, &rays, &s.isect.current(), &s.v[0], &s.v[1], &s.v[2]},
                 surface);
}

bool StreamTracer::reflect(const Texture& rays, const Texture& surface, Texture& next_rays) {
  State& s = *s_;
  PassRunner& r = *s.runner;
  // rayosReflejados: how many rays the shader reflected (marked in the walk's mask).
  if (r.count(s.reflected, s.result.current(), nullptr, &s.grid_mask) == 0) return false;
  // direccionReflejo: their directions.
  r.pass(
      s.direction,
      {&rays, &surface, &s.result.current(), &s.v[0], &s.v[1], &s.v[2], &s.n[0], &s.n[1], &s.n[2]},
      next_rays);
  return true;
}

void StreamTracer::shade_lights(const Camera& cam, Texture& surface, Texture& rays,
                                Texture& origins, PingPong<Texture*>& col) {
  State& s = *s_;
  PassRunner& r = *s.runner;
  const auto& lights = scene_->lights;
  for (size_t li = 0; li < lights.size(); ++li) {
    Shader& sh = s.shader.kernel;
    sh.light = lights[li].position;
    sh.light_color = lights[li].color;
    sh.first_light = li == 0;
    sh.last_light = li + 1 == lights.size();
    // rayosSombra: the shadow rays toward this light, traced through the same walk; the shader
    // reads their intersections (continued through glass in a glass scene).
    const Texture* shadow = nullptr;  // the shadow rays' hits, when not the current ones
    if (opt_.shadows) {
      s.shadow.kernel.light = lights[li].position;
      r.pass(s.shadow, {&surface, col.current()}, s.shadow_rays);
      if (opt_.observer) opt_.observer->trace_begin(PassObserver::TraceKind::shadow);
      r.walking = "shadow rays";
      trace(surface, s.shadow_rays, false, cam);
      r.walking = "rays";
      if (s.streams && s.streams->glass_scene())
        shadow = &s.streams->shadows_through_glass(r, surface, s.shadow_rays, &s.isect.current(),
                                                   [&](Texture& o, Texture& d) {
                                                     trace(o, d, false, cam);
                                                     return &s.isect.current();
                                                   });
      if (opt_.observer) opt_.observer->trace_end();
    }
    shader_pass(surface, rays, *col.current(), shadow ? *shadow : s.isect.current(), origins,
                *col.next());
    col.swap();
  }
}

void StreamTracer::shader_pass(const Texture& surface, const Texture& rays, const Texture& colour,
                               const Texture& shadow, const Texture& origins, Texture& out) {
  State& s = *s_;
  if (opt_.user.shader) {
    user_shader_pass(surface, rays, colour, shadow, origins, out);
    return;
  }
  // The shader's inputs, in its binding order (kernels/shader.h); a textured scene's shader
  // also reads the rays' origins (for the ray differentials) and the base-colour textures.
  if (s.textured)
    s.runner->pass(
        s.shader,
        {&surface, &rays, &colour, &shadow, &s.colors, &s.v[0], &s.v[1], &s.v[2], &s.n[0], &s.n[1],
         &s.n[2], &origins, &s.base.uvs01, &s.base.uvs2, &s.base.table, &s.base.atlas},
        out);
  else
    s.runner->pass(s.shader,
                   {&surface, &rays, &colour, &shadow, &s.colors, &s.v[0], &s.v[1], &s.v[2],
                    &s.n[0], &s.n[1], &s.n[2]},
                   out);
}

void StreamTracer::user_shader_pass(const Texture& surface, const Texture& rays,
                                    const Texture& colour, const Texture& shadow,
                                    const Texture& origins, Texture& out) {
  // A shader of one's own (host/trace/user_stage.h): the uniforms the project's shader has for
  // this light, and the textures it binds, to the units the kernel names.
  State& s = *s_;
  const Shader& sh = s.shader.kernel;
  kernels::ShaderStage u;
  u.light = sh.light;
  u.light_color = sh.light_color;
  u.first_light = sh.first_light ? 1.0f : 0.0f;
  u.last_light = sh.last_light ? 1.0f : 0.0f;
  u.shadows = sh.shadows ? 1.0f : 0.0f;
  u.shadow_transmittance = sh.shadow_transmittance ? 1.0f : 0.0f;
  u.ambient = sh.ambient;
  u.background = sh.background;
  u.specular = sh.specular;
  u.atten_dist = sh.atten_dist;
  u.scene_width = sh.scene.width;
  UserShader& k = *opt_.user.shader;
  k.bind(u);
  const std::array<const Texture*, Shader::units.size()> stage{
      &surface,
      &rays,
      &colour,
      &shadow,
      &s.colors,
      &s.v[0],
      &s.v[1],
      &s.v[2],
      &s.n[0],
      &s.n[1],
      &s.n[2],
      &origins,
      s.textured ? &s.base.uvs01 : nullptr,
      s.textured ? &s.base.uvs2 : nullptr,
      s.textured ? &s.base.table : nullptr,
      s.textured ? &s.base.atlas : nullptr};
  std::vector<const Texture*> in;
  for (const std::string& name : k.units()) {
    const auto at = std::find(Shader::units.begin(), Shader::units.end(), name);
    const Texture* t =
        at == Shader::units.end() ? nullptr : stage[size_t(at - Shader::units.begin())];
    if (!t)  // validate() refuses these before the frame
      throw vgpu::Error(std::string("shader '") + k.program().name() + "': no texture '" + name +
                        "' in this frame");
    in.push_back(t);
  }
  s.runner->pass(k.program(), in, {&out});
}

void StreamTracer::download_aovs(RenderResult& res, Texture& hits) {
  const int W = opt_.width, H = opt_.height;
  gpu_->download(hits);
  res.depth.resize(size_t(W) * H);
  res.hit_id.resize(size_t(W) * H);
  auto rows = [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const float* t = hits.texel(x, y);
        const bool hit = t[3] >= 0;
        res.depth[size_t(y) * W + x] = hit ? t[0] : 0.0f;
        res.hit_id[size_t(y) * W + x] = hit ? float(scene_->id[size_t(t[3])]) : -1.0f;
      }
  };
  // On the emulator, over its threads (a serial part of a 16-thread frame otherwise).
  if (auto* emu = dynamic_cast<vgpu::Gpu*>(gpu_.get()))
    emu->parallel_blocks(size_t(H), size_t(65536 / W) + 1,
                         [&](size_t y0, size_t y1) { rows(int(y0), int(y1)); });
  else
    rows(0, H);
}

void StreamTracer::stream_frame(const Camera& cam, const vgpu::Program& generate, RenderResult& res,
                                bool aovs, int& iteration_number, const Texture* marks,
                                bool keep_hits) {
  State& s = *s_;
  PassRunner& r = *s.runner;
  RayStreams& g = *s.streams;
  const int W = opt_.width, H = opt_.height;
  g.stats.on = true;
  // Level 0 is the paper's primary frame: one ray per pixel from the eye, weight 1.
  generate_rays(cam, generate, marks);
  const Texture* const statics[6] = {&s.v[0], &s.v[1], &s.v[2], &s.n[0], &s.n[1], &s.n[2]};
  const int iterations = 1 + std::max(0, opt_.bounces);
  uint64_t n = uint64_t(W) * uint64_t(H);
  int deepest = 0;
  for (int k = 0; k < iterations; ++k) {
    const int number = ++iteration_number;
    res.iterations = std::max(res.iterations, k + 1);
    if (opt_.progress) opt_.progress(k + 1, iterations);
    if (opt_.observer) opt_.observer->iteration(number);
    RayStreams::Level& L = g.level(k, n);
    g.stats.levels[size_t(k)].rays += n;
    g.stats.levels[size_t(k)].chunks += uint64_t(L.chunks);
    const bool spawns = k + 1 < iterations;
    const bool chunked = L.chunks > 1;
    for (int c = 0; c < L.chunks; ++c) {
      // This chunk's rays, its surface record and spawn shares, and the pair the shader
      // ping-pongs (the first holds the rays' weights): level 0 in the tracer's own textures,
      // a one-chunk level in its own, a longer one through the chunk textures.
      Texture *origins, *rays, *surface, *split;
      PingPong<Texture*> col;
      if (k == 0) {
        origins = &s.origins.current(), rays = &s.rays.current();
        col = {&s.result.current(), &s.result.next()};
        surface = &L.surface, split = &L.split;
      } else if (!chunked) {
        origins = &L.origins, rays = &L.rays, col = {&L.weight, &L.colour};
        surface = &L.surface, split = &L.split;
      } else {
        origins = &g.work(0), rays = &g.work(1), col = {&g.work(2), &g.work(5)};
        surface = &g.work(3), split = &g.work(4);
        g.copy_chunk(r, L.origins, *origins, c, false);
        g.copy_chunk(r, L.rays, *rays, c, false);
        g.copy_chunk(r, L.weight, *col.current(), c, false);
      }
      walk_rays(*origins, *rays, k == 0, cam);
      if (k == 0) primary_hits(res, aovs, keep_hits);
      reflection_origin(*origins, *rays, *surface);
      // dividirRayos: the weights of the rays this one spawns, before the shader replaces the
      // weight.
      if (spawns)
        g.pass(r, g.split,
               {rays, surface, col.current(), &g.glass(), &s.v[0], &s.v[1], &s.v[2], &s.n[0],
                &s.n[1], &s.n[2]},
               *split, nullptr, g.stats.split_passes, g.stats.split_bytes);
      // shader: one pass per light after its shadow rays (continued through glass).
      shade_lights(cam, *surface, *rays, *origins, col);
      if (k == 0 && col.which() == 1) s.result.swap();  // the shading's last pass wrote next()
      if (!chunked) {
        L.shaded = col.current();
      } else {
        g.copy_chunk(r, *surface, L.surface, c, true);
        if (spawns) g.copy_chunk(r, *split, L.split, c, true);
        g.copy_chunk(r, *col.current(), L.colour, c, true);
        L.shaded = &L.colour;
      }
    }
    if (!spawns) break;
    // The compaction: the next level holds only the rays spawned.
    n = g.compact(r, k, k == 0 ? s.rays.current() : L.rays, statics);
    if (n == 0) break;
    deepest = k + 1;
  }
  // The colours return to the pixels, deepest level first (level 0's shaded colour is the
  // current result).
  if (deepest > 0) {
    g.gather_back(r, deepest, s.result.next());
    s.result.swap();
  }
}

}  // namespace host
