// Optical properties of the water column, for the underwater image renderer.
//
// Image formation (seed 000, eq. 2; the haze model the dark-channel dehazing inverts):
//   I_c = J_c t_c(r) + A_c (1 - t_c(r)),     t_c(r) = exp(-c_c r)
// per colour channel c, where J is the radiance of the object, r the range along the line of
// sight (m), c the beam attenuation coefficient (absorption + scattering, 1/m) and A the
// veiling light (the radiance of an infinitely long water path: ambient light scattered into the
// line of sight).
//
// Channel order is B, G, R everywhere (OpenCV's order). Units: attenuation in 1/m; veiling light
// as a fraction of full scale (1.0 = 255 gray levels at exposure 1).
//
// Figures (Jerlov's optical classification of ocean and coastal water; beam attenuation
// c = a + b is larger than the diffuse attenuation K_d that Jerlov tabulates, because it counts
// all scattering as loss). A camera's colour channels are broad: B ~ 450-490 nm, G ~ 520-570 nm,
// R ~ 580-650 nm, so each c below is a channel-averaged value.
//   kClear   (open ocean, Jerlov I-II): pure-water absorption dominates; it is tiny in the blue
//            (~0.01-0.02 /m), ~0.06 /m in the green and ~0.25-0.35 /m over the red channel's band;
//            particle scattering adds ~0.04 /m. c = (0.06, 0.09, 0.30): blue travels furthest,
//            red is gone after ~10 m. Veiling light deep blue.
//   kCoastal (Jerlov coastal 1-3): chlorophyll and dissolved organic matter absorb the blue,
//            scattering rises to ~0.2 /m. c = (0.45, 0.32, 0.55): green travels furthest.
//            Veiling light blue-green.
//   kTurbid  (harbour / river plume, Jerlov coastal 7-9, suspended sediment): scattering
//            ~0.5-0.8 /m on top of strong blue absorption. c = (1.10, 0.75, 1.05). Veiling light
//            bright green-brown (much scattered light).
// With the renderer's default light radiance these give (blue-green guide light, luma peak above
// background >= 12 gray levels): detectable to ~35 m in clear, ~14 m in coastal and ~5.5 m in
// turbid water.
#pragma once

#include <string>

#include <Eigen/Core>

namespace auvdock {

enum class WaterType { kClear, kCoastal, kTurbid };

// "clear", "coastal", "turbid".
const char* WaterTypeName(WaterType type);
// Parses the names above (exact, lower case); returns false on anything else.
bool ParseWaterType(const std::string& text, WaterType* type);

struct WaterModel {
  Eigen::Vector3d attenuation_per_m = Eigen::Vector3d(0.06, 0.09, 0.30);  // c per channel, B G R
  Eigen::Vector3d veiling_light = Eigen::Vector3d(0.42, 0.22, 0.03);      // A, B G R, in [0, 1]

  static WaterModel ForType(WaterType type);

  // exp(-c r) per channel; r in metres (r <= 0 gives 1).
  Eigen::Vector3d Transmission(double range_m) const;
};

}  // namespace auvdock
