#include "codec/sweep_plan.h"

#include <fmt/format.h>

#include <algorithm>
#include <memory>
#include <optional>

#include "codec/field_path.h"

namespace seep::service {
namespace {

// One swept path with its values, as checked: where they are written in the Sweep.
struct CheckedAxis {
  std::string path;
  std::vector<v1::SweepSetting> values;
  std::vector<std::string> value_fields;
};

core::Status Prefixed(std::string_view field, const core::Status& status) {
  return core::InvalidArgument(fmt::format("sweep.{}: {}", field, status.message()));
}

// The path resolves on a scratch copy of the base, and every value is set there in turn.
core::Status CheckValues(const google::protobuf::Message& base, std::string_view path_field,
                         CheckedAxis& axis) {
  std::unique_ptr<google::protobuf::Message> scratch(base.New());
  scratch->CopyFrom(base);
  const core::Result<FieldSlot> slot = ResolveFieldPath(*scratch, axis.path);
  if (!slot.ok()) {
    return Prefixed(path_field, core::InvalidArgument(
                                    fmt::format("'{}': {}", axis.path, slot.status().message())));
  }
  for (std::size_t j = 0; j < axis.values.size(); ++j) {
    if (core::Status set = SetFieldValue(*slot, axis.values[j]); !set.ok()) {
      return Prefixed(axis.value_fields[j], core::InvalidArgument(fmt::format(
                                                "{} = {}: {}", axis.path,
                                                SettingValueText(axis.values[j]), set.message())));
    }
  }
  return core::Status::Ok();
}

core::Result<CheckedAxis> CheckAxis(const v1::SweepAxis& wire, std::size_t i,
                                    const google::protobuf::Message& base) {
  const std::string field = fmt::format("axes[{}]", i);
  CheckedAxis axis;
  axis.path = wire.path();
  const int lists = (wire.numbers_size() > 0) + (wire.texts_size() > 0) + (wire.flags_size() > 0);
  if (lists != 1) {
    return core::InvalidArgument(
        fmt::format("sweep.{}: give the values of '{}' in exactly one of numbers, texts or flags "
                    "(it has {} non-empty lists)",
                    field, axis.path, lists));
  }
  const auto add = [&](const char* list, int j, v1::SweepSetting value) {
    value.set_path(axis.path);
    axis.values.push_back(std::move(value));
    axis.value_fields.push_back(fmt::format("{}.{}[{}]", field, list, j));
  };
  for (int j = 0; j < wire.numbers_size(); ++j) {
    v1::SweepSetting v;
    v.set_number(wire.numbers(j));
    add("numbers", j, std::move(v));
  }
  for (int j = 0; j < wire.texts_size(); ++j) {
    v1::SweepSetting v;
    v.set_text(wire.texts(j));
    add("texts", j, std::move(v));
  }
  for (int j = 0; j < wire.flags_size(); ++j) {
    v1::SweepSetting v;
    v.set_flag(wire.flags(j));
    add("flags", j, std::move(v));
  }
  SEEP_RETURN_IF_ERROR(CheckValues(base, field + ".path", axis));
  return axis;
}

// The seeds of the replicates: listed, or `count` from the base's own seed on.
core::Result<CheckedAxis> CheckReplicates(const v1::SweepReplicates& wire,
                                          const google::protobuf::Message& base) {
  CheckedAxis axis;
  axis.path = wire.seed_path();
  if (axis.path.empty()) return core::InvalidArgument("sweep.replicates.seed_path: is required");
  if ((wire.count() > 0) == (wire.seeds_size() > 0)) {
    return core::InvalidArgument(
        "sweep.replicates: give either count (seeds from the base's own on) or seeds, not both "
        "nor neither");
  }
  std::unique_ptr<google::protobuf::Message> scratch(base.New());
  scratch->CopyFrom(base);
  const core::Result<FieldSlot> slot = ResolveFieldPath(*scratch, axis.path);
  if (!slot.ok()) {
    return core::InvalidArgument(
        fmt::format("sweep.replicates.seed_path: '{}': {}", axis.path, slot.status().message()));
  }
  const core::Result<std::uint64_t> first = ReadUnsignedValue(*slot);
  if (!first.ok()) {
    return core::InvalidArgument(
        fmt::format("sweep.replicates.seed_path: '{}': {}", axis.path, first.status().message()));
  }
  for (std::uint32_t k = 0; k < wire.count(); ++k) {
    v1::SweepSetting v;
    v.set_path(axis.path);
    v.set_number(static_cast<double>(*first + k));
    axis.values.push_back(std::move(v));
    axis.value_fields.push_back("replicates.count");
  }
  for (int j = 0; j < wire.seeds_size(); ++j) {
    v1::SweepSetting v;
    v.set_path(axis.path);
    v.set_number(static_cast<double>(wire.seeds(j)));
    axis.values.push_back(std::move(v));
    axis.value_fields.push_back(fmt::format("replicates.seeds[{}]", j));
  }
  SEEP_RETURN_IF_ERROR(CheckValues(base, "replicates.seed_path", axis));
  return axis;
}

// How many points the axes make (before replicates), or why they cannot be combined.
core::Result<std::size_t> CombinedCount(const v1::Sweep& sweep,
                                        const std::vector<CheckedAxis>& axes) {
  if (axes.empty()) return std::size_t{1};
  if (sweep.combine() == v1::SWEEP_COMBINE_ZIP) {
    for (std::size_t i = 1; i < axes.size(); ++i) {
      if (axes[i].values.size() != axes[0].values.size()) {
        return core::InvalidArgument(fmt::format(
            "sweep.axes[{}]: a zipped sweep needs axes of equal length: axes[0] has {} values, "
            "axes[{}] has {}",
            i, axes[0].values.size(), i, axes[i].values.size()));
      }
    }
    return axes[0].values.size();
  }
  if (sweep.combine() != v1::SWEEP_COMBINE_PRODUCT) {
    return core::InvalidArgument(
        fmt::format("sweep.combine: must be SWEEP_COMBINE_PRODUCT or SWEEP_COMBINE_ZIP (got {})",
                    v1::SweepCombine_Name(sweep.combine())));
  }
  std::size_t count = 1;
  for (const CheckedAxis& axis : axes) count *= axis.values.size();
  return count;
}

// How many values an axis lists on the wire (its one list, or all when it wrongly has several).
std::size_t ListedValues(const v1::SweepAxis& axis) {
  return static_cast<std::size_t>(axis.numbers_size()) +
         static_cast<std::size_t>(axis.texts_size()) + static_cast<std::size_t>(axis.flags_size());
}

// The number of jobs, read from the request's own list sizes and replicates.count before any
// value is copied or checked: a count of 2^32-1 or a list of millions of seeds is refused before
// anything proportional to it is built. Counted in floating point, so no product overflows.
core::Status CheckJobCount(const v1::Sweep& sweep, std::size_t max_points) {
  const auto too_many = [&](std::string_view field, std::size_t n, std::string_view what) {
    return core::InvalidArgument(fmt::format(
        "sweep.{}: {} {} exceed the limit of {} jobs per sweep", field, n, what, max_points));
  };
  const v1::SweepReplicates& wire = sweep.replicates();
  if (wire.count() > max_points) return too_many("replicates.count", wire.count(), "replicates");
  if (static_cast<std::size_t>(wire.seeds_size()) > max_points) {
    return too_many("replicates.seeds", static_cast<std::size_t>(wire.seeds_size()), "seeds");
  }
  for (int i = 0; i < sweep.axes_size(); ++i) {
    if (const std::size_t n = ListedValues(sweep.axes(i)); n > max_points) {
      return too_many(fmt::format("axes[{}]", i), n, "values");
    }
  }
  const bool zip = sweep.combine() == v1::SWEEP_COMBINE_ZIP;
  double jobs = std::max(1.0, static_cast<double>(wire.count()) + wire.seeds_size());
  if (zip && sweep.axes_size() > 0) jobs *= static_cast<double>(ListedValues(sweep.axes(0)));
  for (const v1::SweepAxis& axis : sweep.axes()) {
    if (!zip) jobs *= static_cast<double>(ListedValues(axis));
  }
  if (jobs <= static_cast<double>(max_points)) return core::Status::Ok();
  return core::InvalidArgument(
      fmt::format("sweep: {:.0f} jobs exceed the limit of {} per sweep", jobs, max_points));
}

}  // namespace

core::Result<SweepPlan> PlanSweep(const v1::Sweep& sweep, const google::protobuf::Message& base,
                                  std::size_t max_points) {
  SEEP_RETURN_IF_ERROR(CheckJobCount(sweep, max_points));
  std::vector<CheckedAxis> axes;
  for (int i = 0; i < sweep.axes_size(); ++i) {
    SEEP_ASSIGN_OR_RETURN(CheckedAxis axis,
                          CheckAxis(sweep.axes(i), static_cast<std::size_t>(i), base));
    for (std::size_t k = 0; k < axes.size(); ++k) {
      if (axes[k].path == axis.path) {
        return core::InvalidArgument(
            fmt::format("sweep.axes[{}].path: '{}' is swept by axes[{}] already", i, axis.path, k));
      }
    }
    axes.push_back(std::move(axis));
  }
  std::optional<CheckedAxis> seeds;
  if (sweep.has_replicates()) {
    SEEP_ASSIGN_OR_RETURN(seeds, CheckReplicates(sweep.replicates(), base));
    for (std::size_t k = 0; k < axes.size(); ++k) {
      if (axes[k].path == seeds->path) {
        return core::InvalidArgument(fmt::format(
            "sweep.replicates.seed_path: '{}' is swept by axes[{}] already", seeds->path, k));
      }
    }
  }
  if (axes.empty() && !seeds) {
    return core::InvalidArgument("sweep.axes: a sweep needs at least one axis or replicates");
  }
  const std::size_t replicates = seeds ? seeds->values.size() : 1;
  const bool zip = sweep.combine() == v1::SWEEP_COMBINE_ZIP;
  SEEP_ASSIGN_OR_RETURN(const std::size_t combined, CombinedCount(sweep, axes));
  SweepPlan plan;
  for (const CheckedAxis& axis : axes) plan.parameters.push_back(axis.path);
  const std::size_t swept = axes.size();  // the axes proper, before the seeds join them
  if (seeds) {
    plan.parameters.push_back(seeds->path);
    axes.push_back(std::move(*seeds));
  }
  for (std::size_t p = 0; p < combined * replicates; ++p) {
    SweepPoint point;
    // Mixed radix: the replicate innermost, then the last axis fastest (zip: one index for all).
    std::size_t rest = p / replicates;
    std::vector<std::size_t> chosen(axes.size());
    if (seeds) chosen.back() = p % replicates;
    for (std::size_t a = swept; a-- > 0;) {
      if (zip) {
        chosen[a] = rest;
      } else {
        chosen[a] = rest % axes[a].values.size();
        rest /= axes[a].values.size();
      }
    }
    for (std::size_t a = 0; a < axes.size(); ++a) {
      point.settings.push_back(axes[a].values[chosen[a]]);
      point.value_fields.push_back(axes[a].value_fields[chosen[a]]);
    }
    plan.points.push_back(std::move(point));
  }
  return plan;
}

core::Status ApplySweepPoint(const SweepPlan& plan, const SweepPoint& point,
                             google::protobuf::Message& message) {
  for (std::size_t i = 0; i < point.settings.size(); ++i) {
    SEEP_ASSIGN_OR_RETURN(const FieldSlot slot, ResolveFieldPath(message, plan.parameters[i]));
    SEEP_RETURN_IF_ERROR(SetFieldValue(slot, point.settings[i]));
  }
  return core::Status::Ok();
}

std::string DescribeSweepPoint(const SweepPlan& plan, const SweepPoint& point) {
  std::string text;
  for (std::size_t i = 0; i < point.settings.size(); ++i) {
    if (i > 0) text += ", ";
    text += fmt::format("{} = {}", plan.parameters[i], SettingValueText(point.settings[i]));
  }
  return text;
}

}  // namespace seep::service
