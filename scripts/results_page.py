#!/usr/bin/env python3
"""Writes docs/results.md (to stdout): the real sequence first, then the scene-family suite and its ablation.

    scripts/results_page.py [--real DIR] [--real-ablation DIR] --suite DIR --ablation DIR
    scripts/results_page.py [--real DIR] [--real-ablation DIR] --keep-suite-of PAGE

--real holds dynamic_vo --dataset's dataset_summary.csv, --real-ablation the ablation.md of
scripts/ablation.sh --dataset; --suite holds dynamic_vo's family_summary.md / .csv (scripts/demo.sh
--suite), --ablation the ablation.md of scripts/ablation.sh. Each may hold the run_info.txt that
scripts/results.sh writes, and the suite the families.txt it copies from dynamic_vo --help.
--keep-suite-of copies the suite sections of an existing page unchanged (everything from its first
"## What runs"), so the real sequence can be rerun alone. --keep-orbslam2-of copies the sections
scripts/orbslam2.sh wrote into an existing page. Called by scripts/results.sh.
"""
import argparse
import csv
import os
import sys

from page_common import read, run_info, table_lines
from results_real import TARGET_COST, real_section

TARGET_RATIO = 1.15   # recommended ATE at most this times the oracle's, on every family
TARGET_LABELS = 0.9   # dynamic-label precision and recall, pooled per family


def strategies(directory):
    path = os.path.join(directory, "strategies.txt")
    if not os.path.exists(path):
        return "`dynamic_vo --list` says what each row switches off."
    return "What each row switches off (`dynamic_vo --list`):\n\n```\n" + read(path).rstrip() + "\n```"


def targets(suite_csv):
    with open(suite_csv, newline="", encoding="utf-8") as f:
        rows = [r for r in csv.DictReader(f) if r["motion"] == "all"]
    families = []
    for r in rows:
        if r["family"] not in families:
            families.append(r["family"])
    rec = {r["family"]: r for r in rows if r["recommended"] == "1"}
    oracle = {r["family"]: r for r in rows if r["oracle"] == "1"}
    none = {r["family"]: r for r in rows if r["strategy"] == "none"}

    def num(r, key):
        return float(r[key]) if r and r.get(key) else None

    checks = {"ratio": [], "none": [], "labels": [], "cost": []}
    for fam in families:
        a, o, n = num(rec.get(fam), "median_ate_m"), num(oracle.get(fam), "median_ate_m"), num(none.get(fam), "median_ate_m")
        if a is not None and o:
            checks["ratio"].append((fam, a / o, a / o <= TARGET_RATIO, f"{a / o:.2f}"))
        if a is not None and n:
            checks["none"].append((fam, a / n, a <= n, f"{a / n:.2f}"))
        p, q = num(rec.get(fam), "precision"), num(rec.get(fam), "recall")
        if p is not None and q is not None:
            checks["labels"].append((fam, -min(p, q), p >= TARGET_LABELS and q >= TARGET_LABELS, f"{p:.3f} / {q:.3f}"))
        c = num(rec.get(fam), "cull_over_front_end")
        if c is not None:
            checks["cost"].append((fam, c, c < TARGET_COST, f"{c:.3f}"))

    names = {
        "ratio": f"recommended ATE <= {TARGET_RATIO}x the oracle's",
        "none": "recommended never worse than no culling",
        "labels": f"dynamic-label precision and recall >= {TARGET_LABELS}",
        "cost": f"culling < {TARGET_COST:g} of the front end's time",
    }
    out = ["| target | met on | not met on |", "|---|---|---|"]
    for key, name in names.items():
        met = ", ".join(f"{f} ({v})" for f, _, ok, v in checks[key] if ok) or "-"
        missed = sorted((c for c in checks[key] if not c[2]), key=lambda c: c[1])
        out.append(f"| {name} | {met} | {', '.join(f'{f} ({v})' for f, _, _, v in missed) or '-'} |")
    return "\n".join(out)


SUITE_START = "## What runs"

def header():
    return """# Results

How well culling works: the absolute trajectory error (ATE RMSE, as the TUM benchmark's `evaluate_ate.py`)
of one RGB-D visual odometry front end with each culling strategy, first on a real dynamic RGB-D sequence
with a real detector, then on synthetic scene families modelled on the TUM fr3 dynamic sequences, with the
ablation tables that are the evidence for the recommended preset. This page is generated:
`scripts/results.sh` runs every experiment and rewrites it (about an hour on two free cores);
`scripts/results.sh --real-only` reruns the real sequence alone; `scripts/results.sh --suite DIR
--ablation DIR` rewrites it from earlier output. The ORB-SLAM2 sections at the end are written by
`scripts/orbslam2.sh` and kept as they are by `scripts/results.sh`.
"""


