#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz/*_fuzz.cpp, clang++ with ASan + UBSan) in build/fuzz and
# runs each for a bounded time from its checked-in seed corpus tests/fuzz/corpus/<name>/, printing the
# number of executions per target. Exit status 1 when a target found a crash, a leak, a timeout or a
# broken invariant; the input is saved as build/fuzz/crashes/<name>-crash-<sha1> (add it to the seed
# corpus or turn it into a regression test once fixed).
#   scripts/fuzz.sh [seconds per target]     (default 60; also DYNCULL_FUZZ_SECONDS)
#   DYNCULL_FUZZ_TARGETS="tum yolo"          run only these targets (culler needs OpenCV 4)
#   DYNCULL_FUZZ_SEED=N                      libFuzzer's -seed (default: a random seed each run; .ci/run fixes
#                                            it so that a failure in CI reproduces with the same command)
#   DYNCULL_FUZZ_TREE=build/asan             the fuzz targets of that tree (scripts/test.sh --asan builds them
#                                            with its libraries) instead of a build/fuzz of their own
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
seconds=${1:-${DYNCULL_FUZZ_SECONDS:-60}}
jobs=${DYNCULL_JOBS:-$(nproc)}
build="$root/build/fuzz"
[[ -n "${DYNCULL_FUZZ_TREE:-}" ]] && build=$(cd "$DYNCULL_FUZZ_TREE" && pwd)
cxx=$(command -v clang++ || true)
if [[ -z "$cxx" ]]; then
  echo "fuzz.sh: clang++ not found (libFuzzer needs clang)" >&2
  exit 2
fi
# Ninja when it is installed and the build tree is new: it builds the fuzz targets side by side, where make
# builds the targets named on one command line one after another (each a single translation unit).
generator=()
if [[ ! -f "$build/CMakeCache.txt" ]] && command -v ninja >/dev/null; then generator=(-G Ninja); fi
if [[ -n "${DYNCULL_FUZZ_TREE:-}" ]]; then
  if ! grep -qx 'DYNCULL_BUILD_FUZZERS:BOOL=ON' "$build/CMakeCache.txt" 2>/dev/null; then
    echo "fuzz.sh: $DYNCULL_FUZZ_TREE is not a tree configured with DYNCULL_BUILD_FUZZERS=ON" >&2
    exit 2
  fi
else
  cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DCMAKE_CXX_COMPILER="$cxx" \
    -DDYNCULL_WERROR=ON -DDYNCULL_BUILD_FUZZERS=ON -DDYNCULL_BUILD_TESTS=OFF -DDYNCULL_BUILD_BENCHMARKS=OFF \
    -DDYNCULL_BUILD_EXAMPLES=OFF -DDYNCULL_BUILD_APPS=OFF -DDYNCULL_INSTALL=OFF -DDYNCULL_WITH_OPENCV=ON -DDYNCULL_WITH_CERES=OFF >/dev/null
fi

# Every target this configuration builds (the culler target needs OpenCV: fuzz.sh says when it is left out).
targets=${DYNCULL_FUZZ_TARGETS:-$(cat "$build/tests/fuzz/targets.txt")}
for src in "$root"/tests/fuzz/*_fuzz.cpp; do
  t=$(basename "$src" _fuzz.cpp)
  grep -qx "$t" "$build/tests/fuzz/targets.txt" || echo "fuzz.sh: $t not built (needs OpenCV)" >&2
done
cmake --build "$build" -j "$jobs" --target $(for t in $targets; do printf '%s_fuzz ' "$t"; done)

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
mkdir -p "$build/crashes"
seed_arg=()
if [[ -n "${DYNCULL_FUZZ_SEED:-}" ]]; then seed_arg=(-seed="$DYNCULL_FUZZ_SEED"); fi
run_target() {  # target -> its log in $build/<target>.log, its exit status in $build/<target>.status
  local t=$1 status=0
  local work="$build/corpus/$t"  # new inputs go here; the checked-in seeds are only read
  mkdir -p "$work"
  "$build/tests/fuzz/${t}_fuzz" "$work" "$root/tests/fuzz/corpus/$t" ${seed_arg[@]+"${seed_arg[@]}"} -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/crashes/$t-" >"$build/$t.log" 2>&1 || status=$?
  echo "$status" >"$build/$t.status"
}
# One target per core at a time: each runs single-threaded for its full time.
for t in $targets; do
  run_target "$t" &
  while (($(jobs -rp | wc -l) >= jobs)); do wait -n || true; done
done
wait
failed=()
summary=()
for t in $targets; do
  log="$build/$t.log"
  status=$(cat "$build/$t.status")
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  line="fuzz: $t: ${execs:-?} executions in ${seconds} s"
  if ((status != 0)); then
    line+=" FAILED (exit $status; log $log)"
    failed+=("$t")
    grep -E "ERROR|runtime error|fuzz invariant|SUMMARY|Test unit written" "$log" | head -20 >&2 || true
  fi
  echo "$line"
  summary+=("$line")
done
printf '%s\n' "${summary[@]}" >"$build/summary.txt"
if ((${#failed[@]})); then
  echo "fuzz.sh: failures in: ${failed[*]} (inputs in $build/crashes)" >&2
  exit 1
fi
