// The one list of every kernel, in the order a frame first runs them: the paper's programs, then
// supersampling's, the fused programs of --mrt on, each acceleration structure's walk, glass's
// ray streams, the dense streams and the beams over tiles; the looping variant's programs
// (--kernels looping) come last. Everything else that lists kernels is made from it:
//   kernels/kernels.h        declares each kernel's program compiled elsewhere (extern template),
//   kernels/programs_*.cpp   compile each program once, the second column naming the file,
//   kernels/registry.h       the run-time registry (`vgpu-rt kernels`, the report, the GL tests),
// and tests/kernels/test_registry.cpp checks that kernels/README.md's glossary names every kernel
// here, with its C++ type, and nothing else. A new kernel is one X(Type, file) line here, a row
// in the glossary, and its header included by kernels/kernels.h.
// X(Type, file): Type is the functor in namespace kernels; file the programs_<file>.cpp that
// compiles its program.
#pragma once

// The multipass programs: every pass of a frame runs one of these.
#define VGPU_MULTIPASS_KERNELS(X)                                                                \
  /* The paper's fragment programs (and the shadow-ray extension, rayosSombra). */               \
  X(GenerateRays, rays)                                                                          \
  X(InitTraversal, walk)                                                                         \
  X(RaysInGrid, walk)                                                                            \
  X(UpdateVoxel, walk)                                                                           \
  X(RaysIntersecting, hits)                                                                      \
  X(Intersections, hits)                                                                         \
  X(NextTriangle, hits)                                                                          \
  X(Traversal, walk)                                                                             \
  X(ReflectionOrigin, rays)                                                                      \
  X(ShadowRays, rays)                                                                            \
  X(Shader, rays)                                                                                \
  X(ReflectedRays, rays)                                                                         \
  X(ReflectionDirection, rays)                                                                   \
  X(ResetTraversal, walk)                                                                        \
  /* Supersampling (--spp N): the jittered ray generator, the accumulation and the resolve. */   \
  X(GenerateSampleRays, rays)                                                                    \
  X(AccumulateSamples, rays)                                                                     \
  X(ResolveSamples, rays)                                                                        \
  /* Adaptive supersampling (--aa adaptive): surface keys, marks, the marked pixels' count. */   \
  X(KeepHits, rays)                                                                              \
  X(MarkPixels, rays)                                                                            \
  X(MarkedPixels, rays)                                                                          \
  /* Its object-space decision (--aa-criterion object): cones' keys and depths, their marks. */  \
  X(KeepCones, rays)                                                                             \
  X(KeepReflected, rays)                                                                         \
  X(MarkCones, rays)                                                                             \
  /* Its budget (--aa-criterion budget): the cones' scores, the count above a value, the cut. */ \
  X(ScoreCones, rays)                                                                            \
  X(ScoredHits, rays)                                                                            \
  X(CutScores, rays)                                                                             \
  /* Adaptive undersampling (--aa undersample:K): the lattice, the gaps to trace, the fill. */   \
  X(MarkLattice, rays)                                                                           \
  X(MarkGaps, rays)                                                                              \
  X(FillGaps, rays)                                                                              \
  /* The fused programs of --mrt on (kernels/fused.h), two outputs each. */                      \
  X(IntersectNext, fused)                                                                        \
  X(TraverseUpdate, fused)                                                                       \
  /* The BVH walk (an extension, kernels/bvh.h): --accel bvh; its fused forms. */                \
  X(BvhEnter, bvh)                                                                               \
  X(BvhStep, bvh)                                                                                \
  X(BvhLoadLeaf, bvh)                                                                            \
  X(BvhIntersections, bvh)                                                                       \
  X(BvhStepLoad, bvh)                                                                            \
  X(BvhIntersectNext, bvh)                                                                       \
  /* The kd-tree walk (an extension, kernels/kdtree.h): --accel kdtree; its fused forms. */      \
  X(KdEnter, kdtree)                                                                             \
  X(KdStep, kdtree)                                                                              \
  X(KdLoadLeaf, kdtree)                                                                          \
  X(KdIntersections, kdtree)                                                                     \
  X(KdStepLoad, kdtree)                                                                          \
  X(KdIntersectNext, kdtree)                                                                     \
  /* The two-level grid walk (an extension, kernels/grid2.h): --accel grid2; its fused forms. */ \
  X(Grid2Enter, grid2)                                                                           \
  X(Grid2Step, grid2)                                                                            \
  X(Grid2LoadCell, grid2)                                                                        \
  X(Grid2Intersections, grid2)                                                                   \
  X(Grid2StepLoad, grid2)                                                                        \
  X(Grid2IntersectNext, grid2)                                                                   \
  /* Glass (an extension, issue 25): the ray streams, their compaction and the gather back. */   \
  X(SplitRays, streams)                                                                          \
  X(ScanStream, streams)                                                                         \
  X(CountStream, streams)                                                                        \
  X(CompactStream, streams)                                                                      \
  X(CopyRows, streams)                                                                           \
  X(ShadowGlass, streams)                                                                        \
  X(GatherChildren, streams)                                                                     \
  /* Sampling that saves time (issue 35): the marked pixels as a dense stream, and back. */      \
  X(CompactMarks, streams)                                                                       \
  X(GenerateDenseRays, streams)                                                                  \
  X(AccumulateDense, streams)                                                                    \
  X(GatherMarked, streams)                                                                       \
  /* Beams over tiles (issue 35, kernels/beams.h): --beams on, one fragment per tile; through */ \
  /* the BVH (kernels/bvh_beams.h), the descent to each tile's entry node; through the */        \
  /* two-level grid (kernels/grid2_beams.h), the entry at the walk's sub-cell. */                \
  X(BeamMarch, beams)                                                                            \
  X(BeamsMissed, beams)                                                                          \
  X(BeamEntry, beams)                                                                            \
  X(BvhBeamDescend, beams)                                                                       \
  X(BvhBeamsDescending, beams)                                                                   \
  X(BvhBeamEnter, beams)                                                                         \
  X(Grid2BeamEntry, beams)

// The looping variant (--kernels looping): each structure's whole walk in one program with a
// data-dependent loop (kernels/looping_traversal.h and the structures' headers); with beams
// through a tree, the whole descent in one program (kernels/bvh_beams.h); through a grid, the
// whole march (kernels/beams.h).
#define VGPU_LOOPING_KERNELS(X)   \
  X(LoopingTraversal, fused)      \
  X(BvhLooping, bvh)              \
  X(KdLooping, kdtree)            \
  X(Grid2Looping, grid2)          \
  X(BvhBeamDescendLooping, beams) \
  X(BeamMarchLooping, beams)

#define VGPU_ALL_KERNELS(X) VGPU_MULTIPASS_KERNELS(X) VGPU_LOOPING_KERNELS(X)
