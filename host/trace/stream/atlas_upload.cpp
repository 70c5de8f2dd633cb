// The texture atlas upload (atlas_upload.h): mip chains, the atlas, its table, the corners' UVs.
#include "host/trace/stream/atlas_upload.h"

#include <algorithm>
#include <string>
#include <vector>

#include "host/scene/texture_fit.h"
#include "host/trace/textures.h"

namespace host {

void upload_texture_atlas(vgpu::Device& gpu, const Scene& scene, int scene_width, int scene_height,
                          AtlasTextures& out) {
  const int maxs = gpu.profile().max_texture_size;
  const int sw = scene_width, sh = scene_height;
  const size_t ntri = scene.triangle_count();
  // The layout from the sizes alone (pack_atlas's, host/scene/texture_fit.h), then each
  // chain's levels written straight into the atlas texture, one level kept at a time: no
  // chain and no second atlas is held beside it (the texels are pack_atlas's, bit for bit).
  std::vector<glm::ivec2> bases;
  for (const SceneTexture& t : scene.textures) bases.push_back({t.width, t.height});
  TextureAtlas size;
  AtlasLayout layout = layout_atlas(bases, maxs);
  size.width = layout.width;
  size.height = layout.height;
  const std::string why = atlas_refusal(size, scene.textures.size(), maxs, gpu.profile().name);
  if (!why.empty()) throw vgpu::Error(why);
  out.atlas = gpu.make_texture("texture atlas", layout.width, layout.height, 4);
  size_t levels = 0;
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const SceneTexture& t = scene.textures[i];
    const std::vector<glm::ivec4>& rects = layout.rects[i];
    levels = std::max(levels, rects.size());
    std::vector<glm::vec4> level;  // level k >= 1; level 0 is read from the scene
    for (size_t k = 0; k < rects.size(); ++k) {
      if (k > 0) level = halve(k == 1 ? t.texels : level, rects[k - 1].z, rects[k - 1].w);
      const std::vector<glm::vec4>& src = k == 0 ? t.texels : level;
      const glm::ivec4 r = rects[k];
      for (int y = 0; y < r.w; ++y)
        for (int x = 0; x < r.z; ++x) {
          const glm::vec4& c = src[size_t(y) * size_t(r.z) + size_t(x)];
          float* d = out.atlas.texel_mut(r.x + x, r.y + y);
          for (int c4 = 0; c4 < 4; ++c4) d[c4] = c[c4];
        }
    }
  }
  // The table: per image (row i), its level count and wrap modes, then each level's rectangle.
  out.table = gpu.make_texture("texture table", int(1 + levels), int(bases.size()), 4);
  for (size_t i = 0; i < bases.size(); ++i) {
    float* head = out.table.texel_mut(0, int(i));
    head[0] = float(layout.rects[i].size());
    head[1] = float(scene.textures[i].wrap_s);
    head[2] = float(scene.textures[i].wrap_t);
    for (size_t k = 0; k < layout.rects[i].size(); ++k) {
      float* r = out.table.texel_mut(int(1 + k), int(i));
      for (int c = 0; c < 4; ++c) r[c] = float(layout.rects[i][k][c]);
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
