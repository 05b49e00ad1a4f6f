// What the JobStore's source files (job_store*.cc) share inside the store: the one lease-lost
// error and the one way an event is written inside a store transaction.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "seep/core/status.h"
#include "sqlite_handle.h"

namespace seep::service {

// ABORTED: a write fenced by `epoch` found the job no longer RUNNING under it.
core::Status LeaseLost(const std::string& id, std::int64_t epoch);

// Wall-clock milliseconds since the Unix epoch, for the store's own time stamps.
std::int64_t StoreNowMs();

// Appends one event to the job's history (the events table) with the caller's connection, so
// that it commits or rolls back with the change it describes. NOT_FOUND when no job has this id.
core::Status AddEventLocked(Db& db, std::string_view id, std::int64_t at_ms, std::string_view kind,
                            std::string_view message);

}  // namespace seep::service
