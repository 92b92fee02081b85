// Synthetic detections (sim/synthetic_detections.h): noise off gives the exact projections;
// noise on gives the configured white noise, bias, misses, spurious blobs and wrong identities,
// each fault recorded; the same seed gives the same detections.
#include "auvdock/sim/synthetic_detections.h"

#include <cmath>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "tests/testing/dock_views.h"

namespace auvdock {
namespace {

class SyntheticDetectionsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dock_ = test::LoadDock("t_shape.yaml");
    camera_.name = "cam0";
    camera_.intrinsics = test::DefaultMonoCamera();
    camera_.pixel_noise_px = 0.3;
    const PinholeRadtanCamera& k = camera_.intrinsics;
    for (const DockLight& light : dock_.lights) {
      RenderedLight r;
      r.light_id = light.id;
      r.uv = Eigen::Vector2d(k.cx() + 40.0 * light.p_D.x() * 4, k.cy() + 40.0 * light.p_D.y() * 4);
      r.radius_px = 2.0;
      r.peak = 200.0;
      visible_.push_back(r);
    }
  }
  const RenderedLight& Truth(int id) const {
    for (const RenderedLight& r : visible_) {
      if (r.light_id == id) return r;
    }
    return visible_.front();
  }
  DockModel dock_;
  CameraCalibration camera_;
  std::vector<RenderedLight> visible_;
};

TEST_F(SyntheticDetectionsTest, NoiseOffGivesTheExactProjections) {
  SyntheticDetector detector({}, camera_, dock_, /*noisy=*/false, std::mt19937_64(1));
  std::vector<FaultRecord> faults;
  const ImageDetections image = detector.Detect(123, visible_, &faults);
  EXPECT_TRUE(faults.empty());
  EXPECT_EQ(image.t_ns, 123);
  EXPECT_EQ(image.camera, "cam0");
  ASSERT_EQ(image.detections.size(), visible_.size());
  for (size_t i = 0; i < image.detections.size(); ++i) {
    EXPECT_EQ(image.detections[i].uv, Truth(image.light_ids[i]).uv);
    EXPECT_DOUBLE_EQ(image.detections[i].radius_px, 4.0);
  }
}

TEST_F(SyntheticDetectionsTest, ErrorsFollowTheConfiguration) {
  SyntheticDetectionConfig config;
  config.bias_px = 0.0;
  config.miss_probability = 0.1;
  config.spurious_per_frame = 0.5;
  config.wrong_id_probability = 0.05;
  SyntheticDetector detector(config, camera_, dock_, /*noisy=*/true, std::mt19937_64(7));
  std::vector<FaultRecord> faults;
  const int images = 4000;
  double sum_squared = 0.0;
  int right = 0, wrong = 0, spurious = 0;
  for (int n = 0; n < images; ++n) {
    const ImageDetections image = detector.Detect(n, visible_, &faults);
    for (size_t i = 0; i < image.detections.size(); ++i) {
      const int id = image.light_ids[i];
      if (id < 0) {
        ++spurious;
        EXPECT_GE(image.detections[i].score, 0.3);
        EXPECT_LT(image.detections[i].score, 1.0);
        continue;
      }
      const double error = (image.detections[i].uv - Truth(id).uv).norm();
      if (error > 20.0) {
        ++wrong;  // another light's identity
        continue;
      }
      ++right;
      sum_squared += (image.detections[i].uv - Truth(id).uv).squaredNorm();
    }
  }
  std::map<std::string, int> kinds;
  for (const FaultRecord& f : faults) ++kinds[f.kind];
  const double lights = static_cast<double>(images * visible_.size());
  // Each count within ~5 standard deviations of its expectation.
  EXPECT_NEAR(kinds["missed_light"] / lights, 0.1, 0.008);
  EXPECT_NEAR(kinds["spurious_detection"] / static_cast<double>(images), 0.5, 0.06);
  EXPECT_EQ(kinds["spurious_detection"], spurious);
  EXPECT_NEAR(wrong / (lights * 0.9), 0.05, 0.006);
  EXPECT_EQ(kinds["wrong_id"], wrong);
  EXPECT_EQ(right + wrong + kinds["missed_light"], static_cast<int>(lights));
  // Per axis RMS = pixel_noise_px.
  EXPECT_NEAR(std::sqrt(sum_squared / (2.0 * right)), 0.3, 0.006);
}

