#include "auvdock/sim/underwater_renderer.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>

#include "auvdock/sim/image_blobs.h"
#include "auvdock/sim/image_degradation.h"

namespace auvdock {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kFullScale = 255.0;

// Camera response of the scene (not of the lights): linear up to kKneeLevel gray levels, then
// compressed towards kSceneCeiling, as an auto-exposed camera keeps a lamp-lit deck at close
// range out of saturation. Lights are added after it and do saturate; over an unsaturated,
// smooth background their saturated core stays symmetric about the projection.
constexpr float kKneeLevel = 140.0f;
constexpr float kSceneCeiling = 190.0f;
inline float SoftKnee(float level) {
  if (level <= kKneeLevel) return level;
  const float excess = level - kKneeLevel;
  const float room = kSceneCeiling - kKneeLevel;
  return kKneeLevel + excess / (1.0f + excess / room);
}

// The scene is quantized to whole gray levels before the lights, distractors and noise are
// added: the 8-bit image is then round(scene) + round(light + noise), so a noise-free light's
// quantization does not depend on where the scene's level sits between two gray levels (a
// background crossing x.5 under a blob would otherwise round its tails unevenly and shift the
// centroid by up to ~0.2 px). Levels are non-negative, so truncating level + 0.5 rounds.
inline float RoundLevel(float level) { return static_cast<float>(static_cast<int>(level + 0.5f)); }

// Lights emit into the half-space above the deck; beyond 85 deg from the vertical the housing
// hides the emitter.
const double kCosEmissionHalfAngle = std::cos(85.0 * kPi / 180.0);
// Blur of the optics (lens + sensor), pixels: the smallest blob and the scale below which an
// emitter is unresolved.
constexpr double kMinSigmaPx = 0.8;
// A light nearer than this to the camera centre is not drawn (it would fill the image).
constexpr double kMinLightDepthM = 0.05;
// Luma weights (ITU-R BT.601, as cv::cvtColor uses), B G R.
const Eigen::Vector3d kLumaBgr(0.114, 0.587, 0.299);
// Lamp-lit marine snow is whitish.
const Eigen::Vector3d kParticleColourBgr(1.0, 1.0, 0.85);
// Sand/mud is slightly warmer than grey, B G R.
const Eigen::Vector3f kSeabedTintBgr(0.85f, 1.0f, 1.1f);
// Each light sits in a dark (black anodised) housing, a horizontal disc of this many light radii
// around the emitter: flush with the deck for a light on the deck (whose dome may stand up to its
// own radius above it), at the light's own height on top of its mast for a raised light (higher
// above the deck than its radius; the mast itself is not drawn).
// Besides being what guide lights look like, it keeps the surface around a saturated light core
// dark and flat, so clipping does not pull the intensity centroid along the lamp's brightness
// gradient on the deck.
constexpr double kHousingRadiusFactor = 4.0;
// The lamp irradiance 1/r^2 is capped at this range (m) so a surface touching the camera stays
// finite.
constexpr float kMinLampRangeM = 0.5f;

// Transmission table: exp(-c r) per channel at this many samples per metre, interpolated
// linearly (relative error below (c / samples)^2 / 8 < 1e-4), out to where every channel is
// below kMinTransmission; farther surfaces are pure veiling light.
constexpr double kTransmissionSamplesPerM = 32.0;
constexpr double kMinTransmission = 1e-4;

// Seabed texture: one period of kTexturePeriodM metres in kTextureSize texels (6 cm; the
// shortest wave spans 9 texels). 64 KB, so that lookups stay in cache. The wave
// vectors are whole multiples of 2 pi / period along x and y so the table wraps seamlessly.
constexpr int kTextureSize = 128;
constexpr double kTexturePeriodM = 8.0;
struct TextureWave {
  int nx, ny;  // cycles per period along x and y of D
  double amplitude;
  double phase;
};
constexpr TextureWave kTextureWaves[] = {{2, 1, 0.10, 0.3},    // 3.6 m sand ripples
                                         {3, -5, 0.08, 1.7},   // 1.4 m
                                         {-7, 4, 0.07, 4.1},   // 1.0 m
                                         {11, 9, 0.05, 2.6}};  // 0.56 m

// Random draws from the caller's generator, written out so that the image does not depend on the
// standard library's distribution implementations.
double Uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * Uniform01(rng);
}

