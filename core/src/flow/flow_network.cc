#include "seep/core/flow/flow_network.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>
#include <string>

#include "../branch_free.h"
#include "../parallel_threshold.h"
#include "step_input.h"

namespace seep::core {

std::uint64_t NextFlowVersionStamp() {
  static std::atomic<std::uint64_t> counter{0};
  return counter.fetch_add(1, std::memory_order_relaxed) + 1;
}

namespace {

std::string Indexed(const char* field, std::size_t index) {
  return std::string("flow.network.") + field + "[" + std::to_string(index) + "]";
}

Status CheckSize(const char* field, std::size_t got, std::size_t want, const char* per) {
  if (got == want) return Status::Ok();
  return InvalidArgument(std::string("flow.network.") + field + ": has " + std::to_string(got) +
                         " entries, expected " + std::to_string(want) + " (one per " + per + ")");
}

// Counts the entries that fail `ok` in a branch-free pass that vectorises (the coupled loop checks
// every coefficient array at each flow update); only a failure pays for the scan that names it.
template <typename Ok>
std::ptrdiff_t FirstFailing(const std::vector<double>& v, Ok ok) {
  const auto n = static_cast<std::ptrdiff_t>(v.size());
  const double* x = v.data();
  // A count of whole numbers far below 2^53: exact in any order, so threads change nothing.
  const double bad = internal::SumOverShares(n, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    double count = 0.0;
#pragma omp simd reduction(+ : count)
    for (std::ptrdiff_t i = begin; i < end; ++i) count += ok(x[i]) ? 0.0 : 1.0;
    return count;
  });
  if (bad == 0.0) return -1;
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    if (!ok(x[i])) return i;
  }
  return -1;
}

using internal::FiniteBranchFree;

// The rules of the coefficient checks, branch-free: one definition for the ordered checks that
// name a failure and for the one-region pass that finds whether there is one.
inline bool FiniteNonNegative(double x) { return FiniteBranchFree(x) & (x >= 0.0); }
inline bool FinitePositive(double x) { return FiniteBranchFree(x) & (x > 0.0); }
// A source rate is finite, and non-zero only on a source domain.
inline bool SourceRateFits(double rate, DomainRole role) {
  return FiniteBranchFree(rate) & ((rate == 0.0) | (role == DomainRole::kSource));
}

Status CheckFiniteNonNegative(const char* field, const std::vector<double>& v) {
  const std::ptrdiff_t i = FirstFailing(v, FiniteNonNegative);
  if (i < 0) return Status::Ok();
  return InvalidArgument(Indexed(field, static_cast<std::size_t>(i)) +
                         ": must be finite and >= 0 (got " +
                         flow_internal::FormatNumber(v[static_cast<std::size_t>(i)]) + ")");
}

Status CheckFinite(const char* field, const std::vector<double>& v) {
  const std::ptrdiff_t i = FirstFailing(v, [](double x) { return FiniteBranchFree(x); });
  if (i < 0) return Status::Ok();
  return InvalidArgument(Indexed(field, static_cast<std::size_t>(i)) + ": must be finite (got " +
                         flow_internal::FormatNumber(v[static_cast<std::size_t>(i)]) + ")");
}

Status CheckFinitePositive(const char* field, const std::vector<double>& v) {
  const std::ptrdiff_t i = FirstFailing(v, FinitePositive);
  if (i < 0) return Status::Ok();
  return InvalidArgument(Indexed(field, static_cast<std::size_t>(i)) +
                         ": must be finite and > 0 (got " +
                         flow_internal::FormatNumber(v[static_cast<std::size_t>(i)]) + ")");
}

}  // namespace

FlowNetwork::FlowNetwork()
    : topology_version_(NextFlowVersionStamp()),
      coefficient_version_(NextFlowVersionStamp()),
      values_stamp_(NextFlowVersionStamp()) {}

FlowNetwork::FlowNetwork(FlowNetworkData data)
    : data_(std::move(data)),
      topology_version_(NextFlowVersionStamp()),
      coefficient_version_(NextFlowVersionStamp()),
      values_stamp_(NextFlowVersionStamp()) {}

