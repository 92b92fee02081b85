#include "auvdock/vision/pnp_solver.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <sstream>

#include <Eigen/Dense>

#include "auvdock/geometry/so3.h"
#include "auvdock/vision/point_set_alignment.h"

namespace auvdock {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// Shape of the model points from the singular values s1 >= s2 >= s3 of the centred points:
// collinear below s2/s1 = 1e-6 (the rotation about the line is then set by round-off);
// the homography start is tried up to a thickness s3/s1 of 0.1 (it fits the best plane, a good
// enough start for LM at that thickness), EPnP from 1e-4 (below, its control-point basis is
// singular).
constexpr double kCollinearTolerance = 1e-6;
constexpr double kHomographyMaxThickness = 0.1;
constexpr double kEpnpMinThickness = 1e-4;
// Smallest eigenvalue of the Jacobi-scaled normal matrix J^T J, relative to the largest, below
// which the pose is not observable from these points (e.g. P3P on the "danger cylinder").
constexpr double kSingularTolerance = 1e-12;
// Few points make EPnP and the homography fragile, so every P3P triple is tried as well (at
// most 10 triples, 40 poses), and the best few by reprojection error are refined.
constexpr int kMaxPointsForP3pStarts = 5;
constexpr size_t kP3pStartsKept = 3;
// Marquardt damping at the start, relative to the diagonal of J^T J: the starts are close.
constexpr double kInitialDamping = 1e-4;
constexpr double kPi = 3.14159265358979323846;

struct Rigid {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
};

PnpResult Fail(const std::string& reason) {
  PnpResult result;
  result.reason = reason;
  return result;
}

// Pixel of x_C through the full camera model and, if J_uv_p is given, d pixel / d x_C.
Eigen::Vector2d ProjectWithJacobian(const PinholeRadtanCamera& camera, const Eigen::Vector3d& p,
                                    Eigen::Matrix<double, 2, 3>* J_uv_p) {
  const double inv_z = 1.0 / p.z();
  const double x = p.x() * inv_z;
  const double y = p.y() * inv_z;
  const std::array<double, 5>& d = camera.distortion();
  double xd, yd;
  DistortNormalized(d, x, y, &xd, &yd);
  if (J_uv_p != nullptr) {
    // radial = 1 + k1 r2 + k2 r2^2 + k3 r2^3, d radial / d r2, and d r2 / dx = 2x.
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
    const double dradial = d[0] + r2 * (2.0 * d[1] + 3.0 * d[4] * r2);
    const double cross = 2.0 * x * y * dradial + 2.0 * d[2] * x + 2.0 * d[3] * y;
    Eigen::Matrix2d J_d;
    J_d << radial + 2.0 * x * x * dradial + 2.0 * d[2] * y + 6.0 * d[3] * x, cross,  //
        cross, radial + 2.0 * y * y * dradial + 6.0 * d[2] * y + 2.0 * d[3] * x;
    Eigen::Matrix<double, 2, 3> J_xy_p;
    J_xy_p << inv_z, 0.0, -x * inv_z,  //
        0.0, inv_z, -y * inv_z;
    J_d.row(0) *= camera.fx();
    J_d.row(1) *= camera.fy();
    *J_uv_p = J_d * J_xy_p;
  }
  return Eigen::Vector2d(camera.fx() * xd + camera.cx(), camera.fy() * yd + camera.cy());
}

struct Problem {
  const std::vector<Eigen::Vector3d>& X;
  const std::vector<Eigen::Vector2d>& uv;
  const PinholeRadtanCamera& camera;
  // W_i = L_i^-1 with Sigma_i = L_i L_i^T, the pixel's covariance: r_i = W_i (pi(...) - u_i) is
  // whitened, so that 1/2 |r|^2 is half the chi-square of the pixels.
  const std::vector<Eigen::Matrix2d>& whiten;
};

// Whitened residuals r (2n) and J = dr / d(dtheta, dt) for the left perturbation; the squared
// pixel error sum_i |pi(...) - u_i|^2 in *pixel_squared_norm if given. Returns false (and leaves
// r, J unspecified) if a point is not in front of the camera.
bool Evaluate(const Problem& problem, const Rigid& T, Eigen::VectorXd* r, Eigen::MatrixXd* J,
              double* pixel_squared_norm = nullptr) {
  const int n = static_cast<int>(problem.X.size());
  r->resize(2 * n);
  if (J != nullptr) J->resize(2 * n, 6);
  if (pixel_squared_norm != nullptr) *pixel_squared_norm = 0.0;
  bool in_front = true;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d RX = T.R * problem.X[i];
    const Eigen::Vector3d p = RX + T.t;
    if (!(p.z() > 0.0)) in_front = false;
    Eigen::Matrix<double, 2, 3> J_uv_p;
    const Eigen::Vector2d error =
        ProjectWithJacobian(problem.camera, p, J != nullptr ? &J_uv_p : nullptr) - problem.uv[i];
    if (pixel_squared_norm != nullptr) *pixel_squared_norm += error.squaredNorm();
    const Eigen::Matrix2d& W = problem.whiten[i];
    r->segment<2>(2 * i) = W * error;
    if (J != nullptr) {
      J->block<2, 3>(2 * i, 0) = -W * J_uv_p * Hat(RX);
      J->block<2, 3>(2 * i, 3) = W * J_uv_p;
    }
  }
  return in_front && r->allFinite();
}

