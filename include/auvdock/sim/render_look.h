// How the simulator's underwater images look: the parameters of the renderer that are not the
// geometry or the water, and their domain randomisation (the scenario's `randomize:` section).
//
// Why: a detector tuned on one renderer learns that renderer's look (its light shape, its
// distractors, its clean background). Randomising the look, per camera and per run, from ranges
// wide enough to hold the real footage we know, makes "works on our renders" mean more than
// "mirrors our renderer". Nothing here is tuned to a detector; the ranges are physical.
//
// A RenderLook is drawn once per camera and run (DrawRenderLook) and then fixed; the per-frame
// draws (motion blur, interlacing offsets, JPEG quality) are made by the image degradation
// (image_degradation.h) from the per-frame generator. The default look (DefaultRenderLook)
// reproduces the un-randomised renderer exactly.
//
// What is randomised, each effect a switch of RenderRandomization (all on when enabled):
//   light_appearance  tint of the light within its dock colour (hue +-25 deg, saturation 0.7-1),
//                     emitter size x0.6-1.6, radiance x0.5-4 (saturated cores out to longer
//                     ranges), forward-scattering halo (a second Gaussian of 3-8 sigma carrying
//                     0-30 % of the core's energy), sensor bloom (a vertical smear of saturated
//                     cores, 0-6 % of the excess, at most 60 gray levels, in half of the runs),
//                     reflections 1.5-6 sigma + 1-8 px below the light with 2-40 % of its
//                     amplitude.
//   asymmetric_lobes  each light's emission has an off-axis lobe (a second Gaussian of 15-40 % of
//                     the core's amplitude, displaced in the image towards a fixed tilt direction
//                     of that light), so its intensity centroid is biased by 0.1-0.3 px times a
//                     view factor in [0.3, 1] (|sin| of the angle between the view ray and the
//                     deck normal, floored): biased, per light and view-dependent, as a real
//                     LED's asymmetric beam gives. The ground truth stays the light's centre.
//   dock_structures   a white funnel (a bright disc on the deck, 0.9 albedo x 1-2.5 gain after
//                     the camera's knee, so it can saturate) where the deck is clearest of lights
//                     (a ring's centre, beside a T's stem), or, in half of the runs, centred
//                     among the lights with its rim through them (0.85-1.05 of their median
//                     distance from their centroid: lights against a bright funnel), a bright rim
//                     around it, 1-3 cables (bright or dark strips, 1-3 cm wide), 2-6 specular
//                     fittings (small saturated white discs at least 15 cm from any light), deck
//                     albedo 0.3-0.9, lamp power x0.5-2, light housings from black to deck-grey.
//   backgrounds       seabed texture amplitude x0.5-3 with random phases plus a fine grain
//                     (pebbles, 0-25 %), colour cast of the camera (per-channel gain 0.75-1.25),
//                     sensor noise x0.5-2, marine snow x0-4.
//   blur              defocus (Gaussian sigma 0-1.2 px per run) and motion blur (a line of
//                     0-4 px at a random angle, per frame).
//   interlacing       in half of the runs, the two fields of each frame are 1/2 frame apart:
//                     even and odd rows displaced by +-d/2, d ~ N(0, 0.8 px) per axis per frame.
//   jpeg              compression at a quality drawn per frame from 45-95.
//   strong_distortion the camera's radial distortion drawn from k1 -0.35..-0.1, k2 0.02..0.15,
//                     k3 -0.03..0, tangential +-0.002 (monotonic over the image; checked). This is
//                     a calibration change: the dataset's calibration.yaml carries it.
//
// Determinism: every draw comes from the caller's generator (random_stream.h), so a seed gives
// byte-identical images.
#pragma once

#include <array>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/vision/light_colour.h"

