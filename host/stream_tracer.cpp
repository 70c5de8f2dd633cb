// The stream ray tracer's host loop: which pass runs next, steered by occlusion queries.
#include "host/stream_tracer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <mutex>
#include <stdexcept>

#include "host/devices.h"
#include "host/parallel.h"
#include "vgpu/gpu.h"

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
  bool batch_walk = false;  // a walk of this frame ran in batches
  int max_list = 0;         // longest voxel list: a ray tests at most this many triangles per voxel
  // Per program of the walk, the units it reads only at its own texel (batch walks).
  std::vector<std::pair<const vgpu::Program*, uint32_t>> own_only;
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

namespace {

// The walk's call sites: with the step (-1 before the first) and the triangle index k within a
// step (-1 outside the triangle loop), a site names one pass of the walk's pass sequence.
enum Site : int {
  kEnter,           // rayosEnGrilla before the first step
  kUpdate,          // actualizarVoxel
  kTesting,         // rayosIntersectando after actualizarVoxel
  kIntersect,       // intersecciones
  kNext,            // proximoTriangulo
  kIntersectNext,   // intersecciones + proximoTriangulo (--mrt on)
  kTestingOn,       // rayosIntersectando in the triangle loop
  kTraversal,       // traversal
  kTraverseUpdate,  // traversal + actualizarVoxel (--mrt on)
  kInGrid,          // rayosEnGrilla after the step
  kSites
};

// A pass of the walk: its site, step and k; `parity` says which texture of each ping-pong pair
// is current (bit 0 traversal, 1 voxel state, 2 intersection), which fixes the bindings.
struct PassKey {
  int step, k;
  Site site;
  uint8_t parity = 0;
};

// Per pass of the walk (by PassKey), a T: grown on first use, cheap to look up.
template <class T>
class Keyed {
 public:
  [[gnu::always_inline]] T& at(const PassKey& key) {
    // A walk asks for one step's passes in a row: each site's row of the last step is kept.
    auto& [step, row] = rows_[size_t(key.site)];
    if (step != key.step || !row) [[unlikely]]
      row = &step_row(key, step);
    const size_t j = size_t(key.k + 1);
    if (row->size() <= j) [[unlikely]]
      row->resize(j + 1);
    return (*row)[j];
  }
  // f(key, value) for every pass seen.
  template <class Fn>
  void for_each(Fn&& f) {
    for (int site = 0; site < kSites; ++site)
      for (size_t i = 0; i < v_[size_t(site)].size(); ++i)
        for (size_t j = 0; j < v_[size_t(site)][i].size(); ++j)
          f(PassKey{int(i) - 1, int(j) - 1, Site(site)}, v_[size_t(site)][i][j]);
  }

 private:
  std::vector<T>& step_row(const PassKey& key, int& step) {
    auto& by_step = v_[size_t(key.site)];
    const size_t i = size_t(key.step + 1);
    if (by_step.size() <= i) by_step.resize(i + 1);
    step = key.step;
    return by_step[i];
  }

  std::array<std::vector<std::vector<T>>, kSites> v_;
  // Per site, the step asked last and its row (by_step's vectors move when it grows, but only
  // when a new step of the same site is asked for, and that refreshes the row).
  std::array<std::pair<int, std::vector<T>*>, kSites> rows_{};
};

// What one pass of a walk knows about a program, worked out once per walk.
struct ProgramInfo {
  const vgpu::Program* program = nullptr;
  vgpu::Format precision = vgpu::Format::fp32;
  int branches = 0;       // f.branch() calls: the batch counters are kept for it
  uint32_t own_only = 0;  // units the program reads only at the fragment's own texel
  bool idle_discards = false;
  std::array<int, vgpu::kMaxOutputs> passthrough{};
};

// Units a program fetches only at its own texel (Op::fetch_own in its recording, never
// Op::fetch): those may come from a batch's registers.
uint32_t own_only_units(const vgpu::Program& p) {
  const vgpu::Recording rec = p.record();
  uint32_t own = 0, other = 0;
  for (const vgpu::RecNode& n : rec.nodes) {
    if (n.op == vgpu::Op::fetch_own) own |= 1u << n.unit;
    if (n.op == vgpu::Op::fetch) other |= 1u << n.unit;
  }
  return own & ~other;
}

// The batch counters of one pass within one 32x32 tile: its 8x4 tiles holding a fragment that
// took a branch, the fragments that took one, and those that ran (in all and per 8x4 tile).
struct TileAcc {
  uint32_t took_tiles = 0;  // bit j: 8x4 tile j (row-major, 4 per row) holds a took fragment
  uint32_t took = 0, ran = 0;
  std::array<uint8_t, 32> ran_in{};
  bool touched = false;
};

// Runs the walk for one batch of pixels (8 neighbours of a row): every pass runs the program on
// the lanes its work mask leaves (vgpu::run_batch), with the ray state in registers; queries
// return the lanes that survive. Tallies every pass (by PassKey) for the replay. The bindings of
// a pass depend only on its site and parity: they are resolved once per walker (a Plan).
class BatchWalker {
 public:
  using Count = uint8_t;  // lanes as bits
  static bool any(Count c) { return c != 0; }

