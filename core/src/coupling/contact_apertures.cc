// Apertures of contact pipes from per-contact force and gap (see contact_apertures.h).
#include "seep/core/coupling/contact_apertures.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include "../branch_free.h"
#include "../parallel_threshold.h"

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
  keep_.resize(pipe_contact.size());
  for (std::size_t p = 0; p < pipe_contact.size(); ++p) keep_[p] = pipe_contact[p] < 0 ? 1.0 : 0.0;
  max_contact_ = max_contact;
  aperture_.assign(network.pipe_aperture().begin(), network.pipe_aperture().end());
  return Status::Ok();
}

Status ContactApertureUpdater::CheckBound(std::size_t num_pipes) const {
  if (num_pipes == pipe_contact_.size()) return Status::Ok();
  return FailedPrecondition("coupling.contact_apertures: the network has " +
                            std::to_string(num_pipes) + " pipes but the updater was bound to " +
                            std::to_string(pipe_contact_.size()) +
                            " (call Bind after every topology change)");
}

Result<ContactApertureReport> ContactApertureUpdater::Update(FlowNetwork& network,
                                                             std::span<const double> normal_force,
                                                             std::span<const double> gap) {
  const std::size_t num_pipes = network.num_pipes();
  SEEP_RETURN_IF_ERROR(CheckBound(num_pipes));
  const std::size_t needed = static_cast<std::size_t>(max_contact_ + 1);
  if (normal_force.size() < needed || gap.size() < needed) {
    return InvalidArgument("coupling.contact_apertures: normal_force and gap have " +
                           std::to_string(normal_force.size()) + " and " +
                           std::to_string(gap.size()) + " entries; contact ids up to " +
                           std::to_string(max_contact_) + " are bound");
  }
  // Per contact -> per pipe, a block at a time (pipes bound to no contact read 0: ignored).
  const std::int32_t* pipe_contact = pipe_contact_.data();
  return UpdateByBlocks(
      network, [&](std::ptrdiff_t begin, std::ptrdiff_t count, double* force, double* gap_out) {
        for (std::ptrdiff_t k = 0; k < count; ++k) {
          const std::int32_t c = pipe_contact[begin + k];
          force[k] = c < 0 ? 0.0 : normal_force[static_cast<std::size_t>(c)];
          gap_out[k] = c < 0 ? 0.0 : gap[static_cast<std::size_t>(c)];
        }
      });
}

Result<ContactApertureReport> ContactApertureUpdater::UpdatePerPipe(
    FlowNetwork& network, std::span<const double> pipe_force, std::span<const double> pipe_gap) {
  const std::size_t num_pipes = network.num_pipes();
  SEEP_RETURN_IF_ERROR(CheckBound(num_pipes));
  if (pipe_force.size() != num_pipes || pipe_gap.size() != num_pipes) {
    return InvalidArgument("coupling.contact_apertures: pipe_force and pipe_gap have " +
                           std::to_string(pipe_force.size()) + " and " +
                           std::to_string(pipe_gap.size()) + " entries, expected " +
                           std::to_string(num_pipes) + " (one per pipe)");
  }
  return UpdateByBlocks(
      network, [&](std::ptrdiff_t begin, std::ptrdiff_t count, double* force, double* gap) {
        std::copy_n(pipe_force.begin() + begin, count, force);
        std::copy_n(pipe_gap.begin() + begin, count, gap);
      });
}

