// ImagePrefetcher: frames come out in order, whatever the decoder's pace; it never runs more
// than `depth` frames ahead of the consumer; a decoder's exception reaches the consumer at its
// frame; a prefetcher destroyed early stops its thread.
#include "apps/image_prefetcher.h"

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

namespace auvdock::cli {
namespace {

DecodedFrame Numbered(size_t index) {
  DecodedFrame frame;
  frame.images[0] = cv::Mat(1, 1, CV_32S, cv::Scalar(static_cast<int>(index)));
  if (index % 3 == 1) frame.problems.push_back("frame " + std::to_string(index));
  return frame;
}

TEST(ImagePrefetcher, FramesComeInOrderWithTheirProblems) {
  ImagePrefetcher prefetcher(50, [](size_t i) {
    if (i % 7 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    return Numbered(i);
  });
  for (size_t i = 0; i < 50; ++i) {
    if (i % 5 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    const DecodedFrame frame = prefetcher.Take();
    EXPECT_EQ(frame.images[0].at<int>(0, 0), static_cast<int>(i));
    EXPECT_EQ(frame.problems.size(), i % 3 == 1 ? 1u : 0u);
  }
  EXPECT_THROW(prefetcher.Take(), std::logic_error);
}

TEST(ImagePrefetcher, NeverMoreThanDepthAhead) {
  std::atomic<size_t> decoded{0};
  ImagePrefetcher prefetcher(
      20,
      [&](size_t i) {
        ++decoded;
        return Numbered(i);
      },
      3);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(decoded.load(), 3u);  // the queue is full: the decoder waits
  prefetcher.Take();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(decoded.load(), 4u);
}

TEST(ImagePrefetcher, ADecodersFailureReachesTheConsumerAtItsFrame) {
  ImagePrefetcher prefetcher(5, [](size_t i) {
    if (i == 2) throw std::runtime_error("bad frame 2");
    return Numbered(i);
  });
  prefetcher.Take();
  prefetcher.Take();
  EXPECT_THROW(prefetcher.Take(), std::runtime_error);
  EXPECT_EQ(prefetcher.Take().images[0].at<int>(0, 0), 3);
}

TEST(ImagePrefetcher, DestroyedEarlyItStopsItsThread) {
  std::atomic<size_t> decoded{0};
  {
    ImagePrefetcher prefetcher(1000, [&](size_t i) {
      ++decoded;
      return Numbered(i);
    });
    prefetcher.Take();
  }  // joins: the decoder stops at the queue's bound
  EXPECT_LE(decoded.load(), 5u);
}

}  // namespace
}  // namespace auvdock::cli
