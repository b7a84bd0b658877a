// SPDX-License-Identifier: AGPL-3.0-or-later
// How labelmeshd starts labelmesh-worker: the modes of its command line and
// the version line the server checks before it trusts the executable.
#pragma once

namespace labelmesh::server {

// The environment variable that tells a worker how many labels to mesh at
// once: the server's cores divided among its workers.
inline constexpr char kJobThreadsVariable[] = "LABELMESH_JOB_THREADS";

// The first argument of a worker started for a job.
inline constexpr char kWorkerMode[] = "--worker";
// `labelmesh-worker --check-volume FILE MAX_VOXELS`: reads the whole volume
// with the readers a job uses, writes why it cannot be read to descriptor 3,
// exits 0 if it can.
inline constexpr char kCheckVolumeMode[] = "--check-volume";
// What `labelmesh-worker --version` prints, and what the server expects.
inline constexpr char kWorkerVersionLine[] = "labelmesh-worker " LABELMESH_VERSION;

}  // namespace labelmesh::server
