#include "auvdock/camera/pinhole_radtan_camera.h"

#include <cmath>

#include <gtest/gtest.h>

namespace auvdock {
namespace {

const std::array<double, 5> kDistortion{-0.05, 0.01, 0.0005, -0.0003, 0.001};

TEST(PinholeRadtanCamera, ProjectUnprojectRoundTripOverTheImage) {
  const auto cam = PinholeRadtanCamera::FromHorizontalFov(640, 512, 70.0 * M_PI / 180.0,
                                                          kDistortion);
  for (double u = 0; u < 640; u += 31.7) {
    for (double v = 0; v < 512; v += 29.3) {
      const Eigen::Vector2d uv(u, v);
      const Eigen::Vector3d bearing = cam.Bearing(uv);
      const auto back = cam.Project(3.7 * bearing);
      ASSERT_TRUE(back.has_value());
      EXPECT_LT((*back - uv).norm(), 1e-9) << u << " " << v;
    }
  }
}

TEST(PinholeRadtanCamera, KnownProjectionWithoutDistortion) {
  const PinholeRadtanCamera cam(640, 480, 500.0, 510.0, 320.0, 240.0, {});
  const auto uv = cam.Project(Eigen::Vector3d(0.2, -0.1, 2.0));
  ASSERT_TRUE(uv.has_value());
  EXPECT_DOUBLE_EQ(uv->x(), 320.0 + 500.0 * 0.1);
  EXPECT_DOUBLE_EQ(uv->y(), 240.0 - 510.0 * 0.05);
  EXPECT_FALSE(cam.Project(Eigen::Vector3d(0.0, 0.0, -1.0)).has_value());
}

TEST(PinholeRadtanCamera, HorizontalFieldOfView) {
  const auto cam = PinholeRadtanCamera::FromHorizontalFov(640, 512, M_PI / 2.0, {});
  EXPECT_NEAR(cam.fx(), 320.0, 1e-12);
  // A ray at 45 degrees lands on the image border (pixel edge at -0.5).
  const auto uv = cam.Project(Eigen::Vector3d(-1.0, 0.0, 1.0));
  EXPECT_NEAR(uv->x(), -0.5, 1e-9);
  EXPECT_TRUE(cam.InImage(*uv + Eigen::Vector2d(1e-6, 0)));
  EXPECT_FALSE(cam.InImage(*uv + Eigen::Vector2d(-0.01, 0)));
}

TEST(PinholeRadtanCamera, DistortionTemplateMatchesOpenCvFormula) {
  // Hand-worked: x = 0.2, y = -0.1, r2 = 0.05.
  const double x = 0.2, y = -0.1, r2 = 0.05;
  const auto& d = kDistortion;
  const double radial = 1 + d[0] * r2 + d[1] * r2 * r2 + d[4] * r2 * r2 * r2;
  const double xd = x * radial + 2 * d[2] * x * y + d[3] * (r2 + 2 * x * x);
  const double yd = y * radial + d[2] * (r2 + 2 * y * y) + 2 * d[3] * x * y;
  double out_x, out_y;
  DistortNormalized(d, x, y, &out_x, &out_y);
  EXPECT_NEAR(out_x, xd, 1e-15);
  EXPECT_NEAR(out_y, yd, 1e-15);
}

TEST(PinholeRadtanCamera, PointsBeyondTheFoldRadiusAreNotImaged) {
  // A strongly barrel-distorted lens (one the randomised renders draw): radial mapping
  // r (1 - 0.31 r^2 + 0.042 r^4 - 0.022 r^6) stops growing at r ~ 1.05 (46 deg off axis); a ray 60
  // deg off axis would come back to 0.14 of its pinhole radius, mid-image, on the other side.
  const std::array<double, 5> strong{-0.312, 0.0418, 0.0, 0.0, -0.0217};
  const auto cam = PinholeRadtanCamera::FromHorizontalFov(640, 512, 70.0 * M_PI / 180.0, strong);
  const double s = cam.fold_radius() * cam.fold_radius();
  EXPECT_NEAR(1.0 + s * (3.0 * strong[0] + s * (5.0 * strong[1] + s * 7.0 * strong[4])), 0.0,
              1e-9);
  EXPECT_GT(cam.fold_radius(), 1.0);
  EXPECT_LT(cam.fold_radius(), 1.1);
  // Inside the fold points project and round-trip.
  const double r_in = 0.99 * cam.fold_radius();
  const Eigen::Vector2d inside = *cam.Project(Eigen::Vector3d(0.0, 0.9 * cam.fold_radius(), 1.0));
  const auto back = cam.Project(2.0 * cam.Bearing(inside));
  ASSERT_TRUE(back.has_value());
  EXPECT_LT((*back - inside).norm(), 1e-6);
  EXPECT_TRUE(cam.Project(Eigen::Vector3d(r_in, 0.0, 1.0)).has_value());
  // Beyond it, nothing: not a pixel in the middle of the image.
  const double r_out = std::tan(60.0 * M_PI / 180.0);
  EXPECT_FALSE(cam.Project(Eigen::Vector3d(0.0, -r_out, 1.0)).has_value());
  EXPECT_FALSE(cam.Project(Eigen::Vector3d(1.01 * cam.fold_radius(), 0.0, 1.0)).has_value());
  // A lens that never folds (pincushion, or none) images every point in front of it.
  EXPECT_TRUE(std::isinf(PinholeRadtanCamera(640, 480, 500, 500, 320, 240, {}).fold_radius()));
  EXPECT_TRUE(std::isinf(PinholeRadtanCamera(640, 480, 500, 500, 320, 240, {0.1, 0.01, 0, 0, 0})
                             .fold_radius()));
  EXPECT_TRUE(PinholeRadtanCamera(640, 480, 500, 500, 320, 240, {})
                  .Project(Eigen::Vector3d(50.0, 0.0, 1.0))
                  .has_value());
}

}  // namespace
}  // namespace auvdock
