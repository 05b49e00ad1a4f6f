// The labels of a job (SubmitJobRequest.labels, ListJobsRequest.labels): checked here, before
// anything is stored, with an error naming the label and what is wrong with it.
#pragma once

#include <google/protobuf/map.h>

#include <string>
#include <utility>
#include <vector>

#include "seep/core/status.h"

namespace seep::service {

inline constexpr std::size_t kMaxLabels = 32;
inline constexpr std::size_t kMaxLabelKeyLength = 63;
inline constexpr std::size_t kMaxLabelValueLength = 128;

// The labels sorted by key, or INVALID_ARGUMENT "labels[\"<key>\"]: ..." for the first bad one
// (job_service.proto says what a key and a value may hold) or "labels: ..." for too many.
core::Result<std::vector<std::pair<std::string, std::string>>> CheckLabels(
    const google::protobuf::Map<std::string, std::string>& labels);

}  // namespace seep::service
