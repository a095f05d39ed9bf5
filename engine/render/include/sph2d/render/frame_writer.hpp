// sph2d/render/frame_writer.hpp — frame outputs on a background thread.
//
// Design: the frame loop pushes each kept frame (its pixels and, for exports, a
// particle snapshot); one writer thread does the slow parts in frame order:
// PNG encoding (libpng, level 1 by default), the raw frame into an ffmpeg pipe,
// the particle export (CSV or VTK). Every file is encoded in memory, announced
// (beforeWrite: its name, the hash of its bytes, its temporary name), written to
// the temporary name and renamed, so it exists whole or not at all. The queue is bounded (push()
// blocks when `capacity` frames wait) and finish() writes everything queued,
// so a run stopped by Ctrl-C keeps every frame it rendered. The first error
// stops further writes and is rethrown by the next push() or by finish().
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "sph2d/render/particle_export.hpp"

namespace sph2d {

class VideoPipe;

/// What a FrameWriter writes.
struct FrameWriterOptions {
  std::string dir;                           ///< output directory (must exist)
  bool png = true;                           ///< write frame_NNNNN.png
  int pngLevel = 1;                          ///< zlib level 0..9 (1 = fast)
  std::optional<ExportFormat> exportFormat;  ///< also write frame_NNNNN.csv / .vtk
  std::string videoPath;                     ///< "" = no video; else pipe frames to ffmpeg
  double videoFps = 60;                      ///< frame rate of the video
  std::size_t capacity = 6;                  ///< frames that may wait in the queue
  /// Called on the writer thread before each file is written (before its temporary file is
  /// created): the file's name in `dir`, the XXH64 of the bytes it will hold and the name of
  /// the temporary file it is written through. A throw stops the writer as a write error does.
  std::function<void(const std::string& name, std::uint64_t xxh64, const std::string& temp)> beforeWrite;
};

/// Counts of what a FrameWriter wrote.
struct FrameWriterCounts {
  int pngs = 0;         ///< PNG files
  int exports = 0;      ///< particle files
  int videoFrames = 0;  ///< frames sent to ffmpeg
};

/// Writes frames to `dir/frame_NNNNN.png` (and exports, video) on its own thread, in order.
class FrameWriter {
 public:
  /// Starts the writer thread; `dir` must exist.
  FrameWriter(std::string dir, int level = 1, std::size_t capacity = 6);
  /// Starts the writer thread with all options; starts ffmpeg when a video is asked for
  /// (throws std::runtime_error when it cannot).
  explicit FrameWriter(const FrameWriterOptions& options);
  /// Finishes (writes what is queued) if finish() was not called.
  ~FrameWriter();
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;
  /// Queues frame `index` (RGBA8, rows top-down) and its particles (needed with an export).
  /// Throws if an earlier write failed.
  void push(int index, int width, int height, std::vector<std::uint8_t> rgba,
            std::shared_ptr<const ParticleSnapshot> particles = nullptr);
  /// Writes what is queued, closes the video and joins. Returns the number of PNG files written; throws on error.
  int finish();
  /// PNG files written so far.
  int written() const;
  /// Everything written so far.
  FrameWriterCounts counts() const;
  /// Path of frame `index`'s PNG.
  std::string pathOf(int index) const;
  /// Path of frame `index`'s particle export.
  std::string exportPathOf(int index) const;

 private:
  struct Job {
    int index;
    int width, height;
    std::vector<std::uint8_t> rgba;
    std::shared_ptr<const ParticleSnapshot> particles;
  };
  void loop();
  void start();
  /// Calls beforeWrite for the file `path` that will hold `size` bytes at `data`.
  void announce(const std::string& path, const void* data, std::size_t size) const;
  FrameWriterOptions opt_;
  std::unique_ptr<VideoPipe> video_;
  std::deque<Job> queue_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  bool done_ = false;
  bool finished_ = false;
  FrameWriterCounts counts_;
  std::string error_;
  std::thread thread_;
};

}  // namespace sph2d
