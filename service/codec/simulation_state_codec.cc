#include "codec/simulation_state_codec.h"

#include <fmt/format.h>
#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>

#include <algorithm>
#include <cmath>

#include "codec/mechanics_state_codec.h"

namespace seep::service {
namespace {

void StageRunStateToProto(const core::StageRunState& state, v1::StageRunState* out) {
  out->set_index(state.index);
  out->set_start_step(state.start_step);
  out->set_start_time_s(state.start_time_s);
  out->set_bonds_broken(state.bonds_broken);
  out->set_peak_kinetic_energy_j(state.peak_kinetic_energy_j);
  if (state.peak_well_pressure_pa) out->set_peak_well_pressure_pa(*state.peak_well_pressure_pa);
  out->set_held_since_s(state.held_since_s);
  for (const auto& [name, value] : state.ended_metrics) {
    (*out->mutable_ended_metrics())[name] = value;
  }
}

// The numbers a stage's end conditions compare against: a damaged one would end a stage at the
// wrong step, so it is refused here rather than run with.
core::Result<core::StageRunState> StageRunStateFromProto(const v1::StageRunState& state) {
  core::StageRunState out;
  out.index = state.index();
  out.start_step = state.start_step();
  out.start_time_s = state.start_time_s();
  if (!std::isfinite(out.start_time_s) || out.start_time_s < 0.0) {
    return core::DataLoss(fmt::format(
        "state.stages.start_time_s: must be a finite time >= 0 (got {})", out.start_time_s));
  }
  out.bonds_broken = state.bonds_broken();
  out.peak_kinetic_energy_j = state.peak_kinetic_energy_j();
  if (!std::isfinite(out.peak_kinetic_energy_j) || out.peak_kinetic_energy_j < 0.0) {
    return core::DataLoss(
        fmt::format("state.stages.peak_kinetic_energy_j: must be a finite energy >= 0 (got {})",
                    out.peak_kinetic_energy_j));
  }
  if (state.has_peak_well_pressure_pa()) {
    if (!std::isfinite(state.peak_well_pressure_pa())) {
      return core::DataLoss(
          fmt::format("state.stages.peak_well_pressure_pa: must be finite (got {})",
                      state.peak_well_pressure_pa()));
    }
    out.peak_well_pressure_pa = state.peak_well_pressure_pa();
  }
  out.held_since_s = state.held_since_s();
  if (out.held_since_s != -1.0 && !(std::isfinite(out.held_since_s) && out.held_since_s >= 0.0)) {
    return core::DataLoss(
        fmt::format("state.stages.held_since_s: must be -1 (not held) or a finite time >= 0 "
                    "(got {})",
                    out.held_since_s));
  }
  // core keeps them sorted by name; a protobuf map has no order.
  out.ended_metrics.assign(state.ended_metrics().begin(), state.ended_metrics().end());
  std::sort(out.ended_metrics.begin(), out.ended_metrics.end());
  return out;
}

}  // namespace

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
  if (snapshot.stages) StageRunStateToProto(*snapshot.stages, out->mutable_stages());
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
  if (state.has_stages()) {
    SEEP_ASSIGN_OR_RETURN(snap.stages, StageRunStateFromProto(state.stages()));
  }
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
