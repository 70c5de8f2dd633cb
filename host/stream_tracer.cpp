// The stream ray tracer's host loop: which pass runs next, steered by occlusion queries.
#include "host/stream_tracer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "host/devices.h"
#include "host/parallel.h"

namespace host {

using namespace kernels;
using vgpu::Format;
using vgpu::KernelProgram;
using vgpu::Stencil;
using vgpu::Texture;

struct StreamTracer::State {
  // Static textures.
  Texture v[3], n[3], colors, lists, pointers;
  // Dynamic textures (ping-pong pairs where a pass reads what it replaces).
  Texture rays[2], origins[2], shadow_rays, trav[2], vs[2], isect[2], result[2], counter;
  int cur_rays = 0, cur_trav = 0, cur_vs = 0, cur_isect = 0, cur_result = 0;
  Stencil grid_mask, isect_mask;
  // Programs, with their uniforms.
  KernelProgram<GenerateRays> generate;
  KernelProgram<InitTraversal> init;
  KernelProgram<ResetTraversal> reset;
  KernelProgram<Traversal> traversal;
  KernelProgram<RaysInGrid> in_grid;
  KernelProgram<UpdateVoxel> update;
  KernelProgram<Intersections> intersect;
  KernelProgram<NextTriangle> next;
  KernelProgram<RaysIntersecting> intersecting;
  KernelProgram<Shader> shader;
  KernelProgram<ReflectedRays> reflected;
  KernelProgram<ReflectionOrigin> origin;
  KernelProgram<ReflectionDirection> direction;
  KernelProgram<ShadowRays> shadow;
  // Fused programs for --mrt on (kernels/fused.h).
  KernelProgram<IntersectNext> intersect_next;
  KernelProgram<TraverseUpdate> traverse_update;
  KernelProgram<LoopingTraversal> looping;
  uint64_t rays_traced = 0;
  uint64_t rays_unfinished = 0;
  int max_list = 0;  // longest voxel list: a ray tests at most this many triangles per voxel
};

GridSpec grid_spec_for(const GridSpec& spec, const Scene& scene, const vgpu::Profile& profile) {
  if (!spec.automatic()) return spec;
  glm::ivec3 r = auto_resolution(scene.bounds(), scene.triangle_count());
  const double maxs = profile.max_texture_size;
  while (double(r.x) * r.y > maxs) {
    const double f = std::sqrt(maxs / (double(r.x) * r.y));
    r.x = std::max(1, int(r.x * f));
    r.y = std::max(1, int(r.y * f));
  }
  r.z = std::min(r.z, profile.max_texture_size);
  return GridSpec{r};
}

namespace {

// The fused programs, each with its two kernels' groups (their arithmetic must agree).
struct FusedInfo {
  const char* name;
  int outputs;
  Group first, second;
};
const std::array<FusedInfo, 2>& fused_programs() {
  static const std::array<FusedInfo, 2> f{
      FusedInfo{IntersectNext::name, IntersectNext::outputs, Group::hits, Group::voxel},
      FusedInfo{TraverseUpdate::name, TraverseUpdate::outputs, Group::traversal, Group::voxel}};
  return f;
}

}  // namespace

std::string mrt_refusal(const vgpu::Profile& profile, const Formats& formats) {
  for (const FusedInfo& f : fused_programs()) {
    if (f.outputs > profile.max_outputs)
      return "--mrt on: program '" + std::string(f.name) + "' writes " + std::to_string(f.outputs) +
             " outputs; profile " + profile.name + " allows " +
             std::to_string(profile.max_outputs) + " (no multiple render targets)";
    if (formats.arithmetic(f.first) != formats.arithmetic(f.second))
      return "--mrt on: program '" + std::string(f.name) + "' computes in one format, but groups " +
             std::string(group_name(f.first)) + " (" +
             std::string(vgpu::format_name(formats.arithmetic(f.first))) + ") and " +
             std::string(group_name(f.second)) + " (" +
             std::string(vgpu::format_name(formats.arithmetic(f.second))) +
             ") differ; give them one arithmetic format (--formats)";
  }
  return {};
}

std::vector<std::string> mrt_programs() {
  std::vector<std::string> v;
  for (const FusedInfo& f : fused_programs()) v.push_back(f.name);
  return v;
}

kernels::ShadingModel parse_shading(const std::string& name) {
  if (name == "diffuse") return ShadingModel::diffuse;
  if (name == "phong") return ShadingModel::phong;
  if (name == "phong-atten") return ShadingModel::phong_atten;
  throw std::invalid_argument("unknown shading model '" + name +
                              "' (known: diffuse, phong, phong-atten)");
}

StreamTracer::StreamTracer(const Scene& scene, const Grid& grid, const RenderOptions& options)
    : scene_(scene), grid_(grid), opt_(options) {
  const auto t0 = std::chrono::steady_clock::now();
  gpu_ = make_device(opt_);
  s_ = std::make_unique<State>();
  vgpu::Device& gpu = *gpu_;
  if (opt_.masks && !gpu.has_stencil())
    throw vgpu::Error("--masks on needs stencil masks, which the " + opt_.device +
                      " device does not have");
  if (opt_.trace_pixel && !gpu.has_stencil())
    throw vgpu::Error("--trace-pixel follows the emulator's finished-ray masks, which the " +
                      opt_.device + " device does not have");
  // Each program computes in its group's arithmetic format (formats.h: which kernel is where).
  const Formats& fm = opt_.formats;
  for (auto [prog, g] :
       std::initializer_list<std::pair<vgpu::Program*, Group>>{{&s_->generate, Group::rays},
                                                               {&s_->origin, Group::rays},
                                                               {&s_->direction, Group::rays},
                                                               {&s_->shadow, Group::rays},
                                                               {&s_->init, Group::traversal},
                                                               {&s_->reset, Group::traversal},
                                                               {&s_->traversal, Group::traversal},
                                                               {&s_->in_grid, Group::queries},
                                                               {&s_->update, Group::voxel},
                                                               {&s_->next, Group::voxel},
                                                               {&s_->intersecting, Group::queries},
                                                               {&s_->intersect, Group::hits},
                                                               {&s_->shader, Group::colour},
                                                               {&s_->reflected, Group::colour}})
    prog->set_precision(fm.arithmetic(g));
  if (opt_.mrt) {
    const std::string why = mrt_refusal(gpu.profile(), fm);
    if (!why.empty()) throw vgpu::Error(why);
    // mrt_refusal checked that both kernels' groups compute alike.
    s_->intersect_next.set_precision(fm.arithmetic(Group::hits));
    s_->traverse_update.set_precision(fm.arithmetic(Group::traversal));
  }
  // The looping program does the traversal, voxel and hits groups' work: it computes in the
  // finest of their arithmetic formats (their textures keep their own formats).
  Format loop_arith = fm.arithmetic(Group::traversal);
  for (Group g : {Group::voxel, Group::hits})
    if (vgpu::significand_bits(fm.arithmetic(g)) > vgpu::significand_bits(loop_arith))
      loop_arith = fm.arithmetic(g);
  s_->looping.set_precision(loop_arith);
  const int maxs = gpu.profile().max_texture_size;

  // Scene textures: triangle i at texel (i mod width, i div width).
  const size_t ntri = scene.triangle_count();
  const int sw = int(std::min<size_t>(std::max<size_t>(ntri, 1), size_t(maxs)));
  const size_t sh = (ntri + sw - 1) / sw;
  if (sh > size_t(maxs))
    throw vgpu::Error("scene has " + std::to_string(ntri) + " triangles; profile " +
                      gpu.profile().name + " holds at most " + std::to_string(size_t(maxs) * maxs) +
                      " in one " + std::to_string(maxs) + "x" + std::to_string(maxs) + " texture");
  const std::vector<glm::vec3>* P[3] = {&scene.p0, &scene.p1, &scene.p2};
  const std::vector<glm::vec3>* N[3] = {&scene.n0, &scene.n1, &scene.n2};
  for (int c = 0; c < 3; ++c) {
    s_->v[c] = gpu.make_texture("vertices" + std::to_string(c), sw, int(sh), 3);
    s_->n[c] = gpu.make_texture("normals" + std::to_string(c), sw, int(sh), 3);
    for (size_t i = 0; i < ntri; ++i) {
      float* tv = s_->v[c].texel_mut(int(i % sw), int(i / sw));
      float* tn = s_->n[c].texel_mut(int(i % sw), int(i / sw));
      for (int k = 0; k < 3; ++k) tv[k] = (*P[c])[i][k], tn[k] = (*N[c])[i][k];
    }
  }
  s_->colors = gpu.make_texture("colors", sw, int(sh), 4);
  for (size_t i = 0; i < ntri; ++i) {
    const Material& m = scene.materials[scene.material[i]];
    float* t = s_->colors.texel_mut(int(i % sw), int(i / sw));
    t[0] = m.color.r, t[1] = m.color.g, t[2] = m.color.b, t[3] = m.reflect;
  }

  // Grid textures: the lists, each closed by -1 (entry 0 is the -1 every empty voxel shares),
  // and the voxel pointers at (X*sizeY + Y, Z).
  const glm::ivec3 r = grid.res;
  if (size_t(r.x) * r.y > size_t(maxs) || r.z > maxs)
    throw vgpu::Error("grid " + std::to_string(r.x) + "x" + std::to_string(r.y) + "x" +
                      std::to_string(r.z) + " needs a " + std::to_string(r.x * r.y) + "x" +
                      std::to_string(r.z) + " voxel pointer texture; profile " +
                      gpu.profile().name + " allows " + std::to_string(maxs) + "x" +
                      std::to_string(maxs));
  size_t nonempty = 0;
  for (size_t vox = 0; vox < grid.voxels(); ++vox) {
    const uint32_t n = grid.start[vox + 1] - grid.start[vox];
    nonempty += n > 0;
    s_->max_list = std::max(s_->max_list, int(n));
  }
  const size_t list_len = 1 + grid.tris.size() + nonempty;
  if (list_len >= (size_t(1) << 24))
    throw vgpu::Error("grid lists hold " + std::to_string(list_len) +
                      " entries; list positions are exact floats only below 2^24");
  const int lw = int(std::min<size_t>(list_len, size_t(maxs)));
  const size_t lh = (list_len + lw - 1) / lw;
  if (lh > size_t(maxs))
    throw vgpu::Error("grid lists hold " + std::to_string(list_len) + " entries; profile " +
                      gpu.profile().name + " holds at most " + std::to_string(size_t(maxs) * maxs) +
                      " (use a coarser grid)");
  s_->lists = gpu.make_texture("triangle lists", lw, int(lh), 1);
  s_->pointers = gpu.make_texture("voxel pointers", r.x * r.y, r.z, 1);
  size_t k = 0;
  auto put = [&](float value) {
    s_->lists.texel_mut(int(k % lw), int(k / lw))[0] = value;
    ++k;
  };
  put(kNone);
  for (int z = 0; z < r.z; ++z)
    for (int y = 0; y < r.y; ++y)
      for (int x = 0; x < r.x; ++x) {
        const auto tris = grid.triangles_in(grid.index(x, y, z));
        float start = 0;
        if (!tris.empty()) {
          start = float(k);
          for (uint32_t t : tris) put(float(t));
          put(kNone);
        }
        s_->pointers.texel_mut(x * r.y + y, z)[0] = start;
      }

  // Video memory gets the static textures once, at initialization.
  for (const Texture* t : {&s_->v[0], &s_->v[1], &s_->v[2], &s_->n[0], &s_->n[1], &s_->n[2],
                           &s_->colors, &s_->lists, &s_->pointers})
    gpu.upload(*t);

  // Dynamic textures: one texel per pixel.
  const int W = opt_.width, H = opt_.height;
  for (int i = 0; i < 2; ++i) {
    const std::string sfx = i ? " B" : " A";
    s_->rays[i] = gpu.make_texture("rays" + sfx, W, H, 4, fm[Group::rays]);
    s_->origins[i] = gpu.make_texture("origins" + sfx, W, H, 4, fm[Group::rays]);
    s_->trav[i] = gpu.make_texture("traversal" + sfx, W, H, 4, fm[Group::traversal]);
    s_->vs[i] = gpu.make_texture("voxel state" + sfx, W, H, 4, fm[Group::voxel]);
    s_->isect[i] = gpu.make_texture("intersection" + sfx, W, H, 4, fm[Group::hits]);
    s_->result[i] = gpu.make_texture("result" + sfx, W, H, 4, fm[Group::colour]);
  }
  s_->shadow_rays = gpu.make_texture("shadow rays", W, H, 4, fm[Group::rays]);
  // Counting passes need a colour target; only their query result matters.
  s_->counter = gpu.make_texture("counter", W, H, 1, Format::fp16);
  s_->grid_mask = Stencil(W, H, 1);
  s_->isect_mask = Stencil(W, H, 1);

  // Uniforms that do not change during a frame.
  GridUniforms g;
  g.lo = grid.lo;
  g.cell = grid.cell;
  g.res = glm::vec3(r);
  g.list_width = float(lw);
  const float diag = glm::length(grid.hi - grid.lo);
  g.t_slack = float(kSlackOfDiagonal) * diag;
  SceneUniforms su{float(sw)};
  s_->init.kernel.grid = g;
  s_->reset.kernel.grid = g;
  s_->traversal.kernel.grid = g;
  s_->update.kernel.grid = g;
  s_->intersect.kernel.grid = g;
  s_->intersect.kernel.scene = su;
  s_->next.kernel.grid = g;
  s_->intersect_next.kernel.grid = g;
  s_->intersect_next.kernel.scene = su;
  s_->traverse_update.kernel.grid = g;
  s_->looping.kernel.grid = g;
  s_->looping.kernel.scene = su;
  s_->looping.kernel.steps = opt_.steps_per_pass;
  s_->shader.kernel.scene = su;
  s_->shader.kernel.model = opt_.shading;
  s_->shader.kernel.shadows = opt_.shadows;
  s_->shader.kernel.atten_dist = float(kAttenOfDiagonal) * diag;
  s_->origin.kernel.scene = su;
  s_->origin.kernel.offset = float(kOffsetOfDiagonal) * diag;
  s_->direction.kernel.scene = su;
  gpu.stats().keep_pass_records = opt_.keep_pass_records;
  init_ms_ = ms_since(t0);
}

StreamTracer::~StreamTracer() = default;

uint64_t StreamTracer::texture_bytes() const {
  uint64_t b = 0;
  for (const Texture* t : {&s_->v[0], &s_->v[1], &s_->v[2], &s_->n[0], &s_->n[1], &s_->n[2],
                           &s_->colors, &s_->lists, &s_->pointers, &s_->shadow_rays, &s_->counter})
    b += t->bytes();
  for (int i = 0; i < 2; ++i)
    for (const Texture* t :
         {&s_->rays[i], &s_->origins[i], &s_->trav[i], &s_->vs[i], &s_->isect[i], &s_->result[i]})
      b += t->bytes();
  return b;
}

const vgpu::PassRecord& StreamTracer::pass(const vgpu::Program& p,
                                           std::initializer_list<const Texture*> in, Texture& out,
                                           const Stencil* work) {
  return pass(p, in, {&out}, work);
}

const vgpu::PassRecord& StreamTracer::pass(const vgpu::Program& p,
                                           std::initializer_list<const Texture*> in,
                                           std::initializer_list<Texture*> outs,
                                           const Stencil* work) {
  vgpu::Device& gpu = *gpu_;
  gpu.use_program(p);
  gpu.unbind_textures();
  int unit = 0;
  for (const Texture* t : in) gpu.bind_texture(unit++, *t);
  gpu.set_targets(outs);
  // The same finished-ray mask either skips fragments on the modeled hardware (masks on) or
  // only saves the emulator's host work (masks off: every fragment is charged).
  if (gpu.has_stencil()) {
    gpu.set_stencil_test(nullptr);
    gpu.set_work_mask(opt_.masks || opt_.host_shortcut ? work : nullptr);
    gpu.set_work_mask_counts_as_masked(opt_.masks);
  }
  const bool traced = traces_pixel(work);
  if (opt_.observer) opt_.observer->pass_begin(work);
  const vgpu::PassRecord& rec = gpu.draw();
  // The observer sees the first target (a fused pass's other targets are the same pass).
  if (opt_.observer) opt_.observer->pass({p, rec, **outs.begin(), gpu.branch_flags(), gpu.stats()});
  if (traced && !p.idle_discards()) {
    const int x = opt_.trace_pixel->x, y = opt_.trace_pixel->y;
    for (const Texture* out : outs) {
      const float* t = out->texel(x, y);
      char line[256];
      int n = std::snprintf(line, sizeof line, "  %-22s %-24s -> %-14s (", p.paper_name(), p.name(),
                            out->name().c_str());
      for (int c = 0; c < out->channels(); ++c)
        n += std::snprintf(line + n, sizeof line - size_t(n), "%s%g", c ? ", " : "", t[c]);
      *opt_.trace_out << line << ")\n";
    }
  }
  return rec;
}

bool StreamTracer::traces_pixel(const Stencil* work) const {
  return opt_.trace_pixel && opt_.trace_out &&
         (!work || work->get(opt_.trace_pixel->x, opt_.trace_pixel->y) != 0);
}

uint64_t StreamTracer::count(const vgpu::Program& p, const Texture& in, const Stencil* work,
                             Stencil* write) {
  vgpu::Device& gpu = *gpu_;
  const bool traced = traces_pixel(work);
  // The masks are the emulator's (its work mask, or stencils under --masks on).
  if (gpu.has_stencil()) gpu.set_stencil_write(write);
  gpu.begin_query();
  pass(p, {&in}, s_->counter, work);
  const uint64_t n = gpu.end_query();
  if (gpu.has_stencil()) gpu.set_stencil_write(nullptr);
  if (opt_.observer) opt_.observer->query(n, write, gpu.stats());
  if (traced) {
    char line[160];
    const char* mine = !write                                                 ? ""
                       : write->get(opt_.trace_pixel->x, opt_.trace_pixel->y) ? "counted"
                                                                              : "discarded";
    std::snprintf(line, sizeof line, "  %-22s %-24s    query: %llu rays; this one %s\n",
                  p.paper_name(), p.name(), static_cast<unsigned long long>(n), mine);
    *opt_.trace_out << line;
  }
  return n;
}

void StreamTracer::trace(Texture& origins, Texture& rays, bool primary, const Camera& cam) {
  vgpu::Device& gpu = *gpu_;
  State& s = *s_;
  auto swap = [](int& i) { i ^= 1; };
  gpu.clear(s.isect[s.cur_isect], {kFar, 0, 0, kNone});
  gpu.clear(s.vs[s.cur_vs], {0, 0, 0, kNone});
  // Enter the grid.
  if (primary) {
    s.init.kernel.eye = cam.position;
    pass(s.init, {&rays}, s.trav[s.cur_trav ^ 1]);
  } else {
    pass(s.reset, {&origins, &rays}, s.trav[s.cur_trav ^ 1]);
  }
  swap(s.cur_trav);
  s.grid_mask.fill(1);
  uint64_t walking = count(s.in_grid, s.trav[s.cur_trav], nullptr, &s.grid_mask);
  s.rays_traced += walking;
  // In exact arithmetic a ray crosses at most nx+ny+nz voxels and tests each voxel's list once.
  // Reduced precision can break both (fp16 cannot count past 2048): the host stops there and
  // reports the rays left unfinished instead of looping forever.
  if (opt_.looping) {
    walk_looping(origins, rays, walking);
    return;
  }
  const int max_steps = grid_.res.x + grid_.res.y + grid_.res.z + 2;
  for (int step = 0; walking > 0; ++step) {
    if (step == max_steps) {
      s.rays_unfinished += walking;
      break;
    }
    // The first triangle of each ray's new voxel (under --mrt on, only at the first step: later
    // ones come from the fused traversal + update voxel pass).
    if (!opt_.mrt || step == 0) {
      pass(s.update, {&s.trav[s.cur_trav], &s.vs[s.cur_vs], &s.pointers, &s.lists},
           s.vs[s.cur_vs ^ 1], &s.grid_mask);
      swap(s.cur_vs);
    }
    uint64_t testing =
        count(s.intersecting, s.vs[s.cur_vs], &s.grid_mask, &(s.isect_mask = s.grid_mask));
    // One triangle per pass, until no ray has a triangle left in its voxel.
    for (int k = 0; testing > 0; ++k) {
      if (k == s.max_list + 1) break;  // lists cannot be longer: stuck positions (fp16)
      if (opt_.mrt) {
        // intersecciones + proximoTriangulo in one pass, two targets.
        pass(s.intersect_next,
             {&origins, &rays, &s.trav[s.cur_trav], &s.vs[s.cur_vs], &s.isect[s.cur_isect], &s.v[0],
              &s.v[1], &s.v[2], &s.lists},
             {&s.isect[s.cur_isect ^ 1], &s.vs[s.cur_vs ^ 1]}, &s.isect_mask);
        swap(s.cur_isect);
        swap(s.cur_vs);
      } else {
        pass(s.intersect,
             {&origins, &rays, &s.trav[s.cur_trav], &s.vs[s.cur_vs], &s.isect[s.cur_isect], &s.v[0],
              &s.v[1], &s.v[2]},
             s.isect[s.cur_isect ^ 1], &s.isect_mask);
        swap(s.cur_isect);
        pass(s.next, {&s.vs[s.cur_vs], &s.lists}, s.vs[s.cur_vs ^ 1], &s.isect_mask);
        swap(s.cur_vs);
      }
      testing = count(s.intersecting, s.vs[s.cur_vs], &s.isect_mask, &s.isect_mask);
    }
    // One voxel step for every ray still walking (under --mrt on, with the next voxel's first
    // triangle in the same pass).
    if (opt_.mrt) {
      pass(s.traverse_update,
           {&origins, &rays, &s.trav[s.cur_trav], &s.isect[s.cur_isect], &s.vs[s.cur_vs],
            &s.pointers, &s.lists},
           {&s.trav[s.cur_trav ^ 1], &s.vs[s.cur_vs ^ 1]}, &s.grid_mask);
      swap(s.cur_trav);
      swap(s.cur_vs);
    } else {
      pass(s.traversal, {&origins, &rays, &s.trav[s.cur_trav], &s.isect[s.cur_isect]},
           s.trav[s.cur_trav ^ 1], &s.grid_mask);
      swap(s.cur_trav);
    }
    walking = count(s.in_grid, s.trav[s.cur_trav], &s.grid_mask, &s.grid_mask);
  }
}

void StreamTracer::walk_looping(Texture& origins, Texture& rays, uint64_t walking) {
  vgpu::Device& gpu = *gpu_;
  State& s = *s_;
  const vgpu::Program& p = s.looping;
  // A ray iterates once per triangle it tests and once per voxel it steps through: at most
  // (nx + ny + nz + 2) voxels of (longest list + 1) iterations each. Past that many passes the
  // host stops, as the multipass loop does, and reports the rays left unfinished.
  const int64_t max_iterations =
      int64_t(grid_.res.x + grid_.res.y + grid_.res.z + 2) * int64_t(s.max_list + 1);
  const int64_t max_passes = (max_iterations + opt_.steps_per_pass - 1) / opt_.steps_per_pass;
  for (int64_t k = 0; walking > 0; ++k) {
    if (k == max_passes) {
      s.rays_unfinished += walking;
      break;
    }
    Texture& trav = s.trav[s.cur_trav ^ 1];
    gpu.use_program(p);
    gpu.unbind_textures();
    int unit = 0;
    for (const Texture* t :
         {&origins, &rays, &s.trav[s.cur_trav], &s.vs[s.cur_vs], &s.isect[s.cur_isect], &s.v[0],
          &s.v[1], &s.v[2], &s.pointers, &s.lists})
      gpu.bind_texture(unit++, *t);
    gpu.set_targets({&trav, &s.vs[s.cur_vs ^ 1], &s.isect[s.cur_isect ^ 1]});
    // The walking rays' mask, as for the multipass kernels (finished rays keep their state).
    if (gpu.has_stencil()) {
      gpu.set_stencil_test(nullptr);
      gpu.set_work_mask(opt_.masks || opt_.host_shortcut ? &s.grid_mask : nullptr);
      gpu.set_work_mask_counts_as_masked(opt_.masks);
    }
    const bool traced = traces_pixel(&s.grid_mask);
    if (opt_.observer) opt_.observer->pass_begin(&s.grid_mask);
    const vgpu::PassRecord& rec = gpu.draw();
    if (opt_.observer) opt_.observer->pass({p, rec, trav, gpu.branch_flags(), gpu.stats()});
    s.cur_trav ^= 1;
    s.cur_vs ^= 1;
    s.cur_isect ^= 1;
    if (traced) {
      const int x = opt_.trace_pixel->x, y = opt_.trace_pixel->y;
      for (const Texture* t : {&s.trav[s.cur_trav], &s.vs[s.cur_vs], &s.isect[s.cur_isect]}) {
        const float* v = t->texel(x, y);
        char line[256];
        std::snprintf(line, sizeof line, "  %-22s %-24s -> %-14s (%g, %g, %g, %g)\n",
                      p.paper_name(), p.name(), t->name().c_str(), v[0], v[1], v[2], v[3]);
        *opt_.trace_out << line;
      }
    }
    walking = count(s.in_grid, s.trav[s.cur_trav], &s.grid_mask, &s.grid_mask);
  }
}

RenderResult StreamTracer::render(const Camera& cam) {
  const auto t0 = std::chrono::steady_clock::now();
  vgpu::Device& gpu = *gpu_;
  State& s = *s_;
  gpu.stats().clear();
  s.rays_traced = 0;
  s.rays_unfinished = 0;
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
  if (opt_.trace_pixel && opt_.trace_out)
    *opt_.trace_out << "pixel " << opt_.trace_pixel->x << "," << opt_.trace_pixel->y << ":\n";
  int ro = 0;  // origins[ro]: this iteration's ray origins; origins[ro ^ 1]: its hit points
  gpu.clear(s.origins[ro], {cam.position.x, cam.position.y, cam.position.z, 0});
  pass(s.generate, {}, s.rays[s.cur_rays]);
  gpu.clear(s.result[s.cur_result], {0, 0, 0, 1});

  const int iterations = 1 + std::max(0, opt_.bounces);
  for (int it = 0; it < iterations; ++it) {
    if (opt_.trace_pixel && opt_.trace_out) *opt_.trace_out << "iteration " << it + 1 << ":\n";
    res.iterations = it + 1;
    if (opt_.progress) opt_.progress(it + 1, iterations);
    if (opt_.observer) opt_.observer->iteration(it + 1);
    Texture& rays = s.rays[s.cur_rays];
    if (opt_.observer)
      opt_.observer->trace_begin(it ? PassObserver::TraceKind::reflected
                                    : PassObserver::TraceKind::primary);
    trace(s.origins[ro], rays, it == 0, cam);
    if (opt_.observer) opt_.observer->trace_end();
    Texture& hits = s.isect[s.cur_isect];
    if (it == 0) {
      gpu.download(hits);
      res.depth.assign(size_t(W) * H, 0.0f);
      res.hit_id.assign(size_t(W) * H, -1.0f);
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
          const float* t = hits.texel(x, y);
          if (t[3] >= 0) {
            res.depth[size_t(y) * W + x] = t[0];
            res.hit_id[size_t(y) * W + x] = float(scene_.id[size_t(t[3])]);
          }
        }
    }
    // inicioReflejo: hit points, the shader's record and the next rays' origins.
    Texture& surface = s.origins[ro ^ 1];
    pass(s.origin, {&s.origins[ro], &rays, &hits, &s.v[0], &s.v[1], &s.v[2]}, surface);
    // shader: one pass per light, after that light's shadow rays are traced.
    const auto& lights = scene_.lights;
    for (size_t li = 0; li < lights.size(); ++li) {
      Shader& sh = s.shader.kernel;
      sh.light = lights[li].position;
      sh.light_color = lights[li].color;
      sh.first_light = li == 0;
      sh.last_light = li + 1 == lights.size();
      if (opt_.shadows) {
        s.shadow.kernel.light = lights[li].position;
        pass(s.shadow, {&surface, &s.result[s.cur_result]}, s.shadow_rays);
        if (opt_.observer) opt_.observer->trace_begin(PassObserver::TraceKind::shadow);
        trace(surface, s.shadow_rays, false, cam);
        if (opt_.observer) opt_.observer->trace_end();
      }
      pass(s.shader,
           {&surface, &rays, &s.result[s.cur_result], &s.isect[s.cur_isect], &s.colors, &s.v[0],
            &s.v[1], &s.v[2], &s.n[0], &s.n[1], &s.n[2]},
           s.result[s.cur_result ^ 1]);
      s.cur_result ^= 1;
    }
    if (it + 1 == iterations) break;
    // rayosReflejados: stop when no ray was reflected.
    if (count(s.reflected, s.result[s.cur_result], nullptr, &s.grid_mask) == 0) break;
    pass(s.direction,
         {&rays, &surface, &s.result[s.cur_result], &s.v[0], &s.v[1], &s.v[2], &s.n[0], &s.n[1],
          &s.n[2]},
         s.rays[s.cur_rays ^ 1]);
    s.cur_rays ^= 1;
    ro ^= 1;
  }

  Texture& out = s.result[s.cur_result];
  gpu.download(out);
  res.rgb.resize(size_t(W) * H * 3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const float* t = out.texel(x, y);
      for (int c = 0; c < 3; ++c) res.rgb[(size_t(y) * W + x) * 3 + c] = t[c];
    }
  res.stats = gpu.stats();
  res.rays_traced = s.rays_traced;
  res.rays_unfinished = s.rays_unfinished;
  res.render_ms = ms_since(t0);
  return res;
}

}  // namespace host
