// The paper's walk through the uniform grid (host/trace/walks/grid_walk.h): its textures, its pass
// sequence (multipass and looping, on the parts every walk shares: ListWalk,
// host/trace/walks/accel_walk.h) and the walkers instantiated for it.
#include "host/trace/walks/grid_walk.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "host/trace/diagonal.h"
#include "host/trace/walks/walk.h"

namespace host {

using namespace kernels;
using vgpu::Format;
using vgpu::Stencil;
using vgpu::Texture;

GridWalk::GridWalk(vgpu::Device& gpu, const Grid& grid, const RenderOptions& options,
                   float scene_width)
    : ListWalk(options, {&lists_, &pointers_}) {
  compute_in({{&init_, Group::traversal},
              {&reset_, Group::traversal},
              {&traversal_, Group::traversal},
              {&update_, Group::voxel},
              {&intersect_, Group::hits}});
  // The tracer checked mrt_refusal: both kernels' groups compute alike.
  if (opt_.mrt)
    compute_in({{&intersect_next_, Group::hits}, {&traverse_update_, Group::traversal}});
  looping_.set_precision(looping_arithmetic(opt_.formats));
  if (opt_.beams) beams_ = std::make_unique<GridBeams>(opt_);
  set_grid(gpu, grid, scene_width, nullptr);
  if (beams_) statics_.push_back(&beams_->distances());
}

uint64_t GridWalk::set_grid(vgpu::Device& gpu, const Grid& grid, float scene_width,
                            std::vector<std::string>* uploaded) {
  // The lists, each closed by -1 (entry 0 is the -1 every empty voxel shares), and the voxel
  // pointers at (X*sizeY + Y, Z).
  const int maxs = gpu.profile().max_texture_size;
  const glm::ivec3 r = grid.res;
  res_ = r;
  if (size_t(r.x) * r.y > size_t(maxs) || r.z > maxs)
    throw vgpu::Error("grid " + std::to_string(r.x) + "x" + std::to_string(r.y) + "x" +
                      std::to_string(r.z) + " needs a " + std::to_string(r.x * r.y) + "x" +
                      std::to_string(r.z) + " voxel pointer texture; profile " +
                      gpu.profile().name + " allows " + std::to_string(maxs) + "x" +
                      std::to_string(maxs));
  size_t nonempty = 0;
  max_list_ = 0;
  for (size_t vox = 0; vox < grid.voxels(); ++vox) {
    const uint32_t n = grid.start[vox + 1] - grid.start[vox];
    nonempty += n > 0;
    max_list_ = std::max(max_list_, int(n));
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
  // Between frames the textures are kept where the new grid fits them (the lists' texels past
  // the last list are never read), so a moving scene's frames reuse the device's textures.
  const bool fresh = uploaded == nullptr;
  const bool made_lists = fresh || uint64_t(lists_.width()) * uint64_t(lists_.height()) < list_len;
  if (made_lists) lists_ = gpu.make_texture("triangle lists", lw, int(lh), 1);
  const bool made_pointers = fresh || pointers_.width() != r.x * r.y || pointers_.height() != r.z;
  if (made_pointers) pointers_ = gpu.make_texture("voxel pointers", r.x * r.y, r.z, 1);
  const int width = lists_.width();
  StaticTexels lists(lists_, made_lists), pointers(pointers_, made_pointers);
  // (Every voxel's pointer is written below, 0 for an empty one.)
  size_t k = 0;
  auto put = [&](float value) { lists[k++] = value; };
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
        pointers[size_t(z) * size_t(r.x * r.y) + size_t(x * r.y + y)] = start;
      }
  const uint64_t bytes = replace_texels(gpu, {&lists, &pointers}, uploaded);

  // Uniforms that do not change during a frame.
  GridUniforms g;
  g.lo = grid.lo;
  g.cell = grid.cell;
  g.res = glm::vec3(r);
  g.list_width = float(width);
  const float diag = glm::length(grid.hi - grid.lo);
  g.t_slack = float(kSlackOfDiagonal) * diag;
  const SceneUniforms su{scene_width};
  init_.kernel.grid = g;
  reset_.kernel.grid = g;
  traversal_.kernel.grid = g;
  update_.kernel.grid = g;
  intersect_.kernel.grid = g;
  intersect_.kernel.scene = su;
  next_.kernel.lists = g;
  intersect_next_.kernel.grid = g;
  intersect_next_.kernel.scene = su;
  traverse_update_.kernel.grid = g;
  looping_.kernel.grid = g;
  looping_.kernel.scene = su;
  looping_.kernel.steps = opt_.steps_per_pass;
  if (beams_) return bytes + beams_->set_grid(gpu, grid, g, uploaded);
  return bytes;
}

void GridWalk::make_state(vgpu::Device& gpu, const Shared& shared) {
  make_pairs(gpu, shared, "traversal", "voxel state");
  if (beams_) beams_->make_state(gpu);
}

void GridWalk::trace(PassRunner& r, Texture& origins, Texture& rays, bool primary, glm::vec3 eye) {
  clear(r.device());
  // Enter the grid.
  if (primary && beams_) {
    beams_->enter(r, rays, eye, trav_.next());
  } else if (primary) {
    init_.kernel.eye = eye;
    r.pass(init_, {&rays}, trav_.next());
  } else {
    r.pass(reset_, {&origins, &rays}, trav_.next());
  }
  trav_.swap();
  if (opt_.looping) {
    // A ray iterates once per triangle it tests and once per voxel it steps through: at most
    // (nx + ny + nz + 2) voxels of (longest list + 1) iterations each.
    walk_looping(r, looping_, origins, rays, {&pointers_, &lists_},
                 int64_t(res_.x + res_.y + res_.z + 2) * int64_t(max_list_ + 1), count_entered(r));
    return;
  }
  Cursor c = cursor(origins, rays);
  walk::run_walk(r, *this, c);
  settle(c);
}

template <class X>
void GridWalk::walk(X& x, Cursor& c) {
  Texture &origins = *c.origins, &rays = *c.rays;
  Stencil& grid_mask = *sh_.grid_mask;
  const auto key = walk::keys(c);
  x.fill(grid_mask, 1);
  auto walking = x.count(key(-1, -1, kEnter), walking_, c.trav.current(), nullptr, &grid_mask);
  x.traced(walking);
  // In exact arithmetic a ray crosses at most nx+ny+nz voxels and tests each voxel's list once.
  // Reduced precision can break both (fp16 cannot count past 2048): the host stops there and
  // reports the rays left unfinished instead of looping forever.
  const int max_steps = res_.x + res_.y + res_.z + 2;
  for (int step = 0; X::any(walking); ++step) {
    if (step == max_steps) {
      x.unfinished(walking);
      break;
    }
    // The first triangle of each ray's new voxel (under --mrt on, only at the first step: later
    // ones come from the fused traversal + update voxel pass).
    if (!opt_.mrt || step == 0) {
      x.pass(key(step, -1, kUpdate), update_,
             {&c.trav.current(), &c.vs.current(), &pointers_, &lists_}, {&c.vs.next()}, &grid_mask);
      c.vs.swap();
    }
    // One triangle per pass, until no ray has a triangle left in its voxel.
    test_triangles(x, c, key, step, {kTesting, kIntersect, kNext, kIntersectNext, kTestingOn},
                   max_list_, intersect_, intersect_next_, lists_, true);
    // One voxel step for every ray still walking (under --mrt on, with the next voxel's first
    // triangle in the same pass).
    if (opt_.mrt) {
      x.pass(key(step, -1, kTraverseUpdate), traverse_update_,
             {&origins, &rays, &c.trav.current(), &c.isect.current(), &c.vs.current(), &pointers_,
              &lists_},
             {&c.trav.next(), &c.vs.next()}, &grid_mask);
      c.trav.swap();
      c.vs.swap();
    } else {
      x.pass(key(step, -1, kTraversal), traversal_,
             {&origins, &rays, &c.trav.current(), &c.isect.current()}, {&c.trav.next()},
             &grid_mask);
      c.trav.swap();
    }
    walking = x.count(key(step, -1, kInGrid), walking_, c.trav.current(), &grid_mask, &grid_mask);
  }
}

}  // namespace host
