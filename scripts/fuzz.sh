#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (build-fuzz/, QEM_FUZZ=ON), writes the seed corpora, and
# runs each fuzzer for a bounded time. Usage: scripts/fuzz.sh [SECONDS_PER_FUZZER] (default 60).
# Environment: JOBS (build parallelism), FUZZ_BUILD_DIR (default build-fuzz), FUZZERS (default
# "obj ply stl off gltf simplify").
# Prints, per fuzzer, the executions reached (libFuzzer's final stat::number_of_executed_units).
# Exits non-zero when any fuzzer finds a crash, leak, timeout or out-of-memory input; the input is
# kept in $FUZZ_BUILD_DIR/fuzz/findings/<fuzzer>/ and the log beside it. Replay one with
#   $FUZZ_BUILD_DIR/fuzz/fuzz_<name> <file>
# and turn it into a row of tests/fuzz_regressions_test.cpp.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH=${1:-60}
JOBS=${JOBS:-$(nproc)}
BUILD=${FUZZ_BUILD_DIR:-build-fuzz}
FUZZERS=${FUZZERS:-"obj ply stl off gltf simplify"}

CC=${CC:-clang} CXX=${CXX:-clang++} cmake -S . -B "$BUILD" -DQEM_FUZZ=ON -DQEM_BUILD_TESTS=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
# A fixed seed by default, so a CI run explores the same inputs each time (a finding reproduces);
# FUZZ_SEED=0 lets libFuzzer pick one from the clock for exploratory runs.
FUZZ_SEED=${FUZZ_SEED:-1997}
targets=(fuzz_seeds)
for f in $FUZZERS; do targets+=("fuzz_$f"); done
cmake --build "$BUILD" -j"$JOBS" --target "${targets[@]}"

dir="$BUILD/fuzz"
rm -rf "$dir/seeds"
"$dir/fuzz_seeds" "$dir/seeds"

# UBSan checks are recoverable by default; make them fatal so libFuzzer records the input.
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}

failed=0
printf '%-10s %12s  %s\n' fuzzer executions result
for f in $FUZZERS; do
  corpus="$dir/corpus/$f"        # grows across runs; the seeds are read, never written
  findings="$dir/findings/$f"
  log="$dir/findings/$f.log"
  mkdir -p "$corpus" "$findings"
  dict=()
  [ -f "$dir/seeds/$f.dict" ] && dict=(-dict="$dir/seeds/$f.dict")
  touch "$log.start"
  set +e
  "$dir/fuzz_$f" "$corpus" "$dir/seeds/$f" "${dict[@]}" \
    -max_total_time="$SECONDS_EACH" -seed="$FUZZ_SEED" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
    -artifact_prefix="$findings/" >"$log" 2>&1
  rc=$?
  set -e
  execs=$(awk '/stat::number_of_executed_(runs|units):/ {n = $2} END {print (n == "" ? "?" : n)}' "$log")
  # Inputs written by this run (earlier findings stay in the folder until someone removes them).
  new=$(find "$findings" -maxdepth 1 -type f -newer "$log.start" ! -name 'slow-unit-*')
  rm -f "$log.start"
  if [ "$rc" != 0 ] || [ -n "$new" ]; then
    failed=1
    printf '%-10s %12s  FINDING (exit %s), log %s\n' "$f" "$execs" "$rc" "$log"
    for file in $new; do
      printf '             input %s: %s\n' "$file" "$(head -c 64 "$file" | od -An -tx1 | tr -d ' \n')"
    done
    grep -m 3 -E 'ERROR: |runtime error|qem fuzz finding|deadly signal|uncaught exception' "$log" |
      sed 's/^/             /' || true
    grep -m 8 -E '^ +#[0-9]+ ' "$log" | sed 's/^/             /' || true
  else
    printf '%-10s %12s  ok\n' "$f" "$execs"
  fi
done
exit "$failed"
