#!/usr/bin/env python3
"""Writes docs/benchmarks.md from a run of scripts/benchmarks.sh.

    scripts/benchmarks_page.py RUN_DIR PAGE

RUN_DIR holds one Google Benchmark JSON file per bench binary (bench_<module>_<name>_bench.json, and
bench_<...>.<part>.json for a second invocation of the same binary), run_info.txt (machine, compiler,
libraries, commit, command, wall time) and, when the compile-cost scripts wrote them, compile_cost.csv and
compile_cost_host.csv (unit,user_s,wall_s,peak_rss_mb). Every figure on the page comes from these files:
rerunning the script regenerates it.
"""
import csv
import glob
import json
import os
import re
import statistics
import sys

# ---------------------------------------------------------------------------------------------- reading


class Run:
    """The benchmarks of one run: per binary, the median aggregate of each case (or its single run)."""

    def __init__(self, directory):
        self.dir = directory
        self.cases = {}     # binary -> {run name -> record}
        self.order = {}     # binary -> [run name] in the order the binary ran them
        self.context = {}   # binary -> Google Benchmark's context (load average, cpus)
        for path in sorted(glob.glob(os.path.join(directory, "bench_*.json"))):
            binary = os.path.basename(path).split(".")[0]
            with open(path, encoding="utf-8") as f:
                data = json.load(f)
            self.context.setdefault(binary, data.get("context", {}))
            cases = self.cases.setdefault(binary, {})
            order = self.order.setdefault(binary, [])
            for b in data.get("benchmarks", []):
                name = b.get("run_name", b["name"])
                if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
                    continue
                if name not in cases:
                    order.append(name)
                cases[name] = b

    def get(self, binary, name):
        return self.cases.get(binary, {}).get(name)

    def cpu_ns(self, binary, name):
        b = self.get(binary, name)
        if b is None:
            return None
        return b["cpu_time"] * UNIT_NS[b.get("time_unit", "ns")]

    def counter(self, binary, name, key):
        b = self.get(binary, name)
        return None if b is None or key not in b else float(b[key])

    def ratio(self, binary, ours, peer):
        a, b = self.cpu_ns(binary, ours), self.cpu_ns(binary, peer)
        return None if a is None or not b else a / b


UNIT_NS = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}
STANDARD_KEYS = {"name", "family_index", "per_family_instance_index", "run_name", "run_type", "repetitions",
                 "repetition_index", "threads", "aggregate_name", "aggregate_unit", "iterations", "real_time",
                 "cpu_time", "time_unit", "label", "error_occurred", "error_message"}


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def fmt(v, digits=3):
    """A number with `digits` significant digits, without exponent for everyday magnitudes."""
    if v is None:
        return "-"
    if v == 0:
        return "0"
    if abs(v) >= 10 ** digits:
        return f"{v:.0f}"
    if abs(v) < 1e-3:
        return f"{v:.{digits - 1}e}"
    return f"{v:.{digits}g}"


def fmt_time(ns):
    if ns is None:
        return "-"
    for unit, scale in (("s", 1e9), ("ms", 1e6), ("us", 1e3)):
        if ns >= scale:
            return f"{fmt(ns / scale)} {unit}"
    return f"{fmt(ns)} ns"


def fmt_ratio(r):
    return "-" if r is None else f"{r:.3g}x"


# ---------------------------------------------------------------------------------------------- targets


def met_text(ok):
    return "not measured" if ok is None else ("**yes**" if ok else "**no**")


