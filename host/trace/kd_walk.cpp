// The kd-restart walk (host/trace/kd_walk.h): its textures, its pass sequence (multipass and
// looping) and the walkers instantiated for it.
#include "host/trace/kd_walk.h"

#include <algorithm>
#include <tuple>

#include "host/trace/grid_walk.h"  // kSlackOfDiagonal
#include "host/trace/walk.h"

namespace host {

using namespace kernels;
using vgpu::Format;
using vgpu::Stencil;
using vgpu::Texture;

KdWalk::KdWalk(vgpu::Device& gpu, const KdTree& kd, const RenderOptions& options, float scene_width,
               float t_slack)
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
  set_tree(gpu, kd, scene_width, t_slack, nullptr);
}

uint64_t KdWalk::set_tree(vgpu::Device& gpu, const KdTree& kd, float scene_width, float t_slack,
                          std::vector<std::string>* uploaded) {
  const Formats& fm = opt_.formats;
  // Node indices and list positions are texel addresses: refuse a format that cannot hold them
  // (a walk would stall at an index that no longer counts up, as the grid's does past its cap),
  // at construction and for each frame's rebuilt structure.
  for (const auto& [count, g, kind] :
       {std::tuple{uint64_t(kd.nodes.size()), Group::traversal, "node indices"},
        std::tuple{uint64_t(kd.lists.size()), Group::voxel, "list positions"}})
    for (const Format f : {fm[g], fm.arithmetic(g)})
      if (count - 1 > exact_addresses(f))
        throw vgpu::Error(
            "kd-tree: " + std::string(kind) + " reach " + std::to_string(count - 1) + "; the " +
            std::string(group_name(g)) + " group's " + std::string(vgpu::format_name(f)) +
            " addresses texels exactly only to " + std::to_string(exact_addresses(f)) +
            " (give it fp24 or fp32: --formats " + std::string(group_name(g)) + "=fp32)");
  nodes_ = int(kd.nodes.size());
  max_leaf_ = kd.max_leaf;
  depth_ = kd.depth;
  leaves_ = kd.leaves;
  // Between frames the textures are kept where the new tree fits them (entries past its nodes
  // and lists are never reached: children and list starts point inside, lists end with -1).
  const bool fresh = uploaded == nullptr;
  auto fits = [](const Texture& t, size_t count) {
    return uint64_t(t.width()) * uint64_t(t.height()) >= count;
  };
  // Node i: (split, axis or 3 for a leaf, right child, leaf list start).
  if (fresh || !fits(tree_, kd.nodes.size()))
    tree_ = entry_texture(gpu, "kd nodes", kd.nodes.size(), 4, "kd-tree nodes");
  if (fresh || !fits(lists_, kd.lists.size()))
    lists_ = entry_texture(gpu, "kd lists", kd.lists.size(), 1, "kd-tree lists");
  const int nw = tree_.width(), lw = lists_.width();
  std::vector<float> nodes(tree_.data().begin(), tree_.data().end());
  std::vector<float> entries(lists_.data().begin(), lists_.data().end());
  for (size_t i = 0; i < kd.nodes.size(); ++i) {
    const KdNode& n = kd.nodes[i];
    float* t = nodes.data() + 4 * i;
    t[0] = n.split;
    t[1] = float(n.axis);
    t[2] = float(n.right);
    t[3] = n.axis == 3 ? float(n.leaf) : kNone;
  }
  for (size_t k = 0; k < kd.lists.size(); ++k) entries[k] = float(kd.lists[k]);
  uint64_t bytes = 0;
  for (auto [t, texels] : {std::pair{&tree_, &nodes}, std::pair{&lists_, &entries}})
    if (t->replace(*texels) && uploaded) {
      gpu.upload(*t);
      bytes += t->bytes();
      uploaded->push_back(t->name());
    }

  KdUniforms u;
  u.lo = kd.lo;
  u.hi = kd.hi;
  u.node_width = float(nw);
  u.list_width = float(lw);
  u.t_slack = t_slack;
  BvhUniforms lists_only;
  lists_only.list_width = float(lw);
  GridUniforms lists;
  lists.list_width = float(lw);
  const SceneUniforms su{scene_width};
  enter_.kernel.kd = u;
  step_.kernel.kd = u;
  load_.kernel.bvh = lists_only;
  intersect_.kernel.kd = u;
  intersect_.kernel.scene = su;
  next_.kernel.grid = lists;
  step_load_.kernel.kd = u;
  intersect_next_.kernel.kd = u;
  intersect_next_.kernel.scene = su;
  looping_.kernel.kd = u;
  looping_.kernel.scene = su;
  looping_.kernel.steps = opt_.steps_per_pass;
  return bytes;
}

uint64_t KdWalk::rebuild(vgpu::Device& gpu, const Accel& accel, float scene_width,
                         std::vector<std::string>& uploaded) {
  const float t_slack = float(kSlackOfDiagonal) * glm::length(accel.grid->hi - accel.grid->lo);
  return set_tree(gpu, *accel.kd, scene_width, t_slack, &uploaded);
}

uint64_t KdWalk::static_bytes() const {
  return tree_.bytes() + lists_.bytes();
}

