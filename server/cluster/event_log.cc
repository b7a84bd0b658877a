// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/cluster/event_log.h"

#include "absl/base/thread_annotations.h"
#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "core/util/status_macros.h"

namespace labelmesh::cluster {

namespace {

// Takes the message: its data and stream sequence.
LoggedEvent logged_event(natsMsg* message) {
  LoggedEvent event;
  event.data.assign(natsMsg_GetData(message), static_cast<size_t>(natsMsg_GetDataLength(message)));
  jsMsgMetaData* meta = nullptr;
  if (natsMsg_GetMetaData(&meta, message) == NATS_OK) {
    event.sequence = meta->Sequence.Stream;
    jsMsgMetaData_Destroy(meta);
  }
  natsMsg_Destroy(message);
  return event;
}

}  // namespace

// Shared by the subscription and the client's delivery thread; the client
// frees it once the subscription is closed and its last callback returned.
struct EventSubscription::Delivery {
  absl::Mutex mutex;
  bool active ABSL_GUARDED_BY(mutex) = true;
  std::function<void(LoggedEvent)> on_event;

  static void on_message(natsConnection*, natsSubscription*, natsMsg* message, void* closure) {
    auto* delivery = static_cast<Delivery*>(closure);
    LoggedEvent event = logged_event(message);
    absl::MutexLock lock(&delivery->mutex);
    if (delivery->active) delivery->on_event(std::move(event));
  }
  static void on_complete(void* closure) { delete static_cast<Delivery*>(closure); }
};

EventSubscription::~EventSubscription() {
  {
    absl::MutexLock lock(&delivery_->mutex);
    delivery_->active = false;
  }
  natsSubscription_Unsubscribe(subscription_);
  natsSubscription_Destroy(subscription_);
}

EventFollower::~EventFollower() { natsSubscription_Destroy(subscription_); }

absl::StatusOr<std::optional<LoggedEvent>> EventFollower::next(absl::Duration wait) {
  natsMsg* message = nullptr;
  const natsStatus status =
      natsSubscription_NextMsg(&message, subscription_, absl::ToInt64Milliseconds(wait));
  if (status == NATS_TIMEOUT) return std::nullopt;
  if (status != NATS_OK) return nats_error(status, "following a job's events");
  return std::optional<LoggedEvent>(logged_event(message));
}

absl::StatusOr<std::unique_ptr<EventLog>> EventLog::open(NatsClient& client,
                                                         const EventLogConfig& config) {
  const std::string subjects_text = config.subject_prefix + ".>";
  const char* subjects[] = {subjects_text.c_str()};
  jsStreamConfig stream;
  jsStreamConfig_Init(&stream);
  stream.Name = config.stream.c_str();
  stream.Subjects = subjects;
  stream.SubjectsLen = 1;
  stream.Retention = js_LimitsPolicy;
  stream.Storage = js_FileStorage;
  stream.MaxAge = absl::ToInt64Nanoseconds(config.max_age);
  LABELMESH_RETURN_IF_ERROR(add_stream(client, stream));
  return std::unique_ptr<EventLog>(new EventLog(client, config));
}

std::string EventLog::subject(const std::string& job_id) const {
  return absl::StrCat(config_.subject_prefix, ".", job_id);
}

absl::StatusOr<uint64_t> EventLog::append(const std::string& job_id, const std::string& data) {
  jsPubAck* ack = nullptr;
  const natsStatus status =
      js_Publish(&ack, client_.jetstream(), subject(job_id).c_str(), data.data(),
                 static_cast<int>(data.size()), nullptr, nullptr);
  if (status != NATS_OK) return nats_error(status, absl::StrCat("event of ", job_id));
  const uint64_t sequence = ack->Sequence;
  jsPubAck_Destroy(ack);
  return sequence;
}

absl::Status EventLog::append_async(const std::string& job_id, const std::string& data) {
  return nats_error(js_PublishAsync(client_.jetstream(), subject(job_id).c_str(), data.data(),
                                    static_cast<int>(data.size()), nullptr),
                    absl::StrCat("event of ", job_id));
}

absl::StatusOr<std::optional<std::string>> EventLog::last(const std::string& job_id) {
  natsMsg* message = nullptr;
  const natsStatus status = js_GetLastMsg(&message, client_.jetstream(), config_.stream.c_str(),
                                          subject(job_id).c_str(), nullptr, nullptr);
  if (status == NATS_NOT_FOUND) return std::nullopt;
  if (status != NATS_OK) return nats_error(status, absl::StrCat("last event of ", job_id));
  std::string data(natsMsg_GetData(message), static_cast<size_t>(natsMsg_GetDataLength(message)));
  natsMsg_Destroy(message);
  return std::optional<std::string>(std::move(data));
}

jsSubOptions EventLog::follow_options(uint64_t from) const {
  jsSubOptions options;
  jsSubOptions_Init(&options);
  options.Stream = config_.stream.c_str();
  options.Ordered = true;
  if (from > 0) {
    options.Config.DeliverPolicy = js_DeliverByStartSequence;
    options.Config.OptStartSeq = from;
  }
  return options;
}

absl::StatusOr<std::unique_ptr<EventFollower>> EventLog::follow(const std::string& job_id,
                                                                uint64_t from) {
  jsSubOptions options = follow_options(from);
  natsSubscription* subscription = nullptr;
  const natsStatus status = js_SubscribeSync(&subscription, client_.jetstream(),
                                             subject(job_id).c_str(), nullptr, &options, nullptr);
  if (status != NATS_OK) return nats_error(status, absl::StrCat("events of ", job_id));
  return std::make_unique<EventFollower>(subscription);
}

absl::StatusOr<std::unique_ptr<EventSubscription>> EventLog::subscribe(
    const std::string& job_id, uint64_t from, std::function<void(LoggedEvent)> on_event) {
  jsSubOptions options = follow_options(from);
  auto* delivery = new EventSubscription::Delivery{{}, true, std::move(on_event)};
  natsSubscription* subscription = nullptr;
  natsStatus status =
      js_Subscribe(&subscription, client_.jetstream(), subject(job_id).c_str(),
                   &EventSubscription::Delivery::on_message, delivery, nullptr, &options, nullptr);
  if (status == NATS_OK) {
    status = natsSubscription_SetOnCompleteCB(subscription,
                                              &EventSubscription::Delivery::on_complete, delivery);
    if (status != NATS_OK) {
      // The client never frees the delivery now, and a callback may still
      // hold it: it is stopped and left, never freed.
      {
        absl::MutexLock lock(&delivery->mutex);
        delivery->active = false;
      }
      natsSubscription_Unsubscribe(subscription);
      natsSubscription_Destroy(subscription);
      return nats_error(status, absl::StrCat("events of ", job_id));
    }
    return std::make_unique<EventSubscription>(subscription, delivery);
  }
  delete delivery;
  return nats_error(status, absl::StrCat("events of ", job_id));
}

absl::Status EventLog::remove(const std::string& job_id) {
  jsOptions options;
  jsOptions_Init(&options);
  const std::string filter = subject(job_id);
  options.Stream.Purge.Subject = filter.c_str();
  return nats_error(js_PurgeStream(client_.jetstream(), config_.stream.c_str(), &options, nullptr),
                    absl::StrCat("removing the events of ", job_id));
}

}  // namespace labelmesh::cluster
