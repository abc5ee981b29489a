#!/usr/bin/env bash
# qem-mpi with 2 ranks on one machine (docs/parallel.md): the result is valid (closed like its
# input: no crack where parts met), reaches the target, is the same file as the partitioned run on
# threads with the same parts, and its E is within 1.1x of the in-core run's.
#   tests/mpi_test.sh BUILD_DIR MPIEXEC
set -euo pipefail
BUILD=$1
MPIEXEC=${2:-mpirun}
QEM=$BUILD/qem
DIR=$(mktemp -d)
trap 'rm -rf "$DIR"' EXIT
field() { /usr/bin/python3 -c "import json,sys; print(json.loads(sys.stdin.read().splitlines()[-1])['$1'])"; }

"$QEM" generate torus "$DIR/in.ply" --faces 200000 2>/dev/null
in_faces=$("$QEM" info "$DIR/in.ply" --json | field faces)
target=$((in_faces / 10))
# As root (CI), OpenMPI wants --allow-run-as-root; --oversubscribe lets 2 ranks share fewer cores.
"$MPIEXEC" --oversubscribe --allow-run-as-root -np 2 "$BUILD/qem-mpi" "$DIR/in.ply" "$DIR/mpi.ply" \
  --ratio 0.1 --parts 4 --threads 1 --json --quiet > "$DIR/mpi.json"
[ "$(field ranks < "$DIR/mpi.json")" = 2 ] || { echo "not 2 ranks: $(cat "$DIR/mpi.json")"; exit 1; }
[ "$(field parts < "$DIR/mpi.json")" = 4 ] || { echo "not 4 parts: $(cat "$DIR/mpi.json")"; exit 1; }
"$QEM" info "$DIR/mpi.ply" --json > "$DIR/info.json"
faces=$(field faces < "$DIR/info.json")
boundary=$(field boundary_edges < "$DIR/info.json")
non_manifold=$(field non_manifold_edges < "$DIR/info.json")
[ "$faces" = "$target" ] || { echo "qem-mpi wrote $faces faces, target $target"; exit 1; }
[ "$boundary" = 0 ] || { echo "qem-mpi's output has $boundary boundary edges; the torus has none (a crack)"; exit 1; }
[ "$non_manifold" = 0 ] || { echo "qem-mpi's output has $non_manifold non-manifold edges"; exit 1; }
# The same parts simplified on threads: the same bytes.
"$QEM" simplify "$DIR/in.ply" "$DIR/threads.ply" --ratio 0.1 --partition 4 --threads 2 --quiet
cmp "$DIR/mpi.ply" "$DIR/threads.ply" || { echo "qem-mpi and qem simplify --partition 4 differ"; exit 1; }
"$QEM" simplify "$DIR/in.ply" "$DIR/incore.ply" --ratio 0.1 --partition off --quiet
e_mpi=$("$QEM" measure "$DIR/in.ply" "$DIR/mpi.ply" --json | field E)
e_core=$("$QEM" measure "$DIR/in.ply" "$DIR/incore.ply" --json | field E)
/usr/bin/python3 -c "import sys; r = $e_mpi / $e_core; print('E qem-mpi / in-core = %.4f' % r); sys.exit(0 if r <= 1.1 else 1)"
# A bad input stops every rank with an error, not a hang.
echo "ply" > "$DIR/bad.ply"
if "$MPIEXEC" --oversubscribe --allow-run-as-root -np 2 "$BUILD/qem-mpi" "$DIR/bad.ply" "$DIR/bad_out.ply" \
  --ratio 0.1 --quiet 2> "$DIR/bad.err"; then
  echo "qem-mpi accepted a broken file"; exit 1
fi
grep -q "qem-mpi: error: .*bad.ply" "$DIR/bad.err" || { echo "no clear error: $(cat "$DIR/bad.err")"; exit 1; }
[ ! -e "$DIR/bad_out.ply" ] || { echo "an output was written for a broken input"; exit 1; }
# A mesh with attributes: the parts travel as positions and faces, so qem-mpi says so (qem simplify
# --partition carries them).
/usr/bin/python3 - "$DIR/uv.obj" <<'PY'
import sys
with open(sys.argv[1], "w") as f:
    f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\n")
    f.write("f 1/1 3/3 2/2\nf 1/1 2/2 4/3\nf 2/2 3/3 4/1\nf 3/3 1/1 4/2\n")
PY
if "$MPIEXEC" --oversubscribe --allow-run-as-root -np 2 "$BUILD/qem-mpi" "$DIR/uv.obj" "$DIR/uv_out.ply" \
  --ratio 0.5 --quiet 2> "$DIR/uv.err"; then
  echo "qem-mpi accepted a mesh with attributes"; exit 1
fi
grep -q "qem-mpi sends the parts' positions and faces only" "$DIR/uv.err" || { echo "no clear error: $(cat "$DIR/uv.err")"; exit 1; }
echo "qem-mpi: 2 ranks, $in_faces -> $faces faces, closed, same bytes as the threads"