def targets(run):
    """(hot path, target, measured, met) rows, each computed from one binary's JSON."""
    rows = []
    binary = [None]

    def row(path, target, measured, ok):
        if binary[0] not in run.cases:
            measured, ok = f"not in this run (`{binary[0]}`)", None
        rows.append((path, target, measured, ok))

    # F-RANSAC: median over the five data sets of the per-set ratio to USAC_FAST.
    b = binary[0] = "bench_geometry_fundamental_bench"
    per = {}
    for t in ("float", "double"):
        rs = [run.ratio(b, f"BM_Ours_FRansac<{t}>/{s}", f"BM_OpenCV_USAC_FAST/{s}") for s in range(1, 6)]
        rs = [r for r in rs if r is not None]
        per[t] = (statistics.median(rs), min(rs), max(rs)) if rs else None
    rec = [(run.counter(b, f"BM_Ours_FRansac<float>/{s}", "recall"), run.counter(b, f"BM_OpenCV_USAC_FAST/{s}", "recall"))
           for s in range(1, 6)]
    rec = [(a, c) for a, c in rec if a is not None and c is not None]
    if per["float"] and per["double"]:
        better = sum(a >= c for a, c in rec)
        row("F-RANSAC, 1000 correspondences, 30 % outliers", "<= 0.5x `cv::findFundamentalMat` USAC_FAST",
            f"median of per-set ratios: float {per['float'][0]:.2f}x, double {per['double'][0]:.2f}x "
            f"(float per set {per['float'][1]:.2f}-{per['float'][2]:.2f}x); recall >= USAC's on {better}/{len(rec)} sets",
            per["float"][0] <= 0.5 and per["double"][0] <= 0.5)
    else:
        row("F-RANSAC, 1000 correspondences", "<= 0.5x USAC_FAST", "not in this run", None)

    b = binary[0] = "bench_geometry_pnp_bench"
    r = run.ratio(b, "BM_dyncull_pnp_ransac<double>/1000", "BM_opencv_pnp_ransac/1000/2")
    if r is not None:
        e = [run.counter(b, n, k) for n in ("BM_dyncull_pnp_ransac<double>/1000", "BM_opencv_pnp_ransac/1000/2")
             for k in ("rot_err_deg", "trans_err_mm")]
        ok_err = None not in e and e[0] <= e[2] and e[1] <= e[3]
        row("PnP-RANSAC, 1000 correspondences, 30 % outliers", "<= 0.5x `cv::solvePnPRansac` P3P, errors at least as good",
            f"{r:.2f}x; {fmt(e[0])} deg / {fmt(e[1])} mm against {fmt(e[2])} deg / {fmt(e[3])} mm", r <= 0.5 and ok_err)
    else:
        row("PnP-RANSAC, 1000 correspondences", "<= 0.5x solvePnPRansac P3P", "not in this run", None)

    b = binary[0] = "bench_geometry_epipolar_bench"
    rf = run.ratio(b, "BM_Ours_PointToLine<float>/1000", "BM_OpenCV_Epilines_Loop/1000")
    rd = run.ratio(b, "BM_Ours_PointToLine<double>/1000", "BM_OpenCV_Epilines_Loop_Double/1000")
    row("epipolar point-line distances, 1000 points", "<= 0.5x `computeCorrespondEpilines` + distance loop",
        f"float {fmt_ratio(rf)}, double {fmt_ratio(rd)} (against the double peer)",
        None if rf is None or rd is None else rf <= 0.5 and rd <= 0.5)

    b = binary[0] = "bench_geometry_rigid_bench"
    r = run.ratio(b, "BM_dyncull_umeyama/1000/0", "BM_eigen_umeyama/1000/0")
    d = run.counter(b, "BM_dyncull_umeyama/1000/0", "max_diff_vs_eigen")
    row("Umeyama SE(3), 1000 pairs", "<= 0.5x `Eigen::umeyama`, same result to 1e-12",
        f"{fmt_ratio(r)}, largest difference {fmt(d, 2)}", None if r is None or d is None else r <= 0.5 and d <= 1e-12)

    b = binary[0] = "bench_geometry_rotation_centre_bench"
    rn = run.ratio(b, "BM_NormalEquations<double>/500", "BM_CeresBfgs/500")
    rb = run.ratio(b, "BM_OurBfgs/500", "BM_CeresBfgs/500")
    en = run.counter(b, "BM_NormalEquations<double>/500", "err_vs_ceres_px")
    eb = run.counter(b, "BM_OurBfgs/500", "err_vs_ceres_px")
    ok = None if None in (rn, rb, en, eb) else rn <= 0.1 and rb <= 0.5 and max(en, eb) <= 1e-6
    row("rotation centre, 500 flow vectors", "exact solve <= 0.1x Ceres BFGS, our BFGS <= 0.5x, agreement 1e-6 px",
        f"exact {fmt_ratio(rn)}, BFGS {fmt_ratio(rb)}; distance to Ceres' minimum {fmt(en, 2)} / {fmt(eb, 2)} px", ok)

    b = binary[0] = "bench_geometry_icp_bench"
    peer = next((n for n in run.order.get(b, []) if n.startswith("BM_open3d_icp") and "skipped" not in n), None)
    if peer:
        r = run.ratio(b, "BM_dyncull_icp", peer)
        row("ICP point-to-point, 5000 + 5000 points, 30 iterations", "<= 0.5x Open3D", fmt_ratio(r), r <= 0.5)
    else:
        row("ICP point-to-point, 5000 + 5000 points, 30 iterations", "<= 0.5x Open3D",
            f"Open3D not found at build time (dyncull alone: {fmt_time(run.cpu_ns(b, 'BM_dyncull_icp'))})", None)

    b = binary[0] = "bench_culling_pipeline_bench"
    for name, what in (("BM_Pipeline_Recommended", "recommended preset"),
                       ("BM_Pipeline_RecommendedWithPoints", "given 3-D points (reprojection check)"),
                       ("BM_Pipeline_RecommendedWithPointsAndIds", "given 3-D points and track ids (static history)")):
        r = run.ratio(b, name, "BM_Pipeline_PeerLK")
        row(f"culling pipeline, one frame of ~1100 features, 5 boxes, 640x480: {what}",
            "<= 0.05x `calcOpticalFlowPyrLK` on the same features",
            "not in this run" if r is None else
            f"{r:.3f}x ({fmt_time(run.cpu_ns(b, name))} against {fmt_time(run.cpu_ns(b, 'BM_Pipeline_PeerLK'))})",
            None if r is None else r <= 0.05)

    b = binary[0] = "bench_culling_culler_bench"
    v = run.counter(b, "BM_CullerPerFrame", "vs_orb")
    row("the culler's whole per-frame cost (its matching to the keyframe included), ~1000 ORB features, 640x480",
        "<= 0.35x `cv::ORB::detectAndCompute` of those features",
        "not in this run" if v is None else
        f"{v:.3f}x ({fmt(run.counter(b, 'BM_CullerPerFrame', 'frame_us'))} us against "
        f"{fmt(run.counter(b, 'BM_CullerPerFrame', 'orb_us'))} us)", None if v is None else v <= 0.35)

    b = binary[0] = "bench_culling_keyframe_matcher_bench"
    v = run.counter(b, "BM_KeyframeMatcher/0", "vs_orb")
    row("the culler's correspondence step alone (guided matching to the keyframe)", "< 0.1x ORB detectAndCompute",
        "not in this run" if v is None else f"{v:.3f}x", None if v is None else v < 0.1)

    b = binary[0] = "bench_culling_depth_mask_bench"
    floor = "BM_DepthMask_MemcpyFloor"
    one_pass = [run.ratio(b, n, floor) for n in ("BM_DepthMask_Plain", "BM_DepthMask_RobustMissingInMask")]
    rp = run.ratio(b, "BM_DepthMask_Plain", "BM_DepthMask_OpenCVInRange")
    rn = run.ratio(b, "BM_DepthMask_Robust", floor)
    rc = run.ratio(b, "BM_DepthMask_Robust", "BM_DepthMask_OpenCVNearestFill")
    ok = None if None in one_pass else all(r <= 2 for r in one_pass)
    row("depth mask, 200x300 box of a 640x480 image", "within 2x of a memory pass over the box (the one-pass modes)",
        f"plain {fmt_ratio(one_pass[0])} ({fmt_ratio(rp)} of `cv::inRange`), robust with holes in the mask "
        f"{fmt_ratio(one_pass[1])}; the default (`MissingDepth::Nearest`, not one pass: distance transforms where "
        f"holes are wide) {fmt_ratio(rn)}, {fmt_ratio(rc)} of the same rule written with OpenCV", ok)
    b = binary[0] = "bench_culling_moving_consistency_bench"
    r = run.ratio(b, "BM_MovingConsistency_Dyncull/0/0", "BM_MovingConsistency_PartsFloor")
    row("epipolar moving-consistency check, ~1100 tracks", "within 1.2x of F-RANSAC + one batch distance pass",
        fmt_ratio(r), None if r is None else r <= 1.2)

    for csv_name, unit, base, path, target, limit in (
            ("compile_cost.csv", "instantiate_precompiled", "instantiate",
             "compile cost of a unit instantiating the pipeline, linked to `dyncull::pipeline`",
             "<= 0.5x the header-only instantiation (user time and peak RSS)", 0.5),
            ("compile_cost_host.csv", "host_front_end_culler", "host_front_end",
             "compile cost of a host front-end unit calling the compiled culler",
             "<= 2x the same unit without dyncull (user time and peak RSS)", 2.0)):
        units = read_units(run.dir, csv_name)
        a, c = units.get(unit), units.get(base)
        binary[0] = next(iter(run.cases), None)  # the CSV, not a binary, decides
        if a and c and float(c["user_s"]) > 0 and float(c["peak_rss_mb"]) > 0:
            ru, rm = float(a["user_s"]) / float(c["user_s"]), float(a["peak_rss_mb"]) / float(c["peak_rss_mb"])
            row(path, target, f"{ru:.2f}x time, {rm:.2f}x peak RSS ({fmt(float(a['user_s']))} s, "
                f"{fmt(float(a['peak_rss_mb']), 4)} MB)", ru <= limit and rm <= limit)
        else:
            rows.append((path, target, f"not in this run ({csv_name})", None))
    return rows


