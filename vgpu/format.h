// Texel and arithmetic number formats of 2004-era fragment pipelines.
// A store into a texture rounds to the texture's format exactly as that hardware would, so
// precision loss in the emulator is the hardware's loss, not simulated noise.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <string_view>

namespace vgpu {

enum class Format : uint8_t {
  fp32,  // IEEE binary32: NV3x "float", NV4x, every later GPU
  fp24,  // 1 sign, 7 exponent, 16 mantissa bits: ATI R300 (Radeon 9700) shader precision
  fp16,  // IEEE binary16 (s10e5): NV3x "half"
};

// Bytes one channel of this format occupies in texture memory. R300 had no fp24 texture
// format: fp24 values live in 32-bit texels, only the arithmetic is 24-bit.
constexpr int bytes_per_channel(Format f) {
  return f == Format::fp16 ? 2 : 4;
}

constexpr std::string_view format_name(Format f) {
  return f == Format::fp32 ? "fp32" : f == Format::fp24 ? "fp24" : "fp16";
}

// Round a binary32 value to IEEE binary16 (round to nearest, ties to even), returned as the
// binary32 value it represents. Gradual underflow to subnormals, overflow to infinity.
inline float round_fp16(float v) {
  uint32_t b = std::bit_cast<uint32_t>(v);
  const uint32_t sign = b & 0x80000000u;
  const uint32_t mag = b & 0x7fffffffu;
  if (mag >= 0x7f800000u) return v;  // inf and NaN pass through
  // 65520 = max half (65504) + half an ulp: at or above it rounds to infinity.
  if (mag >= 0x477ff000u) return std::bit_cast<float>(sign | 0x7f800000u);
  if (mag < 0x38800000u) {
    // Below the smallest normal half (2^-14): quantise to multiples of 2^-24 (RNE).
    const float q = std::nearbyint(std::bit_cast<float>(mag) * 16777216.0f) / 16777216.0f;
    return std::bit_cast<float>(sign | std::bit_cast<uint32_t>(q));
  }
  // Normal: keep 10 of 23 mantissa bits, ties to even.
  const uint32_t drop = 13, half = 1u << (drop - 1), lsb = (mag >> drop) & 1u;
  const uint32_t r = (mag + half - 1 + lsb) & ~((1u << drop) - 1);
  return std::bit_cast<float>(sign | r);
}

// Round a binary32 value to R300 fp24 (s7e16, exponent bias 63), as a binary32 value.
// Model choices (no public bit-exact spec): ties to even; values below the smallest normal
// (2^-62) flush to signed zero (R300 has no denormals); overflow past 2^64 goes to infinity.
inline float round_fp24(float v) {
  uint32_t b = std::bit_cast<uint32_t>(v);
  const uint32_t sign = b & 0x80000000u;
  const uint32_t mag = b & 0x7fffffffu;
  if (mag >= 0x7f800000u) return v;
  const int exp = int(mag >> 23) - 127;
  if (exp < -62) return std::bit_cast<float>(sign);
  const uint32_t drop = 7, half = 1u << (drop - 1), lsb = (mag >> drop) & 1u;
  const uint32_t r = (mag + half - 1 + lsb) & ~((1u << drop) - 1);
  if (int(r >> 23) - 127 > 63) return std::bit_cast<float>(sign | 0x7f800000u);
  return std::bit_cast<float>(sign | r);
}

inline float round_to(Format f, float v) {
  switch (f) {
    case Format::fp16:
      return round_fp16(v);
    case Format::fp24:
      return round_fp24(v);
    default:
      return v;
  }
}

}  // namespace vgpu
