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
#       folder, evaluates the ATE with dyncull_eval and writes OUT/orbslam2_summary.csv; with --page, writes
#       the page's "In ORB-SLAM2" section (default page: none).
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
integration="$root/integrations/orb_slam2"
thirdparty="$root/../shared/thirdparty"
work="${XDG_CACHE_HOME:-$HOME/.cache}/dyncull-orbslam2"
dyncull_prefix=""
pangolin_prefix=""
vocabulary=""
sequence=""
out=""
runs=5
variants="stock,box_only,culler"
families=""
motions="xyz,halfsphere"
frames=300
page=""
jobs=2
mode=run
install_deps=""
detector=""
while (($#)); do
  case "$1" in
    --thirdparty) thirdparty=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    --dyncull-prefix) dyncull_prefix=$2; shift 2 ;;
    --pangolin-prefix) pangolin_prefix=$2; shift 2 ;;
    --vocabulary) vocabulary=$2; shift 2 ;;
    --sequence) sequence=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --variants) variants=$2; shift 2 ;;
    --families) families=$2; shift 2 ;;
    --motions) motions=$2; shift 2 ;;
    --frames) frames=$2; shift 2 ;;
    --page) page=$2; shift 2 ;;
    --detector) detector=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --build-only) mode=build; shift ;;
    --compile-check) mode=compile_check; shift ;;
    --install-deps) install_deps=1; shift ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d'; exit 0 ;;
    *) echo "orbslam2.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ -d "$thirdparty/ORB_SLAM2" ]] || { echo "orbslam2.sh: no ORB_SLAM2 in $thirdparty (--thirdparty DIR)" >&2; exit 1; }
