#!/usr/bin/env bash
# Builds dynamic_vo and dyncull_motion_truth (apps/, Release) and runs the main demo: dynamic_vo on the synthetic dynamic RGB-D
# sequences, every culling preset against no culling. Without arguments it runs the scene-family suite
# (dynamic_vo --suite: every family x static,xyz,rpy,halfsphere x seeds 1,2,3, 150 frames each, on
# DYNCULL_JOBS threads, default all cores) and prints one summary table, a row per family; it also writes
# family_summary.md / family_summary.csv. With arguments they go to dynamic_vo instead (try --help).
# Output (tables, CSV, plots drawn by scripts/figures.py, frames) goes to ./dynamic_vo_out unless --out is given. DYNCULL_DEMO_BUILD sets
# the build directory (default build/demo).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="${DYNCULL_DEMO_BUILD:-$root/build/demo}"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DDYNCULL_BUILD_TESTS=OFF \
  -DDYNCULL_BUILD_BENCHMARKS=OFF -DDYNCULL_BUILD_EXAMPLES=OFF -DDYNCULL_BUILD_APPS=ON >/dev/null
# dyncull_motion_truth beside it: scripts/results.sh labels the real sequence with it first.
cmake --build "$build" -j "${DYNCULL_JOBS:-$(nproc)}" --target dynamic_vo dyncull_motion_truth
if (($# == 0)); then
  set -- --suite --jobs "${DYNCULL_JOBS:-$(nproc)}"
fi
"$build/apps/dynamic_vo" "$@"
# dynamic_vo writes the plots' data (CSV); scripts/figures.py draws them (matplotlib) beside it. The
# suite's dozens of sequences get the family summary only.
out=dynamic_vo_out summary_only=() previous=
for arg in "$@"; do
  [[ "$previous" == --out ]] && out=$arg
  [[ "$arg" == --suite ]] && summary_only=(--summary-only)
  previous=$arg
done
if [[ -f "$out/family_summary.csv" ]] || compgen -G "$out/*_poses.csv" >/dev/null; then
  "$root/scripts/figures.sh" "$out" "${summary_only[@]}"
fi
