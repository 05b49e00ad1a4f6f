// Running an example scene in-process through the codec, as seepd runs it, for the physics tests
// of the examples: the report's metrics by name.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "codec/scene_codec.h"
#include "seep/core/run/simulation.h"

namespace seep::physics_test {

// The decoded scene run to its end (failures are test failures; an empty map then).
inline std::map<std::string, double> RunExample(const v1::Scene& proto) {
  auto scene = service::SceneFromProto(proto);
  EXPECT_TRUE(scene.ok()) << scene.status().message();
  if (!scene.ok()) return {};
  auto sim = core::Simulation::Create(*scene);
  EXPECT_TRUE(sim.ok()) << sim.status().message();
  if (!sim.ok()) return {};
  const core::Status run = sim->Run({});
  EXPECT_TRUE(run.ok()) << run.message();
  const core::RunReport report = sim->Report();
  return {report.metrics.begin(), report.metrics.end()};
}

// A metric of the report, NaN (and a test failure) when it is missing.
inline double Metric(const std::map<std::string, double>& m, const std::string& name) {
  const auto it = m.find(name);
  EXPECT_NE(it, m.end()) << name;
  return it == m.end() ? std::nan("") : it->second;
}

}  // namespace seep::physics_test
