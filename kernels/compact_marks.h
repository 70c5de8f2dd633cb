// Sampling that saves time (an extension, issue 35): a gated sample frame traces only the
// pixels its marks flag, so the marked pixels are packed into a dense stream first and the frame's
// passes draw only the rows that stream fills. Three kernels around the usual frame, with the
// stream reduction of glass's ray streams (Horn, GPU Gems 2 ch. 36; sumaPrefijos scans the
// marks):
//   compactarMarcados    stream slot j finds the j-th marked pixel by a binary search over the
//                        inclusive prefix sums of the marks, and writes that pixel's centre;
//   generadorRayosDensos the sample rays of those pixel centres, one per slot (the same rays
//                        generadorRayosMuestra gives the marked pixels, to the bit);
//   reunirMarcados       after the frame, each marked pixel fetches its slot's texel (its
//                        colour, or its primary hit) back: a gather, no scatter.
#pragma once

#include "kernels/generate_rays.h"
#include "kernels/glass.h"

namespace kernels {

struct CompactMarks {
  static constexpr const char* name = "marks compaction";
  static constexpr const char* paper_name = "compactarMarcados (extension)";
  static constexpr int outputs = 1;  // -> pixel centres of the dense stream
  enum Unit { kScan };
  static constexpr std::array<const char*, 1> units{"scan"};

  float width = 1;    // image width = the stream's width, texels
  float count = 0;    // marked pixels: the stream's live slots
  float sources = 1;  // pixels (entries of the scan)
  int steps = 0;      // ceil(log2(sources)): the binary search's fetches

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const F j = stream_index(f.x, f.y, width);
    F lo = F(0.0f), hi = F(sources - 1.0f);
    for (int s = 0; s < steps; ++s) {
      const F mid = floor((lo + hi) * F(0.5f));
      const auto left = fetch_id(f, kScan, mid, width).x > j;
      hi = select(left, mid, hi);
      lo = select(left, lo, mid + F(1.0f));
    }
    // The first pixel whose inclusive sum passes j is the j-th marked one.
    F u, v;
    id_to_texel(min(lo, F(sources - 1.0f)), width, u, v);
    const F zero = F(0.0f);
    f.out(0) = select(j < F(count), Vec4<F>{u, v, zero, F(1.0f)}, Vec4<F>{zero, zero, zero, zero});
  }
};

// generadorRayosMuestra for a dense stream: slot j's ray goes through the sample position of the
// pixel whose centre compactarMarcados wrote there (w 0: a slot past the marked pixels, no ray).
struct GenerateDenseRays : GenerateRays {
  static constexpr const char* name = "generate dense rays";
  static constexpr const char* paper_name = "generadorRayosDensos (extension)";
  enum Unit { kPixels };
  static constexpr std::array<const char*, 1> units{"pixels"};

  float jitter_x = 0.5f, jitter_y = 0.5f;  // as GenerateSampleRays'

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> p = f.fetch_own(kPixels);
    Vec4<F> ray = ray_through<L>(p.x + F(jitter_x - 0.5f), p.y + F(jitter_y - 0.5f));
    ray.w = select(p.w > F(0.0f), ray.w, F(kNone));
    f.out(0) = ray;
  }
};

// reunirMarcados: a marked pixel (marks x > 0) takes the texel of its slot in the dense stream,
// its inclusive sum minus one; the others take `fallback` (what a gated frame leaves where it
// traced nothing does not matter: every reader is gated by the same marks).
struct GatherMarked {
  static constexpr const char* name = "marked gather";
  static constexpr const char* paper_name = "reunirMarcados (extension)";
  static constexpr int outputs = 1;  // -> the pixels' colour or hits
  enum Unit { kMarks, kScan, kDense };
  static constexpr std::array<const char*, 3> units{"marks", "scan", "dense"};

  float width = 1;  // image width = the stream's width, texels
  glm::vec4 fallback{0.0f, 0.0f, 0.0f, 1.0f};

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const auto marked = f.fetch_own(kMarks).x > F(0.0f);
    const F slot = max(f.fetch_own(kScan).x - F(1.0f), F(0.0f));
    const Vec4<F> own = fetch_id(f, kDense, slot, width);
    const Vec4<F> none = {F(fallback.x), F(fallback.y), F(fallback.z), F(fallback.w)};
    f.out(0) = select(marked, own, none);
  }
};

}  // namespace kernels
