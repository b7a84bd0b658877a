// SPDX-License-Identifier: AGPL-3.0-or-later
// Each job's record, shared by every frontend and worker, in a NATS
// JetStream key-value bucket (file storage). Every change names the
// revision it read: a writer whose view is stale (a worker the queue gave
// up on, whose job went to another) is refused instead of overwriting a
// newer state.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/cluster/nats_client.h"

namespace labelmesh::cluster {

struct Versioned {
  std::string value;
  uint64_t revision = 0;
};

class JobStates {
 public:
  // Opens `bucket`, creating it unless it exists.
  // Errors: those of nats_error, naming the bucket.
  static absl::StatusOr<std::unique_ptr<JobStates>> open(NatsClient& client,
                                                         const std::string& bucket);
  ~JobStates();
  JobStates(const JobStates&) = delete;
  JobStates& operator=(const JobStates&) = delete;

  // Stores a new key's first value; its revision.
  // Errors: ALREADY_EXISTS when the key holds a value.
  absl::StatusOr<uint64_t> create(const std::string& key, const std::string& value);

  // The key's value and revision. Errors: NOT_FOUND.
  absl::StatusOr<Versioned> get(const std::string& key);

  // Replaces the value written at `revision`; the new revision.
  // Errors: ABORTED when another write came after `revision` (read again
  // and decide again); NOT_FOUND when the key is gone.
  absl::StatusOr<uint64_t> update(const std::string& key, const std::string& value,
                                  uint64_t revision);

  // Every key that holds a value.
  absl::StatusOr<std::vector<std::string>> keys();
  // Removes the key (its history too).
  absl::Status remove(const std::string& key);

 private:
  explicit JobStates(kvStore* store) : store_(store) {}
  kvStore* store_;
};

}  // namespace labelmesh::cluster
