// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/client_identity.h"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <algorithm>
#include <fstream>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/digest/sha256.h"
#include "core/util/status_macros.h"
#include "server/stream_limits.h"

namespace labelmesh::server {
namespace {

// Hosts remembered at most; beyond it, hosts not backed off are forgotten.
constexpr size_t kMaxTrackedHosts = 10'000;

bool is_identity_name(std::string_view name) {
  if (name.empty() || name.size() > 64) return false;
  for (char c : name) {
    if (!absl::ascii_isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '@' &&
        c != '-')
      return false;
  }
  return true;
}

bool is_token_text(std::string_view token) {
  if (token.size() < 16 || token.size() > 256) return false;
  for (char c : token) {
    if (c < 0x21 || c > 0x7e) return false;
  }
  return true;
}

// Identities the server gives itself: no client may be named so.
bool is_reserved_name(std::string_view name) {
  return name == kAnonymous || name == kSharedTokenIdentity;
}

absl::StatusOr<std::string> read_single_token(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::InvalidArgumentError(absl::StrCat("--auth-token-file: cannot read ", path));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string token(absl::StripAsciiWhitespace(text));
  if (!is_token_text(token)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--auth-token-file: ", path, ": the token must be 16 to 256 printable characters"));
  }
  return token;
}

}  // namespace

absl::StatusOr<std::vector<TokenHolder>> read_clients_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::InvalidArgumentError(absl::StrCat("--clients-file: cannot read ", path));
  std::vector<TokenHolder> holders;
  std::set<std::string> names, tokens;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    auto bad = [&](const std::string& why) {
      // Never quotes the line: it holds a secret.
      return absl::InvalidArgumentError(
          absl::StrCat("--clients-file: ", path, " line ", number, ": ", why));
    };
    absl::string_view text = absl::StripAsciiWhitespace(line);
    if (text.empty() || text.front() == '#') continue;
    std::vector<absl::string_view> fields = absl::StrSplit(text, ' ', absl::SkipWhitespace());
    if (fields.size() < 2 || fields.size() > 3) return bad("expected NAME TOKEN [admin]");
    TokenHolder holder{std::string(fields[0]), std::string(fields[1]), false};
    if (!is_identity_name(holder.name)) return bad("the name must be 1-64 of A-Z a-z 0-9 . _ @ -");
    if (is_reserved_name(holder.name)) return bad("the names 'anonymous' and 'token' are reserved");
    if (!is_token_text(holder.token))
      return bad("the token must be 16 to 256 printable characters");
    if (fields.size() == 3) {
      if (fields[2] != "admin") return bad("the third field can only be 'admin'");
      holder.admin = true;
    }
    if (!names.insert(holder.name).second) return bad("a name listed twice");
    if (!tokens.insert(holder.token).second) return bad("a token given to two clients");
    holders.push_back(std::move(holder));
  }
  if (holders.empty())
    return absl::InvalidArgumentError(absl::StrCat("--clients-file: ", path, " lists no client"));
  return holders;
}

std::string host_key(const std::string& host) {
  std::string_view text = host;
  if (text.substr(0, 5) != "ipv6:") return host;
  text.remove_prefix(5);
  std::string address(text);
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"%5B", "["}, {"%5D", "]"}}) {
    for (size_t at; (at = address.find(from)) != std::string::npos;) address.replace(at, 3, to);
  }
  if (!address.empty() && address.front() == '[') address = address.substr(1);
  if (const size_t close = address.find(']'); close != std::string::npos) address.resize(close);
  in6_addr v6{};
  if (inet_pton(AF_INET6, address.c_str(), &v6) != 1) return host;
  std::fill(v6.s6_addr + 8, v6.s6_addr + 16, 0);
  char prefix[INET6_ADDRSTRLEN] = "";
  inet_ntop(AF_INET6, &v6, prefix, sizeof prefix);
  return absl::StrCat("ipv6:", prefix, "/64");
}

ShareKeys share_keys(const ClientIdentity& identity, const std::string& peer) {
  std::string host = host_key(peer_host(peer));
  if (identity.name == kAnonymous || identity.name == kSharedTokenIdentity)
    return {absl::StrCat(identity.name, "@", host), host};
  return {identity.name, std::move(host)};
}

absl::Status AuthBackoff::check(const std::string& peer, absl::Time now) {
  const std::string host = host_key(peer);
  absl::MutexLock lock(&mutex_);
  auto it = hosts_.find(host);
  if (it == hosts_.end() || it->second.blocked_until <= now) return absl::OkStatus();
  return absl::ResourceExhaustedError(absl::StrCat(
      "too many failed authentications from this host; try again in ",
      absl::FormatDuration(absl::Ceil(it->second.blocked_until - now, absl::Seconds(1)))));
}

