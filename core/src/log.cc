#include "seep/core/log.h"

#include <spdlog/sinks/stdout_sinks.h>

#include <atomic>
#include <mutex>

namespace seep::core {
namespace {

std::mutex& LoggerMutex() {
  static std::mutex mutex;
  return mutex;
}

std::shared_ptr<spdlog::logger>& LoggerSlot() {
  static std::shared_ptr<spdlog::logger> logger = [] {
    auto quiet = std::make_shared<spdlog::logger>(
        "seep.core", std::make_shared<spdlog::sinks::stderr_sink_mt>());
    quiet->set_level(spdlog::level::warn);
    return quiet;
  }();
  return logger;
}

}  // namespace

std::shared_ptr<spdlog::logger> Logger() {
  std::lock_guard lock(LoggerMutex());
  return LoggerSlot();
}

void SetLogger(std::shared_ptr<spdlog::logger> logger) {
  std::lock_guard lock(LoggerMutex());
  if (logger) LoggerSlot() = std::move(logger);
}

}  // namespace seep::core
