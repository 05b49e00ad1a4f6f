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
