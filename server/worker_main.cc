// SPDX-License-Identifier: AGPL-3.0-or-later
// labelmesh-worker: one job, run with the core library, its events sent to
// the parent labelmeshd over file descriptor 3. The server kills it to stop
// it. Only this program links the core library (CGAL, VTK, TetGen); the
// serving process does not.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include <fcntl.h>
#include <sys/prctl.h>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <new>
#include <string_view>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "core/pipeline/job_options.h"
#include "core/pipeline/pipeline.h"
#include "core/pipeline/report.h"
#include "core/pipeline/write_results.h"
#include "core/volume/read_label_volume.h"
#include "server/event_pipe.h"
#include "server/worker_process.h"

namespace labelmesh::server {
namespace {

using Clock = std::chrono::steady_clock;

// Turns the pipeline's progress callbacks into stage and progress events.
// Some stages report only when they are done (fraction 1), so a stage is
// taken to start when the one before it last reported, not at its own first
// report.
class StageEvents {
 public:
  explicit StageEvents(int fd) : fd_(fd), last_report_(Clock::now()) {}

  void update(std::string_view stage, double fraction) {
    const Clock::time_point now = Clock::now();
    if (stage != stage_) {
      finish_stage();
      stage_ = std::string(stage);
      stage_start_ = last_report_;
      percent_ = -1;
      v1::JobEvent event;
      event.mutable_stage_started()->set_stage(stage_);
      write_event(fd_, event);
    }
    last_report_ = now;
    const int percent = static_cast<int>(fraction * 100);
    if (percent == percent_) return;
    percent_ = percent;
    v1::JobEvent event;
    event.mutable_progress()->set_stage(stage_);
    event.mutable_progress()->set_fraction(fraction);
    write_event(fd_, event);
  }

  void finish_stage() {
    if (stage_.empty()) return;
    v1::JobEvent event;
    event.mutable_stage_finished()->set_stage(stage_);
    event.mutable_stage_finished()->set_seconds(
        std::chrono::duration<double>(last_report_ - stage_start_).count());
    write_event(fd_, event);
    stage_.clear();
  }

 private:
  int fd_;
  std::string stage_;
  int percent_ = -1;
  Clock::time_point stage_start_;
  Clock::time_point last_report_;
};

void send_failure(int fd, const absl::Status& status, const std::string& job_dir) {
  v1::JobEvent event;
  event.mutable_failed()->set_code(static_cast<int>(status.code()));
  // Paths inside the spool mean nothing to the client: name the input plainly.
  event.mutable_failed()->set_message(
      absl::StrReplaceAll(status.message(), {{absl::StrCat(job_dir, "/"), ""}}));
  write_event(fd, event);
}

absl::Status run_job(const std::string& job_dir, const std::string& out_dir, int fd) {
  v1::JobRecord record;
  {
    std::ifstream in(absl::StrCat(job_dir, "/job.pb"), std::ios::binary);
    if (!in || !record.ParseFromIstream(&in)) {
      return absl::InternalError("the worker cannot read its job record");
    }
  }
  auto params = params_from_options(record.spec().options());
  if (!params.ok()) return params.status();
  // The server's share of the cores for each worker (kJobThreadsVariable).
  if (const char* threads = std::getenv(kJobThreadsVariable)) {
    params->threads = static_cast<unsigned>(std::clamp(std::atoi(threads), 1, 256));
  }
  StageEvents events(fd);
  RunContext context;
  context.progress = [&events](std::string_view stage, double fraction) {
    events.update(stage, fraction);
  };
  auto result =
      run_pipeline(absl::StrCat(job_dir, "/input", record.input_extension()), *params, context);
  if (!result.ok()) return result.status();
  if (auto status = write_results(*result, *params, out_dir, context); !status.ok()) return status;
  events.finish_stage();
  v1::JobEvent finished;
  *finished.mutable_finished()->mutable_report() = make_report(*result, *params);
  if (!write_event(fd, finished)) return absl::InternalError("the server stopped listening");
  return absl::OkStatus();
}

}  // namespace

int check_volume(const std::string& path, const std::string& max_voxels) {
  volume::ReadLimits limits;
  limits.allow_data_file = false;
  if (!absl::SimpleAtoi(max_voxels, &limits.max_voxels)) return 2;
  absl::Status status;
  try {
    status = volume::read_label_volume(path, limits, RunContext()).status();
  } catch (const std::bad_alloc&) {
    status = absl::ResourceExhaustedError("the volume does not fit the worker's memory");
  } catch (const std::exception& e) {
    status = absl::InvalidArgumentError(absl::StrCat("the volume cannot be read: ", e.what()));
  }
  if (status.ok()) return 0;
  const std::string message(status.message());
  (void)!::write(3, message.data(), message.size());
  return 1;
}

int run_worker(const std::string& job_dir, const std::string& out_dir, int event_fd) {
  absl::Status status;
  try {
    status = run_job(job_dir, out_dir, event_fd);
  } catch (const std::bad_alloc&) {
    status = absl::ResourceExhaustedError("the job ran out of memory in the worker");
  } catch (const std::exception& e) {
    status = absl::InternalError(absl::StrCat("the worker failed: ", e.what()));
  }
  if (!status.ok()) send_failure(event_fd, status, job_dir);
  return status.ok() ? 0 : 1;
}

}  // namespace labelmesh::server

int main(int argc, char** argv) {
  using labelmesh::server::kWorkerMode;
  if (argc == 2 && std::string_view(argv[1]) == "--version") {
    std::printf("%s\n", labelmesh::server::kWorkerVersionLine);
    return 0;
  }
  if (argc == 4 && std::string_view(argv[1]) == labelmesh::server::kCheckVolumeMode &&
      fcntl(3, F_GETFD) != -1) {
    return labelmesh::server::check_volume(argv[2], argv[3]);
  }
  // Only labelmeshd starts it, with the event pipe as descriptor 3: refuse
  // anything else.
  if (argc != 4 || std::string_view(argv[1]) != kWorkerMode || fcntl(3, F_GETFD) == -1 ||
      !std::filesystem::is_regular_file(std::filesystem::path(argv[2]) / "job.pb") ||
      std::filesystem::path(argv[3]).parent_path() != std::filesystem::path(argv[2]) ||
      !std::filesystem::path(argv[3]).filename().string().starts_with("out-")) {
    std::fprintf(stderr,
                 "labelmesh-worker runs one job for labelmeshd, which starts it as "
                 "`labelmesh-worker --worker JOB_DIR JOB_DIR/out-N` with an event pipe; it is "
                 "not run by hand\n");
    return 2;
  }
  // `ps -o comm` and top show which job this is: "lmw-" and the job id's
  // first eleven digits (the kernel keeps 15 characters).
  const std::string job = std::filesystem::path(argv[2]).filename().string();
  prctl(PR_SET_NAME, ("lmw-" + job.substr(0, 11)).c_str());
  return labelmesh::server::run_worker(argv[2], argv[3], 3);
}
