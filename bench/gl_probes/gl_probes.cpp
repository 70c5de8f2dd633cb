// bench_gl's probes of the card (bench/gl_probes/gl_probes.h): their kernels and timing.
#include "bench/gl_probes/gl_probes.h"

#include <array>
#include <cstdio>
#include <random>
#include <string>

#include "host/model/cost_model.h"
#include "vgpu/gpu.h"
#include "vgpu/program.h"

namespace bench_gl_probes {

namespace {

// Latency probes (--latency): one fragment follows a chain of dependent operations in a loop,
// so the GPU time per iteration is how long one operation waits for the one before, not how
// many the units can start. FetchChase: each texel holds the coordinates of the next texel to
// fetch (one random cycle through the texture). AluChain: 16 dependent multiply-adds an
// iteration (MUL then ADD: the GLSL's `precise` keeps them apart, as the vgpu counts them).
struct FetchChase {
  static constexpr const char* name = "fetch chase";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  static constexpr std::array<const char*, 1> units{"links"};
  int steps = 256;
  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    vgpu::Vec4<F> at = f.fetch_own(0);
    f.loop(steps, at.w >= F(0.0f), [&](const M& act) {
      at = vgpu::select(act, f.fetch(0, at.x, at.y), at);
      return act;
    });
    f.out(0) = at;
  }
};
struct AluChain {
  static constexpr const char* name = "arithmetic chain";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  static constexpr std::array<const char*, 1> units{"seed"};
  static constexpr int kChain = 16;  // multiply-adds per iteration
  int steps = 256;
  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    const vgpu::Vec4<F> s = f.fetch_own(0);  // x, a = 1, b = 0, w = 1: the texture decides
    F x = s.x;
    f.loop(steps, s.w >= F(0.0f), [&](const M& act) {
      F y = x;
      for (int i = 0; i < kChain; ++i) y = y * s.y + s.z;
      x = vgpu::select(act, y, x);
      return act;
    });
    f.out(0) = {x, s.y, s.z, s.w};
  }
};

// Coherence probes (--coherence): every fragment of a pass makes kSpreadSteps independent
// fetches from one RGBA32F data texture, the k-th at its base texel + (k, 0) along the row
// (wrapped), and sums them. Only the bases differ between the probes (the "bases" texture: x,
// y as texel centres, the row's length, 1), so the vgpu counts the same fetches and bytes for
// each and the cost model prices them alike; what a card's texture caches make of where the
// lanes of one warp fetch is what differs.
struct FetchSpread {
  static constexpr const char* name = "fetch spread";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  static constexpr std::array<const char*, 2> units{"bases", "data"};
  static constexpr int kSpreadSteps = 64;
  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    const vgpu::Vec4<F> b = f.fetch_own(0);
    vgpu::Vec4<F> sum{F(0.0f), F(0.0f), F(0.0f), F(0.0f)};
    F x = b.x;
    f.loop(kSpreadSteps, b.w >= F(0.0f), [&](const M& act) {
      const vgpu::Vec4<F> t = f.fetch(1, x, b.y);
      sum =
          vgpu::select(act, vgpu::Vec4<F>{sum.x + t.x, sum.y + t.y, sum.z + t.z, sum.w + t.w}, sum);
      F next = x + F(1.0f);
      next = vgpu::select(next >= b.z, next - b.z, next);
      x = vgpu::select(act, next, x);
      return act;
    });
    f.out(0) = sum;
  }
};

// One pass of p on `dev` (the GL device or the emulator): `sources` on units 0, 1, ..., drawn
// into `target`.
void draw_pass(vgpu::Device& dev, const vgpu::Program& p,
               std::initializer_list<const vgpu::Texture*> sources, vgpu::Texture& target) {
  dev.use_program(p);
  dev.unbind_textures();
  int unit = 0;
  for (const vgpu::Texture* s : sources) dev.bind_texture(unit++, *s);
  dev.set_targets({&target});
  dev.draw();
}

// GPU time of that pass on the GL device, ms: the median of the last `runs` of passes drawn
// for at least `warmup_ms` (a GPU that sat idle runs at a lower clock).
double gpu_ms_of_pass(gl::GlDevice& d, const vgpu::Program& p,
                      std::initializer_list<const vgpu::Texture*> sources, vgpu::Texture& target,
                      int runs, int warmup_ms) {
  std::vector<double> gpu;
  const auto t0 = Clock::now();
  for (int r = 0; r < runs || ms_since(t0) < warmup_ms; ++r) {
    d.finish();
    d.stats().clear();
    draw_pass(d, p, sources, target);
    d.finish();
    gpu.push_back(d.stats().totals.device_ms);
  }
  return median({gpu.end() - std::min<ptrdiff_t>(runs, ptrdiff_t(gpu.size())), gpu.end()});
}

