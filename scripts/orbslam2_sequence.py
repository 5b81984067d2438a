#!/usr/bin/env python3
"""Sequence side of scripts/orbslam2.sh and scripts/orbslam3.sh (standard library; the trajectory figure
needs matplotlib).

  orbslam2_sequence.py prepare SEQUENCE OUT [--dyncull-eval PATH]
      OUT/orbslam2_settings.yaml (ORB-SLAM2's settings, written from SEQUENCE/camera.txt) and
      OUT/associations.txt (rgb and depth paired by `dyncull_eval --associate` as the TUM benchmark's
      associate.py: |dt| < 0.02 s, closest pairs first, each stamp once); when SEQUENCE has rgb_color.txt (colour frames of the same
      stamps, for a live detector), OUT/associations_color.txt pairs those with depth the same way.
  orbslam2_sequence.py prepare SEQUENCE OUT --host orbslam3
      the same with OUT/orbslam3_settings.yaml (ORB-SLAM3's settings format 1.0) in place of ORB-SLAM2's.
  orbslam2_sequence.py summarise SEQUENCE OUT [--vocabulary FILE] [--command TEXT] [--page FILE]
      reads OUT/runs/VARIANT/runN/ (rgbd_tum.log, CameraTrajectory.txt, ate.json), writes
      OUT/orbslam2_summary.csv (a row per variant and run) and prints the table; with --page, replaces
      (or appends) the page's "## In ORB-SLAM2" section, with the trajectory figure of each variant's
      median run drawn by scripts/figures.py from that run's poses.csv (dyncull_eval --poses-csv).

  orbslam2_sequence.py families OUT [--command TEXT] [--page FILE]
      reads OUT/families/NAME/orbslam2_summary.csv (one folder per family and camera motion), writes
      OUT/orbslam2_families.csv (median ATE, lost frames per variant and sequence) and prints the table;
      with --page, replaces (or appends) the page's "## Scene families in ORB-SLAM2" section.

  With --host orbslam3 [--sensor rgbd|mono], summarise and families read and write orbslam3_summary.csv
  and orbslam3_families.csv: the same columns and `sensor`; a monocular run is read from mono_tum.log,
  its frames are rgb.txt's (mono_tum reads the colour list itself) and its ATE is after Sim(3) alignment
  (the script evaluates it with --scale). ORB-SLAM3's maps (Atlas) beyond the first are counted in the
  run's note. The page's sections are written by orbslam_page.py ("In ORB-SLAM3, RGB-D", "In ORB-SLAM3,
  monocular", "Scene families in ORB-SLAM3" for ORB-SLAM3).

Lost frames: ORB-SLAM2 leaves a frame out of CameraTrajectory.txt when it was lost (and every frame before
its map exists), without a message; they are counted as association lines minus trajectory lines.
"""
import argparse
import json
import os
import re
import statistics
import struct
import subprocess
import sys

import orbslam_page

# culler: boxes from the detections folder; culler_live: a detector running beside the tracker (newest
# finished boxes); culler_live_sync: the detector waited for on every frame.
VARIANTS = ["stock", "box_only", "culler", "culler_live", "culler_live_sync"]


def read_list(path):
    """(stamp text, file) pairs of a TUM list file."""
    out = []
    with open(path) as f:
        for line in f:
            fields = line.split()
            if len(fields) >= 2 and not fields[0].startswith("#"):
                out.append((fields[0], fields[1]))
    return out