namespace {

// The law's apertures of `count` pipes into `out` (a pipe to keep keeps `current`); adds how many
// changed and how many had a force or gap that is not finite.
void LawRange(std::ptrdiff_t count, const ApertureLaw law, const double* __restrict current,
              const double* __restrict force, const double* __restrict gap,
              const double* __restrict keep, double* __restrict out, double* changed_count,
              double* bad_count) {
  // Branch-free so that it vectorises (Aperture selects between its branches).
  double changed = 0.0, bad = 0.0;
#pragma omp simd reduction(+ : changed, bad)
  for (std::ptrdiff_t p = 0; p < count; ++p) {
    const double f = force[p], g = gap[p];
    const bool finite =
        (keep[p] != 0.0) | (internal::FiniteBranchFree(f) & internal::FiniteBranchFree(g));
    bad += finite ? 0.0 : 1.0;
    // The law for every pipe, kept ones too, then a select: no branch in the loop, which then
    // vectorises (with -fno-trapping-math, core/CMakeLists.txt, GCC computes both sides of the
    // law's choice between force and gap; before, this loop was scalar with a mispredicted
    // branch per pipe, 8 % of a coupled step on the bench bed).
    const double by_law = Aperture(law, f, g);
    const double a = keep[p] != 0.0 ? current[p] : by_law;
    out[p] = a;
    changed += a != current[p] ? 1.0 : 0.0;
  }
  *changed_count += changed;
  *bad_count += bad;
}

}  // namespace

Result<ContactApertureReport> ContactApertureUpdater::UpdateByBlocks(FlowNetwork& network,
                                                                     const PipeForceGapFill& fill) {
  const std::size_t num_pipes = network.num_pipes();
  SEEP_RETURN_IF_ERROR(CheckBound(num_pipes));
  const double* current = network.pipe_aperture().data();
  const double* keep = keep_.data();
  double* out = aperture_.data();
  const ApertureLaw law = law_;
  // The counts are sums of 0s and 1s: exact in any order, so threads change no bit.
  const auto n = static_cast<std::ptrdiff_t>(num_pipes);
  const std::ptrdiff_t blocks = (n + kPipeBlock - 1) / kPipeBlock;
  std::atomic<double> team_changed{0.0}, team_bad{0.0};
  internal::RunOnCoreThreads(n, [&](const internal::TeamMember& member) {
    const auto [first_block, last_block] = member.Share(blocks);
    // The block's force and gap stay in L1 between the fill and the law.
    alignas(64) double force[kPipeBlock], gap[kPipeBlock];
    double my_changed = 0.0, my_bad = 0.0;
    for (std::ptrdiff_t b = first_block; b < last_block; ++b) {
      const std::ptrdiff_t begin = b * kPipeBlock;
      const std::ptrdiff_t count = std::min(kPipeBlock, n - begin);
      fill(begin, count, force, gap);
      LawRange(count, law, current + begin, force, gap, keep + begin, out + begin, &my_changed,
               &my_bad);
    }
    team_changed.fetch_add(my_changed, std::memory_order_relaxed);
    team_bad.fetch_add(my_bad, std::memory_order_relaxed);
  });
  if (team_bad.load(std::memory_order_relaxed) > 0.0) return NameNonFinite(fill, num_pipes);
  ContactApertureReport report;
  report.pipes_changed = static_cast<std::int64_t>(team_changed.load(std::memory_order_relaxed));
  if (report.pipes_changed == 0) return report;
  SEEP_RETURN_IF_ERROR(network.SetApertures(aperture_, viscosity_));
  report.network_written = true;
  return report;
}

Status ContactApertureUpdater::NameNonFinite(const PipeForceGapFill& fill,
                                             std::size_t num_pipes) const {
  double force[kPipeBlock], gap[kPipeBlock];
  const auto n = static_cast<std::ptrdiff_t>(num_pipes);
  for (std::ptrdiff_t begin = 0; begin < n; begin += kPipeBlock) {
    const std::ptrdiff_t count = std::min(kPipeBlock, n - begin);
    fill(begin, count, force, gap);
    for (std::ptrdiff_t k = 0; k < count; ++k) {
      const auto p = static_cast<std::size_t>(begin + k);
      if (keep_[p] != 0.0 || (std::isfinite(force[k]) && std::isfinite(gap[k]))) continue;
      return InvalidArgument("coupling.contact_apertures: contact " +
                             std::to_string(pipe_contact_[p]) + " (pipe " + std::to_string(p) +
                             "): normal_force and gap must be finite (got " +
                             std::to_string(force[k]) + ", " + std::to_string(gap[k]) + ")");
    }
  }
  // The fill gave other numbers the second time: a broken contract, not bad input.
  return Internal("coupling.contact_apertures: a force or gap was not finite, then was");
}

}  // namespace seep::core
