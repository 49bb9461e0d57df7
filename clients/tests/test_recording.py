"""The recording writer of the Python client (clients/python/omniloc_recording.py): a log written from
plain arrays by clients/python/examples/write_recording.py replays through `omniloc replay` (scored
with its true poses, unscored without), and omniloc's own recordings read back with its reader.

Usage: test_recording.py OMNILOC_BINARY (ctest: olp_recording_py)."""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

HERE = Path(__file__).resolve().parent
CLIENTS = HERE.parent
ROOT = CLIENTS.parent
sys.path.insert(0, str(CLIENTS / "python"))
import omniloc_recording as rec  # noqa: E402

BIN = None
PY = "/usr/bin/python3" if Path("/usr/bin/python3").exists() else sys.executable


class WriterTest(unittest.TestCase):
    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="omniloc_rec_writer_"))

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def write(self, name, *extra):
        out = self.tmp / name
        subprocess.run([PY, str(CLIENTS / "python" / "examples" / "write_recording.py"), str(out), *extra], check=True, capture_output=True)
        return out

    def replay(self, folder, localizer, out):
        r = subprocess.run([BIN, "replay", str(folder), "--localizer", json.dumps(localizer), "-o", str(self.tmp / out), "--quiet"],
                           capture_output=True, text=True, cwd=ROOT, timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        return self.tmp / out

    def test_a_log_with_ground_truth_is_scored(self):
        log = self.write("with_truth")
        header, frames = rec.read(str(log))
        frames = list(frames)
        self.assertEqual(len(frames), 601)
        self.assertEqual(header["written_by"], "clients/python/omniloc_recording.py")
        m = json.loads((self.replay(log, {"type": "matching"}, "m") / "summary.json").read_text())
        o = json.loads((self.replay(log, {"type": "odometry_only"}, "o") / "summary.json").read_text())
        self.assertNotIn("scored", m)
        self.assertEqual(m["omniloc"]["replay"]["recorded_with"], "not omniloc")
        # Matching on 2 cm line-point noise stays within a few centimetres; dead reckoning on 2 %
        # scale noise drifts further (measured 0.2 cm and 0.8 cm rmse, seed 1).
        self.assertLess(m["robots"][0]["position_m"]["rmse"], 0.02)
        self.assertLess(m["robots"][0]["position_m"]["rmse"], o["robots"][0]["position_m"]["rmse"])

    def test_a_log_without_ground_truth_is_not_scored(self):
        log = self.write("no_truth", "--no-truth")
        out = self.replay(log, {"type": "matching"}, "nt")
        s = json.loads((out / "summary.json").read_text())
        self.assertFalse(s["scored"])
        self.assertEqual(s["robots"][0]["frames"], 601)
        self.assertFalse((out / "gt.tum").exists())
        self.assertEqual(len((out / "est.tum").read_text().splitlines()), 601)
        row = (out / "frames.csv").read_text().splitlines()[1].split(",")
        self.assertEqual(row[2:5], ["", "", ""])  # no truth, no error

    def test_writer_refuses_what_a_replay_would(self):
        w = rec.Writer(str(self.tmp / "bad"), name="x", field="msl2012", camera_rate_hz=30, robots=[{"id": 0}], ground_truth=True)
        with self.assertRaises(rec.RecordingError):
            w.frame(0.0, [{"robot": 0, "odometry": (0, 0, 0), "line_points": []}])  # no truth
        w.frame(0.0, [{"robot": 0, "odometry": (0, 0, 0), "line_points": [], "truth": (0, 0, 0)}])
        with self.assertRaises(rec.RecordingError):
            w.frame(0.0, [{"robot": 0, "odometry": (0, 0, 0), "line_points": [], "truth": (0, 0, 0)}])  # time does not advance
        with self.assertRaises(rec.RecordingError):
            w.frame(0.1, [{"robot": 0, "odometry": (float("nan"), 0, 0), "line_points": [], "truth": (0, 0, 0)}])
        self.assertFalse((self.tmp / "bad").exists())  # nothing until close()

    def test_a_tracking_localizer_needs_the_start_pose(self):
        w = rec.Writer(str(self.tmp / "nostart"), name="x", field="msl2012", camera_rate_hz=30, robots=[{"id": 0}], ground_truth=False)
        for k in range(3):
            w.frame(k / 30, [{"robot": 0, "odometry": (0, 0, 0), "line_points": []}])
        w.close()
        r = subprocess.run([BIN, "replay", str(self.tmp / "nostart"), "--localizer", '{"type": "matching"}', "-o", str(self.tmp / "ns")],
                           capture_output=True, text=True, cwd=ROOT)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("/robots/0/start", r.stderr)


if __name__ == "__main__":
    BIN = os.path.abspath(sys.argv.pop(1))
    unittest.main()
