#!/usr/bin/env bash
# The viewer's browser test: builds the page (web/dist) and the qem binary if needed, writes small
# test meshes, then tests/view/viewer.test.mjs starts `qem view` servers on free ports of
# 127.0.0.1 and drives Debian's Chromium headless through playwright-core. Needs
# scripts/install-web-deps.sh first. Prints `N passed, M failed`; exits non-zero on failure.
# Env: BUILD_DIR (default build), JOBS.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
JOBS=${JOBS:-$(nproc)}

if [ ! -d web/node_modules/three ] || [ ! -d web/node_modules/playwright-core ]; then
  echo "test-web: web/node_modules is missing: run scripts/install-web-deps.sh" >&2
  echo "0 passed, 1 failed"
  exit 1
fi
(cd web && npm run --silent build)
if [ ! -x "$BUILD_DIR/qem" ]; then
  cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release
  cmake --build "$BUILD_DIR" --target qem_cli -j"$JOBS"
fi

OUT_DIR="$BUILD_DIR/web-test"
rm -rf "$OUT_DIR"
mkdir -p "$OUT_DIR"
node tests/view/make_meshes.mjs "$OUT_DIR/meshes" >/dev/null
# The node script stops its servers itself (also on SIGTERM); `timeout` bounds a hung browser.
QEM="$BUILD_DIR/qem" MESH_DIR="$OUT_DIR/meshes" OUT_DIR="$OUT_DIR" \
  timeout -k 10 300 node tests/view/viewer.test.mjs
