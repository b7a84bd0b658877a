// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/job_store.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "server/spool.h"

namespace labelmesh::server {
namespace {

// Where a page of ListJobs ends: the last job's creation time (microseconds)
// and id, the order of the listing.
using ListPosition = std::pair<int64_t, std::string>;

ListPosition list_position(const v1::Job& job) {
  return {static_cast<int64_t>(std::llround(job.created_at() * 1e6)), job.job_id()};
}

std::string page_token(const ListPosition& position) {
  return absl::StrCat(position.first, "-", position.second);
}

std::optional<ListPosition> parse_page_token(std::string_view token) {
  const size_t dash = token.find('-');
  if (dash == std::string_view::npos) return std::nullopt;
  int64_t micros = 0;
  if (!absl::SimpleAtoi(std::string(token.substr(0, dash)), &micros)) return std::nullopt;
  const std::string_view id = token.substr(dash + 1);
  if (!is_job_id(id)) return std::nullopt;
  return ListPosition{micros, std::string(id)};
}

}  // namespace

v1::Job with_timestamps(v1::Job job) {
  if (job.created_at() > 0) *job.mutable_created_time() = to_timestamp(job.created_at());
  if (job.started_at() > 0) *job.mutable_started_time() = to_timestamp(job.started_at());
  if (job.finished_at() > 0) *job.mutable_finished_time() = to_timestamp(job.finished_at());
  return job;
}

absl::StatusOr<JobStore::JobPage> page_of(std::vector<v1::Job> jobs,
                                          const JobStore::JobQuery& query) {
  std::optional<ListPosition> after;
  if (!query.page_token.empty()) {
    after = parse_page_token(query.page_token);
    if (!after) return absl::InvalidArgumentError("page_token: not one a reply gave");
  }
  auto wanted = [&query](const v1::Job& job) {
    if (!query.owner.empty() && job.owner() != query.owner) return false;
    return query.states.empty() ||
           std::find(query.states.begin(), query.states.end(), job.state()) != query.states.end();
  };
  // Newest first; ties by id, so that every job has one place in the order.
  std::vector<std::pair<ListPosition, size_t>> order;
  for (size_t i = 0; i < jobs.size(); ++i) {
    if (!wanted(jobs[i])) continue;
    ListPosition position = list_position(jobs[i]);
    if (after && !(position < *after)) continue;
    order.emplace_back(std::move(position), i);
  }
  std::sort(order.begin(), order.end(),
            [](const auto& a, const auto& b) { return b.first < a.first; });
  JobStore::JobPage page;
  for (const auto& [position, index] : order) {
    if (page.jobs.size() == query.page_size) {
      page.next_page_token = page_token(list_position(page.jobs.back()));
      break;
    }
    v1::Job job = std::move(jobs[index]);
    job.clear_report();
    page.jobs.push_back(std::move(job));
  }
  return page;
}

}  // namespace labelmesh::server