  BatchWalker(const vgpu::Gpu& gpu, const std::vector<ProgramInfo>& programs, bool work_masked,
              int width, int height)
      : programs_(programs),
        dynamic_(gpu.profile().branching == vgpu::Branching::dynamic),
        work_masked_(work_masked),
        width_(width),
        height_(height) {}

  struct Entry {
    vgpu::PassTally tally;
    TileAcc acc;
  };
  Keyed<Entry> entries;

  void begin(int x0, int y, int n) {
    x0_ = x0;
    y_ = y;
    n_ = n;
    valid_ = uint8_t((1u << n) - 1);
    tile8x4_ = (y % 32) / 4 * 4 + (x0 % 32) / 8;  // the 8x4 tile of its 32x32 tile it lies in
    loaded_ = 0;
    masks_loaded_ = 0;
  }
  void fill(const Stencil& m, uint8_t v) { set_mask(mask_id(m), v ? valid_ : 0); }
  void copy(const Stencil& to, const Stencil& from) {
    set_mask(mask_id(to), mask_bits(mask_id(from)));
  }
  void traced(Count) {}      // the replay counts rays
  void unfinished(Count) {}  // likewise
  void pass(const PassKey& key, const vgpu::Program& p, std::initializer_list<const Texture*> in,
            std::initializer_list<Texture*> out, const Stencil* work) {
    Plan& plan = plans_[size_t(key.site)][key.parity];
    if (!plan.info)
      build(plan, p, in.begin(), int(in.size()), out.begin(), int(out.size()), work, nullptr);
    run(key, plan);
  }
  Count count(const PassKey& key, const vgpu::Program& p, const Texture& in, const Stencil* work,
              Stencil* write) {
    Plan& plan = plans_[size_t(key.site)][key.parity];
    if (!plan.info) {
      const Texture* input = &in;
      build(plan, p, &input, 1, nullptr, 0, work, write);
    }
    return run(key, plan);
  }

  // The batch's final state into the textures and masks: each ping-pong pair gets the walk's
  // current texel in both textures (a pass-by-pass walk leaves the other one equal to it or
  // one pass older, and no pass reads it before rewriting it whole).
  struct Pair {
    const Texture* t[2];
    float* data[2];
  };
  struct MaskOut {
    const Stencil* mask;
    uint8_t* bits;
  };
  void finish(const Pair* pairs, const int* current, int npairs, const MaskOut* masks, int nmasks) {
    for (int k = 0; k < npairs; ++k) {
      const vgpu::Slot& v = slots_[size_t(loaded(texture_id(*pairs[k].t[current[k]])))];
      for (int b = 0; b < 2; ++b) v.store(*pairs[k].t[b], pairs[k].data[b], x0_, y_, n_);
    }
    for (int k = 0; k < nmasks; ++k) {
      const uint8_t bits = mask_bits(mask_id(*masks[k].mask));
      uint8_t* row = masks[k].bits + size_t(y_) * size_t(width_) + size_t(x0_);
      for (int i = 0; i < n_; ++i) row[i] = (bits >> i) & 1;
    }
  }

