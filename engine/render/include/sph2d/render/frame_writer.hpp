// sph2d/render/frame_writer.hpp — PNG encoding on a background thread.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace sph2d {

/// Encodes frames to `dir/frame_NNNNN.png` on its own thread, in order.
/// push() blocks when `capacity` frames wait; an encoding error is rethrown by
/// the next push() or by finish(), and frames already written stay whole.
class FrameWriter {
 public:
  /// Starts the writer thread; `dir` must exist.
  FrameWriter(std::string dir, int level = 1, std::size_t capacity = 6);
  /// Finishes (writes what is queued) if finish() was not called.
  ~FrameWriter();
  /// Queues frame `index` (RGBA8, rows top-down). Throws if an earlier write failed.
  void push(int index, int width, int height, std::vector<std::uint8_t> rgba);
  /// Writes what is queued and joins. Returns the number of files written; throws on error.
  int finish();
  /// Files written so far.
  int written() const;
  /// Path of frame `index`.
  std::string pathOf(int index) const;

 private:
  struct Job {
    int index;
    int width, height;
    std::vector<std::uint8_t> rgba;
  };
  void loop();
  std::string dir_;
  int level_;
  std::size_t capacity_;
  std::deque<Job> queue_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  bool done_ = false;
  bool finished_ = false;
  int written_ = 0;
  std::string error_;
  std::thread thread_;
};

}  // namespace sph2d