struct Refined {
  Rigid T;
  bool converged = false;
  bool in_front = false;
  double cost = std::numeric_limits<double>::infinity();  // 1/2 sum |r|^2, r whitened
  int iterations = 0;
};

// Levenberg-Marquardt from `start` (see the header). A step that moves a point behind the
// camera is rejected like a step that raises the cost.
Refined Refine(const Problem& problem, const Rigid& start, const PnpOptions& options) {
  Refined out;
  out.T = start;
  Eigen::VectorXd r, r_new;
  Eigen::MatrixXd J;
  out.in_front = Evaluate(problem, out.T, &r, &J);
  if (!r.allFinite()) return out;
  out.cost = 0.5 * r.squaredNorm();
  double lambda = kInitialDamping;
  double nu = 2.0;
  Matrix6d A = J.transpose() * J;
  Vector6d g = J.transpose() * r;
  const double g0 = g.cwiseAbs().maxCoeff();
  while (true) {
    if (g.cwiseAbs().maxCoeff() <= options.gradient_tolerance * g0) {
      out.converged = true;
      break;
    }
    if (out.iterations >= options.max_iterations) break;
    ++out.iterations;

    Matrix6d damped = A;
    damped.diagonal() += lambda * A.diagonal().cwiseMax(1e-12 * A.diagonal().maxCoeff());
    const Vector6d delta = damped.ldlt().solve(-g);
    if (!delta.allFinite()) {
      lambda *= nu;
      nu *= 2.0;
      continue;
    }
    const double x_norm = std::sqrt(LogSO3(out.T.R).squaredNorm() + out.T.t.squaredNorm());
    if (delta.norm() <= options.step_tolerance * (x_norm + options.step_tolerance)) {
      out.converged = true;
      break;
    }
    Rigid candidate;
    candidate.R = ExpSO3(delta.head<3>()) * out.T.R;
    candidate.t = out.T.t + delta.tail<3>();
    const bool in_front = Evaluate(problem, candidate, &r_new, nullptr);
    const double cost_new =
        r_new.allFinite() ? 0.5 * r_new.squaredNorm() : std::numeric_limits<double>::infinity();
    if ((in_front || !out.in_front) && cost_new < out.cost) {
      const double predicted = -delta.dot(g) - 0.5 * delta.dot(A * delta);
      const double rho = predicted > 0.0 ? (out.cost - cost_new) / predicted : 0.0;
      lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      nu = 2.0;
      const bool small_decrease = out.cost - cost_new <= options.function_tolerance * out.cost;
      out.T = candidate;
      out.cost = cost_new;
      out.in_front = Evaluate(problem, out.T, &r, &J);
      A = J.transpose() * J;
      g = J.transpose() * r;
      if (small_decrease) {
        out.converged = true;
        break;
      }
    } else {
      lambda *= nu;
      nu *= 2.0;
    }
  }
  return out;
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& M) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d d(1.0, 1.0, 1.0);
  d(2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * d.asDiagonal() * svd.matrixV().transpose();
}

// Similarity that moves 2-D points to zero mean and mean distance sqrt(2) (Hartley).
Eigen::Matrix3d NormalizingTransform(const std::vector<Eigen::Vector2d>& points) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  double distance = 0.0;
  for (const Eigen::Vector2d& p : points) distance += (p - mean).norm();
  distance /= static_cast<double>(points.size());
  const double s = distance > 0.0 ? std::sqrt(2.0) / distance : 1.0;
  Eigen::Matrix3d T;
  T << s, 0.0, -s * mean.x(), 0.0, s, -s * mean.y(), 0.0, 0.0, 1.0;
  return T;
}

