#include "auvdock/vision/ransac_matcher.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "auvdock/geometry/dock_symmetry.h"
#include "auvdock/vision/hungarian.h"
#include "auvdock/vision/tracking_matcher.h"

namespace auvdock {

namespace {

struct RigidPose {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // R_C_D
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      // p_C_D
};

// ---------------------------------------------------------------------------------------------
// Polynomial roots
// ---------------------------------------------------------------------------------------------

// Largest real root of the monic cubic m^3 + a m^2 + b m + c.
double LargestCubicRoot(double a, double b, double c) {
  // Depressed: m = z - a/3, z^3 + p z + q = 0.
  const double p = b - a * a / 3.0;
  const double q = 2.0 * a * a * a / 27.0 - a * b / 3.0 + c;
  const double half_q = 0.5 * q;
  const double third_p = p / 3.0;
  const double discriminant = half_q * half_q + third_p * third_p * third_p;
  double z;
  if (discriminant > 0.0) {
    const double root = std::sqrt(discriminant);
    z = std::cbrt(-half_q + root) + std::cbrt(-half_q - root);
  } else {
    // Three real roots (trigonometric form); k = 0 is the largest.
    const double radius = std::sqrt(std::max(0.0, -third_p));
    const double cosine =
        radius > 0.0 ? std::clamp(-half_q / (radius * radius * radius), -1.0, 1.0) : 0.0;
    z = 2.0 * radius * std::cos(std::acos(cosine) / 3.0);
  }
  double m = z - a / 3.0;
  for (int i = 0; i < 2; ++i) {  // Newton polish
    const double f = ((m + a) * m + b) * m + c;
    const double df = (3.0 * m + 2.0 * a) * m + b;
    if (df == 0.0) break;
    m -= f / df;
  }
  return m;
}

// Root candidates of the quadratic y^2 + b y + c: the two real roots, or the real part twice for
// a complex pair with a small imaginary part (rounding turns close real roots into such pairs;
// the caller polishes every candidate on the original equations and keeps those that converge).
// A clearly complex pair gives NaN. Writes two values.
void QuadraticRootCandidates(double b, double c, double* roots) {
  const double discriminant = b * b - 4.0 * c;
  if (discriminant >= 0.0) {
    const double root = std::sqrt(discriminant);
    roots[0] = 0.5 * (-b + root);
    roots[1] = 0.5 * (-b - root);
    return;
  }
  const double real = -0.5 * b;
  const double imaginary = 0.5 * std::sqrt(-discriminant);
  const bool close = imaginary <= 0.05 * std::max(std::abs(real), 1.0);
  roots[0] = roots[1] = close ? real : std::numeric_limits<double>::quiet_NaN();
}

// Root candidates of c[4] v^4 + c[3] v^3 + c[2] v^2 + c[1] v + c[0] by Ferrari's method: the
// real roots and the real parts of complex pairs (see QuadraticRootCandidates). Returns the count.
int QuarticRootCandidates(const double c[5], double roots[4]) {
  const double scale =
      std::max({std::abs(c[0]), std::abs(c[1]), std::abs(c[2]), std::abs(c[3]), std::abs(c[4])});
  if (!(std::abs(c[4]) > 1e-12 * scale)) return 0;  // degenerate configuration
  const double a = c[3] / c[4], b = c[2] / c[4], cc = c[1] / c[4], d = c[0] / c[4];
  // Depressed quartic y^4 + p y^2 + q y + r, v = y - a/4.
  const double a2 = a * a;
  const double p = b - 3.0 * a2 / 8.0;
  const double q = cc - a * b / 2.0 + a2 * a / 8.0;
  const double r = d - a * cc / 4.0 + a2 * b / 16.0 - 3.0 * a2 * a2 / 256.0;
  double y[4];
  bool solved = false;
  if (std::abs(q) > 1e-14 * (1.0 + std::abs(p) + std::abs(r))) {
    // (y^2 + p/2 + m)^2 = (s y - q/(2s))^2 with s = sqrt(2m), m > 0 a root of the resolvent
    // 8m^3 + 8p m^2 + (2p^2 - 8r) m - q^2 = 0.
    const double m = LargestCubicRoot(p, p * p / 4.0 - r, -q * q / 8.0);
    if (m > 0.0) {
      const double s = std::sqrt(2.0 * m);
      const double shift = q / (2.0 * s);
      QuadraticRootCandidates(-s, 0.5 * p + m + shift, y);
      QuadraticRootCandidates(s, 0.5 * p + m - shift, y + 2);
      solved = true;
    }
  }
  if (!solved) {
    // Biquadratic: y^2 = z with z^2 + p z + r = 0.
    double z[2];
    QuadraticRootCandidates(p, r, z);
    for (int i = 0; i < 2; ++i) {
      const double root = z[i] >= 0.0 ? std::sqrt(z[i]) : std::numeric_limits<double>::quiet_NaN();
      y[2 * i] = root;
      y[2 * i + 1] = -root;
    }
  }
  for (int i = 0; i < 4; ++i) roots[i] = y[i] - a / 4.0;
  return 4;
}

// Orthonormal frame (columns) of a triangle: x along 1->2, z normal, origin at point 1.
Eigen::Matrix3d TriangleFrame(const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                              const Eigen::Vector3d& p3) {
  const Eigen::Vector3d e1 = (p2 - p1).normalized();
  const Eigen::Vector3d e3 = e1.cross(p3 - p1).normalized();
  Eigen::Matrix3d frame;
  frame << e1, e3.cross(e1), e3;
  return frame;
}

// An ordered triple of model points, with what P3P needs precomputed.
struct ModelTriangle {
  std::array<int, 3> light{};        // indices into the dock's lights
  std::array<Eigen::Vector3d, 3> X;  // points in D
  double a2 = 0, b2 = 0, c2 = 0;     // |X2-X3|^2, |X1-X3|^2, |X1-X2|^2
  Eigen::Matrix3d frame_D;           // TriangleFrame(X1, X2, X3)
  int orientation = 0;               // sign of the (x, y) area in D (planar docks)
};

ModelTriangle MakeModelTriangle(const std::array<Eigen::Vector3d, 3>& X) {
  ModelTriangle m;
  m.X = X;
  m.a2 = (X[1] - X[2]).squaredNorm();
  m.b2 = (X[0] - X[2]).squaredNorm();
  m.c2 = (X[0] - X[1]).squaredNorm();
  m.frame_D = TriangleFrame(X[0], X[1], X[2]);
  const Eigen::Vector3d e12 = X[1] - X[0], e13 = X[2] - X[0];
  const double area = e12.x() * e13.y() - e12.y() * e13.x();
  m.orientation = area > 0 ? 1 : (area < 0 ? -1 : 0);
  return m;
}

// Grunert's solution. f: unit bearings in C. Returns the number of poses written.
// Newton polishing: up to max_newton_iterations steps; a solution is kept when the equations
// hold to `tolerance` relative to the squared sides.
int SolveP3PCore(const std::array<Eigen::Vector3d, 3>& f, const ModelTriangle& m,
                 int max_newton_iterations, double tolerance, RigidPose poses[4]) {
  const double cos_alpha = f[1].dot(f[2]);  // angle opposite side a
  const double cos_beta = f[0].dot(f[2]);
  const double cos_gamma = f[0].dot(f[1]);
  // Law of cosines with s2 = u s1, s3 = v s1:
  //   s1^2 (u^2 + v^2 - 2 u v cos_alpha) = a^2
  //   s1^2 (1 + v^2 - 2 v cos_beta) = b^2
  //   s1^2 (1 + u^2 - 2 u cos_gamma) = c^2.
  // Dividing by the second and subtracting the third from the first gives u = N(v) / D(v) with
  //   N(v) = (k1 - k2)(1 + v^2 - 2 v cos_beta) + 1 - v^2,  D(v) = 2 (cos_gamma - v cos_alpha),
  // k1 = a^2/b^2, k2 = c^2/b^2. The third equation becomes the quartic
  //   N^2 - 2 cos_gamma N D + (1 - k2 (1 + v^2 - 2 v cos_beta)) D^2 = 0.
  const double k1 = m.a2 / m.b2;
  const double k2 = m.c2 / m.b2;
  const double k12 = k1 - k2;
  const double n0 = k12 + 1.0, n1 = -2.0 * k12 * cos_beta, n2 = k12 - 1.0;
  const double d0 = 2.0 * cos_gamma, d1 = -2.0 * cos_alpha;
  const double w0 = 1.0 - k2, w1 = 2.0 * k2 * cos_beta, w2 = -k2;
  const double nn[5] = {n0 * n0, 2.0 * n0 * n1, n1 * n1 + 2.0 * n0 * n2, 2.0 * n1 * n2, n2 * n2};
  const double nd[4] = {n0 * d0, n0 * d1 + n1 * d0, n1 * d1 + n2 * d0, n2 * d1};
  const double dd[3] = {d0 * d0, 2.0 * d0 * d1, d1 * d1};
  const double wdd[5] = {w0 * dd[0], w0 * dd[1] + w1 * dd[0], w0 * dd[2] + w1 * dd[1] + w2 * dd[0],
                         w1 * dd[2] + w2 * dd[1], w2 * dd[2]};
  double quartic[5];
  for (int i = 0; i < 5; ++i) {
    quartic[i] = nn[i] + wdd[i] - (i < 4 ? 2.0 * cos_gamma * nd[i] : 0.0);
  }
  double roots[4];
  const int num_roots = QuarticRootCandidates(quartic, roots);
  // The quartic is badly conditioned when the three depths are similar (v ~ 1, four roots close
  // together): its roots are only starting points. Each is polished by Newton's method on the
  // three law-of-cosines equations in (s1, s2, s3), which are well conditioned away from the
  // true degeneracies, and kept if it converges to a new positive solution.
  const double sides2[3] = {m.a2, m.b2, m.c2};
  Eigen::Vector3d solutions[4];
  int count = 0;
  for (int i = 0; i < num_roots; ++i) {
    const double v = roots[i];
    if (!(v > 0.0)) continue;
    const double denominator = d0 + d1 * v;
    if (std::abs(denominator) < 1e-12) continue;
    const double u = (n0 + (n1 + n2 * v) * v) / denominator;
    if (!(u > 0.0)) continue;
    const double q = 1.0 + v * v - 2.0 * v * cos_beta;
    if (!(q > 0.0)) continue;
    const double s1 = std::sqrt(m.b2 / q);
    Eigen::Vector3d depth(s1, u * s1, v * s1);
    auto residual_of = [&](const Eigen::Vector3d& d) {
      return Eigen::Vector3d(d[1] * d[1] + d[2] * d[2] - 2.0 * d[1] * d[2] * cos_alpha - m.a2,
                             d[0] * d[0] + d[2] * d[2] - 2.0 * d[0] * d[2] * cos_beta - m.b2,
                             d[0] * d[0] + d[1] * d[1] - 2.0 * d[0] * d[1] * cos_gamma - m.c2);
    };
    Eigen::Vector3d residual = residual_of(depth);
    for (int iteration = 0; iteration < max_newton_iterations; ++iteration) {
      Eigen::Matrix3d J;
      J << 0.0, 2.0 * (depth[1] - depth[2] * cos_alpha), 2.0 * (depth[2] - depth[1] * cos_alpha),
          2.0 * (depth[0] - depth[2] * cos_beta), 0.0, 2.0 * (depth[2] - depth[0] * cos_beta),
          2.0 * (depth[0] - depth[1] * cos_gamma), 2.0 * (depth[1] - depth[0] * cos_gamma), 0.0;
      const double determinant = J.determinant();
      if (!(std::abs(determinant) > 0.0)) break;
      const Eigen::Vector3d step = J.inverse() * residual;  // closed-form 3x3 inverse
      depth -= step;
      residual = residual_of(depth);
      if (step.norm() < 1e-12 * depth.norm()) break;
    }
    bool converged = depth.minCoeff() > 0.0;
    for (int k = 0; k < 3; ++k) {
      converged = converged && std::abs(residual[k]) < tolerance * sides2[k];
    }
    if (!converged) continue;
    bool duplicate = false;
    for (int k = 0; k < count; ++k) {
      duplicate = duplicate || (solutions[k] - depth).norm() < 1e-7 * depth.norm();
    }
    if (duplicate) continue;
    solutions[count] = depth;
    const Eigen::Vector3d P1 = depth[0] * f[0];
    const Eigen::Vector3d P2 = depth[1] * f[1];
    const Eigen::Vector3d P3 = depth[2] * f[2];
    RigidPose& pose = poses[count++];
    pose.R = TriangleFrame(P1, P2, P3) * m.frame_D.transpose();
    pose.t = P1 - pose.R * m.X[0];
  }
  return count;
}

// ---------------------------------------------------------------------------------------------
// Scoring and refinement
// ---------------------------------------------------------------------------------------------

struct Scene {
  std::vector<Eigen::Vector3d> X;  // dock lights in D
  std::vector<int> ids;
  std::vector<Eigen::Vector2d> x;  // detections, undistorted normalized coordinates
  std::vector<Eigen::Vector3d> f;  // detections, unit bearings
  double fx = 1.0, fy = 1.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // of the lights, D; z: the deck's plane
};

Eigen::Vector3d LightsCentroid(const DockModel& dock) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const DockLight& light : dock.lights) {
    centroid += light.p_D / static_cast<double>(dock.lights.size());
  }
  return centroid;
}

