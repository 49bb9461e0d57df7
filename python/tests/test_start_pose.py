"""Fair rows and one name (a run records whether its localizer was given the start pose), end to end through the omniloc binary: a sweep that runs a
client given the true start pose (clients/python/examples/dead_reckoning.py, ready.needs_start_pose)
beside a built-in that starts globally (mcl) on the tracking path. Every run records
start_pose_given; the aggregate keeps the two apart and names the client as its runs do (its
ready.name, where the user gave no label: not the script's stem); paper_table never puts the client
in the "(global start)" row. Short runs (2 s, one seed), so it takes seconds.

Run by pytest (ctest results_pytest) with OMNILOC_BIN = the built omniloc; without it these tests skip.
"""
import csv
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

from helpers import OMNILOC, PY, ROOT, needs_omniloc

CLIENT = str(ROOT / "clients" / "python" / "examples" / "dead_reckoning.py")  # ready.name "py_dead_reckoning"
MCL_ROW = "tracking path, MCL alone (global start)"


@needs_omniloc
class StartPoseSweep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="start_pose_"))
        sweep = {"name": "start_pose", "scenarios": [str(ROOT / "scenarios" / "paper" / "tracking.json")],
                 "parameters": {"/duration": [2.0]},
                 "localizers": [{"type": "mcl"}, {"type": "external", "command": [PY, CLIENT]}],
                 "seeds": [1]}
        (cls.tmp / "sweep.json").write_text(json.dumps(sweep))
        cls.out = cls.tmp / "out"
        r = subprocess.run([OMNILOC, "sweep", str(cls.tmp / "sweep.json"), "-o", str(cls.out)], cwd=ROOT, capture_output=True, text=True,
                           timeout=600)
        cls.progress = r.stdout + r.stderr
        if r.returncode != 0:
            raise AssertionError(f"sweep exited {r.returncode}:\n{cls.progress}")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def summary(self, localizer_label):
        run = next(d for d in (self.out / "runs").iterdir() if d.name.split("__")[1] == localizer_label)
        return json.loads((run / "summary.json").read_text())

    def test_every_run_records_whether_it_was_given_the_start_pose(self):
        mcl, client = self.summary("mcl"), self.summary("dead_reckoning")
        self.assertIs(mcl["start_pose_given"], False)
        self.assertIs(client["start_pose_given"], True)
        self.assertEqual(client["localizer"], "py_dead_reckoning")  # no label given: the client's ready.name
        self.assertEqual(client["external"]["name"], "py_dead_reckoning")
        for s in (mcl, client):
            r = s["robots"][0]
            pm = r["position_m"]
            if r["frames"]:
                self.assertLessEqual(pm["mean"], pm["rmse"] + 1e-12)  # mean <= RMSE always
            else:  # no frame answered (a global start that never settles in 2 s): null, never 0
                self.assertIsNone(pm["rmse"])
                self.assertIn("no estimate", r["why_null"])

    def test_coverage_is_recorded_and_shown_beside_the_errors(self):
        # Both tasks are scored over every frame: recall at the headline threshold and the share
        # answered, which paper_table prints before the errors (and the aggregate's no_value column).
        for label in ("mcl", "dead_reckoning"):
            s = self.summary(label)
            r = s["robots"][0]
            self.assertEqual(s["scoring"]["headline"], "25cm_10deg")
            self.assertEqual(sorted(r["recall"]), ["10cm_5deg", "25cm_10deg", "50cm_20deg"])
            self.assertAlmostEqual(r["valid_fraction"], r["frames"] / r["frames_total"])
            self.assertLessEqual(r["recall"]["25cm_10deg"], r["valid_fraction"] + 1e-12)  # a frame without an estimate is never within
        header = (self.out / "aggregate.csv").read_text().splitlines()[0].split(",")
        self.assertEqual(header[-1], "no_value")
        r = subprocess.run([PY, "-m", "omniloc.commands.paper_table", str(self.out), "--paper", "000_tracking", "--rows", MCL_ROW],
                           capture_output=True, text=True, timeout=120)
        self.assertEqual(r.returncode, 0, r.stderr)
        head = r.stdout.splitlines()[0]
        self.assertLess(head.index("within 25 cm / 10 deg"), head.index("answered"))
        self.assertLess(head.index("answered"), head.index("mean x"))

    def test_aggregate_rows_are_apart_and_named_as_their_runs(self):
        agg = json.loads((self.out / "aggregate.json").read_text())
        rows = {g["localizer"]: g for g in agg["groups"]}
        self.assertEqual(sorted(rows), ["mcl", "py_dead_reckoning"])  # not the stem "dead_reckoning"
        self.assertIs(rows["mcl"]["start_pose_given"], False)
        self.assertIs(rows["py_dead_reckoning"]["start_pose_given"], True)
        self.assertIn("r0/position_m/mean", rows["mcl"]["metrics"])
        table = list(csv.DictReader(io.StringIO((self.out / "aggregate.csv").read_text())))
        given = {(r["localizer"], r["start_pose_given"]) for r in table}
        self.assertEqual(given, {("mcl", "false"), ("py_dead_reckoning", "true")})
        self.assertIn("r0/position_m/mean", {r["metric"] for r in table})
        runs = list(csv.DictReader(io.StringIO((self.out / "runs.csv").read_text())))
        self.assertEqual(sorted((r["localizer"], r["start_pose_given"]) for r in runs), [("mcl", "false"), ("py_dead_reckoning", "true")])
        # The progress lines and the printed table use the same name, and say which row was given the start pose.
        self.assertIn("py_dead_reckoning", self.progress)
        self.assertNotIn(" / dead_reckoning", self.progress)
        self.assertIn("py_dead_reckoning (given the start pose)", self.progress)

    def test_paper_table_keeps_the_client_out_of_the_global_start_row(self):
        r = subprocess.run([PY, "-m", "omniloc.commands.paper_table", str(self.out), "--paper", "000_tracking", "--rows", MCL_ROW],
                           capture_output=True, text=True, timeout=120)
        self.assertEqual(r.returncode, 0, r.stderr)
        lines = [l for l in r.stdout.splitlines() if "py_dead_reckoning" in l]
        self.assertEqual(len(lines), 1, r.stdout)
        self.assertFalse(lines[0].startswith(MCL_ROW), r.stdout)
        self.assertIn("(given the start pose)", lines[0])
        self.assertTrue(any(l.startswith(MCL_ROW) and "omniloc" in l for l in r.stdout.splitlines()), r.stdout)

    def test_compare_does_not_pair_the_client_with_the_global_start(self):
        runs = sorted((self.out / "runs").iterdir())
        a, b = self.tmp / "A", self.tmp / "B"
        shutil.copytree(next(d for d in runs if "__mcl__" in d.name), a / "mcl")
        shutil.copytree(next(d for d in runs if "__dead_reckoning__" in d.name), b / "client")
        r = subprocess.run([OMNILOC, "compare", str(a), str(b)], capture_output=True, text=True, timeout=120)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertNotIn("localizer: mcl -> py_dead_reckoning", r.stdout)
        self.assertIn("not comparable", r.stdout)


