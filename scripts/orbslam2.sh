#!/usr/bin/env bash
# Builds ORB-SLAM2 with dyncull's culler and runs it on a TUM-format RGB-D sequence, stock against the
# culler (integrations/orb_slam2/). One build serves every variant: the patched Tracking reads
# DYNCULL_MODE at run time (stock: no culling; box_only: every feature in a person box removed;
# culler: the recommended preset).
#
#   scripts/orbslam2.sh --sequence DIR --out DIR [--runs N] [--variants stock,box_only,culler] [--page FILE]
#       [--detector CFG,WEIGHTS|MODEL.onnx]
#       copies ORB-SLAM2, applies the patches, builds (Pangolin headless too unless --pangolin-prefix), trains
#       a vocabulary when ORBvoc.txt is absent, runs rgbd_tum (viewer off) once per variant and run in its own
#       folder at the recorded rate, and once more per variant not held to it (DYNCULL_FREE_RUN=1, runs/VARIANT/free:
#       the frames per second the whole system sustains), evaluates the ATE with dyncull_eval and writes
#       OUT/orbslam2_summary.csv; with --page, writes the page's "In ORB-SLAM2" section (default page: none).
#   scripts/orbslam2.sh --families LIST|all --out DIR [--motions xyz,halfsphere] [--frames 300] [--runs N]
#       the same on dyncull's scene families: each family and motion written once as a TUM-format sequence
#       (write_tum_sequence --family, seed 1, the simulated detector's boxes in detections_json/), run, and
#       summed up in OUT/orbslam2_families.csv (and the page's "Scene families in ORB-SLAM2" section)
#   scripts/orbslam2.sh --build-only       builds everything, runs nothing
#   scripts/orbslam2.sh --compile-check    applies the patches to a copy of ORB-SLAM2 and compiles the
#       translation unit the culler patch changes (src/Tracking.cc) with ORB-SLAM2's flags against dyncull's
#       install: no Pangolin build (its headers are configured only), no ORB-SLAM2 build, no run.
# Variants: stock, box_only, culler (boxes from the sequence's detections folder), culler_live (the culler
# with a YOLO detector running beside the tracker, DYNCULL_DETECTOR=--detector), culler_live_sync (the
# same detector waited for on every frame, DYNCULL_DETECTOR_SYNC=1). The live variants track on the colour
# frames (associations_color.txt, from the sequence's rgb_color.txt) when the sequence has them, so that the
# detector sees colour; the others on rgb.txt's images.
# Options:
#   --detector SPEC        the live variants' model: CFG,WEIGHTS (Darknet) or MODEL.onnx
#   --thirdparty DIR       ORB_SLAM2/ and Pangolin/ (default: ../shared/thirdparty beside the checkout)
#   --work DIR             build trees and the vocabulary (default: $XDG_CACHE_HOME or ~/.cache, /dyncull-orbslam2)
#   --dyncull-prefix DIR   an installed dyncull with the culler (default: built and installed under --work)
#   --pangolin-prefix DIR  an installed Pangolin (default: built headless under --work)
#   --vocabulary FILE      ORBvoc.txt (default: ORB_SLAM2/Vocabulary/ORBvoc.txt, else one trained under --work)
#   --install-deps         first installs the Debian packages (scripts/install-deps.sh --orbslam2)
#   --jobs N               parallel compile jobs (default 2)
# The sequence folder has rgb.txt, depth.txt, groundtruth.txt, camera.txt (fx, fy, cx, cy,
# depth_units_per_metre, optional k1 k2 p1 p2 k3) and detections/NNNNNN.json (timestamp = the rgb stamp).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
host=orbslam2
integration="$root/integrations/orb_slam2"
# shellcheck source=scripts/orbslam_common.sh
source "$root/scripts/orbslam_common.sh"
while (($#)); do
  common_option "$@"
  if ((used > 0)); then shift "$used"; continue; fi
  case "$1" in
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d'; exit 0 ;;
    *) die "unknown argument '$1' (see --help)" 2 ;;
  esac
done
common_setup ORB_SLAM2
[[ -z "$install_deps" ]] || "$root/scripts/install-deps.sh" --orbslam2

# --- ORB-SLAM2: a fresh copy with the patches applied (recopied when a patch or the source changes) -----
patches=("$integration/debian12-build.patch" "$integration/dyncull-culler.patch" "$integration/tum-examples-no-viewer.patch")
copy_orbslam2() { copy_tree ORB_SLAM2 "$1" "${patches[@]}"; }

build_orbslam2() {
  local tree="$work/ORB_SLAM2" d
  copy_orbslam2 "$tree"
  for d in Thirdparty/DBoW2 Thirdparty/g2o; do
    log "building $d"
    cmake -S "$tree/$d" -B "$tree/$d/build" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >"$work/$(basename $d)-configure.log" 2>&1
    cmake --build "$tree/$d/build" -j "$jobs" >"$work/$(basename $d)-build.log" 2>&1
  done
  log "building ORB-SLAM2 with the culler patch (about 5 minutes on 2 cores)"
  cmake -S "$tree" -B "$tree/build" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" \
    -DPangolin_DIR="$pangolin_prefix/lib/cmake/Pangolin" -Ddyncull_DIR="$dyncull_prefix/lib/cmake/dyncull" \
    >"$work/orbslam2-configure.log" 2>&1
  cmake --build "$tree/build" --target rgbd_tum mono_tum -j "$jobs" >"$work/orbslam2-build.log" 2>&1 ||
    { tail -30 "$work/orbslam2-build.log" >&2; exit 1; }
  rgbd_tum="$tree/Examples/RGB-D/rgbd_tum"
}

# --- compile check: the culler patch's translation unit, with ORB-SLAM2's flags, against the install ----
compile_check() {
  local start tree="$work/compile-check/ORB_SLAM2"
  start=$(date +%s)
  install_dyncull
  rm -rf "$tree"
  copy_orbslam2 "$tree"
  # g2o's and Pangolin's headers need their generated config headers only: configure them, build neither.
  cmake -S "$tree/Thirdparty/g2o" -B "$work/compile-check/g2o-configure" -DCMAKE_BUILD_TYPE=Release \
    >"$work/compile-check-g2o.log" 2>&1
  pangolin_headers
  local cxx_flags
  cxx_flags=$(pkg-config --cflags opencv4 eigen3)
  # ORB-SLAM2's own flags (its CMakeLists.txt): -Wall -O3 -march=native -std=c++11, Release -DNDEBUG.
  # shellcheck disable=SC2086
  g++ -Wall -O3 -march=native -std=c++11 -DNDEBUG -fPIC -c "$tree/src/Tracking.cc" -o "$work/compile-check/Tracking.o" \
    -I"$tree" -I"$tree/include" "${pangolin_includes[@]}" -I"$dyncull_prefix/include" $cxx_flags \
    2>"$work/compile-check/Tracking.log" || { tail -40 "$work/compile-check/Tracking.log" >&2; exit 1; }
  check_compile "$work/compile-check/Tracking.o" "$work/compile-check/Tracking.log" ORB-SLAM2
  grep -q 'U dyncull::host::HostCuller::cull' < <(nm -C "$work/compile-check/Tracking.o") ||
    die "Tracking.o does not call the culler: the patch did not apply as expected"
  log "compile check passed: patched src/Tracking.cc compiles with -std=c++11 -O3 against $dyncull_prefix ($(($(date +%s) - start)) s)"
}

if [[ "$mode" == compile_check ]]; then
  compile_check
  exit 0
fi

install_dyncull
install_pangolin
build_orbslam2
find_vocabulary "$work/ORB_SLAM2" "$thirdparty/ORB_SLAM2/Vocabulary/ORBvoc.txt"
[[ "$mode" == build ]] && { log "built $rgbd_tum"; exit 0; }

# --- runs (run_sequence in orbslam_common.sh): rgbd_tum on the associations -----------------------------
example=$rgbd_tum example_log=rgbd_tum.log uses_associations=1
summarise_sequence() { sequence_tool summarise "$1" "$2"; }

# A path as the page shows it: under $DYNCULL_DATA_DIR when it is there, not this machine's folders.
data_relative() {
  local data
  data=$(cd "${DYNCULL_DATA_DIR:-$root/../shared/data}" 2>/dev/null && pwd) || { echo "$1"; return; }
  echo "${1//$data/\$DYNCULL_DATA_DIR}"
}

mkdir -p "$out"
out=$(cd "$out" && pwd)
if [[ -n "$sequence" ]]; then
  run_sequence "$sequence" "$out" free
  sequence_tool summarise "$sequence" "$out" --vocabulary "$vocabulary" \
    --command "scripts/orbslam2.sh --sequence \$DYNCULL_DATA_DIR/$(basename "$(dirname "$sequence")")/$(basename "$sequence") --out DIR --runs $runs --variants $variants${detector:+ --detector $(data_relative "$detector")}" \
    ${page:+--page "$page"}
fi
if [[ -n "$families" ]]; then
  run_families
  sequence_tool families "$out" \
    --command "scripts/orbslam2.sh --families $families --motions $motions --frames $frames --out DIR --runs $runs" \
    ${page:+--page "$page"}
fi