  // The batch counters of the tile (tx, ty) (32x32 pixels) whose batches just ran: per pass of a
  // program with branches, the idle fragments of its 8x4 tiles and of itself holding a
  // fragment that took a branch (what Gpu::draw()'s idle_in_batches subtracts).
  void settle_tile(int tx, int ty) {
    for (const PassKey& key : touched_) {
      Entry& e = entries.at(key);
      TileAcc& a = e.acc;
      uint64_t near8 = 0;
      for (uint32_t m = a.took_tiles; m; m &= m - 1) {
        const int j = std::countr_zero(m);
        const int x = tx * 32 + (j % 4) * 8, y = ty * 32 + (j / 4) * 4;
        near8 += work_masked_
                     ? a.ran_in[size_t(j)]
                     : uint64_t(std::min(8, width_ - x)) * uint64_t(std::min(4, height_ - y));
      }
      e.tally.idle_near_took8x4 += near8 - a.took;
      if (a.took > 0) {
        const uint64_t area =
            uint64_t(std::min(32, width_ - tx * 32)) * uint64_t(std::min(32, height_ - ty * 32));
        e.tally.idle_near_took32x32 += (work_masked_ ? a.ran : area) - a.took;
      }
      a = TileAcc{};
    }
    touched_.clear();
  }

 private:
  static constexpr int kSlots = 16, kMasks = 4;
  // One pass's bindings as slot and mask numbers.
  struct Plan {
    const ProgramInfo* info = nullptr;
    std::array<vgpu::BoundTexture, vgpu::kMaxTextureUnits> units{};  // resident: into a slot
    uint32_t reads = 0;  // slots loaded before the pass runs
    std::array<vgpu::BatchOutput, vgpu::kMaxOutputs> outputs{};
    int nout = 0;
    int work = -1, write = -1;  // mask numbers
  };

  int texture_id(const Texture& t) {
    for (int k = 0; k < ntextures_; ++k)
      if (slots_[size_t(k)].texture == &t) return k;
    if (ntextures_ == kSlots)
      throw vgpu::Error("batch walk: more than " + std::to_string(kSlots) + " textures");
    slots_[size_t(ntextures_)].texture = &t;
    return ntextures_++;
  }
  int mask_id(const Stencil& m) {
    for (int k = 0; k < nmasks_; ++k)
      if (masks_[size_t(k)] == &m) return k;
    if (nmasks_ == kMasks) throw vgpu::Error("batch walk: more than 4 masks");
    masks_[size_t(nmasks_)] = &m;
    return nmasks_++;
  }
  // Slot k holding this batch's texels (loaded from the texture on first use).
  int loaded(int k) {
    if (!((loaded_ >> k) & 1)) {
      slots_[size_t(k)].load(*slots_[size_t(k)].texture, x0_, y_, n_);
      loaded_ |= 1u << k;
    }
    return k;
  }
  uint8_t mask_bits(int k) {
    if (!((masks_loaded_ >> k) & 1)) {
      uint8_t bits = 0;
      const uint8_t* row = masks_[size_t(k)]->row(y_) + x0_;
      for (int i = 0; i < n_; ++i) bits |= uint8_t((row[i] != 0 ? 1u : 0u) << i);
      mask_bits_[size_t(k)] = bits;
      masks_loaded_ |= 1u << k;
    }
    return mask_bits_[size_t(k)];
  }
  void set_mask(int k, uint8_t bits) {
    mask_bits_[size_t(k)] = bits;
    masks_loaded_ |= 1u << k;
  }
  const ProgramInfo& info(const vgpu::Program& p) const {
    for (const ProgramInfo& i : programs_)
      if (i.program == &p) return i;
    throw vgpu::Error(std::string("program '") + p.name() + "' is not part of the batch walk");
  }
  void build(Plan& plan, const vgpu::Program& p, const Texture* const* in, int nin,
             Texture* const* out, int nout, const Stencil* work, const Stencil* write) {
    const ProgramInfo& pi = info(p);
    for (int u = 0; u < nin; ++u) {
      const Texture& t = *in[u];
      float* lanes = nullptr;
      if ((pi.own_only >> u) & 1) {
        const int k = texture_id(t);
        plan.reads |= 1u << k;
        lanes = &slots_[size_t(k)].v[0][0];
      }
      plan.units[size_t(u)] = {t.data().data(), t.width(), t.height(), t.channels(), lanes};
    }
    // A query's counter target is never read: its slot is not kept (nout 0).
    plan.nout = nout;
    for (int o = 0; o < nout; ++o) {
      const int k = texture_id(*out[o]);
      plan.reads |= 1u << k;  // a discarded fragment keeps the target's texel
      plan.outputs[size_t(o)].slot = &slots_[size_t(k)];
      if (!pi.idle_discards) {
        const int src = texture_id(*in[pi.passthrough[size_t(o)]]);
        plan.reads |= 1u << src;
        plan.outputs[size_t(o)].idle_source = &slots_[size_t(src)];
      }
    }
    plan.work = work ? mask_id(*work) : -1;
    plan.write = write ? mask_id(*write) : -1;
    plan.info = &pi;
  }

