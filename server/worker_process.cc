// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/worker_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <thread>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "absl/strings/str_split.h"
#include "server/event_pipe.h"
#include "server/worker_protocol.h"
#include "spdlog/spdlog.h"

namespace labelmesh::server {
namespace {

constexpr int kChildEventFd = 3;

// Reaps `pid` if it exits before `deadline`; otherwise kills and reaps it.
// True if it exited by itself.
bool exited_before(pid_t pid, std::chrono::steady_clock::time_point deadline, int& status) {
  while (std::chrono::steady_clock::now() < deadline) {
    if (waitpid(pid, &status, WNOHANG) == pid) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  return false;
}

// What a child writes on `fd`, read until it closes it, `limit` bytes have
// come, `deadline` passes or `keep_going` (asked at least twice a second)
// says stop.
struct ChildOutput {
  std::string text;
  bool closed = false;
  bool stopped = false;
};

ChildOutput read_child_output(
    int fd, std::chrono::steady_clock::time_point deadline, size_t limit,
    const std::function<bool()>& keep_going = [] { return true; }) {
  ChildOutput output;
  char buffer[512];
  while (output.text.size() < limit) {
    if (!keep_going()) {
      output.stopped = true;
      break;
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd readable{.fd = fd, .events = POLLIN, .revents = 0};
    const int ready = ::poll(&readable, 1, int(std::min<int64_t>(left.count(), 500)));
    if (ready == 0 || (ready < 0 && errno == EINTR)) continue;
    if (ready < 0) break;
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      output.closed = n == 0;
      break;
    }
    output.text.append(buffer, size_t(n));
  }
  return output;
}

struct ChildSetup {
  pid_t server_pid;
  int event_write_fd;
  int log_fd;
  int null_fd;
  WorkerLimits limits;
  // The server's environment, plus the worker's thread budget.
  char* const* environment;
};

// Between fork and exec only async-signal-safe calls are allowed.
[[noreturn]] void exec_child(const ChildSetup& setup, char* const argv[]) {
  // A worker dies with its server: no job runs on with nobody to hear it.
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (getppid() != setup.server_pid) _exit(127);  // The server died already.
  setpgid(0, 0);  // Terminal signals go to the server, which decides.
  // The server blocks SIGTERM and SIGINT for its sigwait; the worker must
  // not inherit that, nor any signal the server ignores.
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, nullptr);
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  for (int number = 1; number < NSIG; ++number) sigaction(number, &default_action, nullptr);
  rlimit no_core{0, 0};
  setrlimit(RLIMIT_CORE, &no_core);
#if !defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer reserves terabytes of shadow address space.
  if (setup.limits.memory_bytes > 0) {
    rlimit memory{setup.limits.memory_bytes, setup.limits.memory_bytes};
    setrlimit(RLIMIT_AS, &memory);
  }
#endif
  if (setup.limits.cpu_seconds > 0) {
    // SIGXCPU at the soft limit, SIGKILL five seconds later.
    rlimit cpu{setup.limits.cpu_seconds, setup.limits.cpu_seconds + 5};
    setrlimit(RLIMIT_CPU, &cpu);
  }
  if (setup.limits.output_file_bytes > 0) {
    // SIGXFSZ ends the worker when a write would pass it. A lower limit
    // inherited from the server stays.
    rlimit file_size{};
    getrlimit(RLIMIT_FSIZE, &file_size);
    if (file_size.rlim_cur == RLIM_INFINITY || file_size.rlim_cur > setup.limits.output_file_bytes)
      file_size.rlim_cur = setup.limits.output_file_bytes;
    setrlimit(RLIMIT_FSIZE, &file_size);
  }
  dup2(setup.null_fd, STDIN_FILENO);
  dup2(setup.log_fd, STDOUT_FILENO);
  dup2(setup.log_fd, STDERR_FILENO);
  dup2(setup.event_write_fd, kChildEventFd);
  // Nothing of the server's (sockets, other jobs' pipes) reaches the child.
  close_range(kChildEventFd + 1, ~0U, 0);
  execve(argv[0], argv, setup.environment);
  _exit(127);
}

std::string signal_description(int signal_number) {
  const char* name = sigabbrev_np(signal_number);
  return absl::StrCat("signal ", signal_number, " (SIG", name ? name : "?", ")");
}

WorkerOutcome failed(absl::StatusCode code, std::string message) {
  WorkerOutcome outcome;
  outcome.kind = WorkerOutcome::Kind::kFailed;
  outcome.code = static_cast<int>(code);
  outcome.message = std::move(message);
  return outcome;
}

// What a child that ended without a result died of, from its wait status
// and the CPU seconds it used against its limits.
WorkerOutcome outcome_of_exit(int wait_status, double cpu_seconds_used,
                              const WorkerLimits& limits) {
  const uint64_t cpu_limit = limits.cpu_seconds;
  if (WIFSIGNALED(wait_status)) {
    const int number = WTERMSIG(wait_status);
    if (number == SIGXFSZ) {
      return failed(
          absl::StatusCode::kResourceExhausted,
          absl::StrCat("a result file reached the job's output limit of ", limits.output_file_bytes,
                       " bytes and the worker was stopped (", signal_description(number), ")"));
    }
    // The kernel sends SIGXCPU at the soft CPU limit and SIGKILL at the hard.
    const bool over_cpu = number == SIGXCPU || (number == SIGKILL && cpu_limit > 0 &&
                                                cpu_seconds_used >= double(cpu_limit));
    if (over_cpu) {
      return failed(absl::StatusCode::kResourceExhausted,
                    absl::StrCat("the worker went over its CPU time limit of ", cpu_limit,
                                 " s and was killed (", signal_description(number), ")"));
    }
    if (number == SIGKILL || number == SIGTERM) {
      // labelmeshd's own stops (cancel, deadline, shutdown) are reported
      // before this; this one came from outside.
      return failed(absl::StatusCode::kInternal,
                    absl::StrCat("the worker was killed from outside labelmeshd by ",
                                 signal_description(number),
                                 number == SIGKILL ? " (the kernel's out-of-memory killer, or an "
                                                     "operator)"
                                                   : ""));
    }
    return failed(absl::StatusCode::kInternal,
                  absl::StrCat("the worker crashed with ", signal_description(number)));
  }
  const int code = WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : -1;
  return failed(absl::StatusCode::kInternal,
                absl::StrCat("the worker exited with status ", code, " without a result"));
}

// Why the job must stop now, if it must: a cancel, a shutdown or the deadline.
std::optional<WorkerOutcome> stop_requested(const WorkerRun& run) {
  const StopRequest request = run.stop_request ? run.stop_request() : StopRequest::kNone;
  if (request == StopRequest::kCancel) {
    return WorkerOutcome{WorkerOutcome::Kind::kCancelled, 0, "", {}};
  }
  if (request == StopRequest::kShutdown) {
    return WorkerOutcome{WorkerOutcome::Kind::kInterrupted, 0, "", {}};
  }
  if (absl::Now() >= run.deadline) {
    return failed(absl::StatusCode::kDeadlineExceeded,
                  "the job ran over the server's job time limit and was stopped");
  }
  return std::nullopt;
}

}  // namespace

WorkerOutcome run_worker_process(const WorkerRun& run) {
  int pipe_fds[2];
  if (pipe2(pipe_fds, O_CLOEXEC) != 0) {
    return failed(absl::StatusCode::kInternal, "cannot create the worker's event pipe");
  }
  const int log_fd = ::open(run.log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0640);
  const int null_fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  std::string executable = run.executable, job_dir = run.job_dir, output_dir = run.output_dir;
  std::string mode = kWorkerMode;
  std::vector<char*> argv{executable.data(), mode.data(), job_dir.data(), output_dir.data(),
                          nullptr};
  // Built before fork: the child may only make async-signal-safe calls.
  std::vector<std::string> variables;
  for (char** v = environ; *v != nullptr; ++v) {
    if (!absl::StartsWith(*v, absl::StrCat(kJobThreadsVariable, "="))) variables.emplace_back(*v);
  }
  if (run.limits.threads > 0)
    variables.push_back(absl::StrCat(kJobThreadsVariable, "=", run.limits.threads));
  std::vector<char*> environment;
  for (auto& variable : variables) environment.push_back(variable.data());
  environment.push_back(nullptr);
  const ChildSetup setup{getpid(), pipe_fds[1], log_fd >= 0 ? log_fd : null_fd,
                         null_fd,  run.limits,  environment.data()};

  const pid_t pid = fork();
  if (pid == 0) exec_child(setup, argv.data());
  ::close(pipe_fds[1]);
  if (log_fd >= 0) ::close(log_fd);
  if (null_fd >= 0) ::close(null_fd);
  if (pid < 0) {
    ::close(pipe_fds[0]);
    return failed(absl::StatusCode::kInternal,
                  absl::StrCat("cannot start a worker: ", std::strerror(errno)));
  }

  EventPipeReader reader;
  std::optional<WorkerOutcome> result;
  std::optional<WorkerOutcome> stopped;
  char buffer[1 << 16];
  bool open = true;
  // Reads what the pipe holds, waiting up to `wait_ms` for it, and handles
  // the events in it. False when nothing came.
  auto read_events = [&](int wait_ms) {
    pollfd watch{pipe_fds[0], POLLIN, 0};
    if (poll(&watch, 1, wait_ms) <= 0) return false;
    const ssize_t n = ::read(pipe_fds[0], buffer, sizeof buffer);
    if (n > 0) {
      reader.append(buffer, static_cast<size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      open = false;
    }
    for (;;) {
      auto event = reader.next();
      if (!event.ok()) {
        stopped = failed(absl::StatusCode::kInternal, std::string(event.status().message()));
        return false;
      }
      if (!event->has_value()) break;
      v1::JobEvent& e = **event;
      if (e.has_finished()) {
        result = WorkerOutcome{WorkerOutcome::Kind::kSucceeded, 0, "", e.finished().report()};
      } else if (e.has_failed()) {
        result = failed(static_cast<absl::StatusCode>(e.failed().code()), e.failed().message());
      } else if (run.on_event) {
        run.on_event(std::move(e));
      }
    }
    return n > 0;
  };
  while (open && !stopped) {
    read_events(100);
    if (!open || stopped) break;
    if (auto stop = stop_requested(run)) {
      // An outcome the worker has sent stands, even if it is still in the
      // pipe: read what is there (a bounded amount) before deciding. A
      // cancel or the deadline then only stops the worker lingering.
      for (int reads = 0; reads < 64 && open && !stopped && !result && read_events(0); ++reads) {
      }
      if (!result && !stopped) stopped = std::move(stop);
      break;
    }
  }
  if (open || stopped) ::kill(pid, SIGKILL);
  ::close(pipe_fds[0]);
  int wait_status = 0;
  rusage usage{};
  while (wait4(pid, &wait_status, 0, &usage) < 0 && errno == EINTR) {
  }
  const double cpu_seconds_used = double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                                  1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  if (stopped) return *stopped;
  if (result) return *result;
  return outcome_of_exit(wait_status, cpu_seconds_used, run.limits);
}

std::string worker_executable(const ServerConfig& config) {
  if (!config.worker_executable.empty()) return config.worker_executable;
  std::error_code error;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", error);
  return (error ? std::filesystem::path("labelmesh-worker")
                : self.parent_path() / "labelmesh-worker")
      .string();
}

absl::Status check_worker_version(const std::string& executable,
                                  std::chrono::milliseconds answer_time) {
  int out[2];
  if (pipe2(out, O_CLOEXEC) != 0) return absl::InternalError("cannot create a pipe");
  std::string path = executable, flag = "--version";
  std::vector<char*> argv{path.data(), flag.data(), nullptr};
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(out[1], STDOUT_FILENO);
    execv(argv[0], argv.data());
    _exit(127);
  }
  ::close(out[1]);
  // A worker that hangs must not hang the server's start: it is killed once
  // its time to answer is over.
  const auto deadline = std::chrono::steady_clock::now() + answer_time;
  const ChildOutput output = pid > 0 ? read_child_output(out[0], deadline, 4096) : ChildOutput{};
  const std::string& printed = output.text;
  bool answered = output.closed;
  ::close(out[0]);
  int status = 0;
  // Whoever prints more than a version line is not our worker: no waiting.
  const bool too_long = printed.size() >= 4096;
  if (pid > 0 &&
      !exited_before(pid, too_long ? std::chrono::steady_clock::now() : deadline, status) &&
      !too_long)
    answered = false;
  if (pid > 0 && !answered && !too_long)
    return absl::FailedPreconditionError(absl::StrCat(
        "worker ", executable, ": did not answer --version within ", answer_time.count(), " ms"));
  const std::string line(absl::StripAsciiWhitespace(printed));
  if (pid > 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0 && line == kWorkerVersionLine)
    return absl::OkStatus();
  if (pid > 0 && WIFEXITED(status) && WEXITSTATUS(status) == 127)
    return absl::FailedPreconditionError(
        absl::StrCat("worker ", executable,
                     ": cannot be run (install labelmesh-worker beside "
                     "labelmeshd, or name it with --worker-executable)"));
  return absl::FailedPreconditionError(
      absl::StrCat("worker ", executable, ": --version printed '",
                   line.substr(0, std::min<size_t>(line.find('\n'), 80)), "', expected '",
                   kWorkerVersionLine, "'"));
}

absl::Status check_volume_in_worker(const std::string& executable, const std::string& path,
                                    uint64_t max_voxels, bool separate_overlapping,
                                    uint64_t memory_bytes, std::chrono::milliseconds time_limit,
                                    const std::function<bool()>& keep_going) {
  int out[2];
  if (pipe2(out, O_CLOEXEC) != 0) return absl::UnavailableError("cannot create a pipe");
  const int null_fd = ::open("/dev/null", O_RDWR | O_CLOEXEC);
  std::string program = executable, mode = kCheckVolumeMode, file = path,
              voxels = std::to_string(max_voxels),
              overlapping = separate_overlapping ? "separate" : "refuse";
  std::vector<char*> argv{program.data(), mode.data(),        file.data(),
                          voxels.data(),  overlapping.data(), nullptr};
  // The same child as a job's: its answer comes on descriptor 3, its
  // stdout and stderr (VTK's messages) go nowhere.
  ChildSetup setup{.server_pid = getpid(),
                   .event_write_fd = out[1],
                   .log_fd = null_fd,
                   .null_fd = null_fd,
                   .limits = {.memory_bytes = memory_bytes,
                              .cpu_seconds = uint64_t(time_limit.count() / 1000 + 1)},
                   .environment = environ};
  const pid_t pid = fork();
  if (pid == 0) exec_child(setup, argv.data());
  ::close(out[1]);
  ::close(null_fd);
  if (pid < 0) {
    ::close(out[0]);
    return absl::UnavailableError("cannot start a worker to read the upload; try again later");
  }
  const auto deadline = std::chrono::steady_clock::now() + time_limit;
  const ChildOutput output = read_child_output(out[0], deadline, 4096, keep_going);
  const std::string& printed = output.text;
  const bool stopped = output.stopped;
  ::close(out[0]);
  int status = 0;
  const bool exited =
      exited_before(pid, stopped ? std::chrono::steady_clock::now() : deadline, status);
  if (stopped) return absl::CancelledError("upload: the client left while the volume was read");
  if (!exited) {
    return absl::ResourceExhaustedError(absl::StrCat("upload: reading the volume took longer than ",
                                                     time_limit.count() / 1000, " s"));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return absl::OkStatus();
  if (WIFEXITED(status) && WEXITSTATUS(status) == 1) {
    return absl::InvalidArgumentError(
        absl::StrReplaceAll(printed.substr(0, 4096), {{path, "upload"}}));
  }
  // Over the memory or CPU limit (an allocation failing where nothing
  // catches it, SIGXCPU) or crashed: a job on it could not run either.
  return absl::ResourceExhaustedError(absl::StrCat(
      "upload: the volume could not be read within a worker's memory and time limits (",
      WIFSIGNALED(status) ? signal_description(WTERMSIG(status)) : "exit status", ")"));
}

int kill_stale_workers(const std::string& spool_root) {
  const std::string jobs = absl::StrCat(spool_root, "/jobs/");
  int killed = 0;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator("/proc", error)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || !std::all_of(name.begin(), name.end(), ::isdigit)) continue;
    std::ifstream in(entry.path() / "cmdline", std::ios::binary);
    std::string cmdline((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    // argv: <worker> --worker <spool>/jobs/<id> <out dir>, after an interpreter's own
    // arguments when the worker is a script.
    std::vector<std::string> argv = absl::StrSplit(cmdline, '\0');
    bool stale = false;
    for (size_t i = 1; i + 1 < argv.size() && !stale; ++i)
      stale = argv[i] == kWorkerMode && absl::StartsWith(argv[i + 1], jobs);
    if (!stale) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(name));
    if (pid == getpid() || ::kill(pid, SIGKILL) != 0) continue;
    spdlog::warn("killed worker {} left running by an earlier server on this spool", pid);
    ++killed;
  }
  return killed;
}

}  // namespace labelmesh::server
