// Validation of the contact law parameters and the analytic spring-dashpot figures.
#include "seep/core/dem/contact_law.h"

#include <numbers>
#include <string>

namespace seep::core {
namespace {

Status CheckNonNegative(const char* field, double v, bool strictly_positive) {
  const bool ok = std::isfinite(v) && (strictly_positive ? v > 0.0 : v >= 0.0);
  if (ok) return Status::Ok();
  return InvalidArgument(std::string("dem.contact.") + field + ": must be finite and " +
                         (strictly_positive ? "> 0" : ">= 0") + " (got " + std::to_string(v) + ")");
}

}  // namespace

Status ValidateContactLawParams(const ContactLawParams& p) {
  SEEP_RETURN_IF_ERROR(CheckNonNegative("kn", p.kn, true));
  SEEP_RETURN_IF_ERROR(CheckNonNegative("kt", p.kt, false));
  SEEP_RETURN_IF_ERROR(CheckNonNegative("friction", p.friction, false));
  SEEP_RETURN_IF_ERROR(CheckNonNegative("gamma_n", p.gamma_n, false));
  SEEP_RETURN_IF_ERROR(CheckNonNegative("damping_ratio", p.damping_ratio, false));
  return Status::Ok();
}

double SpringDashpotContactDuration(double kn, double m_eff, double gamma_n) {
  return std::numbers::pi / std::sqrt(kn / m_eff - 0.25 * gamma_n * gamma_n);
}

double SpringDashpotRestitution(double kn, double m_eff, double gamma_n) {
  return std::exp(-0.5 * gamma_n * SpringDashpotContactDuration(kn, m_eff, gamma_n));
}

}  // namespace seep::core
