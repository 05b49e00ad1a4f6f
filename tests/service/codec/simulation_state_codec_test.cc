// The checkpoint state codec: a snapshot survives the trip bit-exact, its bytes are the same
// every time (the result hash depends on it), and a damaged series is refused.
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
