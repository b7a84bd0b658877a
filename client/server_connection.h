// SPDX-License-Identifier: AGPL-3.0-or-later
// How the client reaches labelmeshd: address, TLS and bearer token, from
// flags or LABELMESH_SERVER / LABELMESH_TOKEN.
#pragma once

#include <grpcpp/grpcpp.h>

#include <memory>
#include <string>

#include "absl/status/statusor.h"

namespace CLI {
class App;
}

namespace labelmesh::client {

struct ConnectionFlags {
  std::string server = "127.0.0.1:50051";
  std::string token_file;
  bool tls = false;
  std::string tls_ca;
  std::string tls_cert;
  std::string tls_key;
};

void add_connection_flags(CLI::App& command, ConnectionFlags& flags);

class ServerConnection {
 public:
  // INVALID_ARGUMENT naming the flag when a file cannot be read.
  static absl::StatusOr<ServerConnection> open(const ConnectionFlags& flags);

  const std::shared_ptr<grpc::Channel>& channel() const { return channel_; }
  // A context carrying the token; `timeout` zero for none.
  std::unique_ptr<grpc::ClientContext> context(std::chrono::seconds timeout = {}) const;

 private:
  std::shared_ptr<grpc::Channel> channel_;
  std::string token_;
};

// UNAVAILABLE and the like become "cannot reach ADDR: ..." for people.
std::string describe(const grpc::Status& status);

}  // namespace labelmesh::client
