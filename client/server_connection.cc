// SPDX-License-Identifier: AGPL-3.0-or-later
#include "client/server_connection.h"

#include <CLI/CLI.hpp>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "core/util/status_macros.h"

namespace labelmesh::client {
namespace {

absl::StatusOr<std::string> read_file(const std::string& path, const std::string& flag) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::InvalidArgumentError(absl::StrCat("--", flag, ": cannot read ", path));
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

void add_connection_flags(CLI::App& command, ConnectionFlags& flags) {
  command.add_option("--server", flags.server, "labelmeshd address")
      ->envname("LABELMESH_SERVER")
      ->capture_default_str();
  command.add_option("--token-file", flags.token_file,
                     "File holding the bearer token (or set LABELMESH_TOKEN to the token)");
  command.add_flag("--tls", flags.tls, "Use TLS, trusting the system's CAs");
  command.add_option("--tls-ca", flags.tls_ca, "PEM CA that signed the server's certificate");
  command.add_option("--tls-cert", flags.tls_cert, "PEM client certificate (mutual TLS)");
  command.add_option("--tls-key", flags.tls_key, "PEM private key of --tls-cert");
}

absl::StatusOr<ServerConnection> ServerConnection::open(const ConnectionFlags& flags) {
  ServerConnection connection;
  if (!flags.token_file.empty()) {
    LABELMESH_ASSIGN_OR_RETURN(auto token, read_file(flags.token_file, "token-file"));
    connection.token_ = std::string(absl::StripAsciiWhitespace(token));
  } else if (const char* token = std::getenv("LABELMESH_TOKEN")) {
    connection.token_ = std::string(absl::StripAsciiWhitespace(token));
  }
  std::shared_ptr<grpc::ChannelCredentials> credentials;
  if (flags.tls || !flags.tls_ca.empty() || !flags.tls_cert.empty()) {
    grpc::SslCredentialsOptions options;
    if (!flags.tls_ca.empty()) {
      LABELMESH_ASSIGN_OR_RETURN(auto ca, read_file(flags.tls_ca, "tls-ca"));
      options.pem_root_certs = ca;
    }
    if (!flags.tls_cert.empty()) {
      LABELMESH_ASSIGN_OR_RETURN(auto cert, read_file(flags.tls_cert, "tls-cert"));
      LABELMESH_ASSIGN_OR_RETURN(auto key, read_file(flags.tls_key, "tls-key"));
      options.pem_cert_chain = cert;
      options.pem_private_key = key;
    }
    credentials = grpc::SslCredentials(options);
  } else {
    credentials = grpc::InsecureChannelCredentials();
  }
  grpc::ChannelArguments arguments;
  // Reports of large multi-label runs exceed gRPC's 4 MiB default.
  arguments.SetMaxReceiveMessageSize(64 << 20);
  connection.channel_ = grpc::CreateCustomChannel(flags.server, credentials, arguments);
  return connection;
}

std::unique_ptr<grpc::ClientContext> ServerConnection::context(std::chrono::seconds timeout) const {
  auto context = std::make_unique<grpc::ClientContext>();
  if (!token_.empty()) context->AddMetadata("authorization", "Bearer " + token_);
  if (timeout.count() > 0) context->set_deadline(std::chrono::system_clock::now() + timeout);
  return context;
}

std::string describe(const grpc::Status& status) {
  // gRPC and absl share the canonical code numbers and names.
  return absl::StrCat(absl::StatusCodeToString(static_cast<absl::StatusCode>(status.error_code())),
                      ": ", status.error_message());
}

}  // namespace labelmesh::client
