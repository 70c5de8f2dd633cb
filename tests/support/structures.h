// The acceleration structures the walk tests compare, built in one place: a scene, its camera,
// the paper's uniform grid (the reference every other walk is compared with), the one-voxel
// "box" grid that gives the other walks the scene's box, and the structure under test.
// When the way structures are built changes, this file is the one to change.
#pragma once

#include <string>
#include <utility>

#include "host/accel/accel.h"
#include "host/accel/bvh.h"
#include "host/accel/grid.h"
#include "host/accel/grid2.h"
#include "host/accel/kdtree.h"
#include "host/image/image_io.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/walks/grid_walk.h"
#include "vgpu/profile.h"

namespace test_support {

struct Structures {
  host::AccelKind kind = host::AccelKind::grid;  // the structure under test
  host::Scene scene;
  host::Camera camera;
  host::Grid grid;  // the paper's grid: the reference walk
  host::Grid box;   // one voxel: the box the other walks enter
  host::Bvh bvh;    // only the one of `kind` is built
  host::KdTree kd;
  host::Grid2 g2;

  host::Accel grid_accel() const { return {host::AccelKind::grid, &grid}; }
  // The structure under test, as the stream and CPU tracers take it.
  host::Accel accel() const {
    switch (kind) {
      case host::AccelKind::bvh:
        return {kind, &box, &bvh};
      case host::AccelKind::kdtree:
        return {kind, &box, nullptr, &kd};
      case host::AccelKind::grid2:
        return {kind, &box, nullptr, nullptr, &g2};
      default:
        return grid_accel();
    }
  }
};

// The structure of `kind` for a scene whose box grid is built: a BVH over the scene, a kd-tree
// in the box [lo, hi], a two-level grid over the scene's own (padded) bounds.
inline void build_structure(Structures& s, glm::vec3 lo, glm::vec3 hi) {
  switch (s.kind) {
    case host::AccelKind::bvh:
      s.bvh = host::build_bvh(s.scene);
      break;
    case host::AccelKind::kdtree:
      s.kd = host::build_kdtree(s.scene, lo, hi);
      break;
    case host::AccelKind::grid2:
      s.g2 = host::build_grid2(s.scene);
      break;
    default:
      break;
  }
}

// A scene with the grid the CLI builds for `profile`, the one-voxel box over the scene and the
// structure of `kind` in that box.
inline Structures build_structures(host::AccelKind kind, host::Scene scene,
                                   const host::Camera& camera,
                                   const std::string& profile = "gf5700") {
  Structures s;
  s.kind = kind;
  s.scene = std::move(scene);
  s.camera = camera;
  s.grid = host::build_grid(s.scene, host::grid_spec_for({}, s.scene, vgpu::profile(profile)));
  s.box = host::build_grid(s.scene, host::GridSpec{glm::ivec3(1)});
  build_structure(s, s.box.lo, s.box.hi);
  return s;
}

// A bundled scene (host::list_scenes) with its camera for a w x h image.
inline Structures bundled_structures(host::AccelKind kind, const std::string& name, int w, int h,
                                     const std::string& profile = "gf5700") {
  host::Scene scene = host::load_scene(host::resolve_scene(name), host::with_images());
  const host::Camera camera = host::scene_camera(scene, float(w) / float(h));
  return build_structures(kind, std::move(scene), camera, profile);
}

// A hand-built scene with its own grid in the box [lo, hi] (the stability cases): a kd-tree and
// its box grid in that box; a two-level grid and its box over the scene's bounds.
inline Structures structures_in_box(host::AccelKind kind, host::Scene scene,
                                    const host::Camera& camera, host::Grid grid, glm::vec3 lo,
                                    glm::vec3 hi) {
  Structures s;
  s.kind = kind;
  s.scene = std::move(scene);
  s.camera = camera;
  s.grid = std::move(grid);
  s.box = kind == host::AccelKind::kdtree
              ? host::build_grid_in_box(s.scene, lo, hi, glm::ivec3(1), 1)
              : host::build_grid(s.scene, host::GridSpec{glm::ivec3(1)});
  build_structure(s, lo, hi);
  return s;
}

}  // namespace test_support
