// Mip chains and the texture atlas (host/trace/textures.h).
#include "host/trace/textures.h"

#include <algorithm>
#include <cmath>

#include "host/scene/texture_fit.h"

namespace host {

MipChain build_mip_chain(const SceneTexture& texture) {
  MipChain chain;
  chain.levels.push_back({texture.width, texture.height, texture.texels});
  while (chain.levels.back().width > 1 || chain.levels.back().height > 1) {
    const MipChain::Level& src = chain.levels.back();
    MipChain::Level dst;
    dst.width = std::max(1, src.width / 2);
    dst.height = std::max(1, src.height / 2);
    dst.texels = halve(src.texels, src.width, src.height);  // the fitting's filter too
    chain.levels.push_back(std::move(dst));
  }
  return chain;
}

TextureAtlas pack_atlas(const std::vector<MipChain>& chains, int max_width) {
  std::vector<glm::ivec2> bases;
  for (const MipChain& c : chains) bases.push_back({c.levels[0].width, c.levels[0].height});
  AtlasLayout layout = layout_atlas(bases, max_width);  // the fitting's layout too
  TextureAtlas atlas;
  atlas.width = layout.width;
  atlas.height = layout.height;
  atlas.rects = std::move(layout.rects);
  atlas.texels.assign(size_t(atlas.width) * size_t(atlas.height), glm::vec4(0.0f));
  for (size_t t = 0; t < chains.size(); ++t)
    for (size_t k = 0; k < chains[t].levels.size(); ++k) {
      const MipChain::Level& l = chains[t].levels[k];
      const glm::ivec4 r = atlas.rects[t][k];
      for (int j = 0; j < l.height; ++j)
        std::copy_n(l.texels.begin() + std::ptrdiff_t(size_t(j) * size_t(l.width)), l.width,
                    atlas.texels.begin() +
                        std::ptrdiff_t(size_t(r.y + j) * size_t(atlas.width) + size_t(r.x)));
    }
  return atlas;
}

std::string atlas_refusal(const TextureAtlas& atlas, size_t textures, int max_size,
                          const std::string& profile) {
  const std::string limit = "profile " + profile + " holds at most " + std::to_string(max_size) +
                            "x" + std::to_string(max_size) + " texels in one texture";
  if (atlas.width > max_size || atlas.height > max_size)
    return "the scene's textures need a " + std::to_string(atlas.width) + "x" +
           std::to_string(atlas.height) + " atlas (mip chains included); " + limit;
  if (textures > size_t(max_size))
    return "the scene has " + std::to_string(textures) + " textures, one texture-table row each; " +
           limit;
  return {};
}

namespace {

// vgpu::wrap_texel on integers.
int64_t wrap(int64_t i, int64_t n, WrapMode mode) {
  if (mode == WrapMode::repeat) return ((i % n) + n) % n;
  if (mode == WrapMode::clamp_to_edge) return std::clamp<int64_t>(i, 0, n - 1);
  const int64_t m = ((i % (2 * n)) + 2 * n) % (2 * n);
  return m >= n ? 2 * n - 1 - m : m;
}

glm::dvec4 texel(const MipChain::Level& l, int64_t i, int64_t j) {
  return glm::dvec4(l.texels[size_t(j) * size_t(l.width) + size_t(i)]);
}

glm::dvec4 nearest(const MipChain::Level& l, WrapMode ws, WrapMode wt, double u, double v) {
  const auto i = wrap(int64_t(std::floor(u * l.width)), l.width, ws);
  const auto j = wrap(int64_t(std::floor(v * l.height)), l.height, wt);
  return texel(l, i, j);
}

glm::dvec4 bilinear(const MipChain::Level& l, WrapMode ws, WrapMode wt, double u, double v) {
  const double x = u * l.width - 0.5, y = v * l.height - 0.5;
  const double x0 = std::floor(x), y0 = std::floor(y);
  const double fx = x - x0, fy = y - y0;
  const int64_t i0 = wrap(int64_t(x0), l.width, ws), i1 = wrap(int64_t(x0) + 1, l.width, ws);
  const int64_t j0 = wrap(int64_t(y0), l.height, wt), j1 = wrap(int64_t(y0) + 1, l.height, wt);
  const glm::dvec4 top = glm::mix(texel(l, i0, j0), texel(l, i1, j0), fx);
  const glm::dvec4 bottom = glm::mix(texel(l, i0, j1), texel(l, i1, j1), fx);
  return glm::mix(top, bottom, fy);
}

}  // namespace

glm::dvec4 sample_chain(const MipChain& chain, WrapMode wrap_s, WrapMode wrap_t,
                        vgpu::Filter filter, double u, double v, double rho) {
  // Texel indices far outside any level are the same texels, and int64 keeps them exact.
  if (!std::isfinite(u) || !std::isfinite(v)) u = v = 0.0;
  u = std::clamp(u, -1e12, 1e12);
  v = std::clamp(v, -1e12, 1e12);
  const auto& l = chain.levels;
  if (filter == vgpu::Filter::nearest) return nearest(l[0], wrap_s, wrap_t, u, v);
  if (filter == vgpu::Filter::bilinear) return bilinear(l[0], wrap_s, wrap_t, u, v);
  // vgpu::level_of_detail: the level below log2(rho), the fraction piecewise linear.
  const int levels = int(l.size());
  int level = 0;
  double scale = 1.0;
  for (int k = 1; k < vgpu::kMaxMipLevels; ++k)
    if (rho >= double(1 << k) && k < levels) level = k, scale = double(1 << k);
  double frac = rho / scale - 1.0;
  frac = frac > 0.0 ? std::min(frac, 1.0) : 0.0;  // NaN -> 0
  if (level >= levels - 1) frac = 0.0;
  const int next = std::min(level + 1, levels - 1);
  return glm::mix(bilinear(l[size_t(level)], wrap_s, wrap_t, u, v),
                  bilinear(l[size_t(next)], wrap_s, wrap_t, u, v), frac);
}

}  // namespace host