def read_units(directory, name):
    path = os.path.join(directory, name)
    if not os.path.exists(path):
        return {}
    with open(path, newline="", encoding="utf-8") as f:
        return {r["unit"]: r for r in csv.DictReader(f) if r.get("unit")}


# Peers measured without a numeric target: (binary, what, ours, peer).
OTHER_PEERS = [
    ("bench_geometry_ransac_bench", "generic LO-RANSAC, 2-D affine, 30 % outliers", "BM_Dyncull_RansacAffine/30",
     "`cv::estimateAffine2D`", "BM_OpenCV_EstimateAffine2D/30"),
    ("bench_geometry_ransac_bench", "generic LO-RANSAC, 2-D affine, 60 % outliers", "BM_Dyncull_RansacAffine/60",
     "`cv::estimateAffine2D`", "BM_OpenCV_EstimateAffine2D/60"),
    ("bench_geometry_fundamental_bench", "8-point on the true inliers", "BM_Ours_8Point_Inliers",
     "`findFundamentalMat` FM_8POINT", "BM_OpenCV_FM_8POINT_Inliers"),
    ("bench_geometry_pnp_bench", "pose refinement (LM), 1000 points", "BM_dyncull_refine_pose/1000",
     "`cv::solvePnPRefineLM`", "BM_opencv_refine_lm/1000"),
    ("bench_geometry_projection_bench", "project 1000 points (float)", "BM_dyncull_project_points<float>",
     "`cv::projectPoints`", "BM_opencv_project_points"),
    ("bench_geometry_projection_bench", "depth to points, 640x480 with a mask", "BM_dyncull_depth_to_points/1",
     "naive per-pixel back-projection loop", "BM_naive_depth_to_points"),
    ("bench_geometry_bfgs_bench", "BFGS, Rosenbrock", "BM_Dyncull_Bfgs<Rosenbrock>", "Ceres BFGS",
     "BM_Ceres_Bfgs<Rosenbrock>"),
    ("bench_geometry_bfgs_bench", "BFGS, 6-D quadratic, condition 1e4", "BM_Dyncull_Bfgs<Quadratic6>", "Ceres BFGS",
     "BM_Ceres_Bfgs<Quadratic6>"),
    ("bench_geometry_icp_bench", "k-d tree nearest neighbours, 5000 queries", "BM_dyncull_kdtree_nn/12",
     "nanoflann (leaf 10)", "BM_nanoflann_kdtree_nn/10"),
    ("bench_culling_box_rule_bench", "box rule, 1000 keypoints x 5 boxes", "BM_BoxRule_Dyncull/5",
     "`cv::Rect2f::contains` loop", "BM_BoxRule_OpenCVRectContains/5"),
    ("bench_culling_keep_mask_bench", "keep-mask compaction, 1000 features", "BM_Keep_Compact",
     "`push_back` + `Mat::push_back`", "BM_Keep_OpenCVRebuild"),
    ("bench_culling_keep_mask_bench", "dynamic-region raster, 640x480, 5 boxes", "BM_Keep_Rasterise",
     "`setTo` + `cv::rectangle`", "BM_Keep_OpenCVRectangles"),
    ("bench_culling_descriptor_switch_bench", "Hamming matching, 1000 x 1000", "BM_MatchHamming/1000/0",
     "`cv::BFMatcher`", "BM_OpenCvBfMatcherHamming/1000/0"),
    ("bench_culling_descriptor_switch_bench", "L2 matching, 1000 x 1000, 256 floats", "BM_MatchL2/1000/256",
     "`cv::BFMatcher`", "BM_OpenCvBfMatcherL2/1000/256"),
    ("bench_culling_descriptor_switch_bench", "5 nearest of 200 keyframes (eq. 18)", "BM_NearestKeyframes/200",
     "`cv::norm` loop + partial sort", "BM_OpenCvNormKeyframes/200"),
    ("bench_culling_reprojection_check_bench", "reprojection check, ~1100 tracks", "BM_ReprojectionCheck_Dyncull",
     "`solvePnPRansac` + `projectPoints`", "BM_ReprojectionCheck_OpenCV"),
    ("bench_culling_subbox_refine_bench", "sub-box mask with 15 px dilation", "BM_SubBox_Mask_Dyncull", "`cv::dilate`",
     "BM_SubBox_Mask_PeerCvDilate"),
    ("bench_culling_multiview_check_bench", "multi-view region growing", "BM_MultiView_Grow_Dyncull",
     "`cv::floodFill`", "BM_MultiView_Grow_PeerCvFloodFill"),
    ("bench_culling_detections_bench", "YOLO text, 20 boxes", "BM_ParseYolo_Dyncull", "`std::istringstream` loop",
     "BM_ParseYolo_Istringstream"),
    ("bench_eval_ate_bench", "TUM association, 2000 poses", "BM_Associate/2000", "`associate.py`'s algorithm in C++",
     "BM_AssociateNaiveAssociatePy/2000"),
    ("bench_sim_scene_bench", "Kinect depth model", "BM_DepthNoise", "OpenCV noise + quantisation (less work)",
     "BM_DepthNoiseOpenCv"),
]


