// Benchmark: the virtual GPU's fragment throughput against a plain C++ loop doing the same work.
// One pass over 1024x1024 fragments: three fetches from fp32x4 textures, 14 arithmetic ops, one
// fp32x4 write; statistics on, as always. Lane widths 1 and 8, one thread and every core. After
// the runs it prints vgpu/plain for each (the medians when run with --benchmark_repetitions).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <barrier>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "vgpu/vgpu.h"

namespace {

constexpr int kSize = 1024;
constexpr double kFragments = double(kSize) * kSize;
// Bytes one fragment moves: three fp32x4 texels read, one written.
constexpr double kBytesPerFragment = 3 * 16 + 16;

int all_cores() {
  return int(std::max(1u, std::thread::hardware_concurrency()));
}

// The pass: 3 fetches + 14 ops = 17 instructions per fragment.
struct Blend3 {
  static constexpr const char* name = "blend3";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    using F = typename L::F;
    const vgpu::Vec4<F> a = f.fetch_own(0), b = f.fetch_own(1), c = f.fetch_own(2);
    const F d = a.x * b.x + a.y * b.y + a.z * b.z;
    const F e = d * c.w - c.x;
    f.out(0) = {a.x + e * b.w, a.y - d * c.y, min(a.z, c.z) + b.z, e * F(0.5f)};
  }
};

// The same arithmetic on the same arrays (row-major fp32x4 texels), for pixels [i0, i1).
void plain_rows(const float* a, const float* b, const float* c, float* o, size_t i0, size_t i1) {
  for (size_t i = i0; i < i1; ++i) {
    const float* pa = a + 4 * i;
    const float* pb = b + 4 * i;
    const float* pc = c + 4 * i;
    float* po = o + 4 * i;
    const float d = pa[0] * pb[0] + pa[1] * pb[1] + pa[2] * pb[2];
    const float e = d * pc[3] - pc[0];
    po[0] = pa[0] + e * pb[3];
    po[1] = pa[1] - d * pc[1];
    po[2] = (pa[2] < pc[2] ? pa[2] : pc[2]) + pb[2];
    po[3] = e * 0.5f;
  }
}

// A fixed set of threads for the plain loop, so it pays no thread start-up per pass either.
class Pool {
 public:
  explicit Pool(int threads) : sync_(threads) {
    for (int t = 1; t < threads; ++t)
      workers_.emplace_back([this, t] {
        for (;;) {
          sync_.arrive_and_wait();
          if (stop_) return;
          job_(t);
          sync_.arrive_and_wait();
        }
      });
  }
  ~Pool() {
    stop_ = true;
    sync_.arrive_and_wait();
    for (auto& w : workers_) w.join();
  }
  int size() const { return int(workers_.size()) + 1; }
  // Runs job(t) for t = 0..size()-1, t = 0 on the calling thread.
  void run(std::function<void(int)> job) {
    job_ = std::move(job);
    sync_.arrive_and_wait();
    job_(0);
    sync_.arrive_and_wait();
  }

 private:
  std::barrier<> sync_;
  std::vector<std::thread> workers_;
  std::function<void(int)> job_;
  bool stop_ = false;  // written before a barrier phase, read after it
};

struct Inputs {
  vgpu::Texture a, b, c, out;
};

Inputs make_inputs() {
  Inputs in{vgpu::Texture("a", kSize, kSize, 4), vgpu::Texture("b", kSize, kSize, 4),
            vgpu::Texture("c", kSize, kSize, 4), vgpu::Texture("out", kSize, kSize, 4)};
  uint32_t s = 1;
  for (vgpu::Texture* t : {&in.a, &in.b, &in.c})
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x)
        for (int ch = 0; ch < 4; ++ch) {
          s = s * 1664525u + 1013904223u;
          t->set(x, y, ch, float(s >> 8) / float(1 << 24) * 2.0f - 1.0f);
        }
  return in;
}

void set_rates(benchmark::State& state) {
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kFragments));
  state.SetBytesProcessed(int64_t(double(state.iterations()) * kFragments * kBytesPerFragment));
  state.counters["fragments/s"] =
      benchmark::Counter(kFragments, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["bytes/s"] = benchmark::Counter(kFragments * kBytesPerFragment,
                                                 benchmark::Counter::kIsIterationInvariantRate,
                                                 benchmark::Counter::OneK::kIs1024);
}

