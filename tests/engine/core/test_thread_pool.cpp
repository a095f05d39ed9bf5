// The job system (engine/src/core/thread_pool.cpp): fixed blocks that cover every
// index once whatever the thread count, reductions combined in block order (the
// engine's bit-identity across thread counts rests on it), exceptions carried
// back to the caller, and the per-thread shares: a held-up thread's blocks are
// taken by the others, and late workers claim nothing twice; a cancel flag skips the
// blocks not started.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/thread_pool.hpp"
#include "sph2d/world.hpp"  // sph2d::Interrupted

using namespace sph2d;

// Block k is [k·block, min(n, (k+1)·block)).
TEST_CASE(
    "parallelFor calls each block of the fixed split once, begin to end, and covers every index once, for 1 to 4 threads") {
  for (int threads = 1; threads <= 4; ++threads) {
    ThreadPool pool(threads);
    CHECK(pool.size() == threads);
    for (std::size_t n : {0u, 1u, 2u, 7u, 255u, 256u, 257u, 1000u, 4097u}) {
      for (std::size_t block : {1u, 3u, 64u, 256u, 4096u}) {
        CAPTURE(threads);
        CAPTURE(n);
        CAPTURE(block);
        std::unique_ptr<std::atomic<int>[]> hits(new std::atomic<int>[n + 1]);
        for (std::size_t i = 0; i <= n; ++i) hits[i] = 0;
        const std::size_t blocks = (n + block - 1) / block;
        std::unique_ptr<std::atomic<int>[]> calls(new std::atomic<int>[blocks + 1]);
        for (std::size_t k = 0; k <= blocks; ++k) calls[k] = 0;
        std::atomic<int> misaligned{0};
        pool.parallelFor(n, block, [&](std::size_t b, std::size_t e) {
          if (b % block != 0 || e != std::min(n, b + block) || b >= e) ++misaligned;
          ++calls[b / block];
          for (std::size_t i = b; i < e; ++i) ++hits[i];
        });
        int wrongIndex = 0, wrongBlock = 0;
        for (std::size_t i = 0; i < n; ++i) wrongIndex += hits[i] != 1;
        for (std::size_t k = 0; k < blocks; ++k) wrongBlock += calls[k] != 1;
        CHECK(misaligned == 0);
        CHECK(wrongIndex == 0);
        CHECK(wrongBlock == 0);
      }
    }
  }
}

TEST_CASE(
    "reduce combines the blocks' results in block order: a non-associative float sum is bit-identical for 1 to 4 threads") {
  // Values of both signs over nine decades: their float sum depends on the order.
  const std::size_t n = 10000, block = 256;
  std::vector<float> x(n);
  std::mt19937 g(11);
  for (std::size_t i = 0; i < n; ++i)
    x[i] = (float(g() % 20001) / 10000.0f - 1.0f) * std::pow(10.0f, float(int(i % 9) - 4));
  const auto blockSum = [&](std::size_t b, std::size_t e) {
    float s = 0;
    for (std::size_t i = b; i < e; ++i) s += x[i];
    return s;
  };
  // The reference: block sums combined in increasing block order, and the same sums in the opposite order.
  float forward = 0, backward = 0;
  const std::size_t blocks = (n + block - 1) / block;
  for (std::size_t k = 0; k < blocks; ++k) forward += blockSum(k * block, std::min(n, (k + 1) * block));
  for (std::size_t k = blocks; k-- > 0;) backward += blockSum(k * block, std::min(n, (k + 1) * block));
  MESSAGE("block order " << forward << ", reversed " << backward);
  REQUIRE(forward != backward);  // the order matters for this sum, so the check below can fail
  for (int threads = 1; threads <= 4; ++threads) {
    CAPTURE(threads);
    ThreadPool pool(threads);
    for (int repeat = 0; repeat < 20; ++repeat) {
      const float r = pool.reduce(n, block, 0.0f, blockSum, [](float a, float b) { return a + b; });
      CHECK(r == forward);
    }
  }
}

