// Every kernel as a program with its default uniforms, in the order a frame first runs them:
// what `vgpu-rt kernels` lists and prints as GLSL; then supersampling's and the fused programs
// of --mrt on.
#pragma once

#include <memory>
#include <vector>

#include "kernels/kernels.h"
#include "vgpu/program.h"

namespace kernels {

inline std::vector<std::unique_ptr<vgpu::Program>> all_programs() {
  std::vector<std::unique_ptr<vgpu::Program>> v;
  v.push_back(std::make_unique<vgpu::KernelProgram<GenerateRays>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<InitTraversal>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<RaysInGrid>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<UpdateVoxel>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<RaysIntersecting>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<Intersections>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<NextTriangle>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<Traversal>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<ReflectionOrigin>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<ShadowRays>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<Shader>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<ReflectedRays>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<ReflectionDirection>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<ResetTraversal>>());
  // Supersampling (--spp N): the jittered ray generator, the accumulation and the resolve.
  v.push_back(std::make_unique<vgpu::KernelProgram<GenerateSampleRays>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<AccumulateSamples>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<ResolveSamples>>());
  // Adaptive supersampling (--aa adaptive): surface keys, marks, the count of marked pixels.
  v.push_back(std::make_unique<vgpu::KernelProgram<KeepHits>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<MarkPixels>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<MarkedPixels>>());
  // Adaptive undersampling (--aa undersample:K): the lattice, the gaps to trace, the fill.
  v.push_back(std::make_unique<vgpu::KernelProgram<MarkLattice>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<MarkGaps>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<FillGaps>>());
  // The fused programs of --mrt on (kernels/fused.h), two outputs each.
  v.push_back(std::make_unique<vgpu::KernelProgram<IntersectNext>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<TraverseUpdate>>());
  // The BVH walk (an extension, kernels/bvh.h): --accel bvh; its fused and looping forms.
  v.push_back(std::make_unique<vgpu::KernelProgram<BvhEnter>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<BvhStep>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<BvhLoadLeaf>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<BvhIntersections>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<BvhStepLoad>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<BvhIntersectNext>>());
  // The kd-tree walk (an extension, kernels/kdtree.h): --accel kdtree; its fused forms.
  v.push_back(std::make_unique<vgpu::KernelProgram<KdEnter>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<KdStep>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<KdLoadLeaf>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<KdIntersections>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<KdStepLoad>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<KdIntersectNext>>());
  // The two-level grid walk (an extension, kernels/grid2.h): --accel grid2; its fused forms.
  v.push_back(std::make_unique<vgpu::KernelProgram<Grid2Enter>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<Grid2Step>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<Grid2LoadCell>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<Grid2Intersections>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<Grid2StepLoad>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<Grid2IntersectNext>>());
  // Glass (an extension, issue 25): the ray streams, their compaction and the gather back.
  v.push_back(std::make_unique<vgpu::KernelProgram<SplitRays>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<ScanStream>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<CountStream>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<CompactStream>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<CopyRows>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<ShadowGlass>>());
  v.push_back(std::make_unique<vgpu::KernelProgram<GatherChildren>>());
  return v;
}

}  // namespace kernels
