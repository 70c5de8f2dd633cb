// Textures and texture units: stores round to the texture's format; texRECT samples the nearest
// texel at integer coordinates, clamps at the edges, and fills missing channels with (0, 0, 0, 1).
#include <doctest/doctest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "helpers.h"
#include "vgpu/vgpu.h"

using namespace vgpu;
using vgpu_test::Copy;
using vgpu_test::Lookup;

namespace {

const float kInf = std::numeric_limits<float>::infinity();
const float kNaN = std::numeric_limits<float>::quiet_NaN();

// Samples `source` at each (u, v) with the Lookup kernel; returns the fetched texels.
std::vector<std::array<float, 4>> sample(const Texture& source,
                                         const std::vector<std::pair<float, float>>& uv,
                                         int lanes = kLanes) {
  Gpu gpu(profile("gf5700"), 1, lanes);
  Texture coords = gpu.make_texture("coords", int(uv.size()), 1, 2);
  for (size_t i = 0; i < uv.size(); ++i) {
    coords.set(int(i), 0, 0, uv[i].first);
    coords.set(int(i), 0, 1, uv[i].second);
  }
  Texture out = gpu.make_texture("out", int(uv.size()), 1, 4);
  KernelProgram<Lookup> lookup;
  gpu.use_program(lookup);
  gpu.bind_texture(0, source);
  gpu.bind_texture(1, coords);
  gpu.set_targets({&out});
  gpu.draw();
  std::vector<std::array<float, 4>> r(uv.size());
  for (size_t i = 0; i < uv.size(); ++i)
    for (int c = 0; c < 4; ++c) r[i][size_t(c)] = out.get(int(i), 0, c);
  return r;
}

// A 5x3 texture whose texel (x, y) holds (x, y, 10 x + y, -1).
Texture numbered(int channels = 4) {
  Texture t("numbered", 5, 3, channels);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) {
      const float texel[4] = {float(x), float(y), float(10 * x + y), -1.0f};
      for (int c = 0; c < channels; ++c) t.set(x, y, c, texel[c]);
    }
  return t;
}

}  // namespace

TEST_CASE("texture stores from the host round to the texture's format") {
  const float third = 1.0f / 3.0f;
  for (Format fmt : {Format::fp32, Format::fp24, Format::fp16}) {
    CAPTURE(format_name(fmt));
    Texture t("t", 2, 2, 3, fmt);
    t.set(1, 1, 2, third);
    CHECK(t.get(1, 1, 2) == round_to(fmt, third));
    CHECK(t.get(0, 0, 0) == 0.0f);  // new textures are zero
    const float texel[3] = {third, 65520.0f, 1.0f + 0x1p-11f};
    t.fill(texel);
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x)
        for (int c = 0; c < 3; ++c) CHECK(t.get(x, y, c) == round_to(fmt, texel[c]));
  }
  Texture h("h", 1, 1, 1, Format::fp16);
  h.set(0, 0, 0, 65520.0f);
  CHECK(h.get(0, 0) == kInf);
}

TEST_CASE("render-target stores round to the target's format") {
  Gpu gpu(profile("gf5700"), 1);
  Texture src = gpu.make_texture("src", 3, 1, 4);
  const float values[3][4] = {{1.0f / 3.0f, 0.1f, 65520.0f, 1.0f + 3 * 0x1p-17f},
                              {1.0f + 0x1p-11f, 0x1p-25f, 0x1p-63f, -2.0f / 3.0f},
                              {kNaN, -kInf, 1e30f, 0x1p-24f}};
  for (int x = 0; x < 3; ++x)
    for (int c = 0; c < 4; ++c) src.set(x, 0, c, values[x][c]);
  KernelProgram<Copy> copy;
  gpu.use_program(copy);
  gpu.bind_texture(0, src);
  for (Format fmt : {Format::fp32, Format::fp24, Format::fp16}) {
    CAPTURE(format_name(fmt));
    Texture dst = gpu.make_texture("dst", 3, 1, 4, fmt);
    gpu.set_targets({&dst});
    gpu.draw();
    for (int x = 0; x < 3; ++x)
      for (int c = 0; c < 4; ++c) {
        const float want = round_to(fmt, values[x][c]);
        if (std::isnan(want))
          CHECK(std::isnan(dst.get(x, 0, c)));
        else
          CHECK(dst.get(x, 0, c) == want);
      }
  }
  Texture h = gpu.make_texture("h", 3, 1, 4, Format::fp16);
  gpu.set_targets({&h});
  gpu.draw();
  CHECK(h.get(0, 0, 0) == 0.333251953125f);
  CHECK(h.get(0, 0, 2) == kInf);
  CHECK(h.get(1, 0, 0) == 1.0f);
  CHECK(h.get(1, 0, 1) == 0.0f);
  Texture q = gpu.make_texture("q", 3, 1, 4, Format::fp24);
  gpu.set_targets({&q});
  gpu.draw();
  CHECK(q.get(0, 0, 0) == 0x1.5555p-2f);
  CHECK(q.get(0, 0, 3) == 1.0f + 0x1p-15f);
  CHECK(q.get(1, 0, 2) == 0.0f);
  CHECK(q.get(2, 0, 2) == kInf);
}

