#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# Installs every Debian 12 package labelmesh needs to build, test and run.
# Used by README.md, .ci/run and the Dockerfile, so all three install the same way.
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake ninja-build ccache pkg-config git ca-certificates
  # core: image readers, geometry, meshing
  libvtk9-dev libcgal-dev libeigen3-dev libtbb-dev libtet1.5-dev zlib1g-dev libdcmtk-dev
  # service: schema, RPC, logging, metrics
  libgrpc++-dev libgrpc-dev protobuf-compiler protobuf-compiler-grpc libprotobuf-dev
  libspdlog-dev libfmt-dev prometheus-cpp-dev libcivetweb-dev libssl-dev
  # jobs shared between machines: the NATS client, and the server the tests start
  libnats-dev nats-server
  # command line, tests and the static checks CI runs
  libcli11-dev libgtest-dev libgmock-dev clang-tidy clang
  # tests that prove our files with tools we did not write
  python3 python3-numpy python3-nibabel python3-meshio python3-grpcio python3-protobuf
  python3-pydicom python3-h5py  # h5py: meshio imports it to read any XDMF
  python3-yaml  # reads deploy/'s Kubernetes and Compose files in their test
  # finite-element tools that must accept our volume meshes
  calculix-ccx gmsh
  # DICOM tools and a PACS that must accept our DICOM surfaces
  dcmtk orthanc
  # service tests: TLS certificates
  openssl
  # report.html rendered headless in its test
  chromium
)

if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

echo "install-deps: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update
"${sudo[@]}" apt-get install -y --no-install-recommends "${missing[@]}"
