#include "apps/image_prefetcher.h"

#include <chrono>
#include <stdexcept>
#include <utility>

namespace auvdock::cli {

ImagePrefetcher::ImagePrefetcher(size_t count, Decoder decode, size_t depth)
    : count_(count),
      depth_(depth < 1 ? 1 : depth),
      decode_(std::move(decode)),
      worker_([this] { Work(); }) {}

ImagePrefetcher::~ImagePrefetcher() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  worker_.join();
}

void ImagePrefetcher::Work() {
  for (size_t index = 0; index < count_; ++index) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [&] { return stop_ || ready_.size() < depth_; });
      if (stop_) return;
    }
    DecodedFrame frame;
    try {
      frame = decode_(index);
    } catch (...) {
      frame = DecodedFrame();
      frame.error = std::current_exception();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ready_.push_back(std::move(frame));
    }
    changed_.notify_all();
  }
}

DecodedFrame ImagePrefetcher::Take() {
  const auto start = std::chrono::steady_clock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  if (taken_ == count_) throw std::logic_error("ImagePrefetcher: every frame was taken");
  changed_.wait(lock, [&] { return !ready_.empty(); });
  DecodedFrame frame = std::move(ready_.front());
  ready_.pop_front();
  ++taken_;
  lock.unlock();
  changed_.notify_all();
  wait_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (frame.error) std::rethrow_exception(frame.error);
  return frame;
}

}  // namespace auvdock::cli
