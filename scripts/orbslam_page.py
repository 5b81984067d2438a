"""The results page's ORB-SLAM sections, written by orbslam2_sequence.py summarise / families --page:
"In ORB-SLAM2", "Scene families in ORB-SLAM2", "In ORB-SLAM3, RGB-D", "In ORB-SLAM3, monocular" and
"Scene families in ORB-SLAM3". Each section is replaced whole (or appended) and holds the command that
made it; the rest of the page is left as it is."""
import os
import platform
import re
import statistics
import subprocess
import sys
import textwrap

HOSTS = {
    "orbslam2": ("ORB-SLAM2", "raulmur/ORB_SLAM2 at f2e6f51", "integration.md#orb-slam2-the-patch"),
    "orbslam3": ("ORB-SLAM3", "UZ-SLAMLab/ORB_SLAM3 at 4452a3c (release V1.0)", "integration.md#orb-slam3-the-patch"),
}
VARIANT_TEXT = {
    "stock": "**stock** culls nothing (the culler is not called)",
    "box_only": "**box_only** removes every feature inside a person box (the YOLO forks' way)",
    "culler": "**culler** is the recommended preset with the sequence's own `detections/` (matched by timestamp)",
    "culler_live": "**culler_live** runs the YOLO detector (`DYNCULL_DETECTOR`) on its own thread beside "
                   "tracking, at the lowest priority: each frame is culled with the newest finished boxes carried "
                   "to it, and tracking never waits",
    "culler_live_sync": "**culler_live_sync** waits for each frame's own boxes in the tracking thread, as the YOLO "
                        "forks of ORB-SLAM do",
}


def section_heading(host, sensor):
    name = HOSTS[host][0]
    if host == "orbslam2":
        return "## In " + name
    return "## In %s, %s" % (name, "RGB-D" if sensor == "rgbd" else "monocular")


def write_sequence_section(page, host, sensor, table, rows, sequence, out, vocabulary, command, numbers, variants):
    """The section of one sequence: what ran, the table, ratios, timing, the trajectory figure, the setup."""
    name = os.path.basename(sequence.rstrip("/"))
    system, version, link = HOSTS[host]
    mono = sensor == "mono"
    present = [v for v in variants if any(r["variant"] == v for r in rows)]
    image = "images/%s_%s%s_trajectories.png" % (host, "mono_" if mono else "", name)
    os.makedirs(os.path.join(os.path.dirname(os.path.abspath(page)), "images"), exist_ok=True)
    drawn = plot_trajectories("%s on %s" % (system, name), out, rows, variants,
                              os.path.join(os.path.dirname(os.path.abspath(page)), image))
    example = "mono_tum" if mono else "rgbd_tum"
    setup = " ".join([
        "%s (%s, %s, `%s` with the viewer off) with the culler patch of [integration.md](%s), on `%s`."
        % (system, version, "monocular" if mono else "RGB-D", example, link, name),
        "One build; the variant is chosen at run time (`DYNCULL_MODE`): "
        + "; ".join(VARIANT_TEXT[v] for v in present) + ".",
        images_sentence(present, mono),
        "%s is multi-threaded and not deterministic, so every variant ran several times; ATE is against the "
        "sequence's camera ground truth (`dyncull_eval`, %s, the pairs %s wrote)."
        % (system, "Sim(3) alignment: scale too, as a monocular map has no metric scale" if mono
           else "SE(3) alignment", system),
        lost_sentence(host, mono, rows),
        timing_sentence(example, present, any(r["run"] == "free" for r in rows)),
    ])
    figure = ("![Ground truth and %s's aligned trajectories (the median-ATE run of each variant), top view](%s)"
              % (system, image)) if drawn else ""
    paragraphs = [section_heading(host, sensor), wrap(setup), table,
                  wrap(ratio_line(rows, numbers) + ".") if ratio_line(rows, numbers) else "",
                  wrap(timing_note(rows, numbers, variants)), figure, wrap(vocabulary_sentence(vocabulary)),
                  wrap("Machine: %s. Command: `%s` (per-run logs, trajectories and `%s_summary.csv` in its output "
                       "folder)." % (machine(), command, host))]
    lines = [p + "\n" for p in paragraphs if p]
    replace_section(page, section_heading(host, sensor), "\n".join(lines))


