// Number formats: fp16 (IEEE binary16) and fp24 (R300 s7e16) rounding against known values.
#include <doctest/doctest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <ios>
#include <limits>

#include "tests/support/bits.h"
#include "vgpu/format.h"

using vgpu::Format;
using vgpu::round_fp16;
using vgpu::round_fp24;

using test_support::same_bits;

namespace {

const float kInf = std::numeric_limits<float>::infinity();
const float kNaN = std::numeric_limits<float>::quiet_NaN();

// Exact equality of bits: tells +0 from -0, which == does not.
}  // namespace

TEST_CASE("fp16 stores round to the nearest binary16, ties to even") {
  CHECK(round_fp16(1.0f / 3.0f) == 0.333251953125f);  // 0x3555
  CHECK(round_fp16(0.1f) == 0.0999755859375f);        // 0x2e66
  CHECK(round_fp16(1.0f) == 1.0f);
  CHECK(round_fp16(2048.0f + 1.0f) == 2048.0f);  // tie: 2048 is even, 2050 odd
  CHECK(round_fp16(2048.0f + 3.0f) == 2052.0f);  // tie: 2052 is even
  SUBCASE("a tie one half-ulp above 1 goes down to the even 1") {
    CHECK(round_fp16(1.0f + 0x1p-11f) == 1.0f);
  }
  SUBCASE("a tie three half-ulps above 1 goes up to the even 1 + 2^-9") {
    CHECK(round_fp16(1.0f + 3 * 0x1p-11f) == 1.0f + 0x1p-9f);
  }
  SUBCASE("just above a tie rounds up") {
    CHECK(round_fp16(std::nextafter(1.0f + 0x1p-11f, 2.0f)) == 1.0f + 0x1p-10f);
  }
}

TEST_CASE("fp16 holds 65504 at most and rounds 65520 and above to infinity") {
  CHECK(round_fp16(65504.0f) == 65504.0f);
  CHECK(round_fp16(65519.0f) == 65504.0f);
  CHECK(round_fp16(65520.0f) == kInf);
  CHECK(round_fp16(1e10f) == kInf);
  CHECK(round_fp16(-65520.0f) == -kInf);
  CHECK(round_fp16(-65504.0f) == -65504.0f);
}

TEST_CASE("fp16 underflows gradually to subnormals in steps of 2^-24") {
  CHECK(round_fp16(0x1p-14f) == 0x1p-14f);                // smallest normal
  CHECK(round_fp16(1023 * 0x1p-24f) == 1023 * 0x1p-24f);  // largest subnormal
  CHECK(round_fp16(0x1p-24f) == 0x1p-24f);                // smallest subnormal
  CHECK(round_fp16(0x1.8p-24f) == 0x1p-23f);              // 1.5 ulp: tie to the even 2 ulps
  CHECK(round_fp16(3 * 0x1p-25f) == 0x1p-23f);            // the same tie, written as 3 * 2^-25
  CHECK(round_fp16(0x1.4p-24f) == 0x1p-24f);              // 1.25 ulp rounds down
  CHECK(same_bits(round_fp16(0x1p-25f), 0.0f));           // half an ulp: tie to the even 0
  CHECK(round_fp16(std::nextafter(0x1p-25f, 1.0f)) == 0x1p-24f);
  CHECK(same_bits(round_fp16(1e-10f), 0.0f));
  CHECK(round_fp16(1e-40f) == 0.0f);  // binary32 subnormal
}

TEST_CASE("fp16 rounding is symmetric in the sign and keeps the sign of zero") {
  CHECK(round_fp16(-1.0f / 3.0f) == -0.333251953125f);
  CHECK(round_fp16(-(1.0f + 3 * 0x1p-11f)) == -(1.0f + 0x1p-9f));
  CHECK(round_fp16(-0x1p-24f) == -0x1p-24f);
  CHECK(same_bits(round_fp16(-0x1p-25f), -0.0f));
  CHECK(same_bits(round_fp16(-0.0f), -0.0f));
  CHECK(same_bits(round_fp16(0.0f), 0.0f));
}

TEST_CASE("fp16 keeps NaN a NaN and infinities infinite") {
  CHECK(std::isnan(round_fp16(kNaN)));
  CHECK(std::isnan(round_fp16(-kNaN)));
  CHECK(round_fp16(kInf) == kInf);
  CHECK(round_fp16(-kInf) == -kInf);
}