class OneName(unittest.TestCase):
    """The label, when given, is the name a client's results carry (summary.json and all after it);
    it may not be a built-in localizer's, which tables would take the client for."""

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="one_name_"))

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def scenario(self, label):
        s = json.loads((ROOT / "scenarios" / "paper" / "tracking.json").read_text())
        s.update(duration=1.0, localizer={"type": "external", "command": [PY, CLIENT], "label": label})
        f = self.tmp / f"{label}.json"
        f.write_text(json.dumps(s))
        return str(f)

    @needs_omniloc
    def test_the_label_names_the_run(self):
        r = subprocess.run([OMNILOC, "run", self.scenario("my_tracker"), "-o", str(self.tmp / "run")], cwd=ROOT, capture_output=True, text=True,
                           timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        s = json.loads((self.tmp / "run" / "summary.json").read_text())
        self.assertEqual(s["localizer"], "my_tracker")
        self.assertEqual(s["external"]["name"], "py_dead_reckoning")  # what the client announced stays in the provenance
        self.assertIs(s["start_pose_given"], True)

    @needs_omniloc
    def test_a_built_in_name_is_refused_as_a_label(self):
        r = subprocess.run([OMNILOC, "validate", self.scenario("mcl")], cwd=ROOT, capture_output=True, text=True, timeout=120)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("/localizer/label", r.stderr)


if __name__ == "__main__":
    unittest.main()
