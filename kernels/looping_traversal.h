// recorridoIterativo (looping traversal; an extension, the paper has no such kernel): one
// fragment program that walks the grid in a data-dependent loop. Purcell, Buck, Mark & Hanrahan
// ("Ray Tracing on Programmable Graphics Hardware", SIGGRAPH 2002) describe two ways to map the
// tracer onto fragment hardware: the multipass one the paper follows, and a "branching" one
// where a processor with loops and branches runs traversal and intersection in one kernel; Horn,
// Sugerman, Houston & Hanrahan ("Interactive k-D Tree GPU Raytracing", I3D 2007) later walk a
// whole ray in a single pass this way. Each iteration does what one round of the multipass
// pipeline does for a ray, with the same arithmetic (so hit ids and depths match it):
//   - the ray's voxel list is not loaded yet (voxel state z = 0): actualizarVoxel, its first
//     triangle from the voxel pointer and list textures;
//   - then, with a triangle left (voxel state w >= 0): intersecciones and proximoTriangulo, the
//     nearest in-voxel hit kept and the next list entry loaded;
//   - or, with none left: traversal, one 3D-DDA step (done at a hit or outside the grid), the
//     new voxel's list marked not loaded.
// The loop ends for a ray when it is done, or for every ray after `steps` iterations: the host
// then draws the pass again for the rays still walking (rayosEnGrilla's query). State lives in
// the multipass pipeline's textures; voxel state z = 1 marks a loaded list (multipass leaves 0).
#pragma once

#include "kernels/common.h"
#include "kernels/lists.h"

namespace kernels {

struct LoopingTraversal {
  static constexpr const char* name = "looping traversal";
  static constexpr const char* paper_name = "recorridoIterativo";  // an extension: not in the paper
  static constexpr int outputs = 3;  // -> traversal, voxel state, intersection (MRT, fp40)
  enum Unit {
    kOrigins,
    kRays,
    kTraversal,
    kVoxelState,
    kIntersection,
    kV0,
    kV1,
    kV2,
    kPointers,
    kLists
  };
  static constexpr std::array<const char*, 10> units{
      "origins",   "rays",      "traversal", "voxel_state",    "intersection",
      "vertices0", "vertices1", "vertices2", "voxel_pointers", "triangle_lists"};
  // Finished rays keep their whole state.
  static constexpr std::array<int, 3> passthrough{kTraversal, kVoxelState, kIntersection};

  GridUniforms grid;
  SceneUniforms scene;
  int steps = 32;  // iterations per pass (the host's --steps-per-pass)

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    Vec4<F> trav = f.fetch_own(kTraversal);
    Vec4<F> vs = f.fetch_own(kVoxelState);
    Vec4<F> best = f.fetch_own(kIntersection);
    const Vec3<F> o = f.fetch_own(kOrigins).xyz();
    const Vec4<F> ray = f.fetch_own(kRays);
    const Vec3<F> d = ray.xyz();
    f.loop(steps, trav.x >= F(0.0f), [&](const M& act) {
      // actualizarVoxel: voxel (X, Y, Z) lives at texel (X * sizeY + Y, Z).
      const M load = act && (vs.z < F(0.5f));
      const F px = trav.x * F(grid.res.y) + trav.y + F(0.5f), py = trav.z + F(0.5f);
      const F start = f.fetch(kPointers, px, py).x;
      const F first = fetch_id(f, kLists, start, grid.list_width).x;
      vs = select(load, Vec4<F>{start, F(0.0f), F(1.0f), first}, vs);
      // intersecciones + proximoTriangulo, for a ray with a triangle left in its voxel.
      const M testing = act && (vs.w >= F(0.0f));
      const Vec3<F> p0 = fetch_id(f, kV0, vs.w, scene.width).xyz();
      const Vec3<F> p1 = fetch_id(f, kV1, vs.w, scene.width).xyz();
      const Vec3<F> p2 = fetch_id(f, kV2, vs.w, scene.width).xyz();
      F u, v;
      const F t = intersect_triangle(o, d, p0, p1, p2, u, v);
      const Vec3<F> exits = voxel_exits(o, d, trav.xyz(), grid);
      const F t_exit = min3(exits);
      const M in_voxel = (t >= trav.w - F(grid.t_slack)) && (t <= t_exit + F(grid.t_slack));
      const M nearer = testing && in_voxel && (t < best.x) && (t < ray.w);
      best = select(nearer, Vec4<F>{t, u, v, vs.w}, best);
      const F pos = vs.x + F(1.0f);
      const F tri = fetch_id(f, kLists, pos, grid.list_width).x;
      // traversal, for a ray whose voxel has nothing left to test.
      const M stepping = act && !testing;
      auto step = [&](const F& da, const F& ta) {
        return select(ta == t_exit, select(da > F(0.0f), F(1.0f), F(-1.0f)), F(0.0f));
      };
      const Vec3<F> nv{trav.x + step(d.x, exits.x), trav.y + step(d.y, exits.y),
                       trav.z + step(d.z, exits.z)};
      const M outside = (nv.x < F(0.0f)) || (nv.y < F(0.0f)) || (nv.z < F(0.0f)) ||
                        (nv.x >= F(grid.res.x)) || (nv.y >= F(grid.res.y)) ||
                        (nv.z >= F(grid.res.z));
      const M past = past_tmax(t_exit, ray.w, grid.t_slack);  // past the light, as dda_step
      const M done = (best.w >= F(0.0f)) || outside || past;
      const Vec4<F> stepped{nv.x, nv.y, nv.z, t_exit};
      const Vec4<F> finished{F(kNone), F(0.0f), F(0.0f), trav.w};
      vs = select(testing, Vec4<F>{pos, F(0.0f), F(1.0f), tri},
                  select(stepping, Vec4<F>{F(0.0f), F(0.0f), F(0.0f), F(kNone)}, vs));
      trav = select(stepping, select(done, finished, stepped), trav);
      return trav.x >= F(0.0f);
    });
    f.out(0) = trav;
    f.out(1) = vs;
    f.out(2) = best;
  }
};

}  // namespace kernels
