// BearerAuth: the token sources (flag file, environment) and the per-call metadata check.
#include "rpc/bearer_auth.h"

#include <fmt/format.h>
#include <sys/stat.h>

#include <fstream>
#include <iterator>
#include <sstream>

namespace seep::service {
namespace {

constexpr std::size_t kMaxTokenLength = 4096;
constexpr std::string_view kScheme = "Bearer ";

std::string_view Trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r\n");
  return s.substr(first, last - first + 1);
}

grpc::Status Denied(const std::string& why) { return {grpc::StatusCode::UNAUTHENTICATED, why}; }

}  // namespace

bool ConstantTimeEquals(std::string_view presented, std::string_view expected) {
  if (expected.empty()) return false;
  // Walk the presented bytes, always all of them, against the expected ones (cycled), and fold
  // every difference, the length difference included, into one accumulator.
  unsigned diff = presented.size() == expected.size() ? 0u : 1u;
  for (std::size_t i = 0; i < presented.size(); ++i) {
    diff |= static_cast<unsigned char>(presented[i]) ^
            static_cast<unsigned char>(expected[i % expected.size()]);
  }
  return diff == 0;
}

core::Result<BearerAuth> BearerAuth::FromToken(std::string token) {
  if (token.empty()) return core::InvalidArgument("token: is empty");
  if (token.size() > kMaxTokenLength) {
    return core::InvalidArgument(
        fmt::format("token: {} characters, at most {} allowed", token.size(), kMaxTokenLength));
  }
  for (const char c : token) {
    if (c < 0x21 || c > 0x7e) {
      return core::InvalidArgument(
          "token: only visible ASCII characters are allowed (no spaces or control characters)");
    }
  }
  return BearerAuth(std::move(token));
}

core::Result<BearerAuth> BearerAuth::FromFile(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) {
    return core::InvalidArgument(fmt::format("--token-file {}: does not exist", path));
  }
  if (!S_ISREG(info.st_mode)) {
    return core::InvalidArgument(fmt::format("--token-file {}: is not a regular file", path));
  }
  if ((info.st_mode & (S_IRWXG | S_IRWXO)) != 0) {
    return core::InvalidArgument(fmt::format(
        "--token-file {}: group or others may access it (mode {:03o}); run chmod 600 {}", path,
        info.st_mode & 0777, path));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return core::InvalidArgument(fmt::format("--token-file {}: cannot be read", path));
  std::ostringstream content;
  content << in.rdbuf();
  const std::string token(Trim(content.str()));
  if (token.empty()) return core::InvalidArgument(fmt::format("--token-file {}: is empty", path));
  auto auth = FromToken(token);
  if (!auth.ok()) {
    return core::InvalidArgument(fmt::format("--token-file {}: {}", path, auth.status().message()));
  }
  return auth;
}

grpc::Status BearerAuth::Check(const grpc::ServerContext& ctx) const {
  return CheckMetadata(ctx.client_metadata());
}

grpc::Status BearerAuth::CheckMetadata(
    const std::multimap<grpc::string_ref, grpc::string_ref>& metadata) const {
  const auto [first, last] = metadata.equal_range("authorization");
  if (first == last) {
    return Denied(
        "missing 'authorization: Bearer <token>' metadata: this seepd requires a token "
        "(seep --token, --token-file or SEEP_TOKEN)");
  }
  if (std::next(first) != last) return Denied("more than one 'authorization' metadata entry");
  const std::string_view value(first->second.data(), first->second.size());
  if (value.size() <= kScheme.size() || value.substr(0, kScheme.size()) != kScheme) {
    return Denied("'authorization' metadata must be 'Bearer <token>'");
  }
  if (!ConstantTimeEquals(value.substr(kScheme.size()), token_)) {
    return Denied("the bearer token is not the one this seepd accepts");
  }
  return grpc::Status::OK;
}

}  // namespace seep::service
