#!/usr/bin/env bash
# Regenerates docs/benchmarks.md: builds every bench binary in Release, runs each with Google Benchmark's JSON
# output, measures the compile cost of the pipeline and of a host translation unit, records the machine,
# compiler, library versions, commit, command and wall time, and writes the page from that output.
#   scripts/benchmarks.sh [--out DIR] [--build DIR] [--page FILE] [--filter REGEX]   run, then write the page
#   scripts/benchmarks.sh --page-only DIR [--page FILE]                            the page from an earlier run
# DIR defaults to out/benchmarks (ignored by git), the build directory to build/bench, FILE to docs/benchmarks.md; --filter
# runs only the bench binaries whose name matches (the page then shows those). Environment:
# DYNCULL_BENCH_MIN_TIME (seconds per repetition, default 0.2), DYNCULL_BENCH_REPETITIONS (default 3).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=out/benchmarks
build="$root/build/bench"
page="$root/docs/benchmarks.md"
page_only=""
only="."
shown="scripts/benchmarks.sh $*"
while (($#)); do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --page) page=$2; shift 2 ;;
    --page-only) page_only=$2; shift 2 ;;
    --filter) only=$2; shift 2 ;;
    *) echo "benchmarks.sh: unknown argument '$1' (see the comment at the top of $0)" >&2; exit 2 ;;
  esac
done

if [[ -n "$page_only" ]]; then
  ls "$page_only"/bench_*.json >/dev/null 2>&1 || { echo "benchmarks.sh: no bench_*.json in $page_only" >&2; exit 1; }
  python3 "$root/scripts/benchmarks_page.py" "$page_only" "$page"
  echo "benchmarks.sh: wrote $page from $page_only"
  exit 0
fi

min_time=${DYNCULL_BENCH_MIN_TIME:-0.2}
reps=${DYNCULL_BENCH_REPETITIONS:-3}
mkdir -p "$out"
start=$(date +%s)
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
# What is built is the tree as it is now: its commit, and whether it differs from it.
commit="$(git -C "$root" rev-parse --short HEAD)$(git -C "$root" diff --quiet HEAD -- include bench src || echo ' (with local changes)')"
cores=$(getconf _NPROCESSORS_ONLN)

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DDYNCULL_WERROR=ON -DDYNCULL_BUILD_BENCHMARKS=ON \
  -DDYNCULL_BUILD_TESTS=OFF -DDYNCULL_BUILD_EXAMPLES=OFF -DDYNCULL_BUILD_APPS=OFF -DDYNCULL_INSTALL=OFF -DDYNCULL_BUILD_DOCS=OFF >/dev/null
mapfile -t targets < <(cmake --build "$build" --target help | awk '$2 ~ /^bench_/ { print $2 }' | grep -E -- "$only" | sort)
((${#targets[@]})) || { echo "benchmarks.sh: no bench target matches '$only'" >&2; exit 1; }
# One core per compile: an -O3 instantiation of the pipeline takes about 1.5 GB.
cmake --build "$build" --target "${targets[@]}" -j"${DYNCULL_JOBS:-1}"
built=$(date +%s)

common=(--benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true --benchmark_min_time="$min_time"
        --benchmark_format=console --benchmark_out_format=json)
# OpenCV's and Open3D's worker threads are invisible to the CPU time of the thread that calls them.
export OMP_NUM_THREADS=1
for t in "${targets[@]}"; do
  exe="$build/bench/$t"
  echo "== $t"
  case "$t" in
    bench_sim_scene_bench)
      # The front-end cases run one fixed iteration each and their counters do not depend on the load.
      "$exe" "${common[@]}" --benchmark_filter=-FrontEndPull --benchmark_out="$out/$t.json"
      "$exe" --benchmark_filter=FrontEndPull --benchmark_out_format=json --benchmark_out="$out/$t.frontend.json" ;;
    *)
      "$exe" "${common[@]}" --benchmark_out="$out/$t.json" ;;
  esac
done

# Compile cost, when the scripts can write CSV (unit,user_s,wall_s,peak_rss_mb).
for s in compile-cost compile-cost-host; do
  csv="$out/${s//-/_}.csv"
  rm -f "$csv"
  if [[ -x "$root/scripts/$s.sh" ]] && grep -q -- '--csv' "$root/scripts/$s.sh"; then
    echo "== scripts/$s.sh --csv"
    # A unit over its script's limit still has its figures written: the page says whether the target is met.
    "$root/scripts/$s.sh" --csv "$csv" || echo "benchmarks.sh: scripts/$s.sh exited with $? (see its output above)" >&2
  else
    echo "benchmarks.sh: skipped scripts/$s.sh (missing, or no --csv option): no compile-cost table from it" >&2
  fi
done

end=$(date +%s)
compiler=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")
ceres=$(sed -n 's/^set(PACKAGE_VERSION "\(.*\)")/\1/p' \
  "$(sed -n 's/^Ceres_DIR:PATH=//p' "$build/CMakeCache.txt")/CeresConfigVersion.cmake" 2>/dev/null || true)
{
  echo "machine: $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1), $cores cores, $(sed -n 's/^PRETTY_NAME="\(.*\)"/\1/p' /etc/os-release 2>/dev/null)"
  echo "load average: $load_before before the run, $(cut -d' ' -f1-3 /proc/loadavg) after (1, 5, 15 minutes)"
  echo "compiler: $("${compiler:-c++}" --version | head -1), CMAKE_BUILD_TYPE=Release"
  echo "libraries: OpenCV $(pkg-config --modversion opencv4 2>/dev/null || echo '?'), Eigen $(pkg-config --modversion eigen3 2>/dev/null || echo '?'), Ceres ${ceres:-not found}, Google Benchmark $(pkg-config --modversion benchmark 2>/dev/null || echo '?')"
  echo "commit: $commit"
  echo "command: $shown (each binary: --benchmark_repetitions=$reps --benchmark_report_aggregates_only=true --benchmark_min_time=$min_time)"
  echo "wall time: $((end - start)) s ($((built - start)) s building, $((end - built)) s running the benches and the compile-cost scripts)"
} >"$out/run_info.txt"

python3 "$root/scripts/benchmarks_page.py" "$out" "$page"
echo "benchmarks.sh: wrote $page"
