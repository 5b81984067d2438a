#!/usr/bin/env bash
# Regenerates docs/results.md: the real sequence first (dynamic_vo --dataset on the Bonn RGB-D Dynamic
# crowd extract under $DYNCULL_DATA_DIR/bonn/crowd_part1, every strategy scored against the per-pixel motion truth of
# dyncull_motion_truth, and scripts/ablation.sh --dataset on
# it), then the scene-family suite (scripts/demo.sh: every preset against no culling and the oracle) and the
# ablation table of the recommended preset (scripts/ablation.sh), with the machine, the compiler, the commit
# and the commands that produced them.
#   scripts/results.sh [--out DIR] [--page FILE]      runs all four (about 15 + 15 + 30 minutes on two free cores)
#   scripts/results.sh --real-only [--out DIR]         runs only the real sequence and rewrites only its section,
#                                                      keeping the page's suite sections as they are
#   scripts/results.sh --suite DIR --ablation DIR [--real DIR --real-ablation DIR]
#                                                      only the page, from earlier runs' output directories
# DIR defaults to ./results_out, FILE to docs/results.md. Each run directory gets a run_info.txt (machine,
# compiler, commit, command, wall time) that the page quotes. Without $DYNCULL_DATA_DIR the real sequence is
# left out (said on the page).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=results_out
page="$root/docs/results.md"
suite=""
ablation=""
real=""
real_ablation=""
real_only=""
while (($#)); do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --page) page=$2; shift 2 ;;
    --suite) suite=$2; shift 2 ;;
    --ablation) ablation=$2; shift 2 ;;
    --real) real=$2; shift 2 ;;
    --real-ablation) real_ablation=$2; shift 2 ;;
    --real-only) real_only=1; shift ;;
    *) echo "results.sh: unknown argument '$1' (see the comment at the top of $0)" >&2; exit 2 ;;
  esac
done

# Runs one command, then records what ran it where: the page cites this file, not the memory of a person.
run_recorded() {
  local dir=$1 shown=$2; shift 2
  mkdir -p "$dir"
  local start end
  start=$(date +%s)
  "$@"
  end=$(date +%s)
  local build="${DYNCULL_DEMO_BUILD:-$root/build/demo}"
  local compiler
  compiler=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt" 2>/dev/null || true)
  {
    echo "machine: $(lscpu 2>/dev/null | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores"
    echo "compiler: $("${compiler:-c++}" --version | head -1), CMAKE_BUILD_TYPE=Release"
    echo "commit: $(git -C "$root" rev-parse --short HEAD)$(git -C "$root" diff --quiet HEAD -- include apps || echo ' (with local changes)')"
    echo "command: $shown"
    echo "wall time: $((end - start)) s"
  } >"$dir/run_info.txt"
}

# The real sequence (its data is not in the repository: read through DYNCULL_DATA_DIR).
dataset="${DYNCULL_DATA_DIR:-}/bonn/crowd_part1"
if [[ -n "${DYNCULL_DATA_DIR:-}" && -d "$dataset" ]]; then
  build="${DYNCULL_DEMO_BUILD:-$root/build/demo}"
  if [[ -z "$real" ]]; then
    real="$out/real"
    # The per-pixel motion truth first (ground-truth poses and depth, no boxes), and the labeller's own
    # accuracy on the scene families; then every strategy scored against it.
    "$root/scripts/demo.sh" --list >/dev/null  # builds both programs
    run_recorded "$real/truth" "dyncull_motion_truth --dataset \$DYNCULL_DATA_DIR/bonn/crowd_part1 --out TRUTH_DIR" \
      "$build/apps/dyncull_motion_truth" --dataset "$dataset" --out "$real/truth"
    run_recorded "$real/truth_families" "dyncull_motion_truth --families all --out DIR" \
      "$build/apps/dyncull_motion_truth" --families all --out "$real/truth_families"
    # Three PnP-RANSAC seeds: one run's ATE moves by centimetres with the seed alone.
    run_recorded "$real" "dynamic_vo --dataset \$DYNCULL_DATA_DIR/bonn/crowd_part1 --truth TRUTH_DIR --seeds 7,8,9 --out DIR" \
      "$root/scripts/demo.sh" --dataset "$dataset" --truth "$real/truth" --seeds 7,8,9 --out "$real"
  fi
  if [[ -z "$real_ablation" ]]; then
    real_ablation="$out/real_ablation"
    run_recorded "$real_ablation" "scripts/ablation.sh --dataset \$DYNCULL_DATA_DIR/bonn/crowd_part1" \
      "$root/scripts/ablation.sh" --dataset "$dataset" --out "$real_ablation"
  fi
