// thread_pool.cpp — the job system every stage runs on (thread_pool.hpp): a fork-join
// pool whose jobs are fixed blocks claimed dynamically, so that results never depend on
// which thread ran a block (docs/ARCHITECTURE.md, "the job system").
//
// The hand-off. A job's blocks are cut into one contiguous share per thread (the same
// shares for every job of the same size), each share one 64-bit word on its own cache
// line: the next unclaimed block in the low 32 bits, one past the last in the high 32.
// A thread claims from the front of its own share (an atomic add on a line the others
// touch only once their own shares are used up), then from the back of the others' (a
// compare-and-swap of the high half, only while the share holds a block). Each claim is
// one atomic read-modify-write of one word, so each block is claimed once: an add whose
// old word has next >= end claims nothing (and leaves next past the end, which reads the
// same); the end never drops below next, so never below 0. Each thread adds its count of
// finished blocks once, at the end. So a particle's data stays in the cache of the core
// that wrote it in the last stage, and only steals and the one done add per thread move
// a line between the cores (one shared ticket and a done add per block cost a line
// transfer per block: 21 us against 6 us for a trivial 79-block job on this 2-core
// machine). Which thread runs a block never changes what the block computes.
//
// A worker that wakes late (descheduled on a busy machine) claims nothing from the
// shares of a finished job (all used up); if the caller has published the next job's
// shares meanwhile, its claim is a claim of that job, and it reads the job (fn_, n_,
// block_, written before the shares) after the claim. The caller waits for the job's
// blocks to be done, not for every worker to check in.
#include "core/thread_pool.hpp"

#include <chrono>

#include "sph2d/world.hpp"  // sph2d::Interrupted
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define SPH2D_PAUSE() _mm_pause()
#else
#define SPH2D_PAUSE() ((void)0)
#endif

namespace sph2d {

namespace {
constexpr std::uint64_t kHalfBits = 32;
constexpr std::uint64_t kHalfMask = (std::uint64_t(1) << kHalfBits) - 1;
constexpr std::uint64_t kOneEnd = std::uint64_t(1) << kHalfBits;
}  // namespace

ThreadPool::ThreadPool(int threads) {
  int n = threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency());
  if (n < 1) n = 1;
  shares_ = std::vector<Share>(static_cast<std::size_t>(n));
  workers_.reserve(static_cast<std::size_t>(n - 1));
  for (int i = 1; i < n; ++i) workers_.emplace_back([this, i] { workerLoop(std::size_t(i)); });
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

void ThreadPool::runBlocks(std::size_t self) {
  const std::size_t threads = shares_.size();
  std::size_t finished = 0;
  for (std::size_t k = 0; k < threads; ++k) {
    std::atomic<std::uint64_t>& share = shares_[(self + k) % threads].word;
    const bool own = k == 0;  // own share from the front, the others' from the back
    for (;;) {
      std::uint64_t was = share.load(std::memory_order_relaxed);
      if ((was & kHalfMask) >= (was >> kHalfBits)) break;  // used up (a cheap look before the write)
      if (own) {
        was = share.fetch_add(1, std::memory_order_acq_rel);
      } else {
        // A steal takes the last block only while the share holds one: an unconditional
        // subtract could take the end below 0 (a share [0, 1) and two thieves) and open
        // 2^32 blocks that do not exist.
        while ((was & kHalfMask) < (was >> kHalfBits) &&
               !share.compare_exchange_weak(was, was - kOneEnd, std::memory_order_acq_rel, std::memory_order_relaxed)) {
        }
      }
      const std::uint64_t lo = was & kHalfMask, hi = was >> kHalfBits;
      if (lo >= hi) break;
      const std::size_t blk = std::size_t(own ? lo : hi - 1);
      const std::size_t b = blk * block_;
      const std::size_t e = b + block_ < n_ ? b + block_ : n_;
      try {
        if (!cancelNow()) (*fn_)(b, e);  // a skipped block still counts as done
      } catch (...) {
        std::lock_guard<std::mutex> lock(errorMutex_);
        if (!error_) error_ = std::current_exception();
      }
      ++finished;
    }
  }
  if (finished) done_.fetch_add(finished, std::memory_order_acq_rel);
}

void ThreadPool::workerLoop(std::size_t self) {
  unsigned long long seen = 0;
  for (;;) {
    // Spin briefly (a step launches many short jobs), then sleep.
    auto start = std::chrono::steady_clock::now();
    unsigned spins = 0;
    while (epoch_.load(std::memory_order_acquire) == seen) {
      SPH2D_PAUSE();
      if (++spins % 256 == 0 && std::chrono::steady_clock::now() - start > std::chrono::microseconds(100)) {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return epoch_.load(std::memory_order_acquire) != seen; });
        break;
      }
    }
    seen = epoch_.load(std::memory_order_acquire);
    if (stop_.load()) return;
    runBlocks(self);
  }
}

void ThreadPool::parallelFor(std::size_t n, std::size_t block,
                             const std::function<void(std::size_t, std::size_t)>& fn) {
  if (n == 0) return;
  if (block == 0) block = 1;
  const std::size_t blocks = (n + block - 1) / block;
  // Serial when alone, when one block holds everything, and (never met: blocks are
  // hundreds of items) beyond a share's block count. The same blocks either way.
  if (workers_.empty() || blocks == 1 || blocks + 1024 > kHalfMask) {
    for (std::size_t b = 0; b < n; b += block) {
      if (cancelNow()) break;
      fn(b, b + block < n ? b + block : n);
    }
    throwIfCancelled();
    return;
  }
  // Every share of the last job is used up here: no worker reads what is written before
  // a share opens.
  fn_ = &fn;
  n_ = n;
  block_ = block;
  error_ = nullptr;
  done_.store(0, std::memory_order_relaxed);
  const std::size_t threads = shares_.size();
  for (std::size_t t = 0; t < threads; ++t) {
    const std::uint64_t first = std::uint64_t(blocks) * t / threads, last = std::uint64_t(blocks) * (t + 1) / threads;
    shares_[t].word.store((last << kHalfBits) | first, std::memory_order_release);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    epoch_.fetch_add(1, std::memory_order_acq_rel);
  }
  wake_.notify_all();
  runBlocks(0);
  // Wait for blocks other threads hold: spin briefly, then yield the core.
  for (unsigned spins = 0; done_.load(std::memory_order_acquire) != blocks; ++spins) {
    if (spins < 2048)
      SPH2D_PAUSE();
    else
      std::this_thread::yield();
  }
  fn_ = nullptr;
  if (error_) {
    std::exception_ptr e = error_;
    error_ = nullptr;
    cancelled_.store(false, std::memory_order_relaxed);
    std::rethrow_exception(e);
  }
  throwIfCancelled();
}

void ThreadPool::throwIfCancelled() {
  if (!cancelled_.exchange(false, std::memory_order_relaxed)) return;
  throw Interrupted("stopped by the stop flag", "");
}

}  // namespace sph2d