  Count run(const PassKey& key, const Plan& plan) {
    for (uint32_t need = plan.reads & ~loaded_; need; need &= need - 1)
      loaded(std::countr_zero(need));
    const ProgramInfo& pi = *plan.info;
    const uint8_t live = plan.work >= 0 ? uint8_t(mask_bits(plan.work) & valid_) : valid_;
    const vgpu::BatchRun r = vgpu::run_batch(*pi.program, pi.precision, dynamic_, plan.units.data(),
                                             plan.outputs.data(), plan.nout, live, x0_, y_);
    const uint8_t survivors = uint8_t(live & ~r.killed);
    if (plan.write >= 0)
      set_mask(plan.write, uint8_t((survivors | (pi.idle_discards ? 0 : ~live)) & valid_));
    Entry& e = entries.at(key);
    vgpu::PassTally& t = e.tally;
    const int ran = std::popcount(live);
    t.ran += uint64_t(ran);
    t.killed += uint64_t(std::popcount(r.killed));
    t.lanes_idle += r.lanes_idle;
    t.flagged_idle += uint64_t(std::popcount(r.idle));
    if (pi.branches > 0 && ran > 0) {
      TileAcc& a = e.acc;
      if (!a.touched) {
        a.touched = true;
        touched_.push_back(key);
      }
      const int j = tile8x4_;
      a.ran += uint32_t(ran);
      a.ran_in[size_t(j)] = uint8_t(a.ran_in[size_t(j)] + ran);
      if (r.took) {
        a.took += uint32_t(std::popcount(r.took));
        a.took_tiles |= 1u << j;
      }
    }
    return survivors;
  }

  const std::vector<ProgramInfo>& programs_;
  bool dynamic_, work_masked_;
  int width_, height_;
  int x0_ = 0, y_ = 0, n_ = 0;
  uint8_t valid_ = 0;
  int tile8x4_ = 0;
  std::array<vgpu::Slot, kSlots> slots_;
  int ntextures_ = 0;
  uint32_t loaded_ = 0;
  std::array<const Stencil*, kMasks> masks_{};
  std::array<uint8_t, kMasks> mask_bits_{};
  int nmasks_ = 0;
  uint32_t masks_loaded_ = 0;
  std::array<std::array<Plan, 8>, kSites> plans_;
  std::vector<PassKey> touched_;
};

// Visits every pass site of the walk once (each query says "some" the first time its site asks
// and "none" after), noting every pass's program and bindings.
class CheckWalker {
 public:
  using Count = int;
  static bool any(Count c) { return c > 0; }
  struct Seen {
    const vgpu::Program* program;
    std::vector<const Texture*> in;
    std::vector<const Texture*> out;
  };
  std::vector<Seen> seen;

  void fill(const Stencil&, uint8_t) {}
  void copy(const Stencil&, const Stencil&) {}
  void traced(Count) {}
  void unfinished(Count) {}
  void pass(const PassKey&, const vgpu::Program& p, std::initializer_list<const Texture*> in,
            std::initializer_list<Texture*> out, const Stencil*) {
    seen.push_back({&p, {in.begin(), in.end()}, {out.begin(), out.end()}});
  }
  Count count(const PassKey& key, const vgpu::Program& p, const Texture& in, const Stencil*,
              Stencil*) {
    seen.push_back({&p, {&in}, {}});
    return asked_[size_t(key.site)]++ == 0 ? 1 : 0;
  }

