#include "auvdock/sim/render_look.h"

#include <algorithm>
#include <cmath>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/sim/random_stream.h"

namespace auvdock {
namespace {

constexpr double kPi = 3.14159265358979323846;

bool Coin(std::mt19937_64& rng, double p) { return Uniform01(rng) < p; }

// Hue (degrees), saturation and value of a B, G, R colour with components in [0, 1], and back.
Eigen::Vector3d BgrToHsv(const Eigen::Vector3d& bgr) {
  const double b = bgr[0], g = bgr[1], r = bgr[2];
  const double max = bgr.maxCoeff(), min = bgr.minCoeff(), range = max - min;
  double hue = 0.0;
  if (range > 0.0) {
    if (max == r) hue = 60.0 * std::fmod((g - b) / range + 6.0, 6.0);
    else if (max == g) hue = 60.0 * ((b - r) / range + 2.0);
    else hue = 60.0 * ((r - g) / range + 4.0);
  }
  return Eigen::Vector3d(hue, max > 0.0 ? range / max : 0.0, max);
}

Eigen::Vector3d HsvToBgr(const Eigen::Vector3d& hsv) {
  const double h = std::fmod(hsv[0] + 360.0, 360.0) / 60.0, s = hsv[1], v = hsv[2];
  const double c = v * s, x = c * (1.0 - std::fabs(std::fmod(h, 2.0) - 1.0)), m = v - c;
  double r = 0, g = 0, b = 0;
  switch (static_cast<int>(h)) {
    case 0: r = c, g = x; break;
    case 1: r = x, g = c; break;
    case 2: g = c, b = x; break;
    case 3: g = x, b = c; break;
    case 4: r = x, b = c; break;
    default: r = c, b = x; break;
  }
  return Eigen::Vector3d(b + m, g + m, r + m);
}

// The lights' centroid in the deck plane.
Eigen::Vector2d LightCentroid(const DockModel& dock) {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const DockLight& light : dock.lights) centre += light.p_D.head<2>();
  if (!dock.lights.empty()) centre /= static_cast<double>(dock.lights.size());
  return centre;
}

double DistanceToNearestLight(const DockModel& dock, const Eigen::Vector2d& xy) {
  double nearest = 1e9;
  for (const DockLight& light : dock.lights) {
    nearest = std::min(nearest, (light.p_D.head<2>() - xy).norm());
  }
  return nearest;
}

// A point on the deck, uniform over its rectangle (x, y of D).
Eigen::Vector2d UniformOnDeck(const DockModel& dock, std::mt19937_64& rng) {
  return Eigen::Vector2d(Uniform(rng, -0.5, 0.5) * dock.deck_length_m,
                         Uniform(rng, -0.5, 0.5) * dock.deck_width_m);
}

void DrawDockStructures(const DockModel& dock, std::mt19937_64& rng, RenderLook* look) {
  const Eigen::Vector2d centre = LightCentroid(dock);
  const double light_radius = dock.lights.empty() ? 0.05 : dock.lights.front().radius_m;
  // The funnel: where the deck is clearest of lights, preferring the lights' middle (a ring's
  // centre; beside a T's stem), kept 5 light radii clear of every light.
  Eigen::Vector2d best = centre;
  double best_score = -1e9;
  for (int i = 0; i <= 40; ++i) {
    for (int j = 0; j <= 40; ++j) {
      const Eigen::Vector2d xy((i / 40.0 - 0.5) * 0.9 * dock.deck_length_m,
                               (j / 40.0 - 0.5) * 0.9 * dock.deck_width_m);
      const double score = DistanceToNearestLight(dock, xy) - 0.3 * (xy - centre).norm();
      if (score > best_score) best_score = score, best = xy;
    }
  }
  const double clearance = DistanceToNearestLight(dock, best) - 5.0 * light_radius;
  double funnel_radius = std::min(0.6, Uniform(rng, 0.6, 0.9) * clearance);
  // In half of the runs the funnel reaches the lights instead: centred among them, its rim runs
  // through them (radius 0.85-1.05 of the lights' median distance from their centroid), so that
  // lights sit against the bright funnel and rim, as on real docks whose lights ring the funnel's
  // mouth.
  if (Coin(rng, 0.5) && dock.lights.size() >= 3) {
    std::vector<double> distances;
    for (const DockLight& light : dock.lights) {
      distances.push_back((light.p_D.head<2>() - centre).norm());
    }
    std::nth_element(distances.begin(), distances.begin() + distances.size() / 2,
                     distances.end());
    best = centre;
    funnel_radius = std::min(1.0, Uniform(rng, 0.85, 1.05) * distances[distances.size() / 2]);
  }
  if (funnel_radius > 0.08) {
    DeckFeature funnel;
    funnel.name = "funnel";
    funnel.a = best;
    funnel.radius_m = funnel_radius;
    funnel.albedo = 0.9;
    funnel.gain = Uniform(rng, 1.0, 2.5);
    DeckFeature rim = funnel;
    rim.name = "rim";
    rim.inner_radius_m = funnel_radius;
    rim.radius_m = funnel_radius + Uniform(rng, 0.01, 0.04);
    rim.gain = Uniform(rng, 1.0, 2.0);
    look->deck_features.push_back(rim);
    look->deck_features.push_back(funnel);
  }
  const int cables = 1 + static_cast<int>(Uniform01(rng) * 3.0);
  for (int i = 0; i < cables; ++i) {
    DeckFeature cable;
    cable.kind = DeckFeature::Kind::kStrip;
    cable.name = "cable";
    const double angle = Uniform(rng, 0.0, 2.0 * kPi);
    const Eigen::Vector2d direction(std::cos(angle), std::sin(angle));
    const Eigen::Vector2d through = UniformOnDeck(dock, rng);
    cable.a = through - 1.5 * direction;
    cable.b = through + 1.5 * direction;
    cable.radius_m = 0.5 * Uniform(rng, 0.01, 0.03);
    const bool bright = Coin(rng, 0.5);
    cable.albedo = bright ? 0.85 : 0.05;
    cable.gain = bright ? Uniform(rng, 1.0, 1.6) : 1.0;
    look->deck_features.push_back(cable);
  }
  const int fittings = 2 + static_cast<int>(Uniform01(rng) * 5.0);
  for (int i = 0, tries = 0; i < fittings && tries < 100; ++tries) {
    const Eigen::Vector2d xy = UniformOnDeck(dock, rng);
    if (DistanceToNearestLight(dock, xy) < 0.15) continue;
    DeckFeature fitting;
    fitting.name = "fitting";
    fitting.a = xy;
    fitting.radius_m = Uniform(rng, 0.01, 0.03);
    fitting.albedo = 1.0;
    fitting.gain = Uniform(rng, 2.0, 4.0);
    look->deck_features.push_back(fitting);
    ++i;
  }
  look->deck_albedo_scale = Uniform(rng, 0.5, 1.5);
  look->lamp_power_scale = Uniform(rng, 0.5, 2.0);
  look->housing_albedo = Coin(rng, 0.5) ? 0.04 : Uniform(rng, 0.04, 0.6);
}

}  // namespace