// Start for (nearly) coplanar points. Plane frame P: origin at the centroid c, axes B = [e1 e2
// e3] (columns, det +1, e3 the normal), plane coordinates (a, b) = (e1, e2)^T (X - c). The
// homography from (a, b, 1) to normalized (x, y, 1) is lambda [r1 r2 t_P] of R_CP = R_CD B.
std::optional<Rigid> HomographyStart(const std::vector<Eigen::Vector3d>& X,
                                     const std::vector<Eigen::Vector2d>& xy,
                                     const Eigen::Vector3d& c, const Eigen::Matrix3d& B) {
  const int n = static_cast<int>(X.size());
  std::vector<Eigen::Vector2d> ab(n);
  for (int i = 0; i < n; ++i) ab[i] = (B.leftCols<2>().transpose() * (X[i] - c));
  const Eigen::Matrix3d T_src = NormalizingTransform(ab);
  const Eigen::Matrix3d T_img = NormalizingTransform(xy);
  Eigen::MatrixXd A(2 * n, 9);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d s = T_src * ab[i].homogeneous();
    const Eigen::Vector3d m = T_img * xy[i].homogeneous();
    A.row(2 * i) << -s.x(), -s.y(), -1.0, 0.0, 0.0, 0.0, m.x() * s.x(), m.x() * s.y(), m.x();
    A.row(2 * i + 1) << 0.0, 0.0, 0.0, -s.x(), -s.y(), -1.0, m.y() * s.x(), m.y() * s.y(), m.y();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::Matrix<double, 9, 1> h = svd.matrixV().col(8);
  Eigen::Matrix3d H_normalized;
  H_normalized << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  const Eigen::Matrix3d H = T_img.inverse() * H_normalized * T_src;
  const double norm12 = H.col(0).norm() + H.col(1).norm();
  if (!(norm12 > 0.0) || !H.allFinite()) return std::nullopt;
  double scale = 2.0 / norm12;
  if (H(2, 2) * scale < 0.0) scale = -scale;  // the centroid (a, b) = 0 lies in front
  const Eigen::Vector3d r1 = scale * H.col(0);
  const Eigen::Vector3d r2 = scale * H.col(1);
  Eigen::Matrix3d M;
  M << r1, r2, r1.cross(r2);
  Rigid T;
  T.R = NearestRotation(M) * B.transpose();
  T.t = scale * H.col(2) - T.R * c;
  if (!T.R.allFinite() || !T.t.allFinite()) return std::nullopt;
  return T;
}

// Sum of squared normalized-coordinate reprojection errors; infinity if a point is behind.
double NormalizedError(const Rigid& T, const std::vector<Eigen::Vector3d>& X,
                       const std::vector<Eigen::Vector2d>& xy) {
  double sum = 0.0;
  for (size_t i = 0; i < X.size(); ++i) {
    const Eigen::Vector3d p = T.R * X[i] + T.t;
    if (!(p.z() > 0.0)) return std::numeric_limits<double>::infinity();
    sum += (p.head<2>() / p.z() - xy[i]).squaredNorm();
  }
  return std::isfinite(sum) ? sum : std::numeric_limits<double>::infinity();
}

// Index of the monomial beta_k beta_l (k <= l) in the 10-vector of EPnP's L matrix.
int MonomialIndex(int k, int l) {
  static constexpr int kIndex[4][4] = {{0, 1, 3, 6}, {1, 2, 4, 7}, {3, 4, 5, 8}, {6, 7, 8, 9}};
  return kIndex[k][l];
}