def other_peers(run):
    out = ["| case | dyncull | peer | peer time | ratio |", "|---|---|---|---|---|"]
    for binary, what, ours, peer_text, peer in OTHER_PEERS:
        r = run.ratio(binary, ours, peer)
        if r is not None:
            out.append(f"| {what} | {fmt_time(run.cpu_ns(binary, ours))} | {peer_text} | "
                       f"{fmt_time(run.cpu_ns(binary, peer))} | {fmt_ratio(r)} |")
    return "\n".join(out) if len(out) > 2 else "(none of these binaries was in this run)"


def stages(run):
    b = "bench_culling_stages_bench"
    names = [n for n in run.order.get(b, []) if n.startswith("BM_Stage_")]
    if not names:
        return "(bench_culling_stages_bench was not in this run)"
    out = ["| stage | CPU per frame | counters |", "|---|---|---|"]
    for n in names:
        out.append(f"| {STAGE_TEXT.get(n, n)} | {fmt_time(run.cpu_ns(b, n))} | {counters_text(run.get(b, n))} |")
    total = sum(run.cpu_ns(b, n) for n in names)
    out.append(f"| **sum of the stages** | **{fmt_time(total)}** | |")
    return "\n".join(out)


STAGE_TEXT = {
    "BM_Stage_Inputs": "inputs (contract checks)",
    "BM_Stage_Boxes": "boxes (detection filter, tracker)",
    "BM_Stage_Semantic": "semantic (box rule, depth masks)",
    "BM_Stage_Geometric": "geometric (epipolar and reprojection checks)",
    "BM_Stage_Probability": "dynamic probability",
    "BM_Stage_RegionVotes": "region votes (coherent cells, sub-boxes)",
    "BM_Stage_MultiView": "multi-view check",
    "BM_Stage_Combine": "combine (evidence, static history, guard)",
}


