#!/usr/bin/env bash
# Compile cost of the culling pipeline in one translation unit: wall time and peak RSS of g++ -O2 on a file
# that includes culling/pipeline.hpp and instantiates cull_frame<float> (a dynamic_vo-like frame), and on
# one that only includes it. Usage: scripts/compile-cost.sh [source dir] (default: this checkout).
set -euo pipefail
src="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
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
for tu in include_only instantiate; do
  /usr/bin/time -v "$cxx" -std=c++17 -O2 -I"$src/include" $eigen -c "$tmp/$tu.cpp" -o "$tmp/$tu.o" 2> "$tmp/$tu.time"
  wall=$(grep "Elapsed (wall clock)" "$tmp/$tu.time" | awk '{print $NF}')
  user=$(grep "User time" "$tmp/$tu.time" | awk '{print $NF}')
  rss=$(grep "Maximum resident set size" "$tmp/$tu.time" | awk '{print $NF}')
  printf '%-13s user %8s s  wall %9s  peak RSS %6d MB\n' "$tu" "$user" "$wall" $((rss / 1024))
done
