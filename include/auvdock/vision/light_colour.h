// The colour of a dock's guide lights, as a camera sees the light it adds to a scene, and the
// per-pixel "colour excess" that tells a light's glow from white or differently coloured
// structures (a white funnel, a lit deck, a yellow-green wall).
//
// Math: for an 8-bit BGR pixel (b, g, r) the excess of a colour is its own channels minus the
// channel that light of that colour leaves dark, in gray levels:
//   blue:       b - r            green:  g - r           blue_green (cyan): (b + g) / 2 - r
//   red:        r - (b + g) / 2  white:  0 (no colour test: every pixel passes)
// Water absorbs red first, so a blue or green LED's halo is strongly positive, a white surface
// near zero and a yellow-green wall negative. A saturated core is white (excess ~0): the excess
// is measured on the halo around it, not at the centre.
#pragma once

#include <string>

namespace auvdock {

enum class LightColour { kWhite, kBlue, kGreen, kBlueGreen, kRed };

// "white", "blue", "green", "blue_green" (or "cyan"), "red". Throws std::invalid_argument naming
// the accepted values otherwise.
LightColour ParseLightColour(const std::string& name);
const char* LightColourName(LightColour colour);

// Colour excess of one BGR pixel (gray levels, in [-255, 255]).
inline double ColourExcess(LightColour colour, double b, double g, double r) {
  switch (colour) {
    case LightColour::kBlue: return b - r;
    case LightColour::kGreen: return g - r;
    case LightColour::kBlueGreen: return 0.5 * (b + g) - r;
    case LightColour::kRed: return r - 0.5 * (b + g);
    case LightColour::kWhite: break;
  }
  return 0.0;
}

}  // namespace auvdock
