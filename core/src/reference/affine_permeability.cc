#include "seep/core/reference/affine_permeability.h"

namespace seep::core {

double AffinePermeabilityPerCubedAperture(const DomainNetwork& domains, FlowAxis axis) {
  double area = 0.0;
  for (double v : domains.apparent_volume) area += v;
  if (area <= 0.0) return 0.0;
  const std::vector<double>& centroid =
      axis == FlowAxis::kX ? domains.centroid_x : domains.centroid_y;
  double sum = 0.0;
  for (std::size_t p = 0; p < domains.num_pipes(); ++p) {
    const double d = centroid[static_cast<std::size_t>(domains.pipe_domain_b[p])] -
                     centroid[static_cast<std::size_t>(domains.pipe_domain_a[p])];
    sum += d * d / domains.pipe_length[p];
  }
  return sum / (12.0 * area);
}

}  // namespace seep::core
