// The checkpoint state codec: a snapshot survives the trip bit-exact, its bytes are the same
// every time (the result hash depends on it), and a damaged series or stage state is refused.
#include "codec/simulation_state_codec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

namespace seep::service {
namespace {

core::SimulationSnapshot Sample() {
  core::SimulationSnapshot s;
  s.step = 123456789012ull;
  s.time_s = 0.1 + 0.2;  // not exactly representable: checks the bits, not the decimal
  s.pressure = {1e5, -0.0, std::numeric_limits<double>::denorm_min(), 3.0e-310, 42.0};
  s.worst_mass_balance_error = 1.25e-15;
  s.series.columns = {"time_s", "inflow_m2_per_s"};
  s.series.values = {0.0, 1.0, 0.5, 2.0};
  core::FluidLedger& books = s.ledger.emplace();
  books.injected_m2 = 0.1 + 0.7;
  books.left_m2 = {1e-9 / 3.0, -0.0, -2.5e-300};
  books.compressed_m2 = 1.0 / 7.0;
  books.pore_growth_m2 = -1e-17;
  books.redetection_m2 = std::numeric_limits<double>::denorm_min();
  books.handled_m2 = 2.0 / 3.0;
  books.since_step = 77;
  return s;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(SimulationStateCodec, RoundTripsBitExact) {
  const core::SimulationSnapshot in = Sample();
  auto out = ParseSimulationState(SerializeSimulationState(in));
  ASSERT_TRUE(out.ok()) << out.status().ToString();
  EXPECT_EQ(out->step, in.step);
  EXPECT_TRUE(SameBits(out->time_s, in.time_s));
  ASSERT_EQ(out->pressure.size(), in.pressure.size());
  for (std::size_t i = 0; i < in.pressure.size(); ++i) {
    EXPECT_TRUE(SameBits(out->pressure[i], in.pressure[i])) << i;
  }
  EXPECT_TRUE(SameBits(out->worst_mass_balance_error, in.worst_mass_balance_error));
  EXPECT_EQ(out->series.columns, in.series.columns);
  EXPECT_EQ(out->series.values, in.series.values);
  ASSERT_TRUE(out->ledger.has_value());
  const core::FluidLedger& got = *out->ledger;
  const core::FluidLedger& want = *in.ledger;
  ASSERT_EQ(got.left_m2.size(), want.left_m2.size());
  for (std::size_t b = 0; b < want.left_m2.size(); ++b) {
    EXPECT_TRUE(SameBits(got.left_m2[b], want.left_m2[b])) << b;
  }
  for (const auto field : {&core::FluidLedger::injected_m2, &core::FluidLedger::compressed_m2,
                           &core::FluidLedger::pore_growth_m2, &core::FluidLedger::redetection_m2,
                           &core::FluidLedger::handled_m2}) {
    EXPECT_TRUE(SameBits(got.*field, want.*field));
  }
  EXPECT_EQ(got.since_step, want.since_step);
}

// A state written before the books existed has none; it reads back without them.
TEST(SimulationStateCodec, StateWithoutBooksReadsBackWithout) {
  core::SimulationSnapshot in = Sample();
  in.ledger.reset();
  auto out = ParseSimulationState(SerializeSimulationState(in));
  ASSERT_TRUE(out.ok()) << out.status().ToString();
  EXPECT_FALSE(out->ledger.has_value());
}

core::SimulationSnapshot StagedSample() {
  core::SimulationSnapshot s = Sample();
  core::StageRunState& stages = s.stages.emplace();
  stages.index = 2;
  stages.start_step = 40000000001ull;
  stages.start_time_s = 0.1 + 0.2;
  stages.bonds_broken = 17;
  stages.peak_kinetic_energy_j = 1.0 / 3.0;
  stages.peak_well_pressure_pa = 2.5e6 + 1.0 / 7.0;
  stages.held_since_s = 1e-3 / 3.0;
  stages.ended_metrics = {{"stage1_duration_s", 0.25},
                          {"stage1_steps", 1234.0},
                          {"stage2_peak_well_pressure_pa", 3.0e6 / 7.0}};
  return s;
}

// A staged run's state survives the trip bit-exact, its ended metrics in core's (name) order.
TEST(SimulationStateCodec, StageRunStateRoundTripsBitExact) {
  const core::SimulationSnapshot in = StagedSample();
  auto out = ParseSimulationState(SerializeSimulationState(in));
  ASSERT_TRUE(out.ok()) << out.status().ToString();
  ASSERT_TRUE(out->stages.has_value());
  const core::StageRunState& got = *out->stages;
  const core::StageRunState& want = *in.stages;
  EXPECT_EQ(got.index, want.index);
  EXPECT_EQ(got.start_step, want.start_step);
  EXPECT_TRUE(SameBits(got.start_time_s, want.start_time_s));
  EXPECT_EQ(got.bonds_broken, want.bonds_broken);
  EXPECT_TRUE(SameBits(got.peak_kinetic_energy_j, want.peak_kinetic_energy_j));
  ASSERT_TRUE(got.peak_well_pressure_pa.has_value());
  EXPECT_TRUE(SameBits(*got.peak_well_pressure_pa, *want.peak_well_pressure_pa));
  EXPECT_TRUE(SameBits(got.held_since_s, want.held_since_s));
  ASSERT_EQ(got.ended_metrics.size(), want.ended_metrics.size());
  for (std::size_t k = 0; k < want.ended_metrics.size(); ++k) {
    EXPECT_EQ(got.ended_metrics[k].first, want.ended_metrics[k].first);
    EXPECT_TRUE(SameBits(got.ended_metrics[k].second, want.ended_metrics[k].second)) << k;
  }
  EXPECT_EQ(SerializeSimulationState(in), SerializeSimulationState(StagedSample()));
}

// No peak yet and not held: the peak stays unset and -1 comes back as -1. A scene without stages
// has no stage state.
TEST(SimulationStateCodec, StageRunStateKeepsUnsetPeakAndNotHeld) {
  core::SimulationSnapshot in = StagedSample();
  in.stages->peak_well_pressure_pa.reset();
  in.stages->held_since_s = -1.0;
  in.stages->ended_metrics.clear();
  auto out = ParseSimulationState(SerializeSimulationState(in));
  ASSERT_TRUE(out.ok()) << out.status().ToString();
  ASSERT_TRUE(out->stages.has_value());
  EXPECT_FALSE(out->stages->peak_well_pressure_pa.has_value());
  EXPECT_EQ(out->stages->held_since_s, -1.0);
  EXPECT_TRUE(out->stages->ended_metrics.empty());
  auto plain = ParseSimulationState(SerializeSimulationState(Sample()));
  ASSERT_TRUE(plain.ok()) << plain.status().ToString();
  EXPECT_FALSE(plain->stages.has_value());
}

constexpr double kStateNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kStateInf = std::numeric_limits<double>::infinity();

// Numbers the end conditions compare against that no run could have written are DATA_LOSS
// naming the field.
TEST(SimulationStateCodec, DamagedStageRunStateIsDataLossNamingTheField) {
  const struct {
    void (*damage)(core::StageRunState&);
    const char* field;
  } cases[] = {
      {[](core::StageRunState& s) { s.start_time_s = -1.0; }, "state.stages.start_time_s:"},
      {[](core::StageRunState& s) { s.start_time_s = kStateNaN; }, "state.stages.start_time_s:"},
      {[](core::StageRunState& s) { s.peak_kinetic_energy_j = kStateInf; },
       "state.stages.peak_kinetic_energy_j:"},
      {[](core::StageRunState& s) { s.peak_well_pressure_pa = kStateNaN; },
       "state.stages.peak_well_pressure_pa:"},
      {[](core::StageRunState& s) { s.held_since_s = -0.5; }, "state.stages.held_since_s:"},
      {[](core::StageRunState& s) { s.held_since_s = kStateInf; }, "state.stages.held_since_s:"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.field);
    core::SimulationSnapshot in = StagedSample();
    c.damage(*in.stages);
    auto parsed = ParseSimulationState(SerializeSimulationState(in));
    ASSERT_FALSE(parsed.ok());
    EXPECT_EQ(parsed.status().code(), core::StatusCode::kDataLoss);
    EXPECT_EQ(parsed.status().message().rfind(c.field, 0), 0u) << parsed.status().message();
  }
}

// The stability guards' memory of a moving run (core/run/energy_guard.h, reversal_guard.h) survives
// the trip bit-exact, so that a resumed run fails, or not, at the uninterrupted run's step; a
// state written before the reversal guard was kept reads back without it (the guard restarts).
TEST(SimulationStateCodec, TheStabilityGuardsRoundTripBitExact) {
  core::SimulationSnapshot in = Sample();
  core::MechanicsSnapshot& m = in.mechanics.emplace();
  core::EnergyGuardState& energy = m.energy_guard.emplace();
  energy.initial_j = 1.0 / 3.0;
  energy.gravity_moment_j = -2.0 / 7.0;
  energy.work_j = 1e-300 / 3.0;
  energy.fluid_work_j = 0.1 + 0.2;
  energy.wall_load = {1.0 / 9.0, -0.0};
  energy.held_fx = {3.0 / 11.0};
  energy.held_fy = {-5.0 / 13.0};
  energy.fluid_fx = {1e-20 / 3.0, 2.0};
  energy.fluid_fy = {-1e-20 / 7.0, -2.0};
  core::ReversalGuardState& reversal = m.reversal_guard.emplace();
  reversal.disk_checks = 1;
  reversal.wall_speed = {0.02 / 3.0, -0.0};
  reversal.wall_reversals = {31, 0};
  auto out = ParseSimulationState(SerializeSimulationState(in));
  ASSERT_TRUE(out.ok()) << out.status().ToString();
  ASSERT_TRUE(out->mechanics && out->mechanics->energy_guard && out->mechanics->reversal_guard);
  const core::EnergyGuardState& e = *out->mechanics->energy_guard;
  for (const auto field :
       {&core::EnergyGuardState::initial_j, &core::EnergyGuardState::gravity_moment_j,
        &core::EnergyGuardState::work_j, &core::EnergyGuardState::fluid_work_j}) {
    EXPECT_TRUE(SameBits(e.*field, energy.*field));
  }
  for (const auto field : {&core::EnergyGuardState::wall_load, &core::EnergyGuardState::held_fx,
                           &core::EnergyGuardState::held_fy, &core::EnergyGuardState::fluid_fx,
                           &core::EnergyGuardState::fluid_fy}) {
    ASSERT_EQ((e.*field).size(), (energy.*field).size());
    for (std::size_t k = 0; k < (e.*field).size(); ++k) {
      EXPECT_TRUE(SameBits((e.*field)[k], (energy.*field)[k])) << k;
    }
  }
  const core::ReversalGuardState& r = *out->mechanics->reversal_guard;
  EXPECT_EQ(r.disk_checks, reversal.disk_checks);
  ASSERT_EQ(r.wall_speed.size(), reversal.wall_speed.size());
  for (std::size_t k = 0; k < r.wall_speed.size(); ++k) {
    EXPECT_TRUE(SameBits(r.wall_speed[k], reversal.wall_speed[k])) << k;
  }
  EXPECT_EQ(r.wall_reversals, reversal.wall_reversals);

  m.reversal_guard.reset();
  auto older = ParseSimulationState(SerializeSimulationState(in));
  ASSERT_TRUE(older.ok()) << older.status().ToString();
  ASSERT_TRUE(older->mechanics);
  EXPECT_FALSE(older->mechanics->reversal_guard.has_value());
  EXPECT_TRUE(older->mechanics->energy_guard.has_value());
}

TEST(SimulationStateCodec, SerializationIsDeterministic) {
  EXPECT_EQ(SerializeSimulationState(Sample()), SerializeSimulationState(Sample()));
  core::SimulationSnapshot other = Sample();
  other.pressure[4] = std::nextafter(42.0, 43.0);
  EXPECT_NE(SerializeSimulationState(other), SerializeSimulationState(Sample()));
}

TEST(SimulationStateCodec, RaggedSeriesAndGarbageAreDataLoss) {
  core::SimulationSnapshot ragged = Sample();
  ragged.series.values.push_back(7.0);
  auto parsed = ParseSimulationState(SerializeSimulationState(ragged));
  EXPECT_EQ(parsed.status().code(), core::StatusCode::kDataLoss);
  EXPECT_NE(parsed.status().message().find("state.series.values"), std::string::npos);
  EXPECT_EQ(ParseSimulationState(std::string("\xff\xff\xff", 3)).status().code(),
            core::StatusCode::kDataLoss);
}

}  // namespace
}  // namespace seep::service
