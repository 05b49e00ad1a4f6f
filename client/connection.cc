#include "connection.h"

#include <fmt/format.h>

#include <fstream>
#include <sstream>

namespace seep::client {
namespace {

std::string Trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r\n") - first + 1);
}

bool ReadWholeFile(const std::string& path, std::string* content) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream buffer;
  buffer << in.rdbuf();
  *content = buffer.str();
  return true;
}

}  // namespace

std::string LoadConnectionSecrets(Connection& connection) {
  if (!connection.token_file.empty()) {
    std::string content;
    if (!ReadWholeFile(connection.token_file, &content)) {
      return fmt::format("--token-file {}: cannot be read", connection.token_file);
    }
    connection.token = Trim(content);
    if (connection.token.empty()) {
      return fmt::format("--token-file {}: is empty", connection.token_file);
    }
  }
  for (const char c : connection.token) {
    if (c < 0x21 || c > 0x7e) {
      return "--token: only visible ASCII characters are allowed (no spaces or control "
             "characters)";
    }
  }
  if (!connection.tls_ca.empty()) {
    if (!ReadWholeFile(connection.tls_ca, &connection.tls_ca_pem) ||
        connection.tls_ca_pem.find("-----BEGIN") == std::string::npos) {
      return fmt::format("--tls-ca {}: cannot read a PEM certificate from it", connection.tls_ca);
    }
  }
  return {};
}

std::shared_ptr<grpc::Channel> OpenSeepdChannel(const Connection& connection) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(128 << 20);
  if (!connection.tls && connection.tls_ca.empty()) {
    return grpc::CreateCustomChannel(connection.server, grpc::InsecureChannelCredentials(), args);
  }
  grpc::SslCredentialsOptions ssl;
  ssl.pem_root_certs = connection.tls_ca_pem;  // empty: the system's roots
  return grpc::CreateCustomChannel(connection.server, grpc::SslCredentials(ssl), args);
}

void AddToken(const Connection& connection, grpc::ClientContext* ctx) {
  if (!connection.token.empty()) ctx->AddMetadata("authorization", "Bearer " + connection.token);
}

}  // namespace seep::client