const LightLobe* RenderLook::FindLobe(int light_id) const {
  for (const LightLobe& lobe : lobes) {
    if (lobe.light_id == light_id) return &lobe;
  }
  return nullptr;
}

Eigen::Vector3d LightColourBgr(LightColour colour) {
  switch (colour) {
    case LightColour::kBlueGreen: return Eigen::Vector3d(0.85, 1.0, 0.2);
    case LightColour::kBlue: return Eigen::Vector3d(1.0, 0.55, 0.15);
    case LightColour::kGreen: return Eigen::Vector3d(0.3, 1.0, 0.25);
    case LightColour::kRed: return Eigen::Vector3d(0.15, 0.25, 1.0);
    case LightColour::kWhite: break;
  }
  return Eigen::Vector3d(0.95, 1.0, 0.95);
}

RenderLook DefaultRenderLook(const DockModel& dock) {
  RenderLook look;
  look.light_colour_bgr = LightColourBgr(ParseLightColour(dock.light_colour));
  return look;
}

RenderLook DrawRenderLook(const RenderRandomization& randomization, const DockModel& dock,
                          std::mt19937_64& rng) {
  RenderLook look = DefaultRenderLook(dock);
  if (!randomization.enabled) return look;

  if (randomization.light_appearance) {
    Eigen::Vector3d hsv = BgrToHsv(look.light_colour_bgr);
    if (hsv[1] > 0.2) {  // a coloured light: turn its hue, vary its saturation
      hsv[0] += Uniform(rng, -25.0, 25.0);
      hsv[1] = std::min(1.0, hsv[1] * Uniform(rng, 0.7, 1.0));
    }
    look.light_colour_bgr = HsvToBgr(hsv);
    look.light_size_scale = Uniform(rng, 0.6, 1.6);
    look.light_radiance_scale = std::exp(Uniform(rng, std::log(0.5), std::log(4.0)));
    look.halo_energy_fraction = Uniform(rng, 0.0, 0.3);
    look.halo_sigma_factor = Uniform(rng, 3.0, 8.0);
    look.bloom_fraction = Coin(rng, 0.5) ? Uniform(rng, 0.0, 0.06) : 0.0;
    look.reflection_fraction_min = Uniform(rng, 0.02, 0.15);
    look.reflection_fraction_max = look.reflection_fraction_min + Uniform(rng, 0.05, 0.25);
    look.reflection_offset_sigmas = Uniform(rng, 1.5, 6.0);
    look.reflection_offset_px = Uniform(rng, 1.0, 8.0);
  }
  if (randomization.asymmetric_lobes) {
    for (const DockLight& light : dock.lights) {
      const double angle = Uniform(rng, 0.0, 2.0 * kPi);
      LightLobe lobe;
      lobe.light_id = light.id;
      lobe.tilt_D = Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
      lobe.amplitude_fraction = Uniform(rng, 0.15, 0.40);
      lobe.bias_px = Uniform(rng, 0.1, 0.3);
      look.lobes.push_back(lobe);
    }
  }
  if (randomization.dock_structures) DrawDockStructures(dock, rng, &look);
  if (randomization.backgrounds) {
    look.texture_amplitude_scale = Uniform(rng, 0.5, 3.0);
    look.texture_phase_offset = Uniform(rng, 0.0, 2.0 * kPi);
    look.texture_grain = Uniform(rng, 0.0, 0.25);
    look.texture_seed = rng();
    for (int ch = 0; ch < 3; ++ch) look.colour_cast_bgr[ch] = Uniform(rng, 0.75, 1.25);
    look.noise_sigma_scale = Uniform(rng, 0.5, 2.0);
    look.particle_rate_scale = Uniform(rng, 0.0, 4.0);
  }
  if (randomization.blur) {
    look.defocus_sigma_px = Uniform(rng, 0.0, 1.2);
    look.max_motion_blur_px = 4.0;
  }
  if (randomization.interlacing && Coin(rng, 0.5)) {
    look.interlaced = true;
    look.field_offset_sigma_px = 0.8;
  }
  if (randomization.jpeg) {
    look.jpeg_quality_min = 45;
    look.jpeg_quality_max = 95;
  }
  return look;
}

std::array<double, 5> DrawStrongDistortion(double max_radius, std::mt19937_64& rng) {
  for (int attempt = 0;; ++attempt) {
    const std::array<double, 5> d{Uniform(rng, -0.35, -0.1), Uniform(rng, 0.02, 0.15),
                                  Uniform(rng, -0.002, 0.002), Uniform(rng, -0.002, 0.002),
                                  Uniform(rng, -0.03, 0.0)};
    // d r_d / d r of r_d = r (1 + k1 r^2 + k2 r^4 + k3 r^6), checked along r until r_d reaches
    // the corner: every pixel of the image is then the image of exactly one ray. (Checked out to
    // r = max_radius instead, until 2026-12, the corners of barrel-distorted draws lay beyond the
    // fold, where no ray lands, and lights far outside the view were drawn mid-image.)
    bool monotonic = true;
    for (double r = 0.0;; r += max_radius / 200.0) {
      const double r2 = r * r;
      const double radial = 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
      if (RadialDistortionSlope(d, r2) < 0.2) {
        monotonic = false;
        break;
      }
      if (r * radial >= max_radius) break;
    }
    if (monotonic || attempt == 1000) return d;  // 1000: only for a corner radius far past 1
  }
}

}  // namespace auvdock