TEST_F(SyntheticDetectionsTest, EachLightHasItsOwnBoundedBias) {
  SyntheticDetectionConfig config;
  config.bias_px = 0.4;
  config.miss_probability = 0.0;
  config.spurious_per_frame = 0.0;
  config.wrong_id_probability = 0.0;
  camera_.pixel_noise_px = 1e-9;
  SyntheticDetector detector(config, camera_, dock_, /*noisy=*/true, std::mt19937_64(3));
  std::vector<FaultRecord> faults;
  const ImageDetections image = detector.Detect(0, visible_, &faults);
  EXPECT_TRUE(faults.empty());
  std::vector<Eigen::Vector2d> biases;
  for (size_t i = 0; i < image.detections.size(); ++i) {
    const Eigen::Vector2d b = image.detections[i].uv - Truth(image.light_ids[i]).uv;
    EXPECT_GE(b.norm(), 0.2 - 1e-6);
    EXPECT_LE(b.norm(), 0.4 + 1e-6);
    biases.push_back(b);
  }
  // Not one bias shared by all lights.
  EXPECT_GT((biases[0] - biases[1]).norm(), 1e-3);
  // The same light, same place: the same bias (it is a property of the view, not noise).
  const ImageDetections again = detector.Detect(1, visible_, &faults);
  for (size_t i = 0; i < again.detections.size(); ++i) {
    for (size_t j = 0; j < image.detections.size(); ++j) {
      if (image.light_ids[j] == again.light_ids[i]) {
        EXPECT_NEAR((again.detections[i].uv - image.detections[j].uv).norm(), 0.0, 1e-6);
      }
    }
  }
}

TEST_F(SyntheticDetectionsTest, UnidentifiedDetectionsCarryNoIds) {
  SyntheticDetectionConfig config;
  config.identified = false;
  SyntheticDetector detector(config, camera_, dock_, /*noisy=*/true, std::mt19937_64(5));
  std::vector<FaultRecord> faults;
  for (int n = 0; n < 50; ++n) {
    for (int id : detector.Detect(n, visible_, &faults).light_ids) EXPECT_EQ(id, -1);
  }
  for (const FaultRecord& f : faults) EXPECT_NE(f.kind, "wrong_id");
}

TEST_F(SyntheticDetectionsTest, TheSameSeedGivesTheSameDetections) {
  SyntheticDetector a({}, camera_, dock_, true, std::mt19937_64(11));
  SyntheticDetector b({}, camera_, dock_, true, std::mt19937_64(11));
  std::vector<FaultRecord> fa, fb;
  for (int n = 0; n < 100; ++n) {
    const ImageDetections da = a.Detect(n, visible_, &fa);
    const ImageDetections db = b.Detect(n, visible_, &fb);
    ASSERT_EQ(da.detections.size(), db.detections.size());
    EXPECT_EQ(da.light_ids, db.light_ids);
    for (size_t i = 0; i < da.detections.size(); ++i) {
      EXPECT_EQ(da.detections[i].uv, db.detections[i].uv);
    }
  }
  EXPECT_EQ(fa.size(), fb.size());
}

TEST(PoissonCountTest, MeanAndVarianceMatch) {
  std::mt19937_64 rng(2);
  const int n = 20000;
  double sum = 0.0, sum_squared = 0.0;
  for (int i = 0; i < n; ++i) {
    const int k = PoissonCount(2.5, rng);
    sum += k;
    sum_squared += static_cast<double>(k) * k;
  }
  const double mean = sum / n;
  EXPECT_NEAR(mean, 2.5, 0.06);
  EXPECT_NEAR(sum_squared / n - mean * mean, 2.5, 0.15);
  EXPECT_EQ(PoissonCount(0.0, rng), 0);
  EXPECT_EQ(PoissonCount(-1.0, rng), 0);
}

}  // namespace
}  // namespace auvdock