// GPU time of one pass of p over a 1x1 target reading `source`, us.
double time_one_fragment(gl::GlDevice& d, const vgpu::Program& p, const vgpu::Texture& source,
                         int runs, int warmup_ms) {
  vgpu::Texture target = d.make_texture("latency target", 1, 1, 4);
  d.upload(target);
  return 1e3 * gpu_ms_of_pass(d, p, {&source}, target, runs, warmup_ms);
}

}  // namespace

nlohmann::ordered_json measure_latencies(gl::GlDevice& d, int runs, int warmup_ms) {
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  const int short_steps = 1024, long_steps = 8192;
  const double mhz = vgpu::profile("h200").core_mhz;
  auto report = [&](const std::string& what, int texels, const vgpu::Program& a,
                    const vgpu::Program& b, const vgpu::Texture& t, int ops) {
    const vgpu::LoopTally chain = a.analyze().loop;  // what the model's span counts of it
    const double ta = time_one_fragment(d, a, t, runs, warmup_ms);
    const double tb = time_one_fragment(d, b, t, runs, warmup_ms);
    const double ns = 1e3 * (tb - ta) / (long_steps - short_steps);
    std::printf(
        "  %-34s %9d texels  %5d steps %9.1f us  %5d steps %9.1f us  => %7.1f ns, "
        "%6.0f clocks an iteration\n",
        what.c_str(), texels, short_steps, ta, long_steps, tb, ns, ns * mhz * 1e-3);
    std::fflush(stdout);
    rows.push_back({{"what", what},
                    {"texels", texels},
                    {"bytes", uint64_t(texels) * 16},
                    {"ops_per_iteration", ops},
                    {"chain_fetches", chain.chain_fetches},
                    {"chain_operations", chain.chain_operations},
                    {"short_steps", short_steps},
                    {"short_us", ta},
                    {"long_steps", long_steps},
                    {"long_us", tb},
                    {"ns_per_iteration", ns},
                    {"clocks_per_iteration_at_boost", ns * mhz * 1e-3}});
  };
  std::printf("latency probes (one fragment, GPU timer queries, medians of %d passes):\n", runs);
  for (int side : {16, 512, 2048}) {
    // One random cycle through every texel: texel i holds the coordinates of texel perm[i + 1].
    vgpu::Texture links = d.make_texture("links", side, side, 4);
    std::vector<int> perm(size_t(side) * side);
    for (size_t i = 0; i < perm.size(); ++i) perm[i] = int(i);
    std::mt19937 rng(12345);
    std::shuffle(perm.begin() + 1, perm.end(), rng);  // texel 0 (the fragment's own) starts
    std::vector<float> data(perm.size() * 4);
    for (size_t i = 0; i < perm.size(); ++i) {
      const int next = perm[(i + 1) % perm.size()];
      const size_t at = size_t(perm[i]) * 4;
      data[at] = float(next % side) + 0.5f;
      data[at + 1] = float(next / side) + 0.5f;
      data[at + 2] = 0.0f;
      data[at + 3] = 1.0f;
    }
    links.replace(data);
    d.upload(links);
    vgpu::KernelProgram<FetchChase> a(FetchChase{short_steps}), b(FetchChase{long_steps});
    report("dependent fetch (RGBA32F)", side * side, a, b, links, 1);
  }
  vgpu::Texture seed = d.make_texture("seed", 1, 1, 4);
  seed.fill(std::array<float, 4>{0.5f, 1.0f, 0.0f, 1.0f});
  d.upload(seed);
  vgpu::KernelProgram<AluChain> a(AluChain{short_steps}), b(AluChain{long_steps});
  report("16 dependent multiply-adds", 1, a, b, seed, 2 * AluChain::kChain);
  return rows;
}

