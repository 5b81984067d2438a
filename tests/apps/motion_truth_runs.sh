#!/usr/bin/env bash
# ctest driver of dyncull_motion_truth end to end.
#   motion_truth_runs.sh families LABELLER OUT
#       the labeller's accuracy on the walking and crowd families: precision and recall of "moving"
#       on the known pixels at least 0.95 each.
#   motion_truth_runs.sh bonn LABELLER DYNAMIC_VO DATA_DIR OUT
#       the truth of the first 110 frames (people from frame 57) of the Bonn crowd sequence, then dynamic_vo --truth on them:
#       the oracle scores precision and recall 1, a culling preset a precision in [0, 1], no culling none.
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
    done
    echo "labeller accuracy: walking and crowd at least 0.95 precision and recall"
    ;;
  bonn)
    labeller=$2 vo=$3 data=$4 out=$5
    if [[ -z "$data" || ! -d "$data/bonn/crowd_part1" ]]; then
      echo "skipped: DYNCULL_DATA_DIR has no bonn/crowd_part1 (point it at the shared data directory)"
      exit 77
    fi
    rm -rf "$out"
    "$labeller" --dataset "$data/bonn/crowd_part1" --out "$out/truth" --frames 110
    [[ $(grep -vc '^#' "$out/truth/index.txt") == 110 && -f "$out/truth/000109.png" ]] ||
      { echo "FAIL: the truth folder does not hold 60 frames"; exit 1; }
    "$vo" --dataset "$data/bonn/crowd_part1" --truth "$out/truth" --frames 110 --strategies none,zhu_2024,oracle \
      --out "$out/vo" >/dev/null
    csv="$out/vo/dataset_summary.csv"
    [[ $(column precision oracle "$csv") == 1.0000 && $(column recall oracle "$csv") == 1.0000 ]] ||
      { echo "FAIL: the oracle does not cull exactly the moving features"; cat "$csv"; exit 1; }
    p=$(column precision zhu_2024 "$csv") r=$(column recall zhu_2024 "$csv")
    at_least "$p" 0 && at_least 1 "$p" && { [[ -z "$r" ]] || { at_least "$r" 0 && at_least 1 "$r"; }; } ||
      { echo "FAIL: zhu_2024 precision '$p' recall '$r'"; cat "$csv"; exit 1; }
    [[ -z $(column precision none "$csv") ]] || { echo "FAIL: no culling has a precision"; exit 1; }
    echo "dynamic_vo --truth: oracle 1/1, zhu_2024 precision $p recall $r"
    ;;
  *) echo "usage: $0 families|bonn ..." >&2; exit 2 ;;
esac
