#!/usr/bin/python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""Every include follows the build's links, read from CMake's code model (the
file API reply in the build directory): a file of target T includes only
project headers of T or of a target T links, directly or through others.
Also: each folder of core/ is one target, labelmesh_<folder>, with no files
elsewhere; the server and the client reach CGAL, VTK and TetGen only through
core. CMake's build order has no cycles (it drops a link that would close
one), so a cycle shows as an include across a missing link. Prints each break
with its file and line. The rules first run on a small made-up tree whose
breaks are known, so a checker that finds nothing fails.

Usage: layering_test.py BUILD_DIR"""

import json
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')
HEAVY = re.compile(r"^(CGAL/|vtk|tetgen\.h)")


def code_model(build):
    """Target name -> (its project source paths, names of the targets it
    depends on). Asks CMake to write the reply when it has not yet."""
    api = build / ".cmake" / "api" / "v1"
    query = api / "query" / "codemodel-v2"
    replies = api / "reply"
    if not query.exists():
        query.parent.mkdir(parents=True, exist_ok=True)
        query.touch()
    if not list(replies.glob("codemodel-v2-*.json")):
        subprocess.run(["cmake", str(build)], check=True, stdout=subprocess.DEVNULL)
    model = json.loads(next(replies.glob("codemodel-v2-*.json")).read_text())
    targets = {}
    for entry in model["configurations"][0]["targets"]:
        target = json.loads((replies / entry["jsonFile"]).read_text())
        sources = {s["path"] for s in target.get("sources", []) if is_project_file(s["path"], build)}
        depends = {d["id"].split("::")[0] for d in target.get("dependencies", [])
                   if not only_ordered_after(target, d)}
        targets[target["name"]] = (sources, depends)
    return targets


def only_ordered_after(target, dependency):
    """Whether `dependency` of `target` comes from add_dependencies (built
    first, not linked): such a target's headers are not the target's to use."""
    graph = target.get("backtraceGraph", {})
    node = dependency.get("backtrace")
    if node is None:
        return False
    command = graph["nodes"][node].get("command")
    return command is not None and graph["commands"][command] == "add_dependencies"


def is_project_file(path, build):
    """A file of the source tree, not one the build generates."""
    full = (ROOT / path).resolve()
    return full.is_file() and full.is_relative_to(ROOT) and not full.is_relative_to(build)


def reachable(targets, name):
    seen, stack = set(), list(targets[name][1])
    while stack:
        other = stack.pop()
        if other not in seen and other in targets:
            seen.add(other)
            stack.extend(targets[other][1])
    return seen


def owners(targets):
    """Project file -> the targets it belongs to: a source's own targets; a
    header, those of its .cc twin, else those with sources in its folder or
    the nearest folder above, when that is one target (several: none)."""
    by_source, by_folder = {}, {}
    for name, (sources, _) in targets.items():
        for source in sources:
            by_source.setdefault(source, set()).add(name)
            by_folder.setdefault(str(pathlib.PurePosixPath(source).parent), set()).add(name)

    def owner(path):
        if path in by_source:
            return by_source[path]
        twin = re.sub(r"\.h$", ".cc", path)
        if twin in by_source:
            return by_source[twin]
        folder = pathlib.PurePosixPath(path).parent
        while str(folder) != ".":
            names = by_folder.get(str(folder))
            if names:
                return names if len(names) == 1 else set()
            folder = folder.parent
        return set()

    return owner


def includes(text):
    for number, line in enumerate(text.splitlines(), 1):
        match = INCLUDE.match(line)
        if match:
            yield number, match.group(1), match.group(2)


def folder_problems(targets):
    for folder in sorted(p for p in (ROOT / "core").iterdir() if p.is_dir()):
        name = f"labelmesh_{folder.name}"
        if name not in targets:
            yield f"core/{folder.name}: no target {name}"
            continue
        for source in sorted(targets[name][0]):
            if not source.startswith(f"core/{folder.name}/"):
                yield f"{source}: in {name}, outside core/{folder.name}/"
        for source in sorted(folder.rglob("*.cc")):
            relative = source.relative_to(ROOT).as_posix()
            if relative not in targets[name][0]:
                yield f"{relative}: not in {name}"


def project_texts():
    """Path -> text of every C++ file of core/, server/, client/ and tests/."""
    return {p.relative_to(ROOT).as_posix(): p.read_text(errors="replace")
            for folder in ("core", "server", "client", "tests")
            for p in (ROOT / folder).rglob("*") if p.suffix in (".h", ".cc")}


def include_problems(targets, texts):
    owner = owners(targets)
    closure = {name: reachable(targets, name) for name in targets}
    for path in sorted(texts):
        mine = owner(path)
        top = path.split("/")[0]
        for number, bracket, included in includes(texts[path]):
            if top in ("server", "client") and HEAVY.match(included):
                yield (f"{path}:{number}: #include {included}: the server and client reach "
                       "CGAL, VTK and TetGen only through core")
            if bracket != '"' or included not in texts:
                continue
            theirs = owner(included)
            for name in sorted(mine):
                if theirs and not theirs & (closure[name] | {name}):
                    yield (f"{path}:{number}: #include {included}: {name} links none of "
                           f"{sorted(theirs)}")


def self_check():
    """The rules on a made-up tree: what they must find, and what not."""
    targets = {
        "low": ({"core/low/a.cc"}, set()),
        "mid": ({"core/mid/b.cc"}, {"low"}),
        "top": ({"core/top/c.cc"}, {"mid"}),
        "server": ({"server/s.cc"}, {"low"}),
    }
    texts = {
        "core/low/a.h": "",
        "core/low/a.cc": '#include "core/low/a.h"\n',
        "core/low/only_header.h": "",
        "core/mid/b.h": '#include "core/low/only_header.h"\n',
        "core/mid/b.cc": '#include "core/mid/b.h"\n#include "core/top/c.h"\n',
        "core/top/c.h": "",
        "core/top/c.cc": '#include "core/low/a.h"\n#include "core/mid/b.h"\n',
        "server/s.cc": '#include "core/low/a.h"\n#include "core/mid/b.h"\n#include <CGAL/x.h>\n',
    }
    expected = [
        "core/mid/b.cc:2: #include core/top/c.h: mid links none of ['top']",
        "server/s.cc:2: #include core/mid/b.h: server links none of ['mid']",
        "server/s.cc:3: #include CGAL/x.h: the server and client reach CGAL, VTK and TetGen "
        "only through core",
    ]
    found = list(include_problems(targets, texts))
    return [] if found == expected else [f"self-check: found {found}, expected {expected}"]


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    problems = self_check()
    targets = code_model(pathlib.Path(sys.argv[1]).resolve())
    problems += list(folder_problems(targets)) + list(include_problems(targets, project_texts()))
    for problem in problems:
        print(problem)
    ours = sum(1 for sources, _ in targets.values() if sources)
    print(f"{ours} targets read, {len(problems)} includes or files across the links")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
