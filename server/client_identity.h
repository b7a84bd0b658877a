// SPDX-License-Identifier: AGPL-3.0-or-later
// Who a call comes from: a named client identity, from its bearer token (one
// per client, listed in a clients file) or from its TLS client certificate's
// common name. Jobs belong to the identity that submitted them; admins see
// every job. Repeated failed authentication from one host is backed off.
#pragma once

#include <grpcpp/grpcpp.h>

#include <map>
#include <set>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "server/server_config.h"

namespace labelmesh::server {

struct ClientIdentity {
  std::string name;
  bool admin = false;
};

// The identity of calls on a server with no client authentication.
inline constexpr char kAnonymous[] = "anonymous";
// The identity of calls with the --auth-token-file token, which every client
// may share.
inline constexpr char kSharedTokenIdentity[] = "token";

// The key a peer host counts under, for the backoff and for stream and
// upload shares: its address, or for IPv6 its /64 (one host holds a whole
// /64 and could step through it).
std::string host_key(const std::string& host);

// Where a call's streams and uploads count (StreamCounts): `client` is its
// identity, except that the identities every client may share (anonymous,
// the shared token's) count per host; `host` is host_key of the peer.
struct ShareKeys {
  std::string client;
  std::string host;
};
ShareKeys share_keys(const ClientIdentity& identity, const std::string& peer);

struct TokenHolder {
  std::string name;
  std::string token;
  bool admin = false;
};

// A clients file: one `NAME TOKEN [admin]` per line, `#` comments and blank
// lines ignored. Names are 1-64 of [A-Za-z0-9._@-], tokens 16-256 printable
// characters; both unique. Errors name the file and line.
absl::StatusOr<std::vector<TokenHolder>> read_clients_file(const std::string& path);

// Refuses the failing calls from a host for a while once it failed authentication
// `allowed_failures` times: first `first_backoff`, doubling with each further
// failure up to `longest_backoff`. A host's failures are forgotten after
// `kForgetAfter` without one, not by a success (a client with a token of its
// own could otherwise guess others' between its own calls). IPv6 hosts
// count by their /64.
class AuthBackoff {
 public:
  AuthBackoff(int allowed_failures, absl::Duration first_backoff, absl::Duration longest_backoff)
      : allowed_failures_(allowed_failures),
        first_backoff_(first_backoff),
        longest_backoff_(longest_backoff) {}

  // RESOURCE_EXHAUSTED while `host` is backed off.
  absl::Status check(const std::string& host, absl::Time now);
  void failed(const std::string& host, absl::Time now);
  static constexpr absl::Duration kForgetAfter = absl::Minutes(15);

 private:
  struct Host {
    int failures = 0;
    absl::Time last_failure = absl::InfinitePast();
    absl::Time blocked_until = absl::InfinitePast();
  };
  const int allowed_failures_;
  const absl::Duration first_backoff_;
  const absl::Duration longest_backoff_;
  absl::Mutex mutex_;
  std::map<std::string, Host> hosts_ ABSL_GUARDED_BY(mutex_);
};

class ClientAuthenticator {
 public:
  // Reads the clients file and the single-token file the config names.
  static absl::StatusOr<std::unique_ptr<ClientAuthenticator>> from_config(
      const ServerConfig& config);

  // No client authentication at all: every call is `anonymous`.
  bool anonymous() const { return tokens_.empty() && !mutual_tls_; }
  bool has_tokens() const { return !tokens_.empty(); }

  // The caller's identity; UNAUTHENTICATED for a missing or wrong token,
  // RESOURCE_EXHAUSTED for one while its host is backed off. A valid
  // credential is never backed off: the backoff makes failures cheap for
  // the server (they are neither checked further nor audited), and tokens
  // must be random enough not to be guessed (docs/service.md).
  absl::StatusOr<ClientIdentity> identify(const grpc::ServerContextBase& context);

 private:
  ClientAuthenticator(std::vector<TokenHolder> tokens, bool mutual_tls,
                      std::set<std::string> admins, const ServerConfig& config);
  const TokenHolder* find_token(std::string_view presented) const;
  // UNAUTHENTICATED, counting nothing, for a credential that names no client.
  absl::StatusOr<ClientIdentity> identify_by_token(const grpc::ServerContextBase& context) const;
  absl::StatusOr<ClientIdentity> identify_by_certificate(
      const grpc::ServerContextBase& context) const;

  const std::vector<TokenHolder> tokens_;
  const bool mutual_tls_;
  const std::set<std::string> admins_;
  AuthBackoff backoff_;
};

}  // namespace labelmesh::server
