// SPDX-License-Identifier: AGPL-3.0-or-later
// The server's configuration rules and the small parts of its access control:
// loopback addresses, the clients file, backoff, audit lines, error details.
#include <gtest/gtest.h>

#include "google/rpc/status.pb.h"
#include "server/audit_log.h"
#include "server/client_identity.h"
#include "server/error_details.h"
#include "server/json_log_format.h"
#include "server/server_config.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::testing {
namespace {

using server::is_loopback_address;

TEST(LoopbackAddress, IsParsedNotMatchedAsText) {
  for (const char* address :
       {"127.0.0.1:50051", "127.1.2.3:1", "localhost:50051", "[::1]:50051", "ipv4:127.0.0.1:1",
        "ipv6:[::1]:1", "[::ffff:127.0.0.1]:1", "unix:/run/labelmeshd.sock"}) {
    EXPECT_TRUE(is_loopback_address(address)) << address;
  }
  for (const char* address :
       {"127.evil.example:50051", "127.0.0.1.nip.io:1", "0.0.0.0:50051", "[::]:50051",
        "10.0.0.7:50051", "[::ffff:10.0.0.1]:1", "localhost.example:1", "[::1:1", "1270.0.0.1:1"}) {
    EXPECT_FALSE(is_loopback_address(address)) << address;
  }
}

TEST(ServerConfigRules, ANonLoopbackAddressNeedsClientAuthenticationOrAllowAnonymous) {
  server::ServerConfig config;
  config.listen = "0.0.0.0:50051";
  config.tls_cert = "cert.pem";
  config.tls_key = "key.pem";
  auto status = server::validate_config(config);
  EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(status.message().find("--allow-anonymous"), std::string::npos) << status;
  config.allow_anonymous = true;
  EXPECT_THAT(server::validate_config(config), testing::IsOk());
  config.allow_anonymous = false;
  config.clients_file = "clients";
  EXPECT_THAT(server::validate_config(config), testing::IsOk());
  config.clients_file.clear();
  config.client_ca = "ca.pem";
  EXPECT_THAT(server::validate_config(config), testing::IsOk());
}

TEST(ServerConfigRules, NonLoopbackMetricsNeedAllowAnonymous) {
  server::ServerConfig config;
  config.metrics_listen = "0.0.0.0:9464";
  EXPECT_NE(server::validate_config(config).message().find("--metrics-listen"), std::string::npos);
  // Client tokens do not guard /metrics (plain HTTP): still refused.
  config.clients_file = "clients";
  EXPECT_NE(server::validate_config(config).message().find("--metrics-listen"), std::string::npos);
  config.clients_file.clear();
  config.allow_anonymous = true;
  EXPECT_THAT(server::validate_config(config), testing::IsOk());
  config.metrics_listen = "127.0.0.1:9464";
  config.allow_anonymous = false;
  EXPECT_THAT(server::validate_config(config), testing::IsOk());
}

TEST(ServerConfigRules, AbandonedUploadsOutliveEveryPauseOfALivingUpload) {
  server::ServerConfig config;
  config.stream_idle_timeout = absl::Minutes(3);  // a living upload may pause 3 minutes
  // One machine sweeps nothing: any idle timeout is fine there.
  EXPECT_THAT(server::validate_config(config), testing::IsOk());
  config.role = "frontend";
  config.nats_url = "nats://127.0.0.1:4222";
  config.artifact_dir = "/srv/labelmesh";
  auto status = server::validate_config(config);
  EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(status.message().find("--abandoned-upload-age"), std::string::npos) << status;
  config.abandoned_upload_age = absl::Minutes(6);
  EXPECT_THAT(server::validate_config(config), testing::IsOk());
  config.stream_idle_timeout = absl::Seconds(5);
  config.abandoned_upload_age = absl::Seconds(19);
  EXPECT_FALSE(server::validate_config(config).ok());
}

TEST(ClientsFile, ListsNamedTokensAndRefusesWhatIsAmbiguous) {
  const auto dir = scratch_dir("ClientsFile");
  const auto path = dir / "clients";
  write_file(path, "# comment\n\nalice a-token-0123456789ab\n  root r-token-0123456789ab admin \n");
  auto holders = server::read_clients_file(path.string());
  ASSERT_THAT(holders, testing::IsOk());
  ASSERT_EQ(holders->size(), 2u);
  EXPECT_EQ((*holders)[0].name, "alice");
  EXPECT_FALSE((*holders)[0].admin);
  EXPECT_EQ((*holders)[1].name, "root");
  EXPECT_TRUE((*holders)[1].admin);

  const std::pair<const char*, const char*> bad[] = {
      {"alice short\n", "16 to 256"},
      {"alice a-token-0123456789ab\nalice b-token-0123456789ab\n", "listed twice"},
      {"alice a-token-0123456789ab\nbob a-token-0123456789ab\n", "two clients"},
      {"al/ice a-token-0123456789ab\n", "the name"},
      {"alice a-token-0123456789ab root\n", "'admin'"},
      {"anonymous a-token-0123456789ab\n", "reserved"},
      {"alice a-token-0123456789ab\nbob short-token\n", "16 to 256"},
      {"# nobody\n", "no client"},
  };
  for (const auto& [text, why] : bad) {
    write_file(path, text);
    auto refused = server::read_clients_file(path.string());
    ASSERT_FALSE(refused.ok()) << text;
    EXPECT_NE(refused.status().message().find(why), std::string::npos) << refused.status();
    // The message never quotes a token.
    EXPECT_EQ(refused.status().message().find("token-0123"), std::string::npos);
  }
}

TEST(AuthBackoff, DoublesUpToTheLongestAndForgetsOnlyWithTime) {
  server::AuthBackoff backoff(2, absl::Seconds(1), absl::Seconds(3));
  const absl::Time t0 = absl::FromUnixSeconds(1'000'000);
  backoff.failed("ipv4:10.0.0.7", t0);
  EXPECT_THAT(backoff.check("ipv4:10.0.0.7", t0), testing::IsOk());
  backoff.failed("ipv4:10.0.0.7", t0);
  EXPECT_EQ(backoff.check("ipv4:10.0.0.7", t0).code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(backoff.check("ipv4:10.0.0.8", t0), testing::IsOk());
  EXPECT_THAT(backoff.check("ipv4:10.0.0.7", t0 + absl::Seconds(1)), testing::IsOk());
  backoff.failed("ipv4:10.0.0.7", t0);  // third: 2 s
  EXPECT_FALSE(backoff.check("ipv4:10.0.0.7", t0 + absl::Milliseconds(1900)).ok());
  EXPECT_THAT(backoff.check("ipv4:10.0.0.7", t0 + absl::Seconds(2)), testing::IsOk());
  for (int i = 0; i < 5; ++i) backoff.failed("ipv4:10.0.0.7", t0);  // capped at 3 s
  EXPECT_FALSE(backoff.check("ipv4:10.0.0.7", t0 + absl::Milliseconds(2900)).ok());
  EXPECT_THAT(backoff.check("ipv4:10.0.0.7", t0 + absl::Seconds(3)), testing::IsOk());
  // Failures are forgotten a while after the last one.
  const absl::Time later = t0 + server::AuthBackoff::kForgetAfter + absl::Seconds(1);
  backoff.failed("ipv4:10.0.0.7", later);
  EXPECT_THAT(backoff.check("ipv4:10.0.0.7", later), testing::IsOk());
  // IPv6 hosts count by their /64: stepping through it does not help.
  backoff.failed("ipv6:[2001:db8:1:2::10]", t0);
  backoff.failed("ipv6:%5B2001:db8:1:2::11%5D", t0);
  EXPECT_FALSE(backoff.check("ipv6:[2001:db8:1:2::12]", t0).ok());
  EXPECT_THAT(backoff.check("ipv6:[2001:db8:1:3::12]", t0), testing::IsOk());
}

TEST(AuditLine, IsOneJsonObjectWithEveryCharacterEscaped) {
  const std::string line = server::audit_json(
      {.event = "refused", .identity = "a\"b\\c", .peer = "ipv4:10.0.0.7", .reason = "x\ny\x01"},
      "2026-01-31T12:00:00.000Z");
  EXPECT_EQ(line,
            "{\"time\":\"2026-01-31T12:00:00.000Z\",\"event\":\"refused\",\"identity\":"
            "\"a\\\"b\\\\c\",\"peer\":\"ipv4:10.0.0.7\",\"reason\":\"x\\u000ay\\u0001\"}");
}

TEST(ErrorDetails, InvalidArgumentNamesTheFieldInABadRequest) {
  const grpc::Status status = server::to_grpc(
      absl::InvalidArgumentError("spec.options: max_edge_voxels: must be at least 0.5"));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  google::rpc::Status details;
  ASSERT_TRUE(details.ParseFromString(status.error_details()));
  ASSERT_EQ(details.details_size(), 1);
  google::rpc::BadRequest bad_request;
  ASSERT_TRUE(details.details(0).UnpackTo(&bad_request));
  ASSERT_EQ(bad_request.field_violations_size(), 1);
  EXPECT_EQ(bad_request.field_violations(0).field(), "spec.options.max_edge_voxels");
  EXPECT_EQ(bad_request.field_violations(0).description(), "must be at least 0.5");
  // "upload" names the request's bytes; a message that names no field has
  // no details, and other codes neither.
  EXPECT_FALSE(
      server::to_grpc(absl::InvalidArgumentError("upload: truncated")).error_details().empty());
  EXPECT_TRUE(
      server::to_grpc(absl::InvalidArgumentError("The header is bad: x")).error_details().empty());
  EXPECT_TRUE(server::to_grpc(absl::NotFoundError("spec.x: y")).error_details().empty());
}

TEST(JsonLogLine, CarriesTheJobIdAndEscapesTheMessage) {
  const std::string id = "0123456789abcdef0123456789abcdef";
  EXPECT_EQ(server::json_log_line("2026-01-31T12:00:00.000Z", "info",
                                  "job " + id + " stage \"repair\" finished"),
            "{\"time\":\"2026-01-31T12:00:00.000Z\",\"level\":\"info\",\"job_id\":\"" + id +
                "\",\"msg\":\"job " + id + " stage \\\"repair\\\" finished\"}\n");
  EXPECT_EQ(server::job_id_in("job 0123 and job " + id), id);
  EXPECT_EQ(server::job_id_in("jobs " + id), "");
  EXPECT_EQ(server::json_log_line("t", "warn", "a\nb"),
            "{\"time\":\"t\",\"level\":\"warn\",\"msg\":\"a\\u000ab\"}\n");
}

}  // namespace
}  // namespace labelmesh::testing
