#include "auvdock/vision/light_colour.h"

#include <stdexcept>

namespace auvdock {

LightColour ParseLightColour(const std::string& name) {
  if (name == "white") return LightColour::kWhite;
  if (name == "blue") return LightColour::kBlue;
  if (name == "green") return LightColour::kGreen;
  if (name == "blue_green" || name == "cyan") return LightColour::kBlueGreen;
  if (name == "red") return LightColour::kRed;
  throw std::invalid_argument("unknown light colour '" + name +
                              "' (white, blue, green, blue_green, red)");
}

const char* LightColourName(LightColour colour) {
  switch (colour) {
    case LightColour::kWhite: return "white";
    case LightColour::kBlue: return "blue";
    case LightColour::kGreen: return "green";
    case LightColour::kBlueGreen: return "blue_green";
    case LightColour::kRed: return "red";
  }
  return "white";
}

}  // namespace auvdock