namespace auvdock {

// The scenario's `randomize:` section. Off by default; `enabled: true` turns every effect on and
// each effect can be turned off by its own key.
struct RenderRandomization {
  bool enabled = false;
  bool light_appearance = true;
  bool asymmetric_lobes = true;
  bool dock_structures = true;
  bool backgrounds = true;
  bool blur = true;
  bool interlacing = true;
  bool jpeg = true;
  bool strong_distortion = true;
};

// A shape painted on the deck plane (z = 0 of D): a disc or an annulus (inner_radius > 0), or a
// strip between two points. Its radiance is albedo x (ambient + lamp), and gain multiplies the
// pixel after the camera's knee (gain > 1: a surface brighter than Lambertian, e.g. a white
// funnel facing the lamp, which can saturate).
struct DeckFeature {
  enum class Kind { kDisc, kStrip };
  Kind kind = Kind::kDisc;
  std::string name;                       // "funnel", "rim", "cable", "fitting"
  Eigen::Vector2d a = Eigen::Vector2d::Zero();  // disc centre / strip start (x, y of D), m
  Eigen::Vector2d b = Eigen::Vector2d::Zero();  // strip end, m
  double radius_m = 0.0;                  // disc outer radius / strip half width
  double inner_radius_m = 0.0;            // annulus inner radius (0: a full disc)
  double albedo = 0.6;
  double gain = 1.0;
};

// One light's off-axis lobe: its image offset is drawn towards the projection of
// p_D + 0.01 m * tilt_D, scaled so that the unsaturated centroid moves by bias_px * view factor.
struct LightLobe {
  int light_id = 0;
  Eigen::Vector3d tilt_D = Eigen::Vector3d::UnitX();  // unit, in the deck plane
  double amplitude_fraction = 0.0;  // lobe amplitude / core amplitude (0: no lobe)
  double bias_px = 0.0;             // centroid bias at view factor 1
};

struct RenderLook {
  // Lights.
  Eigen::Vector3d light_colour_bgr = Eigen::Vector3d(0.85, 1.0, 0.2);
  double light_size_scale = 1.0;
  double light_radiance_scale = 1.0;
  double halo_energy_fraction = 0.0;  // halo energy / core energy
  double halo_sigma_factor = 4.0;
  double bloom_fraction = 0.0;  // vertical smear per gray level above saturation
  std::vector<LightLobe> lobes;
  // Distractors: each light's reflection (a fraction of its amplitude drawn per frame from
  // [min, max], offset down the image by sigmas x the light's sigma + px) and marine snow.
  double reflection_fraction_min = 0.10;
  double reflection_fraction_max = 0.25;
  double reflection_offset_sigmas = 3.0;
  double reflection_offset_px = 3.0;
  double particle_rate_scale = 1.0;
  // Deck and background.
  double housing_albedo = 0.04;
  double deck_albedo_scale = 1.0;
  double lamp_power_scale = 1.0;
  std::vector<DeckFeature> deck_features;
  double texture_amplitude_scale = 1.0;
  double texture_phase_offset = 0.0;  // radians, added to every seabed wave
  double texture_grain = 0.0;         // fine random albedo modulation, relative
  uint64_t texture_seed = 0;
  Eigen::Vector3d colour_cast_bgr = Eigen::Vector3d::Ones();
  double noise_sigma_scale = 1.0;
  // Optics and video (image_degradation.h draws the per-frame parts).
  double defocus_sigma_px = 0.0;
  double max_motion_blur_px = 0.0;
  bool interlaced = false;
  double field_offset_sigma_px = 0.0;
  int jpeg_quality_min = 0;  // 0: no compression
  int jpeg_quality_max = 0;

  const LightLobe* FindLobe(int light_id) const;
};

// The base colour (B, G, R, max 1) of a light colour.
Eigen::Vector3d LightColourBgr(LightColour colour);

// The un-randomised look for a dock: its light colour, no halo, lobes, structures or video
// effects.
RenderLook DefaultRenderLook(const DockModel& dock);

// A look drawn from the ranges above (the un-randomised values where an effect is off).
RenderLook DrawRenderLook(const RenderRandomization& randomization, const DockModel& dock,
                          std::mt19937_64& rng);

// Strong radial-tangential distortion (k1, k2, p1, p2, k3), monotonic over the whole image:
// redrawn until d r_d / d r > 0.2 for every undistorted radius r whose distorted radius r_d is
// below max_radius (the image corner's distorted normalised radius, pixels / focal length).
std::array<double, 5> DrawStrongDistortion(double max_radius, std::mt19937_64& rng);

}  // namespace auvdock
