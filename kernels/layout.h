// Every texture of the stream ray tracer and its channel layout, in one place (paper Sec. 3.3).
// Static textures hold the scene and the grid; dynamic textures hold one texel of ray state per
// pixel, ping-ponged between passes because a pass may not read the texture it writes.
//
// Static (scene), indexed by internal triangle id i at texel (i mod width, i div width):
//   vertices0/1/2   xyz    corner positions, world space       (paper: texturaVertices)
//   normals0/1/2    xyz    corner normals, world space, unit   (paper: texturaNormales)
//   colors          rgba   rgb = colour, a = reflection coefficient (paper: texturaColores)
//   uvs01           xyzw   texture coordinates of corners 0 (xy) and 1 (zw)     (scenes with a
//   uvs2            xyz    xy = corner 2's coordinates, z = the triangle's       textured
//                          texture (row of the texture table), -1: untextured    material only)
// Static (base-colour textures, kernels/base_color.h; scenes with a textured material only):
//   texture table   rgba   one row per texture: texel 0 = (mip levels, wrap s, wrap t, 0)
//                          (wraps as vgpu::Wrap), texel 1 + k = level k's rectangle in the
//                          atlas (x, y, width, height), texels
//   texture atlas   rgba   every texture's mip chain (linear rgb, alpha), each level a
//                          rectangle: level 0 with levels 1.. stacked at its right
// Static (grid):
//   triangle lists  x      triangle ids of each voxel, voxels one after another, each list
//                          closed by -1; texel of list entry k at (k mod width, k div width)
//                          (paper: texturaTriangulos)
//   voxel pointers  x      index of the voxel's first list entry; voxel (X,Y,Z) at texel
//                          (X*sizeY + Y, Z) (paper: texturaTriangulosEnVoxel)
// Static (BVH, --accel bvh; kernels/bvh.h), node i at (i mod width, i div width):
//   bvh nodes lo    xyz = box minimum (padded), w = escape: the node after i's subtree, -1 at
//                   the end; the left child of an inner node is node i + 1
//   bvh nodes hi    xyz = box maximum (padded), w = the leaf's first list entry, -1 for an inner
//                   node
//   bvh lists       x      triangle ids of each leaf, closed by -1 (entry 0: a -1)
// Static (kd-tree, --accel kdtree; kernels/kdtree.h), node i at (i mod width, i div width):
//   kd nodes        x = split position, y = axis (0, 1, 2; 3 for a leaf), z = right child (the
//                   left child is node i + 1), w = the leaf's first list entry, -1 for an inner
//                   node
//   kd lists        x      triangle ids of each leaf, closed by -1 (entry 0: a -1)
// Static (two-level grid, --accel grid2; kernels/grid2.h), entry k at (k mod width, k div width):
//   grid2 cells     coarse cell c = (Z*resY + Y)*resX + X: xyz = its sub-grid's resolution
//                   (1, 1, 1 for a cell that is not crowded), w = its first sub-cell; the
//                   sub-cells of c follow one another, x fastest
//   grid2 sub-cells x = the sub-cell's first list entry (0: empty), y = its coarse cell
//   grid2 lists     x      triangle ids of each sub-cell, closed by -1 (entry 0: a -1)
// Addressed by (x, y) (ListUniforms::xy, --addressing: past 2^23 entries), a pointer is a texel's
// column and row: a kd node's z, w hold its right child's (or its leaf's list start's); a
// coarse cell's record is (sub-grid resolution x + 1024 y, z, first sub-cell's column, row); a
// sub-cell's texel (list start's column, row, coarse cell). The states below then hold columns
// and rows: kd traversal x = node column (+ the node texture's width once its leaf is reached),
// y = node row; grid2 traversal x, y = sub-cell column, row; leaf and cell state x, y = the list
// position's column, row.
//
// Dynamic (per pixel):
//   origins         xyz = ray origin, world space; w unused    (paper: texturaInicioRayos)
//   rays            xyz = ray direction (unit), w = tmax; tmax < 0 marks no ray
//                   (paper: texturaRayos)
//   traversal       xyz = current voxel, w = ray parameter t where the ray enters it;
//                   x = -1 once the ray is done: left the grid, or found its hit
//                   (paper: texturaEstadoTraversal)
//   voxel state     x = position in the triangle lists, w = triangle to test next;
//                   w = -1: nothing left to test in this voxel   (paper: texturaEstadoVoxel)
//   bvh traversal   x = next node (the node count: the walk ends at the next step; -1: done),
//                   y = list position of the leaf just entered (-1: none)   (--accel bvh)
//   kd traversal    x = node (-1: done), y = list position of the leaf being tested (-1: none),
//                   z, w = tmin, tmax of the ray's segment        (--accel kdtree)
//   grid2 traversal x = sub-cell (-1: done), y = its first list entry, z, w = t where the ray
//                   enters and leaves the sub-cell                 (--accel grid2)
//   leaf state      as the voxel state, over the tree's (or the two-level grid's) lists; the
//   kd-tree's looping kernel
//                   keeps its push-down node in y and a "segment cut" flag in z
//   intersection    x = t of the nearest valid hit so far, w = its triangle, -1 for none;
//                   yz = barycentrics (u, v) of that hit      (paper: texturaEstadoInterseccion)
//   surface         xyz = hit point (offset off the surface, the next ray's origin),
//                   w = hit triangle or -1                      (written by inicioReflejo)
//   result          rgb = colour accumulated so far, a = weight of the current ray in the final
//                   colour (product of the reflection coefficients met so far) (paper:
//                   texturaResultado)
//   sample sum      rgb = sum of the sample frames' colours, a = samples added (--spp N > 1;
//                   an extension, kernels/accumulate_samples.h)
//
// Ray streams (glass, or --ray-streams on; host/trace/stream/ray_streams.h). Static, per triangle
// like the colours:
//   glass           x = mirror coefficient a, y = transmission t, z = index of refraction
//   colors          under ray streams a = 1 - (1 - t)(1 - a): the share of a ray's weight its
//                   surface does not shade itself (a itself when t = 0)
// Per level k of the ray tree, element i at (i mod W, i div W), W the image's width (level 0:
// the pixels), a chunk of W x H elements every H rows:
//   origins, rays   as above (compactarRayos writes them for k >= 1; no ray past the level)
//   weights         a = the ray's weight in its pixel (the shader's result before shading)
//   surface         as above (inicioReflejo)
//   split           x = reflected ray's weight, y = refracted ray's weight (0: not spawned),
//                   z = rays spawned (0-2), w = 1 if the reflected one is a total internal
//                   reflection (dividirRayos)
//   scan            x = inclusive prefix sum of split z over elements 0..i (sumaPrefijos), fp32
//   colour          rgb = the ray's own shaded contribution (weight x local colour)
//   gathered        rgb = colour plus its children's gathered colours (reunirHijos)
//   shadow origins  xyz = a shadow ray's origin past the glass met so far, w = the light's
//                   transmittance so far (sombraVidrio; the shader's visibility)
#pragma once

