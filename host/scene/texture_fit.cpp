// Textures fitted to a profile (host/scene/texture_fit.h).
#include "host/scene/texture_fit.h"

#include <stb_image.h>

#include <algorithm>
#include <climits>

namespace host {

std::optional<glm::ivec2> image_header_size(const std::vector<unsigned char>& bytes) {
  if (bytes.size() > size_t(INT_MAX)) return std::nullopt;
  int w = 0, h = 0, channels = 0;
  if (stbi_info_from_memory(bytes.data(), int(bytes.size()), &w, &h, &channels) && w > 0 && h > 0)
    return glm::ivec2(w, h);
  // stb_image refuses sides past 2^24, the very images that must be refused by size: PNG
  // states its size in the first chunk, IHDR (8-byte signature, 4-byte length, "IHDR", then
  // width and height as big-endian 32-bit numbers).
  static const unsigned char kPng[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (bytes.size() < 24 || !std::equal(kPng, kPng + 8, bytes.begin()) ||
      !std::equal(bytes.begin() + 12, bytes.begin() + 16, "IHDR"))
    return std::nullopt;
  auto be32 = [&](size_t at) {
    return uint32_t(bytes[at]) << 24 | uint32_t(bytes[at + 1]) << 16 |
           uint32_t(bytes[at + 2]) << 8 | uint32_t(bytes[at + 3]);
  };
  const uint32_t pw = be32(16), ph = be32(20);
  if (pw == 0 || ph == 0 || pw > uint32_t(INT_MAX) || ph > uint32_t(INT_MAX)) return std::nullopt;
  return glm::ivec2(int(pw), int(ph));
}

glm::ivec2 halved(glm::ivec2 base, int k) {
  for (int i = 0; i < k; ++i) base = glm::max(glm::ivec2(1), base / 2);
  return base;
}

std::vector<glm::ivec2> chain_sizes(glm::ivec2 base) {
  std::vector<glm::ivec2> sizes{base};
  while (sizes.back().x > 1 || sizes.back().y > 1) sizes.push_back(halved(sizes.back(), 1));
  return sizes;
}

AtlasLayout layout_atlas(const std::vector<glm::ivec2>& bases, int max_width) {
  AtlasLayout atlas;
  int x = 0, y = 0, shelf = 0;
  for (const glm::ivec2 base : bases) {
    const std::vector<glm::ivec2> l = chain_sizes(base);
    int stack = 0;
    for (size_t k = 1; k < l.size(); ++k) stack += l[k].y;
    const int w = l[0].x + (l.size() > 1 ? l[1].x : 0);
    const int h = std::max(l[0].y, stack);
    if (x > 0 && x + w > max_width) {
      y += shelf;
      x = 0;
      shelf = 0;
    }
    std::vector<glm::ivec4> rects{{x, y, l[0].x, l[0].y}};
    int ly = y;
    for (size_t k = 1; k < l.size(); ++k) {
      rects.push_back({x + l[0].x, ly, l[k].x, l[k].y});
      ly += l[k].y;
    }
    atlas.rects.push_back(std::move(rects));
    x += w;
    shelf = std::max(shelf, h);
    atlas.width = std::max(atlas.width, x);
  }
  atlas.height = y + shelf;
  return atlas;
}

std::vector<int> fit_halvings(const std::vector<glm::ivec2>& bases, int max_size) {
  std::vector<int> k(bases.size(), 0);
  std::vector<glm::ivec2> now = bases;
  for (;;) {
    const AtlasLayout a = layout_atlas(now, max_size);
    if (a.width <= max_size && a.height <= max_size) return k;
    size_t pick = now.size();
    for (size_t i = 0; i < now.size(); ++i) {
      const int64_t area = int64_t(now[i].x) * now[i].y;
      if (area > 1 && (pick == now.size() || area > int64_t(now[pick].x) * now[pick].y)) pick = i;
    }
    if (pick == now.size()) return k;  // every texture is 1x1: the caller refuses
    ++k[pick];
    now[pick] = halved(now[pick], 1);
  }
}

std::vector<glm::vec4> halve(const std::vector<glm::vec4>& src, int width, int height) {
  return halve_from([&](int x, int y) { return src[size_t(y) * size_t(width) + size_t(x)]; }, width,
                    height);
}

}  // namespace host
