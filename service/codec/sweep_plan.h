// A seep.v1.Sweep checked against its base and expanded into its points: which value every
// swept path takes in each job. The scenes themselves are made (and validated) by the service.
#pragma once

#include <google/protobuf/message.h>

#include <cstddef>
#include <string>
#include <vector>

#include "seep/core/status.h"
#include "seep/v1/job_service.pb.h"
#include "seep/v1/sweep.pb.h"

namespace seep::service {

struct SweepPoint {
  std::vector<v1::SweepSetting> settings;  // one per SweepPlan::parameters
  // Where each setting's value is written in the Sweep ("axes[0].numbers[2]",
  // "replicates.seeds[1]"), for errors about this point.
  std::vector<std::string> value_fields;
};

struct SweepPlan {
  std::vector<std::string> parameters;  // the axes' paths in order, then the seed path
  std::vector<SweepPoint> points;       // product: the last axis fastest; replicates innermost
};

// Checks every axis (its path resolves in `base` to a number, text or flag field, and every value
// fits it), the combination and the replicates, and lists the points. INVALID_ARGUMENT starts
// with the Sweep field at fault ("sweep.axes[1].path: ...", "sweep.axes[0].numbers[2]: ...").
// More than max_points points is INVALID_ARGUMENT too.
core::Result<SweepPlan> PlanSweep(const v1::Sweep& sweep, const google::protobuf::Message& base,
                                  std::size_t max_points);

// Sets the point's values in `message` (a copy of the base).
core::Status ApplySweepPoint(const SweepPlan& plan, const SweepPoint& point,
                             google::protobuf::Message& message);

// The point's settings for messages: "boundary.inlet_pressure_pa = 200000, ...".
std::string DescribeSweepPoint(const SweepPlan& plan, const SweepPoint& point);

}  // namespace seep::service