TEST_CASE("texRECT samples the nearest texel: floor of each integer-texel coordinate") {
  const Texture t = numbered();
  for (int lanes : {1, 8}) {
    CAPTURE(lanes);
    const auto r = sample(
        t,
        {{0.5f, 0.5f}, {2.0f, 1.0f}, {2.999f, 1.999f}, {3.0f, 0.0f}, {4.5f, 2.5f}, {1.25f, 2.75f}},
        lanes);
    const int want[6][2] = {{0, 0}, {2, 1}, {2, 1}, {3, 0}, {4, 2}, {1, 2}};
    for (int i = 0; i < 6; ++i) {
      CAPTURE(i);
      CHECK(r[size_t(i)][0] == float(want[i][0]));
      CHECK(r[size_t(i)][1] == float(want[i][1]));
      CHECK(r[size_t(i)][2] == float(10 * want[i][0] + want[i][1]));
      CHECK(r[size_t(i)][3] == -1.0f);
    }
  }
}

TEST_CASE("texRECT clamps coordinates outside the texture, NaN and infinities to the edges") {
  const Texture t = numbered();
  for (int lanes : {1, 4, 8, 16}) {
    CAPTURE(lanes);
    const auto r = sample(t,
                          {{-0.5f, 1.5f},
                           {-100.0f, -100.0f},
                           {5.0f, 1.0f},
                           {1e9f, 3.0f},
                           {kNaN, 1.5f},
                           {2.5f, kNaN},
                           {kInf, -kInf},
                           {-kInf, kInf},
                           {4.999f, 2.999f}},
                          lanes);
    const int want[9][2] = {{0, 1}, {0, 0}, {4, 1}, {4, 2}, {0, 1}, {2, 0}, {4, 0}, {0, 2}, {4, 2}};
    for (int i = 0; i < 9; ++i) {
      CAPTURE(i);
      CHECK(r[size_t(i)][0] == float(want[i][0]));
      CHECK(r[size_t(i)][1] == float(want[i][1]));
    }
  }
}

TEST_CASE("texRECT at scattered coordinates reads at every width what the scalar path reads") {
  // Widths 8 and 16 load whole texels by vector indices (texels::gather); width 1 is the scalar
  // reference. Coordinates in and out of range, NaN, and the last texel, whose 16-byte load would
  // run past the end of a 3-channel texture, in every lane position.
  std::vector<std::pair<float, float>> uv;
  const float us[] = {4.5f, 0.5f, 2.25f, -3.0f, 9.0f, kNaN, 4.0f, 3.999f, 1.5f, kInf, 4.75f};
  const float vs[] = {2.5f, 0.0f, 1.75f, -kInf, 2.0f, 7.5f, kNaN, 2.999f};
  for (int i = 0; i < 43; ++i) uv.push_back({us[i % 11], vs[(i * 3) % 8]});
  for (int channels = 1; channels <= 4; ++channels) {
    CAPTURE(channels);
    const Texture t = numbered(channels);
    const auto want = sample(t, uv, 1);
    for (int lanes : {4, 8, 16}) {
      CAPTURE(lanes);
      const auto got = sample(t, uv, lanes);
      for (size_t i = 0; i < uv.size(); ++i)
        for (size_t c = 0; c < 4; ++c) {
          CAPTURE(i);
          CAPTURE(c);
          CHECK(std::bit_cast<uint32_t>(got[i][c]) == std::bit_cast<uint32_t>(want[i][c]));
        }
    }
  }
  // The last texel of the 3-channel texture itself, at width 8: (4, 2, 42) and w = 1.
  const auto last = sample(numbered(3), {{0.5f, 0.5f}, {4.5f, 2.5f}, {1e9f, 1e9f}}, 8);
  for (size_t i : {size_t(1), size_t(2)}) {
    CAPTURE(i);
    CHECK(last[i][0] == 4.0f);
    CHECK(last[i][1] == 2.0f);
    CHECK(last[i][2] == 42.0f);
    CHECK(last[i][3] == 1.0f);
  }
  CHECK(last[0][2] == 0.0f);
}