// EPnP start for non-coplanar points. Control points: the centroid c and c + s_k e_k along
// the principal axes (s_k the RMS spread). Each point is X = sum_j alpha_j c_j; the camera
// control points are sum_k beta_k v_k over the 4 smallest eigenvectors v_k of M^T M, and the
// betas come from the 6 inter-control-point distances (L beta_monomials = rho).
std::optional<Rigid> EpnpStart(const std::vector<Eigen::Vector3d>& X,
                               const std::vector<Eigen::Vector2d>& xy, const Eigen::Vector3d& c,
                               const Eigen::Matrix3d& B, const Eigen::Vector3d& spread) {
  const int n = static_cast<int>(X.size());
  std::array<Eigen::Vector3d, 4> control_D;
  control_D[0] = c;
  for (int k = 0; k < 3; ++k) control_D[k + 1] = c + spread(k) * B.col(k);
  std::vector<Eigen::Vector4d> alpha(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d a = (B.transpose() * (X[i] - c)).cwiseQuotient(spread);
    alpha[i] << 1.0 - a.sum(), a;
  }
  Eigen::Matrix<double, 12, 12> MtM = Eigen::Matrix<double, 12, 12>::Zero();
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<double, 2, 12> rows = Eigen::Matrix<double, 2, 12>::Zero();
    for (int j = 0; j < 4; ++j) {
      rows(0, 3 * j) = alpha[i](j);
      rows(0, 3 * j + 2) = -alpha[i](j) * xy[i].x();
      rows(1, 3 * j + 1) = alpha[i](j);
      rows(1, 3 * j + 2) = -alpha[i](j) * xy[i].y();
    }
    MtM += rows.transpose() * rows;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 12, 12>> eigen(MtM);
  if (eigen.info() != Eigen::Success) return std::nullopt;
  const Eigen::Matrix<double, 12, 4> V = eigen.eigenvectors().leftCols<4>();  // ascending

  static constexpr int kPairs[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  Eigen::Matrix<double, 6, 10> L;
  Eigen::Matrix<double, 6, 1> rho;
  for (int p = 0; p < 6; ++p) {
    const int a = kPairs[p][0], b = kPairs[p][1];
    std::array<Eigen::Vector3d, 4> dv;
    for (int k = 0; k < 4; ++k) dv[k] = V.col(k).segment<3>(3 * a) - V.col(k).segment<3>(3 * b);
    for (int k = 0; k < 4; ++k) {
      for (int l = k; l < 4; ++l)
        L(p, MonomialIndex(k, l)) = (k == l ? 1.0 : 2.0) * dv[k].dot(dv[l]);
    }
    rho(p) = (control_D[a] - control_D[b]).squaredNorm();
  }

  auto solve_columns = [&](const std::vector<int>& columns) {
    Eigen::MatrixXd Lsub(6, columns.size());
    for (size_t k = 0; k < columns.size(); ++k) Lsub.col(k) = L.col(columns[k]);
    return Eigen::VectorXd(Lsub.colPivHouseholderQr().solve(rho));
  };
  std::vector<Eigen::Vector4d> beta_sets;
  {  // N = 4, approximated by the monomials beta_0 beta_k.
    const Eigen::VectorXd s = solve_columns({0, 1, 3, 6});
    Eigen::Vector4d beta = Eigen::Vector4d::Zero();
    if (s(0) != 0.0) {
      const double b0 = std::sqrt(std::abs(s(0)));
      const double sign = s(0) < 0.0 ? -1.0 : 1.0;
      beta << b0, sign * s(1) / b0, sign * s(2) / b0, sign * s(3) / b0;
    }
    beta_sets.push_back(beta);
  }
  {  // N = 2.
    const Eigen::VectorXd s = solve_columns({0, 1, 2});
    Eigen::Vector4d beta = Eigen::Vector4d::Zero();
    beta(0) = std::sqrt(std::abs(s(0)));
    beta(1) = (s(0) < 0.0) == (s(2) < 0.0) ? std::sqrt(std::abs(s(2))) : 0.0;
    if (s(1) * (s(0) < 0.0 ? -1.0 : 1.0) < 0.0) beta(1) = -beta(1);
    beta_sets.push_back(beta);
  }
  {  // N = 3.
    const Eigen::VectorXd s = solve_columns({0, 1, 2, 3, 4});
    Eigen::Vector4d beta = Eigen::Vector4d::Zero();
    beta(0) = std::sqrt(std::abs(s(0)));
    beta(1) = (s(0) < 0.0) == (s(2) < 0.0) ? std::sqrt(std::abs(s(2))) : 0.0;
    if (s(1) * (s(0) < 0.0 ? -1.0 : 1.0) < 0.0) beta(1) = -beta(1);
    if (beta(0) != 0.0) beta(2) = s(3) / beta(0) * (s(0) < 0.0 ? -1.0 : 1.0);
    beta_sets.push_back(beta);
  }

  std::optional<Rigid> best;
  double best_error = std::numeric_limits<double>::infinity();
  for (Eigen::Vector4d beta : beta_sets) {
    // Gauss-Newton on the 6 distance equations in the 4 betas.
    for (int iteration = 0; iteration < 5; ++iteration) {
      Eigen::Matrix<double, 6, 4> J_e = Eigen::Matrix<double, 6, 4>::Zero();
      Eigen::Matrix<double, 6, 1> e = -rho;
      for (int k = 0; k < 4; ++k) {
        for (int l = k; l < 4; ++l) {
          const Eigen::Matrix<double, 6, 1> column = L.col(MonomialIndex(k, l));
          e += column * beta(k) * beta(l);
          J_e.col(k) += column * beta(l);
          J_e.col(l) += column * beta(k);
        }
      }
      const Eigen::Vector4d step = J_e.colPivHouseholderQr().solve(-e);
      if (!step.allFinite()) break;
      beta += step;
    }
    std::array<Eigen::Vector3d, 4> control_C;
    for (int j = 0; j < 4; ++j) {
      control_C[j] = Eigen::Vector3d::Zero();
      for (int k = 0; k < 4; ++k) control_C[j] += beta(k) * V.col(k).segment<3>(3 * j);
    }
    std::vector<Eigen::Vector3d> X_C(n);
    double mean_z = 0.0;
    for (int i = 0; i < n; ++i) {
      X_C[i] = Eigen::Vector3d::Zero();
      for (int j = 0; j < 4; ++j) X_C[i] += alpha[i](j) * control_C[j];
      mean_z += X_C[i].z();
    }
    if (mean_z < 0.0) {
      for (Eigen::Vector3d& p : X_C) p = -p;
    }
    const AlignmentResult aligned = AlignPointSets(X, X_C);
    if (!aligned.ok) continue;
    Rigid T;
    T.R = aligned.T_dst_src.R();
    T.t = aligned.T_dst_src.p;
    const double error = NormalizedError(T, X, xy);
    if (error < best_error) {
      best_error = error;
      best = T;
    }
  }
  return best;
}

// Polynomials with ascending coefficients, for the P3P quartic.
using Polynomial = std::vector<double>;

Polynomial Multiply(const Polynomial& a, const Polynomial& b) {
  Polynomial c(a.size() + b.size() - 1, 0.0);
  for (size_t i = 0; i < a.size(); ++i) {
    for (size_t j = 0; j < b.size(); ++j) c[i + j] += a[i] * b[j];
  }
  return c;
}

Polynomial Add(const Polynomial& a, const Polynomial& b) {
  Polynomial c(std::max(a.size(), b.size()), 0.0);
  for (size_t i = 0; i < a.size(); ++i) c[i] += a[i];
  for (size_t i = 0; i < b.size(); ++i) c[i] += b[i];
  return c;
}

double EvaluatePolynomial(const Polynomial& p, double x) {
  double value = 0.0;
  for (size_t i = p.size(); i-- > 0;) value = value * x + p[i];
  return value;
}

// Real roots by the eigenvalues of the companion matrix, polished by Newton steps.
std::vector<double> RealRoots(Polynomial p) {
  double scale = 0.0;
  for (double c : p) scale = std::max(scale, std::abs(c));
  while (p.size() > 1 && std::abs(p.back()) <= 1e-14 * scale) p.pop_back();
  const int degree = static_cast<int>(p.size()) - 1;
  std::vector<double> roots;
  if (degree < 1) return roots;
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(degree, degree);
  for (int i = 0; i < degree; ++i) companion(0, i) = -p[degree - 1 - i] / p[degree];
  for (int i = 1; i < degree; ++i) companion(i, i - 1) = 1.0;
  const Eigen::EigenSolver<Eigen::MatrixXd> eigen(companion, false);
  if (eigen.info() != Eigen::Success) return roots;
  Polynomial derivative(degree);
  for (int i = 1; i <= degree; ++i) derivative[i - 1] = i * p[i];
  for (int i = 0; i < degree; ++i) {
    const std::complex<double> z = eigen.eigenvalues()(i);
    if (std::abs(z.imag()) > 1e-6 * (1.0 + std::abs(z))) continue;
    double x = z.real();
    for (int k = 0; k < 3; ++k) {
      const double slope = EvaluatePolynomial(derivative, x);
      if (slope == 0.0) break;
      x -= EvaluatePolynomial(p, x) / slope;
    }
    roots.push_back(x);
  }
  return roots;
}

// P3P (Grunert's formulation, eliminated here directly): with unit rays f_k, distances s_k
// along them, s2 = u s1, s3 = v s1 and the law of cosines for the three model distances,
//   E1: b^2 (1 + u^2 - 2 u cos_g) = c^2 (1 + v^2 - 2 v cos_b)
//   E2: b^2 (u^2 + v^2 - 2 u v cos_a) = a^2 (1 + v^2 - 2 v cos_b)
// Both are quadratics in u with leading coefficient b^2; their difference is linear,
// u = N(v) / D(v), and substituting back gives a quartic in v. Up to 4 poses.
std::vector<Rigid> P3p(const std::array<Eigen::Vector3d, 3>& X,
                       const std::array<Eigen::Vector3d, 3>& f) {
  std::vector<Rigid> poses;
  const double a2 = (X[1] - X[2]).squaredNorm();
  const double b2 = (X[0] - X[2]).squaredNorm();
  const double c2 = (X[0] - X[1]).squaredNorm();
  if (!(a2 > 0.0 && b2 > 0.0 && c2 > 0.0)) return poses;
  const double cos_a = f[1].dot(f[2]), cos_b = f[0].dot(f[2]), cos_g = f[0].dot(f[1]);
  // E1 as b^2 u^2 + p1 u + p0(v), E2 as b^2 u^2 + q1(v) u + q0(v).
  const double p1 = -2.0 * b2 * cos_g;
  const Polynomial p0 = {b2 - c2, 2.0 * c2 * cos_b, -c2};
  const Polynomial q1 = {0.0, -2.0 * b2 * cos_a};
  const Polynomial q0 = {-a2, 2.0 * a2 * cos_b, b2 - a2};
  const Polynomial D = Add({p1}, Multiply({-1.0}, q1));
  const Polynomial N = Add(q0, Multiply({-1.0}, p0));
  const Polynomial quartic =
      Add(Add(Multiply({b2}, Multiply(N, N)), Multiply({p1}, Multiply(N, D))),
          Multiply(p0, Multiply(D, D)));
  for (const double v : RealRoots(quartic)) {
    const double d = EvaluatePolynomial(D, v);
    if (!(v > 0.0) || std::abs(d) < 1e-12 * b2) continue;
    const double u = EvaluatePolynomial(N, v) / d;
    const double denominator = 1.0 + v * v - 2.0 * v * cos_b;
    if (!(u > 0.0) || !(denominator > 0.0)) continue;
    const double s1 = std::sqrt(b2 / denominator);
    const std::vector<Eigen::Vector3d> model = {X[0], X[1], X[2]};
    const std::vector<Eigen::Vector3d> camera = {s1 * f[0], u * s1 * f[1], v * s1 * f[2]};
    const AlignmentResult aligned = AlignPointSets(model, camera);
    if (!aligned.ok) continue;
    Rigid T;
    T.R = aligned.T_dst_src.R();
    T.t = aligned.T_dst_src.p;
    poses.push_back(T);
  }
  return poses;
}

// Starts from P3P on every triple of a small point set, ranked by the normalized reprojection
// error over all points; the best `keep` are returned.
std::vector<Rigid> P3pStarts(const std::vector<Eigen::Vector3d>& X,
                             const std::vector<Eigen::Vector2d>& xy, size_t keep) {
  const int n = static_cast<int>(X.size());
  std::vector<std::pair<double, Rigid>> ranked;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      for (int k = j + 1; k < n; ++k) {
        const std::array<Eigen::Vector3d, 3> model = {X[i], X[j], X[k]};
        const std::array<Eigen::Vector3d, 3> rays = {xy[i].homogeneous().normalized(),
                                                     xy[j].homogeneous().normalized(),
                                                     xy[k].homogeneous().normalized()};
        for (const Rigid& T : P3p(model, rays)) {
          const double error = NormalizedError(T, X, xy);
          if (std::isfinite(error)) ranked.emplace_back(error, T);
        }
      }
    }
  }
  std::sort(ranked.begin(), ranked.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Rigid> starts;
  for (const auto& [error, T] : ranked) {
    bool duplicate = false;
    for (const Rigid& S : starts) {
      duplicate =
          duplicate || ((S.R - T.R).norm() < 1e-3 && (S.t - T.t).norm() < 1e-3 * T.t.norm());
    }
    if (duplicate) continue;
    starts.push_back(T);
    if (starts.size() >= keep) break;
  }
  return starts;
}