double StandardNormal(std::mt19937_64& rng) {
  const double u1 = 1.0 - Uniform01(rng);  // (0, 1]
  const double u2 = Uniform01(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
}

int Poisson(std::mt19937_64& rng, double mean) {
  if (!(mean > 0.0)) return 0;
  if (mean > 30.0) {  // normal approximation; Knuth's product would underflow
    return std::max(0, static_cast<int>(std::lround(mean + std::sqrt(mean) * StandardNormal(rng))));
  }
  const double limit = std::exp(-mean);
  int count = 0;
  double product = Uniform01(rng);
  while (product > limit) {
    ++count;
    product *= Uniform01(rng);
  }
  return count;
}

// Solves DistortNormalized(xy) = distorted for the undistorted normalized point by Newton's
// method with the analytic Jacobian, starting from *xy. Returns false if it does not converge.
bool UndistortNewton(const std::array<double, 5>& d, const Eigen::Vector2d& distorted,
                     Eigen::Vector2d* xy) {
  const double k1 = d[0], k2 = d[1], p1 = d[2], p2 = d[3], k3 = d[4];
  for (int iteration = 0; iteration < 12; ++iteration) {
    const double x = xy->x(), y = xy->y();
    double xd, yd;
    DistortNormalized(d, x, y, &xd, &yd);
    const double rx = xd - distorted.x(), ry = yd - distorted.y();
    if (rx * rx + ry * ry < 1e-24) return true;
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double dradial_dr2 = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2);
    const double j00 = radial + 2.0 * x * x * dradial_dr2 + 2.0 * p1 * y + 6.0 * p2 * x;
    const double j01 = 2.0 * x * y * dradial_dr2 + 2.0 * p1 * x + 2.0 * p2 * y;
    const double j10 = 2.0 * x * y * dradial_dr2 + 2.0 * p1 * x + 2.0 * p2 * y;
    const double j11 = radial + 2.0 * y * y * dradial_dr2 + 6.0 * p1 * y + 2.0 * p2 * x;
    const double det = j00 * j11 - j01 * j10;
    if (!(std::fabs(det) > 1e-12)) return false;
    xy->x() -= (j11 * rx - j01 * ry) / det;
    xy->y() -= (-j10 * rx + j00 * ry) / det;
  }
  return false;
}

// The first painted feature (render_look.h) covering (x, y) of the deck sets the albedo and the
// post-knee gain; elsewhere they are left as they are.
void PaintedFeature(const std::vector<DeckFeature>& features, float x, float y,
                    Eigen::Vector3f* albedo, float* gain) {
  for (const DeckFeature& f : features) {
    const double px = x - f.a.x(), py = y - f.a.y();
    bool inside = false;
    if (f.kind == DeckFeature::Kind::kDisc) {
      const double r2 = px * px + py * py;
      inside = r2 <= f.radius_m * f.radius_m && r2 >= f.inner_radius_m * f.inner_radius_m;
    } else {
      const Eigen::Vector2d d = f.b - f.a;
      const double t = std::clamp((px * d.x() + py * d.y()) / d.squaredNorm(), 0.0, 1.0);
      const double ex = px - t * d.x(), ey = py - t * d.y();
      inside = ex * ex + ey * ey <= f.radius_m * f.radius_m;
    }
    if (inside) {
      *albedo = Eigen::Vector3f::Constant(static_cast<float>(f.albedo));
      *gain = static_cast<float>(f.gain);
      return;
    }
  }
}

}  // namespace

UnderwaterRenderer::UnderwaterRenderer(const CameraCalibration& camera, const DockModel& dock,
                                       const WaterModel& water, const RenderOptions& options)
    : UnderwaterRenderer(camera, dock, water, options, DefaultRenderLook(dock)) {}

