// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/labelmesh_server.h"

#include "core/util/status_macros.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "server/audit_log.h"
#include "server/client_identity.h"
#include "server/cluster/cluster_job_store.h"
#include "server/cluster/cluster_worker_role.h"
#include "server/cluster/shared_artifacts.h"
#include "server/job_table.h"
#include "server/meshing_service.h"
#include "server/metrics.h"
#include "server/spool.h"
#include "server/worker_pool.h"
#include "server/worker_process.h"
#include "spdlog/spdlog.h"

namespace labelmesh::server {
namespace {

absl::StatusOr<std::string> read_text_file(const std::string& path, const std::string& flag) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::InvalidArgumentError(absl::StrCat("--", flag, ": cannot read ", path));
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> credentials(const ServerConfig& config) {
  if (!config.tls()) return grpc::InsecureServerCredentials();
  LABELMESH_ASSIGN_OR_RETURN(auto cert, read_text_file(config.tls_cert, "tls-cert"));
  LABELMESH_ASSIGN_OR_RETURN(auto key, read_text_file(config.tls_key, "tls-key"));
  grpc::SslServerCredentialsOptions options;
  options.pem_key_cert_pairs.push_back({key, cert});
  if (!config.client_ca.empty()) {
    LABELMESH_ASSIGN_OR_RETURN(auto ca, read_text_file(config.client_ca, "client-ca"));
    options.pem_root_certs = ca;
    options.client_certificate_request = GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  return grpc::SslServerCredentials(options);
}

// Serves the reflection service on this server or not. Linking gRPC's
// reflection library adds it to every server; this option takes it out.
class ReflectionOption : public grpc::ServerBuilderOption {
 public:
  explicit ReflectionOption(bool served) : served_(served) {}
  void UpdateArguments(grpc::ChannelArguments*) override {}
  void UpdatePlugins(std::vector<std::unique_ptr<grpc::ServerBuilderPlugin>>* plugins) override {
    const std::string name = grpc::reflection::ProtoServerReflectionPlugin().name();
    std::erase_if(*plugins, [&name](const auto& plugin) { return plugin->name() == name; });
    if (served_)
      plugins->push_back(std::make_unique<grpc::reflection::ProtoServerReflectionPlugin>());
  }

 private:
  const bool served_;
};

}  // namespace

absl::StatusOr<std::unique_ptr<LabelmeshServer>> LabelmeshServer::start(ServerConfig config) {
  LABELMESH_RETURN_IF_ERROR(validate_config(config));
  LABELMESH_RETURN_IF_ERROR(check_worker_version(worker_executable(config)));
  std::unique_ptr<LabelmeshServer> server(new LabelmeshServer());
  server->config_ = std::move(config);
  const ServerConfig& c = server->config_;

  LABELMESH_ASSIGN_OR_RETURN(auto authenticator, ClientAuthenticator::from_config(c));
  server->authenticator_ = std::move(authenticator);
  LABELMESH_ASSIGN_OR_RETURN(auto creds, credentials(c));

  server->metrics_ = std::make_unique<Metrics>(c.queue_capacity);
  if (!c.metrics_listen.empty()) {
    LABELMESH_RETURN_IF_ERROR(server->metrics_->expose(c.metrics_listen));
  }
  LABELMESH_RETURN_IF_ERROR(c.clustered() ? server->open_cluster() : server->open_spool());
  if (server->store_ != nullptr) {
    server->service_ = std::make_unique<MeshingService>(*server->store_, c, *server->metrics_,
                                                        *server->authenticator_, *server->audit_);
  }

  grpc::EnableDefaultHealthCheckService(true);
  grpc::ServerBuilder builder;
  // Reflection cannot check a caller: it is served only where every caller
  // is anonymous anyway. Health says only SERVING or not, for probes.
  builder.SetOption(std::make_unique<ReflectionOption>(server->authenticator_->anonymous()));
  builder.AddListeningPort(c.listen, creds, &server->port_);
  if (server->service_) builder.RegisterService(server->service_.get());
  builder.SetMaxReceiveMessageSize(c.max_message_bytes);
  builder.SetMaxSendMessageSize(c.max_message_bytes);
  server->server_ = builder.BuildAndStart();
  if (!server->server_ || server->port_ == 0) {
    return absl::UnavailableError(absl::StrCat("--listen: cannot serve on ", c.listen));
  }
  if (server->table_) {
    server->pool_ = std::make_unique<WorkerPool>(*server->table_, *server->spool_, c);
    server->pool_->start();
  }
  server->update_health();
  server->housekeeper_ = std::thread([s = server.get()] { s->housekeeping_loop(); });
  spdlog::info(
      "labelmeshd ({}) listening on {} (port {}), {} workers, queue capacity {}, TLS {}, "
      "clients {}",
      c.role, c.listen, server->port_, c.role == "frontend" ? 0 : c.workers, c.queue_capacity,
      c.tls() ? "on" : "off",
      !c.clients_file.empty()      ? "by token from the clients file"
      : !c.auth_token_file.empty() ? "by one shared token"
      : !c.client_ca.empty()       ? "by certificate"
                                   : "anonymous");
  return server;
}

absl::Status LabelmeshServer::open_spool() {
  const ServerConfig& c = config_;
  LABELMESH_ASSIGN_OR_RETURN(auto spool, Spool::open(c.spool_dir));
  spool_ = std::make_unique<Spool>(std::move(spool));
  kill_stale_workers(spool_->root());
  LABELMESH_ASSIGN_OR_RETURN(
      auto audit,
      AuditLog::open(c.audit_log.empty() ? spool_->root() + "/audit.log" : c.audit_log));
  audit_ = std::move(audit);
  table_ = std::make_unique<JobTable>(*spool_, c.queue_capacity, *metrics_);
  table_->recover(c.result_ttl);
  store_ = table_.get();
  return absl::OkStatus();
}

absl::Status LabelmeshServer::open_cluster() {
  const ServerConfig& c = config_;
  LABELMESH_ASSIGN_OR_RETURN(auto files, cluster::SharedArtifacts::open(c.artifact_dir));
  files_ = std::make_unique<cluster::SharedArtifacts>(std::move(files));
  cluster::ClusterSettings settings;
  settings.nats_url = c.nats_url;
  settings.connection_name = absl::StrCat("labelmeshd ", c.role);
  settings.queue.ack_wait = c.cluster_ack_wait;
  if (c.role == "worker") {
    LABELMESH_ASSIGN_OR_RETURN(auto workers,
                               ClusterWorkerRole::start(c, settings, *files_, *metrics_));
    cluster_workers_ = std::move(workers);
    return absl::OkStatus();
  }
  // The frontend keeps only its audit log locally.
  std::error_code error;
  std::filesystem::create_directories(c.spool_dir, error);
  LABELMESH_ASSIGN_OR_RETURN(
      auto audit, AuditLog::open(c.audit_log.empty() ? c.spool_dir + "/audit.log" : c.audit_log));
  audit_ = std::move(audit);
  LABELMESH_ASSIGN_OR_RETURN(auto connection, cluster::ClusterConnection::open(settings));
  cluster_ = std::move(connection);
  // Every run ends within the job timeout; a job RUNNING well past it (and
  // past the ack waits of its redeliveries) has lost its workers.
  const absl::Duration abandoned_after = c.job_timeout + 2 * c.cluster_ack_wait + absl::Minutes(1);
  cluster_store_ =
      std::make_unique<ClusterJobStore>(*cluster_, *files_, c.queue_capacity, abandoned_after);
  store_ = cluster_store_.get();
  return absl::OkStatus();
}

void LabelmeshServer::update_health() {
  auto* health = server_->GetHealthCheckService();
  // "liveness" answers while the process serves at all; the overall status
  // ("") says whether it should be sent work.
  health->SetServingStatus(kLivenessService, true);
  if (cluster_workers_) {
    health->SetServingStatus("", cluster_workers_->healthy());
    return;
  }
  auto free = store_->free_bytes();
  const bool under_reserve = !free.ok() || *free < config_.spool_reserve_bytes;
  metrics_->set_spool_space(free.ok() ? *free : 0, under_reserve);
  if (under_reserve != under_reserve_) {
    if (under_reserve) {
      spdlog::error("spool disk under its reserve ({} bytes free, reserve {}): not serving uploads",
                    free.ok() ? *free : 0, config_.spool_reserve_bytes);
    } else {
      spdlog::info("spool disk above its reserve again: serving");
    }
    under_reserve_ = under_reserve;
  }
  // A frontend still serves watches and fetches with the shared disk full
  // (uploads are refused one by one): it is ready while it reaches NATS.
  health->SetServingStatus("", cluster_store_ ? cluster_store_->connected() : !under_reserve);
}

void LabelmeshServer::housekeeping_loop() {
  const auto period =
      std::min(absl::ToChronoMilliseconds(config_.result_ttl), std::chrono::milliseconds(2'000));
  // The cluster's expiry reads every job's record from NATS: every 15th
  // round (30 s) is enough, where the job table's is a look in memory.
  const int expiry_rounds = cluster_store_ ? 15 : 1;
  // Locked and unlocked by hand: a cluster's calls may wait on NATS, and
  // shutdown must not.
  mutex_.Lock();
  for (int round = 0;
       !mutex_.AwaitWithTimeout(absl::Condition(&stopped_), absl::FromChrono(period)); ++round) {
    mutex_.Unlock();
    if (store_ != nullptr && round % expiry_rounds == 0) {
      for (const auto& id : store_->expire(config_.result_ttl, size_t(config_.max_ended_jobs))) {
        audit_->record({.event = "expired", .job_id = id, .identity = "labelmeshd"});
      }
    }
    if (cluster_store_) {
      cluster_store_->check_follows();
      if (auto stored = cluster_->queue->stored(); stored.ok()) metrics_->set_queue_depth(*stored);
      // A living upload changes at least every stream idle timeout; one that
      // has not changed for longer belonged to a frontend that was killed.
      (void)cluster_store_->remove_abandoned_uploads(config_.abandoned_upload_age);
    }
    update_health();
    mutex_.Lock();
  }
  mutex_.Unlock();
}

void LabelmeshServer::shutdown() {
  {
    absl::MutexLock lock(&mutex_);
    if (stopped_) return;
    stopped_ = true;
  }
  spdlog::info("shutting down: no new uploads or jobs; running jobs have {} s to finish",
               absl::ToDoubleSeconds(config_.shutdown_grace));
  if (!server_) return;  // start() failed half way: nothing runs yet.
  if (service_) service_->stop_accepting();
  if (pool_) {
    table_->stop_dispatch();
    pool_->drain(config_.shutdown_grace);
    table_->close();
  }
  if (cluster_workers_) cluster_workers_->drain(config_.shutdown_grace);
  if (cluster_store_) cluster_store_->close();
  server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
  if (pool_) pool_->join();
  if (housekeeper_.joinable()) housekeeper_.join();
  spdlog::info("labelmeshd stopped");
}

LabelmeshServer::~LabelmeshServer() { shutdown(); }

}  // namespace labelmesh::server
