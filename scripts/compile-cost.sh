#!/usr/bin/env bash
# Compile cost of the culling pipeline in one translation unit: user and wall time and peak RSS of g++ -O2 on
# a file that only includes culling/pipeline.hpp, on one that includes it and instantiates cull_frame<float>
# (a dynamic_vo-like frame), and on that same file with -DDYNCULL_PRECOMPILED, as a target linking
# dyncull::pipeline compiles it (cull_frame and the solvers come from the library, not from this unit).
# Usage: scripts/compile-cost.sh [--csv FILE] [source dir] (default: this checkout). --csv writes one line
# per unit, `unit,user_s,wall_s,peak_rss_mb`, after a header line.
set -euo pipefail
csv=""
src=""
while (($#)); do
  case "$1" in
    --csv) csv="${2:?--csv needs a file}"; shift 2 ;;
    -h|--help) sed -n '2,8p' "$0"; exit 0 ;;
    *) src="$1"; shift ;;
  esac
done
src="${src:-$(cd "$(dirname "$0")/.." && pwd)}"
cxx="${CXX:-g++}"
eigen="$(pkg-config --cflags eigen3 2>/dev/null || echo -I/usr/include/eigen3)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cat > "$tmp/include_only.cpp" <<'CPP'
#include "dyncull/culling/pipeline.hpp"
int main() { return 0; }
CPP
cat > "$tmp/instantiate.cpp" <<'CPP'
#include "dyncull/culling/pipeline.hpp"
#include <vector>
int main() {
  using namespace dyncull;
  std::vector<Vec2<float>> kp(10, Vec2<float>(1.f, 1.f));
  std::vector<Vec3<float>> pts(10, Vec3<float>(0.f, 0.f, 1.f));
  CullingFrame<float, std::vector<Vec2<float>>, std::vector<Vec2<float>>, float, std::vector<Vec3<float>>> f;
  f.keypoints = &kp;
  f.prev_keypoints = &kp;
  f.points_3d = &pts;
  PipelineState<float> state;
  return static_cast<int>(cull_frame(f, PipelineOptions<float>{}, &state).num_static);
}
CPP
# unit name, source file, extra flags
units=("include_only include_only" "instantiate instantiate" "instantiate_precompiled instantiate -DDYNCULL_PRECOMPILED")
[[ -n "$csv" ]] && echo "unit,user_s,wall_s,peak_rss_mb" > "$csv"
for u in "${units[@]}"; do
  read -r unit tu flags <<< "$u"
  # shellcheck disable=SC2086  # flags: zero or one word
  /usr/bin/time -v "$cxx" -std=c++17 -O2 $flags -I"$src/include" $eigen -c "$tmp/$tu.cpp" -o "$tmp/$unit.o" \
    2> "$tmp/$unit.time"
  wall=$(grep "Elapsed (wall clock)" "$tmp/$unit.time" | awk '{print $NF}')
  user=$(grep "User time" "$tmp/$unit.time" | awk '{print $NF}')
  rss=$(grep "Maximum resident set size" "$tmp/$unit.time" | awk '{print $NF}')
  printf '%-23s user %8s s  wall %9s  peak RSS %6d MB\n' "$unit" "$user" "$wall" $((rss / 1024))
  if [[ -n "$csv" ]]; then
    # wall clock is [h:]m:ss.ss; the CSV carries seconds
    wall_s=$(awk -F: '{s = 0; for (i = 1; i <= NF; ++i) s = s * 60 + $i; printf "%.2f", s}' <<< "$wall")
    echo "$unit,$user,$wall_s,$((rss / 1024))" >> "$csv"
  fi
done
# The precompiled unit must take cull_frame from the library: a definition of it here means the extern
# declarations (culling/pipeline_extern.hpp) no longer match the frame type above.
if nm -C "$tmp/instantiate_precompiled.o" | grep -q ' [TW] .*cull_frame<'; then
  echo "compile-cost: instantiate_precompiled compiled cull_frame itself (not one of the precompiled frame types)" >&2
  exit 1
fi
