#!/usr/bin/env bash
# Installs what the viewer's browser test needs: Debian's Chromium (the test drives it headless
# through playwright-core; no browser is ever downloaded by npm) and the npm packages of web/
# (three, esbuild, playwright-core) from web/package-lock.json. Run as root, or with sudo.
set -euo pipefail
cd "$(dirname "$0")/.."
SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO=sudo; fi
export DEBIAN_FRONTEND=noninteractive
# Only what is missing: the machine's own Node.js (20+) is newer than Debian's and must be kept.
PKGS=""
command -v chromium >/dev/null || PKGS="$PKGS chromium"
command -v npm >/dev/null || PKGS="$PKGS nodejs npm"
if [ -n "$PKGS" ]; then
  # Several jobs may install packages at once on a shared machine: serialise apt through a lock.
  $SUDO flock /tmp/apt.lock apt-get update
  # shellcheck disable=SC2086
  $SUDO flock /tmp/apt.lock apt-get install -y --no-install-recommends $PKGS
fi
# playwright-core never downloads a browser; the test points it at /usr/bin/chromium.
(cd web && npm ci --no-audit --no-fund)