thirdparty=$(cd "$thirdparty" && pwd)
mkdir -p "$work"
work=$(cd "$work" && pwd)
absolute() { [[ -z "$1" ]] || (cd "$1" && pwd) || { echo "orbslam2.sh: no folder $1" >&2; exit 1; }; }
dyncull_prefix=$(absolute "$dyncull_prefix")
if [[ -n "$detector" ]]; then  # the runs start in their own folders: the model's paths made absolute
  IFS=',' read -r -a detector_files <<<"$detector"
  for i in "${!detector_files[@]}"; do
    [[ "${detector_files[i]}" == /* ]] || detector_files[i]="$PWD/${detector_files[i]}"
  done
  detector=$(IFS=','; echo "${detector_files[*]}")
fi
pangolin_prefix=$(absolute "$pangolin_prefix")
if [[ "$mode" == run ]]; then
  [[ (-n "$sequence" || -n "$families") && -n "$out" ]] ||
    { echo "orbslam2.sh: --sequence DIR or --families LIST, and --out DIR, are needed (or --build-only, --compile-check)" >&2; exit 2; }
  [[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "orbslam2.sh: --runs needs a positive integer, got '$runs'" >&2; exit 2; }
  [[ "$frames" =~ ^[1-9][0-9]*$ ]] || { echo "orbslam2.sh: --frames needs a positive integer, got '$frames'" >&2; exit 2; }
  if [[ -n "$sequence" ]]; then
    [[ -f "$sequence/rgb.txt" && -f "$sequence/camera.txt" ]] || { echo "orbslam2.sh: $sequence has no rgb.txt or camera.txt" >&2; exit 1; }
    sequence=$(cd "$sequence" && pwd)
  fi
fi
[[ -z "$install_deps" ]] || "$root/scripts/install-deps.sh" --orbslam2
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(dirname "$root")}"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
log() { echo "orbslam2.sh: $*" >&2; }

# --- dyncull: the culler and host libraries and dyncull_eval, installed into a prefix ORB-SLAM2's CMake finds ---------
install_dyncull() {
  if [[ -n "$dyncull_prefix" ]]; then return; fi
  dyncull_prefix="$work/dyncull-install"
  local build="$work/dyncull-build"
  log "building dyncull's culler, its host harness and dyncull_eval in $build"
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" -DDYNCULL_BUILD_TESTS=OFF \
    -DDYNCULL_BUILD_BENCHMARKS=OFF -DDYNCULL_BUILD_DOCS=OFF -DDYNCULL_BUILD_EXAMPLES=OFF -DDYNCULL_BUILD_APPS=ON -DDYNCULL_INSTALL=ON \
    -DCMAKE_INSTALL_PREFIX="$dyncull_prefix" >"$work/dyncull-configure.log"
  cmake --build "$build" --target dyncull_culler dyncull_host dyncull_pipeline dyncull_eval -j "$jobs" >"$work/dyncull-build.log"
  cmake --install "$build" >"$work/dyncull-install.log"
}

# dyncull's tools (apps/: write_tum_sequence), built in the same build tree as the install.
build_dyncull_tool() {
  local build="$work/dyncull-build"
  [[ -f "$build/CMakeCache.txt" ]] ||
    cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" -DDYNCULL_BUILD_TESTS=OFF \
      -DDYNCULL_BUILD_BENCHMARKS=OFF -DDYNCULL_BUILD_DOCS=OFF -DDYNCULL_BUILD_EXAMPLES=OFF -DDYNCULL_BUILD_APPS=ON >"$work/dyncull-configure.log"
  cmake --build "$build" --target "$1" -j "$jobs" >"$work/$1-build.log"
}

# --- Pangolin (ORB-SLAM2 links it; the viewer stays off): headless, examples and tools off ---------------
install_pangolin() {
  if [[ -n "$pangolin_prefix" ]]; then return; fi
  pangolin_prefix="$work/pangolin-install"
  [[ -f "$pangolin_prefix/lib/cmake/Pangolin/PangolinConfig.cmake" ]] && return
  log "building Pangolin (about 7 minutes on 2 cores)"
  cmake -S "$thirdparty/Pangolin" -B "$work/pangolin-build" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" \
    -DBUILD_EXAMPLES=OFF -DBUILD_TOOLS=OFF -DBUILD_PANGOLIN_PYTHON=OFF \
    -DCMAKE_INSTALL_PREFIX="$pangolin_prefix" >"$work/pangolin-configure.log"
  cmake --build "$work/pangolin-build" -j "$jobs" >"$work/pangolin-build.log" 2>&1
  cmake --install "$work/pangolin-build" >"$work/pangolin-install.log"
}

# --- ORB-SLAM2: a fresh copy with the patches applied (recopied when a patch or the source changes) -----
patches=("$integration/debian12-build.patch" "$integration/dyncull-culler.patch" "$integration/tum-examples-no-viewer.patch")
copy_orbslam2() {
  local tree=$1 stamp
  stamp=$(cat "${patches[@]}" | sha256sum | cut -c1-16)-$(cd "$thirdparty/ORB_SLAM2" && git rev-parse --short HEAD 2>/dev/null || echo tree)
  if [[ -f "$tree/.dyncull-patches" && "$(cat "$tree/.dyncull-patches")" == "$stamp" ]]; then return; fi
  log "copying ORB-SLAM2 to $tree and applying ${#patches[@]} patches"
  rm -rf "$tree"
  mkdir -p "$(dirname "$tree")"
  cp -a "$thirdparty/ORB_SLAM2" "$tree"
  rm -rf "$tree/.git"
  local p
  for p in "${patches[@]}"; do
    patch -d "$tree" -p1 --forward --quiet <"$p" || { echo "orbslam2.sh: $p does not apply to $thirdparty/ORB_SLAM2" >&2; exit 1; }
  done
  echo "$stamp" >"$tree/.dyncull-patches"
}

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

# --- vocabulary: the published one when present, else trained on frames no evaluation uses --------------
# The training frames are synthetic: dyncull's scene (write_tum_sequence), four camera motions, 120 frames
# each. ORB-SLAM2's own extractor (1000 features, 1.2, 8 levels) and bundled DBoW2 (k = 10, L = 5).
find_vocabulary() {
  if [[ -n "$vocabulary" ]]; then return; fi
  local published="$thirdparty/ORB_SLAM2/Vocabulary/ORBvoc.txt"
  if [[ -f "$published" ]]; then vocabulary=$published; return; fi
  vocabulary="$work/vocabulary/ORBvoc_synthetic_k10_L5.txt"
  if [[ -f "$vocabulary" ]]; then
    log "ORBvoc.txt is absent: using the vocabulary trained on synthetic frames, $vocabulary"
    return
  fi
  log "ORBvoc.txt is absent: training a vocabulary on synthetic frames (not on any evaluated sequence)"
  local vdir="$work/vocabulary" build="$work/dyncull-build" tree="$work/ORB_SLAM2" motion lists=()
  mkdir -p "$vdir"
  build_dyncull_tool write_tum_sequence
  for motion in xyz rpy halfsphere static; do
    "$build/apps/write_tum_sequence" "$vdir/frames_$motion" --motion "$motion" --frames 120 --seed 11 >/dev/null
    lists+=("$vdir/frames_$motion/rgb.txt")
  done
  local cxxflags
  cxxflags=$(pkg-config --cflags opencv4)
  # shellcheck disable=SC2086
  g++ -std=c++11 -O3 -march=native -o "$vdir/train_vocabulary" "$integration/train_vocabulary.cc" \
    "$tree/src/ORBextractor.cc" -I"$tree" -I"$tree/include" $cxxflags \
    -L"$tree/Thirdparty/DBoW2/lib" -Wl,-rpath,"$tree/Thirdparty/DBoW2/lib" -lDBoW2 \
    -lopencv_core -lopencv_imgproc -lopencv_imgcodecs -lopencv_features2d
  "$vdir/train_vocabulary" "$vocabulary.partial" 10 5 "${lists[@]}" | tee "$vdir/train.log" >&2
  mv "$vocabulary.partial" "$vocabulary"
}

# --- compile check: the culler patch's translation unit, with ORB-SLAM2's flags, against the install ----
compile_check() {
  local start tree="$work/compile-check/ORB_SLAM2" pangolin_cfg="$work/compile-check/pangolin-headers"
  start=$(date +%s)
  install_dyncull
  rm -rf "$tree"
  copy_orbslam2 "$tree"
  # g2o's and Pangolin's headers need their generated config headers only: configure them, build neither.
  cmake -S "$tree/Thirdparty/g2o" -B "$work/compile-check/g2o-configure" -DCMAKE_BUILD_TYPE=Release \
    >"$work/compile-check-g2o.log" 2>&1
  if [[ -n "$pangolin_prefix" ]]; then
    pangolin_includes=(-I"$pangolin_prefix/include")
  else
    cmake -S "$thirdparty/Pangolin" -B "$pangolin_cfg" -DBUILD_EXAMPLES=OFF -DBUILD_TOOLS=OFF \
      -DBUILD_PANGOLIN_PYTHON=OFF >"$work/compile-check-pangolin.log" 2>&1
    pangolin_includes=(-I"$thirdparty/Pangolin/include" -I"$pangolin_cfg/src/include")
  fi
  local cxx_flags
  cxx_flags=$(pkg-config --cflags opencv4 eigen3)
  # ORB-SLAM2's own flags (its CMakeLists.txt): -Wall -O3 -march=native -std=c++11, Release -DNDEBUG.
  # shellcheck disable=SC2086
  g++ -Wall -O3 -march=native -std=c++11 -DNDEBUG -fPIC -c "$tree/src/Tracking.cc" -o "$work/compile-check/Tracking.o" \
    -I"$tree" -I"$tree/include" "${pangolin_includes[@]}" -I"$dyncull_prefix/include" $cxx_flags \
    2>"$work/compile-check/Tracking.log" || { tail -40 "$work/compile-check/Tracking.log" >&2; exit 1; }
  if grep -n 'include/dyncull/' "$work/compile-check/Tracking.log" >&2; then
    echo "orbslam2.sh: the lines above are warnings in dyncull's headers under ORB-SLAM2's flags" >&2
    exit 1
  fi
  local symbols
  symbols=$(nm -C "$work/compile-check/Tracking.o")
  grep -q 'U dyncull::host::HostCuller::cull' <<<"$symbols" ||
    { echo "orbslam2.sh: Tracking.o does not call the culler: the patch did not apply as expected" >&2; exit 1; }
  log "compile check passed: patched src/Tracking.cc compiles with -std=c++11 -O3 against $dyncull_prefix ($(($(date +%s) - start)) s)"
}

if [[ "$mode" == compile_check ]]; then
  compile_check
  exit 0
fi

install_dyncull
install_pangolin
build_orbslam2
find_vocabulary
[[ "$mode" == build ]] && { log "built $rgbd_tum"; exit 0; }

# --- one sequence: settings, associations, runs, evaluation ---------------------------------------------
# The boxes: detections/ of JSON files (the real sequences), else detections_json/ (write_tum_sequence).
detections_of() {
  if compgen -G "$1/detections/*.json" >/dev/null; then echo "$1/detections"; else echo "$1/detections_json"; fi
}

# The DYNCULL_* settings of a variant (one per line, for env), given the detections folder.
variant_environment() {
  local variant=$1 detections=$2
  case "$variant" in
    stock|box_only|culler) printf 'DYNCULL_MODE=%s\nDYNCULL_DETECTIONS=%s\n' "$variant" "$detections" ;;
    culler_live) printf 'DYNCULL_MODE=culler\nDYNCULL_DETECTOR=%s\n' "$detector" ;;
    culler_live_sync) printf 'DYNCULL_MODE=culler\nDYNCULL_DETECTOR=%s\nDYNCULL_DETECTOR_SYNC=1\n' "$detector" ;;
  esac
}

run_sequence() {
  local seq=$1 dest=$2 variant run dir detections associations settings=()
  mkdir -p "$dest"
  python3 "$root/scripts/orbslam2_sequence.py" prepare "$seq" "$dest" --dyncull-eval "$dyncull_prefix/bin/dyncull_eval"
  detections=$(detections_of "$seq")
  for variant in "${variant_list[@]}"; do
    associations="$dest/associations.txt"
    if [[ "$variant" == culler_live* && -f "$dest/associations_color.txt" ]]; then
      associations="$dest/associations_color.txt"
    fi
    mapfile -t settings < <(variant_environment "$variant" "$detections")
    for ((run = 1; run <= runs; run++)); do
      dir="$dest/runs/$variant/run$run"
      rm -rf "$dir"
      mkdir -p "$dir"
      log "$(basename "$seq"): $variant run $run of $runs ($(basename "$associations"))"
      (cd "$dir" && env "${settings[@]}" DYNCULL_LOG="$dir/culler_frames.csv" \
        "$rgbd_tum" "$vocabulary" "$dest/orbslam2_settings.yaml" "$seq" "$associations" \
        >"$dir/rgbd_tum.log" 2>&1) || log "$variant run $run: rgbd_tum exited with status $? (see $dir/rgbd_tum.log)"
      "$dyncull_prefix/bin/dyncull_eval" "$seq/groundtruth.txt" "$dir/CameraTrajectory.txt" --json \
        --poses-csv "$dir/poses.csv" \
        >"$dir/ate.json" 2>"$dir/ate.err" || true
    done
  done
}

# A family's sequence, written once into --work by write_tum_sequence (seed 1).
family_sequence() {
  local family=$1 motion=$2 seq="$work/families/${1}_${2}_seed1_${frames}f"
  if [[ ! -f "$seq/.complete" ]]; then
    build_dyncull_tool write_tum_sequence
    rm -rf "$seq"
    "$work/dyncull-build/apps/write_tum_sequence" "$seq" --family "$family" --motion "$motion" --frames "$frames" \
      --seed 1 >/dev/null
    touch "$seq/.complete"
  fi
  echo "$seq"
}

mkdir -p "$out"
out=$(cd "$out" && pwd)
IFS=',' read -r -a variant_list <<<"$variants"
for variant in "${variant_list[@]}"; do
  case "$variant" in
    stock|box_only|culler) ;;
    culler_live|culler_live_sync)
      [[ -n "$detector" ]] || { echo "orbslam2.sh: variant '$variant' needs --detector CFG,WEIGHTS or MODEL.onnx" >&2; exit 2; } ;;
    *) echo "orbslam2.sh: unknown variant '$variant' (stock, box_only, culler, culler_live, culler_live_sync)" >&2; exit 2 ;;
  esac
done
if [[ -n "$sequence" ]]; then
  run_sequence "$sequence" "$out"
  python3 "$root/scripts/orbslam2_sequence.py" summarise "$sequence" "$out" --vocabulary "$vocabulary" \
    --command "scripts/orbslam2.sh --sequence \$DYNCULL_DATA_DIR/$(basename "$(dirname "$sequence")")/$(basename "$sequence") --out DIR --runs $runs" \
    ${page:+--page "$page"}
fi
if [[ -n "$families" ]]; then
  [[ "$families" != all ]] || families=walking,sitting,crowd,far_walker,brisk,low_texture,noisy_detector
  IFS=',' read -r -a family_list <<<"$families"
  IFS=',' read -r -a motion_list <<<"$motions"
  for family in "${family_list[@]}"; do
    for motion in "${motion_list[@]}"; do
      seq=$(family_sequence "$family" "$motion")
      run_sequence "$seq" "$out/families/${family}_${motion}"
      python3 "$root/scripts/orbslam2_sequence.py" summarise "$seq" "$out/families/${family}_${motion}" >/dev/null
    done
  done
  python3 "$root/scripts/orbslam2_sequence.py" families "$out" \
    --command "scripts/orbslam2.sh --families $families --motions $motions --frames $frames --out DIR --runs $runs" \
    ${page:+--page "$page"}
fi
