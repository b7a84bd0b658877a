#!/usr/bin/env python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""Conforming meshes of several labels in solvers nobody here wrote.

The nested-spheres phantom (a ball inside two shells) is meshed with
--volume conforming; meshio reads every volume format back with the same
counts and groups, Gmsh checks the MSH, and CalculiX solves a gravity load
with a stiff core and soft shells. The prostate's two zones get the same
load case, the peripheral zone stiff. Nodes on the interfaces belong to both
materials, so the displacement field is one field across them.
"""
import json
import pathlib
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / "volume_mesh"))
import fe_solvers_test as fe  # noqa: E402

import meshio  # noqa: E402


def element_sets(inp):
    """ELSET name -> element ids, and element id -> nodes, from *ELEMENT blocks."""
    sets, elements, current = {}, {}, None
    for line in inp.read_text().splitlines():
        if line.startswith("*"):
            head = [f.strip() for f in line.upper().split(",")]
            current = None
            if head[0] == "*ELEMENT":
                current = next(f.split("=")[1] for f in head if f.startswith("ELSET="))
                sets[current] = []
            continue
        if current and line.strip():
            fields = [int(v) for v in line.split(",")]
            sets[current].append(fields[0])
            elements[fields[0]] = fields[1:]
    return sets, elements


def check_meshio(work, report):
    volume = report["volume"]
    tets = int(volume["tetrahedra"])
    interfaces = volume["conforming_figures"]
    faces = int(interfaces["interface_faces"]) + int(interfaces["outer_faces"])
    for name in ("volume.vtu", "volume.msh", "volume.mesh", "volume.xdmf"):
        mesh = meshio.read(work / name)
        counts = {}
        for block in mesh.cells:
            counts[block.type] = counts.get(block.type, 0) + len(block.data)
        if counts.get("tetra") != tets or counts.get("triangle", faces) != faces:
            fe.fail(f"{name}: meshio read {counts}, the report has {tets} tetrahedra, "
                    f"{faces} interface triangles")
    vtu = meshio.read(work / "volume.vtu")
    if sorted(set(vtu.cell_data["label"][0].tolist())) != [1, 2, 3]:
        fe.fail(f"volume.vtu labels {sorted(set(vtu.cell_data['label'][0].tolist()))}")
    shared = meshio.read(work / "volume_interfaces.vtu")
    pairs = {(int(a), int(b)) for a, b in zip(shared.cell_data["label_inside"][0],
                                               shared.cell_data["label_outside"][0])}
    if pairs != {(1, 2), (2, 3), (3, 0)}:
        fe.fail(f"volume_interfaces.vtu has label pairs {sorted(pairs)}, not (1,2) (2,3) (3,0)")
    xdmf = meshio.read(work / "volume.xdmf")
    cell_tags = sorted(set(xdmf.cell_data["label"][0].ravel().tolist()))
    if cell_tags != [1, 2, 3]:
        fe.fail(f"volume.xdmf cell tags {cell_tags}")
    facets = meshio.read(work / "volume_facets.xdmf")
    facet_count = sum(len(b.data) for b in facets.cells if b.type == "triangle")
    tags = sorted(set(facets.cell_data["interface"][0].ravel().tolist()))
    if facet_count != faces or tags != [1, 2, 3]:
        fe.fail(f"volume_facets.xdmf: {facet_count} triangles tagged {tags}; the report has "
                f"{faces} interface triangles in 3 interfaces")
    msh = meshio.read(work / "volume.msh")
    names = set(msh.field_data)
    for want in ("label_1__label_2", "label_2__label_3", "label_3__outside"):
        if want not in names:
            fe.fail(f"volume.msh has no physical surface {want}: {sorted(names)}")
    print(f"meshio: {tets} tetrahedra and {faces} interface triangles in vtu, msh, mesh, xdmf; "
          f"interfaces {sorted(pairs)}")


def check_gmsh(work, report):
    run = subprocess.run(["gmsh", "-check", str(work / "volume.msh")], capture_output=True,
                         text=True, timeout=300)
    text = run.stdout + run.stderr
    bad = [l for l in text.splitlines() if l.startswith(("Warning", "Error"))]
    if run.returncode != 0 or bad:
        fe.fail(f"gmsh exited {run.returncode}: {bad[:5] or text[-2000:]}")
    print("gmsh: coherence check clean")


def write_deck(work, nodes, sets, job):
    zs = [p[2] for p in nodes.values()]
    z_min, z_max = min(zs), max(zs)
    fixed = sorted(n for n, p in nodes.items() if p[2] <= z_min + 0.1 * (z_max - z_min))
    core = next(name for name in sets if name.startswith("LABEL_1"))
    shells = [name for name in sets if name != core]
    lines = ["*INCLUDE, INPUT=volume.inp", "*NSET, NSET=EVERY, GENERATE", f"1, {max(nodes)}, 1",
             "*NSET, NSET=FIXED"]
    lines += [", ".join(str(n) for n in fixed[i:i + 12]) for i in range(0, len(fixed), 12)]
    lines += ["*ELSET, ELSET=SHELLS"] + shells
    lines += [
        # mm, N, tonne: a core a hundred times stiffer than the shells around it.
        "*MATERIAL, NAME=STIFF", "*ELASTIC", "100.0, 0.3", "*DENSITY", "1.06e-9",
        "*MATERIAL, NAME=SOFT", "*ELASTIC", "1.0, 0.45", "*DENSITY", "1.06e-9",
        f"*SOLID SECTION, ELSET={core}, MATERIAL=STIFF",
        "*SOLID SECTION, ELSET=SHELLS, MATERIAL=SOFT",
        "*BOUNDARY", "FIXED, 1, 3",
        "*STEP", "*STATIC",
        f"*DLOAD", f"{core}, GRAV, 9810., 0., 0., -1.", "SHELLS, GRAV, 9810., 0., 0., -1.",
        "*NODE PRINT, NSET=EVERY", "U",
        "*END STEP",
    ]
    (work / f"{job}.inp").write_text("\n".join(lines) + "\n")
    return fixed, core


def solve_two_materials(work, report, job):
    """A stiff label 1 inside or beside soft others under gravity; the nodes they share move as one."""
    nodes = fe.read_nodes(work / "volume.inp")
    sets, elements = element_sets(work / "volume.inp")
    fixed, core = write_deck(work, nodes, sets, job)
    core_nodes = {n for e in sets[core] for n in elements[e]}
    shell_nodes = {n for name in sets if name != core for e in sets[name] for n in elements[e]}
    shared = core_nodes & shell_nodes
    if not shared:
        fe.fail(f"{job}: the stiff and the soft labels share no node")
    displacements = fe.check_calculix(work, nodes, fixed, job=job)
    moved = sum(1 for n in shared if any(c != 0 for c in displacements[n]))
    if moved == 0:
        fe.fail(f"{job}: no interface node moved under gravity")
    print(f"{job}: {len(shared)} interface nodes shared by the stiff and the soft labels, "
          f"{moved} of them displaced, one value each")


def mesh_conforming(labelmesh, volume, work, formats):
    run = subprocess.run([labelmesh, "mesh", str(volume), "--volume", "conforming",
                          "--formats", formats, "--out", str(work), "--json"],
                         capture_output=True, text=True, timeout=600)
    if run.returncode != 0:
        fe.fail(f"labelmesh mesh {volume.name} exited {run.returncode}: {run.stderr[-2000:]}")
    report = json.loads(run.stdout)
    volume_report = report["volume"]
    if volume_report["mesher"] != "conforming" or not volume_report.get("conforming"):
        fe.fail(f"{volume.name}: not a conforming mesh: {volume_report['mesher']}")
    return report


def main():
    import argparse
    parser = argparse.ArgumentParser()
    parser.add_argument("--labelmesh", required=True)
    parser.add_argument("--prostate", required=True, help="the two-zone prostate segmentation")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="labelmesh-conforming-") as tmp:
        work = pathlib.Path(tmp)
        phantom = work / "nested.nii.gz"
        subprocess.run([args.labelmesh, "phantom", "nested-spheres", "--out", str(phantom)],
                       check=True, capture_output=True, timeout=120)
        report = mesh_conforming(args.labelmesh, phantom, work, "vtu,msh,mesh,inp,xdmf")
        check_meshio(work, report)
        check_gmsh(work, report)
        solve_two_materials(work, report, "nested")
    # The prostate's two zones (0.6 x 0.6 x 4 mm slices): the peripheral zone
    # stiff, the transition zone soft.
    if not pathlib.Path(args.prostate).exists():
        print(f"SKIP: the nested labels passed; missing shared data file {args.prostate}")
        sys.exit(77)
    with tempfile.TemporaryDirectory(prefix="labelmesh-conforming-") as tmp:
        work = pathlib.Path(tmp)
        report = mesh_conforming(args.labelmesh, pathlib.Path(args.prostate), work, "inp")
        solve_two_materials(work, report, "prostate")
    print("PASS")


if __name__ == "__main__":
    main()
