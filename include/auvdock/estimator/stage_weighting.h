// Stage weighting of the vision residuals: the source paper's mono/stereo fusion by visibility
// stage (seed 000, section 3.1), recast as a scalar weight on the information of each camera
// system's residuals in one frame.
//
// The paper runs two standalone pose solvers and, when both see the dock, averages their poses
// with w_s = n_s / (n_s + n_m), w_m = n_m / (n_s + n_m), n = the number of lights each system
// sees (stereo only / mono only: that pose; neither: no pose). Here the estimator has one
// residual per light instead (StereoPointFactor, MonoReprojectionFactor), and a weight w
// multiplies a residual's information: its sqrt_info is scaled by sqrt(w) (the factors'
// information_weight argument).
//
// Modes:
//   kInformation (default): w_s = w_m = 1. Every residual is weighted by its own noise model.
//   kPaperLightCount: the paper's split s_s = n_s / (n_s + n_m), s_m = 1 - s_s, with s_s clamped
//     to [min_share, 1 - min_share], times one factor c chosen so that the weights do not shrink
//     the total information:
//       c = (n_s + n_m) / (n_s s_s + n_m s_m),   w_i = c s_i,
//     i.e. n_s w_s + n_m w_m = n_s + n_m - the mean weight per light is 1, as in kInformation,
//     and only the split between the two systems changes (w_s / w_m = s_s / s_m). With min_share
//     = 0: w_s = n_s N / (n_s^2 + n_m^2), N = n_s + n_m; equal counts give 1 and 1, one system
//     alone gives 1, (n_s, n_m) = (6, 2) gives (1.2, 0.4). Counting in lights is the paper's
//     unit; it ignores that a stereo light has 3 residuals and a mono light 2.
//   A system with no lights has no residuals to weight; its weight is reported as 1 in both
//   modes, so it is always a valid information_weight.
//
// Why kInformation is the default. With per-light covariances the frame's information is
//   H = sum_{stereo lights} J^T Sigma_S^-1 J + sum_{mono lights} J^T Sigma_uv^-1 J,
// which already grows with each system's count and with the quality of each light. The paper's
// rule is what the information-weighted mean of two independent estimates,
//   x = (H_s + H_m)^-1 (H_s x_s + H_m x_m),
// becomes when every light is worth the same, H_s = n_s I0 and H_m = n_m I0; and to first order
// the joint least-squares solution over both residual sets is that information-weighted mean.
// So weight 1 is the paper's fusion without its equal-light assumption. Multiplying by a weight
// proportional to n on top counts the lights twice (a system's information grows as n^2 / N).
// The equal-light assumption is also far from true here: a triangulated light's depth sigma grows
// as z^2 / (f b) while a mono pixel constrains the pose to about z sigma_px / f, so which system
// is better changes with range and geometry - the covariances say so, counts cannot. Finally,
// any weight other than 1 makes the solver's covariance (J^T J)^-1 and the chi-square / NEES
// figures depart from the noise model. kPaperLightCount stays for comparison with the paper's
// baseline and for a system whose noise model is known to be optimistic.
#pragma once

#include <string>

namespace auvdock {

enum class StageWeightingMode { kInformation, kPaperLightCount };

// "information", "paper_light_count".
const char* StageWeightingModeName(StageWeightingMode mode);
// Parses the names above; returns false (mode untouched) on anything else.
bool ParseStageWeightingMode(const std::string& text, StageWeightingMode* mode);

struct StageWeightingOptions {
  StageWeightingMode mode = StageWeightingMode::kInformation;
  // kPaperLightCount only: the smallest share of the split a system that sees at least one light
  // gets (the other gets 1 - share), in [0, 0.5]. 0 is the paper's rule; a positive floor keeps a
  // system that sees one light from being silenced; 0.5 gives both systems weight 1.
  double min_share = 0.0;
};

struct StageWeights {
  double stereo = 1.0;  // multiplies the information of every stereo residual of the frame
  double mono = 1.0;    // multiplies the information of every mono residual of the frame
};

class StageWeighting {
 public:
  // Throws std::invalid_argument for an unknown mode or min_share outside [0, 0.5] (or NaN).
  explicit StageWeighting(const StageWeightingOptions& options = {});

  // n_stereo: lights triangulated by the stereo pair (stereo residuals of the frame); n_mono:
  // lights identified in the mono image (mono residuals). Throws std::invalid_argument if either
  // is negative. Every returned weight is finite and > 0.
  StageWeights Compute(int n_stereo, int n_mono) const;

  const StageWeightingOptions& options() const { return options_; }

 private:
  StageWeightingOptions options_;
};

}  // namespace auvdock
