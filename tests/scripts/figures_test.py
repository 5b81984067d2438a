#!/usr/bin/env python3
"""Tests of scripts/figures.py (run by ctest; skipped without python3-matplotlib): from dynamic_vo's CSV it
draws the trajectory panels, the error over time with the frames with people shaded, and the family summary;
the runs with a person box become shaded spans; a folder without its CSV is an error."""
import os
import shutil
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
try:
    import matplotlib  # noqa: F401
    import figures  # noqa: E402
except ImportError:
    figures = None

PNG = b"\x89PNG\r\n\x1a\n"


@unittest.skipIf(figures is None, "python3-matplotlib is not installed (scripts/install-deps.sh installs it)")
class Figures(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="dyncull_figures_test_")
        with open(os.path.join(self.dir, "seq_poses.csv"), "w") as f:
            f.write("strategy,stamp,gt_x,gt_y,gt_z,x,y,z,error_m\n")
            for strategy, drift in (("none", 0.1), ("recommended", 0.01)):
                for i in range(30):
                    f.write("%s,%.6f,%f,0,%f,%f,0,%f,%f\n" % (strategy, 10 + i / 30, i / 30, (i % 7) / 30,
                                                              i / 30 + drift, (i % 7) / 30, drift))
        with open(os.path.join(self.dir, "seq_frames.csv"), "w") as f:
            f.write("frame,stamp,person_boxes\n")
            f.write("".join("%d,%.6f,%d\n" % (i, 10 + i / 30, 1 if 10 <= i < 20 else 0) for i in range(30)))
        with open(os.path.join(self.dir, "family_summary.csv"), "w") as f:
            f.write("family,motion,strategy,median_ate_m\nwalking,all,none,0.2\nwalking,all,recommended,0.02\n"
                    "walking,xyz,none,0.3\n")

    def tearDown(self):
        shutil.rmtree(self.dir)

    def test_every_figure_is_drawn(self):
        sys.argv = ["figures.py", self.dir]
        self.assertEqual(figures.main(), 0)
        for name in ("family_summary.png", "seq_trajectories.png", "seq_ate_over_time.png"):
            with open(os.path.join(self.dir, name), "rb") as f:
                self.assertEqual(f.read(8), PNG, name)

    def test_people_spans_are_the_runs_of_frames_with_a_person_box(self):
        frames = figures.read_rows(os.path.join(self.dir, "seq_frames.csv"))
        self.assertEqual([(round(a, 3), round(b, 3)) for a, b in figures.people_spans(frames)], [(10.333, 10.667)])

    def test_a_folder_without_csv_is_an_error(self):
        empty = os.path.join(self.dir, "empty")
        os.makedirs(empty)
        sys.argv = ["figures.py", empty]
        self.assertEqual(figures.main(), 1)


if __name__ == "__main__":
    unittest.main()
