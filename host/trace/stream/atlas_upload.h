// The texture atlas upload: a textured scene's base-colour images on the card, done once at
// initialization (StreamTracer's constructor). Static: a moving scene's frames change
// positions, not UVs.
#pragma once

#include "host/scene/scene.h"
#include "vgpu/vgpu.h"

namespace host {

// What the shader reads for a base colour (kernels/base_color.h, kernels/layout.h).
struct AtlasTextures {
  // Each triangle's corners' texture coordinates, triangle i at texel (i mod width, i div
  // width) as in the scene's textures: uvs01 holds corners 0 and 1, uvs2 corner 2 and the
  // material's texture index.
  vgpu::Texture uvs01, uvs2;
  // One row per image: its level count and wrap modes, then each level's rectangle in the atlas.
  vgpu::Texture table;
  // Every image's mip chain packed into one texture.
  vgpu::Texture atlas;
};

// Builds each of the scene's images' mip chain (host/trace/textures.h), packs the chains into
// one atlas, writes the table and the corners' coordinates (textures `scene_width` x
// `scene_height`, the scene textures' size) into `out`, and uploads the four. Throws
// vgpu::Error where the atlas or the table is wider than the profile's largest texture.
void upload_texture_atlas(vgpu::Device& gpu, const Scene& scene, int scene_width, int scene_height,
                          AtlasTextures& out);

}  // namespace host
