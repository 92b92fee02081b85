#include "auvdock/io/dock_io.h"

#include <cmath>
#include <set>

#include <yaml-cpp/yaml.h>

#include "auvdock/io/yaml_config.h"
#include "auvdock/io/yaml_writer.h"
#include "auvdock/vision/light_colour.h"

namespace auvdock {

DockModel LoadDockModel(const std::string& path) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  DockModel dock;
  dock.name = root.GetString("name");
  dock.light_colour = root.GetString("colour", dock.light_colour);
  try {
    ParseLightColour(dock.light_colour);
  } catch (const std::invalid_argument& e) {
    root.Fail("colour", e.what());
  }
  dock.origin_depth_m = root.GetDouble("origin_depth_m", dock.origin_depth_m);
  dock.gravity_D = root.GetVector<3>("gravity_D", dock.gravity_D);
  if (dock.gravity_D.norm() < 9.0 || dock.gravity_D.norm() > 10.5) {
    root.Fail("gravity_D", "magnitude must be between 9 and 10.5 m/s^2");
  }
  dock.p_D_beacon = root.GetVector<3>("beacon_p_D", dock.p_D_beacon);
  dock.heading_rad = root.GetDouble("heading_deg", dock.heading_rad * 180.0 / M_PI) * M_PI / 180.0;
  if (!std::isfinite(dock.heading_rad)) root.Fail("heading_deg", "must be finite");
  dock.approach_direction_D =
      root.GetVector<3>("approach_direction_D", dock.approach_direction_D);
  if (root.Has("latitude_deg")) {
    const double latitude_deg = root.GetDouble("latitude_deg");
    if (!(latitude_deg >= -90.0 && latitude_deg <= 90.0)) {
      root.Fail("latitude_deg", "must be between -90 and 90 degrees");
    }
    dock.latitude_rad = latitude_deg * M_PI / 180.0;
  }
  const ConfigNode deck = root.ChildOrEmpty("deck");
  dock.deck_length_m = deck.GetPositive("length_m", dock.deck_length_m);
  dock.deck_width_m = deck.GetPositive("width_m", dock.deck_width_m);
  dock.deck_height_m = deck.GetNonNegative("height_above_seabed_m", dock.deck_height_m);

  std::set<int> ids;
  for (const ConfigNode& node : root.Children("lights")) {
    DockLight light;
    light.id = node.GetInt("id");
    if (light.id < 0) node.Fail("id", "must not be negative");
    if (!ids.insert(light.id).second) node.Fail("id", "duplicate light id " + std::to_string(light.id));
    light.p_D = node.GetVector<3>("p_D");
    light.radius_m = node.GetPositive("radius_m", light.radius_m);
    light.intensity = node.GetPositive("intensity", light.intensity);
    dock.lights.push_back(light);
  }
  if (dock.lights.size() < 3) root.Fail("lights", "at least 3 lights are needed");
  // Two lights at one place cannot be told apart in an image (1 mm: any real layout is wider).
  for (size_t i = 0; i < dock.lights.size(); ++i) {
    for (size_t j = i + 1; j < dock.lights.size(); ++j) {
      if ((dock.lights[i].p_D - dock.lights[j].p_D).norm() < 1e-3) {
        root.Fail("lights", "lights " + std::to_string(dock.lights[i].id) + " and " +
                                std::to_string(dock.lights[j].id) + " coincide");
      }
    }
  }
  root.CheckNoUnknownKeys();
  return dock;
}

void SaveDockModel(const DockModel& dock, const std::string& path) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << dock.name;
  out << YAML::Key << "colour" << YAML::Value << dock.light_colour;
  EmitNumber(out, "origin_depth_m", dock.origin_depth_m);
  EmitVector3(out, "gravity_D", dock.gravity_D);
  EmitVector3(out, "beacon_p_D", dock.p_D_beacon);
  if (dock.heading_rad != 0.0) EmitNumber(out, "heading_deg", dock.heading_rad * 180.0 / M_PI);
  if (dock.approach_direction_D.norm() > 0.0) {
    EmitVector3(out, "approach_direction_D", dock.approach_direction_D);
  }
  if (dock.HasLatitude()) EmitNumber(out, "latitude_deg", dock.latitude_rad * 180.0 / M_PI);
  out << YAML::Key << "deck" << YAML::Value << YAML::BeginMap;
  EmitNumber(out, "length_m", dock.deck_length_m);
  EmitNumber(out, "width_m", dock.deck_width_m);
  EmitNumber(out, "height_above_seabed_m", dock.deck_height_m);
  out << YAML::EndMap;
  out << YAML::Key << "lights" << YAML::Value << YAML::BeginSeq;
  for (const auto& light : dock.lights) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "id" << YAML::Value << light.id;
    EmitVector3(out, "p_D", light.p_D);
    EmitNumber(out, "radius_m", light.radius_m);
    EmitNumber(out, "intensity", light.intensity);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  WriteYamlFile(path,
                "auvdock dock model. Frame D: origin on the deck, x along the docking axis,\n"
                "y starboard, z down (deck plane z = 0). Metres, m/s^2.",
                out);
}

}  // namespace auvdock