def wrap(paragraph):
    return textwrap.fill(paragraph, width=110, break_long_words=False, break_on_hyphens=False)


def images_sentence(present, mono):
    if mono:
        return "`mono_tum` reads the sequence's `rgb.txt` images (grey) and no depth."
    if any(v.startswith("culler_live") for v in present):
        return ("Tracking runs on the sequence's grey images (`rgb/`), except the live variants, which track on "
                "the colour images (`rgb_color/`, turned grey by the SLAM system after the detector has seen them).")
    return "Tracking runs on the sequence's grey images (`rgb/`) and depth."


def lost_sentence(host, mono, rows):
    frames = rows[0]["frames"] if rows else "?"
    what = "images of `rgb.txt`" if mono else "associated frames"
    text = ("A lost frame is a frame missing from the trajectory (the system leaves lost frames, and every frame "
            "before its map exists, out without a message), counted against the %s %s." % (frames, what))
    if host == "orbslam3":
        text += (" ORB-SLAM3 starts a new map in its Atlas when tracking is lost for good; the note column of "
                 "`orbslam3_summary.csv` counts the maps, and %s." % (
                     "the trajectory is the largest map's" if mono else "the trajectory holds every map's frames"))
    return text


def timing_sentence(example, present, free):
    text = ("Tracking time is what `%s` prints per run (mean and 95th percentile over frames, culling%s "
            "included); culling time is the glue's own mean per frame." % (
                example, " and a synchronous detector" if "culler_live_sync" in present else ""))
    if any(v.startswith("culler_live") for v in present):
        text += (" Detector time is per detection, on its thread, and box age the frames between a frame and the "
                 "one its boxes were detected on.")
    text += " These runs replay at the recorded rate"
    text += ("; one more run per variant (`DYNCULL_FREE_RUN=1`, the last column) fed frames as fast as the system "
             "took them, for the frames per second it sustains end to end (image loading included)." if free else ".")
    return text


def vocabulary_sentence(vocabulary):
    voc = os.path.basename(vocabulary) if vocabulary else "?"
    if "synthetic" not in voc:
        return "Vocabulary: `%s`." % voc
    return ("Vocabulary: `%s`, trained by the script with ORB-SLAM2's bundled DBoW2 (k = 10, L = 5) on synthetic "
            "frames of dyncull's scene (480 frames, four camera motions), because the published ORBvoc.txt is not "
            "available here; no evaluated frame was used to train it." % voc)


def ratio_line(rows, numbers):
    stock = numbers(rows, "stock", "ate_rmse_m")
    out = []
    for variant in ("box_only", "culler"):
        v = numbers(rows, variant, "ate_rmse_m")
        if stock and v:
            out.append("%s / stock median ATE: %.2f" % (variant, statistics.median(v) / statistics.median(stock)))
    for variant in ("box_only", "culler"):
        fewest = numbers(rows, variant, "fewest_kept")
        if fewest:
            out.append("%s keeps %d features in its leanest frame (fewest over its runs)" % (variant, min(fewest)))
    ts, tc = numbers(rows, "stock", "track_ms"), numbers(rows, "culler", "track_ms")
    if ts and tc:
        out.append("culler / stock median tracking time: %.2f" % (statistics.median(tc) / statistics.median(ts)))
    for column, what in (("ate_rmse_m", "median ATE"), ("track_ms_p95", "tracking time, 95th percentile")):
        offline, live = numbers(rows, "culler", column), numbers(rows, "culler_live", column)
        if offline and live:
            out.append("culler_live / culler %s: %.2f" % (what, statistics.median(live) / statistics.median(offline)))
    return "; ".join(out)