elif [[ -z "$real" ]]; then
  echo "results.sh: DYNCULL_DATA_DIR is not set or has no bonn/crowd_part1: the page has no real-sequence section" >&2
fi

if [[ -n "$real_only" ]]; then
  [[ -n "$real" ]] || { echo "results.sh: --real-only needs the real sequence (set DYNCULL_DATA_DIR)" >&2; exit 1; }
  [[ -f "$page" ]] || { echo "results.sh: --real-only keeps the suite sections of $page, which does not exist" >&2; exit 1; }
else
  if [[ -z "$suite" ]]; then
    suite="$out/suite"
    run_recorded "$suite" "scripts/demo.sh --suite --jobs ${DYNCULL_JOBS:-$(nproc)}" "$root/scripts/demo.sh" --suite --jobs "${DYNCULL_JOBS:-$(nproc)}" --out "$suite"
  fi
  if [[ -z "$ablation" ]]; then
    ablation="$out/ablation"
    run_recorded "$ablation" "scripts/ablation.sh" "$root/scripts/ablation.sh" --out "$ablation"
  fi
  for f in "$suite/family_summary.md" "$suite/family_summary.csv" "$ablation/ablation.md"; do
    [[ -f "$f" ]] || { echo "results.sh: $f is missing (run without --suite / --ablation to produce it)" >&2; exit 1; }
  done
fi

# What the families and the ablation rows are, as the binary that ran them describes them.
vo="${DYNCULL_DEMO_BUILD:-$root/build/demo}/apps/dynamic_vo"
if [[ -x "$vo" && -z "$real_only" ]]; then
  "$vo" --help | awk '/^scene families/ { on = 1; next } on && /^$/ { on = 0 } on' >"$suite/families.txt"
  "$vo" --list | awk '$1 ~ /^recommended-no_/' | sed 's/ *(ablation).*//' >"$ablation/strategies.txt"
fi

# The demo's pictures, for this page and the README: the plots drawn again from the runs' CSV (folders
# given with --suite / --real may predate them).
mkdir -p "$root/docs/images"
if [[ -z "$real_only" ]]; then
  "$root/scripts/figures.sh" "$suite" --summary-only
  for f in family_summary.png frame_strip.png; do
    [[ -f "$suite/$f" ]] && cp "$suite/$f" "$root/docs/images/$f"
  done
fi
if [[ -n "$real" ]]; then
  if compgen -G "$real/*_poses.csv" >/dev/null; then "$root/scripts/figures.sh" "$real"; fi
  for f in trajectories.png ate_over_time.png frame_strip.png; do
    [[ -f "$real/crowd_part1_$f" ]] && cp "$real/crowd_part1_$f" "$root/docs/images/bonn_crowd_part1_$f"
  done
  [[ -f "$real/truth/outside_boxes_strip.png" ]] &&
    cp "$real/truth/outside_boxes_strip.png" "$root/docs/images/bonn_crowd_part1_motion_truth.png"
fi

args=(--real "${real:-}" --real-ablation "${real_ablation:-}")
if [[ -n "$real_only" ]]; then
  args+=(--keep-suite-of "$page")
else
  args+=(--suite "$suite" --ablation "$ablation")
  # The ORB-SLAM2 sections come from scripts/orbslam2.sh: kept as they are.
  [[ -f "$page" ]] && args+=(--keep-orbslam2-of "$page")
fi
python3 "$root/scripts/results_page.py" "${args[@]}" >"$page.new"
mv "$page.new" "$page"
echo "results.sh: wrote $page"
