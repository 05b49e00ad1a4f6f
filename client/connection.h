// How a program connects to seepd: the channel (plaintext, or TLS with the system's roots or a
// given CA) and the bearer token read from a file. Shared by the CLI (seep) and the remote worker
// (seep-worker), so both take the same --server, --token/--token-file/SEEP_TOKEN, --tls and
// --tls-ca.
#pragma once

#include <grpcpp/grpcpp.h>

#include <memory>
#include <string>

namespace seep::client {

struct Connection {
  std::string server = "127.0.0.1:50051";
  std::string token;       // sent as 'authorization: Bearer <token>' when not empty
  std::string token_file;  // read into `token` by LoadConnectionSecrets
  bool tls = false;        // TLS with the system's root certificates
  std::string tls_ca;      // TLS trusting this PEM CA file (implies tls)
  std::string tls_ca_pem;  // its content, read by LoadConnectionSecrets
};

// Reads --token-file into token (wins over --token) and --tls-ca into tls_ca_pem, and checks the
// token; returns "" or what is wrong, naming the flag ("--token-file F: cannot be read").
std::string LoadConnectionSecrets(Connection& connection);

std::shared_ptr<grpc::Channel> OpenSeepdChannel(const Connection& connection);

// Plain metadata rather than call credentials: gRPC only sends call credentials over secure
// channels, and a token-protected seepd may also be plaintext on loopback.
void AddToken(const Connection& connection, grpc::ClientContext* ctx);

}  // namespace seep::client
