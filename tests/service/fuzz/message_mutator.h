// Field-by-field mutation of any protobuf message through reflection: one field somewhere in
// the message's tree, chosen at random, is given an odd value for its type (0, negative, NaN,
// infinities, 1e300, the integer limits, unknown enum values, empty, huge or control-character
// strings, huge or emptied repeated fields, a cleared or emptied message, another oneof member).
// Reflection reaches every field the proto has, those added later included.
#pragma once

#include <google/protobuf/message.h>

#include <string>

#include "fuzz_random.h"

namespace seep::fuzz {

struct MutationLimits {
  // Elements a repeated field may be grown to; the request stays below seepd's message limit.
  int max_repeated = 200'000;
  // Characters a string may be grown to.
  int max_string = 100'000;
};

// Mutates one field of `message` (under `root`, the message's own path in the request, e.g.
// "scene"); returns what it did, e.g. "scene.packing.lattice.columns = 4294967295".
std::string MutateOnce(google::protobuf::Message& message, const std::string& root,
                       FuzzRandom& random, const MutationLimits& limits = {});

// An odd double: an extreme, a non-finite value, or `current` scaled by a power of ten.
double OddDouble(double current, FuzzRandom& random);

}  // namespace seep::fuzz