// FetchSpread over a 512x512 data texture (4 MB, inside the L2); the counts do not see where a
// fetch goes.
nlohmann::ordered_json measure_coherence(gl::GlDevice& d, int runs, int warmup_ms,
                                         const vgpu::Profile& card) {
  constexpr int kSize = 256, kSide = 512, kTile[2] = {8, 4};  // a warp's fragments: 8x4
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  std::vector<float> values(size_t(kSide) * kSide * 4);
  {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (float& x : values) x = u(rng);
  }
  vgpu::Texture data = d.make_texture("data", kSide, kSide, 4);
  data.replace(values);
  d.upload(data);
  vgpu::Texture target = d.make_texture("coherence target", kSize, kSize, 4);
  d.upload(target);
  const vgpu::KernelProgram<FetchSpread> program{FetchSpread{}};
  // The pass's counts as the emulator makes them (the GL device does not count a loop's
  // iterations lane by lane), priced on the card's profile.
  auto emulated = [&](const std::vector<float>& base_texels) {
    vgpu::Gpu emu(card);
    vgpu::Texture eb = emu.make_texture("bases", kSize, kSize, 4);
    eb.replace(base_texels);
    vgpu::Texture ed = emu.make_texture("data", kSide, kSide, 4);
    ed.replace(values);
    vgpu::Texture et = emu.make_texture("coherence target", kSize, kSize, 4);
    emu.upload(eb);
    emu.upload(ed);
    emu.stats().clear();
    draw_pass(emu, program, {&eb, &ed}, et);
    return emu.stats();
  };
  std::printf(
      "coherence probes (%dx%d pass, %d fetches a fragment from a %dx%d RGBA32F texture, "
      "GPU timer queries, medians of %d passes; priced on %s):\n",
      kSize, kSize, FetchSpread::kSpreadSteps, kSide, kSide, runs, card.name.c_str());
  const char* names[] = {"one texel for every fragment", "one texel for each 8x4 tile (warp)",
                         "each fragment its own texel, neighbours adjacent",
                         "each fragment a random texel"};
  for (int pattern = 0; pattern < 4; ++pattern) {
    std::mt19937 rng(99);
    std::uniform_int_distribution<int> pick(0, kSide - 1);
    // A random texel for each 8x4 tile, and one for each fragment (drawn as it is placed).
    std::vector<std::pair<int, int>> tiles(size_t(kSize / kTile[0]) * (kSize / kTile[1]));
    for (auto& t : tiles) t = {pick(rng), pick(rng)};
    vgpu::Texture bases = d.make_texture("bases", kSize, kSize, 4);
    std::vector<float> v(size_t(kSize) * kSize * 4);
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        std::pair<int, int> t{0, 0};
        if (pattern == 1)
          t = tiles[size_t(y / kTile[1]) * (kSize / kTile[0]) + size_t(x / kTile[0])];
        if (pattern == 2) t = {x, y};
        if (pattern == 3) t = {pick(rng), pick(rng)};
        float* at = v.data() + (size_t(y) * kSize + size_t(x)) * 4;
        at[0] = float(t.first) + 0.5f;
        at[1] = float(t.second) + 0.5f;
        at[2] = float(kSide);
        at[3] = 1.0f;
      }
    bases.replace(v);
    d.upload(bases);
    const vgpu::FrameStats one = emulated(v);
    const double ms = gpu_ms_of_pass(d, program, {&bases, &data}, target, runs, warmup_ms);
    const host::CostBreakdown b = host::predict(one, card);
    const double work = b.arithmetic_ms + b.texture_ms + b.memory_ms + b.latency_ms;
    const double bytes = double(one.totals.bytes_read);
    const double per_clock = ms > 0 ? bytes / (ms * 1e-3 * card.core_mhz * 1e6) : 0.0;
    std::printf("  %-50s GPU %8.3f ms  priced work %8.3f ms  (%5.2fx)  %6.1f bytes a clock\n",
                names[pattern], ms, work, work > 0 ? ms / work : 0.0, per_clock);
    std::fflush(stdout);
    rows.push_back({{"what", names[pattern]},
                    {"size", kSize},
                    {"data_side", kSide},
                    {"fetches_per_fragment", FetchSpread::kSpreadSteps},
                    {"texture_fetches", one.totals.texture_fetches},
                    {"bytes_read", one.totals.bytes_read},
                    {"gpu_ms", ms},
                    {"card_profile", card.name},
                    {"priced_work_ms", work},
                    {"priced_texture_demand_ms", b.texture_demand_ms},
                    {"bytes_per_clock", per_clock}});
  }
  return rows;
}

}  // namespace bench_gl_probes
