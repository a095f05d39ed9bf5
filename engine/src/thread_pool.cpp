#include "sph2d/thread_pool.hpp"

#include <chrono>
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define SPH2D_PAUSE() _mm_pause()
#else
#define SPH2D_PAUSE() ((void)0)
#endif

namespace sph2d {

ThreadPool::ThreadPool(int threads) {
  int n = threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency());
  if (n < 1) n = 1;
  workers_.reserve(static_cast<std::size_t>(n - 1));
  for (int i = 1; i < n; ++i) workers_.emplace_back([this] { workerLoop(); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_.store(true);
    epoch_.fetch_add(1);
  }
  wake_.notify_all();
  for (auto& t : workers_) t.join();
}

void ThreadPool::runBlocks() {
  for (;;) {
    const std::size_t k = next_.fetch_add(1, std::memory_order_relaxed);
    const std::size_t b = k * block_;
    if (b >= n_) break;
    const std::size_t e = b + block_ < n_ ? b + block_ : n_;
    try {
      (*fn_)(b, e);
    } catch (...) {
      std::lock_guard<std::mutex> lock(errorMutex_);
      if (!error_) error_ = std::current_exception();
    }
  }
}

void ThreadPool::workerLoop() {
  unsigned long long seen = 0;
  for (;;) {
    // Spin briefly (a step launches many short jobs), then sleep.
    auto start = std::chrono::steady_clock::now();
    unsigned spins = 0;
    while (epoch_.load(std::memory_order_acquire) == seen) {
      SPH2D_PAUSE();
      if (++spins % 256 == 0 &&
          std::chrono::steady_clock::now() - start > std::chrono::microseconds(100)) {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return epoch_.load(std::memory_order_acquire) != seen; });
        break;
      }
    }
    seen = epoch_.load(std::memory_order_acquire);
    if (stop_.load()) return;
    runBlocks();
    busy_.fetch_sub(1, std::memory_order_acq_rel);
  }
}

void ThreadPool::parallelFor(std::size_t n, std::size_t block,
                             const std::function<void(std::size_t, std::size_t)>& fn) {
  if (n == 0) return;
  if (block == 0) block = 1;
  if (workers_.empty() || n <= block) {
    for (std::size_t b = 0; b < n; b += block) fn(b, b + block < n ? b + block : n);
    return;
  }
  fn_ = &fn;
  n_ = n;
  block_ = block;
  error_ = nullptr;
  next_.store(0, std::memory_order_relaxed);
  busy_.store(static_cast<int>(workers_.size()), std::memory_order_relaxed);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    epoch_.fetch_add(1, std::memory_order_acq_rel);
  }
  wake_.notify_all();
  runBlocks();
  // Wait for the workers: spin briefly, then yield the core (on a busy machine
  // the worker may be descheduled, and spinning would only delay it).
  for (unsigned spins = 0; busy_.load(std::memory_order_acquire) != 0; ++spins) {
    if (spins < 2048) SPH2D_PAUSE();
    else std::this_thread::yield();
  }
  fn_ = nullptr;
  if (error_) {
    std::exception_ptr e = error_;
    error_ = nullptr;
    std::rethrow_exception(e);
  }
}

}  // namespace sph2d
