"""Tests of omniloc.global_start (global localisation judged per run): the Wilson interval against published values, and the
per-run classification (ended right, first correct convergence, error while right, wrong frames,
estimates beyond the walls) on hand-made frames with known answers. Plain python3, run by pytest (ctest results_pytest)."""
import csv
import dataclasses
import json
import pathlib
import sys
import tempfile
import unittest

from omniloc import global_start
from omniloc.core import stats


COLS = ["t", "robot", "gt_x", "gt_y", "gt_theta", "est_x", "est_y", "est_theta", "err_x", "err_y", "err_theta", "err_pos", "valid"]


def row(t, ex, ey=0.0, eth=0.0, valid=True, gx=0.0, gy=0.0):
    return {"t": f"{t:.4f}", "robot": "0", "gt_x": str(gx), "gt_y": str(gy), "gt_theta": "0", "est_x": str(gx + ex), "est_y": str(gy + ey),
            "est_theta": str(eth), "err_x": str(ex), "err_y": str(ey), "err_theta": str(eth), "err_pos": str((ex * ex + ey * ey) ** 0.5),
            "valid": "1" if valid else "0"}


class Wilson(unittest.TestCase):
    def test_published_values(self):
        # 18 / 20: 0.699-0.972 (Newcombe 1998, method 3, as tabulated); 0 / 20: upper 0.161; 20 / 20: lower 0.839.
        lo, hi = stats.wilson(18, 20)
        self.assertAlmostEqual(lo, 0.6990, places=3)
        self.assertAlmostEqual(hi, 0.9721, places=3)
        self.assertEqual(stats.wilson(0, 20)[0], 0.0)
        self.assertAlmostEqual(stats.wilson(0, 20)[1], 0.1611, places=3)
        self.assertAlmostEqual(stats.wilson(20, 20)[0], 0.8389, places=3)
        self.assertEqual(stats.wilson(0, 0), (0.0, 1.0))


