// ViridisColour (see colour_map.h).
#include "colour_map.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace seep::client {
namespace {

int Channel(const char* hex, int k) {
  const char digits[3] = {hex[1 + 2 * k], hex[2 + 2 * k], '\0'};
  return static_cast<int>(std::strtol(digits, nullptr, 16));
}

}  // namespace

std::string ViridisColour(double t) {
  if (std::isnan(t)) t = 0.5;
  t = std::clamp(t, 0.0, 1.0);
  const double position = t * static_cast<double>(kViridisStops.size() - 1);
  const auto below = std::min(static_cast<std::size_t>(position), kViridisStops.size() - 2);
  const double f = position - static_cast<double>(below);
  int rgb[3];
  for (int k = 0; k < 3; ++k) {
    const double a = Channel(kViridisStops[below], k);
    const double b = Channel(kViridisStops[below + 1], k);
    rgb[k] = static_cast<int>(std::lround(a + f * (b - a)));
  }
  return fmt::format("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2]);
}

}  // namespace seep::client
