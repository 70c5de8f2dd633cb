// The scene's base-colour textures as the devices hold them: each texture's mip chain (box
// filtered, GL's level sizes), and every chain packed into one atlas with its table
// (kernels/layout.h). The CPU tracer samples the chains; the stream tracer uploads the atlas.
#pragma once

#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "host/scene/scene.h"
#include "vgpu/sampler.h"

namespace host {

struct MipChain {
  struct Level {
    int width = 0, height = 0;
    std::vector<glm::vec4> texels;  // row-major, row 0 = the image's top
  };
  std::vector<Level> levels;  // level 0 = the image; each next one half as wide and high
                              // (rounded down, at least 1), down to 1x1
};

// Level k + 1's texel (i, j) is the mean of level k's texels (2i, 2j) .. (2i + 1, 2j + 1)
// (clamped to the level where a side is 1).
MipChain build_mip_chain(const SceneTexture& texture);

struct TextureAtlas {
  int width = 0, height = 0;
  std::vector<glm::vec4> texels;  // row-major
  // Per texture, per level: the rectangle (x, y, width, height), texels.
  std::vector<std::vector<glm::ivec4>> rects;
};

// Shelves of chains (level 0 with the rest stacked at its right), left to right, a new shelf
// when a row would pass max_width.
TextureAtlas pack_atlas(const std::vector<MipChain>& chains, int max_width);

// Why the scene's textures do not fit a profile whose textures are at most max_size texels a
// side (the atlas, or the table's rows), naming the limit; empty when they fit.
std::string atlas_refusal(const TextureAtlas& atlas, size_t textures, int max_size,
                          const std::string& profile);

// The texture unit's filters in double precision, as vgpu/sampler.h computes them (the CPU
// tracer): the chain sampled at (u, v) (glTF's coordinates) with its wraps; rho, the footprint in
// level-0 texels, picks trilinear's levels (vgpu::level_of_detail's rule).
glm::dvec4 sample_chain(const MipChain& chain, WrapMode wrap_s, WrapMode wrap_t,
                        vgpu::Filter filter, double u, double v, double rho);

}  // namespace host
