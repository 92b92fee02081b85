#include "auvdock/estimator/vision_error_statistics.h"

#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <vector>

#include <ceres/problem.h>
#include <ceres/sized_cost_function.h>
#include <gtest/gtest.h>

namespace auvdock {
namespace {

// A residual block that returns a fixed (whitened) residual whatever its parameter.
class FixedResidual final : public ceres::CostFunction {
 public:
  explicit FixedResidual(std::vector<double> r) : r_(std::move(r)) {
    set_num_residuals(static_cast<int>(r_.size()));
    mutable_parameter_block_sizes()->push_back(1);
  }
  bool Evaluate(double const* const*, double* residuals, double** jacobians) const override {
    for (size_t i = 0; i < r_.size(); ++i) residuals[i] = r_[i];
    if (jacobians && jacobians[0]) {
      for (size_t i = 0; i < r_.size(); ++i) jacobians[0][i] = 0.0;
    }
    return true;
  }

 private:
  std::vector<double> r_;
};

constexpr int64_t kFrameNs = 100'000'000;  // 10 Hz

struct Tracks {
  ceres::Problem problem;
  double parameter = 0.0;
  std::vector<VisionResidual> residuals;

  // A track of mono pixel errors (px) of one light, whitened with sigma_px.
  void AddMono(int light, const std::vector<Eigen::Vector2d>& errors_px, double sigma_px,
               int64_t step_ns = kFrameNs) {
    for (size_t k = 0; k < errors_px.size(); ++k) {
      const Eigen::Vector2d w = errors_px[k] / sigma_px;
      VisionResidual r;
      r.id = problem.AddResidualBlock(new FixedResidual({w.x(), w.y()}), nullptr, &parameter);
      r.mono = true;
      r.light_id = light;
      r.t_ns = static_cast<int64_t>(k) * step_ns;
      r.sensor = "cam2";
      r.pixel_sigma_px = sigma_px;
      residuals.push_back(r);
    }
  }
};

// White (sigma_w) plus AR(1) (sigma_s, correlation time tau) errors per coordinate.
std::vector<Eigen::Vector2d> Errors(int n, double sigma_w, double sigma_s, double tau_s,
                                    std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  const double rho = std::exp(-0.1 / tau_s);
  Eigen::Vector2d slow(sigma_s * normal(rng), sigma_s * normal(rng));
  std::vector<Eigen::Vector2d> out;
  for (int k = 0; k < n; ++k) {
    out.push_back(slow + sigma_w * Eigen::Vector2d(normal(rng), normal(rng)));
    slow = rho * slow + sigma_s * std::sqrt(1.0 - rho * rho) *
                            Eigen::Vector2d(normal(rng), normal(rng));
  }
  return out;
}

TEST(VisionErrorStatistics, SeparatesTheWhiteAndTheSlowPartsOfKnownErrors) {
  std::mt19937_64 rng(7);
  Tracks tracks;
  for (int light = 0; light < 40; ++light) {
    tracks.AddMono(light, Errors(400, 0.2, 0.1, 20.0, rng), /*sigma_px=*/0.5);
  }
  const VisionErrorStatistics stats =
      MeasureVisionErrors(tracks.problem, tracks.residuals, 3 * kFrameNs / 2);
  EXPECT_EQ(stats.coordinates, 40 * 400 * 2);
  EXPECT_EQ(stats.lag_pairs, 40 * 399 * 2);
  EXPECT_NEAR(stats.white_px, 0.2, 0.01);
  EXPECT_NEAR(stats.slow_px, 0.1, 0.015);
}

TEST(VisionErrorStatistics, WhiteErrorsHaveNoSlowPartAndTheSigmaUsedCancels) {
  std::mt19937_64 rng(3);
  Tracks tracks;
  for (int light = 0; light < 20; ++light) {
    // The same pixel errors whatever sigma they were whitened with.
    tracks.AddMono(light, Errors(300, 0.3, 0.0, 1.0, rng), light % 2 == 0 ? 0.3 : 2.0);
  }
  const VisionErrorStatistics stats =
      MeasureVisionErrors(tracks.problem, tracks.residuals, 3 * kFrameNs / 2);
  EXPECT_NEAR(stats.white_px, 0.3, 0.01);
  EXPECT_LT(stats.slow_px, 0.03);
}

TEST(VisionErrorStatistics, FramesFartherApartThanTheGapAreNotPairedAndNothingGivesZeros) {
  std::mt19937_64 rng(5);
  Tracks sparse;
  sparse.AddMono(1, Errors(50, 0.2, 0.1, 20.0, rng), 0.5, /*step_ns=*/10 * kFrameNs);
  const VisionErrorStatistics stats =
      MeasureVisionErrors(sparse.problem, sparse.residuals, 3 * kFrameNs / 2);
  EXPECT_EQ(stats.coordinates, 100);
  EXPECT_EQ(stats.lag_pairs, 0);
  EXPECT_EQ(stats.white_px, 0.0);
  EXPECT_EQ(stats.slow_px, 0.0);

  Tracks none;
  const VisionErrorStatistics empty = MeasureVisionErrors(none.problem, {}, kFrameNs);
  EXPECT_EQ(empty.lag_pairs, 0);
  EXPECT_EQ(empty.white_px, 0.0);
}

// SlowVisionError, online: frame after frame, the residuals of two consecutive states. Each
// frame k's mono lights (their pixel errors and sigmas, light i in position i) come from
// `frame(k)`; returns the estimate after the last frame.
struct MonoLight {
  Eigen::Vector2d error_px;
  double sigma_px;
};
double FeedOnline(int frames, const std::function<std::vector<MonoLight>(int)>& frame,
                  const SlowVisionErrorOptions& options = {}) {
  Tracks tracks;
  SlowVisionError slow(options);
  for (int k = 0; k < frames; ++k) {
    const size_t first = tracks.residuals.size();
    const std::vector<MonoLight> lights = frame(k);
    for (size_t i = 0; i < lights.size(); ++i) {
      tracks.AddMono(static_cast<int>(i), {lights[i].error_px}, lights[i].sigma_px);
      tracks.residuals.back().t_ns = k * kFrameNs;
    }
    const std::vector<VisionResidual> newest(tracks.residuals.begin() + first,
                                             tracks.residuals.end());
    slow.Add(tracks.problem, newest, 3 * kFrameNs / 2);
  }
  return slow.slow_px();
}

// Eight lights, each with its own constant bias (as a light's asymmetric lobe gives, 1-sigma
// bias_px per coordinate) plus white noise of white_px, whitened with 0.3 px.
double BiasedLights(int frames, double bias_px, double white_px,
                    const SlowVisionErrorOptions& options = {}) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  std::vector<Eigen::Vector2d> bias;
  for (int light = 0; light < 8; ++light) {
    bias.push_back(bias_px * Eigen::Vector2d(normal(rng), normal(rng)));
  }
  return FeedOnline(
      frames,
      [&](int) {
        std::vector<MonoLight> lights;
        for (const Eigen::Vector2d& b : bias) {
          const Eigen::Vector2d white(white_px * normal(rng), white_px * normal(rng));
          lights.push_back({b + white, 0.3});
        }
        return lights;
      },
      options);
}

TEST(SlowVisionError, FindsPerLightBiasesOnlineAndNothingInWhiteErrors) {
  EXPECT_NEAR(BiasedLights(600, 0.2, 0.3), 0.2, 0.05);
  EXPECT_LT(BiasedLights(600, 0.0, 0.3), 0.04);
}

TEST(SlowVisionError, WaitsForEnoughPairsAndCanBeOff) {
  EXPECT_EQ(BiasedLights(5, 0.2, 0.3), 0.0);  // 64 pairs of the 200 needed
  SlowVisionErrorOptions off;
  off.enabled = false;
  EXPECT_EQ(BiasedLights(600, 0.2, 0.3, off), 0.0);
}

// After a lit approach with white errors, frames whose one light is a wide glow (sigma 5 px)
// with a persistent 3 px error: their information is a hundredth of the approach's frames', so
// the floor stays near where the approach put it instead of jumping to the glow's error.
TEST(SlowVisionError, AWideGlowsPersistentErrorMovesItLittle) {
  std::mt19937_64 rng(13);
  std::normal_distribution<double> normal;
  const double slow = FeedOnline(400, [&](int k) {
    std::vector<MonoLight> lights;
    if (k >= 300) {
      lights.push_back({Eigen::Vector2d(3.0, 0.0), 5.0});
      return lights;
    }
    for (int light = 0; light < 8; ++light) {
      lights.push_back({Eigen::Vector2d(0.3 * normal(rng), 0.3 * normal(rng)), 0.3});
    }
    return lights;
  });
  EXPECT_LT(slow, 0.1);
}

}  // namespace
}  // namespace auvdock
