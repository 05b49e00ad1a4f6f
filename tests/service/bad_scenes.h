// Scenes that are invalid in exactly one field, shared by the codec test and the test that
// submits them to a real seepd. Each mutation turns any valid lattice scene into one whose
// rejection message must start with `field`.
#pragma once

#include <functional>
#include <ostream>
#include <vector>

#include "seep/v1/scene.pb.h"

namespace seep::testing {

struct BadScene {
  const char* name;  // a test-name suffix
  std::function<void(v1::Scene&)> mutate;
  const char* field;  // the message must start with this path
};

// Keeps test names readable where gtest prints the parameter.
inline void PrintTo(const BadScene& bad, std::ostream* os) { *os << bad.name; }

const std::vector<BadScene>& CommonBadScenes();

}  // namespace seep::testing
