// The two-level grid walk (host/trace/grid2_walk.h): its textures, its pass sequence (multipass
// and looping) and the walkers instantiated for it.
#include "host/trace/grid2_walk.h"

#include <algorithm>
#include <tuple>

#include "host/trace/grid_walk.h"  // kSlackOfDiagonal
#include "host/trace/walk.h"

namespace host {

using namespace kernels;
using vgpu::Format;
using vgpu::Stencil;
using vgpu::Texture;

Grid2Walk::Grid2Walk(vgpu::Device& gpu, const Grid2& g2, const RenderOptions& options,
                     float scene_width, float t_slack)
    : opt_(options) {
  const Formats& fm = opt_.formats;
  for (auto [prog, g] :
       std::initializer_list<std::pair<vgpu::Program*, Group>>{{&enter_, Group::traversal},
                                                               {&step_, Group::traversal},
                                                               {&load_, Group::voxel},
                                                               {&next_, Group::voxel},
                                                               {&intersecting_, Group::queries},
                                                               {&walking_, Group::queries},
                                                               {&intersect_, Group::hits}})
    prog->set_precision(fm.arithmetic(g));
  step_load_.set_precision(fm.arithmetic(Group::traversal));
  intersect_next_.set_precision(fm.arithmetic(Group::hits));
  Format loop_arith = fm.arithmetic(Group::traversal);
  for (Group g : {Group::voxel, Group::hits})
    if (vgpu::significand_bits(fm.arithmetic(g)) > vgpu::significand_bits(loop_arith))
      loop_arith = fm.arithmetic(g);
  looping_.set_precision(loop_arith);
  set_grid(gpu, g2, scene_width, t_slack, nullptr);
}

uint64_t Grid2Walk::set_grid(vgpu::Device& gpu, const Grid2& g2, float scene_width, float t_slack,
                             std::vector<std::string>* uploaded) {
  const Formats& fm = opt_.formats;
  // Cell and sub-cell indices and list positions are texel addresses: refuse a format that
  // cannot hold them (as the kd-tree's walk does), at construction and for each frame's
  // rebuilt structure.
  for (const auto& [count, g, kind] :
       {std::tuple{uint64_t(g2.sub_cells()), Group::traversal, "sub-cell indices"},
        std::tuple{uint64_t(g2.cells()), Group::traversal, "coarse cell indices"},
        std::tuple{uint64_t(g2.lists.size()), Group::traversal, "list positions"},
        std::tuple{uint64_t(g2.lists.size()), Group::voxel, "list positions"}})
    for (const Format f : {fm[g], fm.arithmetic(g)})
      if (count - 1 > exact_addresses(f))
        throw vgpu::Error("two-level grid: " + std::string(kind) + " reach " +
                          std::to_string(count - 1) + "; the " + std::string(group_name(g)) +
                          " group's " + std::string(vgpu::format_name(f)) +
                          " addresses texels exactly only to " +
                          std::to_string(exact_addresses(f)) + " (give it " +
                          (count - 1 > exact_addresses(Format::fp24) ? "fp32" : "fp24 or fp32") +
                          ": --formats " + std::string(group_name(g)) + "=fp32)");
  max_list_ = g2.max_list;
  // A ray crosses at most res.x + res.y + res.z coarse cells, and in each at most the sum of
  // its sub-grid's resolutions.
  int sub_span = 1;
  for (const glm::ivec3& r : g2.sub_res) sub_span = std::max(sub_span, r.x + r.y + r.z);
  const glm::ivec3 cr = g2.coarse.res;
  max_steps_ = int64_t(cr.x + cr.y + cr.z) * int64_t(sub_span) + 1;
  const bool fresh = uploaded == nullptr;
  auto fits = [](const Texture& t, size_t count) {
    return uint64_t(t.width()) * uint64_t(t.height()) >= count;
  };
  // Coarse cell c: (sub-grid resolution x, y, z, first sub-cell); sub-cell k: (list start,
  // coarse cell); lists: triangle ids closed by -1.
  if (fresh || !fits(cells_, g2.cells()))
    cells_ = entry_texture(gpu, "grid2 cells", g2.cells(), 4, "two-level grid coarse cells");
  if (fresh || !fits(subs_, g2.sub_cells()))
    subs_ = entry_texture(gpu, "grid2 sub-cells", g2.sub_cells(), 2, "two-level grid sub-cells");
  if (fresh || !fits(lists_, g2.lists.size()))
    lists_ = entry_texture(gpu, "grid2 lists", g2.lists.size(), 1, "two-level grid lists");
  std::vector<float> cells(cells_.data().begin(), cells_.data().end());
  std::vector<float> subs(subs_.data().begin(), subs_.data().end());
  std::vector<float> entries(lists_.data().begin(), lists_.data().end());
  for (size_t c = 0; c < g2.cells(); ++c) {
    float* t = cells.data() + 4 * c;
    t[0] = float(g2.sub_res[c].x);
    t[1] = float(g2.sub_res[c].y);
    t[2] = float(g2.sub_res[c].z);
    t[3] = float(g2.first[c]);
  }
  for (size_t k = 0; k < g2.sub_cells(); ++k) {
    subs[2 * k] = float(g2.list_start[k]);
    subs[2 * k + 1] = float(g2.cell_of[k]);
  }
  for (size_t k = 0; k < g2.lists.size(); ++k) entries[k] = float(g2.lists[k]);
  uint64_t bytes = 0;
  for (auto [t, texels] :
       {std::pair{&cells_, &cells}, std::pair{&subs_, &subs}, std::pair{&lists_, &entries}})
    if (t->replace(*texels) && uploaded) {
      gpu.upload(*t);
      bytes += t->bytes();
      uploaded->push_back(t->name());
    }

  Grid2Uniforms u;
  u.lo = g2.coarse.lo;
  u.cell = g2.coarse.cell;
  u.res = glm::vec3(g2.coarse.res);
  u.cell_width = float(cells_.width());
  u.sub_width = float(subs_.width());
  u.list_width = float(lists_.width());
  u.t_slack = t_slack;
  KdUniforms lists_kd;  // interseccionesKd's test reads only these two
  lists_kd.list_width = u.list_width;
  lists_kd.t_slack = t_slack;
  BvhUniforms lists_only;
  lists_only.list_width = u.list_width;
  GridUniforms lists;
  lists.list_width = u.list_width;
  const SceneUniforms su{scene_width};
  enter_.kernel.grid2 = u;
  step_.kernel.grid2 = u;
  load_.kernel.bvh = lists_only;
  intersect_.kernel.kd = lists_kd;
  intersect_.kernel.scene = su;
  next_.kernel.grid = lists;
  step_load_.kernel.grid2 = u;
  intersect_next_.kernel.kd = lists_kd;
  intersect_next_.kernel.scene = su;
  looping_.kernel.grid2 = u;
  looping_.kernel.scene = su;
  looping_.kernel.steps = opt_.steps_per_pass;
  return bytes;
}

uint64_t Grid2Walk::rebuild(vgpu::Device& gpu, const Accel& accel, float scene_width,
                            std::vector<std::string>& uploaded) {
  const float t_slack = float(kSlackOfDiagonal) * glm::length(accel.grid->hi - accel.grid->lo);
  return set_grid(gpu, *accel.grid2, scene_width, t_slack, &uploaded);
}

uint64_t Grid2Walk::static_bytes() const {
  return cells_.bytes() + subs_.bytes() + lists_.bytes();
}

void Grid2Walk::make_state(vgpu::Device& gpu, const WalkShared& shared) {
  sh_ = shared;
  const Formats& fm = opt_.formats;
  for (int i = 0; i < 2; ++i) {
    const std::string sfx = i ? " B" : " A";
    trav_[i] =
        gpu.make_texture("grid2 traversal" + sfx, opt_.width, opt_.height, 4, fm[Group::traversal]);
    vs_[i] = gpu.make_texture("cell state" + sfx, opt_.width, opt_.height, 4, fm[Group::voxel]);
  }
}

void Grid2Walk::upload(vgpu::Device& gpu) const {
  gpu.upload(cells_);
  gpu.upload(subs_);
  gpu.upload(lists_);
}

uint64_t Grid2Walk::texture_bytes() const {
  return static_bytes() + trav_[0].bytes() + trav_[1].bytes() + vs_[0].bytes() + vs_[1].bytes();
}

WriteBack Grid2Walk::write_back(const Cursor& c) const {
  WriteBack wb;
  wb.npairs = 3;
  wb.pairs[0] = {const_cast<Texture*>(&trav_[0]), const_cast<Texture*>(&trav_[1])};
  wb.pairs[1] = {const_cast<Texture*>(&vs_[0]), const_cast<Texture*>(&vs_[1])};
  wb.pairs[2] = {sh_.isect[0], sh_.isect[1]};
  wb.current = {c.trav, c.vs, c.isect, 0};
  wb.nmasks = 2;
  wb.masks = {sh_.grid_mask, sh_.isect_mask, nullptr, nullptr};
  return wb;
}

void Grid2Walk::trace(PassRunner& r, Texture& origins, Texture& rays, bool, glm::vec3) {
  vgpu::Device& gpu = r.device();
  int& cur_isect = *sh_.cur_isect;
  gpu.clear(*sh_.isect[cur_isect], {kFar, 0, 0, kNone});
  gpu.clear(vs_[cur_vs_], {0, 0, 0, kNone});
  // Every ray starts in the sub-cell where it enters the box (primary rays' origins hold the
  // eye), that sub-cell's list start in hand.
  r.pass(enter_, {&origins, &rays, &cells_, &subs_}, trav_[cur_trav_ ^ 1]);
  cur_trav_ ^= 1;
  if (opt_.looping) {
    sh_.grid_mask->fill(1);
    const uint64_t walking = r.count(walking_, trav_[cur_trav_], nullptr, sh_.grid_mask);
    r.counts.rays_traced += walking;
    r.pass(load_, {&trav_[cur_trav_], &vs_[cur_vs_], &lists_}, vs_[cur_vs_ ^ 1], sh_.grid_mask);
    cur_vs_ ^= 1;
    walk_looping(r, origins, rays, walking);
    return;
  }
  Cursor c{&origins, &rays, cur_trav_, cur_vs_, cur_isect};
  walk::run_walk(r, *this, c);
  cur_trav_ = c.trav;
  cur_vs_ = c.vs;
  cur_isect = c.isect;
}

template <class X>
void Grid2Walk::walk(X& x, Cursor& c) {
  Texture &origins = *c.origins, &rays = *c.rays;
  Texture* const* isect = sh_.isect;
  const Texture* const* v = sh_.vertices;
  Stencil &grid_mask = *sh_.grid_mask, &isect_mask = *sh_.isect_mask;
  auto key = [&c](int step, int k, Site site) {
    return walk::PassKey{step, k, site, uint8_t(c.trav | c.vs << 1 | c.isect << 2)};
  };
  x.fill(grid_mask, 1);
  auto walking = x.count(key(-1, -1, kEnter), walking_, trav_[c.trav], nullptr, &grid_mask);
  x.traced(walking);
  if (!X::any(walking)) return;
  x.pass(key(-1, -1, kLoadFirst), load_, {&trav_[c.trav], &vs_[c.vs], &lists_}, {&vs_[c.vs ^ 1]},
         &grid_mask);
  c.vs ^= 1;
  for (int64_t step = 0;; ++step) {
    // The triangles of the sub-cell each walking ray stands in, one per pass.
    x.copy(isect_mask, grid_mask);
    auto testing =
        x.count(key(int(step), -1, kTesting), intersecting_, vs_[c.vs], &grid_mask, &isect_mask);
    for (int k = 0; X::any(testing); ++k) {
      if (k == max_list_ + 1) break;  // lists are not longer: stuck positions (fp16)
      if (opt_.mrt) {
        x.pass(key(int(step), k, kIntersectNext), intersect_next_,
               {&origins, &rays, &trav_[c.trav], &vs_[c.vs], isect[c.isect], v[0], v[1], v[2],
                &lists_},
               {isect[c.isect ^ 1], &vs_[c.vs ^ 1]}, &isect_mask);
        c.isect ^= 1;
        c.vs ^= 1;
      } else {
        x.pass(key(int(step), k, kIntersect), intersect_,
               {&origins, &rays, &trav_[c.trav], &vs_[c.vs], isect[c.isect], v[0], v[1], v[2]},
               {isect[c.isect ^ 1]}, &isect_mask);
        c.isect ^= 1;
        x.pass(key(int(step), k, kNext), next_, {&vs_[c.vs], &lists_}, {&vs_[c.vs ^ 1]},
               &isect_mask);
        c.vs ^= 1;
      }
      testing = x.count(key(int(step), k, kTestingOn), intersecting_, vs_[c.vs], &isect_mask,
                        &isect_mask);
    }
    // Then one step to the next sub-cell (done at a hit or out of the box), its list loaded.
    if (opt_.mrt) {
      x.pass(
          key(int(step), -1, kStepLoad), step_load_,
          {&origins, &rays, &trav_[c.trav], isect[c.isect], &vs_[c.vs], &cells_, &subs_, &lists_},
          {&trav_[c.trav ^ 1], &vs_[c.vs ^ 1]}, &grid_mask);
      c.trav ^= 1;
      c.vs ^= 1;
    } else {
      x.pass(key(int(step), -1, kStep), step_,
             {&origins, &rays, &trav_[c.trav], isect[c.isect], &cells_, &subs_},
             {&trav_[c.trav ^ 1]}, &grid_mask);
      c.trav ^= 1;
      x.pass(key(int(step), -1, kLoad), load_, {&trav_[c.trav], &vs_[c.vs], &lists_},
             {&vs_[c.vs ^ 1]}, &grid_mask);
      c.vs ^= 1;
    }
    walking =
        x.count(key(int(step), -1, kWalking), walking_, trav_[c.trav], &grid_mask, &grid_mask);
    if (!X::any(walking)) break;
    if (step + 1 == max_steps_) {  // no ray visits more sub-cells: stuck positions (fp16)
      x.unfinished(walking);
      break;
    }
  }
}

void Grid2Walk::walk_looping(PassRunner& r, Texture& origins, Texture& rays, uint64_t walking) {
  vgpu::Device& gpu = r.device();
  const vgpu::Program& p = looping_;
  int& cur_isect = *sh_.cur_isect;
  // Per sub-cell visited: one step and its triangles.
  const int64_t max_iterations = max_steps_ * int64_t(max_list_ + 1);
  const int64_t max_passes = (max_iterations + opt_.steps_per_pass - 1) / opt_.steps_per_pass;
  for (int64_t k = 0; walking > 0; ++k) {
    if (k == max_passes) {
      r.counts.rays_unfinished += walking;
      break;
    }
    Texture& trav = trav_[cur_trav_ ^ 1];
    gpu.use_program(p);
    gpu.unbind_textures();
    int unit = 0;
    for (const Texture* t : std::initializer_list<const Texture*>{
             &origins, &rays, &trav_[cur_trav_], &vs_[cur_vs_], sh_.isect[cur_isect],
             sh_.vertices[0], sh_.vertices[1], sh_.vertices[2], &cells_, &subs_, &lists_})
      gpu.bind_texture(unit++, *t);
    gpu.set_targets({&trav, &vs_[cur_vs_ ^ 1], sh_.isect[cur_isect ^ 1]});
    r.set_work(sh_.grid_mask);
    const bool traced = r.traces_pixel(sh_.grid_mask);
    if (opt_.observer) opt_.observer->pass_begin(sh_.grid_mask);
    const vgpu::PassRecord& rec = gpu.draw();
    if (opt_.observer) opt_.observer->pass({p, rec, trav, gpu.branch_flags(), gpu.stats()});
    cur_trav_ ^= 1;
    cur_vs_ ^= 1;
    cur_isect ^= 1;
    if (traced) r.trace_targets(p, {&trav_[cur_trav_], &vs_[cur_vs_], sh_.isect[cur_isect]});
    walking = r.count(walking_, trav_[cur_trav_], sh_.grid_mask, sh_.grid_mask);
  }
}

}  // namespace host
