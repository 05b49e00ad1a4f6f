// One contact's pipe, appended to a DomainNetwork the way DomainDetector emits it; shared with
// LocalDomainDetector::Emit, which must write the same network to the bit.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "seep/core/geometry/domain_detection.h"

namespace seep::core::geometry_internal {

// Contact `contact` between particles i and j (surface gap `gap`) with domain da on its left and
// db on its right: a pipe between them, or, when one side is outer face k (given as -k - 1), a
// boundary pipe of that face whose contact point lies on the line of centres halfway across the
// gap; the domain beside it is then marked is_boundary.
inline void AppendContactPipe(DomainNetwork& net, std::int32_t da, std::int32_t db,
                              std::int32_t contact, std::size_t i, std::size_t j, double gap,
                              const double* x, const double* y, const double* r) {
  const double length = r[i] + r[j];
  if (da >= 0 && db >= 0) {
    net.pipe_domain_a.push_back(da);
    net.pipe_domain_b.push_back(db);
    net.pipe_contact.push_back(contact);
    net.pipe_length.push_back(length);
    return;
  }
  const std::int32_t domain = da >= 0 ? da : db;
  const std::int32_t outer = da >= 0 ? -db - 1 : -da - 1;
  net.is_boundary[static_cast<std::size_t>(domain)] = 1;
  const double dx = x[j] - x[i];
  const double dy = y[j] - y[i];
  const double dist = std::sqrt(dx * dx + dy * dy);
  const double along = dist > 0.0 ? (r[i] + 0.5 * gap) / dist : 0.0;
  net.boundary_pipe_domain.push_back(domain);
  net.boundary_pipe_contact.push_back(contact);
  net.boundary_pipe_outer_face.push_back(outer);
  net.boundary_pipe_length.push_back(length);
  net.boundary_pipe_x.push_back(x[i] + along * dx);
  net.boundary_pipe_y.push_back(y[i] + along * dy);
}

}  // namespace seep::core::geometry_internal
