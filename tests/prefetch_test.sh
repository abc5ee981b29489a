#!/usr/bin/env bash
# The software prefetches reach the compiled code. GCC 12 once dropped the prefetches of the
# helpers that hold nothing else (apparently judged free of side effects), silently: the output was
# the same and only the time showed it (docs/benchmarks.md, "Measurements behind the code"). The
# helpers are always inlined now; this counts the prefetch instructions in the objects using them.
#   prefetch_test.sh OBJECTS...   (the qem library's object files)
set -euo pipefail
count() {  # prefetch instructions in the object whose path ends with $1
  local object
  object=$(printf '%s\n' "${objects[@]}" | grep -E "/$1\.o$" | head -1)
  [ -n "$object" ] || { echo "no object for $1 among the library's" >&2; exit 1; }
  objdump -d --no-show-raw-insn "$object" | grep -cE '\sprefetch' || true
}
objects=("$@")
fail=0
check() {  # name, minimum
  local n
  n=$(count "$1")
  echo "$1: $n prefetch instructions (at least $2 expected)"
  [ -n "$n" ] && [ "$n" -ge "$2" ] || fail=1
}
check src/core/regions.cpp 10  # the passes' staged prefetch, in the object that makes the bands
check src/io/weld.cpp 1         # the welder's table lookups
check src/io/stl.cpp 1          # the same, inlined into the STL reader
exit $fail
