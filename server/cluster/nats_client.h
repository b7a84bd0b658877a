// SPDX-License-Identifier: AGPL-3.0-or-later
// One connection to a NATS server and its JetStream context, for the parts
// of labelmeshd that share jobs between machines (job_queue.h,
// job_states.h). The C client (Debian's libnats) does the protocol.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include <nats/nats.h>

#include "absl/status/statusor.h"
#include "absl/time/time.h"

namespace labelmesh::cluster {

class NatsClient {
 public:
  // Connects to `url` (nats://HOST:PORT), naming the connection `name` in
  // the server's monitoring, waiting at most `timeout`.
  // Errors: UNAVAILABLE when no server answers; INVALID_ARGUMENT for a bad
  // URL; INTERNAL otherwise.
  static absl::StatusOr<std::unique_ptr<NatsClient>> connect(const std::string& url,
                                                             const std::string& name,
                                                             absl::Duration timeout);
  ~NatsClient();
  NatsClient(const NatsClient&) = delete;
  NatsClient& operator=(const NatsClient&) = delete;

  natsConnection* connection() const { return connection_; }
  // False while the client is cut off and reconnecting.
  bool connected() const {
    return natsConnection_Status(connection_) == NATS_CONN_STATUS_CONNECTED;
  }
  jsCtx* jetstream() const { return jetstream_; }

 private:
  NatsClient(natsConnection* connection, jsCtx* jetstream)
      : connection_(connection), jetstream_(jetstream) {}
  natsConnection* connection_;
  jsCtx* jetstream_;
};

// Creates the stream `config` describes, or keeps the one of that name that
// exists (another machine made it). Errors: those of nats_error.
absl::Status add_stream(NatsClient& client, jsStreamConfig& config);

// A failed call as a status naming `what`: NATS_NOT_FOUND is NOT_FOUND; an
// unanswered call (NATS_TIMEOUT) or a closed or absent server UNAVAILABLE, so
// that clients try again; the rest INTERNAL with the client's own text.
absl::Status nats_error(natsStatus status, std::string_view what);

}  // namespace labelmesh::cluster