def kept_suite(page):
    text = read(page)
    at = text.find("\n" + SUITE_START + "\n")
    if at < 0:
        sys.exit(f"results_page: {page} has no '{SUITE_START}' section to keep")
    return text[at + 1:]


def kept_orbslam2(page):
    """The sections scripts/orbslam2.sh writes ("## In ORB-SLAM2", "## Scene families in ORB-SLAM2"), from
    the first of them to the end of `page`, or nothing."""
    if not page or not os.path.exists(page):
        return ""
    text = read(page)
    starts = [text.find("\n" + h + "\n") for h in ("## In ORB-SLAM2", "## Scene families in ORB-SLAM2")]
    starts = [s for s in starts if s >= 0]
    return ("\n" + text[min(starts) + 1:]) if starts else ""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--real", default="")
    ap.add_argument("--real-ablation", default="")
    ap.add_argument("--suite")
    ap.add_argument("--ablation")
    ap.add_argument("--keep-suite-of")
    ap.add_argument("--keep-orbslam2-of", default="")
    a = ap.parse_args()
    if a.keep_suite_of:
        suite_text = kept_suite(a.keep_suite_of)
    elif a.suite and a.ablation:
        suite_text = suite_sections(a.suite, a.ablation) + kept_orbslam2(a.keep_orbslam2_of)
    else:
        sys.exit("results_page: give --suite and --ablation, or --keep-suite-of PAGE")
    print(header() + "\n" + real_section(a.real, a.real_ablation) + "\n" + suite_text, end="")


def suite_sections(suite, ablation):
    families = os.path.join(suite, "families.txt")
    family_text = ("```\n" + read(families).rstrip() + "\n```\n") if os.path.exists(families) else \
        "`dynamic_vo --help` lists them with their `--scene` text.\n"
    return f"""## What runs

`apps/dynamic_vo` renders each sequence in memory (`dyncull::sim::Scene`: 640x480 at 30 fps,
Kinect-like depth noise and holes, detections from a simulated detector) and tracks it with an RGB-D front
end: ORB corners tracked by pyramidal Lucas-Kanade, PnP-RANSAC against the keyframe's depth, Huber
Levenberg-Marquardt refinement and a constant-velocity fallback. Every strategy culls the same frames
through `dyncull::cull_frame` before the pose is estimated:

- `none`: no culling;
- the papers' presets of `culling/presets.hpp` (`zhang_2023`, `zhu_2024`, `dld_slam`, `dfd_slam`,
  `rtd_slam`), on frame-to-frame tracks as in the papers;
- `recommended`: `presets::recommended()`, on tracks against the keyframe;
- `oracle`: culls exactly the features the renderer marks as moving, the best any culling can do with
  this front end.

The suite runs every family with four camera motions (static, xyz, rpy, halfsphere: the motions of TUM
fr3/walking_*) and scene seeds 1, 2 and 3, 150 frames each. The families:

{family_text}
## Scene-family suite

{run_info(suite)}

![Median ATE per scene family and strategy](images/family_summary.png)

One frame of each family's xyz sequence with the recommended preset (green: kept; red: culled; yellow
ring: a moving feature kept; red cross: a static feature culled; blue: detection boxes):

![One annotated frame per family](images/frame_strip.png)

{table_lines(read(os.path.join(suite, "family_summary.md")))}

Against the targets (median over motions x seeds per family; the families sorted from nearest to
furthest from the target):

{targets(os.path.join(suite, "family_summary.csv"))}

## Ablation of the recommended preset

Each row switches one stage or one non-default option of the recommended preset back off
(`dynamic_vo --list` names them `recommended-no_<x>`) and runs the whole suite again; the references
`none` and `oracle` close the table. A positive change means the suite is worse without that stage or
option: it earns its place; a row that is better on most families marks a default to revisit.

{run_info(ablation)}

{table_lines(read(os.path.join(ablation, "ablation.md")))}

{strategies(ablation)}

## Real camera motion

The same suite runs on the ground-truth camera trajectories of the TUM fr3 dynamic sequences
(`dynamic_vo --sequences fr3_walking_xyz,fr3_sitting_static,...`; the trajectories are read from
`$DYNCULL_DATA_DIR/tum`, which the repository does not ship).
"""


if __name__ == "__main__":
    main()
