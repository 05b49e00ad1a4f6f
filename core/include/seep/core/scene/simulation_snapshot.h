// SimulationSnapshot: everything a Simulation needs to continue bit-identically on the same
// build, as plain arrays (design-anchors §5.3 "Snapshot"). What is rebuilt deterministically from
// the scene (the packing of a rigid scene, its contacts, domains and pipes, the solver's caches)
// is not stored; the scene's hash in the checkpoint header ties the two together.
//
// The service stores it as seep.v1.SimulationState (service/codec/simulation_state_codec).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace seep::core {

// A table of samples taken at fixed step numbers, so that a resumed run samples at the same
// steps as an uninterrupted one. Row-major: values[row * columns.size() + column].
struct TimeSeries {
  std::vector<std::string> columns;  // the first column is always "time_s"
  std::vector<double> values;

  std::size_t rows() const { return columns.empty() ? 0 : values.size() / columns.size(); }
};

struct SimulationSnapshot {
  std::uint64_t step = 0;                 // steps completed
  double time_s = 0.0;                    // simulated time reached
  std::vector<double> pressure;           // per flow-network node (domains then reservoirs), Pa
  double worst_mass_balance_error = 0.0;  // the largest relative step error so far
  TimeSeries series;
};

}  // namespace seep::core