 private:
  std::array<int, kSites> asked_{};
};

}  // namespace

// Where the walk is: the rays it traces and the current texture of each ping-pong pair.
struct StreamTracer::Cursor {
  Texture *origins, *rays;
  int trav, vs, isect;
};

// The walk on the device, pass by pass; with `replay`, each pass charges what a batch walk
// tallied for it instead of running (the device is then the vgpu).
struct StreamTracer::DeviceWalker {
  StreamTracer& t;
  Keyed<vgpu::PassTally>* replay = nullptr;
  using Count = uint64_t;
  static bool any(Count n) { return n > 0; }
  // The masks: as the walk changes them, or left as the batch walk finished them.
  void fill(Stencil& m, uint8_t v) {
    if (!replay) m.fill(v);
  }
  void copy(Stencil& to, const Stencil& from) {
    if (!replay) to = from;
  }
  void traced(Count n) { t.s_->rays_traced += n; }
  void unfinished(Count n) { t.s_->rays_unfinished += n; }
  void arm(const PassKey& key) {
    if (replay) static_cast<vgpu::Gpu&>(*t.gpu_).replay_next(replay->at(key));
  }
  void pass(const PassKey& key, const vgpu::Program& p, std::initializer_list<const Texture*> in,
            std::initializer_list<Texture*> out, const Stencil* work) {
    arm(key);
    t.pass(p, in, out, work);
  }
  Count count(const PassKey& key, const vgpu::Program& p, const Texture& in, const Stencil* work,
              Stencil* write) {
    arm(key);
    return t.count(p, in, work, write);
  }
};

