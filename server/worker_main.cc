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
#include <map>
#include <new>
#include <string>
#include <string_view>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "core/job/job_options.h"
#include "core/pipeline/pipeline.h"
#include "core/pipeline/report.h"
#include "core/pipeline/write_results.h"
#include "core/util/status_macros.h"
#include "core/volume/read_label_volume.h"
#include "server/event_pipe.h"
#include "server/worker_protocol.h"

namespace labelmesh::server {
namespace {

using Clock = std::chrono::steady_clock;

// Turns the pipeline's progress callbacks into stage and progress events.
// Some stages report only when they are done (fraction 1), so a stage is
// taken to start when the one before it last reported, not at its own first
// report. Stages that work label by label run for several labels at once and
// interleave: each is started once, at its first report, and all of them end
// together when the next whole-volume stage begins, so a watcher sees every
// stage once.
class StageEvents {
 public:
  explicit StageEvents(int fd) : fd_(fd), last_report_(Clock::now()) {}

  void update(const ProgressUpdate& update) {
    const Clock::time_point now = Clock::now();
    const bool labelled = update.label != nullptr;
    if (!labelled && (open_.size() != 1 || open_.front().name != update.stage)) finish_stage();
    if (labelled && !open_.empty() && !open_.front().labelled) finish_stage();
    if (!is_open(update.stage)) {
      open_.push_back({std::string(update.stage), labelled, last_report_, now});
      v1::JobEvent event;
      event.mutable_stage_started()->set_stage(std::string(update.stage));
      write_event(fd_, event);
    }
    for (auto& stage : open_)
      if (stage.name == update.stage) stage.last = now;
    last_report_ = now;
    send_progress(update, now);
  }

  // Ends every open stage, in the order they started.
  void finish_stage() {
    for (const auto& stage : open_) {
      v1::JobEvent event;
      event.mutable_stage_finished()->set_stage(stage.name);
      event.mutable_stage_finished()->set_seconds(
          std::chrono::duration<double>(stage.last - stage.start).count());
      write_event(fd_, event);
    }
    open_.clear();
  }

 private:
  struct OpenStage {
    std::string name;
    bool labelled;
    Clock::time_point start, last;
  };

  bool is_open(std::string_view name) const {
    for (const auto& stage : open_)
      if (stage.name == name) return true;
    return false;
  }

  // A progress event for each stage (of each label) as it starts, then when
  // its percentage moves: at most one each 50 ms for a label's stage, since
  // labels interleave and report often, but always its end.
  void send_progress(const ProgressUpdate& update, Clock::time_point now) {
    const int percent = static_cast<int>(update.fraction * 100);
    const int32_t label = update.label ? update.label->label : 0;
    const auto key = std::make_pair(label, std::string(update.stage));
    const auto found = sent_.find(key);
    if (found != sent_.end()) {
      const Sent& last = found->second;
      if (percent == last.percent) return;
      if (label != 0 && percent < 100 && now - last.at < std::chrono::milliseconds(50)) return;
    }
    sent_[key] = {percent, now};
    v1::JobEvent event;
    auto* progress = event.mutable_progress();
    progress->set_stage(key.second);
    progress->set_fraction(update.fraction);
    if (const LabelInProgress* in_progress = update.label) {
      progress->set_label(in_progress->label);
      progress->set_label_name(in_progress->name);
      progress->set_label_index(in_progress->index);
      progress->set_label_count(in_progress->count);
      progress->set_labels_done(in_progress->done);
    }
    write_event(fd_, event);
  }

  int fd_;
  std::vector<OpenStage> open_;
  Clock::time_point last_report_;
  struct Sent {
    int percent;
    Clock::time_point at;
  };
  // The last event sent for each (label, stage).
  std::map<std::pair<int32_t, std::string>, Sent> sent_;
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
  // Never meshed with defaults in place of options the record lacks.
  if (!record.job().has_options()) return absl::InternalError("the job record holds no options");
  LABELMESH_ASSIGN_OR_RETURN(auto params, params_from_options(record.job().options()));
  // The server's share of the cores for each worker (kJobThreadsVariable).
  if (const char* threads = std::getenv(kJobThreadsVariable)) {
    params.threads = static_cast<unsigned>(std::clamp(std::atoi(threads), 1, 256));
  }
  StageEvents events(fd);
  RunContext context;
  context.progress = [&events](const ProgressUpdate& update) { events.update(update); };
  auto result =
      run_pipeline(absl::StrCat(job_dir, "/input", record.input_extension()), params, context);
  if (!result.ok()) return result.status();
  LABELMESH_RETURN_IF_ERROR(write_results(*result, params, out_dir, context));
  events.finish_stage();
  v1::JobEvent finished;
  *finished.mutable_finished()->mutable_report() = make_report(*result, params);
  if (!write_event(fd, finished)) return absl::InternalError("the server stopped listening");
  return absl::OkStatus();
}

}  // namespace

int check_volume(const std::string& path, const std::string& max_voxels,
                 std::string_view overlapping) {
  volume::ReadLimits limits;
  limits.allow_data_file = false;
  if (!absl::SimpleAtoi(max_voxels, &limits.max_voxels)) return 2;
  if (overlapping != "separate" && overlapping != "refuse") return 2;
  limits.separate_overlapping = overlapping == "separate";
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
  if (argc == 5 && std::string_view(argv[1]) == labelmesh::server::kCheckVolumeMode &&
      fcntl(3, F_GETFD) != -1) {
    return labelmesh::server::check_volume(argv[2], argv[3], argv[4]);
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
