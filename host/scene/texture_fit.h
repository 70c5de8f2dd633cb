// Textures fitted to what a profile can hold, decided before any image is decoded: each image's
// size read from its header, the atlas's shelf layout (host/trace/textures.h packs the texels
// the same way), and the rule that picks how many times each texture is halved.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <vector>

namespace host {

// The largest image the loader decodes: width * height * 16 bytes (the linear RGBA floats a
// SceneTexture holds per texel) at most 1 GiB, i.e. 8192x8192 texels. A larger image is refused
// from its header, before anything of its size is allocated.
inline constexpr uint64_t kMaxDecodedImageBytes = uint64_t(1) << 30;
inline constexpr uint64_t kDecodedBytesPerTexel = 16;

// An image's width and height as its header states them (PNG's IHDR, a JPEG's start of frame,
// through stb_image's header reader), without decoding it; nullopt when the bytes are neither.
std::optional<glm::ivec2> image_header_size(const std::vector<unsigned char>& bytes);

// The sizes of a mip chain whose level 0 is `base`: each level half as wide and high as the one
// before (rounded down, at least 1), down to 1x1 (GL's rule).
std::vector<glm::ivec2> chain_sizes(glm::ivec2 base);

// `base` halved k times (level k of its chain).
glm::ivec2 halved(glm::ivec2 base, int k);

// Where every chain sits in the atlas: shelves of chains (level 0 with the other levels stacked
// at its right), left to right, a new shelf when a row would pass max_width.
struct AtlasLayout {
  int width = 0, height = 0;
  std::vector<std::vector<glm::ivec4>> rects;  // per texture, per level: x, y, width, height
};
AtlasLayout layout_atlas(const std::vector<glm::ivec2>& bases, int max_width);

// The fitting rule: how many times to halve each texture (its base becomes that level of its
// own mip chain) so that the atlas of every chain is at most max_size texels a side. While the
// atlas is too large, the texture with the most texels in its base (the lowest index among
// equals) is halved once more. Textures already at 1x1 are not halved; if the atlas still does
// not fit, the counts reached are returned and the caller refuses. All zeros when it fits.
std::vector<int> fit_halvings(const std::vector<glm::ivec2>& bases, int max_size);

// One step of the box filter that makes mip levels: texel (i, j) of the result is the mean of
// texels (2i, 2j) .. (2i + 1, 2j + 1) of `texels` (width x height, row-major), clamped to the
// image where a side is 1. The result is max(1, width / 2) x max(1, height / 2).
std::vector<glm::vec4> halve(const std::vector<glm::vec4>& texels, int width, int height);

// The same step reading texel (x, y) through texel(x, y): the loader halves an image straight
// from the decoder's texels, never holding the full-size RGBA floats.
template <class Texel>
std::vector<glm::vec4> halve_from(Texel&& texel, int width, int height) {
  const int w = width / 2 > 1 ? width / 2 : 1, h = height / 2 > 1 ? height / 2 : 1;
  std::vector<glm::vec4> dst(size_t(w) * size_t(h));
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      glm::vec4 sum(0.0f);
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a) {
          const int x = 2 * i + a < width ? 2 * i + a : width - 1;
          const int y = 2 * j + b < height ? 2 * j + b : height - 1;
          sum += texel(x, y);
        }
      dst[size_t(j) * size_t(w) + size_t(i)] = sum * 0.25f;
    }
  return dst;
}

}  // namespace host
