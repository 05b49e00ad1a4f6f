// BearerAuth: the optional shared-secret check on seep.v1.SeepService calls.
//
// When seepd has a token, every SeepService call must carry the metadata
// `authorization: Bearer <token>`. The check runs inside the wrapper every handler uses, not in a
// grpc::AuthMetadataProcessor: that hook only works on secure credentials, and seepd also serves
// plaintext on loopback. grpc.health.v1.Health and reflection are separate services and stay open,
// so liveness probes need no secret.
#pragma once

#include <grpcpp/grpcpp.h>

#include <map>
#include <string>
#include <string_view>

#include "seep/core/status.h"

namespace seep::service {

class BearerAuth {
 public:
  // The token must be 1..4096 visible ASCII characters (it travels as an HTTP/2 header value).
  static core::Result<BearerAuth> FromToken(std::string token);
  // Reads the token from a file (surrounding whitespace and the final newline are dropped). The
  // file must exist, hold a token and be readable by its owner only (chmod 600): a secret other
  // users can read is no secret.
  static core::Result<BearerAuth> FromFile(const std::string& path);

  // The token itself, for the workers seepd starts (--executor slurm gives it in their
  // environment).
  const std::string& token() const { return token_; }

  // OK, or UNAUTHENTICATED with a message saying what is missing or wrong.
  grpc::Status Check(const grpc::ServerContext& ctx) const;
  // The same check on raw metadata (what Check reads from the context).
  grpc::Status CheckMetadata(
      const std::multimap<grpc::string_ref, grpc::string_ref>& metadata) const;

 private:
  explicit BearerAuth(std::string token) : token_(std::move(token)) {}
  std::string token_;
};

// Compares in time that depends on `presented`'s length only, never on where the first
// difference is, so the token cannot be guessed byte by byte from response times.
bool ConstantTimeEquals(std::string_view presented, std::string_view expected);

}  // namespace seep::service
