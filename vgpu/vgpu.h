// The virtual GPU's public header: include this one to use it.
#pragma once

#include "vgpu/device.h"
#include "vgpu/format.h"
#include "vgpu/fragment.h"
#include "vgpu/glsl.h"
#include "vgpu/gpu.h"
#include "vgpu/lanes.h"
#include "vgpu/precision.h"
#include "vgpu/profile.h"
#include "vgpu/program.h"
#include "vgpu/stats.h"
#include "vgpu/texture.h"
