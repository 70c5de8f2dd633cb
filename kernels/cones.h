// The object-space decision of adaptive supersampling (--aa adaptive --aa-criterion object), after
// Amanatides' cones (1984) and Genetti & Gordon's pyramidal rays (1993). A pixel's centre ray
// stands for a cone as wide as the pixel: at the hit, distance t from the eye, its cross-section
// is about t * spread across (spread: the angle between neighbouring pixels' rays). The four
// neighbouring pixels' cones touch it, so their hits tell what lies under its edge:
//  - a neighbour hit another surface (another material, or nothing): a silhouette or an edge
//    between surfaces crosses the cone, as marcarPixeles tests;
//  - the neighbours on both sides hit the same surface, but their hit distances do not continue
//    the pixel's own: the second difference of t along x or y (left + right - 2 own) exceeds
//    depth_cones times the cone's width there. On one smooth surface it is a tiny fraction of
//    the width (the surface curves little over two pixels); where a fold of the surface hides
//    another part of it (the bunny's ear in front of its back), t jumps by far more than the
//    width, though the material is the same and the colours may hardly differ;
//  - the cones bounced off a mirror (the centre rays' first reflected rays) see different
//    surfaces: a reflected edge crosses the cone, however faint its colour step;
//  - what the cones cannot see from the hits alone (a shadow's edge, a texture) shows in the
//    colour: its second difference above the threshold, as marcarPixeles.
// guardarConos keeps each pixel's surface key and hit distance after the primary walk,
// guardarReflejos its reflected ray's surface key after the first reflected walk; marcarConos
// marks the pixels whose cones an edge crosses.
#pragma once

#include "kernels/common.h"
#include "vgpu/program.h"

namespace kernels {

// guardarConos: after the primary walk of the centre frame, into the mark texture: candidate 1,
// the surface key (the hit triangle's material, -1 for a miss), the hit distance t (0 for a
// miss), -1 (no reflected surface yet: guardarReflejos writes it).
struct KeepCones {
  static constexpr const char* name = "keep cones";
  static constexpr const char* paper_name = "guardarConos (extension)";
  static constexpr int outputs = 1;  // -> marks
  enum Unit { kIntersection, kMaterials };
  static constexpr std::array<const char*, 2> units{"intersection", "triangle_materials"};

  SceneUniforms scene;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> hit = f.fetch_own(kIntersection);
    const auto hits = hit.w >= F(0.0f);
    const F material = fetch_id(f, kMaterials, max(hit.w, F(0.0f)), scene.width).x;
    f.out(0) = {F(1.0f), select(hits, material, F(-1.0f)), select(hits, hit.x, F(0.0f)), F(-1.0f)};
  }
};

// guardarReflejos: after the first reflected walk of the centre frame, the reflected ray's
// surface key (the material its hit triangle has; -1 for a miss, and for a pixel that reflected
// no ray) into the mark texture's last channel, the rest kept. The reflected rays are the
// pixels' cones bounced off a mirror: where neighbouring pixels on one mirror see different
// surfaces, a reflected edge crosses the cone.
struct KeepReflected {
  static constexpr const char* name = "keep reflected";
  static constexpr const char* paper_name = "guardarReflejos (extension)";
  static constexpr int outputs = 1;  // -> marks
  enum Unit { kMarks, kIntersection, kMaterials };
  static constexpr std::array<const char*, 3> units{"marks", "intersection", "triangle_materials"};

  SceneUniforms scene;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> own = f.fetch_own(kMarks);
    const Vec4<F> hit = f.fetch_own(kIntersection);
    const auto hits = hit.w >= F(0.0f);
    const F material = fetch_id(f, kMaterials, max(hit.w, F(0.0f)), scene.width).x;
    f.out(0) = {own.x, own.y, own.z, select(hits, material, F(-1.0f))};
  }
};

// marcarConos: a pixel still a candidate (x > 0) gets more samples where its cone is crossed by
// an edge (above). The output keeps the key and the distance for the next level's marks.
struct MarkCones {
  static constexpr const char* name = "mark cones";
  static constexpr const char* paper_name = "marcarConos (extension)";
  static constexpr int outputs = 1;  // -> marks
  enum Unit { kMarks, kColour };
  static constexpr std::array<const char*, 2> units{"marks", "colour_estimate"};

  float threshold = 0.1f;    // the colour's second difference, as marcarPixeles (linear)
  float spread = 0.01f;      // angle between neighbouring pixels' rays, radians
  float depth_cones = 2.0f;  // the depth's second difference that marks, in cone widths

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> own = f.fetch_own(kMarks);
    const Vec4<F> c = f.fetch_own(kColour);
    auto marks = [&](float dx, float dy) { return f.fetch(kMarks, f.x + F(dx), f.y + F(dy)); };
    auto colour = [&](float dx, float dy) { return f.fetch(kColour, f.x + F(dx), f.y + F(dy)); };
    const Vec4<F> left = marks(-1, 0), right = marks(1, 0), up = marks(0, -1), down = marks(0, 1);
    const F two(2.0f);
    // The cone's width at the hit, times how many widths the depth may bend by.
    const F width = own.z * F(spread * depth_cones);
    // Only between hits: a miss has t 0 (and another key, which marks it anyway).
    auto folds = [&](const Vec4<F>& a, const Vec4<F>& b) {
      return (own.y >= F(0.0f)) && (abs(a.z + b.z - two * own.z) > width);
    };
    auto bends = [&](const Vec4<F>& a, const Vec4<F>& b) {
      const F d = max(max(abs(a.x + b.x - two * c.x), abs(a.y + b.y - two * c.y)),
                      abs(a.z + b.z - two * c.z));
      return d > F(threshold);
    };
    const auto edge = (left.y != own.y) || (right.y != own.y) || (up.y != own.y) ||
                      (down.y != own.y) || (left.w != own.w) || (right.w != own.w) ||
                      (up.w != own.w) || (down.w != own.w) || folds(left, right) ||
                      folds(up, down) || bends(colour(-1, 0), colour(1, 0)) ||
                      bends(colour(0, -1), colour(0, 1));
    const auto marked = (own.x > F(0.0f)) && edge;
    f.out(0) = {select(marked, F(1.0f), F(0.0f)), own.y, own.z, own.w};
  }
};

}  // namespace kernels
