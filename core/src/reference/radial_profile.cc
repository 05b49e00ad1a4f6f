#include "seep/core/reference/radial_profile.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace seep::core {

Result<RadialProfileFit> FitRadialProfile(const SceneNetwork& net, double r_min, double r_max) {
  RadialProfileFit fit;
  const auto pressure = net.flow.pressure();
  for (std::size_t d = 0; d < net.domains.num_domains(); ++d) {
    if (static_cast<std::int32_t>(d) == net.well_domain) continue;
    const double r = std::hypot(net.domains.centroid_x[d] - net.well_x_m,
                                net.domains.centroid_y[d] - net.well_y_m);
    if (r <= r_min || r >= r_max) continue;
    fit.ln_r.push_back(std::log(r));
    fit.pressure.push_back(pressure[d]);
  }
  const double n = static_cast<double>(fit.ln_r.size());
  double mx = 0.0;
  double mp = 0.0;
  for (std::size_t i = 0; i < fit.ln_r.size(); ++i) {
    mx += fit.ln_r[i] / n;
    mp += fit.pressure[i] / n;
  }
  double sxx = 0.0;
  double sxp = 0.0;
  for (std::size_t i = 0; i < fit.ln_r.size(); ++i) {
    sxx += (fit.ln_r[i] - mx) * (fit.ln_r[i] - mx);
    sxp += (fit.ln_r[i] - mx) * (fit.pressure[i] - mp);
  }
  if (!(sxx > 0.0)) {
    return FailedPrecondition(fmt::format(
        "radial profile: {} domains between r = {} m and {} m; need at least two distinct radii",
        fit.ln_r.size(), r_min, r_max));
  }
  fit.slope = sxp / sxx;
  fit.intercept = mp - fit.slope * mx;
  return fit;
}

std::vector<RingMean> RingMeans(const RadialProfileFit& fit, double r_min, double r_max,
                                double ring_width) {
  const auto rings = static_cast<std::size_t>(std::ceil((r_max - r_min) / ring_width));
  std::vector<double> sum_p(rings, 0.0);
  std::vector<double> sum_ln_r(rings, 0.0);
  std::vector<double> count(rings, 0.0);
  for (std::size_t i = 0; i < fit.ln_r.size(); ++i) {
    const auto ring =
        std::min(rings - 1, static_cast<std::size_t>((std::exp(fit.ln_r[i]) - r_min) / ring_width));
    sum_p[ring] += fit.pressure[i];
    sum_ln_r[ring] += fit.ln_r[i];
    count[ring] += 1.0;
  }
  std::vector<RingMean> out;
  for (std::size_t g = 0; g < rings; ++g) {
    if (count[g] == 0.0) continue;
    out.push_back({sum_ln_r[g] / count[g], sum_p[g] / count[g]});
  }
  return out;
}

}  // namespace seep::core
