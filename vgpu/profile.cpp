// The profile table. Sources are named per figure (review, datasheet or specification).
#include "vgpu/profile.h"

#include <stdexcept>

namespace vgpu {

namespace {
// The cards the GL device was measured on, defined below the table.
Profile measured_h200();
Profile measured_h100();
}  // namespace

const std::vector<Profile>& profiles() {
  static const std::vector<Profile> table = [] {
    std::vector<Profile> t;
    Profile fx;
    fx.name = "gf5700";
    fx.display = "GeForce FX 5700 (NV36), Cg fp30";
    fx.cg_profile = "fp30";
    fx.pipelines = 4;                // hexus.net FX 5700 Ultra review p.2: 4 pipes, 1 TMU each
    fx.core_mhz = 425;               // FX 5700 non-Ultra (secondary sources); paper omits variant
    fx.mem_gbps = 8.8;               // FX 5700 non-Ultra, 128-bit @ 550 MHz effective
    fx.max_outputs = 1;              // OpenGL/Cg fp30 writes one color output
    fx.max_instructions = 1024;      // Mesa MAX_NV_FRAGMENT_PROGRAM_INSTRUCTIONS
    fx.branching = Branching::none;  // NVIDIA Cg docs, fp30: no data-dependent branching/loops
    fx.branch_granularity = 1;
    fx.max_texture_size = 4096;  // NV3x GL_MAX_TEXTURE_SIZE / RECTANGLE size (driver caps)
    fx.memory_mib = 256;  // boards of 128 MB, the chip takes 256 at most (tecchannel.de, FX 5700 U)
    // NVIDIA's developer FAQ: GL_MAX_TEXTURE_UNITS is 4 on GeForce FX and GeForce 6 "since those
    // GPUs have 16 texture units", reached through ARB_fragment_program's texture image units.
    fx.texture_units = 16;        // GL_MAX_TEXTURE_IMAGE_UNITS_ARB on NV3x (NVIDIA developer FAQ)
    fx.precision = Format::fp32;  // fp30 "float" is IEEE single; "half" is fp16
    fx.bus_mbps = 2112;           // AGP 8x: 264 MB/s x 8 (GPU Gems 2, ch. 30)
    // Fixed costs: no public figure; one unit u fitted on Table 1 Bunny3 on this card (5075 ms,
    // scripts/docs/table1.py --fit), split pass : load : read-back = u : u : 2u
    // (docs/studies/table1.md).
    fx.program_load_us = 651;  // fitted (Table 1 Bunny3), driver cost of a program switch
    fx.readback_us = 1301;     // fitted (Table 1 Bunny3); GPU Gems 2 ch. 6: a stall
    fx.pass_us = 651;          // fitted (Table 1 Bunny3)
    fx.alu_lanes = 4;          // NV_fragment_program instructions are 4-component (vec4)
    fx.alu_per_clock = 1;      // hexus.net FX 5700 Ultra review p.2: one shader unit per pipe
    fx.fp32_rate = 0.5;        // model parameter: NV3x slow at fp32 (Tom's Hardware NV40 review)
    fx.fp24_rate = 0.5;        // no fp24 units: fp24 values need the fp32 path
    fx.texels_per_clock = 1;   // hexus.net FX 5700 Ultra review p.2: one texture unit per pipe

    fx.max_loop_iterations = 0;  // NVIDIA Cg docs, fp30: loops unroll, no data-dependent exit
    t.push_back(fx);

    // The fp24 part of 2004: every fragment operation in s7e16, no fp32 and no separate half
    // speed (partial precision runs on the same fp24 units).
    Profile ati;
    ati.name = "r300";
    ati.display = "Radeon 9700 Pro (R300), ps_2_0 / ARB_fragment_program";
    ati.cg_profile = "arbfp1";
    ati.pipelines = 8;     // guru3d.com Radeon 9700 Pro review p.2: 8 rendering pipelines
    ati.core_mhz = 325;    // guru3d.com Radeon 9700 Pro review p.2: engine clock 325 MHz
    ati.mem_gbps = 19.84;  // 256-bit DDR @ 310 MHz (620 MT/s effective), same review
    ati.max_outputs = 4;   // multiple render targets (rage3d.com R9500/9700 feature list)
    // ps_2_0 has 64 arithmetic + 32 texture instruction slots; the vgpu checks the limit against
    // counted scalar operations, so 96 slots x 3 operations per vec4 instruction. The ALU/TEX
    // split and R300's 4 levels of dependent texture reads are not modeled.
    ati.max_instructions = 96 * 3;    // model parameter: Direct3D 9 ps_2_0 96 slots x 3 operations
    ati.branching = Branching::none;  // ps_2_0: no flow control in fragment programs
    ati.branch_granularity = 1;       // no branching
    ati.max_texture_size = 2048;      // R300 GL_MAX_TEXTURE_SIZE (driver caps)
    ati.texture_units = 16;        // Direct3D 9 ps_2_0: samplers s0..s15; ARB_fragment_program 16
    ati.precision = Format::fp24;  // en.wikipedia.org "Radeon 9000 series": FP24 shader precision
    ati.has_fp16 = false;          // partial-precision hints run at fp24 on R300
    ati.bus_mbps = 2112;           // AGP 8x, as the FX 5700
    // Fixed costs: no Table 1 figure on this card to fit; the FX 5700's fitted values.
    ati.program_load_us = 651;  // model parameter: the FX 5700's fitted value (no Table 1 cell)
    ati.readback_us = 1301;     // model parameter: the FX 5700's fitted value (no Table 1 cell)
    ati.pass_us = 651;          // model parameter: the FX 5700's fitted value (no Table 1 cell)
    ati.alu_lanes = 4;          // vec3 + scalar co-issue: one vec4 instruction a clock
    ati.alu_per_clock = 1;      // one shader ALU per pipe (guru3d.com review: 8 pipes)
    ati.fp32_rate = 1;          // fp32 requests compute in fp24 (Profile::computes), full speed
    ati.fp24_rate = 1;          // native format
    ati.texels_per_clock = 1;   // 8 TMUs for 8 pipes (guru3d.com: 2600 Mtexel/s at 325 MHz)

    ati.max_loop_iterations = 0;  // ps_2_0: no flow control in fragment programs
    t.push_back(ati);

    Profile g6;
    g6.name = "gf6600";
    g6.display = "GeForce 6600 (NV43), Cg fp40";
    g6.cg_profile = "fp40";
    g6.pipelines = 8;             // Tom's Hardware 6600 GT review: 8 pixel pipelines
    g6.core_mhz = 300;            // 6600 non-GT (Tom's Hardware); GT is 500 MHz
    g6.mem_gbps = 11.2;           // one non-GT board, 700 MHz effective x 128 bit (Tom's Hardware)
    g6.max_outputs = 4;           // MRT (NVIDIA CineFX 3.0 brief; "up to 4": forum source)
    g6.max_instructions = 65536;  // NV_fragment_program2 (fp40) executed-instruction limit
    g6.branching = Branching::dynamic;  // NVIDIA Cg docs, fp40
    g6.branch_granularity = 1024;       // ~1000 pixels on NV4x (AnandTech)
    g6.max_texture_size = 4096;         // NV4x driver caps
    g6.memory_mib = 256;    // 128 or 256 MB boards (hexus.net, XFX GeForce 6600 DDR2 review p.2)
    g6.texture_units = 16;  // GL_MAX_TEXTURE_IMAGE_UNITS on NV4x (NVIDIA developer FAQ)
    g6.precision = Format::fp32;  // FP32 and FP16 equal speed on GeForce 6 (CineFX 3.0 brief)
    g6.bus_mbps = 4000;           // PCI Express x16, one direction (PCI-SIG 1.0a: 250 MB/s/lane)
    // Fixed costs: fitted as on the FX 5700, on Table 1 Bunny3 on this card (1079 ms).
    g6.program_load_us = 160;  // fitted (Table 1 Bunny3), driver cost of a program switch
    g6.readback_us = 320;      // fitted (Table 1 Bunny3)
    g6.pass_us = 160;          // fitted (Table 1 Bunny3)
    g6.alu_lanes = 4;          // NV_fragment_program2 instructions are 4-component (vec4)
    g6.alu_per_clock = 2;      // Tom's Hardware NV40 review: two FP32 units per pipe
    g6.fp32_rate = 1;          // NVIDIA CineFX 3.0 brief: FP32 and FP16 equal speed
    g6.fp24_rate = 1;          // computed on the fp32 units, at their speed
    g6.texels_per_clock = 1;   // one texture unit per pipe (NV4x pipe, GPU Gems 2 ch. 30)

    // Loops: the NV_fragment_program2 spec (NVIDIA, 2004) clamps REP/LOOP counts to
    // MAX_PROGRAM_LOOP_COUNT_NV, 255 on NV4x (as ps_3_0's loop/rep count range [0, 255]).
    g6.max_loop_iterations = 255;  // NV_fragment_program2 spec: MAX_PROGRAM_LOOP_COUNT_NV
    // GPU Gems 2 ch. 34 (Harris & Buck, "GPU Flow-Control Idioms"), the GeForce 6800's cost of
    // flow-control instructions: a loop/endloop pair about 4 clocks.
    g6.loop_overhead_clocks = 4;  // GPU Gems 2 ch. 34: loop/endloop about 4 clocks (6800)
    t.push_back(g6);

    Profile m;
    m.name = "rtx4090";
    m.display = "GeForce RTX 4090 (AD102), as a fragment pipeline";
    m.cg_profile = "ps_5_0-class";
    m.pipelines = 16384;           // CUDA cores (NVIDIA RTX 4090 specifications)
    m.core_mhz = 2520;             // boost clock (NVIDIA RTX 4090 specifications)
    m.mem_gbps = 1008;             // 384-bit GDDR6X @ 21 Gbps (NVIDIA RTX 4090 specifications)
    m.max_outputs = 8;             // D3D11+ simultaneous render targets
    m.max_instructions = 1 << 20;  // effectively unlimited (model parameter)
    m.branching = Branching::dynamic;
    m.branch_granularity = 32;   // one warp (NVIDIA CUDA programming guide)
    m.max_texture_size = 32768;  // D3D12 feature level 12 max texture dimension
    m.memory_mib = 24 * 1024;    // 24 GB GDDR6X (NVIDIA RTX 4090 specifications)
    m.texture_units = 32;        // GL_MAX_TEXTURE_IMAGE_UNITS on NVIDIA's current GL drivers
    m.precision = Format::fp32;
    m.bus_mbps = 32000;     // PCI Express 4.0 x16, one direction
    m.program_load_us = 2;  // model parameter (assumed; no Table 1 figure to fit)
    m.readback_us = 10;     // model parameter (assumed; no Table 1 figure to fit)
    m.pass_us = 3;          // model parameter (assumed; no Table 1 figure to fit)
    m.alu_lanes = 1;        // scalar CUDA cores: every scalar operation is one instruction
    m.alu_per_clock = 1;    // one FP32 FMA per core per clock (NVIDIA Ada whitepaper)
    m.fp32_rate = 1;
    m.texels_per_clock = 512.0 / 16384;  // 512 texture units for 16384 cores (Ada whitepaper)

    m.max_loop_iterations = 1 << 20;  // model parameter: no loop count limit
    m.loop_overhead_clocks = 1;       // model parameter (assumed: a compare and a branch)
    t.push_back(m);

    t.push_back(measured_h200());
    t.push_back(measured_h100());
    return t;
  }();
  return table;
}

const Profile* profile_for_renderer(std::string_view renderer) {
  for (const Profile& p : profiles())
    if (!p.gl_renderer.empty() && renderer.find(p.gl_renderer) != std::string_view::npos) return &p;
  return nullptr;
}

Format Profile::computes(Format f) const {
  const Format g = coarser(f, precision);
  return g == Format::fp16 && !has_fp16 ? precision : g;
}

namespace {

// The H200 the GL device is measured on (docs/studies/real_gpu.md): a 2026 GPU running the
// paper's multipass loop through OpenGL 3.3 (EGL, NVIDIA 580 driver).
Profile measured_h200() {
  Profile m;
  m.name = "h200";
  m.display = "NVIDIA H200 SXM (GH100), through OpenGL 3.3";
  m.cg_profile = "GLSL 3.30 (generated)";
  m.gl_renderer = "NVIDIA H200/";  // "NVIDIA H200/PCIe/SSE2" (NVIDIA 580 driver)
  // GH100 is a compute part: of its 66 TPCs (132 SMs) only 2 TPCs, 4 SMs, can run vertex and
  // pixel shaders (NVIDIA H100 Tensor Core GPU Architecture whitepaper, 2022). Fragment
  // programs run on those: 4 SMs x 128 FP32 cores.
  // nvidia-smi showed the boost clock through the measured frames, ~1 GHz when the GPU sat
  // idle between passes (docs/studies/real_gpu.md).
  m.pipelines = 512;  // 4 graphics-capable SMs x 128 FP32 cores (H100 architecture whitepaper)
  m.core_mhz = 1980;  // boost clock, SXM (NVIDIA H100 SXM5 specifications; H200 same GH100)
  m.mem_gbps = 4800;  // HBM3e, 4.8 TB/s (NVIDIA H200 datasheet)
  m.max_outputs = 8;  // GL_MAX_DRAW_BUFFERS on NVIDIA drivers
  m.max_instructions = 1 << 20;  // effectively unlimited (model parameter)
  m.branching = Branching::dynamic;
  m.branch_granularity = 32;              // one warp (NVIDIA CUDA programming guide)
  m.branches_as_selects = true;           // the generated GLSL has no branches (vgpu/glsl.cpp)
  m.max_texture_size = 32768;             // GL_MAX_TEXTURE_SIZE on NVIDIA drivers
  m.memory_mib = int(141e9 / (1 << 20));  // 141 GB HBM3e (NVIDIA H200 datasheet)
  m.texture_units = 32;  // GL_MAX_TEXTURE_IMAGE_UNITS on NVIDIA's current GL drivers
  m.precision = Format::fp32;
  m.bus_mbps = 64000;  // PCI Express 5.0 x16, one direction (H200 datasheet)
  // Fixed costs measured by bench_gl on this H200 (NVIDIA 580 driver, EGL, 1x1 passes, medians
  // of two runs, docs/studies/real_gpu.md): a pass 10.0 and 10.8 us, a polled query read-back 9
  // to 14 us more, a program switch under 1 us. The blocking GL_QUERY_RESULT wait costs up to
  // 140 us more after a long pass (the driver sleeps); the model prices the polled wait.
  m.pass_us = 10.4;                // measured (bench_gl)
  m.readback_us = 12;              // measured (bench_gl, polled)
  m.program_load_us = 0.5;         // measured (bench_gl: within noise of 0)
  m.alu_lanes = 1;                 // scalar CUDA cores: every scalar operation is one instruction
  m.alu_per_clock = 1;             // one FP32 FMA per core per clock (Hopper whitepaper)
  m.fp32_rate = 1;                 // FP32 is the full rate (Hopper whitepaper)
  m.texels_per_clock = 4.0 / 128;  // 4 texture units per SM (Hopper whitepaper)
  // 16 texture units (4 SMs) fetching one 32-bit component a clock each (RGBA32F in 4).
  m.texture_bytes_per_clock = 64;  // model parameter (assumed rate per texture unit)
  // The ROPs: bench_gl's 1024x1024 copy pass writes 16 MB in 301.6 us of GPU time at 1980 MHz
  // and two targets take twice as long: 28 bytes a clock. Measured on tiny programs, not on the
  // frames it predicts.
  m.output_bytes_per_clock = 28;  // model parameter (measured by bench_gl's copy pass)
  // The L2: 50 MB on GH100 (H100 architecture whitepaper; the H200 is the same die). In the
  // multipass frames at 1024x1024 (results/real_gpu/h100/t1_*.json), the texture-bound passes
  // whose footprint is 50.3 MB or more (three RGBA32F textures of 1024x1024) read 40 to 53 bytes
  // a clock, the intersection passes 51.4; at 256x256 the same kernels read 64 to 72 (update
  // voxel 49). Fitted: the bytes over the timer-query time of every texture-bound pass over
  // l2_bytes in the H100's three 1024x1024 Table 1 frames, 51.2 (the H200's give 50.6;
  // docs/studies/real_gpu.md). l2_bytes is where the measured passes place the step: passes of
  // 39.4 MB read at the in-cache rate (640x640), of 50.3 MB at the spilled one; the whitepaper's
  // 50 MB, taken as 50e6 bytes (50 MiB would put the 50.3 MB passes in the cache).
  m.l2_bytes = 50e6;                       // fitted: between 39.4 and 50.3 MB (H100 frames)
  m.texture_spilled_bytes_per_clock = 51;  // fitted (H100 1024x1024 Table 1 frames)
  // A glGetTexImage of one RGBA32F texture to the host: 330 us for 1 MB, 5.43 ms for 16 MB,
  // 28.1 ms for 64 MB (bench_gl, results/real_gpu/real_gpu_h200_texture_io.json): 3.1 GB/s, no
  // fixed part.
  m.download_us = 0;      // measured (bench_gl: within noise of 0)
  m.download_gbps = 3.1;  // measured (bench_gl, 16 MB read-back)
  // The looping frames' wall time beyond the GPU's timer queries and the fixed costs above
  // grows with the image: 8x8 0.10 ms, 64x64 0.11, 256x256 0.49, 512x512 2.08 ms (medians,
  // results/structures/structures_h200_sizes_looping.json: 84 frames), 7.8 ns a pixel by least
  // squares: the host filling the frame's image, depth and hit ids from the two RGBA32F
  // textures it read back (32 bytes a pixel) into memory fresh each frame.
  m.download_host_gbps = 32 / 7.8;  // measured: 32 bytes read back a pixel in 7.8 ns

  m.max_loop_iterations = 1 << 20;  // model parameter: no loop count limit
  m.loop_overhead_clocks = 1;       // model parameter (assumed: a compare and a branch)
  // One fragment on this H200 (bench_gl --latency,
  // results/structures/structures_h200_latency.json, GPU timer queries, 1024 against 8192
  // iterations): following links through RGBA32F textures of 512x512 and 2048x2048 texels, 235.4
  // and 238.8 ns an iteration (473 clocks at 1980 MHz for the larger; 212 where the 16x16 texture
  // stays in the first-level cache); 16 dependent multiply-adds, 77.3 ns (153 clocks). Priced as
  // the model counts those loops (vgpu/span.h: the multiply-adds' iteration is 35 operation
  // units, the chase's one fetch and 6 units):
  m.operation_latency_clocks = 4.37;  // measured: 153 clocks / 35
  m.fetch_latency_clocks = 447;       // measured: 473 clocks - 6 x 4.37
  return m;
}

// The H100 the GL device hands out as often as the H200 (issue 51), measured the way the h200
// was: bench_gl's fixed costs and latency probes on it (results/real_gpu/h100/, NVIDIA 580
// driver, EGL). The same GH100 chip with the same 4 graphics SMs: the h200's figures, but for
// its memory and what was measured on this card.
Profile measured_h100() {
  Profile m = measured_h200();
  m.name = "h100";
  m.display = "NVIDIA H100 SXM5 80GB (GH100), through OpenGL 3.3";
  m.gl_renderer = "NVIDIA H100 80GB HBM3/";  // the NVIDIA 580 driver's GL_RENDERER start
  m.core_mhz = 1980;     // measured: nvidia-smi clocks.max.sm, and the SM clock while busy
  m.mem_gbps = 3350;     // HBM3, 3.35 TB/s (NVIDIA H100 SXM5 datasheet)
  m.memory_mib = 81559;  // measured: nvidia-smi memory.total (80 GB HBM3)
  m.bus_mbps = 64000;    // PCI Express 5.0 x16, one direction (nvidia-smi: gen 5, width 16)
  // Fixed costs measured by bench_gl on this H100 (medians of 5 runs of 50 passes), as what
  // a pass adds to the wall clock beyond its GPU time (the model prices the GPU's work
  // apart): 12.1 us (1x1), 11.1 (64x64), 10.1 (256x256), 11.1 and 11.7 with the program
  // switched every pass: 11.1 (the median). A polled query read-back adds 8.0 (1x1), 10.5
  // (256x256) and 10.3 us (1024x1024) more: 10.3. A program switch: within noise of 0. (The
  // H200's run of the same rows gives 12.3, 8.0 and 10.3 us a pass: its profile's 10.4.)
  m.pass_us = 11.1;       // measured (bench_gl: wall minus GPU time, tiny passes)
  m.readback_us = 10.3;   // measured (bench_gl, polled)
  m.program_load_us = 0;  // measured (bench_gl: within noise of 0)
  // The 1024x1024 copy pass writes 16 MB in 301.9 us of GPU time at 1980 MHz: 28 bytes a
  // clock, as on the H200.
  m.output_bytes_per_clock = 28;  // measured (bench_gl's copy pass)
  // glGetTexImage of one RGBA32F texture: 290 us for 1 MB, 3,958 us for 16 MB, 18,231 us for
  // 64 MB.
  m.download_us = 0;       // measured (bench_gl: within noise of 0)
  m.download_gbps = 4.24;  // measured (bench_gl, 16 MB read-back)
  // The looping frames' wall time beyond the GPU's timer queries and the fixed costs above,
  // by size (scripts/docs/cells.py --host-fit, results/real_gpu/h100/sizes.json: 36 frames):
  // 8x8 0.06 ms, 64x64 0.06, 256x256 0.27, 512x512 1.54 ms; 6.6 ns a pixel by least squares.
  m.download_host_gbps = 32 / 6.6;  // measured: 32 bytes read back a pixel in 6.6 ns
  // One fragment on this H100 (bench_gl --latency, GPU timer queries, 1024 against 8192
  // iterations): 462 clocks an iteration through RGBA32F textures of 512x512 and 2048x2048
  // texels (212 in the 16x16 one), 153 clocks for 16 dependent multiply-adds: as the H200's.
  m.operation_latency_clocks = 4.37;  // measured: 153 clocks / 35
  m.fetch_latency_clocks = 436;       // measured: 462 clocks - 6 x 4.37
  return m;
}

}  // namespace

const Profile& profile(std::string_view name) {
  for (const Profile& p : profiles())
    if (p.name == name) return p;
  std::string known;
  for (const Profile& p : profiles()) known += (known.empty() ? "" : ", ") + p.name;
  throw std::invalid_argument("unknown profile '" + std::string(name) + "' (known: " + known + ")");
}

}  // namespace vgpu
