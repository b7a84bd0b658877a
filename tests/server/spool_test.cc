// SPDX-License-Identifier: AGPL-3.0-or-later
// The spool under a full disk and with damaged records: a failed write keeps
// the previous record, and an unreadable record is set aside, never deleted.
#include "server/spool.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>

#include "absl/strings/match.h"
#include "server/durable_file.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {
namespace fs = std::filesystem;
using testing::scratch_dir;

v1::JobRecord record_with(const std::string& job_id, v1::JobState state, size_t padding) {
  v1::JobRecord record;
  record.mutable_job()->set_job_id(job_id);
  record.mutable_job()->set_state(state);
  record.mutable_job()->set_created_at(1.0e9);
  // Room for the write to fail in the middle of the record.
  record.mutable_spec()->set_sha256(std::string(padding, 'a'));
  return record;
}

// A small queued job's directory and record.
bool save_queued(const server::Spool& spool, const std::string& id) {
  fs::create_directories(spool.job_dir(id));
  return spool.save(record_with(id, v1::JOB_STATE_QUEUED, 10)).ok();
}

// A full disk, short of a file system of our own: the file size limit makes
// every write past it fail with EFBIG, as ENOSPC would.
TEST(Spool, AFailedWriteKeepsThePreviousRecord) {
  const fs::path root = scratch_dir("SpoolFailedWrite");
  auto spool = server::Spool::open(root.string());
  ASSERT_THAT(spool, testing::IsOk());
  const std::string id = server::new_job_id();
  ASSERT_TRUE(save_queued(*spool, id));

  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{64, 64};
    setrlimit(RLIMIT_FSIZE, &limit);
    const absl::Status status = spool->save(record_with(id, v1::JOB_STATE_CANCELLED, 2000));
    const bool as_expected = status.code() == absl::StatusCode::kResourceExhausted &&
                             absl::StartsWith(status.message(), "spool disk full");
    _exit(as_expected ? 0 : 1);
  }
  int wait_status = 0;
  ASSERT_EQ(waitpid(child, &wait_status, 0), child);
  ASSERT_TRUE(WIFEXITED(wait_status));
  EXPECT_EQ(WEXITSTATUS(wait_status), 0) << "save did not report a full disk";

  const auto records = spool->load_all();
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].job().job_id(), id);
  EXPECT_EQ(records[0].job().state(), v1::JOB_STATE_QUEUED);
  EXPECT_FALSE(fs::exists(fs::path(spool->job_dir(id)) / "job.pb.tmp"));
}

TEST(Spool, UnreadableRecordsAreQuarantinedNotDeleted) {
  const fs::path root = scratch_dir("SpoolQuarantine");
  auto spool = server::Spool::open(root.string());
  ASSERT_THAT(spool, testing::IsOk());
  const std::string good = server::new_job_id();
  ASSERT_TRUE(save_queued(*spool, good));
  // A record cut to nothing, one that is not a record, one naming another
  // job, and a directory that never got its record.
  const std::string empty = server::new_job_id(), garbage = server::new_job_id(),
                    other = server::new_job_id(), unrecorded = server::new_job_id();
  for (const auto& id : {empty, garbage, other, unrecorded})
    fs::create_directories(spool->job_dir(id));
  testing::write_file(fs::path(spool->job_dir(empty)) / "job.pb", "");
  testing::write_file(fs::path(spool->job_dir(garbage)) / "job.pb", "\xff\xff\xff not a record");
  ASSERT_THAT(spool->save(record_with(good, v1::JOB_STATE_QUEUED, 10)), testing::IsOk());
  fs::copy_file(fs::path(spool->job_dir(good)) / "job.pb",
                fs::path(spool->job_dir(other)) / "job.pb");
  std::ofstream(fs::path(spool->job_dir(other)) / "input.nii") << "kept";

  const auto records = spool->load_all();
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].job().job_id(), good);
  EXPECT_EQ(testing::entries_in(root / "quarantine"), 3u);
  EXPECT_EQ(testing::entries_in(root / "jobs"), 1u);
  // What was set aside is whole.
  size_t inputs_kept = 0;
  for (const auto& entry : fs::directory_iterator(root / "quarantine"))
    inputs_kept += fs::exists(entry.path() / "input.nii");
  EXPECT_EQ(inputs_kept, 1u);
}

