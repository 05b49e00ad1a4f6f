// Apertures of contact pipes from per-contact force and gap (see contact_apertures.h).
#include "seep/core/coupling/contact_apertures.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace seep::core {

Result<ContactApertureUpdater> ContactApertureUpdater::Create(const ApertureLaw& law,
                                                              double viscosity) {
  SEEP_RETURN_IF_ERROR(ValidateApertureLaw(law));
  if (!(std::isfinite(viscosity) && viscosity > 0.0)) {
    return InvalidArgument("flow.fluid.viscosity: must be finite and > 0 (got " +
                           std::to_string(viscosity) + ")");
  }
  return ContactApertureUpdater(law, viscosity);
}

Status ContactApertureUpdater::Bind(const FlowNetwork& network,
                                    std::span<const std::int32_t> pipe_contact) {
  if (pipe_contact.size() != network.num_pipes()) {
    return InvalidArgument("coupling.contact_apertures.pipe_contact: has " +
                           std::to_string(pipe_contact.size()) + " entries, expected " +
                           std::to_string(network.num_pipes()) + " (one per pipe)");
  }
  std::int32_t max_contact = -1;
  for (std::size_t p = 0; p < pipe_contact.size(); ++p) {
    if (pipe_contact[p] < -1) {
      return InvalidArgument("coupling.contact_apertures.pipe_contact[" + std::to_string(p) +
                             "]: must be a contact id >= 0 or -1 (got " +
                             std::to_string(pipe_contact[p]) + ")");
    }
    max_contact = std::max(max_contact, pipe_contact[p]);
  }
  pipe_contact_.assign(pipe_contact.begin(), pipe_contact.end());
  max_contact_ = max_contact;
  aperture_.assign(network.pipe_aperture().begin(), network.pipe_aperture().end());
  return Status::Ok();
}

Result<ContactApertureReport> ContactApertureUpdater::Update(FlowNetwork& network,
                                                             std::span<const double> normal_force,
                                                             std::span<const double> gap) {
  const std::size_t num_pipes = network.num_pipes();
  if (num_pipes != pipe_contact_.size()) {
    return FailedPrecondition("coupling.contact_apertures: the network has " +
                              std::to_string(num_pipes) + " pipes but the updater was bound to " +
                              std::to_string(pipe_contact_.size()) +
                              " (call Bind after every topology change)");
  }
  const std::size_t needed = static_cast<std::size_t>(max_contact_ + 1);
  if (normal_force.size() < needed || gap.size() < needed) {
    return InvalidArgument("coupling.contact_apertures: normal_force and gap have " +
                           std::to_string(normal_force.size()) + " and " +
                           std::to_string(gap.size()) + " entries; contact ids up to " +
                           std::to_string(max_contact_) + " are bound");
  }
  const std::span<const double> current = network.pipe_aperture();
  ContactApertureReport report;
  for (std::size_t p = 0; p < num_pipes; ++p) {
    const std::int32_t c = pipe_contact_[p];
    if (c < 0) {
      aperture_[p] = current[p];
      continue;
    }
    const double f = normal_force[static_cast<std::size_t>(c)];
    const double g = gap[static_cast<std::size_t>(c)];
    if (!std::isfinite(f) || !std::isfinite(g)) {
      return InvalidArgument("coupling.contact_apertures: contact " + std::to_string(c) +
                             " (pipe " + std::to_string(p) +
                             "): normal_force and gap must be finite (got " + std::to_string(f) +
                             ", " + std::to_string(g) + ")");
    }
    const double a = Aperture(law_, f, g);
    aperture_[p] = a;
    report.pipes_changed += a != current[p];
  }
  if (report.pipes_changed == 0) return report;
  SEEP_RETURN_IF_ERROR(network.SetApertures(aperture_, viscosity_));
  report.network_written = true;
  return report;
}

}  // namespace seep::core
