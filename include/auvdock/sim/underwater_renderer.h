// Renders the simulator's underwater camera images: a lamp-lit deck and seabed seen through a
// scattering, absorbing water column, with the dock's guide lights, their reflections and
// marine-snow particles.
//
// Math, per pixel and per colour channel c (B, G, R), following seed 000's haze model (eq. 2):
//   I_c = J_c t_c(r) + A_c (1 - t_c(r)),   t_c(r) = exp(-c_c r)            (WaterModel)
// The pixel's ray from the camera centre is intersected with the deck rectangle (plane z = 0 of
// D, |x| <= L/2, |y| <= W/2, seen from above) and otherwise with the seabed (z = deck_height_m);
// r is the range to the hit. A ray that hits nothing (going up or level) sees pure veiling light.
// The object radiance is Lambertian,
//   J_c = albedo_c (ambient A_c + lamp cos(i) beam t_c(r) / r^2)
// with a lamp co-located with the camera (so the incidence angle i equals the viewing angle and
// the light crosses the same water path twice), beam = cos^2 of the angle off the optical axis,
// and ambient = the downwelling daylight on the bottom as a multiple of the veiling light. The
// seabed albedo carries a low-contrast periodic texture (a sum of four sinusoids in D, period
// 8 m), so that dehazing and feature extraction have structure to work with; the deck is plain
// grey except for a dark housing (a disc of 4 light radii, albedo 0.04) around each light, which
// keeps the scene under a saturated light core dark and flat. The scene then passes a soft-knee
// camera response (linear to 140 gray levels, compressed towards 190 above, as an auto-exposed
// camera keeps a lamp-lit deck out of saturation), is multiplied by the vignetting
//   v = 1 - vignetting (1 - cos^4 theta) / (1 - cos^4 theta_corner)
// and is rounded to whole gray levels, so that a light's quantization below does not depend on
// where the scene level sits between two gray levels.
//
// Guide lights are added as isotropic 2-D Gaussian blobs centred exactly at the distorted
// projection of the light centre p_D_L:
//   sigma_px = max(0.8, fx rho / range)  with rho = the light's radius_m
//   amplitude_c = 255 exposure vignette(centre) light_radiance intensity colour_c t_c(range) s
//   s = 1 - exp(-rho_px^2 / (2 * 0.8^2)),  rho_px = fx rho / range
// A resolved emitter keeps its radiance along the ray (only t_c dims it) while it shrinks as
// 1/range; once it is smaller than the optics' blur (~0.8 px) the same energy is spread over the
// blur spot, which the factor s models (it is ~1 up to ~15 m for a 5 cm light at fx = 457 px and
// makes the irradiance fall as t/range^2 beyond). The colour is blue-green (cyan LED guide
// lights). Blobs are added before 8-bit clipping, so a saturated core is a symmetric plateau and
// the intensity centroid stays on the projection (within ~0.12 px of it over the dark housing,
// noise off, in the tests). Vignetting is applied per pixel to the scene but, for lights, as the
// constant vignette value at the blob centre (a blob is small; a slope across it would bias the
// centroid). A light of intensity 0 is never visible: "lights off" keeps the housings. Then
// reflections (a dimmer, wider copy of each visible light displaced toward the image bottom: its
// glint on the wet deck / the camera port) and marine-snow particles (Poisson count, uniform
// position) are added as distractors, then additive Gaussian sensor noise, then rounding and
// clipping to 8 bit.
//
// The look (render_look.h) sets what is not geometry or water: the lights' tint, size, radiance,
// halo, bloom and asymmetric lobes, the deck's albedo, painted structures (a white funnel, rim,
// cables, fittings; their gain applies after the knee, so they can saturate), the housings, the
// seabed texture, the reflections' and particles' figures, the colour cast and noise level, and
// the camera and video chain (image_degradation.h: defocus and motion blur, interlacing, JPEG),
// applied after the distractors and before the sensor noise (JPEG last). The default look
// (DefaultRenderLook) is the renderer described above, with the light colour of the dock's
// `colour`.
//
// Frames: T_D_C maps camera coordinates (OpenCV: x right, y down, z optical axis) into the dock
// frame D (origin on the deck, z down). Units: metres, pixels, 8-bit gray levels; radiances are
// in full-scale units (1.0 = 255 gray levels at exposure 1).
//
// Cost: the rays, vignetting and a per-channel transmission table exp(-c r) are computed once in
// the constructor; a 640x512 frame takes ~8 ms for the scene plus ~3 ms for the sensor noise on
// one core.
//
// Determinism: every random draw comes from the caller's std::mt19937_64 (the sensor noise via a
// cv::RNG seeded from it), so equal generator states give byte-identical images. No threads, no
// global state; a renderer is immutable after construction and Render() is const.
#pragma once

#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "auvdock/camera/camera_calibration.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/sim/render_look.h"
#include "auvdock/sim/water_model.h"