def allocations(run):
    b = "bench_culling_allocations_bench"
    names = [n for n in run.order.get(b, []) if n.startswith("BM_Allocations")]
    if not names:
        return "(bench_culling_allocations_bench was not in this run)"
    out = ["| preset | allocations per frame after warm-up (most of any frame) | mean | CPU per 3 frames |",
           "|---|---|---|---|"]
    for n in names:
        rec = run.get(b, n)
        out.append(f"| {rec.get('label', n)} | {fmt(run.counter(b, n, 'allocs_per_frame'))} | "
                   f"{fmt(run.counter(b, n, 'allocs_mean'))} | {fmt_time(run.cpu_ns(b, n))} |")
    return "\n".join(out)


def compile_cost(directory, name, baseline, baseline_text):
    """The CSV's units as a table; with `baseline` (a unit name, or None for the first line) a column of
    user time and peak memory over that unit's."""
    path = os.path.join(directory, name)
    if not os.path.exists(path):
        return None
    with open(path, newline="", encoding="utf-8") as f:
        rows = [r for r in csv.DictReader(f) if r.get("unit")]
    if not rows:
        return None
    base = rows[0] if baseline is None else next((r for r in rows if r["unit"] == baseline), None)
    head = "| translation unit | user time | wall | peak RSS |"
    sep = "|---|---|---|---|"
    if base:
        head += f" x {baseline_text} (user time / peak RSS) |"
        sep += "---|"
    out = [head, sep]
    for r in rows:
        u, w, m = float(r["user_s"]), float(r["wall_s"]), float(r["peak_rss_mb"])
        line = f"| `{r['unit']}` | {fmt(u)} s | {fmt(w)} s | {fmt(m, 4)} MB |"
        if base:
            bu, bm = float(base["user_s"]), float(base["peak_rss_mb"])
            line += f" {fmt(u / bu) if bu else '-'} / {fmt(m / bm) if bm else '-'} |"
        out.append(line)
    return "\n".join(out)


# ---------------------------------------------------------------------------------------------- tables


def counters_text(b):
    if b is None:
        return ""
    out = []
    for k in b:
        if k in STANDARD_KEYS or not isinstance(b[k], (int, float)):
            continue
        if k == "bytes_per_second":
            out.append(f"{fmt(b[k] / 1e9)} GB/s")
        elif k == "items_per_second":
            out.append(f"{fmt(b[k] / 1e6)} M items/s")
        else:
            out.append(f"{k} {fmt(float(b[k]))}")
    return ", ".join(out)


def binary_table(run, binary):
    labels = any(run.cases[binary][n].get("label") or run.cases[binary][n].get("error_occurred")
                 for n in run.order[binary])
    out = ["| case |" + (" label |" if labels else "") + " CPU | wall | counters |",
           "|---|" + ("---|" if labels else "") + "---|---|---|"]
    for n in run.order[binary]:
        b = run.cases[binary][n]
        if b.get("error_occurred"):
            out.append(f"| `{n}` | {b.get('error_message', '')} | - | - | |")
            continue
        unit = UNIT_NS[b.get("time_unit", "ns")]
        label = f" {b.get('label', '')} |" if labels else ""
        out.append(f"| `{n}` |{label} {fmt_time(b['cpu_time'] * unit)} | "
                   f"{fmt_time(b['real_time'] * unit)} | {counters_text(b)} |")
    return "\n".join(out)


