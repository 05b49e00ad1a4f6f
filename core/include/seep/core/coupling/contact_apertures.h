// Pipe apertures from the contacts' mechanical state, every coupled step (docs/physics.md §2.3,
// §2.7 step 2): a = Aperture(law, F, g) of flow/aperture_law.h (seed eqs. 2-3), C = a^3/(12 mu L).
//
// A flow pipe stands for one contact. The updater is bound once per topology to the map
// pipe -> contact id (the index into the per-contact force and gap arrays the DEM provides);
// pipes with contact id -1 (e.g. a pipe that stands for no contact) keep their aperture.
// Each Update evaluates the law for every bound pipe (a few flops each, O(pipes), no
// allocation) and writes the network only when some aperture changed, so a static packing
// leaves the network's coefficient stamp, and the solvers' factorizations, untouched.
//
// Writing: FlowNetwork offers SetApertures for all pipes at once (it re-validates and recomputes
// every conductance), so a change of one contact costs one O(pipes) pass; a per-pipe setter in
// the flow area would make it O(changed pipes).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "seep/core/flow/aperture_law.h"
#include "seep/core/flow/flow_network.h"
#include "seep/core/status.h"

namespace seep::core {

struct ContactApertureReport {
  std::int64_t pipes_changed = 0;  // bound pipes whose aperture differs from the network's
  bool network_written = false;    // SetApertures was called (coefficient stamp bumped)
};

class ContactApertureUpdater {
 public:
  // Validates the law (flow.aperture_law.<field>) and the viscosity (flow.fluid.viscosity).
  static Result<ContactApertureUpdater> Create(const ApertureLaw& law, double viscosity);

  // pipe_contact[p] for every pipe p of `network` (size num_pipes): a contact id >= 0, or -1.
  // Call again whenever the network's topology changes.
  Status Bind(const FlowNetwork& network, std::span<const std::int32_t> pipe_contact);

  // normal_force[c] (N per m, > 0 compression) and gap[c] (m, > 0 open) per contact id; both
  // must cover every bound contact id and be finite there. On error the network is untouched.
  Result<ContactApertureReport> Update(FlowNetwork& network, std::span<const double> normal_force,
                                       std::span<const double> gap);

  // The same with the force and gap already per pipe (size num_pipes; entries of pipes bound to
  // -1 are ignored).
  Result<ContactApertureReport> UpdatePerPipe(FlowNetwork& network,
                                              std::span<const double> pipe_force,
                                              std::span<const double> pipe_gap);

  // Pipes per block of UpdateByBlocks.
  static constexpr std::ptrdiff_t kPipeBlock = 256;
  // Writes force[k] and gap[k], k < count, of the pipes [begin, begin + count), count <=
  // kPipeBlock (entries of pipes bound to -1 are ignored). Called on disjoint blocks from the
  // core's threads at once, and again on one block to name a pipe whose force or gap is not
  // finite: it must give the same numbers every time.
  // A reference to such a callable (not a copy, and no allocation, as std::function could make at
  // every update); the callable must outlive the call it is passed to.
  class PipeForceGapFill {
   public:
    template <class Fill>
    PipeForceGapFill(const Fill& fill)  // implicit: callers pass a lambda
        : context_(&fill),
          call_([](const void* context, std::ptrdiff_t begin, std::ptrdiff_t count, double* force,
                   double* gap) {
            (*static_cast<const Fill*>(context))(begin, count, force, gap);
          }) {}
    void operator()(std::ptrdiff_t begin, std::ptrdiff_t count, double* force, double* gap) const {
      call_(context_, begin, count, force, gap);
    }

   private:
    const void* context_;
    void (*call_)(const void*, std::ptrdiff_t, std::ptrdiff_t, double*, double*);
  };
  // The same with the force and gap made a block at a time, each block's just before the law
  // reads them: what the coupled loop passes, reading them from the DEM's pair table, so that
  // neither it nor the updater holds them per pipe (16 bytes a pipe) and they are not written to
  // memory and read back.
  Result<ContactApertureReport> UpdateByBlocks(FlowNetwork& network, const PipeForceGapFill& fill);

  const ApertureLaw& law() const { return law_; }

 private:
  ContactApertureUpdater(const ApertureLaw& law, double viscosity)
      : law_(law), viscosity_(viscosity) {}
  Status CheckBound(std::size_t num_pipes) const;
  // After a block's law found a force or gap that is not finite: the error naming the first.
  Status NameNonFinite(const PipeForceGapFill& fill, std::size_t num_pipes) const;

  ApertureLaw law_;
  double viscosity_;
  std::vector<std::int32_t> pipe_contact_;
  std::int32_t max_contact_ = -1;
  std::vector<double> aperture_;  // scratch: the apertures written at the last Update
  std::vector<double> keep_;      // per pipe: 1 if bound to no contact (keeps its aperture)
};

}  // namespace seep::core
