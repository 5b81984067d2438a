#!/usr/bin/env bash
# ctest driver of dyncull_motion_truth end to end.
#   motion_truth_runs.sh families LABELLER OUT
#       the labeller's accuracy on the walking and crowd families: precision and recall of "moving"
#       on the known pixels at least 0.95 each, and at least 80 % of the pixels with depth known.
#   motion_truth_runs.sh bonn LABELLER DYNAMIC_VO DATA_DIR OUT
#       the truth of 80 frames of the Bonn crowd sequence with people walking, then dynamic_vo --truth on them:
#       the oracle scores precision and recall 1, a culling preset both in (0, 1], no culling neither.
#       Exits 77 (skipped) without the data.
set -euo pipefail
column() {  # column NAME STRATEGY CSV: the value of column NAME in STRATEGY's row
  awk -F, -v name="$1" -v row="$2" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == name) c = i; next }
                                    $1 == row { print $c }' "$3"
}
at_least() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "" && a + 0 >= b + 0) }'; }

case "$1" in
  families)
    "$2" --families walking,crowd --frames 20 --out "$3"
    for family in walking crowd; do
      for what in precision recall; do
        v=$(column "$what" "$family" "$3/sim_accuracy.csv")
        at_least "$v" 0.95 || { echo "FAIL: $family $what $v < 0.95"; exit 1; }
      done
      v=$(column known_share "$family" "$3/sim_accuracy.csv")
      at_least "$v" 0.80 || { echo "FAIL: $family labels $v of the pixels with depth, < 0.80"; exit 1; }
    done
    echo "labeller accuracy: walking and crowd at least 0.95 precision and recall, 80 % of the pixels known"
    ;;
  bonn)
    labeller=$2 vo=$3 data=$4 out=$5
    if [[ -z "$data" || ! -d "$data/bonn/crowd_part1" ]]; then
      echo "skipped: DYNCULL_DATA_DIR has no bonn/crowd_part1 (point it at the shared data directory)"
      exit 77
    fi
    rm -rf "$out"
    # Frames 220-299, where people walk through the view: the sequence's lists cut to them, its images,
    # depth and boxes linked.
    src="$data/bonn/crowd_part1" seq="$out/seq"
    mkdir -p "$seq/detections"
    ln -s "$src/rgb" "$seq/rgb" && ln -s "$src/depth" "$seq/depth"
    cp "$src/camera.txt" "$src/groundtruth.txt" "$src/depth.txt" "$seq/"
    grep -v '^#' "$src/rgb.txt" | sed -n '221,300p' >"$seq/rgb.txt"
    for i in $(seq 220 299); do ln -s "$src/detections/$(printf %06d "$i").json" "$seq/detections/"; done
    "$labeller" --dataset "$seq" --out "$out/truth"
    [[ $(grep -vc '^#' "$out/truth/index.txt") == 80 && -f "$out/truth/000079.png" ]] ||
      { echo "FAIL: the truth folder does not hold 80 frames"; exit 1; }
    "$vo" --dataset "$seq" --truth "$out/truth" --strategies none,zhu_2024,oracle --out "$out/vo" >/dev/null
    csv="$out/vo/dataset_summary.csv"
    [[ $(column precision oracle "$csv") == 1.0000 && $(column recall oracle "$csv") == 1.0000 ]] ||
      { echo "FAIL: the oracle does not cull exactly the moving features"; cat "$csv"; exit 1; }
    p=$(column precision zhu_2024 "$csv") r=$(column recall zhu_2024 "$csv")
    at_least "$p" 0.01 && at_least 1 "$p" && at_least "$r" 0.01 && at_least 1 "$r" ||
      { echo "FAIL: zhu_2024 precision '$p' recall '$r'"; cat "$csv"; exit 1; }
    [[ -z $(column precision none "$csv") ]] || { echo "FAIL: no culling has a precision"; exit 1; }
    echo "dynamic_vo --truth: oracle 1/1, zhu_2024 precision $p recall $r"
    ;;
  *) echo "usage: $0 families|bonn ..." >&2; exit 2 ;;
esac