TEST_CASE("an exception thrown in a job is rethrown by parallelFor on the caller, and the pool keeps working") {
  for (int threads = 1; threads <= 4; ++threads) {
    CAPTURE(threads);
    ThreadPool pool(threads);
    std::atomic<int> ran{0};
    // Block 5 of 40 throws; the others run.
    try {
      pool.parallelFor(40 * 16, 16, [&](std::size_t b, std::size_t) {
        if (b / 16 == 5) throw std::runtime_error("block 5 failed");
        ++ran;
      });
      FAIL("the exception was lost");
    } catch (const std::runtime_error& e) {
      CHECK(std::string(e.what()) == "block 5 failed");
    }
    CHECK(ran <= 39);
    // Every block throws: one of their exceptions arrives, once.
    CHECK_THROWS_AS(pool.parallelFor(1000, 10, [](std::size_t, std::size_t) { throw std::logic_error("every block"); }),
                    std::logic_error);
    // The pool is not left broken: the next job runs every block.
    std::atomic<int> after{0};
    pool.parallelFor(1000, 10, [&](std::size_t b, std::size_t e) { after += int(e - b); });
    CHECK(after == 1000);
  }
}

TEST_CASE("a pool of 0 threads takes the hardware's, at least one") {
  ThreadPool pool(0);
  CHECK(pool.size() >= 1);
  std::atomic<int> sum{0};
  pool.parallelFor(100, 7, [&](std::size_t b, std::size_t e) { sum += int(e - b); });
  CHECK(sum == 100);
}

namespace {
/// Runs a 2-thread job of 64 one-item blocks (shares: blocks 0–31 the caller's, 32–63 the
/// worker's) whose first block on the held thread (caller or worker) waits until another thread
/// has run a block of the held thread's share (at most 20 s). Returns the blocks of that share
/// the other thread ran; `once` is false when a block ran twice or not at all; `ownInOrder` is
/// false when the other thread ran blocks of its own share out of ascending order.
std::vector<std::size_t> blocksTakenFromHeldShare(bool holdCaller, bool& once, bool& ownInOrder) {
  ThreadPool pool(2);
  const std::size_t n = 64, half = n / 2;
  const std::thread::id caller = std::this_thread::get_id();
  std::unique_ptr<std::atomic<int>[]> calls(new std::atomic<int>[n]);
  std::unique_ptr<std::atomic<bool>[]> byOther(new std::atomic<bool>[n]);
  for (std::size_t k = 0; k < n; ++k) calls[k] = 0, byOther[k] = false;
  std::unique_ptr<std::atomic<int>[]> stamp(new std::atomic<int>[n]);  // the order blocks started in
  std::atomic<int> seq{0};
  std::atomic<int> takenByOther{0};
  std::atomic<bool> held{false};
  const std::size_t first = holdCaller ? 0 : half;  // the held thread's share
  pool.parallelFor(n, 1, [&](std::size_t b, std::size_t) {
    const bool onCaller = std::this_thread::get_id() == caller;
    ++calls[b];
    stamp[b] = seq++;
    byOther[b] = onCaller != holdCaller;  // run by the thread that is not held
    if (byOther[b] && b >= first && b < first + half) ++takenByOther;
    if (onCaller == holdCaller && !held.exchange(true)) {
      const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
      while (takenByOther == 0 && std::chrono::steady_clock::now() < until) std::this_thread::yield();
    }
  });
  once = true;
  for (std::size_t k = 0; k < n; ++k) once = once && calls[k] == 1;
  // The other thread's own share: the blocks it ran there, in the order they started.
  const std::size_t otherFirst = holdCaller ? half : 0;
  ownInOrder = true;
  int last = -1;
  for (std::size_t k = otherFirst; k < otherFirst + half; ++k) {
    if (!byOther[k]) continue;
    ownInOrder = ownInOrder && stamp[k] > last;
    last = stamp[k];
  }
  std::vector<std::size_t> taken;
  for (std::size_t k = first; k < first + half; ++k)
    if (byOther[k]) taken.push_back(k);
  return taken;
}
}  // namespace

