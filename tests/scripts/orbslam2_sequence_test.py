#!/usr/bin/env python3
"""Tests of scripts/orbslam2_sequence.py (run by ctest): rgb and depth paired by dyncull_eval --associate as
associate.py (closest first, each stamp once, none beyond 0.02 s); the settings file written from camera.txt and the image size;
the trajectory figure takes each variant's median run as dyncull_eval aligned it; a run's lost frames are counted against the
associations (ORB-SLAM2 leaves them out of its trajectory); the summary has a row per variant and run with
the required columns, and a run without a trajectory is reported, not dropped; the 95th percentile of tracking
time is read from every run and the frames per second from the free run only, which the medians leave out."""
import json
import os
import shutil
import struct
import sys
import tempfile
import unittest
import zlib

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import orbslam2_sequence as seq  # noqa: E402
import orbslam_page  # noqa: E402


def write_png(path, width, height):
    """A grey 8-bit PNG of the given size (only its header is read)."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    raw = b"".join(b"\x00" + b"\x80" * width for _ in range(height))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


# The pairing is dyncull_eval's (ctest passes the built program in DYNCULL_EVAL).
DYNCULL_EVAL = os.environ.get("DYNCULL_EVAL", "")


@unittest.skipUnless(DYNCULL_EVAL and os.access(DYNCULL_EVAL, os.X_OK), "DYNCULL_EVAL names no dyncull_eval program")
class Sequence(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="dyncull_orbslam2_test_")
        os.makedirs(os.path.join(self.dir, "rgb"))
        write_png(os.path.join(self.dir, "rgb", "1.000000.png"), 64, 48)
        with open(os.path.join(self.dir, "rgb.txt"), "w") as f:
            f.write("# color images\n1.000000 rgb/1.000000.png\n1.033333 rgb/1.033333.png\n"
                    "1.066667 rgb/1.066667.png\n1.100000 rgb/1.100000.png\n")
        # depth 1.052 is within the window of rgb 1.033 (0.019) and rgb 1.067 (0.015): the closer one gets it,
        # and rgb 1.033 stays without a partner; rgb 1.100 has none within 0.02 s (1.130).
        with open(os.path.join(self.dir, "depth.txt"), "w") as f:
            f.write("# depth maps\n1.010000 depth/a.png\n1.052000 depth/b.png\n1.130000 depth/c.png\n")
        with open(os.path.join(self.dir, "camera.txt"), "w") as f:
            f.write("fx 542.8\nfy 542.5\ncx 315.5\ncy 237.7\ndepth_units_per_metre 5000\n")

    def tearDown(self):
        shutil.rmtree(self.dir)

    def test_pairs_closest_first_each_stamp_once(self):
        seq.prepare(self.dir, self.dir, DYNCULL_EVAL)
        self.assertEqual(open(os.path.join(self.dir, "associations.txt")).read().splitlines(),
                         ["1.000000 rgb/1.000000.png 1.010000 depth/a.png",
                          "1.066667 rgb/1.066667.png 1.052000 depth/b.png"])

    def test_settings_from_camera_and_image_size(self):
        seq.prepare(self.dir, self.dir, DYNCULL_EVAL)
        text = open(os.path.join(self.dir, "orbslam2_settings.yaml")).read()
        self.assertTrue(text.startswith("%YAML:1.0\n"))
        for line in ("Camera.fx: 542.8", "Camera.cy: 237.7", "Camera.k1: 0.0", "Camera.width: 64",
                     "Camera.height: 48", "DepthMapFactor: 5000.0", "ORBextractor.nFeatures: 1000"):
            self.assertIn(line + "\n", text)
        self.assertEqual(seq.count_lines(os.path.join(self.dir, "associations.txt")), 2)

    def test_lost_frames_and_summary_rows(self):
        seq.prepare(self.dir, self.dir, DYNCULL_EVAL)
        good = os.path.join(self.dir, "runs", "culler", "run1")
        empty = os.path.join(self.dir, "runs", "culler", "run2")
        os.makedirs(good)
        os.makedirs(empty)
        with open(os.path.join(good, "CameraTrajectory.txt"), "w") as f:
            f.write("1.000000 0 0 0 0 0 0 1\n")  # one of the two associated frames: one lost
        with open(os.path.join(good, "rgbd_tum.log"), "w") as f:
            f.write("median tracking time: 0.030\nmean tracking time: 0.0325\n"
                    "dyncull: mode culler, 2 frames (0 without a detections file, 0 not Ok, 0 restarts), "
                    "features 1000.0 -> 800.5 per frame, 1.500 ms per frame culling\n")
        with open(os.path.join(good, "ate.json"), "w") as f:
            json.dump({"status": "ok", "ate": {"pairs": 1, "error_m": {"rmse": 0.0123}}}, f)
        seq.summarise(self.dir, self.dir, "", "cmd", "")
        lines = open(os.path.join(self.dir, "orbslam2_summary.csv")).read().splitlines()
        header = lines[0].split(",")
        for column in ("variant", "run", "ate_rmse_m", "lost_frames", "frames", "track_ms"):
            self.assertIn(column, header)
        rows = [dict(zip(header, line.split(","))) for line in lines[1:]]
        self.assertEqual(len(rows), 2)
        self.assertEqual((rows[0]["variant"], rows[0]["run"], rows[0]["ate_rmse_m"], rows[0]["lost_frames"],
                          rows[0]["frames"], rows[0]["track_ms"], rows[0]["cull_ms"], rows[0]["features_kept"]),
                         ("culler", "1", "0.01230", "1", "2", "32.50", "1.500", "800.5"))
        self.assertEqual((rows[1]["run"], rows[1]["ate_rmse_m"], rows[1]["lost_frames"]), ("2", "", "2"))
        self.assertIn("no trajectory", rows[1]["note"])
        self.assertEqual((rows[0]["detector_ms"], rows[0]["box_age_frames"]), ("", ""))

    def test_live_variant_reads_detector_time_and_box_age(self):
        with open(os.path.join(self.dir, "rgb_color.txt"), "w") as f:
            f.write("# colour\n1.000000 rgb_color/1.000000.jpg\n1.066667 rgb_color/1.066667.jpg\n")
        seq.prepare(self.dir, self.dir, DYNCULL_EVAL)
        self.assertEqual(seq.count_lines(os.path.join(self.dir, "associations_color.txt")), 2)
        run = os.path.join(self.dir, "runs", "culler_live", "run1")
        os.makedirs(run)
        with open(os.path.join(run, "rgbd_tum.log"), "w") as f:
            f.write("mean tracking time: 0.030\n"
                    "dyncull: mode culler, 2 frames (1 without boxes, 1 not Ok, 0 restarts), features 1000.0 -> 900.0 "
                    "per frame, 1.200 ms per frame culling; live detector: 41.5 ms per detection, box age 1.50 "
                    "frames, 0 failed frames\n")
        seq.summarise(self.dir, self.dir, "", "cmd", "")
        lines = open(os.path.join(self.dir, "orbslam2_summary.csv")).read().splitlines()
        header = lines[0].split(",")
        for column in ("fps", "track_ms_p95", "detector_ms", "box_age_frames"):
            self.assertIn(column, header)
        row = dict(zip(header, lines[1].split(",")))
        self.assertEqual((row["variant"], row["detector_ms"], row["box_age_frames"]), ("culler_live", "41.5", "1.50"))

    def test_free_run_gives_frames_per_second_apart_from_the_recorded_rate_runs(self):
        seq.prepare(self.dir, self.dir, DYNCULL_EVAL)
        for name, mean, p95, fps in (("run1", "0.020", "0.031", "29.9 (recorded rate)"),
                                     ("free", "0.025", "0.040", "52.25 (free run)")):
            run = os.path.join(self.dir, "runs", "culler", name)
            os.makedirs(run)
            with open(os.path.join(run, "rgbd_tum.log"), "w") as f:
                f.write("median tracking time: %s\nmean tracking time: %s\n95th percentile tracking time: %s\n"
                        "frames per second: %s\n" % (mean, mean, p95, fps))
        table = seq.summarise(self.dir, self.dir, "", "cmd", "")
        lines = open(os.path.join(self.dir, "orbslam2_summary.csv")).read().splitlines()
        header = lines[0].split(",")
        rows = {r["run"]: r for r in (dict(zip(header, line.split(","))) for line in lines[1:])}
        self.assertEqual((rows["1"]["track_ms_p95"], rows["1"]["fps"]), ("31.00", ""))  # recorded rate: no fps
        self.assertEqual((rows["free"]["track_ms_p95"], rows["free"]["fps"]), ("40.00", "52.2"))
        # The medians are the recorded-rate runs'; the free run has its own column.
        self.assertEqual(seq.numbers(list(rows.values()), "culler", "track_ms"), [20.0])
        self.assertIn("| culler | 1 (1 without an ATE) | n/a | 2 (2-2) | 20.0 (20.0-20.0) | 31.0 |", table)
        self.assertTrue(table.splitlines()[0].endswith("| Free run: frames per second (ATE, cm) |"))
        self.assertTrue(table.splitlines()[2].endswith("| 52.2 (no ATE) |"))


class Trajectories(unittest.TestCase):
    """The trajectory figure shows each variant's median-ATE run as dyncull_eval aligned it (its poses.csv)."""

    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="dyncull_orbslam2_plot_test_")
        self.rows = [{"variant": "stock", "run": str(k), "ate_rmse_m": ate} for k, ate in ((1, "0.30"), (2, "0.10"), (3, "0.20"))]
        self.rows.append({"variant": "culler", "run": "1", "ate_rmse_m": "0.02"})
        self.rows.append({"variant": "box_only", "run": "1", "ate_rmse_m": ""})  # no trajectory
        for variant, run in (("stock", 1), ("stock", 2), ("stock", 3), ("culler", 1)):
            run_dir = os.path.join(self.dir, "runs", variant, "run%d" % run)
            os.makedirs(run_dir)
            with open(os.path.join(run_dir, "poses.csv"), "w") as f:
                f.write("stamp,gt_x,gt_y,gt_z,x,y,z,error_m\n")
                for i in range(5):
                    f.write("%d.0,%d,0,%d,%d,0.01,%d,0.01\n" % (i, i, i % 2, i, i % 2))

    def tearDown(self):
        shutil.rmtree(self.dir)

    def test_median_run_of_each_variant(self):
        chosen = orbslam_page.median_runs(self.dir, self.rows, seq.VARIANTS)
        self.assertEqual([(v, r, a) for v, r, a, _ in chosen], [("stock", 3, 0.2), ("culler", 1, 0.02)])
        self.assertTrue(chosen[0][3].endswith(os.path.join("runs", "stock", "run3", "poses.csv")))

    def test_figure_is_drawn_from_the_poses(self):
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            self.skipTest("python3-matplotlib is not installed (scripts/install-deps.sh installs it)")
        path = os.path.join(self.dir, "trajectories.svg")
        self.assertEqual(len(orbslam_page.plot_trajectories("seq", self.dir, self.rows, seq.VARIANTS, path)), 2)
        self.assertIn("<svg", open(path).read())


if __name__ == "__main__":
    unittest.main()