namespace auvdock {

struct RenderOptions {
  double noise_sigma = 2.0;  // additive Gaussian sensor noise, 8-bit gray levels; 0 = off
  double vignetting = 0.3;   // relative brightness loss at the image corners (cos^4 shape)
  double exposure = 1.0;     // global gain
  // Radiance of a light of intensity 1 before attenuation, full-scale units. 5.0 saturates the
  // light's green channel out to ~10 m in clear water and ~4 m in coastal water, and keeps the
  // luma peak above detection_threshold to ~35 m (clear), ~14 m (coastal), ~5.5 m (turbid).
  double light_radiance = 5.0;
  bool reflections = true;           // a dimmer, wider reflection of each visible light
  double particles_per_frame = 2.0;  // Poisson mean of bright marine-snow specks
  double seabed_albedo = 0.3;        // Lambertian, mean of the texture
  double deck_albedo = 0.6;          // Lambertian, a light-grey painted platform
  double lamp_power = 3.0;           // vehicle lamp irradiance at 1 m on its axis, full-scale units
  // Downwelling daylight on the bottom, as a multiple of the veiling light A: a Lambertian bottom
  // of albedo rho then has radiance rho ambient A. 2 makes the plain deck brighter than open
  // water and the seabed a little darker, as seen looking down in daylight.
  double ambient_light = 2.0;
  // A light is visible (and drawn) only when its luma peak above the background reaches this
  // (gray levels). 12 is 6 sigma of the default noise.
  double detection_threshold = 12.0;
};

struct RenderedLight {
  int light_id = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // distorted projection of p_D_L, pixels
  double radius_px = 0.0;  // sigma of the drawn Gaussian blob = max(0.8, fx radius_m / range)
  // Unclipped luma amplitude (0.114 B + 0.587 G + 0.299 R) of the blob above the background, gray
  // levels; > 255 means the core saturates.
  double peak = 0.0;
  double range_m = 0.0;  // distance camera centre - light centre
};

struct RenderedDistractor {
  std::string kind;  // "reflection" or "particle"
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  double radius_px = 0.0;  // sigma of the drawn blob
};

struct RenderResult {
  cv::Mat image;  // CV_8UC3, BGR
  std::vector<RenderedLight> lights;
  std::vector<RenderedDistractor> distractors;
};

class UnderwaterRenderer {
 public:
  // Precomputes the per-pixel unit rays in C (undistorted) and the vignetting, once. The first
  // form uses the dock's default look (render_look.h).
  UnderwaterRenderer(const CameraCalibration& camera, const DockModel& dock,
                     const WaterModel& water, const RenderOptions& options);
  UnderwaterRenderer(const CameraCalibration& camera, const DockModel& dock,
                     const WaterModel& water, const RenderOptions& options,
                     const RenderLook& look);

  // Geometric visibility without rasterising: the lights in front of the camera whose distorted
  // projection lies inside the image, whose emitting side faces the camera (emission cone of
  // half-angle 85 deg about -z of D) and whose peak reaches options.detection_threshold. In the
  // dock's light order.
  std::vector<RenderedLight> VisibleLights(const Pose3& T_D_C) const;

  // Renders one 8-bit BGR image. All randomness comes from rng.
  RenderResult Render(const Pose3& T_D_C, std::mt19937_64& rng) const;

  const CameraCalibration& camera() const { return camera_; }
  const DockModel& dock() const { return dock_; }
  const WaterModel& water() const { return water_; }
  const RenderOptions& options() const { return options_; }
  const RenderLook& look() const { return look_; }

 private:
  // Scene radiance (lamp-lit deck and seabed through the water), gray levels, CV_32FC3.
  void RenderBackground(const Pose3& T_D_C, cv::Mat* image) const;
  // Albedo modulation of the seabed at (x, y) of D, mean 1, bilinear in the periodic table.
  float SeabedTexture(float x_D, float y_D) const;
  // Brightness factor of the optics for a ray at angle theta off the optical axis.
  double Vignette(double cos_theta) const;
  // Per-channel blob amplitude (gray levels) of a light seen at the given range and angle theta
  // off the optical axis.
  Eigen::Vector3d LightAmplitude(const DockLight& light, double range_m, double cos_theta) const;
  // Adds one visible light with the look's halo, lobe and bloom to a CV_32FC3 image.
  void DrawLight(const RenderedLight& rendered, const Pose3& T_C_D, cv::Mat* image) const;

  CameraCalibration camera_;
  DockModel dock_;
  WaterModel water_;
  RenderOptions options_;
  RenderLook look_;
  // Per pixel, row-major: unit ray in C (x, y, z) and the gray-level gain 255 exposure vignette.
  std::vector<float> pixel_rays_;
  // Seabed albedo modulation, kTextureSize^2 texels over one period, wrapped.
  std::vector<float> seabed_texture_;
  double corner_falloff_ = 1.0;  // 1 - cos^4(theta) at the farthest image corner
  // exp(-c r) per channel (B G R interleaved) sampled along r, and the range beyond which a
  // surface is invisible (every channel's transmission below 1e-4).
  std::vector<float> transmission_table_;
  double max_surface_range_m_ = 0.0;
};

}  // namespace auvdock