TEST_CASE(
    "work stealing: the blocks of a thread held up in one block are run by the other thread, each once, from its share's back") {
  // Each thread starts on its own share; when it is used up it takes the others' blocks from
  // their back. A thread stuck in one block must not hold up the rest of its share, and what
  // the other takes is the share's end (the held thread keeps the front it will reach first).
  for (bool holdCaller : {true, false}) {
    CAPTURE(holdCaller);
    bool once = false, ownInOrder = false;
    const std::vector<std::size_t> taken = blocksTakenFromHeldShare(holdCaller, once, ownInOrder);
    CHECK(once);
    CHECK(ownInOrder);  // its own share front to back (the same particles as in the last stage)
    REQUIRE(!taken.empty());
    const std::size_t shareEnd = holdCaller ? 32 : 64;
    bool suffix = true;  // the taken blocks are the share's last ones, without a gap
    for (std::size_t k = 0; k < taken.size(); ++k) suffix = suffix && taken[k] == shareEnd - taken.size() + k;
    CHECK(suffix);
  }
}

TEST_CASE(
    "many short jobs in a row, up to more threads than cores: each block of each job runs once (late workers claim nothing stale)") {
  // Oversubscribed pools get their workers descheduled mid-claim: a worker that wakes after its
  // job ended must not run a block of it again, nor a block of the next job twice.
  const int over = int(std::thread::hardware_concurrency()) + 1;  // more threads than this machine has cores
  for (int threads : {2, 3, 5, over}) {
    CAPTURE(threads);
    ThreadPool pool(threads);
    std::vector<std::atomic<int>> hits(800);
    int bad = 0;
    for (int job = 0; job < 30000; ++job) {
      // Every third job has 2–5 blocks: fewer than the threads of the larger pools (empty
      // shares, shares of one block: thieves meet on the last block of a share that starts at 0).
      const std::size_t n = job % 3 ? 1 + std::size_t(job * 7919) % 700 : 2 + std::size_t(job) % 4;
      const std::size_t block = job % 3 ? 1 + std::size_t(job) % 37 : 1;
      for (std::size_t i = 0; i < n; ++i) hits[i].store(0, std::memory_order_relaxed);
      pool.parallelFor(n, block, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) hits[i].fetch_add(1, std::memory_order_relaxed);
      });
      for (std::size_t i = 0; i < n; ++i) bad += hits[i].load(std::memory_order_relaxed) != 1;
    }
    CHECK(bad == 0);
  }
}

TEST_CASE("a cancel flag set during a job skips the blocks not started and throws Interrupted, for 1 to 3 threads") {
  for (int threads = 1; threads <= 3; ++threads) {
    CAPTURE(threads);
    ThreadPool pool(threads);
    std::atomic<bool> cancel{false};
    pool.setCancel(&cancel);
    // Unset: every block runs, nothing is thrown.
    std::atomic<std::size_t> ran{0};
    pool.parallelFor(1000, 10, [&](std::size_t, std::size_t) { ++ran; });
    CHECK(ran.load() == 100);
    // Set by block 5: the blocks under way finish, the rest are skipped, and the caller is told.
    ran = 0;
    bool interrupted = false;
    try {
      pool.parallelFor(1000, 10, [&](std::size_t b, std::size_t) {
        ++ran;
        if (b == 50) cancel.store(true);
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      });
    } catch (const Interrupted& e) {
      interrupted = true;
      CHECK(e.stage.empty());  // the caller (the stage list) names the stage
    }
    CHECK(interrupted);
    CHECK(ran.load() >= 1);
    CHECK(ran.load() < 100);
    // Cleared: the pool runs whole jobs again; without a flag it never throws.
    cancel.store(false);
    ran = 0;
    pool.parallelFor(1000, 10, [&](std::size_t, std::size_t) { ++ran; });
    CHECK(ran.load() == 100);
    cancel.store(true);
    pool.setCancel(nullptr);
    ran = 0;
    pool.parallelFor(1000, 10, [&](std::size_t, std::size_t) { ++ran; });
    CHECK(ran.load() == 100);
  }
}