bool StreamTracer::walk_in_batches(Cursor& c) {
  auto* gpu = dynamic_cast<vgpu::Gpu*>(gpu_.get());
  if (!opt_.batch_walk || !gpu || gpu->lanes() != vgpu::kBatchWidth || opt_.observer ||
      opt_.trace_pixel || !(opt_.masks || opt_.host_shortcut))
    return false;
  State& s = *s_;
  const auto t0 = std::chrono::steady_clock::now();
  // The walk's passes and bindings: a batch keeps a texture in registers where every program
  // reads it at the fragment's own texel; a texture the walk writes must be read so everywhere.
  CheckWalker check;
  {
    Cursor probe = c;
    walk_multipass(check, probe);
  }
  std::vector<ProgramInfo> programs;
  std::vector<const Texture*> written;
  for (const CheckWalker::Seen& p : check.seen)
    for (const Texture* t : p.out) written.push_back(t);
  for (const CheckWalker::Seen& p : check.seen) {
    auto it = std::find_if(programs.begin(), programs.end(),
                           [&](const ProgramInfo& i) { return i.program == p.program; });
    if (it == programs.end()) {
      ProgramInfo i;
      i.program = p.program;
      i.precision = gpu->precision_of(*p.program);
      const vgpu::Program::Analysis a = p.program->analyze();
      if (a.loop.loops > 0) return false;
      i.branches = a.branches;
      i.idle_discards = p.program->idle_discards();
      if (!i.idle_discards && !p.program->has_passthrough()) return false;
      for (int o = 0; o < p.program->outputs(); ++o)
        i.passthrough[size_t(o)] = i.idle_discards ? -1 : p.program->passthrough(o);
      auto cached = std::find_if(s.own_only.begin(), s.own_only.end(),
                                 [&](const auto& e) { return e.first == p.program; });
      if (cached == s.own_only.end()) {
        s.own_only.emplace_back(p.program, own_only_units(*p.program));
        cached = s.own_only.end() - 1;
      }
      i.own_only = cached->second;
      programs.push_back(i);
      it = programs.end() - 1;
    }
    for (size_t u = 0; u < p.in.size(); ++u) {
      const Texture& t = *p.in[u];
      const bool sized = t.width() == opt_.width && t.height() == opt_.height;
      const bool own = (it->own_only >> u) & 1;
      if (own && !sized) return false;
      if (!own && std::find(written.begin(), written.end(), &t) != written.end()) return false;
    }
    if (!it->idle_discards)
      for (size_t o = 0; o < p.out.size(); ++o) {
        const size_t u = size_t(it->passthrough[o]);
        if (u >= p.in.size() || !((it->own_only >> u) & 1)) return false;
      }
  }

  // The batches, 32x32 pixel tiles at a time (the batch counters' largest tile), over the
  // threads; every batch writes only its own pixels' texels.
  BatchWalker::Pair pairs[3] = {
      {{&s.trav[0], &s.trav[1]}, {}}, {{&s.vs[0], &s.vs[1]}, {}}, {{&s.isect[0], &s.isect[1]}, {}}};
  for (BatchWalker::Pair& p : pairs)
    for (int b = 0; b < 2; ++b) p.data[b] = const_cast<Texture*>(p.t[b])->texel_mut(0, 0);
  const BatchWalker::MaskOut masks[2] = {{&s.grid_mask, s.grid_mask.row_mut(0)},
                                         {&s.isect_mask, s.isect_mask.row_mut(0)}};
  std::vector<std::unique_ptr<BatchWalker>> walkers;
  for (int k = 0; k < gpu->threads(); ++k)
    walkers.push_back(
        std::make_unique<BatchWalker>(*gpu, programs, opt_.masks, opt_.width, opt_.height));
  const int W = opt_.width, H = opt_.height, tiles_x = (W + 31) / 32, tiles_y = (H + 31) / 32;
  // An error on a worker thread (a binding the check let through) reaches the caller.
  std::mutex failed_mu;
  std::exception_ptr failed;
  gpu->parallel_for(tiles_x * tiles_y, [&](int tile, int slot) {
    try {
      BatchWalker& x = *walkers[size_t(slot)];
      const int tx = tile % tiles_x, ty = tile / tiles_x;
      for (int y = ty * 32; y < std::min(H, ty * 32 + 32); ++y)
        for (int x0 = tx * 32; x0 < std::min(W, tx * 32 + 32); x0 += vgpu::kBatchWidth) {
          x.begin(x0, y, std::min(vgpu::kBatchWidth, W - x0));
          Cursor b = c;
          walk_multipass(x, b);
          const int current[3] = {b.trav, b.vs, b.isect};
          x.finish(pairs, current, 3, masks, 2);
        }
      x.settle_tile(tx, ty);
    } catch (...) {
      const std::lock_guard lk(failed_mu);
      if (!failed) failed = std::current_exception();
    }
  });
  if (failed) std::rethrow_exception(failed);
  Keyed<vgpu::PassTally> tallies;
  uint64_t ran = 0;
  for (auto& w : walkers)
    w->entries.for_each([&](const PassKey& key, const BatchWalker::Entry& e) {
      tallies.at(key) += e.tally;
      ran += e.tally.ran;
    });
  // The walk's host time, shared out by the fragments each pass ran.
  const double ms = ms_since(t0);
  tallies.for_each([&](const PassKey&, vgpu::PassTally& t) {
    t.host_ms = ran ? ms * double(t.ran) / double(ran) : 0.0;
  });
  // The same walk on the device, each pass charged from its tally: the statistics, the program
  // loads and the query read-backs come out as a pass-by-pass walk's.
  DeviceWalker replay{*this, &tallies};
  walk_multipass(replay, c);
  s.batch_walk = true;
  return true;
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
  if (opt_.looping) {
    s.grid_mask.fill(1);
    const uint64_t walking = count(s.in_grid, s.trav[s.cur_trav], nullptr, &s.grid_mask);
    s.rays_traced += walking;
    walk_looping(origins, rays, walking);
    return;
  }
  Cursor c{&origins, &rays, s.cur_trav, s.cur_vs, s.cur_isect};
  if (!walk_in_batches(c)) {
    DeviceWalker x{*this};
    walk_multipass(x, c);
  }
  s.cur_trav = c.trav;
  s.cur_vs = c.vs;
  s.cur_isect = c.isect;
}

