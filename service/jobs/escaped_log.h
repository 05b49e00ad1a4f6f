// The log format of seepd and seep-worker: "<time> [<logger>] <level>: <text>", the text with
// control characters escaped (\n, \r, \t, \x1b, ...): job names and ids come from clients, and a
// newline in one would forge a log line of its own.
#pragma once

#include <spdlog/formatter.h>

#include <memory>

namespace seep::service {

std::unique_ptr<spdlog::formatter> EscapingLogFormatter();

}  // namespace seep::service
