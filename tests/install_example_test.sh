#!/usr/bin/env bash
# Installs qem from the build tree into a temporary prefix, builds examples/hello_qem against it
# with find_package(qem), and runs it on a generated mesh: the README's library example works.
set -euo pipefail
build_dir=$1 source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
cmake -S "$source_dir/examples/hello_qem" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/build" >/dev/null
"$work/prefix/bin/qem" generate sphere "$work/in.ply" --faces 5000 2>/dev/null
out=$("$work/build/hello_qem" "$work/in.ply" "$work/out.obj")
echo "$out"
[[ "$out" == "5120 -> 512 faces"* ]]
[ -s "$work/out.obj" ]
# The viewer's HTTP module is installed where the installed qem looks for it (src/view/http_server.h),
# and qem itself does not load cpp-httplib (and OpenSSL with it) at every start.
[ -f "$work/prefix/lib/qem/libqem_http.so" ] || [ -f "$work/prefix/lib/$(gcc -print-multiarch 2>/dev/null)/qem/libqem_http.so" ]
if command -v readelf >/dev/null; then
  ! readelf -d "$work/prefix/bin/qem" | grep -q "cpp-httplib"
fi
