#!/usr/bin/env python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""The liver's volume mesh in solvers nobody here wrote.

`labelmesh mesh liver.inr.gz --labels 255 --volume tet --formats inp,msh`
(or `--volume hex --hex-size 5` for hexahedra, C3D8 in the deck, or `--volume mixed
--hex-size 4 --hex-interior-size 16` for an octree's hexahedra, pyramids and tetrahedra),
with the label named "liver" by a label table, then:
- Gmsh loads volume.msh and its coherence check (duplicate nodes and
  elements, isolated nodes) finds nothing, with the report's counts, and
  Gmsh writes the physical group back under its name, label_255_liver;
- CalculiX solves a linear-elastic load case on volume.inp, on the element set
  named after the label (LABEL_255_LIVER): the nodes in the
  lowest 5 % of the z range fixed, gravity along -z, soft-tissue material.
  It must finish without an error or a Jacobian warning, and the largest
  displacement must be finite, positive and downward at the far end.
"""
import argparse
import json
import math
import pathlib
import re
import subprocess
import sys
import tempfile


def fail(message):
    print(f"FAIL: {message}", file=sys.stderr)
    sys.exit(1)


def read_nodes(inp):
    """Node id -> (x, y, z) from the *NODE block of an Abaqus deck."""
    nodes, in_nodes = {}, False
    for line in inp.read_text().splitlines():
        if line.startswith("*"):
            in_nodes = line.upper().split(",")[0].strip() == "*NODE"
            continue
        if in_nodes and line.strip():
            fields = line.split(",")
            nodes[int(fields[0])] = tuple(float(v) for v in fields[1:4])
    return nodes


def write_deck(work, nodes, element_set):
    zs = [p[2] for p in nodes.values()]
    z_min, z_max = min(zs), max(zs)
    fixed = sorted(n for n, p in nodes.items() if p[2] <= z_min + 0.05 * (z_max - z_min))
    lines = ["*INCLUDE, INPUT=volume.inp", "*NSET, NSET=EVERY, GENERATE", f"1, {max(nodes)}, 1",
             "*NSET, NSET=FIXED"]
    lines += [", ".join(str(n) for n in fixed[i:i + 12]) for i in range(0, len(fixed), 12)]
    lines += [
        # Units mm, N, tonne, s: E = 1 MPa (rubber-like; liver is softer, but a linear
        # solve of its sag would be meaningless), nearly incompressible.
        "*MATERIAL, NAME=TISSUE", "*ELASTIC", "1.0, 0.45",
        "*DENSITY", "1.06e-9",
        f"*SOLID SECTION, ELSET={element_set}, MATERIAL=TISSUE",
        "*BOUNDARY", "FIXED, 1, 3",
        "*STEP", "*STATIC",
        "*DLOAD", f"{element_set}, GRAV, 9810., 0., 0., -1.",
        "*NODE PRINT, NSET=EVERY", "U",
        "*END STEP",
    ]
    (work / "liver.inp").write_text("\n".join(lines) + "\n")
    return fixed


def check_gmsh(work, report):
    run = subprocess.run(["gmsh", "-check", str(work / "volume.msh")], capture_output=True,
                         text=True, timeout=300)
    text = run.stdout + run.stderr
    if run.returncode != 0:
        fail(f"gmsh exited {run.returncode}: {text[-2000:]}")
    bad = [l for l in text.splitlines() if l.startswith(("Warning", "Error"))]
    if bad:
        fail(f"gmsh complained: {bad[:5]}")
    nodes = re.search(r"Info\s*:\s*(\d+) nodes", text)
    elements = re.search(r"Info\s*:\s*(\d+) elements", text)
    volume = report["volume"]
    if not nodes or int(nodes.group(1)) != int(volume["nodes"]):
        fail(f"gmsh read {nodes and nodes.group(1)} nodes, the report has {volume['nodes']}")
    cells = sum(int(volume.get(kind, 0)) for kind in ("tetrahedra", "hexahedra", "prisms",
                                                       "pyramids"))
    if not elements or int(elements.group(1)) != cells:
        fail(f"gmsh read {elements and elements.group(1)} elements, the report has {cells}")
    # Gmsh writes what it read: the physical group must come back with its name.
    run = subprocess.run(["gmsh", "-0", str(work / "volume.msh"), "-o", str(work / "gmsh.msh"),
                          "-format", "msh4"], capture_output=True, text=True, timeout=300)
    if run.returncode != 0:
        fail(f"gmsh could not write the mesh back: {(run.stdout + run.stderr)[-2000:]}")
    if '3 255 "label_255_liver"' not in (work / "gmsh.msh").read_text():
        fail("gmsh did not keep the physical name label_255_liver")
    print(f"gmsh: {nodes.group(1)} nodes, {elements.group(1)} elements, coherence check clean, "
          "physical name label_255_liver")


def check_calculix(work, nodes, fixed, job="liver"):
    run = subprocess.run(["ccx", "-i", job], cwd=work, capture_output=True, text=True,
                         timeout=1200)
    text = run.stdout + run.stderr
    (work / "ccx.log").write_text(text)
    if run.returncode != 0 or "*ERROR" in text or "*WARNING" in text:
        fail(f"ccx exited {run.returncode}: {text[-2000:]}")
    if re.search(r"jacobian", text, re.IGNORECASE):
        fail("ccx warned about a Jacobian: " + text[-2000:])
    if "Job finished" not in text:
        fail("ccx did not finish: " + text[-2000:])
    displacements = {}
    in_table = False
    for line in (work / f"{job}.dat").read_text().splitlines():
        if "displacements" in line:
            in_table = True
            continue
        fields = line.split()
        if in_table and len(fields) == 4:
            displacements[int(fields[0])] = tuple(float(v) for v in fields[1:])
    if len(displacements) != len(nodes):
        fail(f"ccx printed {len(displacements)} displacements for {len(nodes)} nodes")
    if any(not all(math.isfinite(c) for c in u) for u in displacements.values()):
        fail("a displacement is not finite")
    if any(any(c != 0 for c in displacements[n]) for n in fixed):
        fail("a fixed node moved")
    largest = max(displacements, key=lambda n: math.dist((0, 0, 0), displacements[n]))
    u = displacements[largest]
    if not (u[2] < 0 and math.dist((0, 0, 0), u) > 0):
        fail(f"the largest displacement {u} does not point down")
    print(f"ccx: {len(fixed)} fixed nodes, largest displacement {math.dist((0, 0, 0), u):.3g} mm "
          f"at node {largest} (z {nodes[largest][2]:.1f} mm), no error or Jacobian warning")
    return displacements


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--labelmesh", required=True)
    parser.add_argument("--data", required=True)
    parser.add_argument("--volume", default="tet", choices=["tet", "mixed", "hex"])
    parser.add_argument("--hex-size", default="0")
    parser.add_argument("--hex-interior-size", default="0")
    args = parser.parse_args()
    liver = pathlib.Path(args.data) / "liver.inr.gz"
    if not liver.exists():
        print(f"SKIP: missing shared data file {liver}")
        sys.exit(77)
    with tempfile.TemporaryDirectory(prefix="labelmesh-fe-") as tmp:
        work = pathlib.Path(tmp)
        (work / "names.json").write_text('{"255": "liver"}')
        run = subprocess.run([args.labelmesh, "mesh", f"{args.data}/liver.inr.gz", "--labels", "255",
                              "--volume", args.volume, "--hex-size", args.hex_size,
                              "--hex-interior-size", args.hex_interior_size,
                              "--formats", "inp,msh", "--out", str(work),
                              "--label-names", str(work / "names.json"), "--json"],
                             capture_output=True, text=True, timeout=600)
        if run.returncode != 0:
            fail(f"labelmesh mesh exited {run.returncode}: {run.stderr[-2000:]}")
        report = json.loads(run.stdout)
        volume = report["volume"]
        if args.volume == "hex" and (int(volume.get("hexahedra", 0)) == 0 or
                                     volume.get("labels_left_out")):
            fail(f"no hexahedral mesh of the liver: {volume.get('labels_left_out')}")
        if int(volume.get("inverted", 0)) != 0:
            fail(f"{volume['inverted']} inverted cells")
        check_gmsh(work, report)
        nodes = read_nodes(work / "volume.inp")
        if len(nodes) != int(report["volume"]["nodes"]):
            fail(f"volume.inp has {len(nodes)} nodes, the report {report['volume']['nodes']}")
        fixed = write_deck(work, nodes, "LABEL_255_LIVER")
        check_calculix(work, nodes, fixed)
    print("PASS")


if __name__ == "__main__":
    main()
