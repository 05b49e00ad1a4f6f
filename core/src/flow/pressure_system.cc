#include "pressure_system.h"

#include <algorithm>
#include <string>

namespace seep::core::flow_internal {

namespace {
// Index of (row, col) in a compressed column-major matrix; -1 if absent.
int FindSlot(const SparseMatrix& m, int row, int col) {
  const int* begin = m.innerIndexPtr() + m.outerIndexPtr()[col];
  const int* end = m.innerIndexPtr() + m.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(begin, end, row);
  if (it == end || *it != row) return -1;
  return static_cast<int>(it - m.innerIndexPtr());
}
}  // namespace

Status PressureSystem::SyncTopology(const FlowNetwork& network,
                                    std::span<const std::uint8_t> pinned) {
  if (network.topology_version() == topology_key_) return Status::Ok();
  const std::size_t nd = network.num_domains();
  if (!pinned.empty() && pinned.size() != nd) {
    return Internal("flow.pressure_system: pinned mask size mismatch");
  }
  pinned_.assign(pinned.begin(), pinned.end());
  const auto role = network.role();
  unknown_of_domain_.assign(nd, -1);
  domain_of_unknown_.clear();
  for (std::size_t d = 0; d < nd; ++d) {
    if (role[d] == DomainRole::kFixedPressure || is_pinned(d)) continue;
    unknown_of_domain_[d] = static_cast<std::int32_t>(domain_of_unknown_.size());
    domain_of_unknown_.push_back(static_cast<std::int32_t>(d));
  }
  const int n = static_cast<int>(domain_of_unknown_.size());
  const auto pa = network.pipe_domain_a();
  const auto pb = network.pipe_domain_b();
  const std::size_t np = network.num_pipes();

  std::vector<Eigen::Triplet<double, int>> triplets;
  triplets.reserve(static_cast<std::size_t>(n) + np);
  for (int u = 0; u < n; ++u) triplets.emplace_back(u, u, 0.0);
  for (std::size_t p = 0; p < np; ++p) {
    const int ua = unknown_of_domain_[pa[p]];
    const int ub = unknown_of_domain_[pb[p]];
    if (ua >= 0 && ub >= 0) triplets.emplace_back(std::max(ua, ub), std::min(ua, ub), 0.0);
  }
  matrix_ = SparseMatrix(n, n);
  matrix_.setFromTriplets(triplets.begin(), triplets.end());
  matrix_.makeCompressed();

  diagonal_slot_.resize(static_cast<std::size_t>(n));
  for (int u = 0; u < n; ++u) diagonal_slot_[u] = FindSlot(matrix_, u, u);
  pipe_slot_a_.assign(np, -1);
  pipe_slot_b_.assign(np, -1);
  pipe_slot_off_.assign(np, -1);
  for (std::size_t p = 0; p < np; ++p) {
    const int ua = unknown_of_domain_[pa[p]];
    const int ub = unknown_of_domain_[pb[p]];
    if (ua >= 0) pipe_slot_a_[p] = diagonal_slot_[ua];
    if (ub >= 0) pipe_slot_b_[p] = diagonal_slot_[ub];
    if (ua >= 0 && ub >= 0)
      pipe_slot_off_[p] = FindSlot(matrix_, std::max(ua, ub), std::min(ua, ub));
  }

  values_valid_ = false;
  topology_key_ = 0;  // stays invalid if the analysis fails
  if (n > 0) {
    SEEP_RETURN_IF_ERROR(factorization_.Analyze(matrix_));
    ++stats_.analyses;
  }
  topology_key_ = network.topology_version();
  return Status::Ok();
}

Status PressureSystem::SyncValues(const FlowNetwork& network,
                                  std::span<const double> storage_diagonal,
                                  std::uint64_t coefficient_stamp, double dt_key) {
  if (values_valid_ && coefficient_stamp == coefficient_key_ && dt_key == dt_key_) {
    return Status::Ok();
  }
  values_valid_ = false;
  double* values = matrix_.valuePtr();
  std::fill(values, values + matrix_.nonZeros(), 0.0);
  if (!storage_diagonal.empty()) {
    for (std::size_t u = 0; u < domain_of_unknown_.size(); ++u) {
      values[diagonal_slot_[u]] += storage_diagonal[domain_of_unknown_[u]];
    }
  }
  const auto c = network.pipe_conductance();
  for (std::size_t p = 0; p < c.size(); ++p) {
    if (pipe_slot_a_[p] >= 0) values[pipe_slot_a_[p]] += c[p];
    if (pipe_slot_b_[p] >= 0) values[pipe_slot_b_[p]] += c[p];
    if (pipe_slot_off_[p] >= 0) values[pipe_slot_off_[p]] -= c[p];
  }
  if (num_unknowns() > 0) {
    SEEP_RETURN_IF_ERROR(factorization_.Factorize(matrix_));
    ++stats_.factorizations;
  }
  coefficient_key_ = coefficient_stamp;
  dt_key_ = dt_key;
  values_valid_ = true;
  return Status::Ok();
}

void PressureSystem::AddKnownCoupling(const FlowNetwork& network, Eigen::VectorXd& rhs) const {
  const auto pa = network.pipe_domain_a();
  const auto pb = network.pipe_domain_b();
  const auto c = network.pipe_conductance();
  const auto pressure = network.pressure();
  for (std::size_t p = 0; p < c.size(); ++p) {
    const int ua = unknown_of_domain_[pa[p]];
    const int ub = unknown_of_domain_[pb[p]];
    if ((ua >= 0) == (ub >= 0)) continue;  // both unknown (matrix) or both known (no equation)
    if (ua >= 0) {
      if (!is_pinned(pb[p])) rhs[ua] += c[p] * pressure[pb[p]];
    } else {
      if (!is_pinned(pa[p])) rhs[ub] += c[p] * pressure[pa[p]];
    }
  }
}

Status PressureSystem::Solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x) {
  if (num_unknowns() == 0) {
    x.resize(0);
    return Status::Ok();
  }
  SEEP_RETURN_IF_ERROR(factorization_.Solve(rhs, x));
  ++stats_.solves;
  return Status::Ok();
}

}  // namespace seep::core::flow_internal
