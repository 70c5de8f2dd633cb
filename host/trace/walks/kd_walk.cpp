// The kd-restart walk (host/trace/walks/kd_walk.h): its textures, its pass sequence
// (multipass and looping, on the parts every walk shares: ListWalk, host/trace/walks/accel_walk.h)
// and the walkers instantiated for it.
#include "host/trace/walks/kd_walk.h"

#include <algorithm>

#include "host/trace/diagonal.h"
#include "host/trace/walks/grid_walk.h"  // kSlackOfDiagonal
#include "host/trace/walks/walk.h"

namespace host {

using namespace kernels;
using vgpu::Format;
using vgpu::Stencil;
using vgpu::Texture;

KdWalk::KdWalk(vgpu::Device& gpu, const KdTree& kd, const RenderOptions& options, float scene_width,
               float t_slack)
    : ListWalk(options, {&tree_, &lists_}) {
  compute_in_groups(enter_, step_, step_load_, load_, intersect_, intersect_next_, looping_);
  if (options.beams) {
    beams_ = std::make_unique<BvhBeams>(options);
    compute_in_groups(beam_enter_, beam_step_, beam_step_load_, load_, intersect_, intersect_next_,
                      beam_looping_);
    statics_.push_back(&boxes_lo_);
    statics_.push_back(&boxes_hi_);
  }
  set_tree(gpu, kd, scene_width, t_slack, nullptr);
}

uint64_t KdWalk::set_tree(vgpu::Device& gpu, const KdTree& kd, float scene_width, float t_slack,
                          std::vector<std::string>* uploaded) {
  // Node indices and list positions are texel addresses: linear, or (x, y) where a linear index
  // would pass what its group's format holds exactly.
  const std::initializer_list<AddressUse> linear{
      {kd.nodes.size(), Group::traversal, "node indices"},
      {kd.lists.size(), Group::voxel, "list positions"}};
  xy_ = host::addresses_by_xy(opt_, linear);
  if (!xy_) check_addresses(opt_.formats, "kd-tree", linear);
  if (xy_ && beams_)
    throw vgpu::LimitError("kd-tree: " + std::to_string(kd.nodes.size()) + " nodes and " +
                           std::to_string(kd.lists.size()) +
                           " list positions, addressed by (x, y); beams over tiles address the "
                           "tree's nodes linearly (--beams off)");
  nodes_ = int(kd.nodes.size());
  max_leaf_ = kd.max_leaf;
  depth_ = kd.depth;
  leaves_ = kd.leaves;
  // Between frames the textures are kept where the new tree fits them (entries past its nodes
  // and lists are never reached: children and list starts point inside, lists end with -1).
  const bool fresh = uploaded == nullptr;
  // Node i: (split, axis or 3 for a leaf, right child, leaf list start).
  const bool made_tree = fresh || !holds(tree_, kd.nodes.size());
  if (made_tree) tree_ = entry_texture(gpu, "kd nodes", kd.nodes.size(), 4, "kd-tree nodes", xy_);
  const bool made_lists = fresh || !holds(lists_, kd.lists.size());
  if (made_lists) lists_ = entry_texture(gpu, "kd lists", kd.lists.size(), 1, "kd-tree lists", xy_);
  const int nw = tree_.width(), lw = lists_.width();
  // By (x, y) the traversal state holds a node's column plus the width once its leaf is
  // reached, and its row; the leaf state a list position's column and row.
  if (xy_)
    check_addresses(opt_.formats, "kd-tree",
                    {{uint64_t(2 * nw), Group::traversal, "node columns (with the reached flag)"},
                     {uint64_t(tree_.height()), Group::traversal, "node rows"},
                     {uint64_t(lw), Group::voxel, "list columns"},
                     {uint64_t(lists_.height()), Group::voxel, "list rows"}},
                    "no format addresses more");
  load_reads_ = xy_ ? &tree_ : nullptr;
  StaticTexels nodes(tree_, made_tree), entries(lists_, made_lists);
  for (size_t i = 0; i < kd.nodes.size(); ++i) {
    const KdNode& n = kd.nodes[i];
    float* t = &nodes[4 * i];
    t[0] = n.split;
    t[1] = float(n.axis);
    if (xy_) {
      // The right child's column and row, or the leaf's list start's.
      const int32_t p = n.axis == 3 ? n.leaf : n.right;
      const int w = n.axis == 3 ? lw : nw;
      t[2] = float(p % w);
      t[3] = float(p / w);
    } else {
      t[2] = float(n.right);
      t[3] = n.axis == 3 ? float(n.leaf) : kNone;
    }
  }
  for (size_t k = 0; k < kd.lists.size(); ++k) entries[k] = float(kd.lists[k]);
  uint64_t bytes = replace_texels(gpu, {&nodes, &entries}, uploaded);
  Bvh boxes;
  if (beams_) {
    // The nodes' boxes for the beams' descent, laid out as the BVH walk lays out its nodes.
    boxes = kd_beam_nodes(kd);
    const bool made = fresh || !holds(boxes_lo_, kd.nodes.size());
    if (made) {
      boxes_lo_ = entry_texture(gpu, "kd boxes lo", kd.nodes.size(), 4, "kd-tree nodes");
      boxes_hi_ = entry_texture(gpu, "kd boxes hi", kd.nodes.size(), 4, "kd-tree nodes");
    }
    StaticTexels lo(boxes_lo_, made), hi(boxes_hi_, made);
    bvh_node_texels(boxes, lo.span(), hi.span());
    bytes += replace_texels(gpu, {&lo, &hi}, uploaded);
  }

  KdUniforms u;
  u.lo = kd.lo;
  u.hi = kd.hi;
  u.node_width = float(nw);
  u.list_width = float(lw);
  u.t_slack = t_slack;
  u.xy = xy_ ? 1.0f : 0.0f;
  const SceneUniforms su{scene_width};
  enter_.kernel.kd = u;
  step_.kernel.kd = u;
  load_.kernel.kd = u;
  intersect_.kernel.kd = u;
  intersect_.kernel.scene = su;
  next_.kernel.lists = u;
  step_load_.kernel.kd = u;
  intersect_next_.kernel.kd = u;
  intersect_next_.kernel.scene = su;
  looping_.kernel.kd = u;
  looping_.kernel.scene = su;
  looping_.kernel.steps = opt_.steps_per_pass;
  if (beams_) {
    const float tile = float(opt_.beam_tile);
    beam_enter_.kernel = enter_.kernel;
    beam_step_.kernel = step_.kernel;
    beam_step_load_.kernel = step_load_.kernel;
    beam_looping_.kernel = looping_.kernel;
    beam_enter_.kernel.beam_tile = beam_step_.kernel.beam_tile = tile;
    beam_step_load_.kernel.beam_tile = beam_looping_.kernel.beam_tile = tile;
    BvhUniforms bu;
    bu.node_width = float(boxes_lo_.width());
    bu.nodes = float(nodes_);
    beams_->set_bvh(boxes, bu);
  }
  return bytes;
}

uint64_t KdWalk::rebuild(vgpu::Device& gpu, const Accel& accel, float scene_width,
                         std::vector<std::string>& uploaded) {
  const float t_slack = float(kSlackOfDiagonal) * glm::length(accel.box().hi - accel.box().lo);
  return set_tree(gpu, *accel.kd(), scene_width, t_slack, &uploaded);
}

void KdWalk::make_state(vgpu::Device& gpu, const WalkShared& shared) {
  make_pairs(gpu, shared, "kd traversal", "leaf state");
  if (beams_) beams_->make_state(gpu);
}

void KdWalk::trace(PassRunner& r, Texture& origins, Texture& rays, bool primary, glm::vec3 eye) {
  clear(r.device());
  // Every ray starts at the root with its segment inside the scene box (primary rays' origins
  // hold the eye); with beams over tiles, a primary ray starts at its tile's node instead, and
  // restarts there.
  const bool beams = primary && beams_;
  if (beams) {
    beams_->descend(r, eye, boxes_lo_, boxes_hi_);
    beam_nodes_ = &beams_->beams();
    r.pass(beam_enter_, {&origins, &rays, beam_nodes_}, trav_.next());
  } else {
    beam_nodes_ = nullptr;
    r.pass(enter_, {&origins, &rays}, trav_.next());
  }
  trav_.swap();
  if (opt_.looping) {
    // Per leaf visited: at most depth descents, two steps at the leaf, its triangles.
    const int64_t most = int64_t(depth_ + 2 + max_leaf_) * int64_t(leaves_ + 1);
    if (beams)
      walk_looping(r, beam_looping_, origins, rays, {&tree_, &lists_, beam_nodes_}, most,
                   count_entered(r));
    else
      walk_looping(r, looping_, origins, rays, {&tree_, &lists_}, most, count_entered(r));
    return;
  }
  Cursor c = cursor(origins, rays);
  walk::run_walk(r, *this, c);
  settle(c);
}

template <class X>
void KdWalk::walk(X& x, Cursor& c) {
  Stencil& grid_mask = *sh_.grid_mask;
  const auto key = walk::keys(c);
  x.fill(grid_mask, 1);
  auto walking = x.count(key(-1, -1, kEnter), walking_, c.trav.current(), nullptr, &grid_mask);
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
    if (beam_nodes_)
      step_and_load(x, c, key, step, {kStep, kLoad, kStepLoad}, beam_step_, load_, beam_step_load_,
                    tree_, nullptr, lists_, beam_nodes_);
    else
      step_and_load(x, c, key, step, {kStep, kLoad, kStepLoad}, step_, load_, step_load_, tree_,
                    nullptr, lists_);
    test_triangles(x, c, key, step, {kTesting, kIntersect, kNext, kIntersectNext, kTestingOn},
                   max_leaf_, intersect_, intersect_next_, lists_, true);
    walking = x.count(key(step, -1, kWalking), walking_, c.trav.current(), &grid_mask, &grid_mask);
  }
}

}  // namespace host
