#!/usr/bin/python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""labelmeshd as a cluster on loopback, for the drills and the benchmark: a
nats-server, frontends and workers as processes with their logs, and the
calls a client makes."""

import hashlib
import os
import signal
import socket
import subprocess
import time

CHUNK_BYTES = 1 << 20
READY_SECONDS = 30
JOB_SECONDS = 300  # bounds a hang; small phantoms take seconds
CALL_SECONDS = 30
ACK_WAIT = "3s"  # a silent worker loses its job after this
ABANDONED_UPLOAD_AGE = "20s"  # a killed frontend's partial upload is swept after this


class CheckFailed(Exception):
    pass


def check(condition, message):
    # Not `assert`: these checks must also hold under `python3 -O`.
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
                "--shutdown-grace", "20s", "--stream-idle-timeout", "10s",
                "--abandoned-upload-age", ABANDONED_UPLOAD_AGE]
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


def spec_for(pb, options_pb, path, data, request_id="", volume=False, surface=None):
    """Repaired surfaces (quick) unless `volume` (Poisson and TetGen) or
    `surface` says otherwise."""
    if surface is None:
        surface = "poisson" if volume else "repaired"
    surface = {"poisson": options_pb.SURFACE_METHOD_POISSON,
               "repaired": options_pb.SURFACE_METHOD_REPAIRED}[surface]
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


def wait_for(condition, what, seconds=JOB_SECONDS):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(0.05)
    raise CheckFailed(f"timed out waiting for {what}")