UnderwaterRenderer::UnderwaterRenderer(const CameraCalibration& camera, const DockModel& dock,
                                       const WaterModel& water, const RenderOptions& options,
                                       const RenderLook& look)
    : camera_(camera), dock_(dock), water_(water), options_(options), look_(look) {
  const PinholeRadtanCamera& intrinsics = camera_.intrinsics;
  const int width = intrinsics.width();
  const int height = intrinsics.height();
  assert(width > 0 && height > 0);

  // The farthest corner sets the scale of the vignetting (its loss is options.vignetting).
  double min_cos4 = 1.0;
  for (const Eigen::Vector2d& corner :
       {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(width - 0.5, -0.5),
        Eigen::Vector2d(-0.5, height - 0.5), Eigen::Vector2d(width - 0.5, height - 0.5)}) {
    const double c = intrinsics.Bearing(corner).z();
    min_cos4 = std::min(min_cos4, c * c * c * c);
  }
  corner_falloff_ = std::max(1e-9, 1.0 - min_cos4);

  // Rays by Newton's method on the distortion, warm-started from the neighbouring pixel (a few
  // iterations each); the camera's own Unproject is the fallback.
  pixel_rays_.resize(static_cast<size_t>(width) * height * 4);
  float* ray = pixel_rays_.data();
  Eigen::Vector2d row_start((-intrinsics.cx()) / intrinsics.fx(),
                            (-intrinsics.cy()) / intrinsics.fy());
  for (int v = 0; v < height; ++v) {
    Eigen::Vector2d xy = row_start;
    for (int u = 0; u < width; ++u, ray += 4) {
      const Eigen::Vector2d distorted((u - intrinsics.cx()) / intrinsics.fx(),
                                      (v - intrinsics.cy()) / intrinsics.fy());
      if (!UndistortNewton(intrinsics.distortion(), distorted, &xy)) {
        xy = intrinsics.Unproject(Eigen::Vector2d(u, v));
      }
      if (u == 0) row_start = xy;
      const Eigen::Vector3d bearing = Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
      ray[0] = static_cast<float>(bearing.x());
      ray[1] = static_cast<float>(bearing.y());
      ray[2] = static_cast<float>(bearing.z());
      ray[3] = static_cast<float>(kFullScale * options_.exposure * Vignette(bearing.z()));
    }
  }

  const double min_attenuation = std::max(1e-3, water_.attenuation_per_m.minCoeff());
  max_surface_range_m_ = std::log(1.0 / kMinTransmission) / min_attenuation;
  const int num_samples =
      static_cast<int>(std::ceil(max_surface_range_m_ * kTransmissionSamplesPerM)) + 2;
  transmission_table_.resize(3 * static_cast<size_t>(num_samples));
  for (int i = 0; i < num_samples; ++i) {
    const Eigen::Vector3d t = water_.Transmission(i / kTransmissionSamplesPerM);
    for (int ch = 0; ch < 3; ++ch) transmission_table_[3 * i + ch] = static_cast<float>(t[ch]);
  }

  // The look scales the waves, shifts their phases and adds a fine grain (pebbles): one uniform
  // draw per texel, mean zero, clamped so the albedo stays positive.
  seabed_texture_.resize(kTextureSize * kTextureSize);
  std::mt19937_64 grain_rng(look_.texture_seed);
  for (int j = 0; j < kTextureSize; ++j) {
    for (int i = 0; i < kTextureSize; ++i) {
      double value = 1.0;
      for (const TextureWave& wave : kTextureWaves) {
        const double phase =
            2.0 * kPi * (wave.nx * i + wave.ny * j) / static_cast<double>(kTextureSize);
        value += look_.texture_amplitude_scale * wave.amplitude *
                 std::sin(phase + wave.phase + look_.texture_phase_offset);
      }
      if (look_.texture_grain > 0.0) {
        value += look_.texture_grain * (2.0 * Uniform01(grain_rng) - 1.0);
      }
      seabed_texture_[j * kTextureSize + i] = static_cast<float>(std::max(0.05, value));
    }
  }
}

