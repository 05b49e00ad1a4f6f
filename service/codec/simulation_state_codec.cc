#include "codec/simulation_state_codec.h"

#include <fmt/format.h>
#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>

#include "codec/mechanics_state_codec.h"

namespace seep::service {

void SimulationStateToProto(const core::SimulationSnapshot& snapshot, v1::SimulationState* out) {
  out->Clear();
  out->set_step(snapshot.step);
  out->set_time_s(snapshot.time_s);
  out->mutable_pressure_pa()->Assign(snapshot.pressure.begin(), snapshot.pressure.end());
  out->set_worst_mass_balance_error(snapshot.worst_mass_balance_error);
  out->set_step_mass_balance_error(snapshot.step_mass_balance_error);
  if (const auto& ledger = snapshot.ledger) {
    v1::FluidLedger* books = out->mutable_ledger();
    books->set_injected_m2(ledger->injected_m2);
    books->mutable_left_m2()->Assign(ledger->left_m2.begin(), ledger->left_m2.end());
    books->set_compressed_m2(ledger->compressed_m2);
    books->set_pore_growth_m2(ledger->pore_growth_m2);
    books->set_redetection_m2(ledger->redetection_m2);
    books->set_handled_m2(ledger->handled_m2);
    books->set_since_step(ledger->since_step);
  }
  auto* series = out->mutable_series();
  for (const auto& c : snapshot.series.columns) series->add_columns(c);
  series->mutable_values()->Assign(snapshot.series.values.begin(), snapshot.series.values.end());
  if (snapshot.mechanics) MechanicsStateToProto(*snapshot.mechanics, out->mutable_mechanics());
}

core::Result<core::SimulationSnapshot> SimulationStateFromProto(const v1::SimulationState& state) {
  core::SimulationSnapshot snap;
  snap.step = state.step();
  snap.time_s = state.time_s();
  snap.pressure.assign(state.pressure_pa().begin(), state.pressure_pa().end());
  snap.worst_mass_balance_error = state.worst_mass_balance_error();
  snap.step_mass_balance_error = state.step_mass_balance_error();
  if (state.has_ledger()) {
    const v1::FluidLedger& books = state.ledger();
    core::FluidLedger& ledger = snap.ledger.emplace();
    ledger.injected_m2 = books.injected_m2();
    ledger.left_m2.assign(books.left_m2().begin(), books.left_m2().end());
    ledger.compressed_m2 = books.compressed_m2();
    ledger.pore_growth_m2 = books.pore_growth_m2();
    ledger.redetection_m2 = books.redetection_m2();
    ledger.handled_m2 = books.handled_m2();
    ledger.since_step = books.since_step();
  }
  snap.series.columns.assign(state.series().columns().begin(), state.series().columns().end());
  snap.series.values.assign(state.series().values().begin(), state.series().values().end());
  if (state.has_mechanics()) snap.mechanics = MechanicsStateFromProto(state.mechanics());
  const std::size_t columns = snap.series.columns.size();
  if ((columns == 0 && !snap.series.values.empty()) ||
      (columns > 0 && snap.series.values.size() % columns != 0)) {
    return core::DataLoss(
        fmt::format("state.series.values: {} values do not fill rows of {} columns",
                    snap.series.values.size(), columns));
  }
  return snap;
}

std::string SerializeSimulationState(const core::SimulationSnapshot& snapshot) {
  v1::SimulationState state;
  SimulationStateToProto(snapshot, &state);
  std::string bytes;
  {
    google::protobuf::io::StringOutputStream raw(&bytes);
    google::protobuf::io::CodedOutputStream out(&raw);
    out.SetSerializationDeterministic(true);
    state.SerializeToCodedStream(&out);
  }
  return bytes;
}

core::Result<core::SimulationSnapshot> ParseSimulationState(const std::string& bytes) {
  v1::SimulationState state;
  if (!state.ParseFromString(bytes)) {
    return core::DataLoss("checkpoint state does not parse as seep.v1.SimulationState");
  }
  return SimulationStateFromProto(state);
}

}  // namespace seep::service
