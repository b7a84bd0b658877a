#!/usr/bin/python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""Includes follow the layers docs/architecture.md draws: util and digest
include nothing above them, the stage folders never include the pipeline,
the server (but its worker) only the job checks, the client never the
server, and neither links CGAL, VTK or TetGen headers directly. Prints each
include that breaks a rule, with its file and line."""

import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')

STAGES = ["volume", "surface", "volume_mesh", "quality", "mixed_mesh", "conforming", "dicom"]
# What the serving process may include of core: the job checks (options,
# volume headers), the digest and the status macros. labelmesh-worker
# (worker_main.cc) runs the whole pipeline.
SERVER_CORE = re.compile(r"^core/(digest/|util/status_macros\.h|pipeline/job_options\.h|"
                         r"pipeline/mesh_params\.h|"
                         r"volume/(image_geometry|volume_header|header_checks)\.h)")
HEAVY = re.compile(r"^(CGAL/|vtk|tetgen\.h)")


def includes(path):
    for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
        match = INCLUDE.match(line)
        if match:
            yield number, match.group(1), match.group(2)


def broken_rules(path):
    relative = path.relative_to(ROOT).as_posix()
    folder = relative.split("/")
    for number, bracket, target in includes(path):
        why = None
        if bracket == '"' and target.startswith("core/"):
            layer = target.split("/")[1]
            if folder[:2] in (["core", "util"], ["core", "digest"]) and layer != folder[1]:
                why = f"core/{folder[1]} includes nothing above it"
            elif folder[0] == "core" and folder[1] in STAGES and layer == "pipeline":
                why = "a stage never includes the pipeline above it"
            elif (folder[0] == "server" and relative != "server/worker_main.cc"
                  and not SERVER_CORE.match(target)):
                why = "the server links only core's job checks and digest"
        if bracket == '"' and folder[0] == "client" and target.startswith("server/"):
            why = "the client never includes the server"
        if folder[0] in ("server", "client") and HEAVY.match(target):
            why = "the server and client reach CGAL, VTK and TetGen only through core"
        if why:
            yield f"{relative}:{number}: #include {target}: {why}"


def main():
    files = [p for folder in ("core", "server", "client") for p in (ROOT / folder).rglob("*")
             if p.suffix in (".h", ".cc")]
    problems = [problem for path in sorted(files) for problem in broken_rules(path)]
    for problem in problems:
        print(problem)
    print(f"{len(files)} files read, {len(problems)} includes across the layers")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
