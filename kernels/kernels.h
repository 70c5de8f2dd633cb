// The paper's fragment programs (and the shadow-ray extension), one functor per file, and the
// fused two-output programs --mrt on runs (kernels/fused.h).
#pragma once

#include "kernels/fused.h"
#include "kernels/generate_rays.h"
#include "kernels/init_traversal.h"
#include "kernels/intersections.h"
#include "kernels/looping_traversal.h"
#include "kernels/next_triangle.h"
#include "kernels/rays_in_grid.h"
#include "kernels/rays_intersecting.h"
#include "kernels/reflected_rays.h"
#include "kernels/reflection_direction.h"
#include "kernels/reflection_origin.h"
#include "kernels/reset_traversal.h"
#include "kernels/shader.h"
#include "kernels/shadow_rays.h"
#include "kernels/traversal.h"
#include "kernels/update_voxel.h"
