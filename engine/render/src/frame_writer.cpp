#include "sph2d/render/frame_writer.hpp"

#include <cstdio>
#include <stdexcept>

#include "sph2d/hash.hpp"
#include "sph2d/render/png_io.hpp"
#include "sph2d/render/video.hpp"

namespace sph2d {

FrameWriter::FrameWriter(std::string dir, int level, std::size_t capacity) {
  opt_.dir = std::move(dir);
  opt_.pngLevel = level;
  opt_.capacity = capacity;
  start();
}

FrameWriter::FrameWriter(const FrameWriterOptions& options) : opt_(options) { start(); }

void FrameWriter::start() {
  if (opt_.capacity == 0) opt_.capacity = 1;
  thread_ = std::thread([this] { loop(); });
}

FrameWriter::~FrameWriter() {
  try {
    if (!finished_) finish();
  } catch (...) {
  }
}

std::string FrameWriter::pathOf(int index) const {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", index);
  return opt_.dir + "/" + name;
}

std::string FrameWriter::exportPathOf(int index) const {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.", index);
  return opt_.dir + "/" + name + exportExtension(opt_.exportFormat.value_or(ExportFormat::Csv));
}

void FrameWriter::push(int index, int width, int height, std::vector<std::uint8_t> rgba,
                       std::shared_ptr<const ParticleSnapshot> particles) {
  std::unique_lock<std::mutex> lock(mutex_);
  cv_.wait(lock, [&] { return queue_.size() < opt_.capacity || !error_.empty(); });
  if (!error_.empty()) throw std::runtime_error(error_);
  if (opt_.exportFormat && !particles) throw std::logic_error("FrameWriter::push: an export needs the particles");
  queue_.push_back(Job{index, width, height, std::move(rgba), std::move(particles)});
  cv_.notify_all();
}

void FrameWriter::loop() {
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait(lock, [&] { return !queue_.empty() || done_; });
      if (queue_.empty()) return;
      job = std::move(queue_.front());
      queue_.pop_front();
      cv_.notify_all();
      if (!error_.empty()) continue;  // after an error, drop the rest
    }
    try {
      if (opt_.png) {
        const std::string path = pathOf(job.index);
        thread_local std::vector<std::uint8_t> bytes;
        try {
          encodePng(job.width, job.height, job.rgba.data(), pngSettings(opt_.pngLevel), bytes);
        } catch (const std::exception& e) {
          throw std::runtime_error("cannot write " + path + ": " + e.what());
        }
        announce(path, bytes.data(), bytes.size());
        writeEncodedPngAtomic(path, bytes);
        std::lock_guard<std::mutex> lock(mutex_);
        ++counts_.pngs;
      }
      if (opt_.exportFormat) {
        const std::string path = exportPathOf(job.index);
        std::string text = encodeParticles(*job.particles, *opt_.exportFormat);
        announce(path, text.data(), text.size());
        writeFileAtomic(path, text);
        if (*opt_.exportFormat == ExportFormat::Csv && !job.particles->bodies.empty()) {
          char name[32];
          std::snprintf(name, sizeof name, "/bodies_%05d.csv", job.index);
          text = encodeBodiesCsv(*job.particles);
          announce(opt_.dir + name, text.data(), text.size());
          writeFileAtomic(opt_.dir + name, text);
        }
        if (*opt_.exportFormat == ExportFormat::Surface) {  // the drawing beside the JSON
          char name[32];
          std::snprintf(name, sizeof name, "/frame_%05d.svg", job.index);
          text = encodeSurfaceSvg(*job.particles);
          announce(opt_.dir + name, text.data(), text.size());
          writeFileAtomic(opt_.dir + name, text);
        }
        std::lock_guard<std::mutex> lock(mutex_);
        ++counts_.exports;
      }
      if (!opt_.videoPath.empty()) {
        if (!video_) video_ = std::make_unique<VideoPipe>(opt_.videoPath, job.width, job.height, opt_.videoFps);
        video_->write(job.rgba.data());
        std::lock_guard<std::mutex> lock(mutex_);
        ++counts_.videoFrames;
      }
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (error_.empty()) error_ = e.what();
      cv_.notify_all();
    }
  }
}

void FrameWriter::announce(const std::string& path, const void* data, std::size_t size) const {
  if (!opt_.beforeWrite) return;
  const auto name = [](const std::string& p) { return p.substr(p.find_last_of('/') + 1); };
  opt_.beforeWrite(name(path), xxh64(data, size), name(tempPathFor(path)));
}

int FrameWriter::finish() {
  if (!finished_) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    cv_.notify_all();
    thread_.join();
    finished_ = true;
    if (video_) {
      try {
        video_->close();
      } catch (const std::exception& e) {
        if (error_.empty()) error_ = e.what();
      }
    }
  }
  if (!error_.empty()) throw std::runtime_error(error_);
  return counts_.pngs;
}

int FrameWriter::written() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counts_.pngs;
}

FrameWriterCounts FrameWriter::counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counts_;
}

}  // namespace sph2d
