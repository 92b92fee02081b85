// dock.yaml <-> DockModel (data/docks/*.yaml; a dataset's dock.yaml).
//
//   name: t_shape_6
//   origin_depth_m: 30.0          # water depth of the D origin (m)
//   gravity_D: [0, 0, 9.81]       # m/s^2 in D (z down)
//   beacon_p_D: [0, 0, 0]         # acoustic beacon on the platform (m)
//   deck: {length_m: 3.0, width_m: 2.0, height_above_seabed_m: 0.5}
//   lights:
//     - {id: 0, p_D: [0.75, 0.0, 0.0], radius_m: 0.05, intensity: 1.0}
// Light ids must be unique; at least 3 lights. Throws InputError naming the file and key.
#pragma once

#include <string>

#include "auvdock/geometry/dock_model.h"

namespace auvdock {

DockModel LoadDockModel(const std::string& path);
void SaveDockModel(const DockModel& dock, const std::string& path);

}  // namespace auvdock