// The other pose of a (nearly) planar model under the near-affine ambiguity: the plane's
// normal mirrored about the line of sight to the centroid, rotating about the centroid.
Rigid PlanarFlip(const Rigid& T, const Eigen::Vector3d& centroid_D,
                 const Eigen::Vector3d& normal_D) {
  const Eigen::Vector3d centroid_C = T.R * centroid_D + T.t;
  const Eigen::Vector3d sight = centroid_C.normalized();
  const Eigen::Vector3d normal = T.R * normal_D;
  const Eigen::Vector3d mirrored = 2.0 * normal.dot(sight) * sight - normal;
  const Eigen::Matrix3d R_flip =
      Eigen::Quaterniond::FromTwoVectors(normal, mirrored).toRotationMatrix();
  Rigid flipped;
  flipped.R = R_flip * T.R;
  flipped.t = centroid_C - flipped.R * centroid_D;
  return flipped;
}

// Inverse of the left Jacobian of SO(3): d rvec = Jl(rvec)^-1 dtheta.
Eigen::Matrix3d LeftJacobianInverse(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  const Eigen::Matrix3d W = Hat(w);
  double c;
  if (theta < 1e-5) {
    c = 1.0 / 12.0 + theta * theta / 720.0;
  } else {
    const double half = 0.5 * theta;
    c = 1.0 / (theta * theta) - std::cos(half) / (2.0 * theta * std::sin(half));
  }
  return Eigen::Matrix3d::Identity() - 0.5 * W + c * W * W;
}

}  // namespace