TEST_CASE("fp16 rounding leaves every binary16 value unchanged") {
  // All 63488 finite binary16 values, built from their bits.
  int checked = 0;
  for (uint32_t h = 0; h < 0x10000u; ++h) {
    const uint32_t e = (h >> 10) & 31, m = h & 1023;
    if (e == 31) continue;
    const float mag =
        e == 0 ? float(m) * 0x1p-24f : std::ldexp(1.0f + float(m) / 1024.0f, int(e) - 15);
    const float v = (h & 0x8000u) ? -mag : mag;
    if (!same_bits(round_fp16(v), v)) {
      FAIL_CHECK("binary16 0x" << std::hex << h << " changed");
      break;
    }
    ++checked;
  }
  CHECK(checked == 63488);
}

TEST_CASE("fp24 stores keep 16 mantissa bits, ties to even") {
  CHECK(round_fp24(1.0f + 0x1p-17f) == 1.0f);                 // tie down to even
  CHECK(round_fp24(1.0f + 3 * 0x1p-17f) == 1.0f + 0x1p-15f);  // tie up to even
  CHECK(round_fp24(1.0f + 0x1p-16f) == 1.0f + 0x1p-16f);      // representable
  CHECK(round_fp24(std::nextafter(1.0f + 0x1p-17f, 2.0f)) == 1.0f + 0x1p-16f);
  CHECK(round_fp24(1.0f / 3.0f) == 0x1.5555p-2f);  // 0.0101...01 (17 bits) x 2^-1
  CHECK(round_fp24(2.0f / 3.0f) == 0x1.5555p-1f);
  CHECK(round_fp24(0.1f) == 0x1.999ap-4f);  // 0x1.99999ap-4 rounds up
  CHECK(round_fp24(-1.0f / 3.0f) == -0x1.5555p-2f);
}

TEST_CASE("fp24 flushes magnitudes below 2^-62 to a signed zero") {
  CHECK(round_fp24(0x1p-62f) == 0x1p-62f);  // smallest normal (exponent bias 63)
  CHECK(same_bits(round_fp24(0x1.fffffep-63f), 0.0f));
  CHECK(same_bits(round_fp24(0x1p-63f), 0.0f));
  CHECK(same_bits(round_fp24(-0x1p-70f), -0.0f));
  CHECK(same_bits(round_fp24(1e-40f), 0.0f));
  CHECK(same_bits(round_fp24(-0.0f), -0.0f));
}

TEST_CASE("fp24 overflows past its largest value to infinity") {
  const float largest = 0x1.ffffp63f;  // (2 - 2^-16) x 2^63
  CHECK(round_fp24(largest) == largest);
  CHECK(round_fp24(0x1.ffff7p63f) == largest);  // below the tie
  CHECK(round_fp24(0x1.ffff8p63f) == kInf);     // the tie with 2^64 goes to the even 2^64
  CHECK(round_fp24(0x1p64f) == kInf);
  CHECK(round_fp24(1e30f) == kInf);
  CHECK(round_fp24(-1e30f) == -kInf);
}

TEST_CASE("fp24 keeps NaN a NaN and infinities infinite") {
  CHECK(std::isnan(round_fp24(kNaN)));
  CHECK(round_fp24(kInf) == kInf);
  CHECK(round_fp24(-kInf) == -kInf);
}

TEST_CASE("fp32 stores are exact and formats name their size in texture memory") {
  CHECK(same_bits(vgpu::round_to(Format::fp32, 1.0f / 3.0f), 1.0f / 3.0f));
  CHECK(std::isnan(vgpu::round_to(Format::fp32, kNaN)));
  CHECK(vgpu::round_to(Format::fp16, 1.0f / 3.0f) == round_fp16(1.0f / 3.0f));
  CHECK(vgpu::round_to(Format::fp24, 1.0f / 3.0f) == round_fp24(1.0f / 3.0f));
  CHECK(vgpu::bytes_per_channel(Format::fp32) == 4);
  CHECK(vgpu::bytes_per_channel(Format::fp24) == 4);  // R300 kept fp24 values in 32-bit texels
  CHECK(vgpu::bytes_per_channel(Format::fp16) == 2);
  CHECK(vgpu::format_name(Format::fp32) == "fp32");
  CHECK(vgpu::format_name(Format::fp24) == "fp24");
  CHECK(vgpu::format_name(Format::fp16) == "fp16");
}
