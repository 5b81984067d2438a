#!/usr/bin/env python3
"""Draws the plots of the docs from the CSV that dynamic_vo writes (matplotlib, Debian's python3-matplotlib).

  figures.py DIR [--summary-only]
      DIR/family_summary.csv   -> DIR/family_summary.png: median ATE per scene family and strategy (log axis)
      DIR/NAME_poses.csv       -> DIR/NAME_trajectories.png: one panel per strategy, top view in metres, the
                                  estimate coloured by its error, the ground truth in grey
                                  DIR/NAME_ate_over_time.png: each strategy's error over time, the frames with
                                  people in view (NAME_frames.csv: person boxes) shaded
      --summary-only skips the per-sequence figures (the scene-family suite has dozens of sequences).

NAME_poses.csv has dyncull_eval --poses-csv's columns after a strategy column: strategy,stamp,gt_x,gt_y,
gt_z,x,y,z,error_m (the estimate as the ATE aligned it).
"""
import argparse
import csv
import glob
import math
import os
import sys

try:
    import matplotlib
except ImportError:
    sys.exit("figures.py: needs matplotlib (Debian's python3-matplotlib, which scripts/install-deps.sh installs)")

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402

PEOPLE_SHADE = "#f3d9a4"


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def read_poses(path, label=None):
    """strategy -> columns (stamp, gt, estimate as lists of (x, y, z), error_m), in file order. A file of
    dyncull_eval --poses-csv (no strategy column) is one run, named `label`."""
    runs = {}
    for r in read_rows(path):
        run = runs.setdefault(r.get("strategy", label), {"stamp": [], "gt": [], "est": [], "error": []})
        run["stamp"].append(float(r["stamp"]))
        run["gt"].append(tuple(float(r[k]) for k in ("gt_x", "gt_y", "gt_z")))
        run["est"].append(tuple(float(r[k]) for k in ("x", "y", "z")))
        run["error"].append(float(r["error_m"]))
    return runs


def top_view_axes(points):
    """The two world axes of largest ground-truth extent (the motion's plane), in x-y-z order."""
    extent = [max(p[i] for p in points) - min(p[i] for p in points) for i in range(3)]
    return sorted(sorted(range(3), key=lambda i: -extent[i])[:2])


def rmse(values):
    return math.sqrt(sum(v * v for v in values) / len(values)) if values else float("nan")


def grid_shape(n):
    """Columns for n panels: 3 up to 9 panels, 4 beyond, so few panels stay large."""
    cols = min(n, 3 if n <= 9 else 4)
    return (n + cols - 1) // cols, cols


def limits(values):
    lo, hi = min(values), max(values)
    pad = 0.05 * max(hi - lo, 1e-3)
    return lo - pad, hi + pad


