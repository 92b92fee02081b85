// Decoding ahead: the images of the frames to come are decoded on one background thread while
// the current frame goes through the front-end and the estimator, at most `depth` frames ahead
// (a bounded queue: memory stays at depth frames of images). The consumer takes the frames in
// order, 0, 1, 2, ...; what it gets is what decoding that frame on its own thread would give
// (decoding has no state), so a run's results do not change, only its wall time.
//
// The decoder may not touch the consumer's state: it returns the images, the problems it found
// (for the consumer to report and count, in frame order) and the seconds it worked. An exception
// in the decoder is carried to the consumer and rethrown by Take() of that frame.
#pragma once

#include <array>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

namespace auvdock::cli {

struct DecodedFrame {
  std::array<cv::Mat, 3> images;      // stereo left, stereo right, mono (empty: none or unreadable)
  std::vector<std::string> problems;  // one per unreadable image: "PATH: why"
  double decode_s = 0.0;              // the decoder's own time
  std::exception_ptr error;
};

class ImagePrefetcher {
 public:
  using Decoder = std::function<DecodedFrame(size_t index)>;

  // Starts decoding frames 0 .. count - 1. depth >= 1.
  ImagePrefetcher(size_t count, Decoder decode, size_t depth = 3);
  ~ImagePrefetcher();  // stops the decoder and waits for it
  ImagePrefetcher(const ImagePrefetcher&) = delete;
  ImagePrefetcher& operator=(const ImagePrefetcher&) = delete;

  // The next frame's images, waiting for them if needed; rethrows the decoder's exception.
  // Frames are taken in order; after the last, throws std::logic_error.
  DecodedFrame Take();
  // Seconds Take() spent waiting for the decoder (the part of decoding the run still waits for).
  double wait_s() const { return wait_s_; }

 private:
  void Work();

  const size_t count_;
  const size_t depth_;
  Decoder decode_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<DecodedFrame> ready_;
  size_t taken_ = 0;
  bool stop_ = false;
  double wait_s_ = 0.0;
  std::thread worker_;  // last: starts after everything it uses
};

}  // namespace auvdock::cli