def timing_note(rows, numbers, variants):
    """How far tracking times spread within one variant, and the culler's own share of stock's time."""
    spreads = []
    for variant in variants:
        t = numbers(rows, variant, "track_ms")
        if len(t) > 1:
            spreads.append((max(t) - min(t)) / statistics.median(t))
    ts, cull = numbers(rows, "stock", "track_ms"), numbers(rows, "culler", "cull_ms")
    parts = []
    if spreads:
        parts.append("Tracking times of one variant spread over up to %.0f %% of their median between runs here, "
                     "so differences between the variants' tracking times below that are noise" % (100 * max(spreads)))
    if ts and cull:
        parts.append("The culler's own time, %.2f ms per frame (median of its runs), is %.1f %% of stock's median "
                     "tracking time" % (statistics.median(cull), 100 * statistics.median(cull) / statistics.median(ts)))
    return ("; the culler's".join(" ".join(parts).split(" The culler's")) + ".") if parts else ""


def median_runs(out, rows, variants):
    """Per variant, the run with the median ATE that has dyncull_eval's poses.csv (its pairs, aligned as the
    ATE aligns them): [(variant, run, ate_m, poses path)]."""
    chosen = []
    for variant in variants:
        mine = sorted((float(r["ate_rmse_m"]), int(r["run"])) for r in rows
                      if r["variant"] == variant and r["ate_rmse_m"] and r["run"] != "free")
        if not mine:
            continue
        ate, run = mine[(len(mine) - 1) // 2]
        poses = os.path.join(out, "runs", variant, "run%d" % run, "poses.csv")
        if os.path.exists(poses):
            chosen.append((variant, run, ate, poses))
    return chosen


def plot_trajectories(title, out, rows, variants, path):
    """scripts/figures.py's trajectory panels (matplotlib) of each variant's median run. Returns the runs drawn."""
    chosen = median_runs(out, rows, variants)
    if chosen:
        import figures  # matplotlib: only when there is something to draw
        runs = {}
        for variant, run, _, poses in chosen:
            runs.update(figures.read_poses(poses, "%s (run %d)" % (variant, run)))
        figures.plot_trajectories(runs, title, path)
    return chosen


def write_families_section(page, host, table, counts, command):
    """The scene families' section: counts = (within half of stock, sequences with a ratio, culler below
    box-only, sequences, culler losing no more than stock)."""
    system = HOSTS[host][0]
    within, with_ratio, wins, sequences, no_more_lost = counts
    section = "\n".join([
        "## Scene families in " + system,
        "",
        "The same %s build and variants as above (RGB-D), on every scene family with the camera motions of the"
        % system,
        "command, written as TUM-format sequences by `write_tum_sequence --family NAME` (seed 1) with the",
        "simulated detector's boxes (`detections_json/`). ATE and lost frames: median (range) over the runs; lost",
        "frames as above.",
        "The vocabulary was trained on frames of the same synthetic room (another seed, the walking family), so",
        "it fits these scenes better than it fits the real sequence.",
        "",
        table,
        "",
        "Culler at most 0.5x stock's median ATE on %d of %d sequences; culler below box-only on %d of %d; culler "
        "losing no more frames than stock (medians) on %d of %d. Where a variant lost frames, its ATE covers only "
        "the frames it tracked: read the two columns together." % (
            within, with_ratio, wins, sequences, no_more_lost, sequences),
        "",
        "Command: `%s`." % command,
        "",
    ])
    replace_section(page, "## Scene families in " + system, section)


def machine():
    cpu = ""
    try:
        cpu = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        cpu = re.search(r"Model name:\s*(.*)", cpu).group(1)
    except (OSError, AttributeError):
        cpu = platform.processor()
    return "%s, %d cores" % (cpu, os.cpu_count() or 0)


def replace_section(page, heading, section):
    text = open(page).read() if os.path.exists(page) else "# Results\n"
    m = re.search(r"^" + re.escape(heading) + r"\n.*?(?=^## |\Z)", text, flags=re.S | re.M)
    if m:
        text = text[:m.start()] + section + "\n" + text[m.end():]
    else:
        text = text.rstrip("\n") + "\n\n" + section
    with open(page, "w") as f:
        f.write(text.rstrip("\n") + "\n")
    print("orbslam2_sequence.py: wrote the %s section of %s" % (heading[3:], page), file=sys.stderr)