def plot_trajectories(runs, name, path):
    """Small multiples: every strategy on the same axes and colour scale, so panels compare by eye."""
    truth = max(runs.values(), key=lambda r: len(r["gt"]))["gt"]
    a, b = top_view_axes(truth)
    errors = sorted(e for r in runs.values() for e in r["error"])
    vmax = max(errors[int(0.95 * (len(errors) - 1))], 1e-3)  # the 95th percentile: one outlier keeps the scale
    points = truth + [p for r in runs.values() for p in r["est"]]
    xlim, ylim = limits([p[a] for p in points]), limits([p[b] for p in points])
    aspect = (ylim[1] - ylim[0]) / (xlim[1] - xlim[0])  # panel height over width at equal scale
    rows, cols = grid_shape(len(runs))
    panel = 3.6  # inches per panel's width
    fig, axes = plt.subplots(rows, cols, figsize=(panel * cols + 1.2, (panel * min(aspect, 1.5) + 0.5) * rows + 0.5),
                             sharex=True, sharey=True, squeeze=False, constrained_layout=True)
    for ax, (strategy, run) in zip(axes.flat, runs.items()):
        ax.plot([p[a] for p in truth], [p[b] for p in truth], color="0.6", lw=2.5, label="ground truth")
        xy = [(p[a], p[b]) for p in run["est"]]
        segments = LineCollection([[xy[i], xy[i + 1]] for i in range(len(xy) - 1)], cmap="viridis",
                                  norm=plt.Normalize(0, vmax), lw=1.6)
        segments.set_array(run["error"][1:])
        ax.add_collection(segments)
        ax.set_title("%s: ATE %.1f cm" % (strategy, 100 * rmse(run["error"])), fontsize=9)
        ax.set_aspect("equal", adjustable="box")
        ax.grid(True, color="0.9")
    axes[0, 0].set_xlim(*xlim)  # shared: every panel gets these limits
    axes[0, 0].set_ylim(*ylim)
    for ax in axes.flat[len(runs):]:
        ax.axis("off")
    for ax in axes[-1]:
        ax.set_xlabel("%s (m)" % "xyz"[a])
    for ax in axes[:, 0]:
        ax.set_ylabel("%s (m)" % "xyz"[b])
    fig.colorbar(segments, ax=axes, shrink=0.6, label="position error after alignment (m)")
    axes.flat[0].legend(loc="best", fontsize=8)
    fig.suptitle("%s: ground truth (grey) and each strategy's aligned estimate, top view" % name, fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def people_spans(frames):
    """(start, end) stamps of the runs of frames with at least one person box."""
    spans, start = [], None
    for i, r in enumerate(frames):
        stamp, people = float(r["stamp"]), int(r["person_boxes"]) > 0
        if people and start is None:
            start = stamp
        if start is not None and (not people or i == len(frames) - 1):
            spans.append((start, stamp))
            start = None
    return spans


def plot_ate_over_time(runs, frames, name, path):
    fig, ax = plt.subplots(figsize=(8, 3.6), constrained_layout=True)
    t0 = min(r["stamp"][0] for r in runs.values())
    for k, (start, end) in enumerate(people_spans(frames)):
        ax.axvspan(start - t0, end - t0, color=PEOPLE_SHADE, lw=0, label="people in view" if k == 0 else None)
    colours = plt.get_cmap("tab10")
    for k, (strategy, run) in enumerate(runs.items()):
        ax.plot([s - t0 for s in run["stamp"]], [100 * e for e in run["error"]], lw=1.2, color=colours(k % 10),
                label="%s (%.1f cm)" % (strategy, 100 * rmse(run["error"])))
    ax.set_xlabel("time (s)")
    ax.set_ylabel("position error after alignment (cm)")
    ax.set_ylim(bottom=0)
    ax.grid(True, color="0.9")
    ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize=8, title="strategy (ATE RMSE)",
              title_fontsize=8)
    ax.set_title("%s: error over time; shaded: frames with a person box" % name, fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def leading_digit(v):
    return round(v / 10 ** math.floor(math.log10(v))) if v > 0 else 0


def plot_family_summary(rows, path):
    """Grouped bars, log axis: no culling is often ten times worse than the rest."""
    rows = [r for r in rows if r["motion"] == "all" and r["median_ate_m"] and float(r["median_ate_m"]) > 0]
    if not rows:
        return False
    families = list(dict.fromkeys(r["family"] for r in rows))
    strategies = list(dict.fromkeys(r["strategy"] for r in rows))
    ate = {(r["family"], r["strategy"]): 100 * float(r["median_ate_m"]) for r in rows}
    width = 0.8 / len(strategies)
    colours = plt.get_cmap("tab10" if len(strategies) <= 10 else "tab20")
    fig, ax = plt.subplots(figsize=(max(7, 1.1 * len(families) + 3), 4.2), constrained_layout=True)
    for s, strategy in enumerate(strategies):
        xs = [f + (s - (len(strategies) - 1) / 2) * width for f, family in enumerate(families)
              if (family, strategy) in ate]
        ys = [ate[(family, strategy)] for family in families if (family, strategy) in ate]
        ax.bar(xs, ys, width, color=colours(s % colours.N), label=strategy)
    ax.set_yscale("log")
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: "%g" % v))  # 1, 10 rather than 10^0, 10^1
    ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: "%g" % v if leading_digit(v) in (2, 5) else ""))
    ax.set_xticks(range(len(families)))
    ax.set_xticklabels(families, rotation=20, ha="right", fontsize=8)
    ax.set_ylabel("median ATE RMSE (cm, log scale)")
    ax.grid(True, axis="y", which="both", color="0.9")
    ax.set_axisbelow(True)
    ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize=8)
    ax.set_title("Median ATE RMSE per scene family and strategy", fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def sequence_figures(poses_path):
    """The two figures of one sequence; returns the paths written."""
    prefix = poses_path[:-len("_poses.csv")]
    name = os.path.basename(prefix)
    runs = read_poses(poses_path)
    if not runs:
        return []
    written = [prefix + "_trajectories.png"]
    plot_trajectories(runs, name, written[0])
    frames_path = prefix + "_frames.csv"
    frames = read_rows(frames_path) if os.path.exists(frames_path) else []
    written.append(prefix + "_ate_over_time.png")
    plot_ate_over_time(runs, frames, name, written[1])
    return written


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("dir", help="dynamic_vo's output folder (--out)")
    parser.add_argument("--summary-only", action="store_true", help="skip the per-sequence figures")
    args = parser.parse_args()
    written = []
    summary = os.path.join(args.dir, "family_summary.csv")
    if os.path.exists(summary) and plot_family_summary(read_rows(summary), os.path.join(args.dir, "family_summary.png")):
        written.append(os.path.join(args.dir, "family_summary.png"))
    if not args.summary_only:
        for poses in sorted(glob.glob(os.path.join(args.dir, "*_poses.csv"))):
            written += sequence_figures(poses)
    for path in written:
        print("wrote %s" % path)
    if not written:
        print("figures.py: no family_summary.csv or *_poses.csv in %s" % args.dir, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
