// compactarRayos (an extension: stream reduction, Horn, GPU Gems 2 ch. 36): the gather pass of
// the compaction. Output slot j of the next level finds the ray of the current level that spawned
// it by a binary search over the inclusive prefix sums of the spawn counts (sumaPrefijos): the
// first i with S[i] > j, in a fixed number of dependent fetches (ceil(log2 n): no data-dependent
// loop, so the FX runs it). Slot j is i's first spawned ray (reflected if that one lives) when
// j = S[i] - count[i], its refracted ray otherwise. One output per pass (fp30), so `part` picks
// what this pass writes: 0, the ray's origin (the hit point lifted along the geometric normal to
// the ray's side, or pushed through to the far side for the refracted ray); 1, its direction and
// tmax; 2, its weight, as the result texture's alpha. Slots past `count` get no ray.
#pragma once

#include "kernels/glass.h"

namespace kernels {

struct CompactStream {
  static constexpr const char* name = "stream compaction";
  static constexpr const char* paper_name = "compactarRayos (extension)";
  static constexpr int outputs = 1;  // -> origins, rays or result of the next level
  enum Unit { kScan, kSplit, kRays, kSurface, kGlass, kV0, kV1, kV2, kN0, kN1, kN2 };
  static constexpr std::array<const char*, 11> units{
      "scan",      "split",     "rays",     "surface",  "glass",   "vertices0",
      "vertices1", "vertices2", "normals0", "normals1", "normals2"};

  SceneUniforms scene;
  float width = 1;       // width of both levels' stream textures, texels
  float count = 0;       // slots of the next level (rays spawned)
  float sources = 1;     // rays of the current level (entries of the scan)
  int steps = 0;         // ceil(log2(sources)): the binary search's fetches
  int part = 0;          // 0: origins, 1: rays, 2: weight (result)
  float offset = 1e-4f;  // world units, inicioReflejo's

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const F j = stream_index(f.x, f.y, width);
    const auto live = j < F(count);
    const F i = scan_search(f, kScan, j, sources, steps, width);
    const Vec4<F> split = fetch_id(f, kSplit, i, width);
    const F first_slot = fetch_id(f, kScan, i, width).x - split.z;
    const auto reflected = (j - first_slot < F(0.5f)) && (split.x > F(0.0f));
    const F zero = F(0.0f);
    if (part == 2) {
      f.out(0) = select(live, Vec4<F>{zero, zero, zero, select(reflected, split.x, split.y)},
                        Vec4<F>{zero, zero, zero, zero});
      return;
    }
    const Vec4<F> surf = fetch_id(f, kSurface, i, width);
    const Vec3<F> d = fetch_id(f, kRays, i, width).xyz();
    if (part == 0) {
      // inicioReflejo lifted the point by `offset` to the ray's side; the refracted ray starts
      // as far on the other side. Only the geometric normal is needed (surface_at's, to the same
      // rounding): the shading normals are not fetched, as a compiler would drop those fetches.
      const Vec3<F> p0 = fetch_id(f, kV0, surf.w, scene.width).xyz();
      const Vec3<F> p1 = fetch_id(f, kV1, surf.w, scene.width).xyz();
      const Vec3<F> p2 = fetch_id(f, kV2, surf.w, scene.width).xyz();
      Vec3<F> ng = normalize(cross(p1 - p0, p2 - p0));
      ng = select(dot(ng, d) > F(0.0f), -ng, ng);
      const Vec3<F> p = select(reflected, surf.xyz(), surf.xyz() - ng * F(2.0f * offset));
      f.out(0) = select(live, Vec4<F>{p.x, p.y, p.z, zero}, Vec4<F>{zero, zero, zero, zero});
      return;
    }
    const Surface<F> s = surface_at(f, surf.w, surf.xyz(), d, kV0, kN0, scene);
    const F ior = fetch_id(f, kGlass, surf.w, scene.width).z;
    const Glass<L> g = glass_optics<L>(d, s, ior);
    // direccionReflejo's mirror direction, to the same rounding.
    const Vec3<F> r = normalize(d - s.n * (F(2.0f) * dot(d, s.n)));
    const Vec3<F> dir = select(reflected, r, g.refracted);
    f.out(0) =
        select(live, Vec4<F>{dir.x, dir.y, dir.z, F(kFar)}, Vec4<F>{zero, zero, zero, F(kNone)});
  }
};

}  // namespace kernels
