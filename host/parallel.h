// A row-parallel worker pool shared by the CPU tracer and the test references.
#pragma once

#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>
#include <vector>

namespace host {

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