Matrix6d CameraInDockCovariance(const Pose3& T_C_D, const Matrix6d& covariance_local) {
  const Eigen::Matrix3d R_D_C = T_C_D.R().transpose();
  Matrix6d J = Matrix6d::Zero();  // d(dp_D, dtheta_D) / d(dtheta, dt)
  J.block<3, 3>(0, 0) = -R_D_C * Hat(T_C_D.p);
  J.block<3, 3>(0, 3) = -R_D_C;
  J.block<3, 3>(3, 0) = -R_D_C;
  return J * covariance_local * J.transpose();
}

PnpResult SolvePnp(const std::vector<Eigen::Vector3d>& points_D,
                   const std::vector<Eigen::Vector2d>& pixels_distorted,
                   const PinholeRadtanCamera& camera, const PnpOptions& options,
                   const std::optional<Pose3>& initial_T_C_D,
                   const std::vector<Eigen::Matrix2d>& pixel_covariances) {
  const size_t n = points_D.size();
  if (pixels_distorted.size() != n) return Fail("size mismatch between points and pixels");
  if (n < 3) return Fail("fewer than 3 correspondences");
  for (size_t i = 0; i < n; ++i) {
    if (!points_D[i].allFinite() || !pixels_distorted[i].allFinite()) {
      return Fail("NaN or Inf in the input");
    }
  }
  if (!(options.pixel_sigma > 0.0) || !std::isfinite(options.pixel_sigma)) {
    return Fail("pixel_sigma must be positive and finite");
  }
  if (initial_T_C_D.has_value() &&
      (!initial_T_C_D->q.coeffs().allFinite() || !initial_T_C_D->p.allFinite())) {
    return Fail("NaN or Inf in the initial pose");
  }
  if (!pixel_covariances.empty() && pixel_covariances.size() != n) {
    return Fail("size mismatch between pixels and pixel covariances");
  }
  // Whitening W_i = L_i^-1 (Sigma_i = L_i L_i^T); pixel_sigma^2 I when no covariances are given.
  std::vector<Eigen::Matrix2d> whiten(n, Eigen::Matrix2d::Identity() / options.pixel_sigma);
  for (size_t i = 0; i < pixel_covariances.size(); ++i) {
    const Eigen::Matrix2d& S = pixel_covariances[i];
    const Eigen::LLT<Eigen::Matrix2d> llt(S);
    if (!S.allFinite() || std::abs(S(0, 1) - S(1, 0)) > 1e-9 * S.norm() ||
        llt.info() != Eigen::Success || !(llt.matrixLLT().diagonal().minCoeff() > 0.0)) {
      return Fail("pixel covariance " + std::to_string(i) + " is not positive definite");
    }
    whiten[i] = llt.matrixL().solve(Eigen::Matrix2d::Identity());
  }

  // Shape of the model: centroid, principal axes (det +1) and RMS spreads.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& X : points_D) centroid += X;
  centroid /= static_cast<double>(n);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& X : points_D) scatter += (X - centroid) * (X - centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter / static_cast<double>(n));
  const Eigen::Vector3d spread = eigen.eigenvalues().reverse().cwiseMax(0.0).cwiseSqrt();
  Eigen::Matrix3d B = eigen.eigenvectors().rowwise().reverse();  // largest first
  B.col(2) = B.col(0).cross(B.col(1));
  if (!(spread(0) > 0.0) || spread(1) <= kCollinearTolerance * spread(0)) {
    return Fail("model points are collinear: rotation about their line is unobservable");
  }
  if (n == 3 && !initial_T_C_D.has_value()) {
    return Fail("3 points: up to 4 solutions, ambiguous");
  }

  std::vector<Rigid> starts;
  if (initial_T_C_D.has_value()) {
    Rigid T;
    T.R = initial_T_C_D->R();
    T.t = initial_T_C_D->p;
    starts.push_back(T);
  }
  if (n >= 4) {
    std::vector<Eigen::Vector2d> xy(n);
    bool finite = true;
    for (size_t i = 0; i < n; ++i) {
      xy[i] = camera.Unproject(pixels_distorted[i]);
      finite = finite && xy[i].allFinite();
    }
    const double thickness = spread(2) / spread(0);
    if (finite && thickness <= kHomographyMaxThickness) {
      if (const auto T = HomographyStart(points_D, xy, centroid, B)) {
        starts.push_back(*T);
        starts.push_back(PlanarFlip(*T, centroid, B.col(2)));
      }
    }
    if (finite && thickness >= kEpnpMinThickness) {
      if (const auto T = EpnpStart(points_D, xy, centroid, B, spread)) starts.push_back(*T);
    }
    if (finite && n <= kMaxPointsForP3pStarts) {
      for (const Rigid& T : P3pStarts(points_D, xy, kP3pStartsKept)) starts.push_back(T);
    }
  }
  if (starts.empty()) return Fail("no closed-form start (degenerate image points)");

  const Problem problem{points_D, pixels_distorted, camera, whiten};
  // Root mean square pixel error of a pose (unweighted), for the reasons and rms_px.
  auto pixel_rms = [&](const Rigid& T) {
    Eigen::VectorXd unused;
    double squared = 0.0;
    Evaluate(problem, T, &unused, nullptr, &squared);
    return std::sqrt(squared / static_cast<double>(n));
  };
  std::vector<Refined> minima;  // converged, every point in front
  bool any_in_front = false;
  for (const Rigid& start : starts) {
    const Refined refined = Refine(problem, start, options);
    if (!refined.in_front) continue;
    any_in_front = true;
    if (refined.converged) minima.push_back(refined);
  }
  if (minima.empty()) {
    return Fail(any_in_front ? "no convergence" : "points behind the camera at the solution");
  }
  auto by_cost = [](const Refined& a, const Refined& b) { return a.cost < b.cost; };
  std::stable_sort(minima.begin(), minima.end(), by_cost);
  // A (nearly) planar model: the flipped twin of the best minimum is always a candidate, whatever
  // the starts found (see the file comment, step 2b).
  const bool check_ambiguity = n >= 4 && options.ambiguity_chi2 > 0.0;
  if (check_ambiguity && spread(2) / spread(0) <= kHomographyMaxThickness) {
    const Refined twin = Refine(problem, PlanarFlip(minima.front().T, centroid, B.col(2)), options);
    if (twin.in_front && twin.converged) {
      minima.push_back(twin);
      std::stable_sort(minima.begin(), minima.end(), by_cost);
    }
  }
  const Refined& lowest = minima.front();

  // Normal matrix at the lowest minimum: observability, and the metric that tells a distinct
  // second minimum from the same one reached by another start.
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  Evaluate(problem, lowest.T, &r, &J);
  Matrix6d A = J.transpose() * J;
  if (!(A.diagonal().minCoeff() > 0.0)) return Fail("singular normal equations");

  // Step 2b: a second minimum, distinct beyond the noise (Mahalanobis distance^2 from the lowest
  // above ambiguity_chi2 in the lowest's covariance) whose chi-square exceeds the lowest's by
  // less than ambiguity_chi2, explains the pixels about as well. (Costs and A are whitened.)
  const Refined* rival = nullptr;
  if (check_ambiguity) {
    for (std::size_t k = 1; k < minima.size() && rival == nullptr; ++k) {
      const Refined& other = minima[k];
      if (2.0 * (other.cost - lowest.cost) >= options.ambiguity_chi2) break;
      Vector6d d;
      d << LogSO3(other.T.R * lowest.T.R.transpose()), other.T.t - lowest.T.t;
      if (d.dot(A * d) > options.ambiguity_chi2) rival = &other;
    }
  }
  const Refined* chosen = &lowest;
  std::vector<Pose3> ambiguous_T_C_D;
  if (rival != nullptr) {
    ambiguous_T_C_D = {Pose3(Eigen::Quaterniond(lowest.T.R), lowest.T.t),
                       Pose3(Eigen::Quaterniond(rival->T.R), rival->T.t)};
    const double rms_lowest = pixel_rms(lowest.T);
    const double rms_rival = pixel_rms(rival->T);
    const double apart = RotationAngleBetween(ambiguous_T_C_D[0].q, ambiguous_T_C_D[1].q);
    std::ostringstream reason;
    reason.precision(3);
    reason << "ambiguous: two poses " << apart * 180.0 / kPi
           << " deg apart fit the pixels about equally well (rms " << rms_lowest << " and "
           << rms_rival << " px)";
    if (!initial_T_C_D.has_value()) {
      PnpResult refused = Fail(reason.str() + " and there is no prediction to choose");
      refused.ambiguous_T_C_D = ambiguous_T_C_D;
      return refused;
    }
    const double to_lowest = RotationAngleBetween(initial_T_C_D->q, ambiguous_T_C_D[0].q);
    const double to_rival = RotationAngleBetween(initial_T_C_D->q, ambiguous_T_C_D[1].q);
    if (to_rival <= options.prediction_angle_ratio * to_lowest) {
      chosen = rival;
    } else if (!(to_lowest <= options.prediction_angle_ratio * to_rival)) {
      reason << " and the prediction, " << to_lowest * 180.0 / kPi << " and "
             << to_rival * 180.0 / kPi << " deg from them, does not choose";
      PnpResult refused = Fail(reason.str());
      refused.ambiguous_T_C_D = ambiguous_T_C_D;
      return refused;
    }
    if (chosen != &lowest) {
      Evaluate(problem, chosen->T, &r, &J);
      A = J.transpose() * J;
      if (!(A.diagonal().minCoeff() > 0.0)) return Fail("singular normal equations");
    }
  }
  const Refined& best = *chosen;

  const Vector6d diagonal = A.diagonal();
  const Vector6d inv_scale = diagonal.cwiseSqrt().cwiseInverse();
  const Matrix6d A_scaled = inv_scale.asDiagonal() * A * inv_scale.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen_A(A_scaled);
  if (eigen_A.info() != Eigen::Success ||
      !(eigen_A.eigenvalues()(0) > kSingularTolerance * eigen_A.eigenvalues()(5))) {
    return Fail("singular normal equations: the pose is not observable from these points");
  }
  const Matrix6d A_scaled_inverse = eigen_A.eigenvectors() *
                                    eigen_A.eigenvalues().cwiseInverse().asDiagonal() *
                                    eigen_A.eigenvectors().transpose();

  PnpResult result;
  result.ok = true;
  result.T_C_D = Pose3(Eigen::Quaterniond(best.T.R), best.T.t);
  result.ambiguous_T_C_D = ambiguous_T_C_D;
  result.chi2 = 2.0 * best.cost;
  result.dof = 2 * static_cast<int>(n) - 6;
  result.variance_factor = result.dof > 0 ? result.chi2 / result.dof : 1.0;
  const double inflation = options.inflate_by_variance_factor ? std::max(1.0, result.variance_factor)
                                                              : 1.0;
  result.covariance_local =
      inflation * inv_scale.asDiagonal() * A_scaled_inverse * inv_scale.asDiagonal();
  Matrix6d G = Matrix6d::Identity();
  G.topLeftCorner<3, 3>() = LeftJacobianInverse(LogQuaternion(result.T_C_D.q));
  result.covariance = G * result.covariance_local * G.transpose();
  result.rms_px = pixel_rms(best.T);
  result.iterations = best.iterations;
  return result;
}

}  // namespace auvdock
