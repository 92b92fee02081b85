// Random views of the dock for the matcher tests: the default mono camera, dock files, and a
// camera pose generator (any yaw, bounded roll/pitch, 2-8 m, every light in the image).
#pragma once

#include <random>
#include <string>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/pose3.h"

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

}  // namespace auvdock::test