double UnderwaterRenderer::Vignette(double cos_theta) const {
  const double cos2 = cos_theta * cos_theta;
  return 1.0 - options_.vignetting * (1.0 - cos2 * cos2) / corner_falloff_;
}

Eigen::Vector3d UnderwaterRenderer::LightAmplitude(const DockLight& light, double range_m,
                                                   double cos_theta) const {
  // Share of the emitter's core that survives the optics' blur: ~1 while the disc is resolved.
  const double radius_px =
      camera_.intrinsics.fx() * light.radius_m * look_.light_size_scale / range_m;
  const double blur_share =
      1.0 - std::exp(-radius_px * radius_px / (2.0 * kMinSigmaPx * kMinSigmaPx));
  const double gain = kFullScale * options_.exposure * Vignette(cos_theta) *
                      options_.light_radiance * look_.light_radiance_scale * light.intensity *
                      blur_share;
  return gain * look_.light_colour_bgr.cwiseProduct(water_.Transmission(range_m));
}

inline float UnderwaterRenderer::SeabedTexture(float x_D, float y_D) const {
  constexpr float kTexelsPerM = static_cast<float>(kTextureSize / kTexturePeriodM);
  const float tx = x_D * kTexelsPerM;
  const float ty = y_D * kTexelsPerM;
  // Floor by truncation (std::floor is a library call without SSE4.1). Far seabed ranges reach
  // ~150 m: well inside int, and & wraps negatives correctly.
  int ix = static_cast<int>(tx);
  int iy = static_cast<int>(ty);
  ix -= tx < static_cast<float>(ix) ? 1 : 0;
  iy -= ty < static_cast<float>(iy) ? 1 : 0;
  const float ax = tx - static_cast<float>(ix);
  const float ay = ty - static_cast<float>(iy);
  const int i0 = ix & (kTextureSize - 1);
  const int j0 = iy & (kTextureSize - 1);
  const int i1 = (i0 + 1) & (kTextureSize - 1);
  const int j1 = (j0 + 1) & (kTextureSize - 1);
  const float* row0 = &seabed_texture_[j0 * kTextureSize];
  const float* row1 = &seabed_texture_[j1 * kTextureSize];
  const float top = row0[i0] + ax * (row0[i1] - row0[i0]);
  const float bottom = row1[i0] + ax * (row1[i1] - row1[i0]);
  return top + ay * (bottom - top);
}

std::vector<RenderedLight> UnderwaterRenderer::VisibleLights(const Pose3& T_D_C) const {
  const PinholeRadtanCamera& intrinsics = camera_.intrinsics;
  const Pose3 T_C_D = T_D_C.Inverse();
  std::vector<RenderedLight> visible;
  for (const DockLight& light : dock_.lights) {
    const Eigen::Vector3d p_C = T_C_D * light.p_D;
    const auto uv = intrinsics.Project(p_C, kMinLightDepthM);
    if (!uv || !intrinsics.InImage(*uv)) continue;
    // Emitting side: the camera must lie within the emission cone about -z of D.
    const Eigen::Vector3d light_to_camera = T_D_C.p - light.p_D;
    const double range = light_to_camera.norm();
    if (-light_to_camera.z() < kCosEmissionHalfAngle * range) continue;

    const double peak = kLumaBgr.dot(LightAmplitude(light, range, p_C.z() / p_C.norm()));
    if (!(peak >= options_.detection_threshold)) continue;

    RenderedLight rendered;
    rendered.light_id = light.id;
    rendered.uv = *uv;
    rendered.radius_px = std::max(
        kMinSigmaPx, intrinsics.fx() * light.radius_m * look_.light_size_scale / range);
    rendered.peak = peak;
    rendered.range_m = range;
    visible.push_back(rendered);
  }
  return visible;
}

