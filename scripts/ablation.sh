#!/usr/bin/env bash
# Regenerates the ablation table of the recommended preset over the scene-family suite: dynamic_vo --suite
# with the recommended preset, no culling, the oracle and every "recommended-no_<x>" strategy (the preset
# with one of its stages, or one of its non-default options, switched back off; dynamic_vo --list), then
# a Markdown table and a CSV of the median ATE per family, the change against the recommended preset and
# the pooled label precision / recall.
#   scripts/ablation.sh [--out DIR] [dynamic_vo options, e.g. --frames 100 --seeds 1,2 --family walking,sitting]
#   scripts/ablation.sh --table CSV [--out DIR]   only the table, from an existing family_summary.csv
#   scripts/ablation.sh --dataset DIR [--out DIR] [dynamic_vo options, e.g. --frames 100]
#                                                 the same strategies on a real sequence (dynamic_vo --dataset:
#                                                 one sequence, no oracle), a row per strategy with its ATE,
#                                                 the change against the recommended preset, RPE, lost frames
#                                                 and where its culls fall; --table then reads a dataset_summary.csv
# Output: DIR/ablation.md and DIR/ablation.csv (DIR defaults to ./ablation_out). DYNCULL_DEMO_BUILD sets the
# build directory (default build/demo, shared with scripts/demo.sh), DYNCULL_JOBS the parallel sequences. Every strategy runs its own
# front end, so this costs about 4x the demo's suite (28 strategies instead of 8: measured 0.28 against
# 0.07 CPU-seconds a frame, about 30 minutes on two free cores at the suite's 150 frames; --frames, --seeds
# and --sequences make it shorter).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=ablation_out
table_only=""
dataset=""
pass=()
while (($#)); do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --table) table_only=$2; shift 2 ;;
    --dataset) dataset=$2; shift 2 ;;
    *) pass+=("$1"); shift ;;
  esac
done
mkdir -p "$out"

if [[ -z "$table_only" ]]; then
  build="${DYNCULL_DEMO_BUILD:-$root/build/demo}"
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DDYNCULL_BUILD_TESTS=OFF \
    -DDYNCULL_BUILD_BENCHMARKS=OFF -DDYNCULL_BUILD_EXAMPLES=OFF -DDYNCULL_BUILD_APPS=ON >/dev/null
  cmake --build "$build" -j "${DYNCULL_JOBS:-$(nproc)}" --target dynamic_vo
  vo="$build/apps/dynamic_vo"
  ablations=$("$vo" --list | awk '$1 ~ /^recommended-no_/ { print $1 }' | paste -sd, -)
  if [[ -n "$dataset" ]]; then
    "$vo" --dataset "$dataset" --strategies "none,recommended,$ablations" --out "$out" ${pass[@]+"${pass[@]}"}
    table_only="$out/dataset_summary.csv"
  else
    "$vo" --suite --jobs "${DYNCULL_JOBS:-$(nproc)}" --strategies "none,recommended,oracle,$ablations" \
      --out "$out" ${pass[@]+"${pass[@]}"}
    table_only="$out/family_summary.csv"
  fi
fi

if head -1 "$table_only" | grep -q '^strategy,frames,'; then
  # One real sequence (dataset_summary.csv): a row per strategy.
  python3 - "$table_only" "$out" <<'EOF'
import csv, sys

src, out = sys.argv[1], sys.argv[2]
with open(src, newline="") as f:
    rows = list(csv.DictReader(f))
by = {r["strategy"]: r for r in rows}
if "recommended" not in by:
    sys.exit(f"ablation: no recommended row in {src}")
base = float(by["recommended"]["ate_rmse_m"]) if by["recommended"]["ate_rmse_m"] else None
order = ["recommended"] + [r["strategy"] for r in rows if r["strategy"].startswith("recommended-no_")]
order += [r["strategy"] for r in rows if r["strategy"] not in order]


def pct(x):
    return "-" if x in (None, "") else f"{100 * float(x):.1f} %"


md = ["| strategy | ATE RMSE (cm) | vs recommended | RPE 1 s (cm) | lost frames | culled in person boxes | culled outside boxes |",
      "|---|---|---|---|---|---|---|"]
csv_rows = [["strategy", "ate_rmse_m", "change_vs_recommended", "rpe_trans_m", "lost_frames", "culled_in_person_boxes",
             "culled_outside_boxes"]]
for s in order:
    r = by[s]
    a = float(r["ate_rmse_m"]) if r["ate_rmse_m"] else None
    change = (a - base) / base if a is not None and base and s != "recommended" else None
    rpe = float(r["rpe_trans_m"]) if r["rpe_trans_m"] else None
    md.append(f"| {s} | {'-' if a is None else f'{100 * a:.2f}'} | {'-' if change is None else f'{100 * change:+.0f} %'} | "
              f"{'-' if rpe is None else f'{100 * rpe:.2f}'} | {r['lost_frames']} of {r['frames']} | "
              f"{pct(r['culled_in_person_boxes']) if s != 'none' else '-'} | {pct(r['culled_outside_boxes']) if s != 'none' else '-'} |")
    csv_rows.append([s, r["ate_rmse_m"], "" if change is None else f"{change:.4f}", r["rpe_trans_m"], r["lost_frames"],
                     r["culled_in_person_boxes"], r["culled_outside_boxes"]])
