// The paper's "CPU" column and the accuracy ground truth: a direct, recursive Whitted tracer on
// the host in double precision. Same camera, grid, traversal rule, shading models, shadows,
// offsets and blend formula as the stream tracer (host/trace/stream/stream_tracer.h), so the two
// images can be compared pixel by pixel; only the precision (double against the card's
// fp32/fp24/fp16) and the execution model (recursion and a per-ray loop against query-steered
// passes) differ.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "host/accel/grid.h"
#include "host/scene/scene.h"
#include "host/trace/stream/stream_tracer.h"

namespace host {

// Work counters of one CPU render, summed over every thread as integers.
struct CpuStats {
  uint64_t rays = 0;         // rays cast: primary, reflected, shadow (also those missing the grid)
  uint64_t voxel_steps = 0;  // voxels examined by the 3D-DDA, summed over every ray
  uint64_t triangle_tests = 0;  // ray-triangle tests (no mailbox: a triangle listed in several
                                // voxels may be tested once per voxel)
  uint64_t nodes_visited = 0;   // BVH nodes whose box was tested, kd-tree nodes descended
  uint64_t restarts = 0;        // kd-restart: walks begun again from the root (--accel kdtree)
  // Glass: rays spawned per iteration by kind, as the stream tracer's StreamLevel counts them
  // (index i: spawned by iteration i, 0 the primary rays', and traced in iteration i + 1; one
  // entry per iteration the render ran, RenderResult::iterations, so the last is 0): reflected
  // (by a mirror or by glass), refracted, and total_internal, the reflected rays of glass past its
  // critical angle (a part of `reflected`). reflected + refracted is every secondary ray cast.
  std::vector<uint64_t> reflected, refracted, total_internal;
  uint64_t glass_shadow_crossings = 0;  // glass surfaces shadow rays went through (each a ray)
  // Beams over tiles (--beams on, host/trace/cpu/cpu_beams.h), over every sample position's
  // beams: tiles, tiles whose beam missed the grid, the passes a GPU would have run (per sample
  // position, the most steps one tile's beam took) and the march steps of every tile.
  uint64_t beam_tiles = 0, beam_tiles_missed = 0, beam_passes = 0, beam_steps = 0;
};

// The kinds of ray in a pixel's ray tree.
enum class CpuRayKind { primary, reflected, refracted, total_internal };

// A shadow ray crosses at most this many glass surfaces: the eighth glass surface it meets
// blocks it (docs/studies/materials.md, "Shadow rays through glass"; the stream tracer's 8 rounds
// of sombraVidrio, the last of which blocks).
inline constexpr int kMaxGlassCrossings = 7;

// One ray of a pixel's tree as the CPU tracer traces it (cpu_ray_tree).
struct CpuRay {
  int depth = 0;  // surfaces before it on its path: 0 for the primary ray
  CpuRayKind kind = CpuRayKind::primary;
  glm::dvec3 origin{0.0}, dir{0.0};  // world space; dir unit
  double weight = 1;                 // its share of the pixel's colour
  int64_t hit = -1;                  // internal triangle index it hits, -1: none
  double t = 0;                      // hit distance (world units), infinite for none
  double local_share = 1;  // of `weight`, the share its hit's own shading (or the background) has
};

// Renders with the options the stream tracer takes; the GPU-only ones (profile, lanes, masks,
// host_shortcut, trace_pixel, keep_pass_records) are ignored, `progress` is not called.
//   - primary rays: cpu_primary_dir, from the camera position;
//   - traversal: incremental 3D-DDA (Amanatides & Woo) over the Grid's voxels, tied axes stepped
//     together; in each voxel every listed triangle is tested (Moller-Trumbore, two-sided) and
//     the nearest hit is kept only if its t lies in the voxel's [t_enter, t_exit] widened by
//     t_slack = 1e-5 * grid diagonal (the stream tracer's rule); the walk ends at the first voxel
//     with such a hit, or when it leaves the grid; with beams over tiles (options.beams), a
//     primary ray's walk starts where its tile's beam stopped, in the state the walk would reach
//     there (host/trace/cpu/cpu_beams.h), and a ray of a tile whose beam missed hits nothing;
//   - shading: kernels::Shader's models and constants (ambient 0.1 x kd, specular 0.5, exponent
//     32, atten_dist = 0.5 * grid diagonal), evaluated at the exact hit point with the shading
//     normal interpolated by the hit's barycentrics; background black; with no lights, only the
//     ambient term;
//   - shadows: a ray from the offset hit point to each light, blocked by any hit with t below the
//     light's distance; with glass in the scene, dimmed by t at each glass surface it crosses
//     (nearest first, at most kMaxGlassCrossings) and blocked by an opaque one;
//   - offsets: reflection and shadow origin = hit point + geometric normal (towards the incoming
//     side) * 1e-4 * grid diagonal; a refracted ray's origin is on the other side;
//   - blend: final = sum_i w_i (1 - a_i) C_i, w_{i+1} = w_i a_i; reflection stops when
//     w < 1/512 or after 1 + bounces iterations;
//   - glass (Material::transmission t > 0): docs/studies/materials.md's model, the exact
//     Fresnel term F of host/trace/cpu/optics.h splitting w into (1 - t)(1 - a) for the local
//     shading, (1 - t) a + t F for the reflected ray and t (1 - F) for the refracted one, the
//     same cut-off and limit.
// Multi-threaded over rows (options.threads, 0 = every core); each pixel is computed alone, so
// the output is bit-identical for any thread count. RenderResult::stats (vgpu::FrameStats) stays
// empty; rays_traced counts the rays that enter the grid, as the stream tracer's queries do;
// render_ms is the wall time of the whole call. Counters go to *stats when given.
RenderResult render_cpu(const Scene& scene, const Grid& grid, const Camera& camera,
                        const RenderOptions& options, CpuStats* stats = nullptr);
// The same over the structure `accel` names: with a BVH, the stackless walk of kernels/bvh.h
// in double (every node whose padded box the ray meets before the nearest hit so far; every
// triangle of a leaf tested; no voxel rule), counted in CpuStats::nodes_visited.
RenderResult render_cpu(const Scene& scene, const Accel& accel, const Camera& camera,
                        const RenderOptions& options, CpuStats* stats = nullptr);

// Every pixel's samples as --aa adaptive would trace them if every pixel were refined at every
// level: the centre ray (its colour, surface key, reflected surface key, hit distance) and each
// level's n x n estimate, each with the rays it traced (RenderResult::rays_traced's count, shadow
// and reflected rays included). A rule of where to refine can then be tried offline: a pixel's
// image is the estimate of the last level the rule gave it, its rays the sum of its levels'
// (bench_mark_rules and scripts/docs/sampling_rules.py). The estimates are render_cpu's: the
// centre its spp 1 colour, level n its spp n x n colour, bit for bit.
struct CpuAdaptiveLevels {
  int width = 0, height = 0;
  std::vector<int> sides;  // adaptive_levels(options.spp): 2, 4 for spp 16
  // Per pixel, row-major (colours rgb): the centre ray's.
  std::vector<float> centre, depth;     // depth: hit distance, 0 for a miss
  std::vector<int> key, reflected_key;  // -1: a miss (or, reflected, no reflected ray)
  std::vector<uint32_t> centre_rays;
  // Per level, then per pixel: the level's mean colour (rgb) and the rays it traced.
  std::vector<std::vector<float>> level;
  std::vector<std::vector<uint32_t>> level_rays;
  // Per level, a level that keeps the samples of the one before (a proposal, not a mode): its
  // n x n strata that hold none of them get a sample each (sample_offset(n * n, stratum)), and
  // the estimate is the mean of the kept and the new samples; kept_rays counts the new ones'
  // rays. Empty for the first level, and where the earlier samples do not fall one to a
  // stratum (the side not doubling, as spp 9's 2 then 3).
  std::vector<std::vector<float>> kept;
  std::vector<std::vector<uint32_t>> kept_rays;
};
CpuAdaptiveLevels cpu_adaptive_levels(const Scene& scene, const Accel& accel, const Camera& camera,
                                      const RenderOptions& options);

// Every ray the CPU tracer traces for one camera ray from `origin` along the unit `dir` (shadow
// rays aside), depth-first in the order traced: the tree of docs/studies/materials.md's glass
// model, with each ray's weight. A ray's weight is w times its parent's share; the weights of its
// hit's local shading and of its children never sum above its own.
std::vector<CpuRay> cpu_ray_tree(const Scene& scene, const Accel& accel,
                                 const RenderOptions& options, const glm::dvec3& origin,
                                 const glm::dvec3& dir);

// host::primary_dir's contract (camera.h) evaluated in double from the camera's float fields:
// the unit world-space direction through the centre of pixel (x, y), y = 0 the top row.
glm::dvec3 cpu_primary_dir(const Camera& camera, int W, int H, int x, int y);

}  // namespace host