def source_comment(binary):
    """The leading comment of the binary's source: what it measures, as the bench says it."""
    m = re.match(r"bench_([a-z]+)_(.+)$", binary)
    if not m:
        return ""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "bench", m.group(1), m.group(2) + ".cpp")
    if not os.path.exists(path):
        return ""
    lines = []
    for line in read(path).splitlines():
        if not line.startswith("//"):
            break
        lines.append(line[2:].strip())
    return " ".join(lines)


# What each binary measures, beyond its source's opening comment: data, peers, how to read the counters.
PROSE = {
    "bench_geometry_fundamental_bench": """Data (`tests/support/two_view.hpp`): 1000 correspondences, fx = fy = 535,
640x480, 0.5 px Gaussian noise in both images, 30 % outliers (at least 3 px off their epipolar line), five data
sets (the benchmark argument is the seed). Threshold 1 px and confidence 0.99 for every method; OpenCV pinned to one
thread. Counters: `recall` / `precision` of the true inliers, `sampson_rms_px` = RMS Sampson distance of the
noise-free true correspondences under the estimated F (how well F models the truth). With 0.5 px noise per image
P(Sampson < 1 px) = 95.4 %, the recall ceiling. Hypotheses are scored with float Sampson distances for both scalar
types; the 7-point solves, the refits and the returned F are double for `T = double`.""",
    "bench_geometry_epipolar_bench": """For packed (x, y) containers (Eigen 2-vectors, `cv::Point_<T>`, `{T x, y}`
structs) `epipolar_distances(F, points1, points2, out)` reads the pairs and writes the distances in one SSE2 pass;
other distance kinds and containers (e.g. `cv::KeyPoint`) go through a block copy. `BM_OpenCV_Epilines_Loop_Double`
gives OpenCV `cv::Point2d` input, the peer of the double rows. Without `-march` double arithmetic is 2-wide SSE2,
half the float throughput.""",
    "bench_geometry_rigid_bench": """SE(3) (`/0`) and Sim(3) (`/1`) for 100, 1000 and 10000 pairs; the counter is the
largest coefficient difference from `Eigen::umeyama`'s result.""",
    "bench_geometry_pnp_bench": """1000 (and 100) correspondences, 0.5 px noise, 30 % outliers, 8 scenes cycled,
2 px threshold, confidence 0.99, at most 1000 iterations for both; `BM_opencv_pnp_ransac/N/2` is P3P and `/N/1`
EPnP. Errors are means over the timed calls.""",
    "bench_geometry_icp_bench": """Both ICPs are forced to 30 iterations (tolerances 0), maximum correspondence distance
0.05 m; dyncull's time includes building its k-d tree. Open3D (Debian `libopen3d-dev`) is the peer when CMake finds
it (`OMP_NUM_THREADS=1`); nanoflann is the peer of the nearest-neighbour kernel.""",
    "bench_geometry_projection_bench": """`cv::rgbd::depthTo3d` would be the natural peer of `depth_to_points` but
opencv_rgbd is not among the components the build links; the naive loop writes less (no pixel index, no counts).
The voxel grid sorts 64-bit keys.""",
    "bench_geometry_rotation_centre_bench": """500 flow vectors of a 0.3 rad rotation about (350, 210), 0.5 px noise
per end, the same normalised bisectors for every solver, started at the image centre. `err_vs_ceres_px` = distance
to a tightly converged Ceres minimiser, `err_vs_truth_px` = distance to the true centre (limited by the noise).
`BM_Robust/loss/solver`: 30 % of the vectors translate (a walking person), scale 2 px; loss 0 Huber, 1 Cauchy;
`BM_FullAlgorithm2` is the whole algorithm from point containers (bisectors, fit, eq. 15 filter, eq. 16 angle).""",
    "bench_geometry_bfgs_bench": """Our BFGS needs more iterations than Ceres on the ill-conditioned quadratic (its
first step is not rescaled) but each costs a fraction of Ceres' per-iteration overhead.""",
    "bench_geometry_ransac_bench": """The affine estimator in `bench/geometry/ransac_bench.cpp` is about 25 lines:
all a user writes to put a new model on the engine.""",
    "bench_culling_box_rule_bench": """Counter `dynamic` is the same for the three implementations. Ours also fills
reasons and the deciding box index: points copied once to SoA, an SSE2 block of 16 points against all boxes, then
a 16-entry decision table.""",
    "bench_culling_depth_mask_bench": """Wall at about 3 m, a person at about 1.5 m in the box centre, 3 % Kinect holes.
`Plain` and `RobustMissingInMask` are one pass (unsigned compares OR-ed into the mask); `RobustHistogramFallback`
(no corner depth) samples at most 4096 pixels into histograms first; `Robust` is the default (`MissingDepth::Nearest`:
a hole takes the side of its nearest measured pixel), which needs distance transforms where holes are wide, and
`OpenCVNearestFill` is that rule written with OpenCV. The pipeline labels points, never this raster.""",
    "bench_culling_dynamic_probability_bench": """1000 features, 300 in 5 masks, 120 true movers. The baseline is the
paper's plain loop (mean flow, fixed threshold); the extra cost is four medians and the track store's hash map.""",
    "bench_culling_keep_mask_bench": """Compaction of 1000 features (keypoint, 32-byte descriptor row, depth) with
30 % culled, a 640x480 raster of 5 boxes, and the region predicate at random pyramid levels.""",
    "bench_culling_moving_consistency_bench": """Data for the culling benches (`tests/support/culling_scenes.hpp`):
1102 features of which 1100 tracked, 30 % on movers, 0.25 px noise per end, 640x480 float depth, 5 boxes (two
people, chair, TV, cup). `Dyncull/refits/boxes`: the number of refits and whether the fit uses only the features
outside the boxes (the default is 2/1); `PartsFloor` is our F-RANSAC plus one batch distance pass, the floor of
the 1.2x target. Without boxes every estimator is inaccurate on this small-baseline frame.""",
    "bench_culling_reprojection_check_bench": """Each track's exact 3-D point at the previous frame; `DyncullWithDepth`
the depth residual the preset uses; the OpenCV peer is `solvePnPRansac`
(P3P, 300 iterations, 2 px, 0.999) plus `projectPoints` with the same thresholds.""",
    "bench_culling_pipeline_bench": """One frame of the culling scene (about 1100 features, 5 boxes, 640x480 depth, a
keyframe 8 frames back) through `cull_frame`, against pyramidal LK (21x21, 3 levels) of the same features between
two textured 640x480 frames. `RecommendedWithout/k` switches one stage off (0 assignment of overlapping masks by
depth, 1 depth mask, 2 sub-box, 3 moving consistency, 4 box tracker, 5 low-level shelter by depth). Counters:
precision and recall of the dynamic labels against the scene's truth, and which optional stages ran.""",
    "bench_culling_culler_bench": """`Culler` (`culling/culler.hpp`) does everything the recommended preset needs per
frame: guided descriptor matching to its keyframe, 3-D points from the keyframe's depth, track ids, keyframe
decisions and `cull_frame`. 30 frames of the synthetic walking scene, 1000 ORB features each; the first frame (no
keyframe yet) is not timed. The CPU time of `BM_CullerPerFrame` is one pass over the sequence; the per-frame figure
is the counter `frame_us`, and `vs_orb` divides it by ORB's median time on the same frames, measured in the binary.""",
    "bench_culling_keyframe_matcher_bench": """`BM_KeyframeMatcher/k`: the guided matching alone, with its variants;
`BM_OpenCvPyrLK/window/levels` shows what optical flow of the same points would cost.""",
    "bench_culling_stages_bench": """The earlier stages run once before the timed loop; the loop repeats only the
stage named.""",
    "bench_culling_allocations_bench": """Counts `operator new` calls inside `cull_frame` (a counting global allocator
in this binary only), so its times include that count.""",
    "bench_sim_scene_bench": """Rendering is ray casting of 640x480 frames with the Kinect-like depth model
(`BM_RenderFrame/motion/depth model`); the OpenCV depth-noise peer does less (no discontinuity holes, no border band).
`BM_FrontEndPull/motion/culled/wall contrast %`: OpenCV ORB (1500 features), cross-checked Hamming matching,
`solvePnPRansac` (SQPnP, 200 iterations, 2 px) between frames i and i + 5 for 40 pairs, with all features (`/0`) or
with the features on moving truth removed (`/1`, an oracle culling); one deterministic iteration each, so its
counters do not depend on the load. People pull a two-frame PnP-RANSAC off by little: RANSAC rejects most moving
features; the ATE effect of culling is measured on whole sequences (results.md).""",
    "bench_eval_ate_bench": """A 2000-pose estimate at 30 Hz (3 mm position noise, 0.17 deg rotation noise, 3 ms
stamp jitter, in another world frame) against a 100 Hz ground truth of 6677 poses. The reference in the same
binary is `associate.py`'s algorithm ported literally (O(n m) candidates, sort, greedy). Accuracy against the TUM
scripts is checked by tests, not here.""",
}

