// SPDX-License-Identifier: AGPL-3.0-or-later
// What a job's state means to its watchers, shared by the one-machine job
// table and the cluster's job states: whether a state is an end, and the
// event that tells where a job stands.
#pragma once

#include <cstdint>

#include "labelmesh/v1/service.pb.h"

namespace labelmesh::server {

// Seconds since 1970, UTC.
double unix_now();

bool has_ended(v1::JobState state);

google::protobuf::Timestamp to_timestamp(double unix_seconds);

// The event that tells a watcher where a job stands: its end, started at
// its attempt while it runs, or queued at `position`.
v1::JobEvent state_event(const v1::Job& job, uint32_t position);

}  // namespace labelmesh::server