md.append("")
md.append("One real sequence, one run: ATE RMSE in cm and its change against the recommended preset; RPE over 1 s;"
          " culled in person boxes / outside boxes: share of the tracked features there that the strategy culled."
          " `recommended-no_<x>`: the preset with `<x>` switched back off (`dynamic_vo --list` says what each undoes).")
with open(f"{out}/ablation.md", "w") as f:
    f.write("\n".join(md) + "\n")
with open(f"{out}/ablation.csv", "w", newline="") as f:
    csv.writer(f).writerows(csv_rows)
print("\n".join(md))
print(f"\nwrote {out}/ablation.md\nwrote {out}/ablation.csv")
EOF
  exit 0
fi

python3 - "$table_only" "$out" <<'EOF'
import csv, sys

src, out = sys.argv[1], sys.argv[2]
with open(src, newline="") as f:
    rows = [r for r in csv.DictReader(f) if r["motion"] == "all"]
if not rows:
    sys.exit(f"ablation: no per-family rows in {src}")
families, strategies = [], []
for r in rows:
    if r["family"] not in families:
        families.append(r["family"])
    if r["strategy"] not in strategies:
        strategies.append(r["strategy"])
cell = {(r["family"], r["strategy"]): r for r in rows}
rec = next((r["strategy"] for r in rows if r["recommended"] == "1"), "recommended")


def ate(family, strategy):
    r = cell.get((family, strategy))
    return float(r["median_ate_m"]) if r and r["median_ate_m"] else None


def pooled(strategy):
    tp = fp = fn = 0
    for family in families:
        r = cell.get((family, strategy))
        if r:
            tp, fp, fn = tp + int(r["true_positive"]), fp + int(r["false_positive"]), fn + int(r["false_negative"])
    p = tp / (tp + fp) if tp + fp else None
    q = tp / (tp + fn) if tp + fn else None
    return p, q


def fmt(x, f="{:.3f}"):
    return "-" if x is None else f.format(x)


# Rows: the recommended preset first, its ablations, then the references.
order = [rec] + [s for s in strategies if s.startswith(rec + "-no_")] + [s for s in strategies if s in ("none", "oracle")]
order += [s for s in strategies if s not in order]
md = ["| strategy | " + " | ".join(families) + " | sum (cm) | vs recommended | families better / worse | precision | recall |",
      "|---|" + "---|" * (len(families) + 5)]
csv_rows = [["strategy", "family", "median_ate_m", "change_vs_recommended", "precision", "recall"]]
rec_sum = sum(ate(f, rec) or 0.0 for f in families)
for s in order:
    cells, total, better, worse = [], 0.0, 0, 0
    for family in families:
        a, base = ate(family, s), ate(family, rec)
        change = (a - base) / base if a is not None and base else None
        total += a or 0.0
        if s != rec and change is not None:
            # Within 2 %: the same, given seed-to-seed noise of a median of a few runs.
            better += change < -0.02
            worse += change > 0.02
        cells.append("-" if a is None else f"{100 * a:.2f}" + ("" if s == rec or change is None else f" ({100 * change:+.0f} %)"))
        r = cell.get((family, s))
        csv_rows.append([s, family, "" if a is None else f"{a:.6f}", "" if change is None else f"{change:.4f}",
                         r["precision"] if r else "", r["recall"] if r else ""])
    p, q = pooled(s)
    if all(not (cell.get((family, s)) or {}).get("precision") for family in families):
        p = q = None  # no culling: no labels to score
    vs = "-" if s == rec or not rec_sum else f"{100 * (total - rec_sum) / rec_sum:+.1f} %"
    bw = "-" if s == rec else f"{better} / {worse}"
    md.append(f"| {s} | " + " | ".join(cells) + f" | {100 * total:.2f} | {vs} | {bw} | {fmt(p)} | {fmt(q)} |")
md.append("")
md.append("Cells: median ATE RMSE in cm over the family's motions x seeds (in brackets: change against the recommended"
          " preset). sum: over the families; better / worse: families where the change exceeds 2 %. Precision / recall:"
          " dynamic labels pooled over every family's runs. `recommended-no_<x>`: the preset with `<x>` switched back off"
          " (`dynamic_vo --list` says what each undoes).")
with open(f"{out}/ablation.md", "w") as f:
    f.write("\n".join(md) + "\n")
with open(f"{out}/ablation.csv", "w", newline="") as f:
    csv.writer(f).writerows(csv_rows)
print("\n".join(md))
print(f"\nwrote {out}/ablation.md\nwrote {out}/ablation.csv")
EOF
