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
import socket
import subprocess
import sys
import tempfile
import threading
import time

CHUNK_BYTES = 1 << 20
READY_SECONDS = 30
JOB_SECONDS = 300  # bounds a hang; small phantoms take seconds
CALL_SECONDS = 30
ACK_WAIT = "3s"  # a silent worker loses its job after this


class CheckFailed(Exception):
    pass


def check(condition, message):
    if not condition:
        raise CheckFailed(message)


def free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


class Processes:
    """Every process the drill starts, with its log; all stopped at the end."""

    def __init__(self, tmp):
        self.tmp = tmp
        self.running = {}
        # A caller's LABELMESHD_* variable must not change the servers.
        self.env = {k: v for k, v in os.environ.items() if not k.startswith("LABELMESHD_")}

    def start(self, name, argv):
        log = open(os.path.join(self.tmp, f"{name}.log"), "ab")
        self.running[name] = subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT,
                                              env=self.env)
        log.close()
        return self.running[name]

    def send(self, name, number):
        self.running[name].send_signal(number)

    def stop(self, name, number=signal.SIGTERM, timeout=60):
        process = self.running.pop(name)
        process.send_signal(number)
        try:
            return process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
            raise CheckFailed(f"{name} still running {timeout} s after signal {number}")

    def stop_all(self):
        for name in list(self.running):
            try:
                self.stop(name, signal.SIGKILL, timeout=10)
            except CheckFailed:
                pass

    def tail(self, name, lines=25):
        path = os.path.join(self.tmp, f"{name}.log")
        if not os.path.exists(path):
            return ""
        return "\n".join(open(path, errors="replace").read().splitlines()[-lines:])


class Cluster:
    def __init__(self, args, tmp, grpc, pb, stubs):
        self.args, self.tmp, self.grpc, self.pb, self.stubs = args, tmp, grpc, pb, stubs
        self.processes = Processes(tmp)
        self.nats_port = free_port()
        self.nats_url = f"nats://127.0.0.1:{self.nats_port}"
        self.artifacts = os.path.join(tmp, "artifacts")
        self.addresses = {}
        self.channels = {}

    def start_nats(self):
        self.processes.start("nats", [
            "nats-server", "-js", "-a", "127.0.0.1", "-p", str(self.nats_port),
            "-sd", os.path.join(self.tmp, "nats-store")])
        deadline = time.monotonic() + READY_SECONDS
        while time.monotonic() < deadline:
            try:
                socket.create_connection(("127.0.0.1", self.nats_port), timeout=1).close()
                return
            except OSError:
                time.sleep(0.1)
        raise CheckFailed("nats-server did not listen")

    def start_node(self, name, role, workers=1):
        if name not in self.addresses:
            self.addresses[name] = f"127.0.0.1:{free_port()}"
        argv = [self.args.labelmeshd, "--role", role, "--listen", self.addresses[name],
                "--nats-url", self.nats_url, "--artifact-dir", self.artifacts,
                "--spool-dir", os.path.join(self.tmp, name), "--workers", str(workers),
                "--cluster-ack-wait", ACK_WAIT, "--spool-reserve-bytes", str(16 << 20),
                "--shutdown-grace", "20s"]
        process = self.processes.start(name, argv)
        self.wait_serving(name, process)

    def wait_serving(self, name, process):
        deadline = time.monotonic() + READY_SECONDS
        while time.monotonic() < deadline:
            check(process.poll() is None,
                  f"{name} exited at start: {process.poll()}\n{self.processes.tail(name)}")
            health = subprocess.run([self.args.labelmesh, "health", "--server",
                                     self.addresses[name]], capture_output=True)
            if health.returncode == 0:
                self.channels[name] = self.grpc.insecure_channel(self.addresses[name])
                return
            time.sleep(0.1)
        raise CheckFailed(f"{name} not serving in {READY_SECONDS} s\n{self.processes.tail(name)}")

    def stub(self, name):
        return self.stubs.MeshingServiceStub(self.channels[name])


def spec_for(pb, options_pb, path, data, request_id="", volume=False):
    surface = options_pb.SURFACE_METHOD_POISSON if volume else options_pb.SURFACE_METHOD_REPAIRED
    options = options_pb.MeshOptions(surface=surface)
    if volume:
        options.volume = options_pb.VOLUME_METHOD_TETGEN
    return pb.JobSpec(options=options, file_name=os.path.basename(path), size_bytes=len(data),
                      sha256=hashlib.sha256(data).hexdigest(), request_id=request_id)


def requests(pb, spec, data, pause=None):
    yield pb.SubmitRequest(spec=spec)
    for start in range(0, len(data), CHUNK_BYTES):
        if pause is not None:
            pause()
        yield pb.SubmitRequest(chunk=data[start:start + CHUNK_BYTES])


def submit(pb, options_pb, stub, path, **kwargs):
    data = open(path, "rb").read()
    return stub.Submit(requests(pb, spec_for(pb, options_pb, path, data, **kwargs), data),
                       timeout=CALL_SECONDS)


def watch(pb, stub, job_id):
    return list(stub.Watch(pb.WatchRequest(job_id=job_id), timeout=JOB_SECONDS))


def kinds(events):
    return [event.WhichOneof("event") for event in events]


def artifact_digests(pb, stub, job_id):
    """sha256 of every artifact fetched, by name (report.json, which holds
    timings, aside)."""
    digests = {}
    for artifact in stub.ListArtifacts(pb.ListArtifactsRequest(job_id=job_id),
                                       timeout=CALL_SECONDS).artifacts:
        content = b"".join(chunk.data for chunk in stub.Fetch(
            pb.FetchRequest(job_id=job_id, artifact=artifact.name), timeout=CALL_SECONDS))
        check(hashlib.sha256(content).hexdigest() == artifact.sha256,
              f"{artifact.name} of {job_id}: fetched bytes do not match its sha256")
        if artifact.name != "report.json":
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


def wait_for(condition, what, seconds=JOB_SECONDS):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(0.05)
    raise CheckFailed(f"timed out waiting for {what}")


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
    victim = node_of_pid(cluster, pid)
    check(victim in ("worker-1", "worker-2"), f"job runs under {pid}, not a worker")
    cluster.processes.stop(victim, signal.SIGKILL)
    events = watch(pb, cluster.stub("frontend-2"), job_id)
    check(kinds(events).count("finished") == 1 and kinds(events)[-1] == "finished",
          f"after kill -9 of {victim}: {kinds(events)}")
    attempts = [event.started.attempt for event in events if event.HasField("started")]
    check(attempts == [1, 2], f"attempts started {attempts}, expected [1, 2]")
    check(attempt_dirs(cluster, job_id) == ["out-2"],
          f"attempt directories left: {attempt_dirs(cluster, job_id)}")
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
    cluster.processes.stop("frontend-1", signal.SIGKILL)
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
            drill_kill_frontend_mid_upload(cluster, pb, options_pb, big)
            drill_nats_restart(cluster, pb, options_pb, volumes[0])
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
