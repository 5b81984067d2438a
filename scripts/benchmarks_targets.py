"""docs/benchmarks.md's target table: each hot path's target against one binary's JSON (benchmarks_page.Run)."""
import csv
import os
import statistics

from page_common import fmt, fmt_ratio, fmt_time


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