class ScoreRun(unittest.TestCase):
    def test_wrong_then_right(self):
        # 0-2 s invalid (searching), 2-5 s valid but 8 m off (wrong), from 5 s on 3 cm off in x until 10 s.
        rows = []
        for k in range(0, 301):
            t = k / 30
            if t < 2:
                rows.append(row(t, 5.0, valid=False))
            elif t < 5:
                rows.append(row(t, 8.0, gx=3.0))  # estimate at x = 11: beyond a wall at 10
            else:
                rows.append(row(t, 0.03, eth=0.01))
        rows[-10]["valid"] = "0"  # unsure for one frame near the end: still ended right
        rows[-10]["err_x"] = "3.0"
        r = global_start.score_run(rows, half_floor=(10.0, 7.0))
        self.assertTrue(r.ended_right)
        self.assertAlmostEqual(r.t_first, 5.0, places=3)
        self.assertEqual(r.wrong_frames, 90)            # 2.0 .. 4.967 s
        self.assertEqual(r.outside_walls_frames, 90)
        self.assertEqual(r.outside_walls_any_frames, 90)
        self.assertEqual(r.right_frames, 150)           # 5.0 .. 10.0 s, less the unsure one
        s = global_start.summarise([r])
        self.assertAlmostEqual(s.right_mean_x_cm, 3.0, places=6)
        self.assertAlmostEqual(s.right_mean_theta_rad, 0.01, places=6)
        self.assertAlmostEqual(s.wrong_frame_fraction, 90 / 301, places=9)
        # Mean over every valid frame: (90 x 8 m + 151 x 0.03 m) / 241, the figure that hides both.
        self.assertAlmostEqual(s.all_mean_pos_cm, 100 * (90 * 8 + 150 * 0.03) / 240, places=6)

    def test_ends_wrong_and_a_short_right_spell_is_no_convergence(self):
        rows = [row(k / 30, 0.05 if 30 <= k < 50 else 2.0) for k in range(0, 200)]  # right for 0.67 s only
        r = global_start.score_run(rows)
        self.assertFalse(r.ended_right)
        self.assertIsNone(r.t_first)
        s = global_start.summarise([r, dataclasses.replace(r, ended_right=True)])
        self.assertEqual(s.ended_right, 1)
        self.assertEqual(s.wilson95, list(stats.wilson(1, 2)))

    def test_collect_reads_run_folders(self):
        with tempfile.TemporaryDirectory() as d:
            for seed, off in ((1, 0.02), (2, 9.0)):
                f = pathlib.Path(d) / f"run{seed}"
                f.mkdir()
                (f / "summary.json").write_text(json.dumps({"scenario": "tracking", "localizer": "mcl", "seed": seed, "robots": []}))
                (f / "field.json").write_text(json.dumps({"length": 18.0, "width": 12.0, "margin": 1.0}))
                with (f / "frames.csv").open("w", newline="") as fh:
                    w = csv.DictWriter(fh, fieldnames=COLS)
                    w.writeheader()
                    for k in range(60):
                        w.writerow(row(k / 30, off, gx=2.0))
            by = global_start.collect([d])
            self.assertEqual(sorted(s for s, _ in by["mcl"]), [1, 2])
            s = global_start.summarise([r for _, r in by["mcl"]])
            self.assertEqual((s.ended_right, s.runs_with_wrong_frames, s.outside_walls_frames), (1, 1, 60))

    def test_a_run_without_any_estimate_has_no_error_while_right(self):
        # Every frame invalid (the localizer never answered): no right frame, so no error while
        # right and no maximum (None, never 0), and the table says "no estimate".
        rows = [row(k / 30, 3.0, valid=False) for k in range(60)]
        r = global_start.score_run(rows)
        self.assertEqual((r.valid_frames, r.right_frames), (0, 0))
        self.assertIsNone(r.max_x)
        s = global_start.summarise([r, r])
        for k in ("right_mean_x_cm", "right_pos_rmse_cm", "right_max_x_cm", "right_max_y_cm", "all_mean_pos_cm", "t_first_median_s"):
            self.assertIsNone(getattr(s, k), k)
        self.assertEqual((s.ended_right, s.runs_without_estimate, s.wrong_frame_fraction), (0, 2, 0.0))
        md = global_start.markdown({"mcl": s})
        self.assertIn("no estimate / no estimate, no estimate, no estimate", md)
        self.assertNotIn("0.00 / 0.00", md)
        # Frames without ground truth (a log not made by omniloc) are not scored, not a crash.
        blank = dict(row(0.0, 0.1), err_x="", err_y="", err_theta="", err_pos="")
        self.assertEqual(global_start.score_run([blank] + rows).frames, 60)

    def test_collect_reads_recall_from_the_summaries(self):
        with tempfile.TemporaryDirectory() as d:
            for seed, (recall, first) in ((1, (0.9, 0.5)), (2, (0.0, None))):
                f = pathlib.Path(d) / f"run{seed}"
                f.mkdir()
                rob = {"robot": 0, "frames": 60, "frames_total": 60, "valid_fraction": 1.0 if seed == 1 else 0.5,
                       "recall": {"10cm_5deg": recall, "25cm_10deg": recall, "50cm_20deg": recall}, "first_within_s": first}
                (f / "summary.json").write_text(json.dumps({"scenario": "tracking", "localizer": "mcl", "seed": seed, "robots": [rob],
                                                            "scoring": {"headline": "25cm_10deg"}}))
                with (f / "frames.csv").open("w", newline="") as fh:
                    w = csv.DictWriter(fh, fieldnames=COLS)
                    w.writeheader()
                    for k in range(60):
                        w.writerow(row(k / 30, 0.02))
            s = global_start.summarise([r for _, r in global_start.collect([d])["mcl"]])
            self.assertAlmostEqual(s.recall_mean, 0.45)
            self.assertAlmostEqual(s.answered_mean, 0.75)
            self.assertEqual((s.recall_key, s.first_within_median_s, s.runs_never_within), ("25cm_10deg", 0.5, 1))
            md = global_start.markdown({"mcl": s})
            self.assertIn("| within 25 cm / 10 deg: mean over runs (answered) |", md)
            self.assertIn("| mcl | 2 | 45.0 % (75.0 %) | 0.50 (1) |", md)


if __name__ == "__main__":
    unittest.main()
