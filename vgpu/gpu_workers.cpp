// The Gpu's thread pool: the workers the constructor starts and the destructor stops, and the
// jobs handed to them (a pass's row chunks, parallel_for's items); the calling thread works too.
#include <algorithm>
#include <atomic>
#include <functional>
#include <thread>
#include <vector>

#include "vgpu/gpu.h"
#include "vgpu/gpu_internal.h"

namespace vgpu {

Gpu::Gpu(const Profile& profile, int threads, int lanes) : profile_(profile), lanes_(lanes) {
  if (lanes != 1 && lanes != 4 && lanes != 8 && lanes != 16)
    throw Error("lane width must be 1, 4, 8 or 16 (got " + std::to_string(lanes) + ")");
  if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { worker_loop(); });
}

Gpu::~Gpu() {
  {
    std::lock_guard lk(mu_);
    stop_ = true;
  }
  cv_work_.notify_all();
  for (auto& w : workers_) w.join();
}

void Gpu::parallel_rows(const Rect& r, uint64_t work,
                        const std::function<void(int, int, Chunk&)>& body,
                        std::vector<Chunk>& chunks) {
  const int rows = r.height();
  // Enough chunks to balance uneven rows, few enough to keep scheduling cheap; a pass that
  // visits few fragments runs on the calling thread (waking workers would cost more).
  const bool small = work < 4096;
  const int nchunks = small ? 1 : std::max(1, std::min(rows, threads() * 8));
  chunks.resize(size_t(nchunks));
  for (Chunk& c : chunks) c.reset();
  std::atomic<int> next{0};
  const std::function<void()> job = [&] {
    for (;;) {
      const int k = next.fetch_add(1);
      if (k >= nchunks) return;
      const int ya = r.y0 + int(int64_t(rows) * k / nchunks);
      const int yb = r.y0 + int(int64_t(rows) * (k + 1) / nchunks);
      body(ya, yb, chunks[size_t(k)]);
    }
  };
  if (workers_.empty() || nchunks == 1) {
    job();
    return;
  }
  run_on_workers(job);
}

// job() on the calling thread and on every worker, until all have returned.
void Gpu::run_on_workers(const std::function<void()>& job) {
  {
    std::lock_guard lk(mu_);
    job_ = &job;
    ++job_serial_;
    busy_ = int(workers_.size());
  }
  cv_work_.notify_all();
  job();
  std::unique_lock lk(mu_);
  cv_done_.wait(lk, [&] { return busy_ == 0; });
  job_ = nullptr;
}

void Gpu::worker_loop() {
  uint64_t seen = 0;
  std::unique_lock lk(mu_);
  for (;;) {
    cv_work_.wait(lk, [&] { return stop_ || job_serial_ != seen; });
    if (stop_) return;
    seen = job_serial_;
    const std::function<void()>* job = job_;
    lk.unlock();
    (*job)();
    lk.lock();
    if (--busy_ == 0) cv_done_.notify_one();
  }
}

void Gpu::parallel_for(int n, const std::function<void(int, int)>& body) {
  std::atomic<int> next{0}, slot{0};
  const std::function<void()> job = [&] {
    const int mine = slot.fetch_add(1);
    for (;;) {
      const int k = next.fetch_add(1);
      if (k >= n) return;
      body(k, mine);
    }
  };
  if (workers_.empty() || n <= 1) {
    job();
    return;
  }
  run_on_workers(job);
}

void Gpu::parallel_blocks(size_t n, size_t serial_below,
                          const std::function<void(size_t, size_t)>& body) {
  const size_t blocks = std::min(n, size_t(threads()) * 4);
  if (n < serial_below || blocks <= 1) {
    body(0, n);
    return;
  }
  parallel_for(int(blocks),
               [&](int k, int) { body(n * size_t(k) / blocks, n * size_t(k + 1) / blocks); });
}

}  // namespace vgpu