void FlowNetwork::StampCheckedValues(bool checked) {
  const bool passed_before = values_passed_.Get() == values_stamp_;
  values_stamp_ = NextFlowVersionStamp();
  if (passed_before && checked) values_passed_.Set(values_stamp_);
}

Status FlowNetwork::Validate() const {
  SEEP_RETURN_IF_ERROR(Validate(data_));
  values_passed_.Set(values_stamp_);
  return Status::Ok();
}

Result<FlowNetwork> FlowNetwork::Create(FlowNetworkData data) {
  SEEP_RETURN_IF_ERROR(Validate(data));
  return FlowNetwork(std::move(data));
}

Status FlowNetwork::Validate(const FlowNetworkData& d) {
  const std::size_t nd = d.pressure.size();
  SEEP_RETURN_IF_ERROR(CheckSize("apparent_volume", d.apparent_volume.size(), nd, "domain"));
  SEEP_RETURN_IF_ERROR(CheckSize("pore_volume", d.pore_volume.size(), nd, "domain"));
  SEEP_RETURN_IF_ERROR(CheckSize("role", d.role.size(), nd, "domain"));
  SEEP_RETURN_IF_ERROR(CheckSize("source_rate", d.source_rate.size(), nd, "domain"));
  const std::size_t np = d.pipe_conductance.size();
  SEEP_RETURN_IF_ERROR(CheckSize("pipe_domain_a", d.pipe_domain_a.size(), np, "pipe"));
  SEEP_RETURN_IF_ERROR(CheckSize("pipe_domain_b", d.pipe_domain_b.size(), np, "pipe"));
  SEEP_RETURN_IF_ERROR(CheckSize("pipe_length", d.pipe_length.size(), np, "pipe"));
  SEEP_RETURN_IF_ERROR(CheckSize("pipe_aperture", d.pipe_aperture.size(), np, "pipe"));
  if (!d.pipe_head_offset.empty()) {
    SEEP_RETURN_IF_ERROR(
        CheckSize("pipe_head_offset", d.pipe_head_offset.size(), np, "pipe, or none"));
  }
  if (nd > static_cast<std::size_t>(INT32_MAX)) {
    return InvalidArgument("flow.network: more than 2^31-1 domains");
  }

  for (std::size_t i = 0; i < nd; ++i) {
    if (!std::isfinite(d.pressure[i])) {
      return InvalidArgument(Indexed("pressure", i) + ": must be finite (got " +
                             flow_internal::FormatNumber(d.pressure[i]) + ")");
    }
    const auto r = static_cast<std::uint8_t>(d.role[i]);
    if (r > static_cast<std::uint8_t>(DomainRole::kSource)) {
      return InvalidArgument(Indexed("role", i) + ": unknown role " + std::to_string(r));
    }
  }

  for (std::size_t p = 0; p < np; ++p) {
    const std::int32_t a = d.pipe_domain_a[p];
    const std::int32_t b = d.pipe_domain_b[p];
    if (a < 0 || static_cast<std::size_t>(a) >= nd) {
      return InvalidArgument(Indexed("pipe_domain_a", p) + ": domain index " + std::to_string(a) +
                             " out of range [0, " + std::to_string(nd) + ")");
    }
    if (b < 0 || static_cast<std::size_t>(b) >= nd) {
      return InvalidArgument(Indexed("pipe_domain_b", p) + ": domain index " + std::to_string(b) +
                             " out of range [0, " + std::to_string(nd) + ")");
    }
    if (a == b) {
      return InvalidArgument(Indexed("pipe_domain_b", p) + ": pipe connects domain " +
                             std::to_string(a) + " to itself");
    }
  }
  return ValidateCoefficients(d);
}