// args: lanes, threads (0: every core)
void BM_vgpu_pass(benchmark::State& state) {
  const int lanes = int(state.range(0));
  const int threads = state.range(1) ? int(state.range(1)) : all_cores();
  Inputs in = make_inputs();
  vgpu::Gpu gpu(vgpu::profile("gf6600"), threads, lanes);
  vgpu::KernelProgram<Blend3> blend;
  gpu.use_program(blend);
  gpu.bind_texture(0, in.a);
  gpu.bind_texture(1, in.b);
  gpu.bind_texture(2, in.c);
  gpu.set_targets({&in.out});
  for (auto _ : state) {
    const vgpu::PassRecord& r = gpu.draw();
    benchmark::DoNotOptimize(r.counters.bytes_read);
    benchmark::ClobberMemory();
  }
  // The statistics must describe the pass the plain loop does.
  const vgpu::Counters& t = gpu.stats().totals;
  const double passes = double(t.passes);
  if (t.texture_fetches != t.passes * 3 * uint64_t(kFragments) ||
      double(t.bytes_read + t.bytes_written) != passes * kFragments * kBytesPerFragment ||
      t.instructions != t.passes * 17 * uint64_t(kFragments))
    state.SkipWithError("statistics do not match the pass");
  set_rates(state);
  state.counters["threads"] = threads;
}

// args: threads (0: every core)
void BM_plain_loop(benchmark::State& state) {
  const int threads = state.range(0) ? int(state.range(0)) : all_cores();
  Inputs in = make_inputs();
  const float* a = in.a.data().data();
  const float* b = in.b.data().data();
  const float* c = in.c.data().data();
  float* o = in.out.texel_mut(0, 0);
  Pool pool(threads);
  const size_t n = size_t(kSize) * kSize;
  for (auto _ : state) {
    if (threads == 1) {
      plain_rows(a, b, c, o, 0, n);
    } else {
      pool.run([&](int t) {
        plain_rows(a, b, c, o, n * size_t(t) / size_t(threads),
                   n * size_t(t + 1) / size_t(threads));
      });
    }
    benchmark::DoNotOptimize(o);
    benchmark::ClobberMemory();
  }
  set_rates(state);
  state.counters["threads"] = threads;
}

BENCHMARK(BM_vgpu_pass)
    ->ArgNames({"lanes", "threads"})
    ->Args({1, 1})
    ->Args({8, 1})
    ->Args({1, 0})
    ->Args({8, 0})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_plain_loop)
    ->ArgNames({"threads"})
    ->Arg(1)
    ->Arg(0)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// Console output as usual, plus the fragments/s of each run kept for the ratios. With
// repetitions the median aggregate is kept; without, the single run.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  RatioReporter() : ConsoleReporter(isatty(fileno(stdout)) ? OO_Defaults : OO_Tabular) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      if (r.error_occurred) continue;
      const bool median = r.run_type == Run::RT_Aggregate && r.aggregate_name == "median";
      if (r.run_type == Run::RT_Aggregate && !median) continue;
      if (r.run_type == Run::RT_Iteration && r.repetitions > 1) continue;
      const auto it = r.counters.find("fragments/s");
      if (it != r.counters.end()) rate_[r.run_name.str()] = it->second.value;
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    const std::string cores = std::to_string(all_cores());
    std::printf("\nvgpu / plain loop, fragments/s (%s):\n",
                rate_.empty() ? "no runs" : "median when repeated");
    for (const char* threads : {"1", "0"}) {
      const auto plain = rate_.find(std::string("BM_plain_loop/threads:") + threads + "/real_time");
      if (plain == rate_.end()) continue;
      for (const char* lanes : {"1", "8"}) {
        const auto v = rate_.find(std::string("BM_vgpu_pass/lanes:") + lanes +
                                  "/threads:" + threads + "/real_time");
        if (v == rate_.end()) continue;
        std::printf("  lanes %-2s threads %-3s  vgpu %8.1f M/s  plain %8.1f M/s  ratio %.2f\n",
                    lanes, threads[0] == '0' ? cores.c_str() : threads, v->second / 1e6,
                    plain->second / 1e6, v->second / plain->second);
      }
    }
  }

 private:
  std::map<std::string, double> rate_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
