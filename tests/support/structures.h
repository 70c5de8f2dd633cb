// The acceleration structures the walk tests compare, built in one place: a scene, its camera,
// the paper's uniform grid (the reference every other walk is compared with) and the structure
// under test, each a host::Accel (host/accel/accel.h).
// When the way structures are built changes, this file is the one to change.
#pragma once

#include <memory>
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
  std::unique_ptr<host::Accel> grid;        // the paper's grid: the reference walk
  std::unique_ptr<host::Accel> under_test;  // the structure of `kind` (none for the grid)

  const host::Accel& grid_accel() const { return *grid; }
  // The structure under test, as the stream and CPU tracers take it.
  const host::Accel& accel() const { return under_test ? *under_test : *grid; }
  const host::Bvh& bvh() const { return *accel().bvh(); }
  const host::Grid2& g2() const { return *accel().grid2(); }
};

// A scene with the grid the CLI builds for `profile` and the structure of `kind` in the scene's
// box, both made as the CLI makes them (host::make_accel).
inline Structures build_structures(host::AccelKind kind, host::Scene scene,
                                   const host::Camera& camera,
                                   const std::string& profile = "gf5700") {
  Structures s;
  s.kind = kind;
  s.scene = std::move(scene);
  s.camera = camera;
  const host::AccelParams params{host::grid_spec_for({}, s.scene, vgpu::profile(profile))};
  s.grid = host::make_accel(host::AccelKind::grid, s.scene, params);
  if (kind != host::AccelKind::grid) s.under_test = host::make_accel(kind, s.scene, params);
  return s;
}

// A bundled scene (host::list_scenes) with its camera for a w x h image.
inline Structures bundled_structures(host::AccelKind kind, const std::string& name, int w, int h,
                                     const std::string& profile = "gf5700") {
  host::Scene scene = host::load_scene(host::resolve_scene(name), host::with_images());
  const host::Camera camera = host::scene_camera(scene, float(w) / float(h));
  return build_structures(kind, std::move(scene), camera, profile);
}

// A hand-built scene with its own grid in the box [lo, hi] (the stability cases): a kd-tree in
// that box; a BVH or a two-level grid in the scene's own (padded) box.
inline Structures structures_in_box(host::AccelKind kind, host::Scene scene,
                                    const host::Camera& camera, host::Grid grid, glm::vec3 lo,
                                    glm::vec3 hi) {
  Structures s;
  s.kind = kind;
  s.scene = std::move(scene);
  s.camera = camera;
  s.grid = std::make_unique<host::GridAccel>(std::move(grid));
  if (kind == host::AccelKind::kdtree)
    s.under_test = std::make_unique<host::KdAccel>(s.scene, host::build_kdtree(s.scene, lo, hi));
  else if (kind != host::AccelKind::grid)
    s.under_test = host::make_accel(kind, s.scene, {});
  return s;
}

}  // namespace test_support