void UnderwaterRenderer::RenderBackground(const Pose3& T_D_C, cv::Mat* image) const {
  const int num_pixels = image->rows * image->cols;
  assert(image->isContinuous() && image->type() == CV_32FC3);
  const Eigen::Matrix3f R_D_C = T_D_C.R().cast<float>();
  const Eigen::Vector3f p_D_C = T_D_C.p.cast<float>();
  const float ox = p_D_C.x(), oy = p_D_C.y(), oz = p_D_C.z();
  const float half_length = static_cast<float>(0.5 * dock_.deck_length_m);
  const float half_width = static_cast<float>(0.5 * dock_.deck_width_m);
  const float seabed_z = static_cast<float>(dock_.deck_height_m);
  const Eigen::Vector3f A = water_.veiling_light.cast<float>();
  const Eigen::Vector3f ambient = static_cast<float>(options_.ambient_light) * A;
  const float lamp = static_cast<float>(options_.lamp_power * look_.lamp_power_scale);
  const Eigen::Vector3f deck_albedo =
      Eigen::Vector3f::Constant(static_cast<float>(options_.deck_albedo * look_.deck_albedo_scale));
  const Eigen::Vector3f seabed_albedo = static_cast<float>(options_.seabed_albedo) * kSeabedTintBgr;
  // Beyond this range every channel's transmission is below 1e-4: the pixel is veiling light.
  const float max_range = static_cast<float>(max_surface_range_m_);
  const float samples_per_m = static_cast<float>(kTransmissionSamplesPerM);
  const float min_lamp_range2 = kMinLampRangeM * kMinLampRangeM;
  // Light housings: centres and squared radii. Those flush with the deck share a bounding box;
  // a raised light's housing is a disc at its own height z (< 0: above the deck).
  struct Housing {
    float x, y, z, radius2;
  };
  std::vector<Housing> housings, raised_housings;
  float box_min_x = 0.0f, box_max_x = -1.0f, box_min_y = 0.0f, box_max_y = -1.0f;
  for (const DockLight& light : dock_.lights) {
    const float radius = static_cast<float>(kHousingRadiusFactor * light.radius_m);
    const float x = static_cast<float>(light.p_D.x());
    const float y = static_cast<float>(light.p_D.y());
    if (-light.p_D.z() > light.radius_m) {  // on a mast
      raised_housings.push_back({x, y, static_cast<float>(light.p_D.z()), radius * radius});
      continue;
    }
    if (housings.empty()) {
      box_min_x = x - radius, box_max_x = x + radius, box_min_y = y - radius;
      box_max_y = y + radius;
    } else {
      box_min_x = std::min(box_min_x, x - radius), box_max_x = std::max(box_max_x, x + radius);
      box_min_y = std::min(box_min_y, y - radius), box_max_y = std::max(box_max_y, y + radius);
    }
    housings.push_back({x, y, 0.0f, radius * radius});
  }
  const Eigen::Vector3f housing_albedo =
      Eigen::Vector3f::Constant(static_cast<float>(look_.housing_albedo));
  const std::vector<DeckFeature>& features = look_.deck_features;

  const float* ray = pixel_rays_.data();
  float* out = image->ptr<float>(0);
  for (int k = 0; k < num_pixels; ++k, ray += 4, out += 3) {
    const float rx = ray[0], ry = ray[1], rz = ray[2], gain = ray[3];
    const float dx = R_D_C(0, 0) * rx + R_D_C(0, 1) * ry + R_D_C(0, 2) * rz;
    const float dy = R_D_C(1, 0) * rx + R_D_C(1, 1) * ry + R_D_C(1, 2) * rz;
    const float dz = R_D_C(2, 0) * rx + R_D_C(2, 1) * ry + R_D_C(2, 2) * rz;

    float range = -1.0f;
    float surface_gain = 1.0f;
    Eigen::Vector3f albedo;
    if (dz > 0.0f) {  // looking down (+z of D)
      // A raised light's housing, seen from above, hides what lies behind it.
      for (const Housing& housing : raised_housings) {
        if (oz >= housing.z) continue;
        const float s = (housing.z - oz) / dz;
        const float hx = ox + s * dx - housing.x, hy = oy + s * dy - housing.y;
        if (hx * hx + hy * hy <= housing.radius2 && s < max_range && (range < 0.0f || s < range)) {
          range = s;
          albedo = housing_albedo;
        }
      }
      if (range < 0.0f && oz < 0.0f) {
        const float s = -oz / dz;
        const float x = ox + s * dx;
        const float y = oy + s * dy;
        if (std::fabs(x) <= half_length && std::fabs(y) <= half_width && s < max_range) {
          range = s;
          albedo = deck_albedo;
          bool in_housing = false;
          if (x >= box_min_x && x <= box_max_x && y >= box_min_y && y <= box_max_y) {
            for (const Housing& housing : housings) {
              const float hx = x - housing.x, hy = y - housing.y;
              if (hx * hx + hy * hy <= housing.radius2) {
                albedo = housing_albedo;
                in_housing = true;
                break;
              }
            }
          }
          if (!in_housing && !features.empty()) {
            PaintedFeature(features, x, y, &albedo, &surface_gain);
          }
        }
      }
      if (range < 0.0f && oz < seabed_z) {
        const float s = (seabed_z - oz) / dz;
        if (s < max_range) {
          range = s;
          albedo = SeabedTexture(ox + s * dx, oy + s * dy) * seabed_albedo;
        }
      }
    }
    if (range < 0.0f) {
      out[0] = RoundLevel(gain * A[0]);
      out[1] = RoundLevel(gain * A[1]);
      out[2] = RoundLevel(gain * A[2]);
      continue;
    }
    // Lamp at the camera: incidence angle = viewing angle (cos = dz for a horizontal surface),
    // beam cos^2 off the optical axis, inverse square law.
    const float lamp_term = lamp * dz * rz * rz / std::max(range * range, min_lamp_range2);
    const float sample = range * samples_per_m;
    const int i = static_cast<int>(sample);
    const float alpha = sample - static_cast<float>(i);
    const float* t0 = &transmission_table_[3 * i];
    for (int ch = 0; ch < 3; ++ch) {
      const float t = t0[ch] + alpha * (t0[ch + 3] - t0[ch]);
      const float J = albedo[ch] * (ambient[ch] + lamp_term * t);
      out[ch] = RoundLevel(surface_gain * SoftKnee(gain * (J * t + A[ch] * (1.0f - t))));
    }
  }
}

