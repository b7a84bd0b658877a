#!/usr/bin/python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""Proves the labelmesh gRPC API usable from Python: starts labelmeshd, runs a
whole job on a sphere phantom (submit, watch, get, list, fetch), checks two
error statuses, and runs the README's client snippet as written. Exits
non-zero with a message on the first failed check."""

import argparse
import hashlib
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

CHUNK_BYTES = 1 << 20  # the API's largest upload and fetch chunk
READY_SECONDS = 20
JOB_SECONDS = 240  # far above a small phantom's few seconds; bounds a hang
CALL_SECONDS = 30
STOP_SECONDS = 40

# The harness the cluster drills share: checks that hold under `python3 -O`,
# free ports, the Submit stream.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cluster_harness import CheckFailed, check, free_port, requests  # noqa: E402


def sha256_hex(data):
    return hashlib.sha256(data).hexdigest()


def fetch_artifact(stub, pb, job_id, name):
    """Returns (header Artifact, bytes) of one artifact."""
    header, parts = None, []
    for index, chunk in enumerate(stub.Fetch(pb.FetchRequest(job_id=job_id, artifact=name),
                                             timeout=CALL_SECONDS)):
        check((index == 0) == chunk.HasField("artifact"),
              f"{name}: chunk {index} should {'' if index == 0 else 'not '}carry the artifact header")
        check(len(chunk.data) <= CHUNK_BYTES, f"{name}: chunk {index} is over 1 MiB")
        header = header or chunk.artifact
        parts.append(chunk.data)
    check(header is not None, f"{name}: Fetch sent no message")
    return header, b"".join(parts)


def wait_ready(grpc, channel, server, address):
    # Short waits in a loop, so a server that dies at start fails at once.
    ready = grpc.channel_ready_future(channel)
    deadline = time.monotonic() + READY_SECONDS
    while time.monotonic() < deadline:
        check(server.poll() is None, f"labelmeshd exited at start, code {server.poll()}")
        try:
            return ready.result(timeout=0.5)
        except grpc.FutureTimeoutError:
            pass
    raise CheckFailed(f"labelmeshd not ready on {address} in {READY_SECONDS} s")


def expect_status(grpc, code, call, what):
    try:
        call()
    except grpc.RpcError as error:
        check(error.code() == code, f"{what}: expected {code}, got {error.code()}: {error.details()}")
        return
    raise CheckFailed(f"{what}: expected {code}, the call succeeded")


def run_whole_job(pb, options_pb, stub, volume_path):
    data = open(volume_path, "rb").read()
    # Repaired Marching Cubes: closed and manifold with no Poisson parameters
    # in play; the API is under test here, not the mesher.
    options = options_pb.MeshOptions(surface=options_pb.SURFACE_METHOD_REPAIRED)
    spec = pb.JobSpec(options=options, file_name=os.path.basename(volume_path),
                      size_bytes=len(data), sha256=sha256_hex(data))
    reply = stub.Submit(requests(pb, spec, data), timeout=CALL_SECONDS)
    job_id = reply.job_id
    check(re.fullmatch(r"[0-9a-f]{32}", job_id), f"job id {job_id!r} is not 32 hex digits")

    events = list(stub.Watch(pb.WatchRequest(job_id=job_id), timeout=JOB_SECONDS))
    kinds = [event.WhichOneof("event") for event in events]
    check(all(event.job_id == job_id for event in events), "an event names another job")
    check("started" in kinds, f"no started event in {kinds}")
    check("stage_started" in kinds and "stage_finished" in kinds, f"no stage events in {kinds}")
    check(kinds and kinds[-1] == "finished", f"the last event is not finished: {kinds} "
          f"{events[-1] if events else ''}")
    report = events[-1].finished.report
    outputs = [surface for surface in report.surfaces if surface.output]
    check(len(outputs) == 1, f"expected one output surface, got {len(outputs)}")
    surface = outputs[0]
    check(surface.label == 1, f"output surface label {surface.label}, expected 1")
    check(surface.closed and surface.manifold, f"output surface not closed and manifold: {surface}")
    check(surface.nodes > 100, f"output surface has only {surface.nodes} nodes")

    job = stub.GetJob(pb.GetJobRequest(job_id=job_id), timeout=CALL_SECONDS)
    check(job.state == pb.JOB_STATE_SUCCEEDED, f"GetJob state {pb.JobState.Name(job.state)}")
    listed = stub.ListJobs(pb.ListJobsRequest(), timeout=CALL_SECONDS).jobs
    check(any(listed_job.job_id == job_id for listed_job in listed), "ListJobs misses the job")

    artifacts = stub.ListArtifacts(pb.ListArtifactsRequest(job_id=job_id),
                                   timeout=CALL_SECONDS).artifacts
    names = [artifact.name for artifact in artifacts]
    check("report.json" in names, f"no report.json in {names}")
    check(any(re.fullmatch(r"surface-label1\.\w+", name) for name in names),
          f"no surface-label1.* in {names}")
    fetched = {}
    for artifact in artifacts:
        header, content = fetch_artifact(stub, pb, job_id, artifact.name)
        check(header.name == artifact.name, f"Fetch of {artifact.name} names {header.name}")
        check(header.size_bytes == len(content) == artifact.size_bytes,
              f"{artifact.name}: {len(content)} bytes fetched, header says {header.size_bytes}, "
              f"list says {artifact.size_bytes}")
        check(header.sha256 == sha256_hex(content) == artifact.sha256,
              f"{artifact.name}: fetched bytes do not match the sha256 of the header or list")
        fetched[artifact.name] = content

    # report.json is the proto JSON form with proto names; false is left out.
    report_json = json.loads(fetched["report.json"])
    json_nodes = [s.get("nodes", 0) for s in report_json.get("surfaces", []) if s.get("output")]
    check(json_nodes == [surface.nodes], f"report.json output nodes {json_nodes}, "
          f"finished event {surface.nodes}")
    print(f"job {job_id}: {len(events)} events, {surface.nodes} output nodes, "
          f"artifacts {sorted(names)}")
    return data


def check_errors(grpc, pb, stub, data):
    spec = pb.JobSpec(file_name="sphere.nii.gz", size_bytes=len(data), sha256="0" * 64)
    expect_status(grpc, grpc.StatusCode.INVALID_ARGUMENT,
                  lambda: stub.Submit(requests(pb, spec, data), timeout=CALL_SECONDS),
                  "Submit with a wrong sha256")
    expect_status(grpc, grpc.StatusCode.NOT_FOUND,
                  lambda: stub.GetJob(pb.GetJobRequest(job_id="0" * 32), timeout=CALL_SECONDS),
                  "GetJob of an unknown job")


def readme_snippet():
    """The README's Python client, verbatim: the code block after "From Python"."""
    readme = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "README.md")
    text = open(readme).read()
    start = text.index("```python\n", text.index("From Python")) + len("```python\n")
    return text[start:text.index("```", start)]