// The camera centre above the deck (z down, the deck's plane at the lights' mean z): at least
// min_camera_height_m, and seen from the lights' centroid at least min_view_elevation_deg above
// the deck's plane.
bool CameraAboveTheDeck(const Eigen::Vector3d& centroid, const Eigen::Vector3d& camera_D,
                        const RansacMatcherOptions& options) {
  const double height = centroid.z() - camera_D.z();
  if (!(height > options.min_camera_height_m)) return false;
  const double sin_min = std::sin(options.min_view_elevation_deg * 3.14159265358979323846 / 180.0);
  return height >= sin_min * (camera_D - centroid).norm();
}

bool CameraAboveTheDeck(const Scene& scene, const Eigen::Vector3d& camera_D,
                        const RansacMatcherOptions& options) {
  return CameraAboveTheDeck(scene.centroid, camera_D, options);
}

struct Hypothesis {
  RigidPose pose;
  std::vector<int> detection_of_light;  // -1: light not matched
  int inliers = 0;
  double squared_error = 0.0;  // pixel-equivalent, over the inliers
};

bool BetterHypothesis(const Hypothesis& a, const Hypothesis& b) {
  if (a.inliers != b.inliers) return a.inliers > b.inliers;
  return a.squared_error < b.squared_error;
}

bool PlausiblePose(const Scene& scene, const RigidPose& pose, const RansacMatcherOptions& options) {
  if (!CameraAboveTheDeck(scene, -pose.R.transpose() * pose.t, options)) return false;
  for (const Eigen::Vector3d& X : scene.X) {
    if (!(pose.R.row(2).dot(X) + pose.t.z() > options.min_depth_m)) return false;
  }
  return true;
}

