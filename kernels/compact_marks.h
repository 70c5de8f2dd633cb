// Sampling that saves time (an extension, issue 35): a gated sample frame traces only the
// pixels its marks flag, so the marked pixels are packed into a dense stream first and the frame's
// passes draw only the rows that stream fills. Three kernels around the usual frame, with the
// stream reduction of glass's ray streams (Horn, GPU Gems 2 ch. 36; sumaPrefijos scans the
// marks):
//   compactarMarcados    stream slot j finds the j-th marked pixel by a binary search over the
//                        inclusive prefix sums of the marks, and writes that pixel's centre;
//   generadorRayosDensos the sample rays of those pixel centres, one per slot, several samples
//                        of a level in one stream (the same rays generadorRayosMuestra gives
//                        the marked pixels, to the bit);
//   acumularDensos       after the frame, each marked pixel adds its slot's colour for one
//                        sample to its sum: a gather, no scatter;
//   reunirMarcados       the same gather for the primary hits, where a frame keeps them.
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
    // The first pixel whose inclusive sum passes j is the j-th marked one.
    F u, v;
    id_to_texel(scan_search(f, kScan, j, sources, steps, width), width, u, v);
    const F zero = F(0.0f);
    f.out(0) = select(j < F(count), Vec4<F>{u, v, zero, F(1.0f)}, Vec4<F>{zero, zero, zero, zero});
  }
};

// generadorRayosMuestra for a dense stream of several samples: slot s holds sample k of the j-th
// marked pixel, s = k m + j (m marked pixels, sample-major: a whole sample's pixels, then the
// next sample's). Its ray goes through that pixel's centre (compactarMarcados') moved by sample
// k's offset from the jitter table, as generadorRayosMuestra's uniform moves the whole frame.
// Slots past `count` get no ray (tmax -1).
struct GenerateDenseRays : GenerateRays {
  static constexpr const char* name = "generate dense rays";
  static constexpr const char* paper_name = "generadorRayosDensos (extension)";
  enum Unit { kPixels, kJitters };
  static constexpr std::array<const char*, 2> units{"pixels", "jitters"};

  float stream_width = 1;  // the stream's (and image's) width, texels
  float marked = 1;        // m, the marked pixels
  float count = 0;         // live slots: m times the samples this frame traces
  float first = 0;         // the jitter table's entry of this frame's first sample
  float table_width = 1;   // the jitter table's width, texels (entry k: x - 0.5, y - 0.5)

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const F s = stream_index(f.x, f.y, stream_width);
    // k = floor(s / m), exact while s stays far below 2^23 (the tracer checks the size).
    const F k = floor((s + F(0.5f)) / F(marked));
    const Vec4<F> p = fetch_id(f, kPixels, s - k * F(marked), stream_width);
    const Vec4<F> j = fetch_id(f, kJitters, k + F(first), table_width);
    Vec4<F> ray = ray_through<L>(p.x + j.x, p.y + j.y);
    ray.w = select(s < F(count), ray.w, F(kNone));
    f.out(0) = ray;
  }
};

// acumularMuestras for a dense stream: a marked pixel adds the colour of its slot for sample k,
// k m + (its inclusive sum - 1), to its sum, exactly as acumularMuestras adds a gated frame's
// (`restart`: the level's first sample replaces the earlier ones); the others keep their sum.
struct AccumulateDense {
  static constexpr const char* name = "accumulate dense samples";
  static constexpr const char* paper_name = "acumularDensos (extension)";
  static constexpr int outputs = 1;  // -> sample sum
  enum Unit { kSum, kMarks, kScan, kDense };
  static constexpr std::array<const char*, 4> units{"sample_sum", "marks", "scan", "dense"};

  float width = 1;  // image width = the stream's width, texels
  float base = 0;   // k m: the first slot of this sample in the frame's stream
  bool restart = false;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> sum = f.fetch_own(kSum);
    const auto marked = f.fetch_own(kMarks).x > F(0.0f);
    const F slot = F(base) + max(f.fetch_own(kScan).x - F(1.0f), F(0.0f));
    const Vec4<F> c = fetch_id(f, kDense, slot, width);
    const Vec4<F> from = restart ? Vec4<F>{F(0.0f), F(0.0f), F(0.0f), F(0.0f)} : sum;
    const Vec4<F> added = {from.x + c.x, from.y + c.y, from.z + c.z, from.w + F(1.0f)};
    f.out(0) = select(marked, added, sum);
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
