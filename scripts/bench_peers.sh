#!/usr/bin/env bash
# Runs the shared peer benchmark harness (../shared/bench: meshoptimizer, CGAL, OpenMesh, VTK,
# Open3D, MeshLab) with `qem simplify` added as one more peer, on the same meshes and face targets,
# then prints a compact comparison (scripts/bench_summary.py): qem's E/diag², Hausdorff/diag,
# simplify_s and peak RSS beside each peer's, and qem/meshopt time, qem/fastest-other-peer time,
# qem E / best peer E per case. Errors are measured by the harness's own metric (CGAL AABB tree),
# not by qem. See docs/benchmarks.md.
#
#   scripts/bench_peers.sh --meshes /tmp/meshes/bunny.ply /tmp/meshes/sphere_1m3.ply
#   scripts/bench_peers.sh --meshes m.ply --ratios 0.1 --faces '' --peers meshopt,vtk --out /tmp/q
#   scripts/bench_peers.sh --meshes m.ply -- --repeat 3 --repeat-budget 20   # more runner options
set -euo pipefail

REPO=$(cd "$(dirname "$(readlink -f "$0")")/.." && pwd)
BENCH=${QEM_BENCH_DIR:-$REPO/../shared/bench}
BUILD=${BENCH_BUILD:-/tmp/bench-build}
QEM=$REPO/build/qem
OUT=/tmp/qem-bench
RATIOS=0.1,0.01
FACES=100
PEERS=default
NAME=qem
QEM_ARGS=""
MESHES=()
BASELINE=()
RUNNER_ARGS=()

usage() {
  cat <<EOF
usage: $0 --meshes M.ply [M2.ply ...] [options] [-- runner options]

  --meshes FILES...   input meshes (.ply/.obj); the harness's make_meshes.py makes clean PLYs
  --ratios LIST       target ratios of the input faces (default $RATIOS)
  --faces LIST        absolute face targets (default $FACES; '' for none)
  --peers LIST        peers besides qem: default|all|a,b,c|none (default $PEERS)
  --out DIR           results folder: CSV + Markdown from the runner, outputs in DIR/work,
                      the comparison in DIR/summary-TAG.md (default $OUT)
  --qem PATH          the qem binary (default \$REPO/build/qem)
  --qem-args ARGS     extra options for 'qem simplify' (e.g. '--weighting uniform')
  --name NAME         peer name of qem in the tables (default $NAME)
  --baseline CSV      a peers-only CSV: peers missing from this run are filled in from it
                      (use with --peers none to time only qem; marked * in the tables)
  --bench-dir DIR     the harness (default \$QEM_BENCH_DIR or \$REPO/../shared/bench)
  --build-dir DIR     the harness's build (default \$BENCH_BUILD or $BUILD)
  -- ARGS...          passed to the runner (e.g. --repeat 3 --repeat-budget 20 --samples 1e6)
EOF
}

while [ $# -gt 0 ]; do
  case "$1" in
    --meshes)
      shift
      while [ $# -gt 0 ] && [[ "$1" != --* ]]; do MESHES+=("$1"); shift; done
      continue ;;
    --ratios) RATIOS=$2; shift ;;
    --faces) FACES=$2; shift ;;
    --peers) PEERS=$2; shift ;;
    --out) OUT=$2; shift ;;
    --qem) QEM=$2; shift ;;
    --qem-args) QEM_ARGS=$2; shift ;;
    --name) NAME=$2; shift ;;
    --baseline) BASELINE+=(--baseline "$2"); shift ;;
    --bench-dir) BENCH=$2; shift ;;
    --build-dir) BUILD=$2; shift ;;
    -h|--help) usage; exit 0 ;;
    --) shift; RUNNER_ARGS=("$@"); break ;;
    *) echo "bench_peers.sh: unknown option $1" >&2; usage >&2; exit 2 ;;
  esac
  shift
done

die() { echo "bench_peers.sh: $*" >&2; exit 1; }

[ ${#MESHES[@]} -gt 0 ] || { usage >&2; exit 2; }

# --- is the harness there and built? ---------------------------------------------------------------
if [ ! -f "$BENCH/run.py" ]; then
  die "no benchmark harness at $BENCH (set QEM_BENCH_DIR or --bench-dir to the shared bench/ folder)"
fi
if [ ! -x "$BUILD/metric" ]; then
  cat >&2 <<EOF
bench_peers.sh: the harness is not built ($BUILD/metric missing). On Debian 12:
  apt-get install -y --no-install-recommends libmeshoptimizer-dev libcgal-dev libopenmesh-dev \\
      libvtk9-dev python3-open3d meshlab libeigen3-dev libtbb-dev libgmp-dev libmpfr-dev \\
      libboost-dev hyperfine xvfb xauth
  cmake -S $BENCH/peers -B $BUILD -DCMAKE_BUILD_TYPE=Release && cmake --build $BUILD -j2
  /usr/bin/python3 $BENCH/tests/validate_metric.py     # expect '14 passed, 0 failed'
Meshes: python3 $BENCH/make_meshes.py all --bunny BUNNY.ply /tmp/meshes   (see $BENCH/README.md)
EOF
  exit 1
fi
if [ "$PEERS" != none ]; then
  missing=$(python3 "$BENCH/run.py" --list-peers --build-dir "$BUILD" | awk '$2 == "MISSING"' || true)
  if [ -n "$missing" ]; then
    echo "bench_peers.sh: warning: some peers are unavailable (they will show as 'unavailable' rows):" >&2
    echo "$missing" >&2
  fi
fi
[ -x "$QEM" ] || die "no qem binary at $QEM (build it: cmake -S $REPO -B $REPO/build && cmake --build $REPO/build --target qem_cli), or pass --qem"
"$QEM" simplify --help 2>/dev/null | grep -q -- --json || die "$QEM simplify has no --json option"
for m in "${MESHES[@]}"; do [ -f "$m" ] || die "mesh not found: $m"; done

# --- run ------------------------------------------------------------------------------------------
TAG=qem-$(date +%Y%m%d-%H%M%S)
mkdir -p "$OUT/work"
echo "bench_peers.sh: load average $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores; results in $OUT (tag $TAG)" >&2
python3 "$BENCH/run.py" --meshes "${MESHES[@]}" --ratios "$RATIOS" --faces "$FACES" --peers "$PEERS" \
  --extra "$NAME=$QEM simplify {in} {out} --faces {faces} --json --quiet $QEM_ARGS" \
  --build-dir "$BUILD" --work-dir "$OUT/work" --out-dir "$OUT" --tag "$TAG" ${RUNNER_ARGS[@]+"${RUNNER_ARGS[@]}"}

CSV=$(ls -t "$OUT"/*-"$TAG".csv 2>/dev/null | head -1)
[ -n "$CSV" ] || die "the runner wrote no CSV in $OUT"
python3 "$REPO/scripts/bench_summary.py" "$CSV" --ours "$NAME" ${BASELINE[@]+"${BASELINE[@]}"} | tee "$OUT/summary-$TAG.md"
echo >&2
echo "bench_peers.sh: runner tables ${CSV%.csv}.md, CSV $CSV, comparison $OUT/summary-$TAG.md" >&2
