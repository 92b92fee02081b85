#include "apps/footage_source.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "auvdock/io/input_error.h"

namespace fs = std::filesystem;

namespace auvdock::cli {
namespace {

// The image as 8-bit, 1 or 3 channels (4 made BGR); origin names it in the error.
cv::Mat Normalised(cv::Mat image, const std::string& origin) {
  if (image.depth() != CV_8U) throw InputError(origin + ": not an 8-bit image");
  if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);
  if (image.channels() != 1 && image.channels() != 3) {
    throw InputError(origin + ": an image of " + std::to_string(image.channels()) +
                     " channels (1 or 3 expected)");
  }
  return image;
}

}  // namespace

FootageSource FootageSource::Images(const std::string& pattern, double rate_hz) {
  FootageSource source;
  std::vector<cv::String> files;
  try {
    cv::glob(pattern, files, false);
  } catch (const cv::Exception&) {
    files.clear();
  }
  if (files.empty()) throw InputError("--images: no file matches '" + pattern + "'");
  std::sort(files.begin(), files.end());
  source.files_.assign(files.begin(), files.end());
  source.announced_ = static_cast<int>(files.size());
  source.interval_s_ = 1.0 / rate_hz;
  return source;
}

FootageSource FootageSource::Video(const std::string& path, double fallback_rate_hz) {
  if (!fs::is_regular_file(path)) throw InputError("--video: no such file: " + path);
  FootageSource source;
  source.video_path_ = path;
  source.OpenVideo();
  const double fps = source.video_->get(cv::CAP_PROP_FPS);
  source.interval_s_ = std::isfinite(fps) && fps > 0.0 ? 1.0 / fps : 1.0 / fallback_rate_hz;
  const double count = source.video_->get(cv::CAP_PROP_FRAME_COUNT);
  source.announced_ = std::isfinite(count) && count > 0.0 ? static_cast<int>(count) : 0;
  return source;
}

void FootageSource::OpenVideo() {
  // FFmpeg's and OpenCV's own complaints about a file they cannot read (several lines each) would
  // bury the one line of the error below: quiet, unless the user asked for them.
  setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", /*overwrite=*/0);
  const cv::utils::logging::LogLevel level =
      cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  // Only OpenCV's file readers, FFmpeg first: CAP_ANY would also probe camera backends (DC1394
  // enumerates the USB devices and leaks what it allocates for them).
  video_ = std::make_unique<cv::VideoCapture>();
  for (const int reader : {cv::CAP_FFMPEG, cv::CAP_OPENCV_MJPEG}) {
    try {
      if (video_->open(video_path_, reader)) break;
    } catch (const cv::Exception&) {
      video_->release();
    }
  }
  cv::utils::logging::setLogLevel(level);
  if (!video_->isOpened()) {
    throw InputError("--video: " + video_path_ +
                     ": OpenCV's video readers (FFmpeg, Motion JPEG) cannot open it");
  }
  video_position_ = 0;
}

bool FootageSource::ReadVideoFrame(cv::Mat* image, double* time_ms) {
  bool read = false;
  try {
    read = video_->read(*image);
  } catch (const cv::Exception&) {
    read = false;
  }
  if (!read || image->empty()) return false;
  *time_ms = video_->get(cv::CAP_PROP_POS_MSEC);
  ++video_position_;
  return true;
}

std::string FootageSource::VideoFrameName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%06d", index);
  return name;
}

bool FootageSource::ended_early() const {
  return is_video() && ended_ && announced_ > 0 && next_ < announced_;
}

bool FootageSource::Next(FootageFrame* frame) {
  if (ended_) return false;
  frame->index = next_;
  if (!is_video()) {
    if (next_ >= static_cast<int>(files_.size())) {
      ended_ = true;
      return false;
    }
    const std::string& path = files_[next_];
    cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
    if (image.empty()) throw InputError(path + ": cannot decode the image");
    frame->image = Normalised(image, path);
    frame->name = fs::path(path).filename().string();
    frame->origin = path;
    frame->time_s = next_ * interval_s_;
    ++next_;
    return true;
  }
  cv::Mat image;
  double time_ms = 0.0;
  if (!ReadVideoFrame(&image, &time_ms)) {
    ended_ = true;
    if (next_ == 0) {
      throw InputError("--video: " + video_path_ + ": no frame that OpenCV can decode");
    }
    return false;
  }
  frame->origin = video_path_ + "#" + std::to_string(next_);
  frame->image = Normalised(image, frame->origin);
  frame->name = VideoFrameName(next_);
  // The file's time stamps while they rise; else the last time plus the nominal interval.
  if (next_ == 0) {
    first_time_ms_ = std::isfinite(time_ms) ? time_ms : 0.0;
    last_time_s_ = 0.0;
  } else {
    const double stamped = (time_ms - first_time_ms_) / 1000.0;
    last_time_s_ =
        std::isfinite(stamped) && stamped > last_time_s_ ? stamped : last_time_s_ + interval_s_;
  }
  frame->time_s = last_time_s_;
  ++next_;
  return true;
}

cv::Mat FootageSource::Reread(int index) {
  if (index < 0) return {};
  if (!is_video()) {
    if (index >= static_cast<int>(files_.size())) return {};
    const cv::Mat image = cv::imread(files_[index], cv::IMREAD_UNCHANGED);
    if (image.empty()) return {};
    return Normalised(image, files_[index]);
  }
  // A frame already passed: from the start again.
  if (index < video_position_) OpenVideo();
  cv::Mat image;
  double time_ms = 0.0;
  while (video_position_ <= index) {
    if (!ReadVideoFrame(&image, &time_ms)) return {};
  }
  return Normalised(image, video_path_ + "#" + std::to_string(index));
}

}  // namespace auvdock::cli