// Scores a plausible pose (see PlausiblePose; false otherwise): each light claims its nearest
// detection within the gate; a detection claimed by two lights keeps the closer one. Scratch
// vectors are reused across calls.
bool ScorePose(const Scene& scene, const RigidPose& pose, const RansacMatcherOptions& options,
               std::vector<Eigen::Vector3d>* p_C, std::vector<int>* light_of_detection,
               std::vector<double>* claim_d2, Hypothesis* out) {
  if (!CameraAboveTheDeck(scene, -pose.R.transpose() * pose.t, options)) return false;
  p_C->resize(scene.X.size());
  for (size_t i = 0; i < scene.X.size(); ++i) {
    (*p_C)[i] = pose.R * scene.X[i] + pose.t;
    if (!((*p_C)[i].z() > options.min_depth_m)) return false;
  }
  const double gate2 = options.hypothesis_gate_px * options.hypothesis_gate_px;
  const size_t num_detections = scene.x.size();
  light_of_detection->assign(num_detections, -1);
  claim_d2->assign(num_detections, 0.0);
  for (size_t i = 0; i < scene.X.size(); ++i) {
    const Eigen::Vector3d& p = (*p_C)[i];
    const double inverse_z = 1.0 / p.z();
    const double px = p.x() * inverse_z, py = p.y() * inverse_z;
    int nearest = -1;
    double nearest_d2 = gate2;
    for (size_t j = 0; j < num_detections; ++j) {
      const double du = scene.fx * (px - scene.x[j].x());
      const double dv = scene.fy * (py - scene.x[j].y());
      const double d2 = du * du + dv * dv;
      if (d2 <= nearest_d2) {
        nearest_d2 = d2;
        nearest = static_cast<int>(j);
      }
    }
    if (nearest < 0) continue;
    if ((*light_of_detection)[nearest] < 0 || nearest_d2 < (*claim_d2)[nearest]) {
      (*light_of_detection)[nearest] = static_cast<int>(i);
      (*claim_d2)[nearest] = nearest_d2;
    }
  }
  out->pose = pose;
  out->detection_of_light.assign(scene.X.size(), -1);
  out->inliers = 0;
  out->squared_error = 0.0;
  for (size_t j = 0; j < num_detections; ++j) {
    const int i = (*light_of_detection)[j];
    if (i < 0) continue;
    out->detection_of_light[i] = static_cast<int>(j);
    ++out->inliers;
    out->squared_error += (*claim_d2)[j];
  }
  return true;
}

