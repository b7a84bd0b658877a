// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/metrics.h"

#include <CivetServer.h>
#include <prometheus/counter.h>
#include <prometheus/exposer.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>
#include <prometheus/text_serializer.h>

#include "absl/strings/str_cat.h"
#include "spdlog/spdlog.h"

namespace labelmesh::server {

using prometheus::Histogram;

struct Metrics::Families {
  prometheus::Family<prometheus::Gauge>& queue_depth;
  prometheus::Family<prometheus::Gauge>& queue_capacity;
  prometheus::Family<prometheus::Gauge>& running;
  prometheus::Family<prometheus::Counter>& jobs;
  prometheus::Family<Histogram>& queue_wait;
  prometheus::Family<Histogram>& stage_duration;
  prometheus::Family<prometheus::Counter>& rejections;
  prometheus::Family<prometheus::Counter>& upload_bytes;
  prometheus::Family<prometheus::Gauge>& spool_free_bytes;
  prometheus::Family<prometheus::Gauge>& spool_disk_pressure;
  prometheus::Family<prometheus::Counter>& spool_write_failures;
};

namespace {

// Seconds from 10 ms to about 45 minutes: queue waits and stage times alike.
Histogram::BucketBoundaries seconds_buckets() {
  return {0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10, 25, 50, 100, 250, 500, 1000, 2500};
}

}  // namespace

Metrics::Metrics(int queue_capacity) : registry_(std::make_shared<prometheus::Registry>()) {
  auto& r = *registry_;
  families_.reset(new Families{
      prometheus::BuildGauge()
          .Name("labelmesh_queue_depth")
          .Help("Jobs waiting to start")
          .Register(r),
      prometheus::BuildGauge()
          .Name("labelmesh_queue_capacity")
          .Help("Most jobs the queue holds")
          .Register(r),
      prometheus::BuildGauge().Name("labelmesh_jobs_running").Help("Jobs running now").Register(r),
      prometheus::BuildCounter()
          .Name("labelmesh_jobs_total")
          .Help("Jobs ended, by outcome")
          .Register(r),
      prometheus::BuildHistogram()
          .Name("labelmesh_queue_wait_seconds")
          .Help("Time from acceptance to start")
          .Register(r),
      prometheus::BuildHistogram()
          .Name("labelmesh_stage_duration_seconds")
          .Help("Pipeline stage durations, by stage")
          .Register(r),
      prometheus::BuildCounter()
          .Name("labelmesh_rejections_total")
          .Help("Submissions refused, by reason")
          .Register(r),
      prometheus::BuildCounter()
          .Name("labelmesh_upload_bytes_total")
          .Help("Bytes of accepted uploads")
          .Register(r),
      prometheus::BuildGauge()
          .Name("labelmesh_spool_free_bytes")
          .Help("Bytes still free on the spool's file system")
          .Register(r),
      prometheus::BuildGauge()
          .Name("labelmesh_spool_disk_pressure")
          .Help("1 while the spool's free space is under its reserve: no uploads accepted")
          .Register(r),
      prometheus::BuildCounter()
          .Name("labelmesh_spool_write_failures_total")
          .Help("Job records the spool could not save")
          .Register(r),
  });
  families_->queue_capacity.Add({}).Set(queue_capacity);
  families_->queue_depth.Add({}).Set(0);
  families_->running.Add({}).Set(0);
  families_->spool_disk_pressure.Add({}).Set(0);
  families_->spool_write_failures.Add({});
}

Metrics::~Metrics() = default;

absl::Status Metrics::expose(const std::string& address) {
  try {
    static CivetCallbacks callbacks = [] {
      CivetCallbacks c{};
      c.log_message = [](const mg_connection*, const char* message) {
        spdlog::warn("metrics endpoint: {}", message);
        return 1;
      };
      return c;
    }();
    exposer_ = std::make_unique<prometheus::Exposer>(address, 2, &callbacks);
  } catch (const std::exception& e) {
    return absl::InvalidArgumentError(
        absl::StrCat("--metrics-listen: cannot serve on ", address, ": ", e.what()));
  }
  exposer_->RegisterCollectable(registry_);
  return absl::OkStatus();
}

int Metrics::port() const {
  if (!exposer_) return 0;
  const auto ports = exposer_->GetListeningPorts();
  return ports.empty() ? 0 : ports.front();
}

std::string Metrics::text() const {
  return prometheus::TextSerializer().Serialize(registry_->Collect());
}

void Metrics::set_queue_depth(size_t depth) { families_->queue_depth.Add({}).Set(double(depth)); }

void Metrics::set_running(size_t running) { families_->running.Add({}).Set(double(running)); }

void Metrics::job_ended(const std::string& outcome) {
  families_->jobs.Add({{"outcome", outcome}}).Increment();
}

void Metrics::queue_wait(double seconds) {
  families_->queue_wait.Add({}, seconds_buckets()).Observe(seconds);
}

void Metrics::stage_finished(const std::string& stage, double seconds) {
  families_->stage_duration.Add({{"stage", stage}}, seconds_buckets()).Observe(seconds);
}

void Metrics::rejected(Refusal why) {
  families_->rejections.Add({{"reason", std::string(refusal_code(why))}}).Increment();
}

void Metrics::upload_bytes(uint64_t bytes) {
  families_->upload_bytes.Add({}).Increment(double(bytes));
}

void Metrics::set_spool_space(uint64_t free_bytes, bool under_reserve) {
  families_->spool_free_bytes.Add({}).Set(double(free_bytes));
  families_->spool_disk_pressure.Add({}).Set(under_reserve ? 1 : 0);
}

void Metrics::spool_write_failed() { families_->spool_write_failures.Add({}).Increment(); }

}  // namespace labelmesh::server