template <class X>
void StreamTracer::walk_multipass(X& x, Cursor& c) {
  State& s = *s_;
  Texture &origins = *c.origins, &rays = *c.rays;
  auto key = [&c](int step, int k, Site site) {
    return PassKey{step, k, site, uint8_t(c.trav | c.vs << 1 | c.isect << 2)};
  };
  x.fill(s.grid_mask, 1);
  auto walking = x.count(key(-1, -1, kEnter), s.in_grid, s.trav[c.trav], nullptr, &s.grid_mask);
  x.traced(walking);
  // In exact arithmetic a ray crosses at most nx+ny+nz voxels and tests each voxel's list once.
  // Reduced precision can break both (fp16 cannot count past 2048): the host stops there and
  // reports the rays left unfinished instead of looping forever.
  const int max_steps = grid_.res.x + grid_.res.y + grid_.res.z + 2;
  for (int step = 0; X::any(walking); ++step) {
    if (step == max_steps) {
      x.unfinished(walking);
      break;
    }
    // The first triangle of each ray's new voxel (under --mrt on, only at the first step: later
    // ones come from the fused traversal + update voxel pass).
    if (!opt_.mrt || step == 0) {
      x.pass(key(step, -1, kUpdate), s.update,
             {&s.trav[c.trav], &s.vs[c.vs], &s.pointers, &s.lists}, {&s.vs[c.vs ^ 1]},
             &s.grid_mask);
      c.vs ^= 1;
    }
    x.copy(s.isect_mask, s.grid_mask);
    auto testing =
        x.count(key(step, -1, kTesting), s.intersecting, s.vs[c.vs], &s.grid_mask, &s.isect_mask);
    // One triangle per pass, until no ray has a triangle left in its voxel.
    for (int k = 0; X::any(testing); ++k) {
      if (k == s.max_list + 1) break;  // lists cannot be longer: stuck positions (fp16)
      if (opt_.mrt) {
        // intersecciones + proximoTriangulo in one pass, two targets.
        x.pass(key(step, k, kIntersectNext), s.intersect_next,
               {&origins, &rays, &s.trav[c.trav], &s.vs[c.vs], &s.isect[c.isect], &s.v[0], &s.v[1],
                &s.v[2], &s.lists},
               {&s.isect[c.isect ^ 1], &s.vs[c.vs ^ 1]}, &s.isect_mask);
        c.isect ^= 1;
        c.vs ^= 1;
      } else {
        x.pass(key(step, k, kIntersect), s.intersect,
               {&origins, &rays, &s.trav[c.trav], &s.vs[c.vs], &s.isect[c.isect], &s.v[0], &s.v[1],
                &s.v[2]},
               {&s.isect[c.isect ^ 1]}, &s.isect_mask);
        c.isect ^= 1;
        x.pass(key(step, k, kNext), s.next, {&s.vs[c.vs], &s.lists}, {&s.vs[c.vs ^ 1]},
               &s.isect_mask);
        c.vs ^= 1;
      }
      testing = x.count(key(step, k, kTestingOn), s.intersecting, s.vs[c.vs], &s.isect_mask,
                        &s.isect_mask);
    }
    // One voxel step for every ray still walking (under --mrt on, with the next voxel's first
    // triangle in the same pass).
    if (opt_.mrt) {
      x.pass(
          key(step, -1, kTraverseUpdate), s.traverse_update,
          {&origins, &rays, &s.trav[c.trav], &s.isect[c.isect], &s.vs[c.vs], &s.pointers, &s.lists},
          {&s.trav[c.trav ^ 1], &s.vs[c.vs ^ 1]}, &s.grid_mask);
      c.trav ^= 1;
      c.vs ^= 1;
    } else {
      x.pass(key(step, -1, kTraversal), s.traversal,
             {&origins, &rays, &s.trav[c.trav], &s.isect[c.isect]}, {&s.trav[c.trav ^ 1]},
             &s.grid_mask);
      c.trav ^= 1;
    }
    walking =
        x.count(key(step, -1, kInGrid), s.in_grid, s.trav[c.trav], &s.grid_mask, &s.grid_mask);
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
  s.batch_walk = false;
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
  res.batch_walk = s.batch_walk;
  res.render_ms = ms_since(t0);
  return res;
}

}  // namespace host
