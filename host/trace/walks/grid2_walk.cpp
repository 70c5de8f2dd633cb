// The two-level grid walk (host/trace/walks/grid2_walk.h): its textures, its pass sequence
// (multipass and looping, on the parts every walk shares: ListWalk, host/trace/walks/accel_walk.h)
// and the walkers instantiated for it.
#include "host/trace/walks/grid2_walk.h"

#include <algorithm>

#include "host/trace/diagonal.h"
#include "host/trace/walks/grid_walk.h"  // kSlackOfDiagonal
#include "host/trace/walks/walk.h"

namespace host {

using namespace kernels;
using vgpu::Format;
using vgpu::Stencil;
using vgpu::Texture;

Grid2Walk::Grid2Walk(vgpu::Device& gpu, const Grid2& g2, const RenderOptions& options,
                     float scene_width, float t_slack)
    : ListWalk(options, {&cells_, &subs_, &lists_}) {
  compute_in_groups(enter_, step_, step_load_, load_, intersect_, intersect_next_, looping_);
  if (opt_.beams) {
    beams_ = std::make_unique<GridBeams>(opt_);
    compute_in({{&beam_enter_, Group::traversal}});
  }
  set_grid(gpu, g2, scene_width, t_slack, nullptr);
  if (beams_) statics_.push_back(&beams_->distances());
}

uint64_t Grid2Walk::set_grid(vgpu::Device& gpu, const Grid2& g2, float scene_width, float t_slack,
                             std::vector<std::string>* uploaded) {
  // Cell and sub-cell indices and list positions are texel addresses (as the kd-tree's are):
  // linear, or the sub-cells' and lists' by (x, y) where a linear index would pass what its
  // group's format holds exactly. Coarse cells stay linear (a sub-cell's texel names its cell).
  const std::initializer_list<AddressUse> linear{
      {g2.sub_cells(), Group::traversal, "sub-cell indices"},
      {g2.cells(), Group::traversal, "coarse cell indices"},
      {g2.lists.size(), Group::traversal, "list positions"},
      {g2.lists.size(), Group::voxel, "list positions"}};
  xy_ = host::addresses_by_xy(opt_, linear);
  if (!xy_) check_addresses(opt_.formats, "two-level grid", linear);
  if (xy_) {
    check_addresses(opt_.formats, "two-level grid",
                    {{g2.cells(), Group::traversal, "coarse cell indices"}});
    if (beams_)
      throw vgpu::LimitError("two-level grid: " + std::to_string(g2.sub_cells()) +
                             " sub-cells and " + std::to_string(g2.lists.size()) +
                             " list positions, addressed by (x, y); beams over tiles enter "
                             "sub-cells by linear index (--beams off)");
    for (const glm::ivec3& r : g2.sub_res)
      if (r.x >= int(kGrid2ResPack) || r.y >= int(kGrid2ResPack))
        throw vgpu::LimitError("two-level grid: a sub-grid of " + std::to_string(r.x) + "x" +
                               std::to_string(r.y) + " cells; (x, y) addressing packs at most " +
                               std::to_string(int(kGrid2ResPack) - 1) + " per axis");
  }
  max_list_ = g2.max_list;
  // A ray crosses at most res.x + res.y + res.z coarse cells, and in each at most the sum of
  // its sub-grid's resolutions.
  int sub_span = 1;
  for (const glm::ivec3& r : g2.sub_res) sub_span = std::max(sub_span, r.x + r.y + r.z);
  const glm::ivec3 cr = g2.coarse.res;
  max_steps_ = int64_t(cr.x + cr.y + cr.z) * int64_t(sub_span) + 1;
  const bool fresh = uploaded == nullptr;
  // Coarse cell c: (sub-grid resolution x, y, z, first sub-cell); sub-cell k: (list start,
  // coarse cell); lists: triangle ids closed by -1.
  // By (x, y) a sub-cell's texel holds its list start's column and row, then its coarse cell.
  const int sub_channels = xy_ ? 3 : 2;
  const bool made_cells = fresh || !holds(cells_, g2.cells());
  if (made_cells)
    cells_ = entry_texture(gpu, "grid2 cells", g2.cells(), 4, "two-level grid coarse cells");
  const bool made_subs = fresh || !holds(subs_, g2.sub_cells()) || subs_.channels() != sub_channels;
  if (made_subs)
    subs_ = entry_texture(gpu, "grid2 sub-cells", g2.sub_cells(), sub_channels,
                          "two-level grid sub-cells", xy_);
  const bool made_lists = fresh || !holds(lists_, g2.lists.size());
  if (made_lists)
    lists_ = entry_texture(gpu, "grid2 lists", g2.lists.size(), 1, "two-level grid lists", xy_);
  const int sw = subs_.width(), lw = lists_.width();
  // By (x, y) the traversal state holds a sub-cell's column and row, the cell state a list
  // position's.
  // The step also carries list columns and rows (the fused and looping kernels), a sub-cell's
  // offset in its sub-grid and the packed sub-grid resolution, in traversal arithmetic.
  uint64_t packed = 1, offsets = 1;
  for (const glm::ivec3& r : g2.sub_res) {
    packed = std::max<uint64_t>(packed, uint64_t(r.x) + uint64_t(kGrid2ResPack) * uint64_t(r.y));
    offsets = std::max<uint64_t>(offsets, uint64_t(r.x) * uint64_t(r.y) * uint64_t(r.z));
  }
  if (xy_)
    check_addresses(opt_.formats, "two-level grid",
                    {{uint64_t(sw), Group::traversal, "sub-cell columns"},
                     {uint64_t(subs_.height()), Group::traversal, "sub-cell rows"},
                     {uint64_t(lw), Group::voxel, "list columns"},
                     {uint64_t(lists_.height()), Group::voxel, "list rows"},
                     {uint64_t(lw), Group::traversal, "list columns"},
                     {uint64_t(lists_.height()), Group::traversal, "list rows"},
                     {offsets, Group::traversal, "sub-cell offsets in a sub-grid"},
                     {packed + 1, Group::traversal, "packed sub-grid resolutions"}},
                    "no format addresses more");
  load_reads_ = xy_ ? &subs_ : nullptr;
  StaticTexels cells(cells_, made_cells), subs(subs_, made_subs), entries(lists_, made_lists);
  for (size_t c = 0; c < g2.cells(); ++c) {
    float* t = &cells[4 * c];
    if (xy_) {
      t[0] = float(g2.sub_res[c].x) + kGrid2ResPack * float(g2.sub_res[c].y);
      t[1] = float(g2.sub_res[c].z);
      t[2] = float(g2.first[c] % uint32_t(sw));
      t[3] = float(g2.first[c] / uint32_t(sw));
    } else {
      t[0] = float(g2.sub_res[c].x);
      t[1] = float(g2.sub_res[c].y);
      t[2] = float(g2.sub_res[c].z);
      t[3] = float(g2.first[c]);
    }
  }
  for (size_t k = 0; k < g2.sub_cells(); ++k) {
    float* t = &subs[size_t(sub_channels) * k];
    if (xy_) {
      t[0] = float(g2.list_start[k] % lw);
      t[1] = float(g2.list_start[k] / lw);
      t[2] = float(g2.cell_of[k]);
    } else {
      t[0] = float(g2.list_start[k]);
      t[1] = float(g2.cell_of[k]);
    }
  }
  for (size_t k = 0; k < g2.lists.size(); ++k) entries[k] = float(g2.lists[k]);
  const uint64_t bytes = replace_texels(gpu, {&cells, &subs, &entries}, uploaded);

  Grid2Uniforms u;
  u.lo = g2.coarse.lo;
  u.cell = g2.coarse.cell;
  u.res = glm::vec3(g2.coarse.res);
  u.cell_width = float(cells_.width());
  u.sub_width = float(subs_.width());
  u.list_width = float(lists_.width());
  u.t_slack = t_slack;
  u.xy = xy_ ? 1.0f : 0.0f;
  const SceneUniforms su{scene_width};
  enter_.kernel.grid2 = u;
  step_.kernel.grid2 = u;
  load_.kernel.grid2 = u;
  intersect_.kernel.grid2 = u;
  intersect_.kernel.scene = su;
  next_.kernel.lists = u;
  step_load_.kernel.grid2 = u;
  intersect_next_.kernel.grid2 = u;
  intersect_next_.kernel.scene = su;
  looping_.kernel.grid2 = u;
  looping_.kernel.scene = su;
  looping_.kernel.steps = opt_.steps_per_pass;
  if (!beams_) return bytes;
  // The beams march over the coarse grid (its beam distances, kernels/beams.h).
  beam_enter_.kernel.grid2 = u;
  GridUniforms coarse;
  coarse.lo = u.lo;
  coarse.cell = u.cell;
  coarse.res = u.res;
  return bytes + beams_->set_grid(gpu, g2.coarse, coarse, uploaded);
}

uint64_t Grid2Walk::rebuild(vgpu::Device& gpu, const Accel& accel, float scene_width,
                            std::vector<std::string>& uploaded) {
  const float t_slack = float(kSlackOfDiagonal) * glm::length(accel.box().hi - accel.box().lo);
  return set_grid(gpu, *accel.grid2(), scene_width, t_slack, &uploaded);
}

void Grid2Walk::make_state(vgpu::Device& gpu, const WalkShared& shared) {
  make_pairs(gpu, shared, "grid2 traversal", "cell state");
  if (beams_) beams_->make_state(gpu);
}

void Grid2Walk::trace(PassRunner& r, Texture& origins, Texture& rays, bool primary, glm::vec3 eye) {
  clear(r.device());
  // Every ray starts in the sub-cell where it enters the box (primary rays' origins hold the
  // eye), that sub-cell's list start in hand; with beams, a primary ray in the sub-cell its walk
  // reaches where its tile's beam stopped.
  if (primary && beams_) {
    Texture& beams = beams_->march(r, eye);
    beam_enter_.kernel.beams = beams_->uniforms();
    r.pass(beam_enter_, {&origins, &rays, &beams, &cells_, &subs_}, trav_.next());
  } else {
    r.pass(enter_, {&origins, &rays, &cells_, &subs_}, trav_.next());
  }
  trav_.swap();
  if (opt_.looping) {
    const uint64_t walking = count_entered(r);
    if (xy_)  // by (x, y) the list start is read from the sub-cell's texel
      r.pass(load_, {&trav_.current(), &vs_.current(), &lists_, &subs_}, vs_.next(), sh_.grid_mask);
    else
      r.pass(load_, {&trav_.current(), &vs_.current(), &lists_}, vs_.next(), sh_.grid_mask);
    vs_.swap();
    // Per sub-cell visited: one step and its triangles.
    walk_looping(r, looping_, origins, rays, {&cells_, &subs_, &lists_},
                 max_steps_ * int64_t(max_list_ + 1), walking);
    return;
  }
  Cursor c = cursor(origins, rays);
  walk::run_walk(r, *this, c);
  settle(c);
}

template <class X>
void Grid2Walk::walk(X& x, Cursor& c) {
  Stencil& grid_mask = *sh_.grid_mask;
  const auto key = walk::keys(c);
  x.fill(grid_mask, 1);
  auto walking = x.count(key(-1, -1, kEnter), walking_, c.trav.current(), nullptr, &grid_mask);
  x.traced(walking);
  if (!X::any(walking)) return;
  if (xy_)  // by (x, y) the list start is read from the sub-cell's texel
    x.pass(key(-1, -1, kLoadFirst), load_, {&c.trav.current(), &c.vs.current(), &lists_, &subs_},
           {&c.vs.next()}, &grid_mask);
  else
    x.pass(key(-1, -1, kLoadFirst), load_, {&c.trav.current(), &c.vs.current(), &lists_},
           {&c.vs.next()}, &grid_mask);
  c.vs.swap();
  for (int64_t step = 0;; ++step) {
    // The triangles of the sub-cell each walking ray stands in, one per pass.
    test_triangles(x, c, key, int(step), {kTesting, kIntersect, kNext, kIntersectNext, kTestingOn},
                   max_list_, intersect_, intersect_next_, lists_, true);
    // Then one step to the next sub-cell (done at a hit or out of the box), its list loaded.
    step_and_load(x, c, key, int(step), {kStep, kLoad, kStepLoad}, step_, load_, step_load_, cells_,
                  &subs_, lists_);
    walking =
        x.count(key(int(step), -1, kWalking), walking_, c.trav.current(), &grid_mask, &grid_mask);
    if (!X::any(walking)) break;
    if (step + 1 == max_steps_) {  // no ray visits more sub-cells: stuck positions (fp16)
      x.unfinished(walking);
      break;
    }
  }
}

}  // namespace host
