// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/cluster/job_queue.h"

#include "core/util/status_macros.h"

#include "absl/strings/str_cat.h"

namespace labelmesh::cluster {

JobDelivery::~JobDelivery() { natsMsg_Destroy(message_); }

JobDelivery::JobDelivery(JobDelivery&& other) noexcept
    : message_(other.message_),
      job_id_(std::move(other.job_id_)),
      made_(std::move(other.made_)),
      delivered_(other.delivered_),
      sequence_(other.sequence_) {
  other.message_ = nullptr;
}

absl::Status JobDelivery::ack() {
  return nats_error(natsMsg_AckSync(message_, nullptr, nullptr), absl::StrCat("ack of ", job_id_));
}

absl::Status JobDelivery::nak(absl::Duration delay) {
  return nats_error(natsMsg_NakWithDelay(message_, absl::ToInt64Milliseconds(delay), nullptr),
                    absl::StrCat("nak of ", job_id_));
}

absl::Status JobDelivery::in_progress() {
  return nats_error(natsMsg_InProgress(message_, nullptr), absl::StrCat("progress of ", job_id_));
}

absl::Status JobDelivery::term() {
  return nats_error(natsMsg_Term(message_, nullptr), absl::StrCat("term of ", job_id_));
}

absl::StatusOr<std::unique_ptr<JobQueue>> JobQueue::open(NatsClient& client,
                                                         const JobQueueConfig& config) {
  jsStreamConfig stream;
  jsStreamConfig_Init(&stream);
  const char* subjects[] = {config.subject.c_str()};
  stream.Name = config.stream.c_str();
  stream.Subjects = subjects;
  stream.SubjectsLen = 1;
  stream.Retention = js_WorkQueuePolicy;
  stream.Storage = js_FileStorage;
  stream.Duplicates = absl::ToInt64Nanoseconds(config.duplicate_window);
  LABELMESH_RETURN_IF_ERROR(add_stream(client, stream));

  jsSubOptions options;
  jsSubOptions_Init(&options);
  options.Stream = config.stream.c_str();
  options.ManualAck = true;
  options.Config.AckPolicy = js_AckExplicit;
  options.Config.AckWait = absl::ToInt64Nanoseconds(config.ack_wait);
  options.Config.MaxDeliver = config.max_deliver;
  options.Config.DeliverPolicy = js_DeliverAll;
  natsSubscription* subscription = nullptr;
  natsStatus status = js_PullSubscribe(&subscription, client.jetstream(), config.subject.c_str(),
                                       config.consumer.c_str(), nullptr, &options, nullptr);
  if (status != NATS_OK) {
    // The consumer exists with other settings (another machine's): bind to
    // it as it is.
    jsSubOptions bind;
    jsSubOptions_Init(&bind);
    bind.Stream = config.stream.c_str();
    bind.Consumer = config.consumer.c_str();
    bind.ManualAck = true;
    status = js_PullSubscribe(&subscription, client.jetstream(), config.subject.c_str(),
                              config.consumer.c_str(), nullptr, &bind, nullptr);
  }
  if (status != NATS_OK) return nats_error(status, absl::StrCat("consumer ", config.consumer));
  return std::unique_ptr<JobQueue>(new JobQueue(client, config, subscription));
}

JobQueue::~JobQueue() { natsSubscription_Destroy(subscription_); }

absl::StatusOr<bool> JobQueue::enqueue(const std::string& job_id, const std::string& dedupe_key,
                                       const std::string& made) {
  jsPubOptions options;
  jsPubOptions_Init(&options);
  options.MsgId = dedupe_key.empty() ? job_id.c_str() : dedupe_key.c_str();
  // The message is "<job id>" or "<job id>:<made>".
  const std::string data = made.empty() ? job_id : absl::StrCat(job_id, ":", made);
  jsPubAck* ack = nullptr;
  const natsStatus status =
      js_Publish(&ack, client_.jetstream(), config_.subject.c_str(), data.data(),
                 static_cast<int>(data.size()), &options, nullptr);
  if (status != NATS_OK) return nats_error(status, absl::StrCat("queueing ", job_id));
  const bool fresh = !ack->Duplicate;
  jsPubAck_Destroy(ack);
  return fresh;
}

absl::StatusOr<std::optional<JobDelivery>> JobQueue::take(absl::Duration wait) {
  natsMsgList list{};
  const natsStatus status =
      natsSubscription_Fetch(&list, subscription_, 1, absl::ToInt64Milliseconds(wait), nullptr);
  if (status == NATS_TIMEOUT || (status == NATS_OK && list.Count == 0)) {
    natsMsgList_Destroy(&list);
    return std::nullopt;
  }
  if (status != NATS_OK) return nats_error(status, "taking a job");
  natsMsg* message = list.Msgs[0];
  list.Msgs[0] = nullptr;
  natsMsgList_Destroy(&list);
  jsMsgMetaData* meta = nullptr;
  uint64_t delivered = 1, sequence = 0;
  if (natsMsg_GetMetaData(&meta, message) == NATS_OK) {
    delivered = meta->NumDelivered;
    sequence = meta->Sequence.Stream;
    jsMsgMetaData_Destroy(meta);
  }
  const std::string data(natsMsg_GetData(message),
                         static_cast<size_t>(natsMsg_GetDataLength(message)));
  const size_t colon = data.find(':');
  std::string job_id = data.substr(0, colon);
  std::string made = colon == std::string::npos ? "" : data.substr(colon + 1);
  return std::optional<JobDelivery>(std::in_place, message, std::move(job_id), std::move(made),
                                    delivered, sequence);
}

absl::StatusOr<uint64_t> JobQueue::stored() {
  jsStreamInfo* info = nullptr;
  const natsStatus status =
      js_GetStreamInfo(&info, client_.jetstream(), config_.stream.c_str(), nullptr, nullptr);
  if (status != NATS_OK) return nats_error(status, absl::StrCat("stream ", config_.stream));
  const uint64_t messages = info->State.Msgs;
  jsStreamInfo_Destroy(info);
  return messages;
}

}  // namespace labelmesh::cluster