void UnderwaterRenderer::DrawLight(const RenderedLight& rendered, const Pose3& T_C_D,
                                   cv::Mat* image) const {
  // VisibleLights reported the luma of this amplitude; the blob needs the colour channels.
  const DockLight* light = dock_.FindLight(rendered.light_id);
  const Eigen::Vector3d p_C = T_C_D * light->p_D;
  const Eigen::Vector3d amplitude = LightAmplitude(*light, rendered.range_m, p_C.z() / p_C.norm());
  const double sigma = rendered.radius_px;
  AddGaussianBlob(rendered.uv, sigma, amplitude, image);

  // Off-axis lobe (render_look.h): towards the image of the light's tilt direction, displaced so
  // that the unsaturated centroid moves by bias_px times the view factor.
  const LightLobe* lobe = look_.FindLobe(light->id);
  if (lobe != nullptr && lobe->amplitude_fraction > 0.0) {
    const auto tip =
        camera_.intrinsics.Project(T_C_D * (light->p_D + 0.01 * lobe->tilt_D), kMinLightDepthM);
    if (tip && (*tip - rendered.uv).norm() > 1e-9) {
      const Eigen::Vector3d normal_C = T_C_D.R() * Eigen::Vector3d(0.0, 0.0, -1.0);
      const double cos_view = std::fabs(p_C.normalized().dot(normal_C));
      const double view = std::max(0.3, std::sqrt(std::max(0.0, 1.0 - cos_view * cos_view)));
      const double f = lobe->amplitude_fraction;
      const double offset = lobe->bias_px * view * (1.0 + f) / f;
      AddGaussianBlob(rendered.uv + offset * (*tip - rendered.uv).normalized(), sigma,
                      f * amplitude, image);
    }
  }
  // Forward scattering in the water: a wide, faint halo carrying a fraction of the core's
  // energy (amplitude x sigma^2), so its peak is that fraction / halo_sigma_factor^2.
  if (look_.halo_energy_fraction > 0.0) {
    const double k = look_.halo_sigma_factor;
    AddGaussianBlob(rendered.uv, sigma * k, look_.halo_energy_fraction / (k * k) * amplitude,
                    image);
  }
  // Sensor bloom: the charge of a saturated core smears along its columns, symmetric about it.
  const double excess = rendered.peak - kFullScale;
  if (look_.bloom_fraction > 0.0 && excess > 0.0) {
    const double level = std::min(60.0, look_.bloom_fraction * excess);
    AddVerticalSmear(rendered.uv, sigma, level * amplitude / amplitude.maxCoeff(), image);
  }
}

