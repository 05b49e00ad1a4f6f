#include "jobs/escaped_log.h"

#include <fmt/format.h>
#include <spdlog/pattern_formatter.h>

#include <iterator>

namespace seep::service {
namespace {

class EscapedText : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& msg, const std::tm&,
              spdlog::memory_buf_t& dest) override {
    for (const char c : msg.payload) {
      const auto u = static_cast<unsigned char>(c);
      if (u >= 0x20 && u != 0x7f) {
        dest.push_back(c);
      } else if (c == '\n' || c == '\r' || c == '\t') {
        const char escaped[2] = {'\\', c == '\n' ? 'n' : c == '\r' ? 'r' : 't'};
        dest.append(escaped, escaped + 2);
      } else {
        fmt::format_to(std::back_inserter(dest), "\\x{:02x}", u);
      }
    }
  }
  std::unique_ptr<custom_flag_formatter> clone() const override {
    return std::make_unique<EscapedText>();
  }
};

}  // namespace

std::unique_ptr<spdlog::formatter> EscapingLogFormatter() {
  auto formatter = std::make_unique<spdlog::pattern_formatter>();
  formatter->add_flag<EscapedText>('*').set_pattern("%Y-%m-%dT%H:%M:%S.%e [%n] %l: %*");
  return formatter;
}

}  // namespace seep::service