def run_readme_snippet(python_api, volume_path, address, tmp):
    """Runs the README's client from a directory laid out like a checkout
    (build/release/python), and checks the files it fetched."""
    work = os.path.join(tmp, "readme")
    os.makedirs(os.path.join(work, "build", "release"))
    os.symlink(os.path.abspath(python_api), os.path.join(work, "build", "release", "python"))
    with open(os.path.join(work, "client.py"), "w") as out:
        out.write(readme_snippet())
    run = subprocess.run([sys.executable, "client.py", volume_path, address], cwd=work,
                         capture_output=True, text=True, timeout=JOB_SECONDS)
    check(run.returncode == 0, f"the README's client exited {run.returncode}: "
          f"{run.stdout[-2000:]}{run.stderr[-2000:]}")
    wrote = sorted(line.split(" ", 1)[1] for line in run.stdout.splitlines()
                   if line.startswith("wrote "))
    check("report.json" in wrote, f"the README's client fetched no report.json: {wrote}")
    check(any(name.endswith(".stl") for name in wrote), f"no .stl fetched: {wrote}")
    in_folders = [name for name in wrote if "/" in name]
    check(in_folders, f"no vtm block in a folder fetched: {wrote}")
    for name in wrote:
        check(os.path.getsize(os.path.join(work, name)) > 0, f"{name}: empty")
    print(f"README client: {len(wrote)} files, {len(in_folders)} in folders")


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--labelmeshd", required=True, help="server binary")
    parser.add_argument("--labelmesh", required=True, help="CLI binary, for the phantom")
    parser.add_argument("--python-api", required=True, help="dir holding labelmesh/v1/*_pb2*.py")
    args = parser.parse_args()
    sys.path.insert(0, args.python_api)
    import grpc
    from labelmesh.v1 import options_pb2 as options_pb, service_pb2 as pb, service_pb2_grpc

    with tempfile.TemporaryDirectory(prefix="labelmesh-python-") as tmp:
        volume_path = os.path.join(tmp, "sphere.nii.gz")
        subprocess.run([args.labelmesh, "phantom", "sphere", "--out", volume_path], check=True)
        address = f"127.0.0.1:{free_port()}"
        # A LABELMESHD_* variable of the caller (a token file, say) must not
        # change the server under test.
        env = {k: v for k, v in os.environ.items() if not k.startswith("LABELMESHD_")}
        log_path = os.path.join(tmp, "labelmeshd.log")
        with open(log_path, "wb") as log:
            server = subprocess.Popen(
                [args.labelmeshd, "--listen", address, "--spool-dir", os.path.join(tmp, "spool"),
                 "--spool-reserve-bytes", str(16 << 20), "--workers", "1"],
                stdout=log, stderr=subprocess.STDOUT, env=env)
        failure = None
        try:
            with grpc.insecure_channel(address) as channel:
                wait_ready(grpc, channel, server, address)
                stub = service_pb2_grpc.MeshingServiceStub(channel)
                data = run_whole_job(pb, options_pb, stub, volume_path)
                check_errors(grpc, pb, stub, data)
                run_readme_snippet(args.python_api, volume_path, address, tmp)
        except (CheckFailed, grpc.RpcError) as error:
            failure = error
        finally:
            server.send_signal(signal.SIGTERM)
            try:
                code = server.wait(timeout=STOP_SECONDS)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait()
                code = f"none: still running {STOP_SECONDS} s after SIGTERM, killed"
        if failure is None and code != 0:
            failure = CheckFailed(f"labelmeshd exit code after SIGTERM: {code}")
        if failure is not None:
            print(f"FAILED: {failure}", file=sys.stderr)
            print("--- labelmeshd log (last 40 lines) ---", file=sys.stderr)
            print("\n".join(open(log_path, errors="replace").read().splitlines()[-40:]),
                  file=sys.stderr)
            return 1
    print("PASSED")
    return 0


if __name__ == "__main__":
    sys.exit(main())