RenderResult UnderwaterRenderer::Render(const Pose3& T_D_C, std::mt19937_64& rng) const {
  const PinholeRadtanCamera& intrinsics = camera_.intrinsics;
  const int width = intrinsics.width();
  const int height = intrinsics.height();
  cv::Mat image(height, width, CV_32FC3);
  RenderBackground(T_D_C, &image);

  RenderResult result;
  result.lights = VisibleLights(T_D_C);
  const Pose3 T_C_D = T_D_C.Inverse();
  for (const RenderedLight& rendered : result.lights) {
    DrawLight(rendered, T_C_D, &image);
    if (options_.reflections) {
      // Glint on the wet deck / camera port: dimmer, wider, below the light in the image.
      const DockLight* light = dock_.FindLight(rendered.light_id);
      const Eigen::Vector3d p_C = T_C_D * light->p_D;
      const Eigen::Vector3d amplitude =
          LightAmplitude(*light, rendered.range_m, p_C.z() / p_C.norm());
      const double sigma = rendered.radius_px;
      const double fraction =
          Uniform(rng, look_.reflection_fraction_min, look_.reflection_fraction_max);
      const double jitter_u = 0.3 * sigma * StandardNormal(rng);
      const double jitter_v = 0.3 * sigma * StandardNormal(rng);
      RenderedDistractor reflection;
      reflection.kind = "reflection";
      reflection.uv = rendered.uv + Eigen::Vector2d(jitter_u, look_.reflection_offset_sigmas * sigma +
                                                                  look_.reflection_offset_px +
                                                                  jitter_v);
      reflection.radius_px = 1.6 * sigma;
      if (intrinsics.InImage(reflection.uv)) {
        AddGaussianBlob(reflection.uv, reflection.radius_px, fraction * amplitude, &image);
        result.distractors.push_back(reflection);
      }
    }
  }

  const int num_particles =
      Poisson(rng, options_.particles_per_frame * look_.particle_rate_scale);
  for (int i = 0; i < num_particles; ++i) {
    RenderedDistractor particle;
    particle.kind = "particle";
    particle.uv =
        Eigen::Vector2d(Uniform(rng, -0.5, width - 0.5), Uniform(rng, -0.5, height - 0.5));
    particle.radius_px = Uniform(rng, 0.6, 1.5);
    const double brightness = Uniform(rng, 60.0, 200.0) * options_.exposure;
    AddGaussianBlob(particle.uv, particle.radius_px, brightness * kParticleColourBgr, &image);
    result.distractors.push_back(particle);
  }

  // The camera and the video chain (nothing with the default look; no draws either).
  const FrameDegradation frame = DrawFrameDegradation(look_, rng);
  ApplyOpticsAndFields(look_, frame, &image);
  ApplyColourCast(look_, &image);
  const double noise_sigma = options_.noise_sigma * look_.noise_sigma_scale;
  if (noise_sigma > 0.0) {
    cv::RNG noise_rng(static_cast<uint64_t>(rng()));
    cv::Mat noise(height, width, CV_32FC3);
    noise_rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
    image += noise;
  }
  cv::Mat quantised;
  image.convertTo(quantised, CV_8UC3);  // rounds to nearest and clips to [0, 255]
  result.image = ApplyJpeg(frame, quantised);
  return result;
}

}  // namespace auvdock
