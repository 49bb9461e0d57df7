"""The CI speed gate's decision (scripts/icount_compare.py), a developer's tool the report's history page reads.
"""
import json
import pathlib
import subprocess
import tempfile
import unittest

from helpers import PY, ROOT, load_script

icount_compare = load_script("icount_compare")

class IcountGateTest(unittest.TestCase):
    """The CI speed gate's decision (scripts/icount_compare.py) on counts at known distances from the
    baseline, and its command-line contract (exit 1 on a regression, --update writes the baseline)."""

    def test_threshold_is_strict_above_and_lenient_below(self):
        base = {"a": 1_000_000, "b": 1_000_000, "c": 1_000_000}
        rows, failed = icount_compare.compare({"a": 1_030_001, "b": 1_029_999, "c": 500_000}, base, 3.0)
        self.assertEqual([f.split(":")[0] for f in failed], ["a"])
        verdicts = {w: v for w, _, _, _, v in rows}
        self.assertIn("SLOWER", verdicts["a"])
        self.assertEqual(verdicts["b"], "")
        self.assertIn("faster", verdicts["c"])

    def test_a_workload_without_baseline_fails(self):
        _, failed = icount_compare.compare({"new": 5}, {"old": 5}, 3.0)
        self.assertEqual(len(failed), 1)
        self.assertIn("not in the baseline", failed[0])

    def test_command_line_fails_on_ten_percent_and_update_accepts_it(self):
        with tempfile.TemporaryDirectory() as d:
            d = pathlib.Path(d)
            counts, base = d / "counts", d / "ref" / "icount.json"
            base.parent.mkdir()
            base.write_text(json.dumps({"instructions": {"matching": 134_000_000, "mcl_update": 50_000_000}}))
            counts.write_text("matching 147400000 1000\nmcl_update 50000000 900\n")
            cmd = [PY, str(ROOT / "scripts" / "icount_compare.py"), str(counts), "--baseline", str(base), "--history", str(d / "h.jsonl")]
            r = subprocess.run(cmd, capture_output=True, text=True)
            self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
            self.assertIn("matching: +10.00%", r.stderr)
            r = subprocess.run(cmd + ["--update", "--commit", "abc"], capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(json.loads(base.read_text())["instructions"]["matching"], 147_400_000)
            self.assertEqual(len((d / "ref" / "icount_history.jsonl").read_text().splitlines()), 1)
            r = subprocess.run(cmd, capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            self.assertEqual(len((d / "h.jsonl").read_text().splitlines()), 3)