SECTIONS = [("Geometry", "bench_geometry_"), ("Culling", "bench_culling_"), ("Evaluation", "bench_eval_"),
            ("Synthetic scene", "bench_sim_")]


def load_text(run, binary):
    load = run.context.get(binary, {}).get("load_avg")
    return f"load average at its start {', '.join(f'{x:.1f}' for x in load)}" if load else ""


def main():
    directory, page = sys.argv[1], sys.argv[2]
    run = Run(directory)
    info_path = os.path.join(directory, "run_info.txt")
    info = ("\n".join("- " + l for l in read(info_path).strip().splitlines()) if os.path.exists(info_path)
            else "- (run_info.txt not found: run scripts/benchmarks.sh to record machine, compiler and commit)")
    rows = targets(run)
    target_table = ["| hot path | target | measured (ratios within one binary's run) | met? |", "|---|---|---|---|"]
    target_table += [f"| {p} | {t} | {m} | {met_text(ok)} |" for p, t, m, ok in rows]

    cc = compile_cost(directory, "compile_cost.csv", "instantiate", "`instantiate`")
    cch = compile_cost(directory, "compile_cost_host.csv", None, "the unit without dyncull")
    cc_text = []
    if cc:
        cc_text += ["The culling pipeline in one translation unit, `g++ -std=c++17 -O2`, measured with `/usr/bin/time -v`",
                    "by `scripts/compile-cost.sh --csv FILE`: `include_only` includes `culling/pipeline.hpp`,",
                    "`instantiate` also instantiates `cull_frame<float>` for a dynamic_vo-like frame, and",
                    "`instantiate_precompiled` is that file with `-DDYNCULL_PRECOMPILED`, as a target linking",
                    "`dyncull::pipeline` compiles it (`cull_frame` and the solvers come from the library). Target: the",
                    "precompiled unit at most half of `instantiate`'s time and peak memory.", "", cc, ""]
    if cch:
        cc_text += ["A host translation unit like an ORB-SLAM front end (`opencv2/core`, `features2d`, `Eigen/Core`; ORB",
                    "into vectors), `g++ -std=c++14 -O2`, without dyncull and with `dyncull/opencv/culler.hpp`",
                    "included and the culler called, `scripts/compile-cost-host.sh --csv FILE`. Target: at most 2x the",
                    "time and peak memory of the unit without it.", "", cch, ""]
    if not cc_text:
        cc_text = ["Not measured in this run: `scripts/compile-cost.sh` and `scripts/compile-cost-host.sh` write the",
                   "CSV the page reads only with `--csv` (run them by hand for a console table).", ""]

    parts = [f"""# Benchmarks

How fast dyncull is, against the library a user would otherwise call (OpenCV, Eigen, Ceres, Open3D) **in the same
binary**, so each ratio comes from one run, with accuracy beside time as counters. Every hot path has a Google
Benchmark case under `bench/` (mirroring `include/dyncull/`; one binary per file, `bench_<module>_<name>_bench`).

This page is generated: `scripts/benchmarks.sh` builds the benches in Release (build/bench), runs each with
`--benchmark_format=json`, measures the compile cost, and rewrites the page from that output with
`scripts/benchmarks_page.py`; `scripts/benchmarks.sh --page-only DIR` rewrites it from an earlier run. To run one
binary by hand:

```sh
cmake -S . -B build/bench -DCMAKE_BUILD_TYPE=Release && cmake --build build/bench --target bench_culling_culler_bench -j1
build/bench/bench/bench_culling_culler_bench --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
```

Times are **CPU-time medians of the repetitions**, one thread (OpenCV pinned to one thread: Google Benchmark's CPU
time does not see worker threads). On a shared machine absolute times move with the load by 1.5-3x and ratios by
about 10-30 %: compare ratios within one run, and read the load average below.

This run:

{info}

## Targets and where dyncull stands

{chr(10).join(target_table)}

## Where the culling time goes

Each stage of `cull_frame` (`culling/stages/`) alone on the pipeline bench's frame (float, the recommended preset
given 3-D points and track ids, the multi-view check verifying its candidates, the probability on for its own case
only), `bench_culling_stages_bench`:

{stages(run)}

## Heap allocations per frame

`bench_culling_allocations_bench`: `cull_frame` on three frames of the synthetic culling scene with 3-D points and
track ids, replayed after three warm-up rounds, a keyframe ring of two slots (full before the count); the counter is
the most allocations any frame made. `tests/culling/pipeline_allocations_test.cpp` fails above its per-preset bound
on the same sequence, and `docs/design.md` lists what still allocates.

{allocations(run)}

## Compile cost

{chr(10).join(cc_text)}
## Other peers (no numeric target)

{other_peers(run)}
"""]
    for title, prefix in SECTIONS:
        binaries = [b for b in sorted(run.cases) if b.startswith(prefix)]
        if not binaries:
            continue
        parts.append(f"## {title} benchmarks\n")
        for b in binaries:
            parts.append(f"### {b}\n")
            text = source_comment(b)
            if text:
                parts.append(text + "\n")
            if b in PROSE:
                parts.append(PROSE[b].replace("\n", " ") + "\n")
            lt = load_text(run, b)
            if lt:
                parts.append(f"({lt}.)\n")
            parts.append(binary_table(run, b) + "\n")
    with open(page, "w", encoding="utf-8") as f:
        f.write("\n".join(parts).rstrip() + "\n")


if __name__ == "__main__":
    main()