void KdWalk::make_state(vgpu::Device& gpu, const WalkShared& shared) {
  sh_ = shared;
  const Formats& fm = opt_.formats;
  for (int i = 0; i < 2; ++i) {
    const std::string sfx = i ? " B" : " A";
    trav_[i] =
        gpu.make_texture("kd traversal" + sfx, opt_.width, opt_.height, 4, fm[Group::traversal]);
    vs_[i] = gpu.make_texture("leaf state" + sfx, opt_.width, opt_.height, 4, fm[Group::voxel]);
  }
}

void KdWalk::upload(vgpu::Device& gpu) const {
  gpu.upload(tree_);
  gpu.upload(lists_);
}

uint64_t KdWalk::texture_bytes() const {
  return tree_.bytes() + lists_.bytes() + trav_[0].bytes() + trav_[1].bytes() + vs_[0].bytes() +
         vs_[1].bytes();
}

WriteBack KdWalk::write_back(const Cursor& c) const {
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

void KdWalk::trace(PassRunner& r, Texture& origins, Texture& rays, bool, glm::vec3) {
  vgpu::Device& gpu = r.device();
  int& cur_isect = *sh_.cur_isect;
  gpu.clear(*sh_.isect[cur_isect], {kFar, 0, 0, kNone});
  gpu.clear(vs_[cur_vs_], {0, 0, 0, kNone});
  // Every ray starts at the root with its segment inside the scene box (primary rays' origins
  // hold the eye).
  r.pass(enter_, {&origins, &rays}, trav_[cur_trav_ ^ 1]);
  cur_trav_ ^= 1;
  if (opt_.looping) {
    sh_.grid_mask->fill(1);
    const uint64_t walking = r.count(walking_, trav_[cur_trav_], nullptr, sh_.grid_mask);
    r.counts.rays_traced += walking;
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
void KdWalk::walk(X& x, Cursor& c) {
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
  // kd-restart visits each leaf at most once, descending at most depth nodes to it and taking
  // two steps there (reach, then end or restart): past that many steps (reduced precision:
  // fp16 cannot count nodes past 2048) the host stops and reports the rays left unfinished.
  const int max_steps = (depth_ + 2) * (leaves_ + 1);
  for (int step = 0; X::any(walking); ++step) {
    if (step == max_steps) {
      x.unfinished(walking);
      break;
    }
    if (opt_.mrt) {
      x.pass(key(step, -1, kStepLoad), step_load_,
             {&origins, &rays, &trav_[c.trav], isect[c.isect], &vs_[c.vs], &tree_, &lists_},
             {&trav_[c.trav ^ 1], &vs_[c.vs ^ 1]}, &grid_mask);
      c.trav ^= 1;
      c.vs ^= 1;
    } else {
      x.pass(key(step, -1, kStep), step_, {&origins, &rays, &trav_[c.trav], isect[c.isect], &tree_},
             {&trav_[c.trav ^ 1]}, &grid_mask);
      c.trav ^= 1;
      x.pass(key(step, -1, kLoad), load_, {&trav_[c.trav], &vs_[c.vs], &lists_}, {&vs_[c.vs ^ 1]},
             &grid_mask);
      c.vs ^= 1;
    }
    x.copy(isect_mask, grid_mask);
    auto testing =
        x.count(key(step, -1, kTesting), intersecting_, vs_[c.vs], &grid_mask, &isect_mask);
    for (int k = 0; X::any(testing); ++k) {
      if (k == max_leaf_ + 1) break;  // leaves are not longer: stuck positions (fp16)
      if (opt_.mrt) {
        x.pass(key(step, k, kIntersectNext), intersect_next_,
               {&origins, &rays, &trav_[c.trav], &vs_[c.vs], isect[c.isect], v[0], v[1], v[2],
                &lists_},
               {isect[c.isect ^ 1], &vs_[c.vs ^ 1]}, &isect_mask);
        c.isect ^= 1;
        c.vs ^= 1;
      } else {
        x.pass(key(step, k, kIntersect), intersect_,
               {&origins, &rays, &trav_[c.trav], &vs_[c.vs], isect[c.isect], v[0], v[1], v[2]},
               {isect[c.isect ^ 1]}, &isect_mask);
        c.isect ^= 1;
        x.pass(key(step, k, kNext), next_, {&vs_[c.vs], &lists_}, {&vs_[c.vs ^ 1]}, &isect_mask);
        c.vs ^= 1;
      }
      testing =
          x.count(key(step, k, kTestingOn), intersecting_, vs_[c.vs], &isect_mask, &isect_mask);
    }
    walking = x.count(key(step, -1, kWalking), walking_, trav_[c.trav], &grid_mask, &grid_mask);
  }
}

void KdWalk::walk_looping(PassRunner& r, Texture& origins, Texture& rays, uint64_t walking) {
  vgpu::Device& gpu = r.device();
  const vgpu::Program& p = looping_;
  int& cur_isect = *sh_.cur_isect;
  // Per leaf visited: at most depth descents, two steps at the leaf, its triangles.
  const int64_t max_iterations = int64_t(depth_ + 2 + max_leaf_) * int64_t(leaves_ + 1);
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
             sh_.vertices[0], sh_.vertices[1], sh_.vertices[2], &tree_, &lists_})
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
