// The images that `auvdock detect` looks at, one after the other: either the files that a glob
// pattern matches (sorted by name) or the frames of a video file (OpenCV's video I/O: its FFmpeg
// reader, whatever codec that reads, else its own Motion JPEG reader).
//
// Each frame carries
//   index   0, 1, 2, ... in the order read;
//   name    what the output files and the hand labels call it: the file's name for an image,
//           frame_NNNNNN (the 0-based index, six digits or more) for a video's frame;
//   origin  where it came from, for messages: the image's path, or "VIDEO#index";
//   time_s  the image's index / the camera's rate; a video frame's presentation time (its
//           time stamp in the file, from the first frame's), or index / the file's frame rate
//           when the file gives no time stamps.
// An image that cannot be decoded is an InputError naming it. A video that cannot be opened, or
// that holds no frame OpenCV can decode, is an InputError naming the file; a video that ends
// before the number of frames its header announces ends there (ended_early() says so, for a
// warning). Reread(index) gives a frame again for the overlays drawn at the end of a run: an
// image is read from its file, a video on from the frame last read (or from its start, when that
// frame was passed), so rereading in rising order reads the video once more.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

namespace auvdock::cli {

struct FootageFrame {
  int index = 0;
  std::string name, origin;
  double time_s = 0.0;
  cv::Mat image;  // as decoded: 8-bit, 1 or 3 channels (a 4-channel image is made BGR)
};

class FootageSource {
 public:
  // The files matching pattern ("DIR/*.jpg"), time = index / rate_hz.
  static FootageSource Images(const std::string& pattern, double rate_hz);
  // The frames of a video file; fallback_rate_hz times its frames when the file has no rate.
  static FootageSource Video(const std::string& path, double fallback_rate_hz);

  // The number of images, or the frames a video's header announces (0 when it does not say).
  int announced_frames() const { return announced_; }
  // The nominal time between frames (1 / rate), seconds.
  double frame_interval_s() const { return interval_s_; }
  bool is_video() const { return video_ != nullptr; }
  // A video that ended before the frames its header announced (after Next returned false).
  bool ended_early() const;

  // The next frame; false at the end.
  bool Next(FootageFrame* frame);
  // Frame index again (an empty image if it can no longer be read).
  cv::Mat Reread(int index);

 private:
  FootageSource() = default;
  static std::string VideoFrameName(int index);
  void OpenVideo();
  bool ReadVideoFrame(cv::Mat* image, double* time_ms);

  std::vector<std::string> files_;
  std::string video_path_;
  std::unique_ptr<cv::VideoCapture> video_;
  int announced_ = 0;
  double interval_s_ = 0.0;
  int next_ = 0;                // index of the next frame Next returns
  int video_position_ = 0;      // index of the frame the capture reads next
  double first_time_ms_ = 0.0;  // the first frame's time stamp in the file
  double last_time_s_ = 0.0;    // the time of the frame Next returned last
  bool ended_ = false;
};

}  // namespace auvdock::cli
