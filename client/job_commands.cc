// SPDX-License-Identifier: AGPL-3.0-or-later
// Commands about jobs on a labelmeshd server: watch, status, fetch, cancel,
// delete, list, health. Each takes --json and the connection flags.
#include <CLI/CLI.hpp>

#include <ctime>

#include "absl/status/status.h"

#include "client/commands.h"
#include "client/exit_codes.h"
#include "client/job_follow.h"
#include "client/label_warnings.h"
#include "client/report_table.h"
#include "client/server_connection.h"
#include "core/pipeline/report.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "labelmesh/v1/service.grpc.pb.h"

namespace labelmesh::client {
namespace {

constexpr std::chrono::seconds kCallTimeout{30};

struct JobFlags {
  std::string job_id;
  std::string out_dir;
  std::string artifact;
  std::vector<std::string> states;
  ConnectionFlags connection;
  bool json = false;
};

CLI::App* add_job_command(CLI::App& app, const std::string& name, const std::string& help,
                          JobFlags& flags, bool takes_job) {
  CLI::App* command = app.add_subcommand(name, help);
  if (takes_job) command->add_option("job", flags.job_id, "Job id")->required();
  add_connection_flags(*command, flags.connection);
  command->add_flag("--json", flags.json, "Print JSON on stdout");
  command->footer(kExitCodeHelp);
  return command;
}

int fail(const char* command, const absl::Status& status) {
  std::fprintf(stderr, "labelmesh %s: %s\n", command, std::string(status.message()).c_str());
  return exit_code_for_call(status);
}

std::string state_name(v1::JobState state) {
  std::string name = v1::JobState_Name(state);
  // A state this client does not know (from a newer server) has no name.
  const std::string prefix = "JOB_STATE_";
  if (name.rfind(prefix, 0) != 0) return "state " + std::to_string(int(state));
  name = name.substr(prefix.size());
  for (char& c : name) c = static_cast<char>(std::tolower(c));
  return name;
}

void print_job_line(const v1::Job& job) {
  char created[32] = "";
  const std::time_t when = static_cast<std::time_t>(job.created_at());
  if (const std::tm* local = std::localtime(&when))
    std::strftime(created, sizeof created, "%Y-%m-%d %H:%M:%S", local);
  std::printf("%s  %-9s  %s", job.job_id().c_str(), state_name(job.state()).c_str(), created);
  if (job.state() == v1::JOB_STATE_QUEUED) std::printf("  position %u", job.queue_position());
  if (job.state() == v1::JOB_STATE_RUNNING) {
    std::printf("  %s %.0f %%", job.stage().c_str(), 100 * job.progress());
  }
  if (job.state() == v1::JOB_STATE_FAILED) std::printf("  %s", job.error().message().c_str());
  std::printf("\n");
}

int run_watch(const JobFlags& flags) {
  auto connection = ServerConnection::open(flags.connection);
  if (!connection.ok()) return fail("watch", connection.status());
  auto job = follow_job(*connection, flags.job_id, FollowOptions{.json = flags.json});
  if (!job.ok()) return fail("watch", job.status());
  if (!flags.json) print_job_line(*job);
  print_label_warnings("watch", job->report());
  return exit_code_for_job(*job);
}

int run_status(const JobFlags& flags) {
  auto connection = ServerConnection::open(flags.connection);
  if (!connection.ok()) return fail("status", connection.status());
  auto stub = v1::MeshingService::NewStub(connection->channel());
  auto context = connection->context(kCallTimeout);
  v1::GetJobRequest request;
  request.set_job_id(flags.job_id);
  v1::Job job;
  if (auto status = stub->GetJob(context.get(), request, &job); !status.ok()) {
    return fail("status", from_grpc(status));
  }
  if (flags.json) {
    std::printf("%s\n", to_json(job).c_str());
  } else {
    print_job_line(job);
  }
  print_label_warnings("status", job.report());
  return kExitSuccess;
}

int run_fetch(const JobFlags& flags) {
  auto connection = ServerConnection::open(flags.connection);
  if (!connection.ok()) return fail("fetch", connection.status());
  std::optional<std::string> only;
  if (!flags.artifact.empty()) only = flags.artifact;
  auto written = fetch_artifacts(*connection, flags.job_id, flags.out_dir, only);
  if (!written.ok()) return fail("fetch", written.status());
  // The files alone do not say which labels were left out: the report does.
  auto stub = v1::MeshingService::NewStub(connection->channel());
  auto context = connection->context(kCallTimeout);
  v1::GetJobRequest request;
  request.set_job_id(flags.job_id);
  v1::Job job;
  const bool known = stub->GetJob(context.get(), request, &job).ok();
  if (known) print_label_warnings("fetch", job.report());
  if (flags.json) {
    std::printf("{\"job_id\": \"%s\", \"files\": %d}\n", flags.job_id.c_str(), *written);
  } else {
    if (known && job.has_report()) std::printf("%s", report_table(job.report()).c_str());
    std::printf("%d files written to %s\n", *written, flags.out_dir.c_str());
  }
  return kExitSuccess;
}

int run_cancel(const JobFlags& flags) {
  auto connection = ServerConnection::open(flags.connection);
  if (!connection.ok()) return fail("cancel", connection.status());
  auto stub = v1::MeshingService::NewStub(connection->channel());
  auto context = connection->context(kCallTimeout);
  v1::CancelRequest request;
  request.set_job_id(flags.job_id);
  v1::Job job;
  if (auto status = stub->Cancel(context.get(), request, &job); !status.ok()) {
    return fail("cancel", from_grpc(status));
  }
  if (flags.json) {
    std::printf("%s\n", to_json(job).c_str());
  } else {
    std::printf("%s: %s\n", job.job_id().c_str(),
                job.state() == v1::JOB_STATE_CANCELLED ? "cancelled" : "cancelling");
  }
  return kExitSuccess;
}

int run_delete(const JobFlags& flags) {
  auto connection = ServerConnection::open(flags.connection);
  if (!connection.ok()) return fail("delete", connection.status());
  auto stub = v1::MeshingService::NewStub(connection->channel());
  auto context = connection->context(kCallTimeout);
  v1::DeleteJobRequest request;
  request.set_job_id(flags.job_id);
  v1::DeleteJobReply reply;
  if (auto status = stub->DeleteJob(context.get(), request, &reply); !status.ok()) {
    return fail("delete", from_grpc(status));
  }
  if (flags.json) {
    std::printf("{\"job_id\": \"%s\", \"state\": \"%s\"}\n", flags.job_id.c_str(),
                state_name(reply.state()).c_str());
  } else {
    std::printf("%s: deleted (was %s)\n", flags.job_id.c_str(), state_name(reply.state()).c_str());
  }
  return kExitSuccess;
}

int run_list(const JobFlags& flags) {
  auto connection = ServerConnection::open(flags.connection);
  if (!connection.ok()) return fail("list", connection.status());
  auto stub = v1::MeshingService::NewStub(connection->channel());
  v1::ListJobsRequest request;
  for (const auto& name : flags.states) {
    v1::JobState state;
    std::string upper = "JOB_STATE_" + name;
    for (char& c : upper) c = static_cast<char>(std::toupper(c));
    if (!v1::JobState_Parse(upper, &state) || state == v1::JOB_STATE_UNSPECIFIED) {
      return fail("list", absl::InvalidArgumentError(
                              "--state: " + name +
                              " is not one of queued, running, succeeded, failed, cancelled"));
    }
    request.add_states(state);
  }
  // Every page, in order: the listing is the caller's jobs, newest first.
  v1::ListJobsReply all;
  do {
    auto context = connection->context(kCallTimeout);
    v1::ListJobsReply page;
    if (auto status = stub->ListJobs(context.get(), request, &page); !status.ok()) {
      return fail("list", from_grpc(status));
    }
    for (auto& job : *page.mutable_jobs()) *all.add_jobs() = std::move(job);
    request.set_page_token(page.next_page_token());
  } while (!request.page_token().empty());
  if (flags.json) {
    std::printf("%s\n", to_json(all).c_str());
  } else {
    for (const auto& job : all.jobs()) print_job_line(job);
  }
  return kExitSuccess;
}

int run_health(const JobFlags& flags) {
  auto connection = ServerConnection::open(flags.connection);
  if (!connection.ok()) return fail("health", connection.status());
  auto stub = grpc::health::v1::Health::NewStub(connection->channel());
  auto context = connection->context(std::chrono::seconds(5));
  grpc::health::v1::HealthCheckResponse reply;
  if (auto status = stub->Check(context.get(), grpc::health::v1::HealthCheckRequest(), &reply);
      !status.ok()) {
    return fail("health", from_grpc(status));
  }
  const bool serving = reply.status() == grpc::health::v1::HealthCheckResponse::SERVING;
  if (flags.json) {
    std::printf("{\"status\": \"%s\"}\n",
                grpc::health::v1::HealthCheckResponse::ServingStatus_Name(reply.status()).c_str());
  } else {
    std::printf("%s: %s\n", flags.connection.server.c_str(), serving ? "serving" : "not serving");
  }
  return serving ? kExitSuccess : kExitService;
}

}  // namespace

CommandRunner add_watch_command(CLI::App& app) {
  auto flags = std::make_shared<JobFlags>();
  add_job_command(app, "watch", "Follow a job to its end (exit 0 only if it finished)", *flags,
                  true);
  return [flags] { return run_watch(*flags); };
}

CommandRunner add_status_command(CLI::App& app) {
  auto flags = std::make_shared<JobFlags>();
  add_job_command(app, "status", "Show a job's state", *flags, true);
  return [flags] { return run_status(*flags); };
}

CommandRunner add_fetch_command(CLI::App& app) {
  auto flags = std::make_shared<JobFlags>();
  CLI::App* fetch = add_job_command(app, "fetch", "Fetch a finished job's files", *flags, true);
  fetch->add_option("--out", flags->out_dir, "Directory to write into")->required();
  fetch->add_option("--artifact", flags->artifact, "Only this file (default: every one)");
  return [flags] { return run_fetch(*flags); };
}

CommandRunner add_cancel_command(CLI::App& app) {
  auto flags = std::make_shared<JobFlags>();
  add_job_command(app, "cancel", "Cancel a queued or running job", *flags, true);
  return [flags] { return run_cancel(*flags); };
}

CommandRunner add_delete_command(CLI::App& app) {
  auto flags = std::make_shared<JobFlags>();
  add_job_command(app, "delete",
                  "Delete a job with its input and results (a running job is stopped first)",
                  *flags, true);
  return [flags] { return run_delete(*flags); };
}

CommandRunner add_list_command(CLI::App& app) {
  auto flags = std::make_shared<JobFlags>();
  CLI::App* list = add_job_command(
      app, "list", "List your jobs (an admin's: everyone's), newest first", *flags, false);
  list->add_option("--state", flags->states,
                   "Only jobs in these states: queued, running, succeeded, failed, cancelled")
      ->delimiter(',');
  return [flags] { return run_list(*flags); };
}

CommandRunner add_health_command(CLI::App& app) {
  auto flags = std::make_shared<JobFlags>();
  add_job_command(app, "health", "Ask the server whether it is serving", *flags, false);
  return [flags] { return run_health(*flags); };
}

}  // namespace labelmesh::client