void AuthBackoff::failed(const std::string& peer, absl::Time now) {
  const std::string host = host_key(peer);
  absl::MutexLock lock(&mutex_);
  if (hosts_.size() >= kMaxTrackedHosts && hosts_.find(host) == hosts_.end()) {
    std::erase_if(hosts_, [now](const auto& entry) {
      return entry.second.blocked_until <= now && now - entry.second.last_failure > kForgetAfter;
    });
    if (hosts_.size() >= kMaxTrackedHosts) return;
  }
  Host& entry = hosts_[host];
  if (now - entry.last_failure > kForgetAfter) entry.failures = 0;
  entry.last_failure = now;
  ++entry.failures;
  const int over = entry.failures - allowed_failures_;
  if (over < 0) return;
  absl::Duration backoff = first_backoff_;
  for (int i = 0; i < over && backoff < longest_backoff_; ++i) backoff *= 2;
  entry.blocked_until = now + std::min(backoff, longest_backoff_);
}

absl::StatusOr<std::unique_ptr<ClientAuthenticator>> ClientAuthenticator::from_config(
    const ServerConfig& config) {
  std::vector<TokenHolder> tokens;
  if (!config.clients_file.empty()) {
    LABELMESH_ASSIGN_OR_RETURN(auto holders, read_clients_file(config.clients_file));
    tokens = std::move(holders);
  }
  if (!config.auth_token_file.empty()) {
    auto token = read_single_token(config.auth_token_file);
    if (!token.ok()) return token.status();
    for (const auto& holder : tokens) {
      if (holder.token == *token)
        return absl::InvalidArgumentError(
            "--auth-token-file: the shared token is also a client's token in --clients-file");
    }
    tokens.push_back({kSharedTokenIdentity, std::move(*token), false});
  }
  std::set<std::string> admins(config.admin_identities.begin(), config.admin_identities.end());
  for (const auto& holder : tokens) {
    if (holder.admin) admins.insert(holder.name);
  }
  return std::unique_ptr<ClientAuthenticator>(new ClientAuthenticator(
      std::move(tokens), !config.client_ca.empty(), std::move(admins), config));
}

ClientAuthenticator::ClientAuthenticator(std::vector<TokenHolder> tokens, bool mutual_tls,
                                         std::set<std::string> admins, const ServerConfig& config)
    : tokens_(std::move(tokens)),
      mutual_tls_(mutual_tls),
      admins_(std::move(admins)),
      backoff_(config.auth_failures_before_backoff, config.auth_first_backoff,
               config.auth_longest_backoff) {}

const TokenHolder* ClientAuthenticator::find_token(std::string_view presented) const {
  // Every token is compared, in constant time, so the time taken tells nothing.
  const TokenHolder* found = nullptr;
  for (const auto& holder : tokens_) {
    if (digest::constant_time_equal(presented, holder.token)) found = &holder;
  }
  return found;
}

absl::StatusOr<ClientIdentity> ClientAuthenticator::identify(
    const grpc::ServerContextBase& context) {
  if (anonymous()) return ClientIdentity{kAnonymous, false};
  auto identity = has_tokens() ? identify_by_token(context) : identify_by_certificate(context);
  // The credential is checked first: a valid one is never backed off, so
  // failures from an address (behind an ingress or NAT, everyone's) hold
  // back only the failing calls, not the clients that share it.
  if (identity.ok()) return identity;
  const std::string host = peer_host(context.peer());
  const absl::Time now = absl::Now();
  LABELMESH_RETURN_IF_ERROR(backoff_.check(host, now));
  backoff_.failed(host, now);
  return identity.status();
}

absl::StatusOr<ClientIdentity> ClientAuthenticator::identify_by_token(
    const grpc::ServerContextBase& context) const {
  const auto& metadata = context.client_metadata();
  auto it = metadata.find("authorization");
  std::string_view presented;
  if (it != metadata.end()) presented = std::string_view(it->second.data(), it->second.size());
  constexpr std::string_view kScheme = "Bearer ";
  const TokenHolder* holder = nullptr;
  if (presented.substr(0, kScheme.size()) == kScheme) {
    holder = find_token(presented.substr(kScheme.size()));
  }
  if (holder == nullptr) {
    return absl::UnauthenticatedError(
        "missing or wrong bearer token (metadata 'authorization: Bearer <token>')");
  }
  return ClientIdentity{holder->name, admins_.count(holder->name) > 0};
}

absl::StatusOr<ClientIdentity> ClientAuthenticator::identify_by_certificate(
    const grpc::ServerContextBase& context) const {
  // Mutual TLS: the transport verified the certificate; its CN names the client.
  const auto auth = context.auth_context();
  const auto names =
      auth ? auth->FindPropertyValues(GRPC_X509_CN_PROPERTY_NAME) : std::vector<grpc::string_ref>{};
  const std::string_view common_name =
      names.empty() ? std::string_view() : std::string_view(names[0].data(), names[0].size());
  if (!is_identity_name(common_name) || is_reserved_name(common_name)) {
    return absl::UnauthenticatedError(
        "the client certificate has no common name usable as an identity "
        "(1-64 of A-Z a-z 0-9 . _ @ -, not 'anonymous' or 'token')");
  }
  std::string name(common_name);
  const bool admin = admins_.count(name) > 0;
  return ClientIdentity{std::move(name), admin};
}

}  // namespace labelmesh::server
