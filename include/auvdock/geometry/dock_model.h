// The recovery platform ("dock") and its guide lights, in the dock frame D.
//
// Frame D: origin on the platform deck, x along the docking axis (the direction the vehicle
// travels when it lands), y to starboard of that axis, z down. The deck is the plane z = 0
// (lights sit on it, the vehicle is above it at z < 0). Gravity is a vector in D, nominally
// (0, 0, +9.81) m/s^2; a tilted platform has a tilted gravity vector rather than a tilted D.
// Units: metres, m/s^2.
//
// Layouts from the seeds: seed 004's T-shape (>= 3 non-collinear lights), seed 001's 8 lights on
// the centre line over 2.8 m (degenerate for a 6-DoF pose: roll about the line is unobservable).
#pragma once

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace auvdock {

struct DockLight {
  int id = 0;
  Eigen::Vector3d p_D = Eigen::Vector3d::Zero();  // centre of the emitting surface
  double radius_m = 0.05;                          // radius of the emitting disc
  double intensity = 1.0;                          // relative radiant intensity (1 = nominal)
};

struct DockModel {
  std::string name;
  std::vector<DockLight> lights;
  // Colour of the light the lights add to an image (vision/light_colour.h names: white, blue,
  // green, blue_green, red); blue-green LEDs are what the seeds' docks carry.
  std::string light_colour = "blue_green";
  // Deck rectangle, centred on the D origin, used for rendering (the bright platform).
  double deck_length_m = 3.0;  // along x
  double deck_width_m = 2.0;   // along y
  // Height of the deck above the surrounding seabed (the seabed is the plane z = deck_height_m).
  double deck_height_m = 0.5;
  Eigen::Vector3d gravity_D = Eigen::Vector3d(0.0, 0.0, 9.81);
  // Water depth (m, below the surface) of the D origin; the pressure sensor measures depth.
  double origin_depth_m = 30.0;
  // The heading of D's x axis (its horizontal part), as a heading sensor would give it
  // (HeadingMeasurement: clockwise from the heading reference seen from above), when surveyed;
  // a heading factor needs it. dock.yaml: heading_deg.
  double heading_rad = 0.0;
  // The site's geodetic latitude (rad; dock.yaml: latitude_deg), for the Earth's rotation that a
  // navigation-grade gyro measures (EarthRate_D); NaN when not given: the Earth's rotation is then
  // not modelled (right for a MEMS gyro, whose noise hides it).
  double latitude_rad = std::numeric_limits<double>::quiet_NaN();
  // Acoustic (USBL/SBL) beacon / transponder position on the platform.
  Eigen::Vector3d p_D_beacon = Eigen::Vector3d::Zero();
  // Where vehicles come from, seen from the dock (any length, D frame; e.g. (-1, 0, -1): from
  // behind the docking axis and above), when the dock's operators know it. It tells a symmetric
  // layout's poses apart (dock_symmetry.h); zero: unknown.
  Eigen::Vector3d approach_direction_D = Eigen::Vector3d::Zero();

  // Whether latitude_rad is given (the Earth's rotation is modelled).
  bool HasLatitude() const { return std::isfinite(latitude_rad); }

  // True when every light lies within tolerance_m of one line (pose about it unobservable).
  bool LightsCollinear(double tolerance_m = 1e-3) const;
  const DockLight* FindLight(int id) const;
};

// The Earth's rotation rate in D (rad/s): in the local north-east-down frame N it is
// Omega (cos lat, 0, -sin lat), Omega = 7.292115e-5 rad/s (WGS-84); D is N turned about down by
// the dock's heading_rad (D's x axis psi clockwise from north), so
//   w_ie_D = Omega (cos lat cos psi, -cos lat sin psi, -sin lat).
// D is fixed to the Earth, so this is also the rate at which D turns against inertial space.
// heading_rad is taken as from true north (a magnetic declination of a few degrees changes the
// horizontal part by that angle: 5e-6 rad/s at most). Zero without a latitude.
Eigen::Vector3d EarthRate_D(const DockModel& dock);
inline constexpr double kEarthRotationRate = 7.292115e-5;  // rad/s, WGS-84

}  // namespace auvdock
