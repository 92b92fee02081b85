// FootageSource: the files of a glob in name order, timed by the camera's rate; a video's frames
// in order, named frame_NNNNNN and timed by the file's rate; a frame read again (forward and
// backward) is the frame read the first time; a missing, empty or unreadable input names itself.
#include "apps/footage_source.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "auvdock/io/input_error.h"
#include "tests/testing/temp_dir.h"

namespace auvdock::cli {
namespace {

// Frame k: a grey level of 20 + 40 k with a bright square whose position also says k.
cv::Mat NumberedImage(int k) {
  cv::Mat image(96, 128, CV_8UC3, cv::Scalar::all(20 + 40 * k));
  image(cv::Rect(8 + 16 * k, 40, 16, 16)).setTo(cv::Scalar(255, 255, 255));
  return image;
}

// Which NumberedImage an (encoded and decoded) image is: the nearest mean grey level.
int WhichNumber(const cv::Mat& image) {
  const cv::Mat background = image(cv::Rect(0, 0, 128, 32));
  return static_cast<int>(std::lround((cv::mean(background)[0] - 20.0) / 40.0));
}

// A Motion-JPEG AVI written by OpenCV's own encoder (no FFmpeg needed to write it).
std::string WriteVideo(const test::TempDir& dir, int frames, double fps) {
  const std::string path = dir / "clip.avi";
  cv::VideoWriter writer(path, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                         fps, cv::Size(128, 96));
  EXPECT_TRUE(writer.isOpened());
  writer.set(cv::VIDEOWRITER_PROP_QUALITY, 100);
  for (int k = 0; k < frames; ++k) writer.write(NumberedImage(k));
  writer.release();
  return path;
}

TEST(FootageSource, ImagesComeInNameOrderTimedByTheCamerasRate) {
  test::TempDir dir;
  for (int k : {2, 0, 1}) {
    cv::imwrite(dir / ("img_" + std::to_string(k) + ".png"), NumberedImage(k));
  }
  FootageSource source = FootageSource::Images(dir / "*.png", 20.0);
  EXPECT_FALSE(source.is_video());
  EXPECT_EQ(source.announced_frames(), 3);
  EXPECT_DOUBLE_EQ(source.frame_interval_s(), 0.05);
  FootageFrame frame;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(source.Next(&frame));
    EXPECT_EQ(frame.index, k);
    EXPECT_EQ(frame.name, "img_" + std::to_string(k) + ".png");
    EXPECT_EQ(frame.origin, dir / frame.name);
    EXPECT_DOUBLE_EQ(frame.time_s, 0.05 * k);
    EXPECT_EQ(WhichNumber(frame.image), k);
  }
  EXPECT_FALSE(source.Next(&frame));
  EXPECT_FALSE(source.ended_early());
  EXPECT_EQ(WhichNumber(source.Reread(1)), 1);
  EXPECT_TRUE(source.Reread(3).empty());
}

TEST(FootageSource, AVideosFramesAreNamedAndTimedByTheFile) {
  test::TempDir dir;
  const std::string path = WriteVideo(dir, 6, 25.0);
  FootageSource source = FootageSource::Video(path, 10.0);
  EXPECT_TRUE(source.is_video());
  EXPECT_NEAR(source.frame_interval_s(), 0.04, 1e-9);
  EXPECT_EQ(source.announced_frames(), 6);
  FootageFrame frame;
  for (int k = 0; k < 6; ++k) {
    ASSERT_TRUE(source.Next(&frame)) << k;
    EXPECT_EQ(frame.index, k);
    EXPECT_EQ(frame.name, "frame_00000" + std::to_string(k));
    EXPECT_EQ(frame.origin, path + "#" + std::to_string(k));
    EXPECT_NEAR(frame.time_s, 0.04 * k, 1e-6);
    EXPECT_EQ(frame.image.type(), CV_8UC3);
    EXPECT_EQ(frame.image.size(), cv::Size(128, 96));
    EXPECT_EQ(WhichNumber(frame.image), k);
  }
  EXPECT_FALSE(source.Next(&frame));
  EXPECT_FALSE(source.ended_early());
  // Again, forward from the start, then backward (from the start once more), then past the end.
  EXPECT_EQ(WhichNumber(source.Reread(2)), 2);
  EXPECT_EQ(WhichNumber(source.Reread(5)), 5);
  EXPECT_EQ(WhichNumber(source.Reread(0)), 0);
  EXPECT_EQ(WhichNumber(source.Reread(4)), 4);
  EXPECT_TRUE(source.Reread(6).empty());
}

TEST(FootageSource, BadFootageNamesItself) {
  test::TempDir dir;
  try {
    FootageSource::Images(dir / "none/*.png", 10.0);
    FAIL() << "no file matches";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--images: no file matches"), std::string::npos);
  }
  try {
    FootageSource::Video(dir / "absent.mp4", 10.0);
    FAIL() << "no such file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--video: no such file: " + dir / "absent.mp4"),
              std::string::npos);
  }
  test::WriteTextFile(dir / "notes.mp4", "this is not a video\n");
  try {
    FootageSource source = FootageSource::Video(dir / "notes.mp4", 10.0);
    FootageFrame frame;
    source.Next(&frame);
    FAIL() << "not a video";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--video: " + dir / "notes.mp4"), std::string::npos)
        << e.what();
  }
  test::WriteTextFile(dir / "broken/a.png", "not a png");
  FootageSource broken = FootageSource::Images(dir / "broken/*.png", 10.0);
  FootageFrame frame;
  try {
    broken.Next(&frame);
    FAIL() << "not an image";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), dir / "broken/a.png" + ": cannot decode the image");
  }
}

}  // namespace
}  // namespace auvdock::cli