def associate(dyncull_eval, first, second):
    """Lines "stamp file stamp file" of two lists paired as the TUM benchmark's associate.py (|dt| < 0.02 s,
    closest pairs first, each stamp once), by `dyncull_eval --associate`."""
    done = subprocess.run([dyncull_eval, "--associate", first, second], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit("orbslam2_sequence.py: %s --associate: %s" % (dyncull_eval, done.stderr.strip()))
    return done.stdout.splitlines()


def write_lines(path, lines):
    with open(path, "w") as f:
        f.write("".join(line + "\n" for line in lines))


def read_camera(path):
    """camera.txt: 'key value' lines (fx, fy, cx, cy, depth_units_per_metre, optional k1 k2 p1 p2 k3), or
    one line of numbers 'fx fy cx cy [width height]' (write_tum_sequence's form, 5000 depth units per metre)."""
    values = {}
    with open(path) as f:
        for line in f:
            fields = line.split()
            if not fields or fields[0].startswith("#"):
                continue
            try:
                numbers = [float(v) for v in fields]
            except ValueError:
                numbers = []
            if len(numbers) >= 4 and "fx" not in values:
                values.update(zip(("fx", "fy", "cx", "cy"), numbers[:4]))
            elif len(fields) >= 2:
                try:
                    values[fields[0]] = float(fields[1])
                except ValueError:
                    pass
    missing = [k for k in ("fx", "fy", "cx", "cy") if k not in values]
    if missing:
        sys.exit("orbslam2_sequence.py: %s has no %s" % (path, ", ".join(missing)))
    return values


def png_size(path):
    with open(path, "rb") as f:
        header = f.read(24)
    if header[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit("orbslam2_sequence.py: %s is not a PNG" % path)
    return struct.unpack(">II", header[16:24])


SETTINGS = """%YAML:1.0
# Written by scripts/orbslam2.sh from {camera}.
Camera.fx: {fx}
Camera.fy: {fy}
Camera.cx: {cx}
Camera.cy: {cy}
Camera.k1: {k1}
Camera.k2: {k2}
Camera.p1: {p1}
Camera.p2: {p2}
Camera.k3: {k3}
Camera.width: {width}
Camera.height: {height}
Camera.fps: 30.0
# IR projector baseline times fx (about 40 for a Kinect-class sensor, as ORB-SLAM2's TUM settings).
Camera.bf: 40.0
Camera.RGB: 1
ThDepth: 40.0
DepthMapFactor: {depth_factor}
ORBextractor.nFeatures: 1000
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 20
ORBextractor.minThFAST: 7
Viewer.KeyFrameSize: 0.05
Viewer.KeyFrameLineWidth: 1
Viewer.GraphLineWidth: 0.9
Viewer.PointSize: 2
Viewer.CameraSize: 0.08
Viewer.CameraLineWidth: 3
Viewer.ViewpointX: 0
Viewer.ViewpointY: -0.7
Viewer.ViewpointZ: -1.8
Viewer.ViewpointF: 500
"""


SETTINGS_ORBSLAM3 = """%YAML:1.0
# Written by scripts/orbslam3.sh from {camera} (ORB-SLAM3's settings format 1.0: real numbers with a point).
File.version: "1.0"
Camera.type: "PinHole"
Camera1.fx: {fx!r}
Camera1.fy: {fy!r}
Camera1.cx: {cx!r}
Camera1.cy: {cy!r}
Camera1.k1: {k1!r}
Camera1.k2: {k2!r}
Camera1.p1: {p1!r}
Camera1.p2: {p2!r}
Camera1.k3: {k3!r}
Camera.width: {width}
Camera.height: {height}
Camera.fps: 30
Camera.RGB: 1
# IR projector baseline (about 40 / fx metres for a Kinect-class sensor, as ORB-SLAM2's Camera.bf 40)
Stereo.ThDepth: 40.0
Stereo.b: {baseline!r}
RGBD.DepthMapFactor: {depth_factor!r}
ORBextractor.nFeatures: 1000
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 20
ORBextractor.minThFAST: 7
Viewer.KeyFrameSize: 0.05
Viewer.KeyFrameLineWidth: 1.0
Viewer.GraphLineWidth: 0.9
Viewer.PointSize: 2.0
Viewer.CameraSize: 0.08
Viewer.CameraLineWidth: 3.0
Viewer.ViewpointX: 0.0
Viewer.ViewpointY: -0.7
Viewer.ViewpointZ: -1.8
Viewer.ViewpointF: 500.0
"""


def prepare(sequence, out, dyncull_eval, host="orbslam2"):
    camera = read_camera(os.path.join(sequence, "camera.txt"))
    rgb = read_list(os.path.join(sequence, "rgb.txt"))
    depth = read_list(os.path.join(sequence, "depth.txt"))
    if not rgb or not depth:
        sys.exit("orbslam2_sequence.py: %s has an empty rgb.txt or depth.txt" % sequence)
    width, height = png_size(os.path.join(sequence, rgb[0][1]))
    values = {k: float(camera.get(k, 0.0)) for k in ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3")}
    depth_factor = float(camera.get("depth_units_per_metre", 5000.0))
    if host == "orbslam3":
        settings = SETTINGS_ORBSLAM3.format(camera="camera.txt", width=width, height=height, depth_factor=depth_factor,
                                            baseline=40.0 / values["fx"], **values)
    else:
        settings = SETTINGS.format(camera="camera.txt", width=width, height=height,
                                   depth_factor=camera.get("depth_units_per_metre", 5000.0),
                                   **{k: camera.get(k, 0.0) for k in values})
    with open(os.path.join(out, "%s_settings.yaml" % host), "w") as f:
        f.write(settings)
    depth_list = os.path.join(sequence, "depth.txt")
    pairs = associate(dyncull_eval, os.path.join(sequence, "rgb.txt"), depth_list)
    write_lines(os.path.join(out, "associations.txt"), pairs)
    print("orbslam2_sequence.py: %d rgb frames, %d with a depth partner (associations.txt), %dx%d"
          % (len(rgb), len(pairs), width, height), file=sys.stderr)
    colour_list = os.path.join(sequence, "rgb_color.txt")
    if os.path.exists(colour_list):
        colour_pairs = associate(dyncull_eval, colour_list, depth_list)
        write_lines(os.path.join(out, "associations_color.txt"), colour_pairs)
        print("orbslam2_sequence.py: %d colour frames with a depth partner (associations_color.txt)"
              % len(colour_pairs), file=sys.stderr)


def count_lines(path):
    if not os.path.exists(path):
        return 0
    with open(path) as f:
        return sum(1 for line in f if line.strip() and not line.startswith("#"))


def read_run(directory, frames, log_name="rgbd_tum.log"):
    row = {"ate_rmse_m": "", "ate_pairs": "", "track_ms": "", "track_median_ms": "", "cull_ms": "", "features": "",
           "features_kept": "", "note": "", "fps": "", "track_ms_p95": "", "detector_ms": "", "box_age_frames": ""}
    poses = count_lines(os.path.join(directory, "CameraTrajectory.txt"))
    row["lost_frames"] = frames - poses
    log_path = os.path.join(directory, log_name)
    text = open(log_path, errors="replace").read() if os.path.exists(log_path) else ""
    m = re.search(r"median tracking time: ([0-9.eE+-]+)", text)
    if m:
        row["track_median_ms"] = "%.2f" % (1000 * float(m.group(1)))
    m = re.search(r"mean tracking time: ([0-9.eE+-]+)", text)
    if m:
        row["track_ms"] = "%.2f" % (1000 * float(m.group(1)))
    m = re.search(r"95th percentile tracking time: ([0-9.eE+-]+)", text)
    if m:
        row["track_ms_p95"] = "%.2f" % (1000 * float(m.group(1)))
    m = re.search(r"frames per second: ([0-9.eE+-]+) \(free run\)", text)
    if m:
        row["fps"] = "%.1f" % float(m.group(1))
    row["fewest_kept"] = fewest_kept(os.path.join(directory, "culler_frames.csv"))
    m = re.search(r"features ([0-9.]+) -> ([0-9.]+) per frame", text)
    if m:
        row["features"], row["features_kept"] = m.group(1), m.group(2)
    m = re.search(r"([0-9.]+) ms per frame culling", text)
    if m:
        row["cull_ms"] = m.group(1)
    m = re.search(r"live detector[^:]*: ([0-9.]+) ms per detection, box age ([0-9.]+) frames", text)
    if m:
        row["detector_ms"], row["box_age_frames"] = m.group(1), m.group(2)
    try:
        with open(os.path.join(directory, "ate.json")) as f:
            report = json.load(f)
        if str(report.get("status", "")).lower() == "ok":
            row["ate_rmse_m"] = "%.5f" % report["ate"]["error_m"]["rmse"]
            row["ate_pairs"] = report["ate"]["pairs"]
        else:
            row["note"] = report.get("reason", "evaluation failed")
    except (OSError, ValueError, KeyError):
        row["note"] = "no trajectory" if poses == 0 else "evaluation failed"
    if not row["track_ms"]:
        row["note"] = (row["note"] + "; " if row["note"] else "") + "%s did not finish" % log_name[:-4]
    maps = len(re.findall(r"Creation of new map with id", text))  # ORB-SLAM3's Atlas; none in ORB-SLAM2
    if maps > 1:
        row["note"] = (row["note"] + "; " if row["note"] else "") + "%d maps" % maps
    return row


def fewest_kept(path):
    """The fewest features kept in one frame of a run's DYNCULL_LOG, or '' without one."""
    if not os.path.exists(path):
        return ""
    with open(path) as f:
        header = f.readline().strip().split(",")
        if "kept" not in header:
            return ""
        k = header.index("kept")
        kept = [int(line.split(",")[k]) for line in f if line.count(",") >= k]
    return min(kept) if kept else ""


# track_ms_p95 and fps come from the patched example's last lines (fps only from the run not held to the
# recorded rate, run "free"); detector_ms and box_age_frames from the host's summary line (live variants).
COLUMNS = ["variant", "run", "ate_rmse_m", "ate_pairs", "lost_frames", "frames", "track_ms", "track_median_ms",
           "track_ms_p95", "fps", "cull_ms", "detector_ms", "box_age_frames", "features", "features_kept",
           "fewest_kept", "note"]


def median_range(values, scale=1.0, digits=2):
    if not values:
        return "n/a"
    v = [x * scale for x in values]
    fmt = "%%.%df" % digits
    return (fmt + " (" + fmt + "-" + fmt + ")") % (statistics.median(v), min(v), max(v))


def summarise(sequence, out, vocabulary, command, page, host="orbslam2", sensor="rgbd"):
    mono = host == "orbslam3" and sensor == "mono"
    frames = count_lines(os.path.join(sequence, "rgb.txt") if mono else os.path.join(out, "associations.txt"))
    columns = COLUMNS + (["sensor"] if host == "orbslam3" else [])
    log_name = "mono_tum.log" if mono else "rgbd_tum.log"
    rows = []
    runs_dir = os.path.join(out, "runs")
    for variant in VARIANTS:
        vdir = os.path.join(runs_dir, variant)
        if not os.path.isdir(vdir):
            continue
        runs = sorted((int(d[3:]) for d in os.listdir(vdir) if re.fullmatch(r"run[0-9]+", d)))
        names = ["run%d" % r for r in runs] + (["free"] if os.path.isdir(os.path.join(vdir, "free")) else [])
        for name in names:
            row = read_run(os.path.join(vdir, name), frames, log_name)
            row.update(variant=variant, run=name[3:] if name != "free" else name, frames=frames, sensor=sensor)
            rows.append(row)
    with open(os.path.join(out, "%s_summary.csv" % host), "w") as f:
        f.write(",".join(columns) + "\n")
        for row in rows:
            f.write(",".join(str(row[c]).replace(",", ";") for c in columns) + "\n")
    table = summary_table(rows)
    if mono:
        table = table.replace("ATE RMSE, cm", "ATE RMSE after Sim(3) alignment, cm")
    print(table)
    if page:
        orbslam_page.write_sequence_section(page, host, sensor, table, rows, sequence, out, vocabulary, command,
                                            numbers, VARIANTS)
    return table


def numbers(rows, variant, column):
    """A column's values over a variant's runs at the recorded rate (the free run is apart)."""
    return [float(r[column]) for r in rows if r["variant"] == variant and r[column] != "" and r.get("run") != "free"]


def summary_table(all_rows):
    """Medians over the runs at the recorded rate; the last column, when there are free runs, is theirs."""
    rows = [r for r in all_rows if r["run"] != "free"]
    free = any(r["run"] == "free" for r in all_rows)
    heads = ["Variant", "Runs", "ATE RMSE, cm: median (range)", "Lost frames: median (range)",
             "Tracking ms per frame, mean: median (range)", "Tracking ms, 95th percentile: median",
             "Culling ms per frame", "Detector ms per detection", "Box age, frames", "Features kept per frame, mean"]
    heads += ["Free run: frames per second (ATE, cm)"] if free else []
    lines = ["| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
    for variant in VARIANTS:
        mine = [r for r in rows if r["variant"] == variant]
        if not mine:
            continue
        failed = sum(1 for r in mine if r["ate_rmse_m"] == "")
        cells = [variant, "%d" % len(mine) + (" (%d without an ATE)" % failed if failed else ""),
                 median_range(numbers(rows, variant, "ate_rmse_m"), 100.0),
                 median_range(numbers(rows, variant, "lost_frames"), 1.0, 0),
                 median_range(numbers(rows, variant, "track_ms"), 1.0, 1),
                 median_cell(numbers(rows, variant, "track_ms_p95"), "%.1f"),
                 median_cell(numbers(rows, variant, "cull_ms"), "%.2f") if variant != "stock" else "-",
                 median_cell(numbers(rows, variant, "detector_ms"), "%.1f", "-"),
                 median_cell(numbers(rows, variant, "box_age_frames"), "%.2f", "-"),
                 median_cell(numbers(rows, variant, "features_kept"), "%.0f")]
        if free:
            cells.append(free_cell([r for r in all_rows if r["variant"] == variant and r["run"] == "free"]))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def median_cell(values, fmt, empty="n/a"):
    return fmt % statistics.median(values) if values else empty


def free_cell(free):
    if not free or not free[0]["fps"]:
        return "n/a"
    ate = free[0]["ate_rmse_m"]
    return "%s (%s)" % (free[0]["fps"], "%.2f" % (100 * float(ate)) if ate else "no ATE")


def read_summary(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
        return [dict(zip(header, line.rstrip("\n").split(","))) for line in f if line.strip()]


def lost_cell(values):
    if not values:
        return "n/a"
    if min(values) == max(values):
        return "%g" % values[0]
    return "%g (%g-%g)" % (statistics.median(values), min(values), max(values))


def families(out, command, page, host="orbslam2"):
    root = os.path.join(out, "families")
    summary = "%s_summary.csv" % host
    names = sorted(d for d in os.listdir(root) if os.path.exists(os.path.join(root, d, summary)))
    table = ["| Sequence | Runs | Stock ATE, cm | Box-only ATE, cm | Culler ATE, cm | Culler / stock | "
             "Lost frames: stock; box-only; culler |",
             "|---|---|---|---|---|---|---|"]
    csv = ["sequence,variant,runs,ate_median_m,ate_min_m,ate_max_m,lost_median,frames"]
    ratios, wins, no_more_lost = [], 0, 0
    for name in names:
        rows = read_summary(os.path.join(root, name, summary))
        medians, ranges, lost, lost_median, runs = {}, {}, {}, {}, 0
        for variant in VARIANTS:
            ate = numbers(rows, variant, "ate_rmse_m")
            lf = numbers(rows, variant, "lost_frames")
            mine = [r for r in rows if r["variant"] == variant]
            runs = max(runs, len(mine))
            frames = mine[0]["frames"] if mine else ""
            if ate:
                medians[variant] = statistics.median(ate)
                ranges[variant] = median_range(ate, scale=100)
                csv.append("%s,%s,%d,%.5f,%.5f,%.5f,%s,%s" % (name, variant, len(mine), medians[variant], min(ate), max(ate),
                                                             "%g" % statistics.median(lf) if lf else "", frames))
            lost[variant] = lost_cell(lf)
            if lf:
                lost_median[variant] = statistics.median(lf)
        ratio = ""
        if "stock" in medians and "culler" in medians and medians["stock"] > 0:
            r = medians["culler"] / medians["stock"]
            ratios.append(r)
            ratio = "%.2f" % r
        if "culler" in medians and "box_only" in medians and medians["culler"] < medians["box_only"]:
            wins += 1
        if "stock" in lost_median and "culler" in lost_median and lost_median["culler"] <= lost_median["stock"]:
            no_more_lost += 1
        cell = lambda v: ranges.get(v, "n/a")
        table.append("| %s | %d | %s | %s | %s | %s | %s |" % (name, runs, cell("stock"), cell("box_only"), cell("culler"),
                                                                ratio or "n/a", "; ".join(lost[v] for v in VARIANTS[:3])))
    with open(os.path.join(out, "%s_families.csv" % host), "w") as f:
        f.write("\n".join(csv) + "\n")
    text = "\n".join(table)
    print(text)
    if page:
        within = sum(1 for r in ratios if r <= 0.5)
        orbslam_page.write_families_section(page, host, text, (within, len(ratios), wins, len(names), no_more_lost),
                                            command)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("action", choices=["prepare", "summarise", "families"])
    parser.add_argument("sequence", help="the sequence folder (families: the output folder)")
    parser.add_argument("out", nargs="?", default="")
    parser.add_argument("--vocabulary", default="")
    parser.add_argument("--command", default="scripts/orbslam2.sh")
    parser.add_argument("--page", default="")
    parser.add_argument("--dyncull-eval", default=os.environ.get("DYNCULL_EVAL", "dyncull_eval"),
                        help="the dyncull_eval program (default: $DYNCULL_EVAL, else dyncull_eval on the PATH)")
    parser.add_argument("--host", choices=["orbslam2", "orbslam3"], default="orbslam2")
    parser.add_argument("--sensor", choices=["rgbd", "mono"], default="rgbd",
                        help="ORB-SLAM3's sensor (ORB-SLAM2 runs RGB-D only)")
    a = parser.parse_args()
    if a.host == "orbslam2" and a.sensor != "rgbd":
        parser.error("--sensor mono needs --host orbslam3")
    if a.action == "families":
        families(a.sequence, a.command, a.page, a.host)
    elif a.action == "prepare":
        prepare(a.sequence, a.out, a.dyncull_eval, a.host)
    else:
        summarise(a.sequence, a.out, a.vocabulary, a.command, a.page, a.host, a.sensor)


if __name__ == "__main__":
    main()
