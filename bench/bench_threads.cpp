// Benchmark: how the emulator's frame time falls with threads. Renders one frame through the
// command line's own code (cli::run_render, so the frame is `vgpu-rt render SCENE --size WxH`
// exactly) at each thread count, in rounds that visit every count once (a noisy machine slows
// them alike), and prints per count the median frame time (initialization + render, host ms),
// the render alone, and the speed-up over one thread. Every count's image and statistics are
// compared with one thread's, byte for byte (the statistics without their timing keys): a
// difference stops the benchmark. Figures in docs/studies/speed.md ("Threads").
//
//   bench_threads [--scene bunny-refl] [--size 1024x1024] [--threads 1,2,4,8,16] [--reps 3]
//                 [--render-option=--accel=bvh ...]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/cli/render.h"
#include "tests/support/stats_json.h"

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The statistics without what a clock measured, nor the thread count they were made with.
host::StatsJson untimed(const host::StatsJson& j) {
  host::StatsJson out = test_support::without_times(j);
  out.erase("threads");
  return out;
}

struct Frame {
  double frame_ms = 0, render_ms = 0;
  std::vector<float> image;  // linear RGB, and the depth and hit-id AOVs after it
  host::StatsJson stats;
};

Frame render(const std::string& scene, const std::string& size, int threads,
             const std::vector<std::string>& extra) {
  std::vector<std::string> args = {
      scene, "--size", size, "--threads", std::to_string(threads), "--stats", "none", "--quiet"};
  args.insert(args.end(), extra.begin(), extra.end());
  bool lanes_given = false;
  const cli::RenderArgs a = cli::parse_render_args(args, lanes_given);
  cli::RenderOutcome out;
  if (cli::run_render(a, lanes_given, &out) != 0) throw std::runtime_error("render failed");
  Frame f;
  f.render_ms = out.result.render_ms;
  f.frame_ms = out.stats.value("init_ms", 0.0) + out.result.render_ms;
  f.image = out.result.rgb;
  f.image.insert(f.image.end(), out.result.depth.begin(), out.result.depth.end());
  f.image.insert(f.image.end(), out.result.hit_id.begin(), out.result.hit_id.end());
  f.stats = untimed(out.stats);
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The emulator's frame time against its thread count (docs/studies/speed.md)."};
  std::string scene = "bunny-refl", size = "1024x1024";
  std::vector<int> counts = {1, 2, 4, 8, 16};
  std::vector<std::string> extra;
  int reps = 3;
  app.add_option("--scene", scene, "scene name or glTF file")->capture_default_str();
  app.add_option("--size", size, "frame size WxH")->capture_default_str();
  app.add_option("--threads", counts, "thread counts, the first the baseline")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--reps", reps, "rounds (the median is printed)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--render-option", extra,
                 "a further `vgpu-rt render` argument, e.g. --render-option=--accel "
                 "--render-option=bvh");
  CLI11_PARSE(app, argc, argv);
  if (counts.empty() || *std::min_element(counts.begin(), counts.end()) < 1) {
    std::fprintf(stderr, "bench_threads: --threads needs one or more counts of at least 1\n");
    return 2;
  }
  try {
    std::vector<std::vector<double>> frame(counts.size()), rend(counts.size());
    Frame base;
    for (int r = 0; r < reps; ++r)
      for (size_t k = 0; k < counts.size(); ++k) {
        Frame f = render(scene, size, counts[k], extra);
        if (r == 0 && k == 0) base = f;
        const bool same_image =
            f.image.size() == base.image.size() &&
            std::memcmp(f.image.data(), base.image.data(), f.image.size() * sizeof(float)) == 0;
        if (!same_image || f.stats != base.stats) {
          std::fprintf(stderr, "bench_threads: %d threads rendered another %s than %d\n", counts[k],
                       same_image ? "statistics" : "image", counts[0]);
          return 1;
        }
        frame[k].push_back(f.frame_ms);
        rend[k].push_back(f.render_ms);
        std::fprintf(stderr, "round %d/%d: %d threads %.0f ms\n", r + 1, reps, counts[k],
                     f.frame_ms);
      }
    std::printf("%s %s, %llu passes, median of %d; frame = initialization + render (host ms)\n",
                scene.c_str(), size.c_str(),
                static_cast<unsigned long long>(base.stats["totals"].value("passes", 0ull)), reps);
    std::printf("%8s %10s %10s %9s %10s\n", "threads", "frame ms", "render ms", "speed-up",
                "efficiency");
    const double f0 = median(frame[0]);
    for (size_t k = 0; k < counts.size(); ++k) {
      const double f = median(frame[k]), s = f0 / f;
      std::printf("%8d %10.1f %10.1f %8.2fx %9.0f%%\n", counts[k], f, median(rend[k]), s,
                  100.0 * s * counts[0] / counts[k]);
    }
    std::printf("images and statistics identical at every count\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_threads: %s\n", e.what());
    return 2;
  }
  return 0;
}