// A few distinct labellings, best first.
class HypothesisPool {
 public:
  explicit HypothesisPool(size_t capacity) : capacity_(capacity) {}

  void Offer(const Hypothesis& h) {
    for (Hypothesis& kept : kept_) {
      if (kept.detection_of_light == h.detection_of_light) {
        if (BetterHypothesis(h, kept)) {
          kept = h;
          Sort();
        }
        return;
      }
    }
    if (kept_.size() < capacity_) {
      kept_.push_back(h);
    } else if (BetterHypothesis(h, kept_.back())) {
      kept_.back() = h;
    } else {
      return;
    }
    Sort();
  }

  const std::vector<Hypothesis>& hypotheses() const { return kept_; }

 private:
  void Sort() { std::stable_sort(kept_.begin(), kept_.end(), BetterHypothesis); }

  size_t capacity_;
  std::vector<Hypothesis> kept_;
};

// RefinePoseOnCorrespondences (tracking_matcher.h) on the light -> detection pairs of a
// labelling; returns the final squared error.
double RefinePoseFrom(const Scene& scene, const std::vector<int>& detection_of_light,
                      RigidPose* pose) {
  std::vector<Eigen::Vector3d> points_D;
  std::vector<Eigen::Vector2d> points_xy;
  for (size_t i = 0; i < scene.X.size(); ++i) {
    const int j = detection_of_light[i];
    if (j < 0) continue;
    points_D.push_back(scene.X[i]);
    points_xy.push_back(scene.x[j]);
  }
  Pose3 T_C_D(Eigen::Quaterniond(pose->R), pose->t);
  const double cost = RefinePoseOnCorrespondences(points_D, points_xy, scene.fx, scene.fy, &T_C_D);
  pose->R = T_C_D.R();
  pose->t = T_C_D.p;
  return cost;
}

// The other local minimum of a planar target seen from afar: the deck tilted the other way about
// the line of sight to the matched lights' centroid (the two solutions of IPPE, Collins & Bartoli,
// "Infinitesimal plane-based pose estimation", IJCV 2014, coincide with this reflection in the
// affine limit). The normal n is reflected about the line of sight v, n' = 2 (n.v) v - n, and the
// pose rotated about the centroid by the smallest rotation taking n to n'.
RigidPose FlippedPose(const Scene& scene, const std::vector<int>& detection_of_light,
                      const RigidPose& pose) {
  Eigen::Vector3d centroid_D = Eigen::Vector3d::Zero();
  int count = 0;
  for (size_t i = 0; i < scene.X.size(); ++i) {
    if (detection_of_light[i] < 0) continue;
    centroid_D += scene.X[i];
    ++count;
  }
  centroid_D /= std::max(count, 1);
  const Eigen::Vector3d centroid_C = pose.R * centroid_D + pose.t;
  const Eigen::Vector3d v = centroid_C.normalized();
  const Eigen::Vector3d n = pose.R.col(2);
  const Eigen::Vector3d n_flipped = 2.0 * n.dot(v) * v - n;
  RigidPose flipped;
  flipped.R = Eigen::Quaterniond::FromTwoVectors(n, n_flipped).toRotationMatrix() * pose.R;
  flipped.t = centroid_C - flipped.R * centroid_D;
  return flipped;
}

// Refines from the given pose; with try_flip also from its flipped twin, keeping the better.
void RefinePose(const Scene& scene, const std::vector<int>& detection_of_light, bool try_flip,
                RigidPose* pose) {
  RigidPose flipped = FlippedPose(scene, detection_of_light, *pose);
  const double cost = RefinePoseFrom(scene, detection_of_light, pose);
  if (!try_flip) return;
  const double flipped_cost = RefinePoseFrom(scene, detection_of_light, &flipped);
  if (flipped_cost < cost) *pose = flipped;
}

// Gated Hungarian between the projected lights and the detections (pixel-equivalent distance);
// excluded detections are not used.
Hypothesis Reassign(const Scene& scene, const RigidPose& pose, double gate_px,
                    const std::vector<char>& excluded) {
  Hypothesis h;
  h.pose = pose;
  h.detection_of_light.assign(scene.X.size(), -1);
  Eigen::MatrixXd cost(scene.X.size(), scene.x.size());
  for (size_t i = 0; i < scene.X.size(); ++i) {
    const Eigen::Vector3d p = pose.R * scene.X[i] + pose.t;
    for (size_t j = 0; j < scene.x.size(); ++j) {
      if (!(p.z() > 1e-9) || excluded[j]) {
        cost(i, j) = kForbiddenCost;
        continue;
      }
      const double du = scene.fx * (p.x() / p.z() - scene.x[j].x());
      const double dv = scene.fy * (p.y() / p.z() - scene.x[j].y());
      const double d = std::sqrt(du * du + dv * dv);
      cost(i, j) = d <= gate_px ? d : kForbiddenCost;
    }
  }
  const std::vector<int> assignment = SolveAssignment(cost);
  for (size_t i = 0; i < scene.X.size(); ++i) {
    const int j = assignment[i];
    if (j < 0) continue;
    h.detection_of_light[i] = j;
    ++h.inliers;
    h.squared_error += cost(i, j) * cost(i, j);
  }
  return h;
}

// True when the hypothesis fits at the noise level (PoseFitConsistentWithNoise).
bool FitsNoise(const Hypothesis& h, const RansacMatcherOptions& options) {
  return PoseFitConsistentWithNoise(h.squared_error, h.inliers, options.pixel_noise_px,
                                    options.consistency_alpha);
}