namespace {

// True when every coefficient passes every check of ValidateCoefficients, in at most one parallel
// region (the coupled loop validates at each flow update, and its seven passes were seven):
// per domain and per pipe a branch-free count of what fails. Only a failure pays for the checks
// in order, which name the first one. False also when the sizes differ (the checks then say how).
bool CoefficientsPass(const FlowNetworkData& d, bool check_all) {
  const std::size_t nd = d.pressure.size();
  const std::size_t np = d.pipe_conductance.size();
  if (d.apparent_volume.size() != nd || d.pore_volume.size() != nd || d.source_rate.size() != nd ||
      d.role.size() != nd || d.pipe_length.size() != np || d.pipe_aperture.size() != np ||
      (!d.pipe_head_offset.empty() && d.pipe_head_offset.size() != np)) {
    return false;
  }
  const bool heads = !d.pipe_head_offset.empty();
  const auto domains = static_cast<std::ptrdiff_t>(nd);
  // Without check_all, the volumes alone.
  const auto pipes = check_all ? static_cast<std::ptrdiff_t>(np) : std::ptrdiff_t{0};
  const double* apparent = d.apparent_volume.data();
  const double* pore = d.pore_volume.data();
  const double* source = d.source_rate.data();
  const DomainRole* role = d.role.data();
  const double* length = d.pipe_length.data();
  const double* aperture = d.pipe_aperture.data();
  const double* conductance = d.pipe_conductance.data();
  const double* head = d.pipe_head_offset.data();
  // What fails among domains [d_begin, d_end) and pipes [p_begin, p_end): a count of whole
  // numbers far below 2^53, exact in any order.
  const auto count = [&](std::ptrdiff_t d_begin, std::ptrdiff_t d_end, std::ptrdiff_t p_begin,
                         std::ptrdiff_t p_end) {
    double bad = 0.0;
#pragma omp simd reduction(+ : bad)
    for (std::ptrdiff_t i = d_begin; i < d_end; ++i) {
      const bool ok =
          FiniteNonNegative(apparent[i]) & FiniteNonNegative(pore[i]) & (pore[i] <= apparent[i]);
      bad += ok ? 0.0 : 1.0;
    }
    if (check_all) {
#pragma omp simd reduction(+ : bad)
      for (std::ptrdiff_t i = d_begin; i < d_end; ++i) {
        bad += SourceRateFits(source[i], role[i]) ? 0.0 : 1.0;
      }
    }
#pragma omp simd reduction(+ : bad)
    for (std::ptrdiff_t p = p_begin; p < p_end; ++p) {
      const bool ok = FinitePositive(length[p]) & FiniteNonNegative(aperture[p]) &
                      FinitePositive(conductance[p]);
      bad += ok ? 0.0 : 1.0;
    }
    if (heads) {  // the fluid's weight
#pragma omp simd reduction(+ : bad)
      for (std::ptrdiff_t p = p_begin; p < p_end; ++p) {
        bad += FiniteBranchFree(head[p]) ? 0.0 : 1.0;
      }
    }
    return bad;
  };
  // One team run for all (or none, on one thread or a small network): each member takes its
  // share of the domains and of the pipes.
  std::atomic<double> bad{0.0};
  internal::RunOnCoreThreads(std::max(domains, pipes), [&](const internal::TeamMember& member) {
    const auto [d_begin, d_end] = member.Share(domains);
    const auto [p_begin, p_end] = member.Share(pipes);
    bad.fetch_add(count(d_begin, d_end, p_begin, p_end), std::memory_order_relaxed);
  });
  return bad.load(std::memory_order_relaxed) == 0.0;
}

}  // namespace

Status FlowNetwork::ValidateCoefficients() const {
  // Values known to pass cannot fail the ordered checks either: the message is the same.
  const bool check_all = values_passed_.Get() != values_stamp_;
  if (!CoefficientsPass(data_, check_all)) SEEP_RETURN_IF_ERROR(ValidateCoefficients(data_));
  values_passed_.Set(values_stamp_);
  return Status::Ok();
}

