#!/usr/bin/python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""Fault drills of labelmeshd as a cluster on loopback: one nats-server, two
frontends and two workers, each its own process, sharing one artifact
directory. Checks that jobs of mixed sizes all finish with the outputs of
single-node mode; that any frontend watches, fetches and cancels any job; that
a retried Submit makes one job; that a worker killed (kill -9) or frozen
mid-job loses nothing and ends the job once; that a frontend killed mid-upload
costs only a retry; and that queued jobs outlive a NATS restart. Exits
non-zero with a message on the first failed check."""

import argparse
import glob
import hashlib
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from cluster_harness import (ABANDONED_UPLOAD_AGE, CALL_SECONDS, READY_SECONDS, CheckFailed,
                             Cluster, Processes, check, free_port, kinds, requests, spec_for,
                             submit, wait_for, watch)


def artifact_digests(pb, stub, job_id):
    """sha256 of every artifact fetched, by name (the reports, which hold
    timings and the time they were made, aside)."""
    digests = {}
    for artifact in stub.ListArtifacts(pb.ListArtifactsRequest(job_id=job_id),
                                       timeout=CALL_SECONDS).artifacts:
        content = b"".join(chunk.data for chunk in stub.Fetch(
            pb.FetchRequest(job_id=job_id, artifact=artifact.name), timeout=CALL_SECONDS))
        check(hashlib.sha256(content).hexdigest() == artifact.sha256,
              f"{artifact.name} of {job_id}: fetched bytes do not match its sha256")
        if artifact.name not in ("report.json", "report.html"):
            digests[artifact.name] = artifact.sha256
    return digests


def worker_running(job_id):
    """The pid of the labelmeshd whose labelmesh-worker child runs `job_id`."""
    name = f"lmw-{job_id[:11]}"
    for comm in glob.glob("/proc/[0-9]*/comm"):
        try:
            if open(comm).read().strip() != name:
                continue
            status = open(comm.replace("comm", "status")).read()
        except OSError:
            continue
        for line in status.splitlines():
            if line.startswith("PPid:"):
                return int(line.split()[1])
    return None


def node_of_pid(cluster, pid):
    for name, process in cluster.processes.running.items():
        if process.pid == pid:
            return name
    return None


def attempt_dirs(cluster, job_id):
    return sorted(os.path.basename(p)
                  for p in glob.glob(os.path.join(cluster.artifacts, "jobs", job_id, "out-*")))


def drill_mixed_jobs(cluster, pb, options_pb, volumes, single_node):
    """20 jobs through alternate frontends, each watched and fetched through
    the other; outputs as single-node mode made them."""
    submitted = []
    for i in range(20):
        path = volumes[i % len(volumes)]
        front, other = ("frontend-1", "frontend-2") if i % 2 == 0 else ("frontend-2", "frontend-1")
        reply = submit(pb, options_pb, cluster.stub(front), path)
        submitted.append((reply.job_id, path, other))
    for job_id, path, other in submitted:
        events = watch(pb, cluster.stub(other), job_id)
        check(kinds(events)[-1] == "finished", f"job {job_id} ended {kinds(events)}")
        check(kinds(events).count("finished") == 1, f"job {job_id}: {kinds(events)}")
        digests = artifact_digests(pb, cluster.stub(other), job_id)
        check(digests == single_node[path],
              f"{os.path.basename(path)}: cluster outputs differ from single-node mode: "
              f"{sorted(set(digests.items()) ^ set(single_node[path].items()))}")
    print(f"20 jobs of {len(volumes)} volumes: all finished, outputs as in single-node mode")


def drill_cancel_across(cluster, pb, options_pb, big):
    running = submit(pb, options_pb, cluster.stub("frontend-1"), big, volume=True).job_id
    queued = [submit(pb, options_pb, cluster.stub("frontend-1"), big, volume=True).job_id
              for _ in range(2)]
    wait_for(lambda: worker_running(running), "the first job to run")
    job = cluster.stub("frontend-2").Cancel(pb.CancelRequest(job_id=running), timeout=CALL_SECONDS)
    check(job.state == pb.JOB_STATE_RUNNING, f"cancel of a running job: {job.state}")
    events = watch(pb, cluster.stub("frontend-2"), running)
    check(kinds(events)[-1] == "cancelled", f"cancelled running job ended {kinds(events)}")
    for job_id in queued:
        try:
            cluster.stub("frontend-2").Cancel(pb.CancelRequest(job_id=job_id),
                                              timeout=CALL_SECONDS)
        except cluster.grpc.RpcError as error:  # it ended meanwhile
            check(error.code() == cluster.grpc.StatusCode.FAILED_PRECONDITION, str(error))
        events = watch(pb, cluster.stub("frontend-1"), job_id)
        check(kinds(events)[-1] in ("cancelled", "finished"), f"{job_id} ended {kinds(events)}")
    print("cancel through the other frontend: running and queued jobs end")


def drill_duplicate_request(cluster, pb, options_pb, small):
    first = submit(pb, options_pb, cluster.stub("frontend-1"), small, request_id="drill-dup")
    again = submit(pb, options_pb, cluster.stub("frontend-2"), small, request_id="drill-dup")
    check(not first.existing and again.existing and again.job_id == first.job_id,
          f"a retried request_id made another job: {first} / {again}")
    watch(pb, cluster.stub("frontend-2"), first.job_id)
    print("a Submit retried through the other frontend gives the same job")


def drill_kill_worker(cluster, pb, options_pb, big):
    job_id = submit(pb, options_pb, cluster.stub("frontend-1"), big, volume=True).job_id
    pid = wait_for(lambda: worker_running(job_id), "the job to start")
    # Any frontend tells a running job's stage, from its newest event.
    stub = cluster.stub("frontend-2")
    running = wait_for(lambda: (lambda job: job if job.stage else None)(
        stub.GetJob(pb.GetJobRequest(job_id=job_id))), "a running job's stage")
    check(running.state == pb.JOB_STATE_RUNNING, f"GetJob of a running job: {running.state}")
    victim = node_of_pid(cluster, pid)
    check(victim in ("worker-1", "worker-2"), f"job runs under {pid}, not a worker")
    cluster.processes.stop(victim, signal.SIGKILL)
    events = watch(pb, cluster.stub("frontend-2"), job_id)
    check(kinds(events).count("finished") == 1 and kinds(events)[-1] == "finished",
          f"after kill -9 of {victim}: {kinds(events)}")
    attempts = [event.started.attempt for event in events if event.HasField("started")]
    check(attempts == [1, 2], f"attempts started {attempts}, expected [1, 2]")
    # The winner cleans up just after it records the end.
    wait_for(lambda: attempt_dirs(cluster, job_id) == ["out-2"],
             f"attempt 1's files to go; left: {attempt_dirs(cluster, job_id)}", seconds=60)
    cluster.start_node(victim, "worker")
    print(f"kill -9 of {victim} mid-job: attempt 2 finished it, one finished event, only out-2")


def drill_frozen_worker(cluster, pb, options_pb, big):
    job_id = submit(pb, options_pb, cluster.stub("frontend-2"), big, volume=True).job_id
    pid = wait_for(lambda: worker_running(job_id), "the job to start")
    frozen = node_of_pid(cluster, pid)
    cluster.processes.send(frozen, signal.SIGSTOP)
    try:
        stub = cluster.stub("frontend-1")
        wait_for(lambda: stub.GetJob(pb.GetJobRequest(job_id=job_id)).attempts == 2,
                 "the job to go to the other worker")
        events = watch(pb, stub, job_id)
    finally:
        cluster.processes.send(frozen, signal.SIGCONT)
    # The frozen worker wakes to a job another attempt ended: its result is
    # refused and its files go, and nothing else changes.
    wait_for(lambda: attempt_dirs(cluster, job_id) == ["out-2"],
             f"attempt 1's files to go; left: {attempt_dirs(cluster, job_id)}", seconds=120)
    job = cluster.stub("frontend-1").GetJob(pb.GetJobRequest(job_id=job_id))
    after = watch(pb, cluster.stub("frontend-1"), job_id)
    check(job.state == pb.JOB_STATE_SUCCEEDED and job.attempts == 2,
          f"after the frozen worker woke: {pb.JobState.Name(job.state)}, attempts {job.attempts}")
    check(kinds(after).count("finished") == 1 and len(after) == len(events),
          f"events changed after the stale worker woke: {kinds(events)} -> {kinds(after)}")
    print(f"{frozen} frozen mid-job: attempt 2 finished; its late result was refused")


def drill_kill_frontend_mid_upload(cluster, pb, options_pb, big):
    data = open(big, "rb").read()
    spec = spec_for(pb, options_pb, big, data, request_id="drill-upload")
    reached, release = threading.Event(), threading.Event()

    def pause():
        reached.set()
        release.wait(10)

    failure = []

    def upload():
        try:
            cluster.stub("frontend-1").Submit(requests(pb, spec, data, pause), timeout=CALL_SECONDS)
        except cluster.grpc.RpcError as error:
            failure.append(error.code())

    thread = threading.Thread(target=upload)
    thread.start()
    check(reached.wait(CALL_SECONDS), "the upload did not start")
    uploads = os.path.join(cluster.artifacts, "uploads")
    wait_for(lambda: os.listdir(uploads), "the partial upload", CALL_SECONDS)
    cluster.processes.stop("frontend-1", signal.SIGKILL)
    partial = [os.path.join(uploads, name) for name in os.listdir(uploads)]
    check(len(partial) == 1, f"the killed frontend's partial upload: {partial}")
    sweep = UploadSweep(partial[0])
    release.set()
    thread.join()
    check(failure == [cluster.grpc.StatusCode.UNAVAILABLE], f"the cut upload ended {failure}")
    stub = cluster.stub("frontend-2")
    retried = stub.Submit(requests(pb, spec, data), timeout=CALL_SECONDS)
    again = stub.Submit(requests(pb, spec, data), timeout=CALL_SECONDS)
    check(not retried.existing and again.existing and again.job_id == retried.job_id,
          f"retries after the frontend died: {retried} / {again}")
    events = watch(pb, stub, retried.job_id)
    check(kinds(events)[-1] == "finished", f"the retried job ended {kinds(events)}")
    listed = [job.job_id for job in stub.ListJobs(pb.ListJobsRequest(page_size=1000)).jobs]
    check(listed.count(retried.job_id) == 1, "the retried request is listed more than once")
    cluster.start_node("frontend-1", "frontend")
    print("kill -9 of a frontend mid-upload: the retry through the other made one job")
    return sweep


class UploadSweep:
    """Watches one file from beside the drills: its last change and when it went."""

    def __init__(self, path):
        self.path, self.gone_at = path, None
        self.changed_at = os.stat(path).st_mtime
        self.thread = threading.Thread(target=self.watch, daemon=True)
        self.thread.start()

    def watch(self):
        deadline = time.time() + 120
        while self.gone_at is None and time.time() < deadline:
            try:
                self.changed_at = os.stat(self.path).st_mtime
            except FileNotFoundError:
                self.gone_at = time.time()
            time.sleep(0.2)


def drill_abandoned_upload_swept(sweep):
    """The partial upload goes once unchanged for the abandoned-upload age, not before."""
    age = float(ABANDONED_UPLOAD_AGE.rstrip("s"))
    sweep.thread.join()
    check(sweep.gone_at is not None, "the killed frontend's partial upload was never swept")
    unchanged = sweep.gone_at - sweep.changed_at
    # Housekeeping looks every 2 s; the watch every 0.2 s.
    check(age - 0.5 <= unchanged <= age + 10,
          f"partial upload swept {unchanged:.1f} s after its last change (age {age:.0f} s)")
    print(f"the killed frontend's partial upload was swept {unchanged:.1f} s after its last change")


def drill_nats_restart(cluster, pb, options_pb, small):
    for worker in ("worker-1", "worker-2"):
        cluster.processes.stop(worker)
    queued = [submit(pb, options_pb, cluster.stub("frontend-1"), small).job_id for _ in range(3)]
    cluster.processes.stop("nats")
    cluster.start_nats()
    for worker in ("worker-1", "worker-2"):
        cluster.start_node(worker, "worker")
    stub = cluster.stub("frontend-2")
    for job_id in queued:
        # The frontends' NATS connections come back on their own.
        events = wait_for(lambda: try_watch(cluster, pb, stub, job_id), "a watch after the restart")
        check(kinds(events)[-1] == "finished", f"{job_id} after the NATS restart: {kinds(events)}")
    print("NATS restarted with 3 jobs queued: all 3 finished")


def try_watch(cluster, pb, stub, job_id):
    try:
        return watch(pb, stub, job_id)
    except cluster.grpc.RpcError as error:
        if error.code() != cluster.grpc.StatusCode.UNAVAILABLE:
            raise
        time.sleep(0.5)
        return None


def single_node_outputs(args, tmp, grpc, pb, options_pb, stubs, volumes):
    """Each volume's artifact digests from labelmeshd --role all."""
    processes = Processes(tmp)
    address = f"127.0.0.1:{free_port()}"
    processes.start("single-node", [args.labelmeshd, "--listen", address, "--spool-dir",
                                     os.path.join(tmp, "single-node"), "--workers", "1",
                                     "--spool-reserve-bytes", str(16 << 20)])
    try:
        with grpc.insecure_channel(address) as channel:
            grpc.channel_ready_future(channel).result(timeout=READY_SECONDS)
            stub = stubs.MeshingServiceStub(channel)
            outputs = {}
            for path in volumes:
                job_id = submit(pb, options_pb, stub, path).job_id
                check(kinds(watch(pb, stub, job_id))[-1] == "finished", f"single-node {path}")
                outputs[path] = artifact_digests(pb, stub, job_id)
            return outputs
    finally:
        processes.stop_all()


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--labelmeshd", required=True)
    parser.add_argument("--labelmesh", required=True, help="CLI binary, for the phantoms")
    parser.add_argument("--python-api", required=True, help="dir holding labelmesh/v1/*_pb2*.py")
    args = parser.parse_args()
    sys.path.insert(0, args.python_api)
    import grpc
    from labelmesh.v1 import options_pb2 as options_pb, service_pb2 as pb, service_pb2_grpc

    with tempfile.TemporaryDirectory(prefix="labelmesh-cluster-") as tmp:
        volumes = []
        for shape, scale in [("sphere", 0.5), ("torus", 0.75), ("boxes", 1), ("nested-spheres", 1),
                             ("oblique-ellipsoid", 1.5)]:
            path = os.path.join(tmp, f"{shape}-{scale}.nii.gz")
            subprocess.run([args.labelmesh, "phantom", shape, "--scale", str(scale), "--out", path],
                           check=True, stdout=subprocess.DEVNULL)
            volumes.append(path)
        big = os.path.join(tmp, "big.nii")  # uncompressed: an upload of several chunks
        subprocess.run([args.labelmesh, "phantom", "nested-spheres", "--scale", "1.5", "--out",
                        big], check=True, stdout=subprocess.DEVNULL)

        cluster = Cluster(args, tmp, grpc, pb, service_pb2_grpc)
        failure = None
        try:
            single_node = single_node_outputs(args, tmp, grpc, pb, options_pb, service_pb2_grpc,
                                              volumes)
            cluster.start_nats()
            for name, role in [("frontend-1", "frontend"), ("frontend-2", "frontend"),
                               ("worker-1", "worker"), ("worker-2", "worker")]:
                cluster.start_node(name, role)
            drill_duplicate_request(cluster, pb, options_pb, volumes[0])
            drill_mixed_jobs(cluster, pb, options_pb, volumes, single_node)
            drill_cancel_across(cluster, pb, options_pb, big)
            drill_kill_worker(cluster, pb, options_pb, big)
            drill_frozen_worker(cluster, pb, options_pb, big)
            sweep = drill_kill_frontend_mid_upload(cluster, pb, options_pb, big)
            drill_nats_restart(cluster, pb, options_pb, volumes[0])
            drill_abandoned_upload_swept(sweep)
            for name in ["frontend-1", "frontend-2", "worker-1", "worker-2"]:
                code = cluster.processes.stop(name)
                check(code == 0, f"{name} exit code after SIGTERM: {code}")
        except (CheckFailed, grpc.RpcError) as error:
            failure = error
        finally:
            logs = {name: cluster.processes.tail(name) for name in
                    ["frontend-1", "frontend-2", "worker-1", "worker-2", "nats"]}
            cluster.processes.stop_all()
        if failure is not None:
            print(f"FAILED: {failure}", file=sys.stderr)
            for name, tail in logs.items():
                print(f"--- {name} (last lines) ---\n{tail}", file=sys.stderr)
            return 1
    print("PASSED")
    return 0


if __name__ == "__main__":
    sys.exit(main())