// Levenberg-Marquardt on the inliers and re-assignment within final_gate_px until the labelling
// is stable. While the fit is worse than the noise allows: first the flipped local minimum is
// tried, then the detection whose removal alone explains the misfit is excluded (a spurious
// detection next to a predicted light drags the pose).
Hypothesis Refine(const Scene& scene, const Hypothesis& start,
                  const RansacMatcherOptions& options) {
  std::vector<char> excluded(scene.x.size(), 0);
  Hypothesis current = start;
  bool try_flip = false;
  for (int round = 0; round < 12; ++round) {
    RigidPose pose = current.pose;
    RefinePose(scene, current.detection_of_light, try_flip, &pose);
    Hypothesis next = Reassign(scene, pose, options.final_gate_px, excluded);
    const bool unchanged = next.detection_of_light == current.detection_of_light;
    current = next;
    if (!unchanged) continue;
    if (current.inliers <= 3 || FitsNoise(current, options)) break;
    if (!try_flip) {
      // Maybe the wrong one of a planar target's two local minima: try the other first.
      try_flip = true;
      continue;
    }
    // Exclude the detection whose removal leaves the best fit, if that removal alone accounts
    // for the misfit (leave-one-out outlier test, 2 degrees of freedom, same false-alarm rate);
    // a misfit spread over all matches is heavier noise than modelled, not a wrong match.
    if (current.inliers <= 4) break;
    int drop = -1;
    double best_error = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < scene.X.size(); ++i) {
      if (current.detection_of_light[i] < 0) continue;
      std::vector<int> without = current.detection_of_light;
      without[i] = -1;
      RigidPose candidate = current.pose;
      const double error = RefinePoseFrom(scene, without, &candidate);
      if (error < best_error) {
        best_error = error;
        drop = static_cast<int>(i);
      }
    }
    const double sigma2 = options.pixel_noise_px * options.pixel_noise_px;
    if ((current.squared_error - best_error) / sigma2 <
        -2.0 * std::log(options.consistency_alpha)) {
      break;
    }
    const int worst = current.detection_of_light[drop];
    excluded[worst] = 1;
    current.detection_of_light[drop] = -1;
    --current.inliers;
    current.squared_error = best_error;
  }
  return current;
}

double Rms(const Hypothesis& h) {
  return h.inliers > 0 ? std::sqrt(h.squared_error / h.inliers) : 0.0;
}

// True when the points lie within `relative_tolerance` of their principal spread from one line.
bool NearlyCollinear(const std::vector<Eigen::Vector3d>& points, double relative_tolerance) {
  if (points.size() < 3) return true;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) scatter += (p - centroid) * (p - centroid).transpose();
  const Eigen::Vector3d eigenvalues =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter, Eigen::EigenvaluesOnly)
          .eigenvalues();  // ascending
  return std::sqrt(std::max(0.0, eigenvalues(1))) <
         relative_tolerance * std::sqrt(std::max(0.0, eigenvalues(2)));
}

std::string Labels(const Scene& scene, const Hypothesis& h) {
  std::ostringstream out;
  bool first = true;
  for (size_t i = 0; i < h.detection_of_light.size(); ++i) {
    if (h.detection_of_light[i] < 0) continue;
    out << (first ? "" : " ") << "d" << h.detection_of_light[i] << "=L" << scene.ids[i];
    first = false;
  }
  return out.str();
}

// The hypothesis h with a dock symmetry applied: its labelling permuted (PermuteLabelling), the
// pose T S^-1 (the same pixels: T S^-1 p_perm(i) = T p_i).
Hypothesis ApplySymmetry(const Hypothesis& h, const DockSymmetry& s) {
  Hypothesis out = h;
  out.detection_of_light = PermuteLabelling(h.detection_of_light, s);
  out.pose.R = h.pose.R * s.R.transpose();
  out.pose.t = h.pose.t - out.pose.R * s.t;
  return out;
}

// Replaces *h by one representative of its symmetric copies (CanonicalSymmetry), so that copies
// are the same hypothesis, not rivals. Nothing to do for a dock without symmetry: this runs for
// every scored pose.
void Canonicalize(const std::vector<DockSymmetry>& symmetries, Hypothesis* h) {
  if (symmetries.size() < 2) return;
  const size_t k = CanonicalSymmetry(symmetries, h->detection_of_light);
  if (k != 0) *h = ApplySymmetry(*h, symmetries[k]);
}

// Spread off the best line below this fraction of the spread along it: collinear.
constexpr double kCollinearTolerance = 0.05;