TEST_CASE("channels a texture lacks read as (0, 0, 0, 1)") {
  for (int channels = 1; channels <= 4; ++channels) {
    CAPTURE(channels);
    const auto r = sample(numbered(channels), {{3.5f, 2.5f}});
    const float full[4] = {3.0f, 2.0f, 32.0f, -1.0f};
    const float missing[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    for (int c = 0; c < 4; ++c) CHECK(r[0][size_t(c)] == (c < channels ? full[c] : missing[c]));
  }
}

TEST_CASE("a fragment's own texel is the texel under its pixel centre, at every width") {
  for (int channels = 1; channels <= 4; ++channels)
    for (int lanes : {1, 4, 8, 16}) {
      CAPTURE(channels);
      CAPTURE(lanes);
      Gpu gpu(profile("gf6600"), 1, lanes);
      Texture src = gpu.make_texture("src", 37, 5, channels);
      vgpu_test::fill_pattern(src, 42);
      Texture dst = gpu.make_texture("dst", 37, 5, channels);
      KernelProgram<Copy> copy;
      gpu.use_program(copy);
      gpu.bind_texture(0, src);
      gpu.set_targets({&dst});
      gpu.draw();
      CHECK(vgpu_test::same_bits(src, dst));
      dst.fill(std::array{9.0f, 9.0f, 9.0f, 9.0f});
      gpu.draw(Rect{5, 1, 30, 4});  // batches that start mid-row
      CHECK(dst.get(4, 1) == 9.0f);
      CHECK(dst.get(30, 3) == 9.0f);
      bool same = true;
      for (int y = 1; y < 4; ++y)
        for (int x = 5; x < 30; ++x)
          same = same && std::memcmp(src.texel(x, y), dst.texel(x, y),
                                     sizeof(float) * size_t(channels)) == 0;
      CHECK(same);
    }
}

TEST_CASE("textures know their size in texture memory and reject impossible shapes") {
  CHECK(Texture("a", 4, 2, 4).bytes_per_texel() == 16);
  CHECK(Texture("a", 4, 2, 4).bytes() == 128);
  CHECK(Texture("a", 4, 2, 3, Format::fp16).bytes_per_texel() == 6);
  CHECK(Texture("a", 4, 2, 1, Format::fp24).bytes_per_texel() == 4);
  CHECK(Texture("a", 4, 2, 2, Format::fp16).bytes() == 32);
  CHECK_THROWS_AS(Texture("a", 4, 2, 0), std::invalid_argument);
  CHECK_THROWS_AS(Texture("a", 4, 2, 5), std::invalid_argument);
  CHECK_THROWS_AS(Texture("a", 0, 2, 4), std::invalid_argument);
  Texture t("t", 3, 2, 2);
  t.set(2, 1, 1, 5.0f);
  CHECK(t.index(2, 1) == size_t((1 * 3 + 2) * 2));
  CHECK(t.texel(2, 1)[1] == 5.0f);
  CHECK(t.data()[t.index(2, 1) + 1] == 5.0f);
}

TEST_CASE("a stencil counts its non-zero pixels") {
  Stencil s(4, 3, 0);
  CHECK(s.count() == 0);
  s.set(1, 2, 1);
  s.set(3, 0, 7);
  CHECK(s.count() == 2);
  CHECK(s.get(3, 0) == 7);
  CHECK(s.row(2)[1] == 1);
  s.fill(1);
  CHECK(s.count() == 12);
}
