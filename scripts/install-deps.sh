#!/usr/bin/env bash
# Installs everything qem needs to build and test on Debian 12 (run as root, or with sudo).
set -euo pipefail
SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO=sudo; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
# build: compiler, CMake, pkg-config (finds cpp-httplib); libraries: Eigen (3x3 / eigen solves),
# CLI11 (command line), fast_float (number parsing in the text readers), nanoflann (k-d tree for
# threshold pairs), cpp-httplib (the viewer's local HTTP server), libpng (`qem render`'s PNGs),
# nlohmann/json (the viewer's LOD manifests and scene description, and tinygltf's JSON), tinygltf
# (glTF 2.0 read and write with pass-through), libdraco and libmeshoptimizer (decode glTF geometry compressed by Draco or
# EXT_meshopt_compression);
# tests: GoogleTest, Google Benchmark; clang + libclang-rt for the libFuzzer targets; chromium for
# the viewer's browser test; the Python module: Python headers, pybind11, numpy, setuptools and pip
# (`pip install --no-build-isolation .`), pytest, Open3D (interoperability test, bench/python_peers.py);
# OpenMPI for qem-mpi, the partitioned run across MPI ranks (docs/parallel.md) and its test.
$SUDO apt-get install -y --no-install-recommends \
  build-essential cmake g++ python3 pkg-config \
  libeigen3-dev libcli11-dev libfast-float-dev libnanoflann-dev \
  libcpp-httplib-dev libpng-dev nlohmann-json3-dev libtinygltf-dev libdraco-dev libmeshoptimizer-dev \
  libgtest-dev libgmock-dev libbenchmark-dev \
  clang libclang-rt-14-dev \
  python3-dev pybind11-dev python3-pybind11 python3-numpy python3-setuptools python3-pip \
  python3-pytest python3-open3d \
  libopenmpi-dev openmpi-bin \
  chromium
# The viewer's npm packages (three, esbuild, playwright-core) from web/package-lock.json.
bash "$(dirname "$0")/install-web-deps.sh"
