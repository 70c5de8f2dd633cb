// The stackless BVH walk (host/trace/walks/bvh_walk.h): its textures, its pass sequence
// (multipass and looping, on the parts every walk shares: ListWalk, host/trace/walks/accel_walk.h)
// and the walkers instantiated for it.
#include "host/trace/walks/bvh_walk.h"

#include <algorithm>

#include "host/trace/walks/walk.h"

namespace host {

using namespace kernels;
using vgpu::Format;
using vgpu::Stencil;
using vgpu::Texture;

BvhWalk::BvhWalk(vgpu::Device& gpu, const Bvh& bvh, const RenderOptions& options, float scene_width)
    : ListWalk(options, {&nodes_lo_, &nodes_hi_, &lists_}) {
  compute_in_groups(enter_, step_, step_load_, load_, intersect_, intersect_next_, looping_);
  if (options.beams) beams_ = std::make_unique<BvhBeams>(options);
  set_bvh(gpu, bvh, scene_width, nullptr);
}

uint64_t BvhWalk::set_bvh(vgpu::Device& gpu, const Bvh& bvh, float scene_width,
                          std::vector<std::string>* uploaded) {
  // Node indices and list positions are texel addresses.
  check_addresses(opt_.formats, "bvh",
                  {{bvh.nodes.size(), Group::traversal, "node indices"},
                   {bvh.lists.size(), Group::voxel, "list positions"}},
                  "the BVH addresses linearly; the kd-tree and the two-level grid address by "
                  "(x, y): --accel kdtree or grid2");
  nodes_ = int(bvh.nodes.size());
  max_leaf_ = bvh.max_leaf;
  // Between frames the textures are kept where the new hierarchy fits them (entries past its
  // nodes and lists are never reached: escapes end the walk, lists are closed by -1).
  const bool fresh = uploaded == nullptr;
  const bool made_nodes = fresh || !holds(nodes_lo_, bvh.nodes.size());
  if (made_nodes) {
    nodes_lo_ = entry_texture(gpu, "bvh nodes lo", bvh.nodes.size(), 4, "bvh nodes");
    nodes_hi_ = entry_texture(gpu, "bvh nodes hi", bvh.nodes.size(), 4, "bvh nodes");
  }
  const bool made_lists = fresh || !holds(lists_, bvh.lists.size());
  if (made_lists) lists_ = entry_texture(gpu, "bvh lists", bvh.lists.size(), 1, "bvh lists");
  const int nw = nodes_lo_.width(), lw = lists_.width();
  StaticTexels lo(nodes_lo_, made_nodes), hi(nodes_hi_, made_nodes), entries(lists_, made_lists);
  bvh_node_texels(bvh, lo.span(), hi.span());
  for (size_t k = 0; k < bvh.lists.size(); ++k) entries[k] = float(bvh.lists[k]);
  const uint64_t bytes = replace_texels(gpu, {&lo, &hi, &entries}, uploaded);

  BvhUniforms u;
  u.node_width = float(nw);
  u.nodes = float(nodes_);
  u.list_width = float(lw);
  u.ends = beams_ != nullptr;  // beams over tiles end a ray's walk at its tile node's escape
  const SceneUniforms su{scene_width};
  step_.kernel.bvh = u;
  load_.kernel.bvh = u;
  intersect_.kernel.scene = su;
  next_.kernel.lists = u;
  step_load_.kernel.bvh = u;
  intersect_next_.kernel.bvh = u;
  intersect_next_.kernel.scene = su;
  looping_.kernel.bvh = u;
  looping_.kernel.scene = su;
  looping_.kernel.steps = opt_.steps_per_pass;
  if (beams_) beams_->set_bvh(bvh, u);
  return bytes;
}

uint64_t BvhWalk::rebuild(vgpu::Device& gpu, const Accel& accel, float scene_width,
                          std::vector<std::string>& uploaded) {
  return set_bvh(gpu, *accel.bvh(), scene_width, &uploaded);
}

void BvhWalk::make_state(vgpu::Device& gpu, const WalkShared& shared) {
  make_pairs(gpu, shared, "bvh traversal", "leaf state");
  if (beams_) beams_->make_state(gpu);
}

void BvhWalk::trace(PassRunner& r, Texture& origins, Texture& rays, bool primary, glm::vec3 eye) {
  clear(r.device());
  // Every ray starts at the root (secondary rays, and primary rays without beams); with beams
  // over tiles, a primary ray starts at the node its tile's beam descended to.
  if (primary && beams_)
    beams_->enter(r, rays, eye, nodes_lo_, nodes_hi_, trav_.next());
  else
    r.pass(enter_, {&rays}, trav_.next());
  trav_.swap();
  if (opt_.looping) {
    // A ray iterates once per node and once per triangle of each leaf it enters, plus once to
    // end.
    walk_looping(r, looping_, origins, rays, {&nodes_lo_, &nodes_hi_, &lists_},
                 int64_t(nodes_) * int64_t(max_leaf_ + 1) + 2, count_entered(r));
    return;
  }
  Cursor c = cursor(origins, rays);
  walk::run_walk(r, *this, c);
  settle(c);
}

template <class X>
void BvhWalk::walk(X& x, Cursor& c) {
  Stencil& grid_mask = *sh_.grid_mask;
  const auto key = walk::keys(c);
  x.fill(grid_mask, 1);
  auto walking = x.count(key(-1, -1, kEnter), walking_, c.trav.current(), nullptr, &grid_mask);
  x.traced(walking);
  // The stackless walk visits a node at most once, and takes one more step to end: past that
  // (reduced precision: fp16 cannot count nodes past 2048) the host stops and reports the rays
  // left unfinished.
  const int max_steps = nodes_ + 2;
  for (int step = 0; X::any(walking); ++step) {
    if (step == max_steps) {
      x.unfinished(walking);
      break;
    }
    step_and_load(x, c, key, step, {kStep, kLoad, kStepLoad}, step_, load_, step_load_, nodes_lo_,
                  &nodes_hi_, lists_);
    test_triangles(x, c, key, step, {kTesting, kIntersect, kNext, kIntersectNext, kTestingOn},
                   max_leaf_, intersect_, intersect_next_, lists_, false);
    walking = x.count(key(step, -1, kWalking), walking_, c.trav.current(), &grid_mask, &grid_mask);
  }
}

}  // namespace host
