// The viridis colour map (perceptually uniform, readable in grey and by most colour-blind
// readers), for the pressure of `seep plot --what particles`.
#pragma once

#include <array>
#include <string>

namespace seep::client {

// Viridis at t = 0, 0.1, ..., 1 (matplotlib's values): the stops of an SVG gradient, and what
// ViridisColour interpolates between.
inline constexpr std::array<const char*, 11> kViridisStops = {
    "#440154", "#482475", "#414487", "#355f8d", "#2a788e", "#21918c",
    "#22a884", "#44bf70", "#7ad151", "#bddf26", "#fde725"};

// "#rrggbb" at t in [0, 1] (clamped; NaN gives the middle), linear between the stops.
std::string ViridisColour(double t);

}  // namespace seep::client
