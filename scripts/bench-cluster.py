#!/usr/bin/python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""Cluster benchmark on loopback: job throughput and start latency of
labelmeshd as one process (--role all, --workers 2) beside the same work
through NATS JetStream (a frontend and workers: one worker process with two
slots, and two worker processes with one each). The three run in turn, round
after round, so that the machine's drift falls on all alike. Prints figures
only; fails only when a server or a job breaks.

Usage: scripts/bench-cluster.py [--bin build/dev] [--rounds 3] [--jobs 40]"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "server"))

from cluster_harness import Cluster, check, submit, watch  # noqa: E402

LATENCY_SAMPLES = 10


def one_job_latencies(pb, options_pb, stub, volume, surface):
    """For jobs sent one at a time to an idle service: seconds from queued to
    started by the events' own times, and from the Submit reply to the
    started event reaching a client that watches at once."""
    logged, seen = [], []
    for _ in range(LATENCY_SAMPLES):
        job_id = submit(pb, options_pb, stub, volume, surface=surface).job_id
        replied = time.monotonic()
        events = []
        for event in stub.Watch(pb.WatchRequest(job_id=job_id), timeout=300):
            if event.HasField("started"):
                seen.append(time.monotonic() - replied)
            events.append(event)
        times = {event.WhichOneof("event"): event.time for event in events}
        check("finished" in times, f"a latency job ended {list(times)}")
        logged.append(times["started"] - times["queued"])
    return statistics.median(logged), statistics.median(seen)


def throughput(pb, options_pb, stub, volume, surface, jobs):
    """Jobs per second for `jobs` submitted at once, to the last one's end."""
    begin = time.monotonic()
    ids = [submit(pb, options_pb, stub, volume, surface=surface).job_id for _ in range(jobs)]
    for job_id in ids:
        events = watch(pb, stub, job_id)
        check(events[-1].HasField("finished"), f"job {job_id} did not finish")
    return jobs / (time.monotonic() - begin)


def run_mode(mode, args, tmp, grpc, pb, options_pb, stubs, volume):
    cluster = Cluster(args, os.path.join(tmp, mode), grpc, pb, stubs)
    os.makedirs(cluster.tmp)
    try:
        if mode == "single-node":
            cluster.start_node("all", "all", workers=2)
            front = "all"
        else:
            cluster.start_nats()
            cluster.start_node("frontend", "frontend")
            if mode == "cluster 1x2":
                cluster.start_node("worker", "worker", workers=2)
            else:
                cluster.start_node("worker-1", "worker")
                cluster.start_node("worker-2", "worker")
            front = "frontend"
        stub = cluster.stub(front)
        latency = one_job_latencies(pb, options_pb, stub, volume, args.surface)
        return latency, throughput(pb, options_pb, stub, volume, args.surface, args.jobs)
    finally:
        cluster.processes.stop_all()


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--bin", default=os.path.join(ROOT, "build", "dev"))
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--jobs", type=int, default=40)
    parser.add_argument("--scale", default="1", help="of the sphere phantom each job meshes")
    parser.add_argument("--surface", choices=["poisson", "repaired"], default="poisson")
    args = parser.parse_args()
    args.labelmeshd = os.path.join(args.bin, "server", "labelmeshd")
    args.labelmesh = os.path.join(args.bin, "client", "labelmesh")
    sys.path.insert(0, os.path.join(args.bin, "python"))
    import grpc
    from labelmesh.v1 import options_pb2 as options_pb, service_pb2 as pb, service_pb2_grpc

    modes = ["single-node", "cluster 1x2", "cluster 2x1"]
    figures = {mode: [] for mode in modes}
    with tempfile.TemporaryDirectory(prefix="labelmesh-bench-cluster-") as tmp:
        volume = os.path.join(tmp, "sphere.nii.gz")
        subprocess.run([args.labelmesh, "phantom", "sphere", "--scale", args.scale, "--out", volume],
                       check=True, stdout=subprocess.DEVNULL)
        for round_number in range(args.rounds):
            for mode in modes:
                run_dir = os.path.join(tmp, f"round{round_number}")
                os.makedirs(run_dir, exist_ok=True)
                latency, rate = run_mode(mode, args, run_dir, grpc, pb, options_pb,
                                         service_pb2_grpc, volume)
                figures[mode].append((latency, rate))
                print(f"round {round_number + 1} {mode:12s} start latency median "
                      f"{latency[0] * 1000:6.1f} ms logged, {latency[1] * 1000:6.1f} ms seen; "
                      f"{args.jobs} jobs at {rate:5.2f} jobs/s", flush=True)
    print(f"\nmedians over {args.rounds} rounds ({args.jobs} jobs of a sphere at scale "
          f"{args.scale}, {args.surface} surface; start latency of {LATENCY_SAMPLES} lone jobs, "
          f"queued to started as logged / Submit reply to started as seen by a watcher):")
    base = statistics.median(rate for _, rate in figures["single-node"])
    for mode in modes:
        logged = statistics.median(latency[0] for latency, _ in figures[mode])
        seen = statistics.median(latency[1] for latency, _ in figures[mode])
        rate = statistics.median(rate for _, rate in figures[mode])
        ratios = [r / s for (_, r), (_, s) in zip(figures[mode], figures["single-node"])]
        print(f"  {mode:12s} start latency {logged * 1000:5.1f} / {seen * 1000:5.1f} ms, "
              f"{rate:5.2f} jobs/s, "
              f"{rate / base * 100:5.1f} % of single-node (per round: "
              f"{', '.join(f'{r * 100:.0f} %' for r in ratios)})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
