#!/usr/bin/env bash
# Builds ORB-SLAM3 with dyncull's culler and runs it on a TUM-format sequence, RGB-D or monocular, stock
# against the culler (integrations/orb_slam3/). One build serves every variant: the patched Tracking reads
# DYNCULL_MODE at run time (stock: no culling; box_only: every feature in a person box removed; culler:
# the recommended preset).
#
#   scripts/orbslam3.sh --sequence DIR --out DIR [--sensor rgbd|mono] [--runs N] [--variants stock,box_only,culler]
#       [--detector CFG,WEIGHTS|MODEL.onnx]
#       checks the Debian packages, copies ORB-SLAM3, applies the patches, builds (Pangolin headless too unless
#       --pangolin-prefix), trains a vocabulary when ORBvoc.txt is absent, runs rgbd_tum or mono_tum (viewer
#       off) once per variant and run in its own folder, evaluates the ATE with dyncull_eval (monocular: after
#       Sim(3) alignment, --scale) and writes OUT/orbslam3_summary.csv (orbslam2_summary.csv's columns and
#       `sensor`).
#   scripts/orbslam3.sh --families LIST|all --out DIR [--motions xyz,halfsphere] [--frames 300] [--runs N]
#       the same on dyncull's scene families (write_tum_sequence --family, seed 1): one orbslam3_summary.csv
#       per family and motion under OUT/families/, and OUT/orbslam3_families.csv
#   With --page FILE, each writes its section of the page ("In ORB-SLAM3, RGB-D", "In ORB-SLAM3, monocular",
#   "Scene families in ORB-SLAM3"; default page: none).
#   scripts/orbslam3.sh --build-only       builds everything, runs nothing
#   scripts/orbslam3.sh --compile-check    applies the patches to a copy of ORB-SLAM3 and compiles what the
#       culler patch changes with ORB-SLAM3's flags against dyncull's install: src/Atlas.cc whole, and the
#       statements it adds to src/Tracking.cc against ORB-SLAM3's Frame.h (the whole file takes minutes);
#       no Pangolin build (its headers are configured only), no ORB-SLAM3 build, no run.
#   scripts/orbslam3.sh --compile-check-full  the same and the whole patched src/Tracking.cc (-fsyntax-only)
# Variants: stock, box_only, culler (boxes from the sequence's detections folder), culler_live and
# culler_live_sync (a YOLO detector beside the tracker or waited for, --detector), as scripts/orbslam2.sh.
# Options:
#   --sensor rgbd|mono     RGB-D (rgbd_tum on the associations) or monocular (mono_tum on rgb.txt); default rgbd
#   --detector SPEC        the live variants' model: CFG,WEIGHTS (Darknet) or MODEL.onnx
#   --thirdparty DIR       ORB_SLAM3/, ORB_SLAM2/ and Pangolin/ (default: ../shared/thirdparty beside the checkout)
#   --work DIR             build trees and the vocabulary (default: $XDG_CACHE_HOME or ~/.cache, /dyncull-orbslam3)
#   --dyncull-prefix DIR   an installed dyncull with the culler (default: built and installed under --work)
#   --pangolin-prefix DIR  an installed Pangolin (default: built headless under --work)
#   --vocabulary FILE      ORBvoc.txt (default: ORB_SLAM3/Vocabulary/ORBvoc.txt, else one trained under --work
#                          with ORB-SLAM2's extractor and DBoW2, whose text format ORB-SLAM3 loads)
#   --install-deps         first installs the Debian packages (scripts/install-deps.sh --orbslam3)
#   --jobs N               parallel compile jobs (default 2)
# The sequence folder has rgb.txt, depth.txt, groundtruth.txt, camera.txt (fx, fy, cx, cy,
# depth_units_per_metre, optional k1 k2 p1 p2 k3) and detections/NNNNNN.json (timestamp = the rgb stamp).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
host=orbslam3
integration="$root/integrations/orb_slam3"
# shellcheck source=scripts/orbslam_common.sh
source "$root/scripts/orbslam_common.sh"
sensor=rgbd
full_check=""
while (($#)); do
  common_option "$@"
  if ((used > 0)); then shift "$used"; continue; fi
  case "$1" in
    --sensor) (($# >= 2)) || die "--sensor needs a value" 2; sensor=$2; shift 2 ;;
    --compile-check-full) mode=compile_check; full_check=1; shift ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d'; exit 0 ;;
    *) die "unknown argument '$1' (see --help)" 2 ;;
  esac
done
[[ "$sensor" == rgbd || "$sensor" == mono ]] || die "--sensor is rgbd or mono, got '$sensor'" 2
common_setup ORB_SLAM3
[[ -z "$install_deps" ]] || "$root/scripts/install-deps.sh" --orbslam3

# --- Debian packages: named when missing, before anything is built ----------------------------------------
# The compile check needs headers only (Boost's serialization headers come with libboost-dev; GL, GLEW
# and EGL for configuring Pangolin); the build also links Boost serialization and libcrypto.
check_packages() {
  local p missing=() packages=(g++ cmake make pkg-config libeigen3-dev libopencv-dev libboost-dev
    libgl1-mesa-dev libglew-dev libegl-dev)
  [[ "$mode" == compile_check ]] || packages+=(libboost-serialization-dev libssl-dev)
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  ((${#missing[@]} == 0)) ||
    die "missing Debian packages: ${missing[*]} (install them with scripts/install-deps.sh --orbslam3, or pass --install-deps)"
}
if command -v dpkg-query >/dev/null; then check_packages; else log "no dpkg-query: the Debian packages are not checked"; fi

# --- ORB-SLAM3: a fresh copy with the patches applied (recopied when a patch or the source changes) -----
patches=("$integration/debian12-build.patch" "$integration/dyncull-culler.patch" "$integration/tum-examples-no-viewer.patch")
# A tree without the bundled libraries' timing helpers (g2o's stuff/timeutil, DBoW2's DUtils/Timestamp,
# which the build needs) takes them from ORB-SLAM2's tree, where they come from.
fill_missing() {
  local tree=$1 f
  for f in Thirdparty/g2o/g2o/stuff/timeutil.h Thirdparty/g2o/g2o/stuff/timeutil.cpp \
    Thirdparty/DBoW2/DUtils/Timestamp.h Thirdparty/DBoW2/DUtils/Timestamp.cpp; do
    [[ -f "$tree/$f" ]] && continue
    [[ -f "$thirdparty/ORB_SLAM2/$f" ]] || die "ORB_SLAM3 has no $f and ORB_SLAM2 has none to take"
    log "ORB_SLAM3 has no $f: taking ORB-SLAM2's"
    cp "$thirdparty/ORB_SLAM2/$f" "$tree/$f"
  done
}
copy_orbslam3() { copy_tree ORB_SLAM3 "$1" "${patches[@]}"; }

build_orbslam3() {
  local tree="$work/ORB_SLAM3"
  copy_orbslam3 "$tree"
  log "building Thirdparty/DBoW2"
  cmake -S "$tree/Thirdparty/DBoW2" -B "$tree/Thirdparty/DBoW2/build" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" \
    >"$work/DBoW2-configure.log" 2>&1
  cmake --build "$tree/Thirdparty/DBoW2/build" -j "$jobs" >"$work/DBoW2-build.log" 2>&1
  log "building ORB-SLAM3 with the culler patch (g2o first: ORB-SLAM3 links it by path)"
  cmake -S "$tree" -B "$tree/build" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" \
    -DPangolin_DIR="$pangolin_prefix/lib/cmake/Pangolin" -Ddyncull_DIR="$dyncull_prefix/lib/cmake/dyncull" \
    >"$work/orbslam3-configure.log" 2>&1 || { tail -30 "$work/orbslam3-configure.log" >&2; exit 1; }
  { cmake --build "$tree/build" --target g2o -j "$jobs" &&
    cmake --build "$tree/build" --target rgbd_tum mono_tum -j "$jobs"; } >"$work/orbslam3-build.log" 2>&1 ||
    { tail -30 "$work/orbslam3-build.log" >&2; exit 1; }
  rgbd_tum="$tree/Examples/RGB-D/rgbd_tum"
  mono_tum="$tree/Examples/Monocular/mono_tum"
}

# The vocabulary trainer uses ORB-SLAM2's extractor and DBoW2: its tree with the build patch, DBoW2 built.
vocabulary_tree() {
  local tree="$work/ORB_SLAM2-vocabulary"
  copy_tree ORB_SLAM2 "$tree" "$root/integrations/orb_slam2/debian12-build.patch"
  if [[ ! -f "$tree/Thirdparty/DBoW2/lib/libDBoW2.so" ]]; then
    cmake -S "$tree/Thirdparty/DBoW2" -B "$tree/Thirdparty/DBoW2/build" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" \
      >"$work/DBoW2-vocabulary-configure.log" 2>&1
    cmake --build "$tree/Thirdparty/DBoW2/build" -j "$jobs" >"$work/DBoW2-vocabulary-build.log" 2>&1
  fi
  echo "$tree"
}

# --- compile check: the culler patch's translation units, with ORB-SLAM3's flags, against the install ---
# ORB-SLAM3's flags (its CMakeLists.txt): -Wall -O3 -std=c++11 -DCOMPILEDWITHC11, Release -O3 -DNDEBUG
# -march=native. src/Atlas.cc is compiled whole. src/Tracking.cc takes minutes to compile (its headers
# are most of ORB-SLAM3, g2o, Eigen and Boost serialization), so the check compiles what the patch adds
# to it instead: the patched statements, cut from the patched file as they are, in a unit that includes
# ORB-SLAM3's own Frame.h (Sophus, DBoW2, the Frame the helper culls) and declares the Tracking members
# they use with Tracking.h's types (each declaration is checked to be in Tracking.h). --compile-check-full
# also checks the whole patched Tracking.cc with -fsyntax-only.
compile_check() {
  local start tree="$work/compile-check/ORB_SLAM3" cxx_flags flags includes unit="$work/compile-check/tracking_patch.cc"
  local declaration statements
  start=$(date +%s)
  install_dyncull
  rm -rf "$tree"
  copy_orbslam3 "$tree"
  # g2o writes its config.h into its source folder when configured; Pangolin's headers need theirs.
  cmake -S "$tree/Thirdparty/g2o" -B "$work/compile-check/g2o3-configure" -DCMAKE_BUILD_TYPE=Release \
    >"$work/compile-check-g2o3.log" 2>&1 || { tail -20 "$work/compile-check-g2o3.log" >&2; die "g2o could not be configured"; }
  pangolin_headers
  cxx_flags=$(pkg-config --cflags opencv4 eigen3)
  flags=(-Wall -O3 -std=c++11 -DCOMPILEDWITHC11 -O3 -DNDEBUG -march=native -fPIC)
  # shellcheck disable=SC2206
  includes=(-I"$tree" -I"$tree/include" -I"$tree/include/CameraModels" -I"$tree/Thirdparty/Sophus"
    "${pangolin_includes[@]}" -I"$dyncull_prefix/include" $cxx_flags)
  g++ "${flags[@]}" -c "$tree/src/Atlas.cc" -o "$work/compile-check/Atlas.o" "${includes[@]}" \
    2>"$work/compile-check/Atlas.log" || { tail -40 "$work/compile-check/Atlas.log" >&2; exit 1; }
  check_compile "$work/compile-check/Atlas.o" "$work/compile-check/Atlas.log" ORB-SLAM3
  grep -q 'U dyncull::host::HostCuller::reset' < <(nm -C "$work/compile-check/Atlas.o") ||
    die "Atlas.o does not reset the culler: the patch did not apply as expected"

  for declaration in 'eTrackingState mState;' 'Frame mCurrentFrame;' 'Frame mLastFrame;' 'cv::Mat mK;' \
    'cv::Mat mDistCoef;' 'bool mbVelocity' 'Sophus::SE3f mVelocity;' 'OK=2,'; do
    grep -qF "$declaration" "$tree/include/Tracking.h" ||
      die "include/Tracking.h declares no '$declaration': the check's stand-in for Tracking no longer matches"
  done
  # Each patched statement: from its cull_orb_slam_frame( line to the line that ends it with ");".
  statements=$(awk '/dyncull::host::cull_orb_slam_frame\(/ { on = 1 } on { print } on && /\);[[:space:]]*$/ { on = 0 }' \
    "$tree/src/Tracking.cc")
  [[ $(grep -c 'cull_orb_slam_frame(' <<<"$statements") == 3 ]] ||
    die "src/Tracking.cc does not cull in GrabImageStereo, GrabImageRGBD and GrabImageMonocular: the patch did not apply as expected"
  {
    echo '// The statements dyncull-culler.patch adds to src/Tracking.cc, as patched, with the members they use.'
    echo '#include "Frame.h"'
    echo '#include <dyncull/host/host_culler.hpp>'
    echo 'namespace ORB_SLAM3 {'
    echo 'struct PatchedTracking {'
    echo '  enum eTrackingState { SYSTEM_NOT_READY = -1, NO_IMAGES_YET = 0, NOT_INITIALIZED = 1, OK = 2 };'
    echo '  eTrackingState mState;'
    echo '  Frame mCurrentFrame, mLastFrame;'
    echo '  cv::Mat mK, mDistCoef;'
    echo '  bool mbVelocity;'
    echo '  Sophus::SE3f mVelocity;'
    echo '  void grab(const cv::Mat& imRectLeft, const cv::Mat& imRGB, const cv::Mat& imDepth, const cv::Mat& im) {'
    echo "$statements"
    echo '  }'
    echo '};'
    echo 'void grab(PatchedTracking& t, const cv::Mat& image) { t.grab(image, image, image, image); }'
    echo '}  // namespace ORB_SLAM3'
  } >"$unit"
  g++ "${flags[@]}" -c "$unit" -o "$work/compile-check/tracking_patch.o" "${includes[@]}" \
    2>"$work/compile-check/tracking_patch.log" || { tail -40 "$work/compile-check/tracking_patch.log" >&2; exit 1; }
  check_compile "$work/compile-check/tracking_patch.o" "$work/compile-check/tracking_patch.log" ORB-SLAM3
  grep -q 'U dyncull::host::HostCuller::cull' < <(nm -C "$work/compile-check/tracking_patch.o") ||
    die "the patched statements do not call the culler"
  if [[ -n "$full_check" ]]; then
    log "checking the whole patched src/Tracking.cc with -fsyntax-only (minutes)"
    g++ "${flags[@]}" -fsyntax-only "$tree/src/Tracking.cc" "${includes[@]}" \
      2>"$work/compile-check/Tracking.log" || { tail -40 "$work/compile-check/Tracking.log" >&2; exit 1; }
    if grep -n 'include/dyncull/' "$work/compile-check/Tracking.log" >&2; then
      die "the lines above are warnings in dyncull's headers under ORB-SLAM3's flags"
    fi
  fi
  log "compile check passed: patched src/Atlas.cc and src/Tracking.cc's patched statements${full_check:+ (and the whole file, -fsyntax-only)} compile with -std=c++11 -O3 against $dyncull_prefix ($(($(date +%s) - start)) s)"
}

if [[ "$mode" == compile_check ]]; then
  compile_check
  exit 0
fi

install_dyncull
install_pangolin
build_orbslam3
find_vocabulary "$(vocabulary_tree)" "$thirdparty/ORB_SLAM3/Vocabulary/ORBvoc.txt"
[[ "$mode" == build ]] && { log "built $rgbd_tum and $mono_tum"; exit 0; }

# --- runs (run_sequence in orbslam_common.sh): the example of the sensor -----------------------------------
if [[ "$sensor" == rgbd ]]; then
  example=$rgbd_tum example_log=rgbd_tum.log uses_associations=1
else
  example=$mono_tum example_log=mono_tum.log eval_options=(--scale)
  # mono_tum writes every tracked frame of the largest map (EuRoC: nanoseconds); the ATE reads TUM.
  after_run() {
    [[ ! -f "$1/CameraTrajectory_EuRoC.txt" ]] ||
      awk '!/^#/ && NF == 8 { printf "%.6f %s %s %s %s %s %s %s\n", $1 / 1e9, $2, $3, $4, $5, $6, $7, $8 }' \
        "$1/CameraTrajectory_EuRoC.txt" >"$1/CameraTrajectory.txt"
  }
fi
summarise_sequence() {
  sequence_tool summarise "$1" "$2" --host orbslam3 --sensor "$sensor" "${@:3}"
}

mkdir -p "$out"
out=$(cd "$out" && pwd)
if [[ -n "$sequence" ]]; then
  run_sequence "$sequence" "$out"
  summarise_sequence "$sequence" "$out" --vocabulary "$vocabulary" \
    --command "scripts/orbslam3.sh --sequence \$DYNCULL_DATA_DIR/$(basename "$(dirname "$sequence")")/$(basename "$sequence") --sensor $sensor --out DIR --runs $runs --variants $variants" \
    ${page:+--page "$page"}
fi
if [[ -n "$families" ]]; then
  [[ "$sensor" == rgbd ]] || log "the scene families run with --sensor $sensor"
  run_families
  sequence_tool families "$out" --host orbslam3 \
    --command "scripts/orbslam3.sh --families $families --motions $motions --frames $frames --out DIR --runs $runs" \
    ${page:+--page "$page"}
fi
