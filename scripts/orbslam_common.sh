# What scripts/orbslam2.sh and scripts/orbslam3.sh share; sourced by both, not run on its own.
# Before sourcing, the script sets `host` (orbslam2 or orbslam3), `root` (the checkout) and `integration`
# (its integrations/ folder). The options both scripts take are parsed by common_option; the functions
# build and install dyncull and Pangolin, copy a host tree with patches applied, train or find a
# vocabulary, configure the headers a compile check needs, and run the variants on sequences.
# shellcheck shell=bash disable=SC2034,SC2154  # sets the options the sourcing script reads; reads its host and root

thirdparty="$root/../shared/thirdparty"
work="${XDG_CACHE_HOME:-$HOME/.cache}/dyncull-$host"
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

log() { echo "$host.sh: $*" >&2; }
die() { echo "$host.sh: $1" >&2; exit "${2:-1}"; }

# Parses one option both scripts take: sets `used` to how many arguments it takes (0: not a shared one)
# and its variable.
common_option() {
  used=0
  case "$1" in
    --thirdparty|--work|--dyncull-prefix|--pangolin-prefix|--vocabulary|--sequence|--out|--runs|--variants|\
    --families|--motions|--frames|--page|--detector|--jobs)
      (($# >= 2)) || die "$1 needs a value" 2
      used=2 ;;
    --build-only|--compile-check|--install-deps) used=1 ;;
    *) return 0 ;;
  esac
  common_set "$@"
}
# Sets the variable of a shared option (called after common_option said it is one).
common_set() {
  case "$1" in
    --thirdparty) thirdparty=$2 ;;
    --work) work=$2 ;;
    --dyncull-prefix) dyncull_prefix=$2 ;;
    --pangolin-prefix) pangolin_prefix=$2 ;;
    --vocabulary) vocabulary=$2 ;;
    --sequence) sequence=$2 ;;
    --out) out=$2 ;;
    --runs) runs=$2 ;;
    --variants) variants=$2 ;;
    --families) families=$2 ;;
    --motions) motions=$2 ;;
    --frames) frames=$2 ;;
    --page) page=$2 ;;
    --detector) detector=$2 ;;
    --jobs) jobs=$2 ;;
    --build-only) mode=build ;;
    --compile-check) mode=compile_check ;;
    --install-deps) install_deps=1 ;;
  esac
}

absolute() { [[ -z "$1" ]] || (cd "$1" && pwd) || die "no folder $1"; }

