// Cost of IMU preintegration per sample (deltas, bias Jacobians and the 9x9 covariance) and of one
// evaluation of the preintegrated-IMU factor, residual only and with Jacobians (what the sliding
// window pays per IMU factor per solver iteration), for the analytic factor (production, arg 1)
// and the autodiff reference (arg 0). At 200 Hz and 10 Hz keyframes a factor holds 20 samples.
#include <memory>

#include <benchmark/benchmark.h>
#include <ceres/cost_function.h>

#include "auvdock/imu/imu_preintegration.h"
#include "factors/imu_preintegration_factor.h"

namespace auvdock {
namespace {

const Eigen::Vector3d kGravity_D(0.0, 0.0, 9.81);

void BM_IntegrateOneSample(benchmark::State& state) {
  ImuPreintegration pim(ImuNoiseDensities{}, ImuBias{});
  const Eigen::Vector3d gyro(0.1, -0.2, 0.3);
  const Eigen::Vector3d accel(0.5, 0.1, -9.7);
  for (auto _ : state) {
    pim.Integrate(gyro, accel, 0.005);
    benchmark::DoNotOptimize(pim.delta_p().data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_IntegrateOneSample);

ceres::CostFunction* MakeFactor(const ImuPreintegration& pim, bool analytic) {
  return analytic ? ImuPreintegrationFactor::Create(pim, kGravity_D)
                  : ImuPreintegrationFactor::CreateAutoDiff(pim, kGravity_D);
}

void BM_FactorEvaluateWithJacobians(benchmark::State& state) {
  ImuPreintegration pim(ImuNoiseDensities{}, ImuBias{});
  for (int k = 0; k < 20; ++k) {
    pim.Integrate(Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(0.5, 0.1, -9.7), 0.005);
  }
  const std::unique_ptr<ceres::CostFunction> cost(MakeFactor(pim, state.range(0) == 1));
  double pose_i[7] = {1, 2, 3, 0.1, 0.2, 0.3, 0.927};
  double pose_j[7] = {1.1, 2, 3, 0.1, 0.2, 0.31, 0.92};
  double v_i[3] = {0.5, 0, 0}, v_j[3] = {0.5, 0.01, 0};
  double b_i[6] = {0.001, 0, 0, 0.01, 0, 0}, b_j[6] = {0.001, 0, 0, 0.01, 0, 0};
  const double* parameters[] = {pose_i, v_i, b_i, pose_j, v_j, b_j};
  double residuals[15];
  double J0[15 * 7], J1[15 * 3], J2[15 * 6], J3[15 * 7], J4[15 * 3], J5[15 * 6];
  double* jacobians[] = {J0, J1, J2, J3, J4, J5};
  for (auto _ : state) {
    cost->Evaluate(parameters, residuals, jacobians);
    benchmark::DoNotOptimize(J5[0]);
  }
}
BENCHMARK(BM_FactorEvaluateWithJacobians)->ArgName("analytic")->Arg(0)->Arg(1);

void BM_FactorEvaluateResidualOnly(benchmark::State& state) {
  ImuPreintegration pim(ImuNoiseDensities{}, ImuBias{});
  for (int k = 0; k < 20; ++k) {
    pim.Integrate(Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(0.5, 0.1, -9.7), 0.005);
  }
  const std::unique_ptr<ceres::CostFunction> cost(MakeFactor(pim, state.range(0) == 1));
  double pose_i[7] = {1, 2, 3, 0.1, 0.2, 0.3, 0.927};
  double pose_j[7] = {1.1, 2, 3, 0.1, 0.2, 0.31, 0.92};
  double v_i[3] = {0.5, 0, 0}, v_j[3] = {0.5, 0.01, 0};
  double b_i[6] = {0.001, 0, 0, 0.01, 0, 0}, b_j[6] = {0.001, 0, 0, 0.01, 0, 0};
  const double* parameters[] = {pose_i, v_i, b_i, pose_j, v_j, b_j};
  double residuals[15];
  for (auto _ : state) {
    cost->Evaluate(parameters, residuals, nullptr);
    benchmark::DoNotOptimize(residuals[0]);
  }
}
BENCHMARK(BM_FactorEvaluateResidualOnly)->ArgName("analytic")->Arg(0)->Arg(1);

}  // namespace
}  // namespace auvdock
