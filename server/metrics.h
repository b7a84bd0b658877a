// SPDX-License-Identifier: AGPL-3.0-or-later
// The server's Prometheus metrics, all named labelmesh_*, in base units.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "server/refusal.h"

namespace prometheus {
class Registry;
class Exposer;
}  // namespace prometheus

namespace labelmesh::server {

class Metrics {
 public:
  explicit Metrics(int queue_capacity);
  ~Metrics();

  // Serves /metrics on `address`. Errors: INVALID_ARGUMENT when it cannot bind.
  absl::Status expose(const std::string& address);
  // The port /metrics is served on (0 before expose()).
  int port() const;
  // The text exposition format of every metric (what /metrics returns).
  std::string text() const;

  void set_queue_depth(size_t depth);
  void set_running(size_t running);
  // outcome: succeeded, failed, cancelled.
  void job_ended(const std::string& outcome);
  void queue_wait(double seconds);
  void stage_finished(const std::string& stage, double seconds);
  // Counted under the refusal's code (refusal.h).
  void rejected(Refusal why);
  void upload_bytes(uint64_t bytes);
  void set_spool_space(uint64_t free_bytes, bool under_reserve);
  void spool_write_failed();

 private:
  struct Families;
  std::shared_ptr<prometheus::Registry> registry_;
  std::unique_ptr<Families> families_;
  std::unique_ptr<prometheus::Exposer> exposer_;
};

}  // namespace labelmesh::server
