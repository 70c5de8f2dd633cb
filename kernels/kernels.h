// The paper's fragment programs (and the shadow-ray extension), one functor per file, and the
// fused two-output programs --mrt on runs (kernels/fused.h), and the ray streams of glass
// (dividirRayos, sumaPrefijos, contarRayos, compactarRayos, copiarFilas, reunirHijos,
// sombraVidrio).
#pragma once

#include "kernels/accumulate_samples.h"
#include "kernels/beams.h"
#include "kernels/bvh.h"
#include "kernels/bvh_beams.h"
#include "kernels/compact_marks.h"
#include "kernels/compact_stream.h"
#include "kernels/copy_rows.h"
#include "kernels/count_stream.h"
#include "kernels/fused.h"
#include "kernels/gather_children.h"
#include "kernels/generate_rays.h"
#include "kernels/grid2.h"
#include "kernels/grid2_beams.h"
#include "kernels/init_traversal.h"
#include "kernels/intersections.h"
#include "kernels/kdtree.h"
#include "kernels/keep_hits.h"
#include "kernels/looping_traversal.h"
#include "kernels/mark_pixels.h"
#include "kernels/next_triangle.h"
#include "kernels/rays_in_grid.h"
#include "kernels/rays_intersecting.h"
#include "kernels/reflected_rays.h"
#include "kernels/reflection_direction.h"
#include "kernels/reflection_origin.h"
#include "kernels/reset_traversal.h"
#include "kernels/resolve_samples.h"
#include "kernels/scan_stream.h"
#include "kernels/shader.h"
#include "kernels/shadow_glass.h"
#include "kernels/shadow_rays.h"
#include "kernels/split_rays.h"
#include "kernels/traversal.h"
#include "kernels/undersample.h"
#include "kernels/update_voxel.h"
#include "vgpu/program.h"

// Each kernel's program (its run at every lane family: widths 1, 4, 8, 16, fp24/fp16 rounding,
// counting, recording) is compiled once, in kernels/programs_*.cpp: a file that includes this
// header and makes a vgpu::KernelProgram<K> links to that copy instead of compiling its own.
extern template class vgpu::KernelProgram<kernels::GenerateRays>;
extern template class vgpu::KernelProgram<kernels::InitTraversal>;
extern template class vgpu::KernelProgram<kernels::ResetTraversal>;
extern template class vgpu::KernelProgram<kernels::Traversal>;
extern template class vgpu::KernelProgram<kernels::RaysInGrid>;
extern template class vgpu::KernelProgram<kernels::UpdateVoxel>;
extern template class vgpu::KernelProgram<kernels::Intersections>;
extern template class vgpu::KernelProgram<kernels::NextTriangle>;
extern template class vgpu::KernelProgram<kernels::RaysIntersecting>;
extern template class vgpu::KernelProgram<kernels::Shader>;
extern template class vgpu::KernelProgram<kernels::ShadowRays>;
extern template class vgpu::KernelProgram<kernels::ReflectedRays>;
extern template class vgpu::KernelProgram<kernels::ReflectionOrigin>;
extern template class vgpu::KernelProgram<kernels::ReflectionDirection>;
extern template class vgpu::KernelProgram<kernels::IntersectNext>;
extern template class vgpu::KernelProgram<kernels::TraverseUpdate>;
extern template class vgpu::KernelProgram<kernels::LoopingTraversal>;
extern template class vgpu::KernelProgram<kernels::GenerateSampleRays>;
extern template class vgpu::KernelProgram<kernels::AccumulateSamples>;
extern template class vgpu::KernelProgram<kernels::ResolveSamples>;
extern template class vgpu::KernelProgram<kernels::KeepHits>;
extern template class vgpu::KernelProgram<kernels::MarkPixels>;
extern template class vgpu::KernelProgram<kernels::MarkedPixels>;
extern template class vgpu::KernelProgram<kernels::MarkLattice>;
extern template class vgpu::KernelProgram<kernels::MarkGaps>;
extern template class vgpu::KernelProgram<kernels::FillGaps>;
extern template class vgpu::KernelProgram<kernels::BvhEnter>;
extern template class vgpu::KernelProgram<kernels::BvhStep>;
extern template class vgpu::KernelProgram<kernels::BvhLoadLeaf>;
extern template class vgpu::KernelProgram<kernels::BvhIntersections>;
extern template class vgpu::KernelProgram<kernels::BvhStepLoad>;
extern template class vgpu::KernelProgram<kernels::BvhIntersectNext>;
extern template class vgpu::KernelProgram<kernels::BvhLooping>;
extern template class vgpu::KernelProgram<kernels::KdEnter>;
extern template class vgpu::KernelProgram<kernels::KdStep>;
extern template class vgpu::KernelProgram<kernels::KdLoadLeaf>;
extern template class vgpu::KernelProgram<kernels::KdIntersections>;
extern template class vgpu::KernelProgram<kernels::KdStepLoad>;
extern template class vgpu::KernelProgram<kernels::KdIntersectNext>;
extern template class vgpu::KernelProgram<kernels::KdLooping>;
extern template class vgpu::KernelProgram<kernels::Grid2Enter>;
extern template class vgpu::KernelProgram<kernels::Grid2Step>;
extern template class vgpu::KernelProgram<kernels::Grid2LoadCell>;
extern template class vgpu::KernelProgram<kernels::Grid2Intersections>;
extern template class vgpu::KernelProgram<kernels::Grid2StepLoad>;
extern template class vgpu::KernelProgram<kernels::Grid2IntersectNext>;
extern template class vgpu::KernelProgram<kernels::Grid2Looping>;
extern template class vgpu::KernelProgram<kernels::SplitRays>;
extern template class vgpu::KernelProgram<kernels::ScanStream>;
extern template class vgpu::KernelProgram<kernels::CountStream>;
extern template class vgpu::KernelProgram<kernels::CompactStream>;
extern template class vgpu::KernelProgram<kernels::CopyRows>;
extern template class vgpu::KernelProgram<kernels::GatherChildren>;
extern template class vgpu::KernelProgram<kernels::CompactMarks>;
extern template class vgpu::KernelProgram<kernels::GenerateDenseRays>;
extern template class vgpu::KernelProgram<kernels::GatherMarked>;
extern template class vgpu::KernelProgram<kernels::AccumulateDense>;
extern template class vgpu::KernelProgram<kernels::ShadowGlass>;
extern template class vgpu::KernelProgram<kernels::BeamMarch>;
extern template class vgpu::KernelProgram<kernels::BeamMarchLooping>;
extern template class vgpu::KernelProgram<kernels::BeamEntry>;
extern template class vgpu::KernelProgram<kernels::BeamsMissed>;
extern template class vgpu::KernelProgram<kernels::BvhBeamDescend>;
extern template class vgpu::KernelProgram<kernels::BvhBeamEnter>;
extern template class vgpu::KernelProgram<kernels::BvhBeamsDescending>;
extern template class vgpu::KernelProgram<kernels::Grid2BeamEntry>;
