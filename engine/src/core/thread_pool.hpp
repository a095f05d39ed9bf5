// sph2d/thread_pool.hpp — the job system every stage runs on.
//
// Work is cut into fixed blocks whose boundaries depend only on the item
// count and the block size, never on the thread count. Threads claim blocks
// dynamically, but each block writes only its own items (gathers), and
// reductions keep one partial result per block and combine them in block
// order on the calling thread. So results are bit-identical for any number of
// threads.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace sph2d {

/// A small fork-join pool: the calling thread plus `threads − 1` workers.
class ThreadPool {
 public:
  /// Creates the pool; `threads` = 0 means all hardware threads.
  explicit ThreadPool(int threads = 0);
  /// Joins the workers.
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  /// Number of threads that run jobs (workers + the caller).
  int size() const { return static_cast<int>(workers_.size()) + 1; }

  /// Calls fn(begin, end) for every block [k·block, min(n, (k+1)·block)).
  /// Returns when all blocks are done; rethrows the first exception thrown. With a cancel
  /// flag set (setCancel) the blocks not started yet are skipped and it throws
  /// sph2d::Interrupted (with an empty stage: the caller names it).
  void parallelFor(std::size_t n, std::size_t block, const std::function<void(std::size_t, std::size_t)>& fn);

  /// Makes every job read `*flag` (null: nothing) before each block it starts: once it is
  /// true, the job's remaining blocks are skipped and parallelFor throws Interrupted. Set
  /// between jobs by the thread that calls parallelFor. A relaxed load a block: blocks are
  /// hundreds of items, and the blocks (so the results) do not change.
  void setCancel(const std::atomic<bool>* flag) { cancel_ = flag; }

  /// Deterministic reduction: blockFn(begin, end) → T per block, then
  /// combine(acc, part) over blocks in increasing order starting from init.
  template <class T, class BlockFn, class Combine>
  T reduce(std::size_t n, std::size_t block, T init, BlockFn blockFn, Combine combine) {
    const std::size_t blocks = n == 0 ? 0 : (n + block - 1) / block;
    std::vector<T> parts(blocks, init);
    parallelFor(n, block, [&](std::size_t b, std::size_t e) { parts[b / block] = blockFn(b, e); });
    T acc = init;
    for (const T& p : parts) acc = combine(acc, p);
    return acc;
  }

 private:
  void workerLoop(std::size_t self);
  void runBlocks(std::size_t self);

  /// One thread's share of a job's blocks: the next unclaimed (low 32 bits) and one past
  /// the last (high 32), alone on its cache line.
  struct alignas(64) Share {
    std::atomic<std::uint64_t> word{0};
  };

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::atomic<unsigned long long> epoch_{0};
  std::vector<Share> shares_;                     ///< per thread (0: the caller), the job's unclaimed blocks
  alignas(64) std::atomic<std::size_t> done_{0};  ///< blocks of the job finished
  std::atomic<bool> stop_{false};
  const std::function<void(std::size_t, std::size_t)>* fn_ = nullptr;
  std::size_t n_ = 0, block_ = 1;
  const std::atomic<bool>* cancel_ = nullptr;  ///< setCancel's flag (read after a claim, like fn_)
  std::atomic<bool> cancelled_{false};         ///< a block of this job was skipped
  /// True when the cancel flag is set (then the job is marked cancelled).
  bool cancelNow() {
    if (!cancel_ || !cancel_->load(std::memory_order_relaxed)) return false;
    cancelled_.store(true, std::memory_order_relaxed);
    return true;
  }
  /// Throws Interrupted when the job just run was cancelled.
  void throwIfCancelled();
  std::mutex errorMutex_;
  std::exception_ptr error_;
};

}  // namespace sph2d
