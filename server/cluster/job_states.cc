// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/cluster/job_states.h"

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace labelmesh::cluster {

absl::StatusOr<std::unique_ptr<JobStates>> JobStates::open(NatsClient& client,
                                                           const std::string& bucket) {
  kvStore* store = nullptr;
  natsStatus status = js_KeyValue(&store, client.jetstream(), bucket.c_str());
  if (status == NATS_NOT_FOUND) {
    kvConfig config;
    kvConfig_Init(&config);
    config.Bucket = bucket.c_str();
    config.History = 1;
    status = js_CreateKeyValue(&store, client.jetstream(), &config);
  }
  if (status != NATS_OK) return nats_error(status, absl::StrCat("bucket ", bucket));
  return std::unique_ptr<JobStates>(new JobStates(store));
}

JobStates::~JobStates() { kvStore_Destroy(store_); }

absl::StatusOr<uint64_t> JobStates::create(const std::string& key, const std::string& value) {
  uint64_t revision = 0;
  const natsStatus status =
      kvStore_Create(&revision, store_, key.c_str(), value.data(), static_cast<int>(value.size()));
  if (status == NATS_OK) return revision;
  // The client reports a wrong last sequence as a plain error: tell it apart.
  if (get(key).ok()) return absl::AlreadyExistsError(absl::StrCat("job state ", key, " exists"));
  return nats_error(status, absl::StrCat("creating job state ", key));
}

absl::StatusOr<Versioned> JobStates::get(const std::string& key) {
  kvEntry* entry = nullptr;
  const natsStatus status = kvStore_Get(&entry, store_, key.c_str());
  if (status != NATS_OK) return nats_error(status, absl::StrCat("job state ", key));
  Versioned versioned{std::string(static_cast<const char*>(kvEntry_Value(entry)),
                                  static_cast<size_t>(kvEntry_ValueLen(entry))),
                      kvEntry_Revision(entry)};
  kvEntry_Destroy(entry);
  return versioned;
}

absl::StatusOr<uint64_t> JobStates::update(const std::string& key, const std::string& value,
                                           uint64_t revision) {
  uint64_t written = 0;
  const natsStatus status = kvStore_Update(&written, store_, key.c_str(), value.data(),
                                           static_cast<int>(value.size()), revision);
  if (status == NATS_OK) return written;
  LABELMESH_ASSIGN_OR_RETURN(auto current, get(key));
  if (current.revision != revision) {
    return absl::AbortedError(absl::StrCat("job state ", key, " changed: revision ",
                                           current.revision, ", not ", revision));
  }
  return nats_error(status, absl::StrCat("updating job state ", key));
}

absl::StatusOr<std::vector<std::string>> JobStates::keys() {
  kvKeysList list{nullptr, 0};
  const natsStatus status = kvStore_Keys(&list, store_, nullptr);
  // An empty bucket answers "not found".
  if (status == NATS_NOT_FOUND) return std::vector<std::string>();
  if (status != NATS_OK) return nats_error(status, "listing job states");
  std::vector<std::string> keys(list.Keys, list.Keys + list.Count);
  kvKeysList_Destroy(&list);
  return keys;
}

absl::Status JobStates::remove(const std::string& key) {
  return nats_error(kvStore_Purge(store_, key.c_str(), nullptr),
                    absl::StrCat("removing job state ", key));
}

}  // namespace labelmesh::cluster