Status FlowNetwork::ValidateCoefficients(const FlowNetworkData& d) {
  if (CoefficientsPass(d, true)) return Status::Ok();
  SEEP_RETURN_IF_ERROR(CheckFiniteNonNegative("apparent_volume", d.apparent_volume));
  SEEP_RETURN_IF_ERROR(CheckFiniteNonNegative("pore_volume", d.pore_volume));
  // Reached only after the one-region pass found a failure: the checks in order, scanning.
  for (std::size_t i = 0; i < d.pressure.size(); ++i) {
    if (d.pore_volume[i] > d.apparent_volume[i]) {
      return InvalidArgument(Indexed("pore_volume", i) + ": exceeds apparent_volume (" +
                             flow_internal::FormatNumber(d.pore_volume[i]) + " > " +
                             flow_internal::FormatNumber(d.apparent_volume[i]) + ")");
    }
    if (!std::isfinite(d.source_rate[i])) {
      return InvalidArgument(Indexed("source_rate", i) + ": must be finite (got " +
                             flow_internal::FormatNumber(d.source_rate[i]) + ")");
    }
    if (d.source_rate[i] != 0.0 && d.role[i] != DomainRole::kSource) {
      return InvalidArgument(Indexed("source_rate", i) + ": is " +
                             flow_internal::FormatNumber(d.source_rate[i]) +
                             " but the domain's role is not kSource");
    }
  }
  SEEP_RETURN_IF_ERROR(CheckFinitePositive("pipe_length", d.pipe_length));
  SEEP_RETURN_IF_ERROR(CheckFiniteNonNegative("pipe_aperture", d.pipe_aperture));
  SEEP_RETURN_IF_ERROR(CheckFinite("pipe_head_offset", d.pipe_head_offset));
  // A zero conductance is a pipe that is not there; keeping it would hide a bug upstream.
  return CheckFinitePositive("pipe_conductance", d.pipe_conductance);
}

Status FlowNetwork::SetPipeHeadOffsets(std::span<const double> offset) {
  if (!offset.empty() && offset.size() != num_pipes()) {
    return InvalidArgument("flow.network.pipe_head_offset: has " + std::to_string(offset.size()) +
                           " entries, expected " + std::to_string(num_pipes()) +
                           " (one per pipe, or none)");
  }
  std::vector<double> values(offset.begin(), offset.end());
  SEEP_RETURN_IF_ERROR(CheckFinite("pipe_head_offset", values));
  data_.pipe_head_offset = std::move(values);
  coefficient_version_ = NextFlowVersionStamp();
  StampCheckedValues(/*checked=*/true);  // finite: all the checks ask of a head offset
  return Status::Ok();
}

std::span<double> FlowNetwork::mutable_pipe_conductance() {
  coefficient_version_ = NextFlowVersionStamp();
  StampCheckedValues(/*checked=*/false);
  return data_.pipe_conductance;
}

std::span<double> FlowNetwork::mutable_apparent_volume() {
  coefficient_version_ = NextFlowVersionStamp();
  return data_.apparent_volume;
}

std::span<double> FlowNetwork::mutable_pore_volume() {
  coefficient_version_ = NextFlowVersionStamp();
  return data_.pore_volume;
}

namespace {

// Apertures that are not finite and > 0 in [begin, end): a count, branch-free so that it
// vectorises.
double CountNonPositiveOrNonFinite(std::ptrdiff_t begin, std::ptrdiff_t end,
                                   const double* __restrict a) {
  double bad = 0.0;
#pragma omp simd reduction(+ : bad)
  for (std::ptrdiff_t p = begin; p < end; ++p) {
    bad += ((a[p] > 0.0) & FiniteBranchFree(a[p])) ? 0.0 : 1.0;
  }
  return bad;
}

// The apertures of [begin, end) and their cubic-law conductances a^3 / (12 mu L).
// Writes a and C = a^3 / (12 mu L) of pipes [begin, end); returns how many of those C fail
// ValidateCoefficients' check (finite and > 0: a^3 can underflow or overflow).
double WriteCubicLaw(std::ptrdiff_t begin, std::ptrdiff_t end, double viscosity,
                     const double* __restrict a_in, const double* __restrict length,
                     double* __restrict a_out, double* __restrict c_out) {
  double bad = 0.0;
#pragma omp simd reduction(+ : bad)
  for (std::ptrdiff_t p = begin; p < end; ++p) {
    const double a = a_in[p];
    a_out[p] = a;
    const double c = a * a * a / (12.0 * viscosity * length[p]);
    c_out[p] = c;
    bad += FinitePositive(c) ? 0.0 : 1.0;
  }
  return bad;
}

}  // namespace

