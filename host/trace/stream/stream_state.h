// The stream tracer's private state: every texture and program of the pipeline, shared by the
// files of the tracer (stream_tracer.cpp, sampling_modes.cpp). Not for users.
#pragma once

#include <memory>

#include "host/trace/passes.h"
#include "host/trace/ping_pong.h"
#include "host/trace/stream/atlas_upload.h"
#include "host/trace/stream/mark_streams.h"
#include "host/trace/stream/ray_streams.h"
#include "host/trace/stream/stream_tracer.h"
#include "host/trace/walks/accel_walk.h"
#include "kernels/cone_budget.h"
#include "kernels/cones.h"

namespace host {

struct StreamTracer::State {
  // Static textures: the scene, triangle i at texel (i mod width, i div width).
  vgpu::Texture v[3], n[3], colors;
  // Base-colour textures (scenes with a textured material): the corners' coordinates, the
  // texture table and the atlas of mip chains (host/trace/stream/atlas_upload.h).
  bool textured = false;
  AtlasTextures base;
  // Dynamic textures: ping-pong pairs (host/trace/ping_pong.h) where a pass reads what it
  // replaces. The origins' current texture holds an iteration's ray origins, the next one its
  // hit points (the surface record the shader reads and the reflected rays start from).
  PingPong<vgpu::Texture> rays, origins, isect, result;
  vgpu::Texture shadow_rays, counter;
  // The rays still walking, and those with a triangle left to test (the walk's masks).
  vgpu::Stencil grid_mask, isect_mask;
  // The programs of the pipeline around the walk, with their uniforms.
  vgpu::KernelProgram<kernels::GenerateRays> generate;
  vgpu::KernelProgram<kernels::Shader> shader;
  vgpu::KernelProgram<kernels::ReflectedRays> reflected;
  vgpu::KernelProgram<kernels::ReflectionOrigin> origin;
  vgpu::KernelProgram<kernels::ReflectionDirection> direction;
  vgpu::KernelProgram<kernels::ShadowRays> shadow;
  // Supersampling (--spp N > 1): sample frames' rays, their sum and the box filter.
  vgpu::KernelProgram<kernels::GenerateSampleRays> sample_generate;
  vgpu::KernelProgram<kernels::AccumulateSamples> accumulate;
  vgpu::KernelProgram<kernels::ResolveSamples> resolve;
  PingPong<vgpu::Texture> sum;
  // Adaptive supersampling (--aa adaptive): surface keys and marks, each triangle's material.
  vgpu::KernelProgram<kernels::KeepHits> keep;
  vgpu::KernelProgram<kernels::MarkPixels> mark;
  vgpu::KernelProgram<kernels::MarkedPixels> marked;
  // ... or the cones' (--aa-criterion object): keys and hit distances, and their marks.
  vgpu::KernelProgram<kernels::KeepCones> keep_cones;
  vgpu::KernelProgram<kernels::KeepReflected> keep_reflected;
  vgpu::KernelProgram<kernels::MarkCones> mark_cones;
  // ... and their budget (--aa-criterion budget): scores, the search's counts, the cut.
  vgpu::KernelProgram<kernels::ScoreCones> score_cones;
  vgpu::KernelProgram<kernels::ScoredHits> scored_hits;
  vgpu::KernelProgram<kernels::CutScores> cut_scores;
  PingPong<vgpu::Texture> marks;
  vgpu::Texture materials;
  // Adaptive undersampling (--aa undersample:K): the lattice, the gaps, the fill.
  vgpu::KernelProgram<kernels::MarkLattice> mark_lattice;
  vgpu::KernelProgram<kernels::MarkGaps> mark_gaps;
  vgpu::KernelProgram<kernels::FillGaps> fill;
  // The walk through the acceleration structure, and how passes are issued.
  std::unique_ptr<AccelWalk> walk;
  std::unique_ptr<PassRunner> runner;
  // Glass (or --ray-streams on): the frame as ray streams (host/trace/stream/ray_streams.h).
  std::unique_ptr<RayStreams> streams;
  // The sampling modes' gated frames as dense streams of their marked pixels (--compact on;
  // host/trace/stream/mark_streams.h).
  std::unique_ptr<MarkStreams> dense;
};

}  // namespace host
