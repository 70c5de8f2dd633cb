// The one list of every kernel, in the order a frame first runs them: the paper's programs,
// then supersampling's, the fused programs of --mrt on, each acceleration structure's walk,
// glass's ray streams, the dense streams and the beams over tiles; the looping variant's
// programs (--kernels looping) come last.
// `vgpu-rt kernels` lists and prints them (host/cli/commands.cpp), the report embeds their
// GLSL (host/report/report.cpp) and the GL device's tests compile each one (tests/gl). What each
// kernel is, and its paper name: kernels/README.md.
#pragma once

#include <memory>
#include <vector>

#include "kernels/cone_budget.h"
#include "kernels/cones.h"
#include "kernels/kernels.h"
#include "vgpu/program.h"

namespace kernels {

// A list of kernel types, read at compile time.
template <class... K>
struct KernelList {};

// The multipass programs: every pass of a frame runs one of these.
using MultipassKernels = KernelList<
    // The paper's fragment programs (and the shadow-ray extension, rayosSombra).
    GenerateRays, InitTraversal, RaysInGrid, UpdateVoxel, RaysIntersecting, Intersections,
    NextTriangle, Traversal, ReflectionOrigin, ShadowRays, Shader, ReflectedRays,
    ReflectionDirection, ResetTraversal,
    // Supersampling (--spp N): the jittered ray generator, the accumulation and the resolve.
    GenerateSampleRays, AccumulateSamples, ResolveSamples,
    // Adaptive supersampling (--aa adaptive): surface keys, marks, the count of marked pixels.
    KeepHits, MarkPixels, MarkedPixels,
    // Its object-space decision (--aa-criterion object): the cones' keys and depths, their marks.
    KeepCones, KeepReflected, MarkCones,
    // Its budget (--aa-criterion budget): the cones' scores, the count above a value, the cut.
    ScoreCones, ScoredHits, CutScores,
    // Adaptive undersampling (--aa undersample:K): the lattice, the gaps to trace, the fill.
    MarkLattice, MarkGaps, FillGaps,
    // The fused programs of --mrt on (kernels/fused.h), two outputs each.
    IntersectNext, TraverseUpdate,
    // The BVH walk (an extension, kernels/bvh.h): --accel bvh; its fused forms.
    BvhEnter, BvhStep, BvhLoadLeaf, BvhIntersections, BvhStepLoad, BvhIntersectNext,
    // The kd-tree walk (an extension, kernels/kdtree.h): --accel kdtree; its fused forms.
    KdEnter, KdStep, KdLoadLeaf, KdIntersections, KdStepLoad, KdIntersectNext,
    // The two-level grid walk (an extension, kernels/grid2.h): --accel grid2; its fused forms.
    Grid2Enter, Grid2Step, Grid2LoadCell, Grid2Intersections, Grid2StepLoad, Grid2IntersectNext,
    // Glass (an extension, issue 25): the ray streams, their compaction and the gather back.
    SplitRays, ScanStream, CountStream, CompactStream, CopyRows, ShadowGlass, GatherChildren,
    // Sampling that saves time (issue 35): the marked pixels as a dense stream, and back.
    CompactMarks, GenerateDenseRays, AccumulateDense, GatherMarked,
    // Beams over tiles (issue 35, kernels/beams.h): --beams on, one fragment per tile; through
    // the BVH (kernels/bvh_beams.h), the descent to each tile's entry node; through the
    // two-level grid (kernels/grid2_beams.h), the entry at the walk's sub-cell.
    BeamMarch, BeamsMissed, BeamEntry, BvhBeamDescend, BvhBeamsDescending, BvhBeamEnter,
    Grid2BeamEntry>;

// The looping variant (--kernels looping): each structure's whole walk in one program with a
// data-dependent loop (kernels/looping_traversal.h and the structures' headers); with beams
// through a tree, the whole descent in one program (kernels/bvh_beams.h); through a grid, the
// whole march (kernels/beams.h).
using LoopingKernels = KernelList<LoopingTraversal, BvhLooping, KdLooping, Grid2Looping,
                                  BvhBeamDescendLooping, BeamMarchLooping>;

// Which kernels a list holds.
enum class Programs {
  multipass,     // MultipassKernels
  with_looping,  // MultipassKernels, then LoopingKernels
};

template <class... K>
inline void append_programs(std::vector<std::unique_ptr<vgpu::Program>>& v, KernelList<K...>) {
  (v.push_back(std::make_unique<vgpu::KernelProgram<K>>()), ...);
}

// Every kernel of the list as a program with its default uniforms, in the list's order.
inline std::vector<std::unique_ptr<vgpu::Program>> all_programs(
    Programs which = Programs::multipass) {
  std::vector<std::unique_ptr<vgpu::Program>> v;
  append_programs(v, MultipassKernels{});
  if (which == Programs::with_looping) append_programs(v, LoopingKernels{});
  return v;
}

}  // namespace kernels