Status FlowNetwork::SetApertures(std::span<const double> aperture, double viscosity) {
  if (aperture.size() != num_pipes()) {
    return InvalidArgument("flow.network.pipe_aperture: has " + std::to_string(aperture.size()) +
                           " entries, expected " + std::to_string(num_pipes()) + " (one per pipe)");
  }
  if (!(std::isfinite(viscosity) && viscosity > 0.0)) {
    return InvalidArgument("flow.fluid.viscosity: must be finite and > 0 (got " +
                           flow_internal::FormatNumber(viscosity) + ")");
  }
  // Checked in one branch-free pass, then written in another: the coupled loop calls this at every
  // flow update.
  const auto n = static_cast<std::ptrdiff_t>(aperture.size());
  const double* a_in = aperture.data();
  const double bad = internal::SumOverShares(n, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    return CountNonPositiveOrNonFinite(begin, end, a_in);
  });
  if (bad > 0.0) {
    for (std::size_t p = 0; p < aperture.size(); ++p) {
      if (std::isfinite(aperture[p]) && aperture[p] > 0.0) continue;
      return InvalidArgument(Indexed("pipe_aperture", p) + ": must be finite and > 0 (got " +
                             flow_internal::FormatNumber(aperture[p]) + ")");
    }
  }
  coefficient_version_ = NextFlowVersionStamp();
  const double bad_conductances =
      internal::SumOverShares(n, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
        return WriteCubicLaw(begin, end, viscosity, a_in, data_.pipe_length.data(),
                             data_.pipe_aperture.data(), data_.pipe_conductance.data());
      });
  // The apertures passed above (finite and > 0) and the lengths did when they last passed (they
  // are never written after); a C that failed is left for ValidateCoefficients to name.
  StampCheckedValues(/*checked=*/bad_conductances == 0.0);
  return Status::Ok();
}

Status FlowNetwork::CheckDomainIndex(std::int32_t domain, const char* what) const {
  if (domain >= 0 && static_cast<std::size_t>(domain) < num_domains()) return Status::Ok();
  return InvalidArgument(std::string("flow.network.") + what + ": domain index " +
                         std::to_string(domain) + " out of range [0, " +
                         std::to_string(num_domains()) + ")");
}

void FlowNetwork::SetRole(std::int32_t domain, DomainRole role) {
  if (data_.role[domain] != role) {
    data_.role[domain] = role;
    topology_version_ = NextFlowVersionStamp();
  }
  coefficient_version_ = NextFlowVersionStamp();
}

Status FlowNetwork::SetFixedPressure(std::int32_t domain, double pressure) {
  SEEP_RETURN_IF_ERROR(CheckDomainIndex(domain, "SetFixedPressure"));
  if (!std::isfinite(pressure)) {
    return InvalidArgument(Indexed("pressure", static_cast<std::size_t>(domain)) +
                           ": must be finite (got " + flow_internal::FormatNumber(pressure) + ")");
  }
  SetRole(domain, DomainRole::kFixedPressure);
  data_.pressure[domain] = pressure;
  data_.source_rate[domain] = 0.0;
  StampCheckedValues(/*checked=*/true);  // a finite rate, non-zero for a source only
  return Status::Ok();
}

Status FlowNetwork::SetSource(std::int32_t domain, double rate) {
  SEEP_RETURN_IF_ERROR(CheckDomainIndex(domain, "SetSource"));
  if (!std::isfinite(rate)) {
    return InvalidArgument(Indexed("source_rate", static_cast<std::size_t>(domain)) +
                           ": must be finite (got " + flow_internal::FormatNumber(rate) + ")");
  }
  SetRole(domain, DomainRole::kSource);
  data_.source_rate[domain] = rate;
  StampCheckedValues(/*checked=*/true);  // a finite rate, non-zero for a source only
  return Status::Ok();
}

Status FlowNetwork::SetFree(std::int32_t domain) {
  SEEP_RETURN_IF_ERROR(CheckDomainIndex(domain, "SetFree"));
  SetRole(domain, DomainRole::kFree);
  data_.source_rate[domain] = 0.0;
  StampCheckedValues(/*checked=*/true);  // a finite rate, non-zero for a source only
  return Status::Ok();
}

}  // namespace seep::core
