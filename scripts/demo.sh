#!/usr/bin/env bash
# Builds the examples (Release) and runs the main demo: dynamic_vo on the synthetic dynamic
# RGB-D sequences, every culling preset against no culling. Extra arguments go to dynamic_vo
# (try --help). Output (table, plots, frames) goes to ./dynamic_vo_out unless --out is given.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build/demo"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DDYNCULL_BUILD_TESTS=OFF \
  -DDYNCULL_BUILD_BENCHMARKS=OFF -DDYNCULL_BUILD_EXAMPLES=ON >/dev/null
cmake --build "$build" -j "${DYNCULL_JOBS:-$(nproc)}" --target dynamic_vo
exec "$build/examples/dynamic_vo" "$@"
