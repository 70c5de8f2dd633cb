// One program on one batch of fragments whose texels stay in registers (vgpu/batch.h).
#include "vgpu/batch.h"

#include <cstring>
#include <type_traits>

#include "vgpu/fragment.h"
#include "vgpu/precision.h"

namespace vgpu {

namespace {

constexpr int W = kBatchWidth;

using V8 = float __attribute__((vector_size(32)));
using V8i = int32_t __attribute__((vector_size(32)));

inline V8 load(const float* p) {
  V8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void save(float* p, V8 v) {
  std::memcpy(p, &v, sizeof v);
}
// Lane i of the mask: bit i of `bits`, as all ones or zero.
inline V8i lanes_of(uint8_t bits) {
  const V8i bit{1, 2, 4, 8, 16, 32, 64, 128};
  return ((V8i{} + int32_t(bits)) & bit) != 0;
}

// A lane mask as bits and back. Where the mask is one vector of 32-bit lanes (all ones or zero),
// one movemask or one compare; otherwise lane by lane.
template <class M>
inline uint8_t bits_of(const M& m) {
  if constexpr (sizeof(M) == sizeof(V8i) && std::is_trivially_copyable_v<M>) {
    V8 v;
    std::memcpy(&v, &m, sizeof v);
    return uint8_t(__builtin_ia32_movmskps256(v));
  } else {
    bool b[W];
    m.copy_to(b, stdx::element_aligned);
    uint8_t r = 0;
    for (int i = 0; i < W; ++i) r |= uint8_t(uint8_t(b[i]) << i);
    return r;
  }
}
template <class M>
inline M mask_of(uint8_t bits) {
  if constexpr (sizeof(M) == sizeof(V8i) && std::is_trivially_copyable_v<M>) {
    const V8i v = lanes_of(bits);
    M m;
    std::memcpy(static_cast<void*>(&m), &v, sizeof m);
    return m;
  } else {
    bool b[W];
    for (int i = 0; i < W; ++i) b[i] = (bits >> i) & 1;
    return M(b, stdx::element_aligned);
  }
}

template <class L>
BatchRun run_as(const Program& p, bool dynamic, const BoundTexture* units,
                const BatchOutput* outputs, int nout, uint8_t live_bits, int x0, int y) {
  static_assert(L::width == W);
  using F = typename L::F;
  using M = typename L::M;
  BatchRun r;
  Fragments<L> f(units, dynamic, &r.lanes_idle, nullptr);
  const M live = mask_of<M>(live_bits);
  f.reset(F([](auto i) { return float(i); }) + float(x0) + 0.5f, F(float(y) + 0.5f), live,
          p.outputs());
  p.run(f);
  const uint8_t idle_bits = bits_of(f.idle_lanes());
  r.killed = bits_of(f.killed()) & live_bits;
  r.idle = idle_bits & live_bits;
  r.took = live_bits & ~idle_bits;
  // As Gpu::draw() stores: a fragment that ran and survived writes its output, rounded to the
  // target's format; one that did not run keeps the passthrough's texel (rounded where that is
  // a wider format) unless the program discards such fragments; a discarded one writes nothing.
  const V8i write = lanes_of(uint8_t(live_bits & ~r.killed));
  for (int o = 0; o < nout; ++o) {
    const BatchOutput& out = outputs[o];
    Slot& dst = *out.slot;
    const Format fmt = dst.texture->format();
    const int ch = dst.texture->channels();
    alignas(32) float val[4][W];
    const Vec4<F>& v = f.output(o);
    v.x.copy_to(val[0], stdx::element_aligned);
    v.y.copy_to(val[1], stdx::element_aligned);
    v.z.copy_to(val[2], stdx::element_aligned);
    v.w.copy_to(val[3], stdx::element_aligned);
    const bool copy_idle = out.idle_source != nullptr;
    const bool exact_idle =
        copy_idle && (out.idle_source->texture->format() == fmt || fmt == Format::fp32);
    const V8i idle_copy = copy_idle ? lanes_of(uint8_t(~live_bits)) : V8i{};
    for (int c = 0; c < ch; ++c) {
      if (fmt != Format::fp32)
        for (int i = 0; i < W; ++i) val[c][i] = round_to(fmt, val[c][i]);
      V8 src = copy_idle ? load(out.idle_source->v[c]) : V8{};
      if (copy_idle && !exact_idle) {
        alignas(32) float rounded[W];
        save(rounded, src);
        for (int i = 0; i < W; ++i) rounded[i] = round_to(fmt, rounded[i]);
        src = load(rounded);
      }
      const V8 old = load(dst.v[c]);
      save(dst.v[c], write ? load(val[c]) : (idle_copy ? src : old));
    }
  }
  return r;
}

}  // namespace

void Slot::load(const Texture& t, int x0, int y, int n) {
  texture = &t;
  const int ch = t.channels();
  if (ch == 4 && n == W) {  // the usual case: 8 whole texels, one transpose
    texels::split8(t.texel(x0, y), v[0], v[1], v[2], v[3]);
    return;
  }
  for (int c = 0; c < 4; ++c)
    for (int i = 0; i < W; ++i) v[c][i] = c == 3 ? 1.0f : 0.0f;
  const float* d = t.texel(x0, y);
  for (int i = 0; i < W; ++i) {
    const int k = i < n ? i : 0;
    for (int c = 0; c < ch; ++c) v[c][i] = d[k * ch + c];
  }
}

void Slot::store(const Texture& t, float* data, int x0, int y, int n) const {
  const int ch = t.channels();
  float* d = data + t.index(x0, y);
  if (ch == 4 && n == W) {
    texels::join8(v[0], v[1], v[2], v[3], d);
    return;
  }
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < ch; ++c) d[i * ch + c] = v[c][i];
}

BatchRun run_batch(const Program& p, Format precision, bool dynamic, const BoundTexture* units,
                   const BatchOutput* outputs, int noutputs, uint8_t live, int x0, int y) {
  switch (precision) {
    case Format::fp16:
      return run_as<RoundedLanes<W, Format::fp16>>(p, dynamic, units, outputs, noutputs, live, x0,
                                                   y);
    case Format::fp24:
      return run_as<RoundedLanes<W, Format::fp24>>(p, dynamic, units, outputs, noutputs, live, x0,
                                                   y);
    default:
      return run_as<SimdLanes<W>>(p, dynamic, units, outputs, noutputs, live, x0, y);
  }
}

}  // namespace vgpu
