// The core's logger. The core never configures spdlog globally (no set_level, set_pattern or
// registry calls): the embedding program installs a logger with SetLogger(); until then the core
// logs through a quiet default that drops everything below warn.
#pragma once

#include <spdlog/spdlog.h>

#include <memory>

namespace seep::core {

std::shared_ptr<spdlog::logger> Logger();
void SetLogger(std::shared_ptr<spdlog::logger> logger);

}  // namespace seep::core