// Which of a symmetric dock's equally good poses to report (see SymmetryHint): the index into
// copies, and in *note how it was chosen.
size_t ChooseSymmetricCopy(const std::vector<Pose3>& copies, const DockModel& dock,
                           const std::vector<DockSymmetry>& symmetries, const SymmetryHint& hint,
                           std::string* note, bool* unresolved, bool* by_prediction) {
  *unresolved = false;
  *by_prediction = false;
  constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
  // Angular error (rad) of every copy against the hint; the smallest wins when the next is at
  // least twice as far (a prediction or gravity a few degrees off, copies tens of degrees apart).
  auto pick = [&](const std::vector<double>& error, const char* by) -> std::optional<size_t> {
    std::vector<size_t> order(error.size());
    for (size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return error[a] < error[b]; });
    std::ostringstream s;
    s.precision(3);
    if (order.size() < 2 || error[order[1]] >= 2.0 * error[order[0]] + 1e-9) {
      s << "chosen by " << by << " (" << error[order[0]] * kRadToDeg << " deg off, next "
        << (order.size() > 1 ? error[order[1]] * kRadToDeg : 0.0) << " deg)";
      *note = s.str();
      return order[0];
    }
    return std::nullopt;
  };
  if (hint.predicted_T_C_D) {
    std::vector<double> error;
    for (const Pose3& c : copies) error.push_back(c.q.angularDistance(hint.predicted_T_C_D->q));
    if (auto k = pick(error, "the prediction")) {
      *by_prediction = true;
      return *k;
    }
  }
  if (hint.gravity_C && hint.gravity_C->norm() > 0.0 && dock.gravity_D.norm() > 0.0) {
    const Eigen::Vector3d g_C = hint.gravity_C->normalized();
    std::vector<double> error;
    for (const Pose3& c : copies) {
      const double cosine = std::clamp((c.R() * dock.gravity_D.normalized()).dot(g_C), -1.0, 1.0);
      error.push_back(std::acos(cosine));
    }
    if (auto k = pick(error, "gravity")) return *k;
  }
  if (hint.fix_p_D && hint.fix_sigma_m > 0.0) {
    // Distances (m) of the fixed point, placed by each copy, from the fix.
    std::vector<double> distance;
    for (const Pose3& c : copies) distance.push_back((c.Inverse() * hint.T_C_S.p - *hint.fix_p_D).norm());
    const double nearest = *std::min_element(distance.begin(), distance.end());
    const double gate = hint.fix_gate_sigmas * hint.fix_sigma_m +
                        hint.fix_range_fraction * copies[0].p.norm();
    if (nearest <= gate) {
      std::vector<size_t> order(distance.size());
      for (size_t k = 0; k < order.size(); ++k) order[k] = k;
      std::sort(order.begin(), order.end(),
                [&](size_t a, size_t b) { return distance[a] < distance[b]; });
      // The next copy must be twice as far and outside the gate itself.
      if (distance[order[1]] >= 2.0 * distance[order[0]] && distance[order[1]] > gate) {
        std::ostringstream s;
        s.precision(3);
        s << "chosen by the acoustic fix (" << distance[order[0]] << " m off, next "
          << distance[order[1]] << " m, sigma " << hint.fix_sigma_m << " m)";
        *note = s.str();
        return order[0];
      }
    }
  }
  if (hint.approach_direction_D && hint.approach_direction_D->norm() > 0.0) {
    // The copies' camera centres differ by turns about the symmetry axis (through the lights'
    // centroid): compare their bearings about that axis with the approach direction's.
    const Eigen::Vector3d axis = symmetries[1].axis_D;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const DockLight& l : dock.lights) centroid += l.p_D / dock.lights.size();
    auto across = [&](const Eigen::Vector3d& v) { return Eigen::Vector3d(v - v.dot(axis) * axis); };
    const Eigen::Vector3d a = across(*hint.approach_direction_D);
    std::vector<double> error;
    for (const Pose3& c : copies) {
      const Eigen::Vector3d b = across(-(c.R().transpose() * c.p) - centroid);
      const double norms = a.norm() * b.norm();
      error.push_back(norms > 1e-9 ? std::acos(std::clamp(a.dot(b) / norms, -1.0, 1.0)) : 0.0);
    }
    if (auto k = pick(error, "the approach side")) return *k;
  }
  *note = "unresolved: no prediction, gravity, acoustic fix or approach side tells the copies "
          "apart; the labels are defined up to the symmetry (the rival poses are listed)";
  *unresolved = true;
  return 0;
}

struct DetectionTriple {
  std::array<int, 3> index{};
  double priority = 0.0;  // area (px^2) times the detection scores
  int orientation = 0;
};

}  // namespace

bool CameraAboveTheDeck(const DockModel& dock, const Pose3& T_C_D,
                        const RansacMatcherOptions& options) {
  if (dock.lights.empty()) return false;
  return CameraAboveTheDeck(LightsCentroid(dock), T_C_D.Inverse().p, options);
}

std::vector<Pose3> SolveP3P(const std::array<Eigen::Vector3d, 3>& bearings_C,
                            const std::array<Eigen::Vector3d, 3>& points_D) {
  std::array<Eigen::Vector3d, 3> f;
  for (int i = 0; i < 3; ++i) f[i] = bearings_C[i].normalized();
  const ModelTriangle model = MakeModelTriangle(points_D);
  RigidPose poses[4];
  const int count = SolveP3PCore(f, model, 10, 1e-10, poses);
  std::vector<Pose3> result;
  for (int i = 0; i < count; ++i) {
    result.emplace_back(Eigen::Quaterniond(poses[i].R), poses[i].t);
  }
  return result;
}

RansacMatchResult MatchRansac(const std::vector<LightDetection>& detections, const DockModel& dock,
                              const PinholeRadtanCamera& camera,
                              const RansacMatcherOptions& options, std::mt19937_64& rng) {
  return MatchRansac(detections, dock, camera, options, rng, SymmetryHint{});
}

