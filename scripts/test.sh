#!/usr/bin/env bash
# The whole test suite: a Release build and an AddressSanitizer + UBSan build, each running every
# test through ctest, then each fuzzer for a bounded time. Build trees go to build/ and build-asan/.
# The Python module and its tests (ctest's PythonTests) are in the Release build only: a module
# built with AddressSanitizer loads only into an interpreter started with libasan preloaded, whose
# own allocations then flood the leak report.
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS=${JOBS:-$(nproc)}
FUZZ_SECONDS=${FUZZ_SECONDS:-60}

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DQEM_BUILD_BENCH=ON  # benchmarks are built (not run) so they cannot rot
cmake --build build -j"$JOBS"
ctest --test-dir build --output-on-failure -j"$JOBS"
# The viewer in a real (headless) browser.
BUILD_DIR=build scripts/test-web.sh

cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DQEM_SANITIZE=ON -DQEM_BUILD_PYTHON=OFF
cmake --build build-asan -j"$JOBS"
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-asan --output-on-failure -j"$JOBS"

if [ -d fuzz ] && command -v clang++ >/dev/null && [ "$FUZZ_SECONDS" != 0 ]; then
  scripts/fuzz.sh "$FUZZ_SECONDS"
fi
