#!/usr/bin/python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""A real DICOM SEG meshed with --formats stl,dcm: DCMTK's dcmdump reads the
Encapsulated STL object, and a real Orthanc, started on loopback, stores it in
the SEG's patient and study and gives back, through its REST API, the same
STL bytes and the SEG's identifiers."""

import argparse
import json
import os
import pathlib
import socket
import struct
import subprocess
import sys
import tempfile
import time
import urllib.request

SEG = "dicom-seg/dcmqi-24x38x3-seg.dcm"


def free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def check(condition, message):
    if not condition:
        raise AssertionError(message)


def dump(path, *options):
    """dcmdump's text of the file; it fails on what it cannot parse."""
    return subprocess.run(["dcmdump", *options, str(path)], check=True, capture_output=True,
                          text=True).stdout


def tag_value(text, tag):
    """The bracketed value dcmdump prints for a tag, e.g. (0020,000d)."""
    for line in text.splitlines():
        line = line.strip()
        if line.startswith(tag) and "[" in line:
            return line[line.index("[") + 1:line.index("]")]
    return None


class Orthanc:
    """Orthanc on loopback ports, its storage in `root`, no authentication."""

    def __init__(self, root):
        self.http = free_port()
        config = {"Name": "labelmesh-test", "StorageDirectory": str(root / "storage"),
                  "IndexDirectory": str(root / "storage"), "HttpPort": self.http,
                  "DicomPort": free_port(), "RemoteAccessAllowed": False,
                  "AuthenticationEnabled": False, "Plugins": []}
        (root / "orthanc.json").write_text(json.dumps(config))
        self.log = open(root / "orthanc.log", "w")
        self.process = subprocess.Popen(["Orthanc", str(root / "orthanc.json")],
                                        stdout=self.log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and self.process.poll() is None:
            try:
                self.get("/system")
                return
            except OSError:
                time.sleep(0.2)
        code = self.process.poll()
        self.stop()
        raise AssertionError(f"Orthanc did not answer within 60 s (exit status {code})")

    def request(self, path, data=None):
        request = urllib.request.Request(f"http://127.0.0.1:{self.http}{path}", data=data)
        with urllib.request.urlopen(request, timeout=30) as reply:
            return reply.read()

    def get(self, path):
        return self.request(path)

    def stop(self):
        self.process.terminate()
        try:
            self.process.wait(30)
        except subprocess.TimeoutExpired:
            self.process.kill()
        self.log.close()


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--labelmesh", required=True)
    parser.add_argument("--data", required=True, help="../shared/data")
    args = parser.parse_args()
    seg = pathlib.Path(args.data) / SEG
    if not seg.exists():
        print(f"SKIP: {seg} is missing (../shared/data beside the project)")
        return 77

    with tempfile.TemporaryDirectory(prefix="labelmesh-dicom-stl-") as tmp:
        tmp = pathlib.Path(tmp)
        out = tmp / "out"
        subprocess.run([args.labelmesh, "mesh", str(seg), "--formats", "stl,dcm", "--out",
                        str(out)], check=True, stdout=subprocess.DEVNULL)
        objects = sorted(out.glob("*.dcm"))
        check(len(objects) == 1, f"one surface object expected: {objects}")
        dcm, stl = objects[0], objects[0].with_suffix(".stl")
        stl_bytes = stl.read_bytes()
        triangles = struct.unpack("<I", stl_bytes[80:84])[0]
        check(triangles > 100 and len(stl_bytes) == 84 + 50 * triangles,
              f"{stl.name}: {len(stl_bytes)} bytes for {triangles} triangles")

        # DCMTK reads it, and it carries the SEG's patient, study and frame.
        ours, theirs = dump(dcm), dump(seg, "+P", "0010,0020", "+P", "0020,000d",
                                      "+P", "0020,0052", "+P", "0020,000e", "+P", "0008,0018")
        check("=EncapsulatedSTLStorage" in ours, "SOP class is not Encapsulated STL")
        check(tag_value(ours, "(0008,0060)") == "M3D", "modality is not M3D")
        check(tag_value(ours, "(0042,0012)") == "model/stl", "MIME type is not model/stl")
        check(f"UL {len(stl_bytes)}" in ours, "EncapsulatedDocumentLength is not the STL's")
        for tag in ["(0010,0020)", "(0020,000d)", "(0020,0052)"]:
            check(tag_value(ours, tag) == tag_value(theirs, tag) is not None,
                  f"{tag}: {tag_value(ours, tag)} against the SEG's {tag_value(theirs, tag)}")
        check(tag_value(ours, "(0020,000e)") != tag_value(theirs, "(0020,000e)"),
              "the surfaces must go to a new series")
        check(tag_value(ours, "(0008,1155)") == tag_value(theirs, "(0008,0018)"),
              "the object does not reference the SEG it was made from")

        orthanc = Orthanc(tmp)
        try:
            stored = json.loads(orthanc.request("/instances", dcm.read_bytes()))
            check(stored.get("Status") == "Success", f"Orthanc refused it: {stored}")
            instance = stored["ID"]
            tags = json.loads(orthanc.get(f"/instances/{instance}/simplified-tags"))
            check(tags["SOPClassUID"] == "1.2.840.10008.5.1.4.1.1.104.3",
                  f"SOPClassUID {tags['SOPClassUID']}")
            check(tags["StudyInstanceUID"] == tag_value(theirs, "(0020,000d)"),
                  "Orthanc filed it under another study")
            check(tags["PatientID"] == tag_value(theirs, "(0010,0020)"),
                  "Orthanc filed it under another patient")
            check(tags["FrameOfReferenceUID"] == tag_value(theirs, "(0020,0052)"),
                  "another frame of reference")
            series = json.loads(orthanc.get(f"/instances/{instance}/series"))
            check(series["MainDicomTags"]["Modality"] == "M3D", f"series {series}")
            document = orthanc.get(f"/instances/{instance}/content/0042-0011")
            check(document[:len(stl_bytes)] == stl_bytes and len(document) - len(stl_bytes) <= 1,
                  f"Orthanc's document: {len(document)} bytes, the STL has {len(stl_bytes)}")
            studies = json.loads(orthanc.get("/studies"))
            check(len(studies) == 1, f"one study expected in Orthanc: {studies}")
        finally:
            orthanc.stop()
        print(f"{dcm.name}: {triangles} triangles, stored in Orthanc and read back "
              "byte for byte in the SEG's patient, study and frame of reference")
    return 0


if __name__ == "__main__":
    sys.exit(main())