#include <glm/glm.hpp>

#include "vgpu/sampler.h"

namespace kernels {

// "No triangle" and "ray done" markers, and the parameter standing for infinity (it survives
// fp16 storage as +inf).
inline constexpr float kNone = -1.0f;
inline constexpr float kFar = 1e30f;

// Uniforms of a structure's triangle lists, which every structure has (kernels/lists.h): the
// list texture's width, and the tolerance of the rule that a hit counts only inside the piece
// of the ray the current voxel (leaf, cell) holds.
struct ListUniforms {
  float list_width = 1;  // width of the triangle-list texture, texels
  float t_slack = 0;     // tolerance of the in-voxel rule, world units along a unit ray
  // 1: the structure's pointers (list positions, and its nodes' or sub-cells') are (x, y) texel
  // coordinates, two channels each, instead of one linear index (kernels/lists.h, Addr): a
  // float addresses linearly only to 2^23 entries, a card's textures by (x, y) far past that.
  // A float, not a bool, so the uniforms' bytes hold no padding.
  float xy = 0;
};

// Uniforms describing the grid (world space), besides its lists'.
struct GridUniforms : ListUniforms {
  glm::vec3 lo{0.0f};    // grid box minimum corner
  glm::vec3 cell{1.0f};  // world size of one voxel
  glm::vec3 res{1.0f};   // voxels per axis, as floats
};

// Uniforms describing the scene textures' layout.
struct SceneUniforms {
  float width = 1;  // width of the vertex/normal/color textures, texels
};

// Base-colour textures (kernels/base_color.h): off for a scene without any, so its programs and
// images are the untextured ones.
struct TextureUniforms {
  bool on = false;
  vgpu::Filter filter = vgpu::Filter::trilinear;
  // The level of detail's ray differentials (Igehy 1999): the camera's right and up (unit,
  // world space) and the angle between neighbouring pixels' rays, 2 tan(yfov / 2) / height.
  glm::vec3 right{1, 0, 0}, up{0, 1, 0};
  float spread = 0;
};

}  // namespace kernels
