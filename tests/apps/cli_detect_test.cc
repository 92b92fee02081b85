// auvdock detect end to end on images drawn here (a flat ring of 8 blue LEDs, 4-fold symmetric,
// seen from 2.5-3.5 m): every file written, every frame posed with its symmetry stated, the
// identities consistent from frame to frame, the detector measured against labels; and the bad
// input that is one line and exit 2.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "auvdock/geometry/pose3.h"
#include "auvdock/geometry/so3.h"
#include "auvdock/io/dock_io.h"
#include "auvdock/io/pose_covariance_csv.h"
#include "auvdock/io/tum_io.h"
#include "tests/testing/led_image.h"
#include "tests/testing/run_command.h"
#include "tests/testing/temp_dir.h"

namespace auvdock {
namespace {

constexpr double kF = 500.0, kCx = 319.5, kCy = 239.5;

const char* kCalibration =
    "cameras:\n"
    "  - name: cam0\n"
    "    role: mono\n"
    "    resolution: [640, 480]\n"
    "    camera_model: pinhole\n"
    "    intrinsics: [500, 500, 319.5, 239.5]\n"
    "    distortion_model: radial-tangential\n"
    "    distortion_coefficients: [0, 0, 0, 0, 0]\n"
    "    rate_hz: 10\n"
    "    pixel_noise_px: 0.5\n"
    "    T_B_S: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n";

struct Footage {
  test::TempDir dir;
  std::vector<std::vector<std::pair<int, Eigen::Vector2d>>> truth;  // per frame: id, pixel
};

// Frames of the ring, the camera looking down from 3 m, drifting and turning slowly. With
// faded_light, that light is a dim blue blob from frame 1 on (below the full-image response), and
// a blue LED that is not the dock's shines beside the ring (a lamp on the deck, say). From frame
// partial_from on, only the dock file's first two lights are drawn (the rest out of the beam),
// and the lamp; with whitened_second, only the second, as a wide white glow (a light a few
// decimetres from the lens).
// whitened_second: from partial_from on only the second light, within decimetres of the lens (a
// wide saturated glow without colour); reflected: with a reflection merged into its plateau below
// it (an egg-shaped saturated region).
void MakeFootage(Footage* footage, int frames, int faded_light = -1, int partial_from = -1,
                 bool whitened_second = false, bool reflected = false) {
  DockModel dock = LoadDockModel(std::string(AUVDOCK_SOURCE_DIR) + "/data/docks/ring_8.yaml");
  dock.light_colour = "blue";
  SaveDockModel(dock, footage->dir / "dock.yaml");
  test::WriteTextFile(footage->dir / "calibration.yaml", kCalibration);
  std::ofstream labels(footage->dir / "labels.csv");
  labels << "frame_file,u,v,status,quality\n";
  for (int f = 0; f < frames; ++f) {
    const double a = 0.03 * f;
    const Pose3 T_C_D(ExpQuaternion(Eigen::Vector3d(0.05 * std::sin(a), -0.04, 0.2 + 0.02 * f)),
                      Eigen::Vector3d(0.1 * std::cos(a), -0.05 + 0.01 * f, 3.0 - 0.02 * f));
    cv::Mat image(480, 640, CV_32FC3, cv::Scalar(30, 95, 90));
    std::vector<std::pair<int, Eigen::Vector2d>> seen;
    const bool partial = partial_from >= 0 && f >= partial_from;
    for (size_t index = 0; index < dock.lights.size(); ++index) {
      const DockLight& light = dock.lights[index];
      if (partial && whitened_second && index != 1) continue;  // the second light alone
      if (partial && seen.size() == 2) break;
      const Eigen::Vector3d p = T_C_D * light.p_D;
      const Eigen::Vector2d uv(kF * p.x() / p.z() + kCx, kF * p.y() / p.z() + kCy);
      seen.emplace_back(light.id, uv);
      if (light.id == faded_light && f > 0) {
        for (int v = 0; v < image.rows; ++v) {
          for (int u = 0; u < image.cols; ++u) {
            const double d2 = (u - uv.x()) * (u - uv.x()) + (v - uv.y()) * (v - uv.y());
            const float w = static_cast<float>(std::exp(-d2 / (2.0 * 2.5 * 2.5)));
            image.at<cv::Vec3f>(v, u) += cv::Vec3f(150.0f * w, 60.0f * w, 10.0f * w);
          }
        }
        continue;
      }
      if (partial && whitened_second) {
        // A light within decimetres of the lens: a wide saturated glow that shows no colour.
        for (int v = 0; v < image.rows; ++v) {
          for (int u = 0; u < image.cols; ++u) {
            const double d2 = (u - uv.x()) * (u - uv.x()) + (v - uv.y()) * (v - uv.y());
            const double dv = v - uv.y() - 40.0;
            const bool reflection =
                reflected && (u - uv.x()) * (u - uv.x()) + dv * dv <= 25.0 * 25.0;
            const float level = static_cast<float>((d2 <= 35.0 * 35.0 || reflection ? 400.0 : 0.0) +
                                                   300.0 * std::exp(-d2 / (2.0 * 35.0 * 35.0)));
            image.at<cv::Vec3f>(v, u) += cv::Vec3f(level, level, level);
          }
        }
        continue;
      }
      test::AddLed({uv, 3.0, 7.0}, &image);
    }
    if (faded_light >= 0 || partial) {
      test::AddLed({Eigen::Vector2d(560.0, 420.0), 3.0, 7.0}, &image);
    }
    cv::Mat bgr;
    image.convertTo(bgr, CV_8UC3);
    char name[32];
    std::snprintf(name, sizeof(name), "f%03d.png", f);
    cv::imwrite(footage->dir / ("frames/" + std::string(name)), bgr);
    for (const auto& [id, uv] : seen) labels << name << "," << uv.x() << "," << uv.y() << ",ok,good\n";
    footage->truth.push_back(seen);
  }
}

std::vector<std::string> DetectArgs(const Footage& footage, const std::string& out) {
  return {"detect", "--images", footage.dir / "frames/*.png", "--calib",
          footage.dir / "calibration.yaml", "--dock", footage.dir / "dock.yaml", "--out", out,
          "--labels", footage.dir / "labels.csv", "--overlay", "--quiet"};
}

// Every detection in out/detections.csv is a true light of the footage (within 1 px) with an id,
// and each true light keeps one id throughout (which one is defined up to the dock's symmetry);
// lights: how many true lights are seen.
void ExpectEveryDetectionIdentifiedConsistently(const Footage& footage, const std::string& out,
                                                size_t lights) {
  std::map<int, int> reported_of_true;
  std::ifstream detections(out + "/detections.csv");
  std::string line;
  std::getline(detections, line);
  while (std::getline(detections, line)) {
    std::stringstream s(line);
    std::string frame, image, id, u, v;
    std::getline(s, frame, ',');
    std::getline(s, image, ',');
    std::getline(s, id, ',');
    std::getline(s, u, ',');
    std::getline(s, v, ',');
    const Eigen::Vector2d uv(std::stod(u), std::stod(v));
    int truth = -1;
    for (const auto& [true_id, p] : footage.truth[std::stoi(frame)]) {
      if ((p - uv).norm() < 1.0) truth = true_id;
    }
    ASSERT_GE(truth, 0) << line;
    ASSERT_GE(std::stoi(id), 0) << line;
    const auto [it, inserted] = reported_of_true.emplace(truth, std::stoi(id));
    EXPECT_EQ(it->second, std::stoi(id)) << "light " << truth << " changed identity: " << line;
  }
  EXPECT_EQ(reported_of_true.size(), lights);
}

TEST(DetectCli, PosesEveryFrameOfASymmetricRingWithConsistentIdentities) {
  Footage footage;
  std::filesystem::create_directories(footage.dir / "frames");
  MakeFootage(&footage, 12);
  const std::string out = footage.dir / "out";
  const test::CommandResult r = test::RunAuvdock(DetectArgs(footage, out));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  for (const char* file : {"detections.csv", "frames.csv", "camera_poses.tum", "summary.json",
                           "rejected.csv", "overlay/f000.png", "camera_pose_covariance.csv"}) {
    EXPECT_TRUE(std::filesystem::exists(out + "/" + file)) << file;
  }
  const nlohmann::json summary = nlohmann::json::parse(test::ReadTextFile(out + "/summary.json"));
  EXPECT_EQ(summary["frames_with_pose"], 12);
  // A covariance for every pose, at its time (the reader checks symmetry and definiteness).
  const Trajectory poses = ReadTumTrajectory(out + "/camera_poses.tum");
  const std::vector<StampedPoseCovariance> covariances =
      ReadPoseCovarianceCsv(out + "/camera_pose_covariance.csv");
  ASSERT_EQ(poses.size(), 12u);
  ASSERT_EQ(covariances.size(), poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    EXPECT_NEAR(static_cast<double>(covariances[k].t_ns - poses[k].t_ns), 0.0, 1e3) << k;
  }
  EXPECT_EQ(summary["labels"]["recall"], 1.0);
  EXPECT_EQ(summary["labels"]["precision"], 1.0);
  EXPECT_LT(summary["labels"]["centroid_rms_px"].get<double>(), 0.3);
  EXPECT_EQ(summary["labels"]["pose_rate"], 1.0);

  // The identities: each true light keeps one reported id through the footage (which one is
  // defined up to the ring's symmetry: the first frame says so).
  std::ifstream frames(out + "/frames.csv");
  std::string line;
  std::getline(frames, line);
  std::getline(frames, line);
  EXPECT_NE(line.find("4-fold"), std::string::npos) << line;
  EXPECT_NE(line.find("unresolved"), std::string::npos) << line;
  ExpectEveryDetectionIdentifiedConsistently(footage, out, 8);
}

TEST(DetectCli, TheSecondLookFindsAFadedLightAndWhatThePoseDoesNotExplainIsRejected) {
  Footage footage;
  std::filesystem::create_directories(footage.dir / "frames");
  MakeFootage(&footage, 6, /*faded_light=*/2);
  const std::string with = footage.dir / "with";
  test::CommandResult r = test::RunAuvdock(DetectArgs(footage, with));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  nlohmann::json summary = nlohmann::json::parse(test::ReadTextFile(with + "/summary.json"));
  EXPECT_EQ(summary["frames_with_pose"], 6);
  EXPECT_EQ(summary["labels"]["recall"], 1.0);
  EXPECT_EQ(summary["second_look"]["guided_detections"], 5);
  // The lamp beside the ring, far from every light the pose puts in the image, is rejected.
  EXPECT_EQ(summary["labels"]["precision"], 1.0);
  EXPECT_EQ(summary["rejected_candidates"]["not a light of the dock at the pose"], 6);
  EXPECT_NE(test::ReadTextFile(with + "/rejected.csv").find("not a light of the dock"),
            std::string::npos);

  const std::string without = footage.dir / "without";
  std::vector<std::string> args = DetectArgs(footage, without);
  args.push_back("--no-second-look");
  r = test::RunAuvdock(args);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  summary = nlohmann::json::parse(test::ReadTextFile(without + "/summary.json"));
  EXPECT_NEAR(summary["labels"]["recall"].get<double>(), 1.0 - 5.0 / 48.0, 1e-9);
  EXPECT_EQ(summary["second_look"]["guided_detections"], 0);

  const std::string kept = footage.dir / "kept";
  args = DetectArgs(footage, kept);
  args.push_back("--keep-unexplained");
  r = test::RunAuvdock(args);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  summary = nlohmann::json::parse(test::ReadTextFile(kept + "/summary.json"));
  EXPECT_EQ(summary["labels"]["recall"], 1.0);
  EXPECT_LT(summary["labels"]["precision"].get<double>(), 1.0);
  EXPECT_FALSE(summary["rejected_candidates"].contains("not a light of the dock at the pose"));
}

// Two of the ring's LEDs and a lamp after 8 frames of the whole ring: too few for a pose, but
// the walk from the posed frames identifies the two (with the ids they had) and rejects the lamp;
// --bridge off leaves all three unidentified.
TEST(DetectCli, FramesWithTooFewLightsForAPoseAreIdentifiedFromTheFramesBefore) {
  Footage footage;
  std::filesystem::create_directories(footage.dir / "frames");
  MakeFootage(&footage, 12, /*faded_light=*/-1, /*partial_from=*/8);
  const std::string out = footage.dir / "out";
  test::CommandResult r = test::RunAuvdock(DetectArgs(footage, out));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  nlohmann::json summary = nlohmann::json::parse(test::ReadTextFile(out + "/summary.json"));
  EXPECT_EQ(summary["frames_with_pose"], 8);
  EXPECT_EQ(summary["bridged_frames"]["frames"], 4);
  EXPECT_EQ(summary["bridged_frames"]["identified"], 8);
  EXPECT_EQ(summary["bridged_frames"]["unexplained"], 4);
  EXPECT_EQ(summary["labels"]["recall"], 1.0);
  EXPECT_EQ(summary["labels"]["precision"], 1.0);
  EXPECT_NE(r.out.find("4 frames without a pose bridged"), std::string::npos) << r.out;
  // Each light keeps the id it had in the posed frames.
  ExpectEveryDetectionIdentifiedConsistently(footage, out, 8);
  // Every bridged frame says so, and the lamp is a rejected candidate with the reason.
  const std::string frames = test::ReadTextFile(out + "/frames.csv");
  const std::string note = "2 identified and 1 unexplained by the poses of the frames from 7 on";
  size_t said = 0;
  for (size_t at = frames.find(note); at != std::string::npos; at = frames.find(note, at + 1)) {
    ++said;
  }
  EXPECT_EQ(said, 4u) << frames;
  EXPECT_NE(test::ReadTextFile(out + "/rejected.csv")
                .find("not a light of the dock at the neighbouring frames' pose"),
            std::string::npos);

  const std::string off = footage.dir / "off";
  std::vector<std::string> args = DetectArgs(footage, off);
  args.insert(args.end(), {"--bridge", "off"});
  r = test::RunAuvdock(args);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  summary = nlohmann::json::parse(test::ReadTextFile(off + "/summary.json"));
  EXPECT_EQ(summary["bridged_frames"]["frames"], 0);
  EXPECT_NEAR(summary["labels"]["precision"].get<double>(), 1.0 - 4.0 / (8 * 8 + 4 * 3), 1e-9);
}

// The same, with only the second light in the frames with too few lights, whitened by its own
// glow (as a light a few decimetres from the lens): the detector rejects it for its colour, and
// the walk from the posed frames takes it as that light.
TEST(DetectCli, AWhitenedCloseLightIsTakenWhereTheWalkPutsIt) {
  Footage footage;
  std::filesystem::create_directories(footage.dir / "frames");
  MakeFootage(&footage, 12, /*faded_light=*/-1, /*partial_from=*/8, /*whitened_second=*/true);
  const std::string out = footage.dir / "out";
  test::CommandResult r = test::RunAuvdock(DetectArgs(footage, out));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const nlohmann::json summary = nlohmann::json::parse(test::ReadTextFile(out + "/summary.json"));
  EXPECT_EQ(summary["bridged_frames"]["frames"], 4);
  EXPECT_EQ(summary["bridged_frames"]["rejected_candidates_accepted"], 4);
  EXPECT_EQ(summary["bridged_frames"]["identified"], 4);
  EXPECT_EQ(summary["labels"]["precision"], 1.0);
  ExpectEveryDetectionIdentifiedConsistently(footage, out, 8);
  const std::string frames = test::ReadTextFile(out + "/frames.csv");
  EXPECT_NE(frames.find("1 candidates that the detector did not take (rejected on appearance, or a "
                        "saturated disc) lie where they put a light and are taken as it"),
            std::string::npos)
      << frames;
  // With --bridge off nothing takes it: the rejected glow stays rejected.
  const std::string off = footage.dir / "off";
  std::vector<std::string> args = DetectArgs(footage, off);
  args.insert(args.end(), {"--bridge", "off"});
  r = test::RunAuvdock(args);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(test::ReadTextFile(off + "/rejected.csv").find("wrong colour"), std::string::npos);
}

// The same light with a reflection merged into its saturated plateau below it: the region's
// centroid is 8 px off; the light is its circle (saturated_disc.h).
TEST(DetectCli, ACloseLightsReflectionDoesNotMoveIt) {
  Footage footage;
  std::filesystem::create_directories(footage.dir / "frames");
  MakeFootage(&footage, 12, /*faded_light=*/-1, /*partial_from=*/8, /*whitened_second=*/true,
              /*reflected=*/true);
  const std::string out = footage.dir / "out";
  const test::CommandResult r = test::RunAuvdock(DetectArgs(footage, out));
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const nlohmann::json summary = nlohmann::json::parse(test::ReadTextFile(out + "/summary.json"));
  EXPECT_EQ(summary["bridged_frames"]["rejected_candidates_accepted"], 4);
  EXPECT_EQ(summary["labels"]["precision"], 1.0);
  ExpectEveryDetectionIdentifiedConsistently(footage, out, 8);
}

TEST(DetectCli, GravityResolvesAnUprightRing) {
  // The same footage with the ring standing upright in the dock file (gravity along +y of D)
  // and a camera known to be upright: the first frame is resolved by gravity.
  Footage footage;
  std::filesystem::create_directories(footage.dir / "frames");
  MakeFootage(&footage, 2);
  DockModel dock = LoadDockModel(footage.dir / "dock.yaml");
  dock.gravity_D = Eigen::Vector3d(0.0, 9.81, 0.0);
  SaveDockModel(dock, footage.dir / "dock.yaml");
  std::vector<std::string> args = DetectArgs(footage, footage.dir / "out");
  for (const char* a : {"--gravity-camera", "0", "1", "0"}) args.push_back(a);
  const test::CommandResult r = test::RunAuvdock(args);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string frames = test::ReadTextFile(footage.dir / "out/frames.csv");
  EXPECT_NE(frames.find("chosen by gravity"), std::string::npos) << frames;
}

// The footage as a video file (Motion JPEG, written by OpenCV's own encoder) instead of images:
// the same lights, poses and identities; frames named frame_NNNNNN (in the outputs and the labels)
// and timed by the file's rate (25/s here, where the calibration says 10/s).
TEST(DetectCli, AVideosFramesAreDetectedAsItsImagesAre) {
  Footage footage;
  std::filesystem::create_directories(footage.dir / "frames");
  MakeFootage(&footage, 12, /*faded_light=*/-1, /*partial_from=*/8);
  const std::string video = footage.dir / "footage.avi";
  cv::VideoWriter writer(video, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                         25.0, cv::Size(640, 480));
  ASSERT_TRUE(writer.isOpened());
  writer.set(cv::VIDEOWRITER_PROP_QUALITY, 100);
  for (int f = 0; f < 12; ++f) {
    char name[32];
    std::snprintf(name, sizeof(name), "frames/f%03d.png", f);
    writer.write(cv::imread(footage.dir / name));
  }
  writer.release();
  // The labels by the video's frame names.
  std::string labels = test::ReadTextFile(footage.dir / "labels.csv");
  for (size_t at = labels.find("f0"); at != std::string::npos; at = labels.find("f0", at)) {
    const int f = std::stoi(labels.substr(at + 1, 3));
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%06d", f);
    labels.replace(at, 8, name);  // fNNN.png
  }
  test::WriteTextFile(footage.dir / "video_labels.csv", labels);

  const std::string out = footage.dir / "out";
  std::vector<std::string> args = DetectArgs(footage, out);
  args[1] = "--video";
  args[2] = video;
  args[10] = footage.dir / "video_labels.csv";
  const test::CommandResult r = test::RunAuvdock(args);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("detect: 12 video frames"), std::string::npos) << r.out;
  const nlohmann::json summary = nlohmann::json::parse(test::ReadTextFile(out + "/summary.json"));
  EXPECT_EQ(summary["footage"], video);
  EXPECT_EQ(summary["frames"], 12);
  EXPECT_EQ(summary["frames_with_pose"], 8);
  EXPECT_EQ(summary["labels"]["frames"], 12);
  EXPECT_EQ(summary["labels"]["recall"], 1.0);
  EXPECT_EQ(summary["labels"]["precision"], 1.0);
  EXPECT_LT(summary["labels"]["centroid_rms_px"].get<double>(), 0.3);
  ExpectEveryDetectionIdentifiedConsistently(footage, out, 8);
  EXPECT_TRUE(std::filesystem::exists(out + "/overlay/frame_000011.png"));
  const Trajectory poses = ReadTumTrajectory(out + "/camera_poses.tum");
  ASSERT_EQ(poses.size(), 8u);
  EXPECT_NEAR(static_cast<double>(poses[7].t_ns), 7 * 0.04e9, 1e3);
  const std::string frames = test::ReadTextFile(out + "/frames.csv");
  EXPECT_NE(frames.find("\n11,frame_000011,"), std::string::npos) << frames;
}

void ExpectOneLineExitTwo(const std::vector<std::string>& args, const std::string& needle) {
  const test::CommandResult r = test::RunAuvdock(args);
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// Blue LEDs searched for as red: nothing is silently empty; every frame and the summary say the
// candidates had the wrong colour, and the end of the run asks whether the colour is right.
TEST(DetectCli, AWrongColourSaysSo) {
  Footage footage;
  std::filesystem::create_directories(footage.dir / "frames");
  MakeFootage(&footage, 2);
  const std::string out = footage.dir / "out";
  std::vector<std::string> args = DetectArgs(footage, out);
  args.push_back("--colour");
  args.push_back("red");
  const test::CommandResult r = test::RunAuvdock(args);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("most candidates had the wrong colour: are the lights red"),
            std::string::npos)
      << r.out;
  const std::string frames = test::ReadTextFile(out + "/frames.csv");
  EXPECT_NE(frames.find("most often: wrong colour"), std::string::npos) << frames;
  const nlohmann::json summary = nlohmann::json::parse(test::ReadTextFile(out + "/summary.json"));
  EXPECT_EQ(summary["frames_with_pose"], 0);
  EXPECT_GT(summary["rejected_candidates"]["wrong colour"].get<int>(), 8);
}

TEST(DetectCli, BadInputIsOneLineAndExitTwo) {
  Footage footage;
  std::filesystem::create_directories(footage.dir / "frames");
  MakeFootage(&footage, 1);
  auto args = [&](const std::string& out) { return DetectArgs(footage, footage.dir / out); };
  std::vector<std::string> a = args("o1");
  a[2] = footage.dir / "nothing/*.png";
  ExpectOneLineExitTwo(a, "no file matches");

  std::filesystem::create_directories(footage.dir / "small");
  std::filesystem::create_directories(footage.dir / "grey");
  cv::imwrite(footage.dir / "small/x.png", cv::Mat(100, 100, CV_8UC3, cv::Scalar(0, 0, 0)));
  a = args("o2");
  a[2] = footage.dir / "small/*.png";
  ExpectOneLineExitTwo(a, "the image is 100x100, the calibration 640x480");

  cv::imwrite(footage.dir / "grey/x.png", cv::Mat(480, 640, CV_8UC1, cv::Scalar(0)));
  a = args("o3");
  a[2] = footage.dir / "grey/*.png";
  ExpectOneLineExitTwo(a, "a grey image, but the lights are blue");

  test::WriteTextFile(footage.dir / "bad_labels.csv", "frame_file,u,v\nf000.png,1,oops\n");
  a = args("o4");
  a[10] = footage.dir / "bad_labels.csv";
  ExpectOneLineExitTwo(a, "bad_labels.csv: line 2: column 'v'");

  a = args("o5");
  a.push_back("--colour");
  a.push_back("purple");
  ExpectOneLineExitTwo(a, "--colour: purple not in {white,blue,green,blue_green,red}");

  a = args("o6");
  a[1] = "--video";
  a[2] = footage.dir / "calibration.yaml";
  ExpectOneLineExitTwo(a, "--video: " + footage.dir / "calibration.yaml");
  a = args("o7");
  a.insert(a.begin() + 3, {"--video", footage.dir / "calibration.yaml"});
  ExpectOneLineExitTwo(a, "--images excludes --video");
  a = args("o8");
  a.erase(a.begin() + 1, a.begin() + 3);
  ExpectOneLineExitTwo(a, "give the footage as --images");
}

}  // namespace
}  // namespace auvdock
