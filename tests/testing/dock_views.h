// Random views of the dock for the matcher tests: the default mono camera, dock files, and a
// camera pose generator (any yaw, bounded roll/pitch, 2-8 m, every light in the image).
#pragma once

#include <random>
#include <string>
#include <vector>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock::test {

// The default rig's down-looking camera (cam2) intrinsics.
PinholeRadtanCamera DefaultMonoCamera();
// data/docks/<name>.
DockModel LoadDock(const std::string& name);
// A random view of the dock: yaw uniform in [0, 360), roll and pitch of the camera (relative to
// looking straight down) uniform in [-max_tilt, max_tilt], the optical axis through a point near
// the dock centre at 2-8 m. Re-sampled until every light is in the image (5 px margin).
// Returns T_C_D.
Pose3 RandomView(const DockModel& dock, const PinholeRadtanCamera& camera, double max_tilt_rad,
                 std::mt19937_64& rng);

// The camera distance_m from the lights' centroid, elevation_rad above the deck's plane (z_D
// down: above is -z) and at azimuth_rad about z_D from behind the dock (0: on the -x side),
// looking at the centroid with its x axis level. Returns T_C_D.
Pose3 ViewFromElevation(const DockModel& dock, double distance_m, double elevation_rad,
                        double azimuth_rad);

// What a light detector would report for a view, with the truth.
struct View {
  Pose3 T_C_D;
  std::vector<LightDetection> detections;
  std::vector<int> truth;  // light id of each detection, -1 for a spurious one
};

// Detections of the visible lights (score 1) with Gaussian pixel noise of noise_px per axis, plus
// num_spurious detections at uniformly random pixels (score 0.5), in random order.
View MakeView(const DockModel& dock, const PinholeRadtanCamera& camera, const Pose3& T_C_D,
              const std::vector<int>& visible_ids, int num_spurious, double noise_px,
              std::mt19937_64& rng);

// The ids of all the dock's lights, in the dock file's order.
std::vector<int> AllLightIds(const DockModel& dock);

}  // namespace auvdock::test
