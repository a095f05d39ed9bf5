#include "thread_pool.hpp"

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

// The hand-off. A job is published as one 64-bit ticket: the next unclaimed block
// from the front in the low 32 bits, one past the last unclaimed block in the high
// 32. The calling thread claims from the front, the workers from the back (one
// compare-and-swap each), so in every job of a substep the caller runs the low
// blocks and the workers the high ones: a particle's data stays in the cache of
// the core that wrote it in the last stage (the split moves little between jobs of
// the same size). Which thread runs a block never changes what the block computes.
// A claim on a ticket whose front has met its back claims nothing, so a worker that
// wakes late (it was descheduled on a busy machine) finds the ticket of a finished
// job closed and never reads that job's state. The caller waits for the job's
// blocks to be done, not for every worker to check in: a worker that is not
// running holds nothing up unless it holds a block.
namespace {
constexpr std::uint64_t kHalfBits = 32;
constexpr std::uint64_t kHalfMask = (std::uint64_t(1) << kHalfBits) - 1;
}  // namespace

void ThreadPool::runBlocks(bool front) {
  for (;;) {
    std::uint64_t t = ticket_.load(std::memory_order_acquire);
    std::size_t k = 0;
    for (;;) {
      const std::uint64_t lo = t & kHalfMask, hi = t >> kHalfBits;
      if (lo >= hi) return;  // closed: every block of the job under way (if any) is claimed
      const std::uint64_t next = front ? t + 1 : t - (std::uint64_t(1) << kHalfBits);
      if (ticket_.compare_exchange_weak(t, next, std::memory_order_acq_rel, std::memory_order_acquire)) {
        k = std::size_t(front ? lo : hi - 1);
        break;
      }
    }
    const std::size_t b = k * block_;
    const std::size_t e = b + block_ < n_ ? b + block_ : n_;
    try {
      (*fn_)(b, e);
    } catch (...) {
      std::lock_guard<std::mutex> lock(errorMutex_);
      if (!error_) error_ = std::current_exception();
    }
    done_.fetch_add(1, std::memory_order_acq_rel);
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
    runBlocks(false);
  }
}

void ThreadPool::parallelFor(std::size_t n, std::size_t block,
                             const std::function<void(std::size_t, std::size_t)>& fn) {
  if (n == 0) return;
  if (block == 0) block = 1;
  const std::size_t blocks = (n + block - 1) / block;
  // Serial when alone, when one block holds everything, and (never met: blocks are
  // hundreds of items) beyond the ticket's block count. The same blocks either way.
  if (workers_.empty() || blocks == 1 || blocks + 1024 > kHalfMask) {
    for (std::size_t b = 0; b < n; b += block) fn(b, b + block < n ? b + block : n);
    return;
  }
  // The ticket is closed here (the last job's blocks are all claimed): no worker
  // reads what is written before it opens.
  fn_ = &fn;
  n_ = n;
  block_ = block;
  error_ = nullptr;
  done_.store(0, std::memory_order_relaxed);
  ticket_.store(std::uint64_t(blocks) << kHalfBits, std::memory_order_release);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    epoch_.fetch_add(1, std::memory_order_acq_rel);
  }
  wake_.notify_all();
  runBlocks(true);
  // Wait for blocks other threads hold: spin briefly, then yield the core.
  for (unsigned spins = 0; done_.load(std::memory_order_acquire) != blocks; ++spins) {
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
