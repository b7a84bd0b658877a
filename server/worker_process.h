// SPDX-License-Identifier: AGPL-3.0-or-later
// Runs one job in a child process (`labelmesh-worker --worker JOB_DIR`) under
// resource limits: CGAL Poisson and TetGen cannot be interrupted mid-call and
// may crash on hostile geometry, so a job that must stop is killed, and a
// crash takes only its own job down.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

#include "absl/status/status.h"
#include "absl/time/time.h"
#include "labelmesh/v1/service.pb.h"
#include "server/server_config.h"

namespace labelmesh::server {

struct WorkerLimits {
  // Labels meshed at once; 0: the worker's default (every core).
  unsigned threads = 0;
  // Address space, bytes; 0 for none.
  uint64_t memory_bytes = 0;
  // CPU time, seconds; 0 for none.
  uint64_t cpu_seconds = 0;
  // Largest file the worker may write, bytes; 0 for no limit of its own.
  uint64_t output_file_bytes = 0;
};

enum class StopRequest { kNone, kCancel, kShutdown };

struct WorkerOutcome {
  enum class Kind { kSucceeded, kFailed, kCancelled, kInterrupted };
  Kind kind = Kind::kFailed;
  // For kFailed: a google.rpc code and the reason.
  int code = 0;
  std::string message;
  // For kSucceeded.
  v1::Report report;
};

struct WorkerRun {
  std::string executable;
  std::string job_dir;
  // Where this attempt writes its results: out-<attempt> in the job's
  // directory.
  std::string output_dir;
  // The child's stderr goes here.
  std::string log_path;
  WorkerLimits limits;
  absl::Time deadline = absl::InfiniteFuture();
  // Stage and progress events as they come.
  std::function<void(v1::JobEvent)> on_event;
  // Polled every 100 ms.
  std::function<StopRequest()> stop_request;
};

WorkerOutcome run_worker_process(const WorkerRun& run);

// The worker executable of `config`: its own, else labelmesh-worker beside
// the running executable.
std::string worker_executable(const ServerConfig& config);

// Reads an uploaded volume whole in a worker process (the server links no
// image library), under the worker memory limit and `time_limit`: the
// payloads the server cannot decode itself (VTK XML arrays) are checked
// before a job is accepted. `keep_going` is asked twice a second; false
// kills the reader (CANCELLED). INVALID_ARGUMENT with the reader's message
// (paths named "upload"); RESOURCE_EXHAUSTED over the memory or time limit.
// `separate_overlapping` is the job's choice for overlapping segments.
absl::Status check_volume_in_worker(const std::string& executable, const std::string& path,
                                    uint64_t max_voxels, bool separate_overlapping,
                                    uint64_t memory_bytes, std::chrono::milliseconds time_limit,
                                    const std::function<bool()>& keep_going);

// Kills the workers of an earlier server on the same spool that are still
// running (a server killed before its workers could see it go), so that
// none writes into a job this server runs again. Returns how many.
int kill_stale_workers(const std::string& spool_root);

// Runs `executable --version` and checks that it prints kWorkerVersionLine,
// so a server never runs jobs on a worker of another version.
// FAILED_PRECONDITION naming the executable otherwise, also when it has not
// exited within `answer_time` (it is then killed).
absl::Status check_worker_version(const std::string& executable,
                                  std::chrono::milliseconds answer_time = std::chrono::seconds(10));

}  // namespace labelmesh::server