RansacMatchResult MatchRansac(const std::vector<LightDetection>& detections, const DockModel& dock,
                              const PinholeRadtanCamera& camera,
                              const RansacMatcherOptions& options, std::mt19937_64& rng,
                              const SymmetryHint& hint) {
  RansacMatchResult result;
  result.status = MatchStatus::kFailed;
  const int num_lights = static_cast<int>(dock.lights.size());
  const int num_detections = static_cast<int>(detections.size());
  if (num_lights < 3) {
    result.reason = "the dock has fewer than 3 lights";
    return result;
  }
  if (dock.LightsCollinear()) {
    result.status = MatchStatus::kAmbiguous;
    result.reason =
        "the dock's lights are collinear: no unique pose, and the order along the line can "
        "reverse";
    return result;
  }
  if (num_detections < std::max(3, options.min_inliers)) {
    result.reason = "only " + std::to_string(num_detections) + " detections";
    return result;
  }

  const std::vector<DockSymmetry> symmetries =
      FindDockSymmetries(dock, options.symmetry_tolerance_m);
  Scene scene;
  scene.fx = camera.fx();
  scene.fy = camera.fy();
  for (const DockLight& light : dock.lights) {
    scene.X.push_back(light.p_D);
    scene.ids.push_back(light.id);
  }
  scene.centroid = LightsCentroid(dock);
  bool planar = true;
  for (const Eigen::Vector3d& X : scene.X) planar = planar && std::abs(X.z() - scene.centroid.z()) < 1e-6;
  for (const LightDetection& detection : detections) {
    const Eigen::Vector2d x = camera.Unproject(detection.uv);
    scene.x.push_back(x);
    scene.f.push_back(Eigen::Vector3d(x.x(), x.y(), 1.0).normalized());
  }

  // Ordered, non-collinear light triples, split by orientation.
  double extent2 = 0.0;
  for (const auto& a : scene.X) {
    for (const auto& b : scene.X) extent2 = std::max(extent2, (a - b).squaredNorm());
  }
  std::vector<ModelTriangle> triangles_by_orientation[2];  // [0]: negative or any, [1]: positive
  for (int a = 0; a < num_lights; ++a) {
    for (int b = 0; b < num_lights; ++b) {
      for (int c = 0; c < num_lights; ++c) {
        if (a == b || b == c || a == c) continue;
        const Eigen::Vector3d normal = (scene.X[b] - scene.X[a]).cross(scene.X[c] - scene.X[a]);
        // Twice the area against the square of the layout's extent: skip degenerate triples.
        if (normal.norm() < 1e-3 * extent2) continue;
        ModelTriangle m = MakeModelTriangle({scene.X[a], scene.X[b], scene.X[c]});
        m.light = {a, b, c};
        triangles_by_orientation[planar && m.orientation > 0 ? 1 : 0].push_back(m);
      }
    }
  }

  // Well-spread detection triples, most promising first: area (a well-conditioned P3P) times the
  // product of the detection scores (likely lights; scores all zero count as equal). The order
  // only changes how soon the enumeration can stop, never which labelling is chosen.
  bool any_score = false;
  for (const LightDetection& detection : detections) any_score = any_score || detection.score > 0.0;
  std::vector<double> weight(num_detections, 1.0);
  if (any_score) {
    for (int i = 0; i < num_detections; ++i) {
      weight[i] = std::clamp(detections[i].score, 0.05, 1.0);
    }
  }
  std::vector<DetectionTriple> triples;
  for (int i = 0; i < num_detections; ++i) {
    for (int j = i + 1; j < num_detections; ++j) {
      for (int k = j + 1; k < num_detections; ++k) {
        const Eigen::Vector2d e1(scene.fx * (scene.x[j] - scene.x[i]).x(),
                                 scene.fy * (scene.x[j] - scene.x[i]).y());
        const Eigen::Vector2d e2(scene.fx * (scene.x[k] - scene.x[i]).x(),
                                 scene.fy * (scene.x[k] - scene.x[i]).y());
        const Eigen::Vector2d e3 = e2 - e1;
        const double cross = e1.x() * e2.y() - e1.y() * e2.x();
        const double longest =
            std::sqrt(std::max({e1.squaredNorm(), e2.squaredNorm(), e3.squaredNorm()}));
        if (!(std::abs(cross) / longest >= options.min_triangle_height_px)) continue;
        triples.push_back({{i, j, k},
                           0.5 * std::abs(cross) * weight[i] * weight[j] * weight[k],
                           cross > 0 ? 1 : -1});
      }
    }
  }
  if (static_cast<int>(triples.size()) > options.max_detection_triples) {
    std::shuffle(triples.begin(), triples.end(), rng);
    triples.resize(options.max_detection_triples);
  }
  std::sort(triples.begin(), triples.end(), [](const DetectionTriple& a, const DetectionTriple& b) {
    return a.priority > b.priority;
  });

  // Hypothesise and verify. A labelling with k >= 4 inlier detections is generated from any of
  // its well-spread detection triples, so it is enough to try, in priority order, triples until
  // every 4-subset of the detections contains a tried one (a greedy covering: about half of the
  // triples for 6 detections, a third for 8).
  const int explain_all = std::min(num_lights, num_detections);
  const int pool_threshold = std::min(options.min_inliers, 4);
  const bool use_cover = num_detections >= 4 && num_detections <= 16;
  std::vector<char> covered(use_cover ? (size_t{1} << num_detections) : 0, 0);
  HypothesisPool pool(static_cast<size_t>(std::max(2, options.max_refined_hypotheses + 2)));
  std::vector<Eigen::Vector3d> p_C;
  std::vector<int> light_of_detection;
  std::vector<double> claim_d2;
  Hypothesis scored;
  int best_inliers = 0;
  RigidPose poses[4];
  for (const DetectionTriple& triple : triples) {
    if (use_cover) {
      const uint32_t mask =
          (1u << triple.index[0]) | (1u << triple.index[1]) | (1u << triple.index[2]);
      bool needed = false;
      for (int l = 0; l < num_detections; ++l) {
        const uint32_t four = mask | (1u << l);
        if (four != mask && !covered[four]) {
          needed = true;
          covered[four] = 1;
        }
      }
      if (!needed) continue;
    }
    ++result.num_triples;
    const std::array<Eigen::Vector3d, 3> f = {scene.f[triple.index[0]], scene.f[triple.index[1]],
                                              scene.f[triple.index[2]]};
    const auto& candidates = planar ? triangles_by_orientation[triple.orientation > 0 ? 1 : 0]
                                    : triangles_by_orientation[0];
    for (const ModelTriangle& model : candidates) {
      ++result.num_p3p;
      // Hypotheses need ~1e-4 relative depths only (millimetres); two Newton steps suffice.
      const int num_poses = SolveP3PCore(f, model, 2, 1e-6, poses);
      for (int p = 0; p < num_poses; ++p) {
        if (!ScorePose(scene, poses[p], options, &p_C, &light_of_detection, &claim_d2, &scored)) {
          continue;
        }
        ++result.num_poses;
        best_inliers = std::max(best_inliers, scored.inliers);
        if (scored.inliers < pool_threshold) continue;
        Canonicalize(symmetries, &scored);
        pool.Offer(scored);
      }
    }
    if (best_inliers >= explain_all) break;
  }

  // Refine the best distinct labellings and rank them again.
  std::vector<Hypothesis> refined;
  const auto& kept = pool.hypotheses();
  for (size_t h = 0; h < kept.size() && static_cast<int>(h) < options.max_refined_hypotheses; ++h) {
    if (kept[h].inliers < kept.front().inliers - 1) break;
    Hypothesis r = Refine(scene, kept[h], options);
    Canonicalize(symmetries, &r);
    if (!PlausiblePose(scene, r.pose, options)) continue;
    bool duplicate = false;
    for (Hypothesis& other : refined) {
      if (other.detection_of_light == r.detection_of_light) {
        if (BetterHypothesis(r, other)) other = r;
        duplicate = true;
      }
    }
    if (!duplicate) refined.push_back(r);
  }
  std::stable_sort(refined.begin(), refined.end(), BetterHypothesis);

  if (refined.empty() || refined.front().inliers < options.min_inliers) {
    result.num_inliers = refined.empty() ? std::min(best_inliers, 3) : refined.front().inliers;
    result.reason = "no pose explains more than " + std::to_string(result.num_inliers) +
                    " detections (need " + std::to_string(options.min_inliers) + ")";
    return result;
  }
  const Hypothesis& best = refined.front();
  result.num_inliers = best.inliers;
  result.cost = Rms(best);
  const double sigma2 = options.pixel_noise_px * options.pixel_noise_px;
  for (size_t r = 1; r < refined.size(); ++r) {
    const Hypothesis& rival = refined[r];
    if (rival.inliers != best.inliers) break;
    if (!PoseFitConsistentWithNoise(rival.squared_error, rival.inliers, options.pixel_noise_px,
                                    options.acceptance_alpha)) {
      continue;  // not an explanation of the image
    }
    if (rival.squared_error - best.squared_error < options.ambiguity_chi2 * sigma2) {
      std::ostringstream reason;
      reason.precision(3);
      reason << "two labellings explain " << best.inliers << " detections: {" << Labels(scene, best)
             << "} (rms " << Rms(best) << " px) and {" << Labels(scene, rival) << "} (rms "
             << Rms(rival) << " px)";
      result.status = MatchStatus::kAmbiguous;
      result.reason = reason.str();
      return result;
    }
  }
  // The inlier lights must span the plane, and keep doing so without any single one of them:
  // otherwise one detection (the "keystone" off the line of the others) alone fixes the rotation
  // about that line and its own label, and a random spurious detection does that at a rate of a
  // few percent.
  std::vector<Eigen::Vector3d> inlier_points;
  for (size_t i = 0; i < scene.X.size(); ++i) {
    if (best.detection_of_light[i] >= 0) inlier_points.push_back(scene.X[i]);
  }
  if (NearlyCollinear(inlier_points, kCollinearTolerance)) {
    result.status = MatchStatus::kAmbiguous;
    result.reason = "the matched lights are collinear: the pose about their line is unobservable";
    return result;
  }
  if (options.require_redundant_support || best.inliers < num_detections) {
    for (size_t k = 0; k < inlier_points.size(); ++k) {
      std::vector<Eigen::Vector3d> others;
      for (size_t i = 0; i < inlier_points.size(); ++i) {
        if (i != k) others.push_back(inlier_points[i]);
      }
      if (NearlyCollinear(others, kCollinearTolerance)) {
        result.status = MatchStatus::kAmbiguous;
        result.reason =
            "all matched lights but one are collinear: a single detection fixes the rotation "
            "about their line and its own label";
        return result;
      }
    }
  }
  if (!PoseFitConsistentWithNoise(best.squared_error, best.inliers, options.pixel_noise_px,
                                  options.acceptance_alpha)) {
    std::ostringstream reason;
    reason.precision(3);
    reason << "the best pose leaves an rms of " << Rms(best) << " px, more than "
           << options.pixel_noise_px << " px noise explains";
    result.reason = reason.str();
    return result;
  }

  // Final labels at the refined pose, with the tracking matcher's ambiguity checks.
  // Of a planar target's two local minima, report the better pose.
  RigidPose best_pose = best.pose;
  RefinePose(scene, best.detection_of_light, /*try_flip=*/true, &best_pose);
  Pose3 T_C_D(Eigen::Quaterniond(best_pose.R), best_pose.t);
  if (symmetries.size() > 1) {
    std::vector<Pose3> copies;
    for (const DockSymmetry& s : symmetries) {
      const Eigen::Matrix3d R = best_pose.R * s.R.transpose();
      copies.emplace_back(Eigen::Quaterniond(R), best_pose.t - R * s.t);
    }
    const size_t chosen = ChooseSymmetricCopy(copies, dock, symmetries, hint, &result.symmetry,
                                             &result.symmetry_unresolved,
                                             &result.symmetry_by_prediction);
    result.symmetry = DescribeDockSymmetries(symmetries) + " symmetric dock: " + result.symmetry;
    T_C_D = copies[chosen];
    for (size_t k = 0; k < copies.size(); ++k) {
      if (k != chosen) result.symmetric_T_C_D.push_back(copies[k]);
    }
  }
  TrackingMatcherOptions tracking;
  tracking.gate_px = options.final_gate_px;
  tracking.min_residual_gate_px = options.final_gate_px;
  tracking.residual_fraction_of_gate = 1.0;
  tracking.final_gate_px = options.final_gate_px;
  tracking.pixel_noise_px = options.pixel_noise_px;
  tracking.consistency_alpha = options.consistency_alpha;
  tracking.acceptance_alpha = options.acceptance_alpha;
  tracking.ambiguity_margin_px = options.ambiguity_margin_px;
  tracking.min_matches = options.min_inliers;
  tracking.min_depth_m = options.min_depth_m;
  const MatchResult labels = MatchByPrediction(detections, dock, camera, T_C_D, tracking);
  if (labels.status != MatchStatus::kOk) {
    result.status = labels.status;
    result.reason = "at the verified pose: " + labels.reason;
    return result;
  }
  result.status = MatchStatus::kOk;
  result.matches = labels.matches;
  result.cost = labels.cost;
  result.num_inliers = static_cast<int>(labels.matches.size());
  result.T_C_D = T_C_D;
  result.reason.clear();
  return result;
}

}  // namespace auvdock