// A worker of an earlier attempt that is still alive (its server was killed)
// writes into its own attempt's directory, never the next attempt's: the
// next attempt starts from an empty directory of its own.
TEST(Spool, EachAttemptHasItsOwnOutputDirectory) {
  const fs::path root = scratch_dir("SpoolAttemptOutput");
  auto spool = server::Spool::open(root.string());
  ASSERT_THAT(spool, testing::IsOk());
  const std::string id = server::new_job_id();
  ASSERT_TRUE(save_queued(*spool, id));
  ASSERT_THAT(spool->reset_output(id, 1), testing::IsOk());
  testing::write_file(fs::path(spool->output_dir(id, 1)) / "surface-label1.stl", "first");
  ASSERT_THAT(spool->reset_output(id, 2), testing::IsOk());
  EXPECT_FALSE(fs::exists(spool->output_dir(id, 1)));
  EXPECT_EQ(testing::entries_in(spool->output_dir(id, 2)), 0u);
  // What the stale worker writes now lands in out-1, not among the results.
  fs::create_directories(spool->output_dir(id, 1));
  testing::write_file(fs::path(spool->output_dir(id, 1)) / "report.json", "stale");
  testing::write_file(fs::path(spool->output_dir(id, 2)) / "report.json", "{}");
  auto artifacts = spool->collect_artifacts(id, 2);
  ASSERT_THAT(artifacts, testing::IsOk());
  ASSERT_EQ(artifacts->size(), 1u);
  EXPECT_EQ((*artifacts)[0].name(), "report.json");
}

// A folder that changes while it is listed (a stale attempt's, removed under
// it) gives an error, not an exception that ends the worker. A link to
// itself fails the same way, every time.
TEST(Spool, AnEntryThatCannotBeReadIsAnErrorNotACrash) {
  const fs::path out = scratch_dir("SpoolUnreadableEntry");
  testing::write_file(out / "report.json", "{}");
  fs::create_symlink(out / "loop", out / "loop");
  auto artifacts = server::list_artifacts(out.string());
  EXPECT_FALSE(artifacts.ok());
  EXPECT_TRUE(absl::StrContains(artifacts.status().message(), "cannot list the results"))
      << artifacts.status();
  EXPECT_FALSE(server::list_artifacts((out / "gone").string()).ok());
}

// What a client sees of a spool failure names files from the spool's own
// folders on, never where the spool lives on the server.
TEST(SpoolErrors, ClientsSeePathsOnlyFromTheSpoolsFoldersOn) {
  EXPECT_EQ(server::spool_relative("cannot write /srv/spool/uploads/ab12.nii.gz"),
            "cannot write uploads/ab12.nii.gz");
  EXPECT_EQ(server::spool_relative("cannot create /mnt/shared/jobs/ab/out-1 now"),
            "cannot create jobs/ab/out-1 now");
  EXPECT_EQ(server::spool_relative("cannot read the free space of /var/lib/labelmesh"),
            "cannot read the free space of labelmesh");
  EXPECT_EQ(server::spool_relative("no path here"), "no path here");
  const absl::Status full = server::spool_io_error("cannot write /srv/spool/jobs/x/job.pb", ENOSPC);
  EXPECT_THAT(full, testing::StatusIs(absl::StatusCode::kResourceExhausted));
  EXPECT_TRUE(absl::StartsWith(full.message(), "spool disk full: cannot write jobs/x/job.pb"))
      << full;
  EXPECT_FALSE(absl::StrContains(full.message(), "/srv")) << full;
  const absl::Status other = server::spool_io_error("cannot sync /srv/spool/uploads/u", EIO);
  EXPECT_THAT(other, testing::StatusIs(absl::StatusCode::kInternal));
  EXPECT_FALSE(absl::StrContains(other.message(), "/srv")) << other;
}

}  // namespace
}  // namespace labelmesh
