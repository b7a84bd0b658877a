// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/cluster/nats_client.h"

#include "absl/strings/str_cat.h"

namespace labelmesh::cluster {

absl::Status nats_error(natsStatus status, std::string_view what) {
  const std::string text = absl::StrCat(std::string(what), ": ", natsStatus_GetText(status));
  switch (status) {
    case NATS_OK:
      return absl::OkStatus();
    case NATS_TIMEOUT:
      // Unanswered: the server is away (the client keeps reconnecting) or
      // overloaded. Clients retry UNAVAILABLE; DEADLINE_EXCEEDED is theirs.
      return absl::UnavailableError(absl::StrCat(text, " (NATS did not answer in time)"));
    case NATS_NOT_FOUND:
      return absl::NotFoundError(text);
    case NATS_NO_SERVER:
    case NATS_CONNECTION_CLOSED:
    case NATS_CONNECTION_DISCONNECTED:
    case NATS_STALE_CONNECTION:
    case NATS_NO_RESPONDERS:
      return absl::UnavailableError(text);
    case NATS_INVALID_ARG:
      return absl::InvalidArgumentError(text);
    default:
      return absl::InternalError(text);
  }
}

absl::StatusOr<std::unique_ptr<NatsClient>> NatsClient::connect(const std::string& url,
                                                                const std::string& name,
                                                                absl::Duration timeout) {
  natsOptions* options = nullptr;
  natsStatus status = natsOptions_Create(&options);
  if (status == NATS_OK) status = natsOptions_SetURL(options, url.c_str());
  if (status == NATS_OK) status = natsOptions_SetName(options, name.c_str());
  if (status == NATS_OK)
    status = natsOptions_SetTimeout(options, absl::ToInt64Milliseconds(timeout));
  // Reconnect for ever: a restarted NATS server keeps the streams on disk.
  if (status == NATS_OK) status = natsOptions_SetMaxReconnect(options, -1);
  // Followers of job events share the client's delivery threads rather
  // than each having one of its own.
  if (status == NATS_OK) status = natsOptions_UseGlobalMessageDelivery(options, true);
  if (status == NATS_OK) status = natsOptions_SetReconnectWait(options, 200);
  natsConnection* connection = nullptr;
  if (status == NATS_OK) status = natsConnection_Connect(&connection, options);
  natsOptions_Destroy(options);
  if (status != NATS_OK) return nats_error(status, absl::StrCat("NATS at ", url));
  jsCtx* jetstream = nullptr;
  status = natsConnection_JetStream(&jetstream, connection, nullptr);
  if (status != NATS_OK) {
    natsConnection_Destroy(connection);
    return nats_error(status, absl::StrCat("JetStream at ", url));
  }
  return std::unique_ptr<NatsClient>(new NatsClient(connection, jetstream));
}

absl::Status add_stream(NatsClient& client, jsStreamConfig& config) {
  jsErrCode code = static_cast<jsErrCode>(0);
  jsStreamInfo* info = nullptr;
  const natsStatus status = js_AddStream(&info, client.jetstream(), &config, nullptr, &code);
  jsStreamInfo_Destroy(info);
  if (status == NATS_OK || code == JSStreamNameExistErr) return absl::OkStatus();
  return nats_error(status, absl::StrCat("stream ", config.Name));
}

NatsClient::~NatsClient() {
  // Events published without waiting go out before the context does.
  jsPubOptions options;
  jsPubOptions_Init(&options);
  options.MaxWait = 2000;
  js_PublishAsyncComplete(jetstream_, &options);
  jsCtx_Destroy(jetstream_);
  natsConnection_Destroy(connection_);
}

}  // namespace labelmesh::cluster
