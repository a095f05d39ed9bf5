#include "sph2d/render/frame_writer.hpp"

#include <cstdio>
#include <stdexcept>

#include "sph2d/render/png_io.hpp"

namespace sph2d {

FrameWriter::FrameWriter(std::string dir, int level, std::size_t capacity)
    : dir_(std::move(dir)), level_(level), capacity_(capacity ? capacity : 1), thread_([this] { loop(); }) {}

FrameWriter::~FrameWriter() {
  try {
    if (!finished_) finish();
  } catch (...) {
  }
}

std::string FrameWriter::pathOf(int index) const {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", index);
  return dir_ + "/" + name;
}

void FrameWriter::push(int index, int width, int height, std::vector<std::uint8_t> rgba) {
  std::unique_lock<std::mutex> lock(mutex_);
  cv_.wait(lock, [&] { return queue_.size() < capacity_ || !error_.empty(); });
  if (!error_.empty()) throw std::runtime_error(error_);
  queue_.push_back(Job{index, width, height, std::move(rgba)});
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
      writePngAtomic(pathOf(job.index), job.width, job.height, job.rgba.data(), level_);
      std::lock_guard<std::mutex> lock(mutex_);
      ++written_;
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (error_.empty()) error_ = e.what();
      cv_.notify_all();
    }
  }
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
  }
  if (!error_.empty()) throw std::runtime_error(error_);
  return written_;
}

int FrameWriter::written() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return written_;
}

}  // namespace sph2d
