// The fuzzer's requests: for a seed, one call of seep.v1.SeepService and its wire bytes. Scenes,
// calibrations and sweeps start from the valid bases (base_requests.h) and have one to a few
// fields mutated (message_mutator.h), at any depth of the request (its request_id, labels,
// priority and fork fields included); the id calls get the ids of jobs and sweeps that exist,
// of the wrong kind, or odd ones (empty, overlong, control characters, SQL); and some requests
// are the bytes of a valid one flipped, cut, grown or sent to another method.
#pragma once

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fuzz_random.h"
#include "seep/v1/scene.pb.h"

namespace seep::fuzz {

// What the fuzzer knows of the server's contents, from the answers it got.
struct FuzzContext {
  std::vector<std::string> job_ids;
  std::vector<std::string> sweep_ids;
  // Jobs whose scene has stages, with that scene: the parents a fork may name.
  std::vector<std::pair<std::string, v1::Scene>> staged_jobs;
  std::vector<std::string> request_ids;  // sent before: a repeat returns what the first made
};

// What the generator leaves out, and why (each run prints it).
struct GeneratorLimits {
  // Scenes of more disks than this, up to the 20,000,000 the codec admits, are drawn again:
  // valid but large, they spend their set-up outside --job-time-limit-s and hold a worker and
  // gigabytes for minutes (issue 50, item 2: an admission estimate and a set-up under the time
  // limit are pending). 0: none left out. Counts above the codec's limit are still sent.
  std::uint64_t max_disks = 0;
  // Sweeps of more jobs than this, up to the 10,000 a sweep may hold, are drawn again: valid, but
  // thousands of queued jobs turn the run into a throughput test. 0: none left out.
  std::uint64_t max_sweep_jobs = 0;
};

struct FuzzRequest {
  std::string method;                                  // e.g. "SubmitJob"
  const google::protobuf::Descriptor* type = nullptr;  // the method's request message
  std::unique_ptr<google::protobuf::Message> message;  // null for raw bytes that decode as none
  std::string bytes;                                   // what goes on the wire
  std::string id;          // the id (or job_id) field, for the refusal rule; "" when none
  std::string what;        // a line saying how the request was made
  bool streaming = false;  // WatchJob
  int redrawn = 0;         // requests drawn and left out (GeneratorLimits) before this one
};

// seep.v1.SeepService's method `name`, from the generated descriptors (std::logic_error when it has
// none of that name).
const google::protobuf::MethodDescriptor& SeepMethod(const std::string& name);

// The request a seed makes, given what the server holds.
FuzzRequest GenerateRequest(FuzzRandom& random, const FuzzContext& context,
                            const GeneratorLimits& limits = {});

// The most disks a scene of the request (a sweep's every point) can have; 0 when it has none.
std::uint64_t LargestPacking(const FuzzRequest& request);
// The jobs a SubmitSweep request asks for (its axes combined, times its replicates); 0 for
// other requests.
std::uint64_t SweepJobCount(const FuzzRequest& request);

}  // namespace seep::fuzz
