// SPDX-License-Identifier: AGPL-3.0-or-later
// Refusal marks: set where the reason is known, read back by the service
// without looking at messages, and never sent to the client.
#include "server/refusal.h"

#include <gtest/gtest.h>

#include <cerrno>
#include <set>
#include <string>

#include "core/util/status_macros.h"
#include "server/durable_file.h"
#include "server/error_details.h"
#include "server/stream_limits.h"
#include "server/upload_checks.h"
#include "support/status_matchers.h"

namespace labelmesh::server {
namespace {

absl::Status passes_on(const absl::Status& status) {
  LABELMESH_RETURN_IF_ERROR(status);
  return absl::OkStatus();
}

TEST(Refusal, EveryReasonHasItsOwnCodeAndComesBack) {
  std::set<std::string> codes;
  for (int i = 0; i <= static_cast<int>(Refusal::kAuthBackoff); ++i) {
    const auto why = static_cast<Refusal>(i);
    const std::string code(refusal_code(why));
    EXPECT_TRUE(codes.insert(code).second) << code;
    EXPECT_EQ(code.find_first_not_of("abcdefghijklmnopqrstuvwxyz_"), std::string::npos) << code;
    // Through a copy and an early return, with code and message unchanged.
    const absl::Status marked = passes_on(refused(why, absl::ResourceExhaustedError("full")));
    EXPECT_EQ(refusal_of(marked, Refusal::kBadRequest), why) << code;
    EXPECT_EQ(marked.code(), absl::StatusCode::kResourceExhausted);
    EXPECT_EQ(marked.message(), "full");
  }
  EXPECT_EQ(codes.size(), static_cast<size_t>(Refusal::kAuthBackoff) + 1);
}

TEST(Refusal, UnmarkedStatusesGiveTheFallback) {
  EXPECT_EQ(refusal_of(absl::InternalError("x"), Refusal::kSpoolError), Refusal::kSpoolError);
  EXPECT_EQ(refusal_of(absl::InternalError("x")), Refusal::kRefused);
  // OK holds no payload: marking it leaves it OK and unmarked.
  const absl::Status ok = refused(Refusal::kQueueFull, absl::OkStatus());
  EXPECT_THAT(ok, testing::IsOk());
  EXPECT_EQ(refusal_of(ok), Refusal::kRefused);
  // A later mark replaces an earlier one.
  const absl::Status twice =
      refused(Refusal::kBadVolume, refused(Refusal::kBadRequest, absl::InvalidArgumentError("x")));
  EXPECT_EQ(refusal_of(twice), Refusal::kBadVolume);
}

TEST(Refusal, TheClientHearsCodeAndMessageOnly) {
  const grpc::Status sent =
      to_grpc(refused(Refusal::kDiskFull, absl::ResourceExhaustedError("spool disk full: 0")));
  EXPECT_EQ(sent.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_EQ(sent.error_message(), "spool disk full: 0");
  EXPECT_EQ(sent.error_details().find("disk_full"), std::string::npos);
}

TEST(Refusal, TheLayersThatKnowWhyMarkTheirStatuses) {
  EXPECT_EQ(refusal_of(spool_io_error("jobs/x", ENOSPC)), Refusal::kDiskFull);
  EXPECT_EQ(refusal_of(spool_io_error("jobs/x", EDQUOT)), Refusal::kDiskFull);
  EXPECT_EQ(refusal_of(spool_io_error("jobs/x", EIO)), Refusal::kSpoolError);

  StreamCounts uploads({1, 5, 5}, "uploads", Refusal::kTooManyUploads);
  auto first = uploads.open("client", "host");
  ASSERT_THAT(first, testing::IsOk());
  auto second = uploads.open("client", "host");
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(refusal_of(second.status()), Refusal::kTooManyUploads);

  ServerConfig config;
  config.max_upload_bytes = 100;
  v1::JobSpec spec;
  spec.set_file_name("seg.nii.gz");
  spec.set_sha256(std::string(64, 'a'));
  spec.set_size_bytes(101);
  EXPECT_EQ(refusal_of(check_spec(spec, config).status()), Refusal::kTooLarge);
  spec.set_size_bytes(0);
  const absl::Status empty = check_spec(spec, config).status();
  EXPECT_EQ(empty.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(refusal_of(empty), Refusal::kRefused);
}

}  // namespace
}  // namespace labelmesh::server
