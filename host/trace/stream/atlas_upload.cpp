// The texture atlas upload (atlas_upload.h): mip chains, the atlas, its table, the corners' UVs.
#include "host/trace/stream/atlas_upload.h"

#include <algorithm>
#include <string>
#include <vector>

#include "host/trace/textures.h"

namespace host {

void upload_texture_atlas(vgpu::Device& gpu, const Scene& scene, int scene_width, int scene_height,
                          AtlasTextures& out) {
  const int maxs = gpu.profile().max_texture_size;
  const int sw = scene_width, sh = scene_height;
  const size_t ntri = scene.triangle_count();
  std::vector<MipChain> chains;
  size_t levels = 0;
  for (const SceneTexture& t : scene.textures) {
    chains.push_back(build_mip_chain(t));
    levels = std::max(levels, chains.back().levels.size());
  }
  const TextureAtlas atlas = pack_atlas(chains, maxs);
  const std::string why = atlas_refusal(atlas, scene.textures.size(), maxs, gpu.profile().name);
  if (!why.empty()) throw vgpu::Error(why);
  out.atlas = gpu.make_texture("texture atlas", atlas.width, atlas.height, 4);
  for (int y = 0; y < atlas.height; ++y)
    for (int x = 0; x < atlas.width; ++x) {
      const glm::vec4& c = atlas.texels[size_t(y) * size_t(atlas.width) + size_t(x)];
      float* t = out.atlas.texel_mut(x, y);
      for (int k = 0; k < 4; ++k) t[k] = c[k];
    }
  // The table: per image (row i), its level count and wrap modes, then each level's rectangle.
  out.table = gpu.make_texture("texture table", int(1 + levels), int(chains.size()), 4);
  for (size_t i = 0; i < chains.size(); ++i) {
    float* head = out.table.texel_mut(0, int(i));
    head[0] = float(chains[i].levels.size());
    head[1] = float(scene.textures[i].wrap_s);
    head[2] = float(scene.textures[i].wrap_t);
    for (size_t k = 0; k < chains[i].levels.size(); ++k) {
      float* r = out.table.texel_mut(int(1 + k), int(i));
      for (int c = 0; c < 4; ++c) r[c] = float(atlas.rects[i][k][c]);
    }
  }
  out.uvs01 = gpu.make_texture("uvs01", sw, sh, 4);
  out.uvs2 = gpu.make_texture("uvs2", sw, sh, 4);
  for (size_t i = 0; i < ntri; ++i) {
    float* a = out.uvs01.texel_mut(int(i % sw), int(i / sw));
    float* b = out.uvs2.texel_mut(int(i % sw), int(i / sw));
    a[0] = scene.uv0[i].x, a[1] = scene.uv0[i].y, a[2] = scene.uv1[i].x, a[3] = scene.uv1[i].y;
    b[0] = scene.uv2[i].x, b[1] = scene.uv2[i].y;
    b[2] = float(scene.materials[scene.material[i]].texture);
  }
  for (const vgpu::Texture* t : {&out.uvs01, &out.uvs2, &out.table, &out.atlas}) gpu.upload(*t);
}

}  // namespace host
