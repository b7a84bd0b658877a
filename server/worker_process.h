// Runs one job in a child process (`labelmeshd --worker JOB_DIR`) under
// resource limits: CGAL Poisson and TetGen cannot be interrupted mid-call and
// may crash on hostile geometry, so a job that must stop is killed, and a
// crash takes only its own job down.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "absl/time/time.h"
#include "labelmesh/v1/service.pb.h"

namespace labelmesh::server {

// The environment variable that tells a worker how many labels to mesh at
// once: the server's cores divided among its workers.
inline constexpr char kJobThreadsVariable[] = "LABELMESH_JOB_THREADS";

struct WorkerLimits {
  // Labels meshed at once; 0: the worker's default (every core).
  unsigned threads = 0;
  // Address space, bytes; 0 for none.
  uint64_t memory_bytes = 0;
  // CPU time, seconds; 0 for none.
  uint64_t cpu_seconds = 0;
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
  // The child's stderr goes here.
  std::string log_path;
  WorkerLimits limits;
  absl::Time deadline = absl::InfiniteFuture();
  // Stage and progress events as they come.
  std::function<void(v1::JobEvent)> on_event;
  // Polled every 100 ms.
  std::function<StopRequest()> stop_request;
};

// The first argument that makes labelmeshd a worker rather than a server.
inline constexpr char kWorkerMode[] = "--worker";

WorkerOutcome run_worker_process(const WorkerRun& run);

// The child's side: runs the pipeline on JOB_DIR/input<ext> into JOB_DIR/out
// and writes events to `event_fd`. Returns the process exit code. Defined in
// worker_main.cc, which only labelmeshd links: the server library itself
// never calls the core pipeline.
int worker_main(const std::string& job_dir, int event_fd);

}  // namespace labelmesh::server
