// Small host-side helpers: a row-parallel worker pool (the CPU tracer, the test references) and
// the wall-clock milliseconds the tracers and the grid builder report.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <thread>
#include <vector>

namespace host {

// Milliseconds of wall time since t0 (std::chrono::steady_clock).
inline double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Calls body(worker, y) once for every row y in [0, rows), on `workers` threads (clamped to
// [1, rows]; the calling thread is worker 0, the others are std::jthreads joined before the
// return). Rows are handed out one at a time, in no fixed order, so the result must not depend on
// which worker takes which row; per-worker state can be indexed by `worker`, which is below the
// clamped count. The first exception thrown by body stops the handing out of rows and is rethrown
// here once every worker has finished.
template <class F>
void for_each_row(int rows, unsigned workers, F body) {
  workers = std::clamp<unsigned>(workers, 1u, unsigned(std::max(rows, 1)));
  std::atomic<int> next_row{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  auto work = [&](unsigned worker) {
    try {
      for (int y; !failed && (y = next_row++) < rows;) body(worker, y);
    } catch (...) {
      if (!failed.exchange(true)) error = std::current_exception();
    }
  };
  {
    std::vector<std::jthread> pool;
    for (unsigned k = 1; k < workers; ++k) pool.emplace_back(work, k);
    work(0);
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace host
