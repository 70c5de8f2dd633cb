// The table of walks (structures.h), beside host/accel/accel.h's kAccelRows.
#include "host/trace/structures.h"

#include <iterator>

#include "host/trace/cpu/cpu_core.h"
#include "host/trace/walks/bvh_walk.h"
#include "host/trace/walks/grid2_walk.h"
#include "host/trace/walks/grid_walk.h"
#include "host/trace/walks/kd_walk.h"
#include "kernels/kernels.h"

namespace host {

namespace {

using cpu_core::Tracer;
using namespace kernels;
using StreamWalk = std::unique_ptr<AccelWalk>;

constexpr WalkRow kWalkRows[] = {
    {AccelKind::grid,
     [](vgpu::Device& gpu, const Accel& accel, const RenderOptions& opt, float scene_width,
        float) -> StreamWalk {
       return std::make_unique<GridWalk>(gpu, walked(accel.grid(), accel), opt, scene_width);
     },
     {&Tracer::start_grid, &Tracer::trace_grid},
     {false,
      {Traversal::name, TraverseUpdate::name},
      {Intersections::name, IntersectNext::name},
      LoopingTraversal::name}},
    {AccelKind::grid2,
     [](vgpu::Device& gpu, const Accel& accel, const RenderOptions& opt, float scene_width,
        float t_slack) -> StreamWalk {
       return std::make_unique<Grid2Walk>(gpu, walked(accel.grid2(), accel), opt, scene_width,
                                          t_slack);
     },
     {&Tracer::start_grid2, &Tracer::trace_grid2},
     {false,
      {Grid2Step::name, Grid2StepLoad::name},
      {Grid2Intersections::name, Grid2IntersectNext::name},
      Grid2Looping::name}},
    {AccelKind::bvh,
     [](vgpu::Device& gpu, const Accel& accel, const RenderOptions& opt, float scene_width,
        float) -> StreamWalk {
       return std::make_unique<BvhWalk>(gpu, walked(accel.bvh(), accel), opt, scene_width);
     },
     {&Tracer::start_bvh, &Tracer::trace_bvh},
     {true,
      {BvhStep::name, BvhStepLoad::name},
      {BvhIntersections::name, BvhIntersectNext::name},
      BvhLooping::name}},
    {AccelKind::kdtree,
     [](vgpu::Device& gpu, const Accel& accel, const RenderOptions& opt, float scene_width,
        float t_slack) -> StreamWalk {
       return std::make_unique<KdWalk>(gpu, walked(accel.kd(), accel), opt, scene_width, t_slack);
     },
     {&Tracer::start_kd, &Tracer::trace_kd},
     {true,
      {KdStep::name, KdStepLoad::name},
      {KdIntersections::name, KdIntersectNext::name},
      KdLooping::name}},
};

// The two halves of the table list the same kinds in the same order.
constexpr bool same_kinds() {
  if (std::size(kWalkRows) != std::size(kAccelRows)) return false;
  for (size_t i = 0; i < std::size(kWalkRows); ++i)
    if (kWalkRows[i].kind != kAccelRows[i].kind) return false;
  return true;
}
static_assert(same_kinds(),
              "host/trace/structures.cpp's kWalkRows and host/accel/accel.h's kAccelRows must "
              "list the same kinds in the same order");

}  // namespace

std::span<const WalkRow> walk_rows() {
  return kWalkRows;
}

const WalkRow& walk_row(AccelKind kind) {
  for (const WalkRow& row : kWalkRows)
    if (row.kind == kind) return row;
  throw std::logic_error("no row in kWalkRows for acceleration structure kind " +
                         std::to_string(int(kind)));
}

}  // namespace host
