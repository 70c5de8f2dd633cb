// The budget criterion of adaptive supersampling (--aa-criterion budget): the cones' evidence
// (kernels/cones.h) as a score per pixel, and a share of the image's pixels that hit as the
// level's budget. A threshold one value for every scene does not fit: a scene full of strong
// edges (a checkerboard) marks a third of its pixels at any threshold, a soft one almost none.
// So each level ranks its candidates by score and refines the highest, as many pixels that hit
// as the budget allows (pixels that miss the scene cost no budget: their samples trace one ray
// each). A card of 2004 cannot sort the pixels, but it can count them: the host finds the
// threshold that fits the budget by binary search, one counting pass and occlusion query per
// step (pixelesPuntuados), then cuts the scores at it (cortarPuntajes).
//  - puntuarConos: the pixel's score, the largest colour step that the cones show an edge
//    behind (to a neighbour with another surface key or reflected key, and to any neighbour
//    where the hit distances fold), or the colour's second difference; kept only above the
//    threshold (the floor of every level's threshold) and in candidates;
//  - pixelesPuntuados: counts the pixels that hit whose score exceeds a value;
//  - cortarPuntajes: marks (1) the pixels whose score exceeds the threshold found, 0 the rest.
#pragma once

#include "kernels/common.h"
#include "vgpu/program.h"

namespace kernels {

// puntuarConos: a candidate (x > 0) gets its score in x when it exceeds `threshold` (0
// otherwise); the key, distance and reflected key are kept for the next level.
struct ScoreCones {
  static constexpr const char* name = "score cones";
  static constexpr const char* paper_name = "puntuarConos (extension)";
  static constexpr int outputs = 1;  // -> marks
  enum Unit { kMarks, kColour };
  static constexpr std::array<const char*, 2> units{"marks", "colour_estimate"};

  float threshold = 0.05f;   // the least score that can refine (linear colour units)
  float spread = 0.01f;      // angle between neighbouring pixels' rays, radians
  float depth_cones = 2.0f;  // the depth's second difference that is a fold, in cone widths

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> own = f.fetch_own(kMarks);
    const Vec4<F> c = f.fetch_own(kColour);
    auto marks = [&](float dx, float dy) { return f.fetch(kMarks, f.x + F(dx), f.y + F(dy)); };
    auto colour = [&](float dx, float dy) { return f.fetch(kColour, f.x + F(dx), f.y + F(dy)); };
    const Vec4<F> left = marks(-1, 0), right = marks(1, 0), up = marks(0, -1), down = marks(0, 1);
    const Vec4<F> cl = colour(-1, 0), cr = colour(1, 0), cu = colour(0, -1), cd = colour(0, 1);
    const F two(2.0f);
    auto step = [&](const Vec4<F>& a) {
      return max(max(abs(a.x - c.x), abs(a.y - c.y)), abs(a.z - c.z));
    };
    auto bend = [&](const Vec4<F>& a, const Vec4<F>& b) {
      return max(max(abs(a.x + b.x - two * c.x), abs(a.y + b.y - two * c.y)),
                 abs(a.z + b.z - two * c.z));
    };
    // A step to a neighbour counts where the cones see an edge between them: another surface
    // key or another reflected surface key.
    auto keyed = [&](const Vec4<F>& n, const Vec4<F>& cn) {
      return select((n.y != own.y) || (n.w != own.w), step(cn), F(0.0f));
    };
    // Where the hit distances fold across the cone (marcarConos' test), every step counts.
    const F width = own.z * F(spread * depth_cones);
    const auto folds = (own.y >= F(0.0f)) && ((abs(left.z + right.z - two * own.z) > width) ||
                                              (abs(up.z + down.z - two * own.z) > width));
    const F contrast = max(max(step(cl), step(cr)), max(step(cu), step(cd)));
    F score = max(bend(cl, cr), bend(cu, cd));
    score = max(score,
                max(max(keyed(left, cl), keyed(right, cr)), max(keyed(up, cu), keyed(down, cd))));
    score = max(score, select(folds, contrast, F(0.0f)));
    const auto scored = (own.x > F(0.0f)) && (score > F(threshold));
    f.out(0) = {select(scored, score, F(0.0f)), own.y, own.z, own.w};
  }
};

// pixelesPuntuados: counts the pixels that hit (key >= 0) whose score exceeds `above` (the rest
// are discarded, so an occlusion query counts them). above -1: every pixel that hits.
struct ScoredHits {
  static constexpr const char* name = "scored hits";
  static constexpr const char* paper_name = "pixelesPuntuados (extension)";
  static constexpr int outputs = 1;  // a dummy target: the count is what matters
  static constexpr bool idle_discards = true;
  enum Unit { kMarks };
  static constexpr std::array<const char*, 1> units{"marks"};

  float above = 0.0f;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> m = f.fetch_own(kMarks);
    f.discard((m.x <= F(above)) || (m.y < F(0.0f)));
    f.out(0) = {F(1.0f), F(0.0f), F(0.0f), F(0.0f)};
  }
};

// cortarPuntajes: the level's marks, 1 where the score exceeds the threshold the search found,
// 0 elsewhere; the key, distance and reflected key kept.
struct CutScores {
  static constexpr const char* name = "cut scores";
  static constexpr const char* paper_name = "cortarPuntajes (extension)";
  static constexpr int outputs = 1;  // -> marks
  enum Unit { kMarks };
  static constexpr std::array<const char*, 1> units{"marks"};

  float above = 0.0f;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> m = f.fetch_own(kMarks);
    f.out(0) = {select(m.x > F(above), F(1.0f), F(0.0f)), m.y, m.z, m.w};
  }
};

}  // namespace kernels