# After parsing: folders made absolute, the run options checked, the detector's paths made absolute.
common_setup() {
  local tree=$1 i
  [[ -d "$thirdparty/$tree" ]] || die "no $tree in $thirdparty (--thirdparty DIR)"
  thirdparty=$(cd "$thirdparty" && pwd)
  mkdir -p "$work"
  work=$(cd "$work" && pwd)
  dyncull_prefix=$(absolute "$dyncull_prefix")
  pangolin_prefix=$(absolute "$pangolin_prefix")
  if [[ -n "$detector" ]]; then  # the runs start in their own folders: the model's paths made absolute
    IFS=',' read -r -a detector_files <<<"$detector"
    for i in "${!detector_files[@]}"; do
      [[ "${detector_files[i]}" == /* ]] || detector_files[i]="$PWD/${detector_files[i]}"
    done
    detector=$(IFS=','; echo "${detector_files[*]}")
  fi
  if [[ "$mode" == run ]]; then
    [[ (-n "$sequence" || -n "$families") && -n "$out" ]] ||
      die "--sequence DIR or --families LIST, and --out DIR, are needed (or --build-only, --compile-check)" 2
    [[ "$runs" =~ ^[1-9][0-9]*$ ]] || die "--runs needs a positive integer, got '$runs'" 2
    [[ "$frames" =~ ^[1-9][0-9]*$ ]] || die "--frames needs a positive integer, got '$frames'" 2
    if [[ -n "$sequence" ]]; then
      [[ -f "$sequence/rgb.txt" && -f "$sequence/camera.txt" ]] || die "$sequence has no rgb.txt or camera.txt"
      sequence=$(cd "$sequence" && pwd)
    fi
    IFS=',' read -r -a variant_list <<<"$variants"
    local variant
    for variant in "${variant_list[@]}"; do
      case "$variant" in
        stock|box_only|culler) ;;
        culler_live|culler_live_sync)
          [[ -n "$detector" ]] || die "variant '$variant' needs --detector CFG,WEIGHTS or MODEL.onnx" 2 ;;
        *) die "unknown variant '$variant' (stock, box_only, culler, culler_live, culler_live_sync)" 2 ;;
      esac
    done
  fi
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(dirname "$root")}"
  launcher=()
  if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache); fi
}

# --- dyncull: the culler and host libraries and dyncull_eval, installed into a prefix the host's CMake finds ------
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

# --- Pangolin (the host links it; the viewer stays off): headless, examples and tools off ---------------
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

# Pangolin's include flags for a compile check: the installed prefix, or its headers with the generated
# config headers (configured, not built). Sets pangolin_includes.
pangolin_headers() {
  local cfg="$work/compile-check/pangolin-headers"
  if [[ -n "$pangolin_prefix" ]]; then
    pangolin_includes=(-I"$pangolin_prefix/include")
  else
    cmake -S "$thirdparty/Pangolin" -B "$cfg" -DBUILD_EXAMPLES=OFF -DBUILD_TOOLS=OFF \
      -DBUILD_PANGOLIN_PYTHON=OFF >"$work/compile-check-pangolin.log" 2>&1 ||
      { tail -20 "$work/compile-check-pangolin.log" >&2; die "Pangolin's headers could not be configured"; }
    pangolin_includes=(-I"$thirdparty/Pangolin/include" -I"$cfg/src/include")
  fi
}

# --- a host tree: a fresh copy of $thirdparty/SOURCE with the patches applied (recopied when a patch or
# the source changes). copy_tree SOURCE TREE PATCH... ; fill_missing SOURCE TREE runs before the patches
# when the calling script defines it.
copy_tree() {
  local source=$1 tree=$2 stamp p
  shift 2
  stamp=$(cat "$@" | sha256sum | cut -c1-16)-$(cd "$thirdparty/$source" && git rev-parse --short HEAD 2>/dev/null || echo tree)
  if [[ -f "$tree/.dyncull-patches" && "$(cat "$tree/.dyncull-patches")" == "$stamp" ]]; then return; fi
  log "copying $source to $tree and applying $# patches"
  rm -rf "$tree"
  mkdir -p "$(dirname "$tree")"
  cp -a "$thirdparty/$source" "$tree"
  chmod -R u+w "$tree"
  rm -rf "$tree/.git"
  if declare -F fill_missing >/dev/null; then fill_missing "$tree"; fi
  for p in "$@"; do
    patch -d "$tree" -p1 --forward --quiet <"$p" || die "$p does not apply to $thirdparty/$source"
  done
  echo "$stamp" >"$tree/.dyncull-patches"
}

# Fails when a compile check's log holds warnings from dyncull's headers, or the object calls no culler.
check_compile() {
  local object=$1 log_file=$2 what=$3 symbols
  if grep -n 'include/dyncull/' "$log_file" >&2; then
    die "the lines above are warnings in dyncull's headers under $what's flags"
  fi
  symbols=$(nm -C "$object")
  grep -q 'U dyncull::host::' <<<"$symbols" ||
    die "$(basename "$object") does not call the host harness: the patch did not apply as expected"
}

# --- vocabulary: the published one when present, else trained on frames no evaluation uses --------------
# The training frames are synthetic: dyncull's scene (write_tum_sequence), four camera motions, 120 frames
# each. ORB-SLAM2's own extractor (1000 features, 1.2, 8 levels) and bundled DBoW2 (k = 10, L = 5), from
# ORB-SLAM2's tree at $1 (its DBoW2 built): ORB-SLAM3 loads the same DBoW2 text format.
# find_vocabulary ORB_SLAM2_TREE PUBLISHED_ORBVOC
find_vocabulary() {
  local tree=$1 published=$2
  if [[ -n "$vocabulary" ]]; then return; fi
  if [[ -f "$published" ]]; then vocabulary=$published; return; fi
  vocabulary="$work/vocabulary/ORBvoc_synthetic_k10_L5.txt"
  if [[ -f "$vocabulary" ]]; then
    log "ORBvoc.txt is absent: using the vocabulary trained on synthetic frames, $vocabulary"
    return
  fi
  log "ORBvoc.txt is absent: training a vocabulary on synthetic frames (not on any evaluated sequence)"
  local vdir="$work/vocabulary" build="$work/dyncull-build" motion lists=()
  mkdir -p "$vdir"
  build_dyncull_tool write_tum_sequence
  for motion in xyz rpy halfsphere static; do
    "$build/apps/write_tum_sequence" "$vdir/frames_$motion" --motion "$motion" --frames 120 --seed 11 >/dev/null
    lists+=("$vdir/frames_$motion/rgb.txt")
  done
  local cxxflags
  cxxflags=$(pkg-config --cflags opencv4)
  # shellcheck disable=SC2086
  g++ -std=c++11 -O3 -march=native -o "$vdir/train_vocabulary" "$root/integrations/orb_slam2/train_vocabulary.cc" \
    "$tree/src/ORBextractor.cc" -I"$tree" -I"$tree/include" $cxxflags \
    -L"$tree/Thirdparty/DBoW2/lib" -Wl,-rpath,"$tree/Thirdparty/DBoW2/lib" -lDBoW2 \
    -lopencv_core -lopencv_imgproc -lopencv_imgcodecs -lopencv_features2d
  "$vdir/train_vocabulary" "$vocabulary.partial" 10 5 "${lists[@]}" | tee "$vdir/train.log" >&2
  mv "$vocabulary.partial" "$vocabulary"
}

# --- sequences -------------------------------------------------------------------------------------------
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

# orbslam2_sequence.py with the Python that has matplotlib (for the page's trajectory figure): Debian's,
# which scripts/install-deps.sh serves, before another python3 first on the PATH (as scripts/figures.sh).
sequence_tool() {
  local python
  for python in /usr/bin/python3 python3; do
    if "$python" -c 'import matplotlib' 2>/dev/null; then break; fi
  done
  "$python" "$root/scripts/orbslam2_sequence.py" "$@"
}

# --- runs: the host script sets example (the TUM example's path), example_log (its log's name), and for
# RGB-D runs uses_associations=1; optional: eval_options (dyncull_eval's, e.g. --scale) and after_run DIR
# (turns the example's trajectory into DIR/CameraTrajectory.txt when it writes another format).
# run_once VARIANT RUN_NAME [SETTING...]: the example once in DEST/runs/VARIANT/RUN_NAME (run_sequence's
# seq, dest, associations and settings), then its ATE.
eval_options=()
run_once() {
  local variant=$1 name=$2 dir="$dest/runs/$1/$2" lists=()
  shift 2
  [[ -z "${uses_associations:-}" ]] || lists=("$associations")
  rm -rf "$dir"
  mkdir -p "$dir"
  log "$(basename "$seq"): $variant $name ($(basename "${lists[0]:-$seq/rgb.txt}"))"
  local status=0
  (cd "$dir" && env "${settings[@]}" "$@" DYNCULL_LOG="$dir/culler_frames.csv" \
    "$example" "$vocabulary" "$dest/${host}_settings.yaml" "$seq" "${lists[@]}" >"$dir/$example_log" 2>&1) ||
    status=$?
  ((status == 0)) || log "$variant $name: $(basename "$example") exited with status $status (see $dir/$example_log)"
  if declare -F after_run >/dev/null; then after_run "$dir"; fi
  "$dyncull_prefix/bin/dyncull_eval" "$seq/groundtruth.txt" "$dir/CameraTrajectory.txt" "${eval_options[@]}" \
    --json --poses-csv "$dir/poses.csv" >"$dir/ate.json" 2>"$dir/ate.err" || true
}

# run_sequence SEQ DEST [free]: every variant --runs times at the recorded rate, taken in turns (run 1 of
# each variant, then run 2 of each, ...) so that a spell of slower CPU, which shared machines have, hits
# every variant alike instead of one; with "free", once more not held to it (DYNCULL_FREE_RUN=1, in
# runs/VARIANT/free), for the frames per second the system sustains. The live variants track on the colour
# frames (associations_color.txt) when the sequence has them.
run_sequence() {
  local seq=$1 dest=$2 free=${3:-} variant run detections
  mkdir -p "$dest"
  sequence_tool prepare "$seq" "$dest" --host "$host" \
    --dyncull-eval "$dyncull_prefix/bin/dyncull_eval"
  detections=$(detections_of "$seq")
  for ((run = 1; run <= runs; run++)); do
    for variant in "${variant_list[@]}"; do
      run_variant "$variant" "$detections" "run$run"
    done
  done
  [[ -z "$free" ]] && return
  for variant in "${variant_list[@]}"; do
    run_variant "$variant" "$detections" free DYNCULL_FREE_RUN=1
  done
}

# run_variant VARIANT DETECTIONS RUN_NAME [SETTING...]: run_once with the variant's settings and lists.
run_variant() {
  local variant=$1 detections=$2 name=$3 associations settings=()
  shift 3
  associations="$dest/associations.txt"
  if [[ "$variant" == culler_live* && -f "$dest/associations_color.txt" ]]; then
    associations="$dest/associations_color.txt"
  fi
  mapfile -t settings < <(variant_environment "$variant" "$detections")
  run_once "$variant" "$name" "$@"
}

# Every family and motion of --families: run_sequence SEQ DEST for each, then the script's summary.
run_families() {
  local family motion seq
  [[ "$families" != all ]] || families=walking,sitting,crowd,far_walker,brisk,low_texture,noisy_detector
  IFS=',' read -r -a family_list <<<"$families"
  IFS=',' read -r -a motion_list <<<"$motions"
  for family in "${family_list[@]}"; do
    for motion in "${motion_list[@]}"; do
      seq=$(family_sequence "$family" "$motion")
      run_sequence "$seq" "$out/families/${family}_${motion}"
      summarise_sequence "$seq" "$out/families/${family}_${motion}" >/dev/null
    done
  done
}
