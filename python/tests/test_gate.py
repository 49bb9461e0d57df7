"""omniloc gate (omniloc.gate, omniloc.commands.gate; docs/ci.md): limits, regressions against a baseline, bad input,
JUnit XML against tests/data/junit.xsd and github-action-benchmark's JSON.

The results are sweeps of the shipped CI suite (scenarios/sweeps/ci_quick.json: ten recordings,
no frame drawn): as it ships (its two reference localizers, matching and the modern ukf_mh), the
built-in matching alone as it ships, and the same with a deliberately degraded
distance map (cell 0.4 m instead of 0.05 m: the map's gradient is coarser than the line points'
spread, so RPROP settles up to a cell off; position rmse about 12 cm instead of about 4 cm).
Runs without an estimate (class NoEstimate): a sweep of the hand-written recording with mcl, which
answers none of its 30 frames (every error statistic null in summary.json), beside matching, which
answers every one; and a copy of the CI sweep with one run's statistic made null. A run without
estimates never passes an accuracy limit, a regression check or a recall limit.
Run by pytest (ctest results_pytest) with OMNILOC_BIN = the built omniloc; without it these tests skip.
"""
import csv
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

from helpers import OMNILOC, PY, ROOT, needs_omniloc
from omniloc import gate

GATE = [PY, "-m", "omniloc.commands.gate"]
SUITE = ROOT / "scenarios" / "sweeps" / "ci_quick.json"
XSD = ROOT / "tests" / "data" / "junit.xsd"
MATCHING = '{"type": "matching"}'
DEGRADED = '{"type": "matching", "cell": 0.4}'
HANDWRITTEN = ROOT / "tests" / "data" / "handwritten_recording"


CWD = tempfile.mkdtemp(prefix="gate_test_cwd_")  # omniloc's caches (results/cache) land here, not in the tree


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=300, cwd=CWD, **kw)


def tearDownModule():
    shutil.rmtree(CWD, ignore_errors=True)


@needs_omniloc
class Gate(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = pathlib.Path(tempfile.mkdtemp(prefix="gate_test_"))
        cls.shipped, cls.good, cls.bad = cls.tmp / "shipped", cls.tmp / "good", cls.tmp / "degraded"
        for out, loc in ((cls.shipped, None), (cls.good, MATCHING), (cls.bad, DEGRADED)):
            cmd = [OMNILOC, "sweep", str(SUITE), "-j", "2", "-o", str(out)] + (["--localizer", loc] if loc else [])
            p = run(cmd)
            assert p.returncode == 0, p.stdout + p.stderr

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def rules(self, rules, name="rules.json"):
        f = self.tmp / name
        f.write_text(json.dumps({"rules": rules}) if not isinstance(rules, str) else rules)
        return str(f)

    def gate(self, *args):
        return run(GATE + [str(a) for a in args])

    def aggregate_mean(self, folder, scenario, metric, localizer="matching"):
        """The mean the C++ aggregate wrote (aggregate.json, full precision)."""
        for g in json.loads((folder / "aggregate.json").read_text())["groups"]:
            if g["scenario"] == scenario and g["localizer"] == localizer:
                return g["metrics"][metric]["mean"]
        raise KeyError(scenario)

    def verdicts(self, out):
        return [ln for ln in out.splitlines() if ln.startswith(("PASS", "FAIL"))]

    # ---- limits -----------------------------------------------------------------------------

    def test_pass(self):
        p = self.gate(self.good, "--rules", self.rules([{"metric": "position_m/rmse", "max": 0.08},
                                                       {"metric": "r0/valid_fraction", "min": 0.99}]))
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        lines = self.verdicts(p.stdout)
        self.assertEqual(len(lines), 4)  # 2 rules x 2 scenarios
        self.assertTrue(all(ln.startswith("PASS") for ln in lines), p.stdout)
        self.assertIn("gate: 4 of 4 checks passed", p.stdout)

    def test_shipped_suite_holds_both_references(self):
        # The suite as it ships gates the papers' matching and the modern reference ukf_mh
        # (docs/modern_localizer.md) on the same frames: four groups, and the modern one at most
        # 0.8 x matching's position RMSE on both scenarios (its requirement; measured 0.48-0.55 x).
        groups = json.loads((self.shipped / "aggregate.json").read_text())["groups"]
        self.assertEqual(sorted((g["scenario"], g["localizer"]) for g in groups),
                         [("ci_occlusion", "matching"), ("ci_occlusion", "ukf_mh"), ("ci_tracking", "matching"), ("ci_tracking", "ukf_mh")])
        for scenario in ("ci_tracking", "ci_occlusion"):
            ukf = self.aggregate_mean(self.shipped, scenario, "r0/position_m/rmse", "ukf_mh")
            self.assertLess(ukf, 0.8 * self.aggregate_mean(self.shipped, scenario, "r0/position_m/rmse"), scenario)
            # The shipped matching is the one the other tests gate alone.
            self.assertEqual(self.aggregate_mean(self.shipped, scenario, "r0/position_m/rmse"),
                             self.aggregate_mean(self.good, scenario, "r0/position_m/rmse"))
        p = self.gate(self.shipped, "--rules", self.rules([{"metric": "position_m/rmse", "max": 0.08}]))
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("gate: 4 of 4 checks passed", p.stdout)

    def test_example_rules_file_passes_the_shipped_references(self):
        # data/gate/ci_quick_rules.json is what the suite's own comment points a team to: it must
        # exist, load, and pass the built-in references, and the degraded localizer must fail it.
        example = ROOT / "data" / "gate" / "ci_quick_rules.json"
        p = self.gate(self.shipped, "--rules", example)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertTrue(all(ln.startswith("PASS") for ln in self.verdicts(p.stdout)), p.stdout)
        p = self.gate(self.bad, "--rules", example)
        self.assertNotEqual(p.returncode, 0, p.stdout + p.stderr)

    def test_fail_by_limit_names_value_and_limit(self):
        # The mean the gate judges is the one the C++ aggregate wrote (computed independently).
        mean = self.aggregate_mean(self.good, "ci_tracking", "r0/position_m/rmse")
        limit = round(mean * 0.9, 4)
        p = self.gate(self.good, "--rules", self.rules([{"metric": "r0/position_m/rmse", "max": limit, "scenario": "ci_tracking"}]))
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        (line,) = self.verdicts(p.stdout)
        self.assertTrue(line.startswith("FAIL  ci_tracking / matching  r0/position_m/rmse"), line)
        self.assertIn(f"mean {mean:.6g} > max {limit:.6g}", line)

    def test_stat_over_seeds(self):
        with open(self.good / "runs.csv", newline="") as fh:
            ids = [r["id"] for r in csv.DictReader(fh) if r["id"].startswith("ci_tracking")]
        worst = max(json.loads((self.good / "runs" / i / "summary.json").read_text())["robots"][0]["position_m"]["max"] for i in ids)
        p = self.gate(self.good, "--rules", self.rules([{"metric": "position_m/max", "stat": "max", "max": worst, "scenario": "ci_tracking"}]))
        self.assertEqual(p.returncode, 0, p.stdout)
        p = self.gate(self.good, "--rules", self.rules([{"metric": "position_m/max", "stat": "max", "max": worst * 0.999, "scenario": "ci_tracking"}]))
        self.assertEqual(p.returncode, 1, p.stdout)

    def test_run_folder_as_results(self):
        run_dir = next((self.good / "runs").iterdir())
        p = self.gate(run_dir, "--rules", self.rules([{"metric": "position_m/rmse", "max": 1.0}]))
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("(n=1)", p.stdout)

    # ---- regressions ------------------------------------------------------------------------

    def test_fail_by_regression_against_baseline(self):
        rules = self.rules([{"metric": "r0/position_m/rmse", "max": 1.0}, {"metric": "r0/theta_rmse_rad", "max": 1.0}])
        p = self.gate(self.bad, "--rules", rules, "--baseline", self.good)
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        lines = self.verdicts(p.stdout)
        self.assertEqual(len(lines), 4)
        for ln in lines:  # every limit holds; each fails as a regression, with the baseline and p
            self.assertTrue(ln.startswith("FAIL"), ln)
            self.assertIn("[regression: mean", ln)
            self.assertNotIn("[limit:", ln)
            p_value = float(ln.split(", p ")[-1].split(" <")[0])
            self.assertLess(p_value, 0.001, ln)

    def test_improvement_and_identical_are_not_regressions(self):
        rules = self.rules([{"metric": "r0/position_m/rmse", "max": 1.0}])
        self.assertEqual(self.gate(self.good, "--rules", rules, "--baseline", self.bad).returncode, 0)
        p = self.gate(self.good, "--rules", rules, "--baseline", self.good)
        self.assertEqual(p.returncode, 0, p.stdout)
        self.assertIn("p 1)", p.stdout)

    def test_tolerance_and_baseline_only_rule(self):
        base = self.aggregate_mean(self.good, "ci_tracking", "r0/position_m/rmse")
        worse = self.aggregate_mean(self.bad, "ci_tracking", "r0/position_m/rmse")
        ok = self.rules([{"metric": "r0/position_m/rmse", "scenario": "ci_tracking", "tolerance": (worse - base) * 1.01}])
        self.assertEqual(self.gate(self.bad, "--rules", ok, "--baseline", self.good).returncode, 0)
        tight = self.rules([{"metric": "r0/position_m/rmse", "scenario": "ci_tracking", "tolerance": (worse - base) * 0.99}])
        self.assertEqual(self.gate(self.bad, "--rules", tight, "--baseline", self.good).returncode, 1)
        frac = self.rules([{"metric": "r0/position_m/rmse", "scenario": "ci_tracking", "tolerance_fraction": 2.0}])
        self.assertEqual(self.gate(self.bad, "--rules", frac, "--baseline", self.good).returncode, 0)  # 12 cm < 4 cm + 200 %

    def test_recall_is_higher_is_better_in_regressions(self):
        # The degraded map puts a third of the tracking frames within 10 cm / 5 deg instead of all:
        # a baseline-only rule on recall knows that a fall is the regression (no "better" given).
        r = self.rules([{"metric": "r0/recall/10cm_5deg", "scenario": "ci_tracking"}])
        p = self.gate(self.bad, "--rules", r, "--baseline", self.good)
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        (line,) = self.verdicts(p.stdout)
        self.assertIn("[regression: mean", line)
        self.assertEqual(self.gate(self.good, "--rules", r, "--baseline", self.bad).returncode, 0)
        # The same for valid_fraction, and a "max" on recall does not turn the direction round.
        self.assertTrue(gate.higher_is_better("r0/tracking_phase/recall/25cm_10deg"))
        self.assertTrue(gate.higher_is_better("valid_fraction"))
        self.assertTrue(gate.higher_is_better("r0/recovery/recovered_fraction"))
        self.assertFalse(gate.higher_is_better("r0/position_m/rmse"))
        rules = gate.load_rules(self.rules([{"metric": "r0/recall/10cm_5deg", "max": 1.0}, {"metric": "r0/position_m/rmse", "min": 0.0},
                                            {"metric": "r0/recall/10cm_5deg", "better": "lower"}]), True)
        self.assertEqual([r.better for r in rules], ["higher", "higher", "lower"])  # min alone: higher, as before

    def test_higher_is_better_direction(self):
        # valid_fraction is 1 on both sides; a rule saying higher is better on the position error
        # treats the degraded (larger) error as an improvement.
        r = self.rules([{"metric": "r0/position_m/rmse", "better": "higher", "scenario": "ci_tracking"}])
        self.assertEqual(self.gate(self.bad, "--rules", r, "--baseline", self.good).returncode, 0)
        self.assertEqual(self.gate(self.good, "--rules", r, "--baseline", self.bad).returncode, 1)

    # ---- bad input: exit 2, nothing written ---------------------------------------------------

    def assert_bad(self, args, fragment):
        junit = self.tmp / "bad_junit.xml"
        p = self.gate(*args, "--junit", junit)
        self.assertEqual(p.returncode, 2, p.stdout + p.stderr)
        self.assertIn(fragment, p.stderr)
        self.assertNotIn("PASS", p.stdout + p.stderr)
        self.assertFalse(junit.exists())

    def test_bad_input(self):
        good_rules = self.rules([{"metric": "position_m/rmse", "max": 1}], "ok.json")
        self.assert_bad([self.tmp / "missing", "--rules", good_rules], "missing: No such file or directory")
        self.assert_bad([self.good, "--rules", self.tmp / "none.json"], "cannot be read")
        self.assert_bad([self.good, "--rules", self.rules("{nope", "broken.json")], "not JSON")
        self.assert_bad([self.good, "--rules", self.rules([])], "/rules: got [], expected a non-empty array")
        self.assert_bad([self.good, "--rules", self.rules([{"metric": "position_m/rmse", "max": "5 cm"}])], '/rules/0/max: got "5 cm", expected a finite number')
        self.assert_bad([self.good, "--rules", self.rules([{"metric": "position_m/rmse", "maximum": 1}])], "/rules/0/maximum: unknown key")
        self.assert_bad([self.good, "--rules", self.rules([{"metric": "position_m/rmse", "max": 1, "min": 2}])], "/rules/0/min: got 2, expected at most max")
        self.assert_bad([self.good, "--rules", self.rules([{"metric": "position_m/rmse"}])], "neither \"max\" nor \"min\", and no --baseline")
        self.assert_bad([self.good, "--rules", self.rules([{"metric": "position_m/rmsee", "max": 1}])], "metric \"position_m/rmsee\" is not among")
        self.assert_bad([self.good, "--rules", self.rules([{"metric": "position_m/rmse", "max": 1, "scenario": "nope"}])], "selects no group")
        self.assert_bad([self.good, "--rules", good_rules, "--alpha", "1.5"], "--alpha")
        self.assert_bad([self.good, "--rules", good_rules, "--baseline", self.tmp / "missing"], "baseline")
        # An unfinished sweep: its runs are there, its final aggregate is not.
        partial = self.tmp / "partial"
        shutil.copytree(self.good, partial)
        (partial / "aggregate.json").unlink()
        self.assert_bad([partial, "--rules", good_rules], "incomplete sweep")
        empty = self.tmp / "empty"
        empty.mkdir(exist_ok=True)
        self.assert_bad([empty, "--rules", good_rules], "no finished run")

    # ---- outputs -----------------------------------------------------------------------------

    def test_junit_against_schema(self):
        junit = self.tmp / "out" / "junit.xml"
        rules = self.rules([{"metric": "r0/position_m/rmse", "max": 0.08, "name": "rmse under 8 cm"},
                            {"metric": "r0/theta_rmse_rad", "max": 1.0}])
        p = self.gate(self.bad, "--rules", rules, "--baseline", self.good, "--junit", junit)
        self.assertEqual(p.returncode, 1)
        if shutil.which("xmllint"):
            v = run(["xmllint", "--noout", "--schema", str(XSD), str(junit)])
            self.assertEqual(v.returncode, 0, v.stderr)
        else:
            self.skipTest("xmllint (libxml2-utils) missing: scripts/install-deps.sh installs it")
        root = ET.parse(junit).getroot()
        self.assertEqual(root.tag, "testsuites")
        suites = root.findall("testsuite")
        self.assertEqual(sorted(s.get("name") for s in suites), ["ci_occlusion", "ci_tracking"])
        self.assertEqual(int(root.get("tests")), 4)
        self.assertEqual(int(root.get("failures")), 4)
        for s in suites:
            cases = s.findall("testcase")
            self.assertEqual(int(s.get("tests")), len(cases))
            self.assertEqual(int(s.get("failures")), sum(1 for c in cases if c.find("failure") is not None))
            for c in cases:
                f = c.find("failure")
                self.assertIsNotNone(f)
                msg = f.get("message")
                self.assertIn("regression", msg)
                self.assertIn("baseline", msg)
                self.assertIn(", p ", msg)
                self.assertEqual(c.get("classname"), f"omniloc.{s.get('name')}.matching")
        names = [c.get("name") for c in root.iter("testcase")]
        self.assertIn("ci_tracking / matching: rmse under 8 cm", names)
        limit_msgs = [c.find("failure").get("message") for c in root.iter("testcase") if "rmse under 8 cm" in c.get("name")]
        self.assertTrue(all("limit: r0/position_m/rmse mean" in m and "> max 0.08" in m for m in limit_msgs), limit_msgs)
        first = junit.read_bytes()
        self.gate(self.bad, "--rules", rules, "--baseline", self.good, "--junit", junit)
        self.assertEqual(junit.read_bytes(), first)  # no timestamps: same results, same file

    def test_junit_passing_is_valid_too(self):
        junit = self.tmp / "pass.xml"
        p = self.gate(self.good, "--rules", self.rules([{"metric": "r0/position_m/rmse", "max": 1.0}]), "--junit", junit)
        self.assertEqual(p.returncode, 0)
        root = ET.parse(junit).getroot()
        self.assertEqual(root.get("failures"), "0")
        self.assertEqual(len(list(root.iter("failure"))), 0)
        self.assertEqual(len(list(root.iter("system-out"))), 2)

    def test_benchmark_json_format(self):
        out = self.tmp / "bench.json"
        rules = self.rules([{"metric": "r0/position_m/rmse", "max": 0.08}, {"metric": "r0/position_m/rmse", "max": 0.2},
                            {"metric": "r0/valid_fraction", "min": 0.9}])
        p = self.gate(self.good, "--rules", rules, "--benchmark-json", out)
        self.assertEqual(p.returncode, 0, p.stdout)
        data = json.loads(out.read_text())
        self.assertIsInstance(data, list)
        self.assertEqual(len(data), 2)  # one per group and metric; valid_fraction (higher is better) left out
        self.assertIn("2 check(s) where higher is better are not in", p.stdout)
        names = [e["name"] for e in data]
        self.assertEqual(len(set(names)), len(names))
        for e in data:
            self.assertLessEqual(set(e), {"name", "unit", "value", "range", "extra"})
            self.assertIsInstance(e["name"], str)
            self.assertEqual(e["unit"], "m")
            self.assertIsInstance(e["value"], float)
            self.assertIsInstance(e["range"], str)
            self.assertIn("limit <= 0.08: PASS; limit <= 0.2: PASS", e["extra"])
            scenario = e["name"].split(" / ")[0]
            self.assertAlmostEqual(e["value"], self.aggregate_mean(self.good, scenario, "r0/position_m/rmse"), places=12)

    def test_partial_no_estimate_fails_and_a_baseline_without_one_is_noted(self):
        # One of five runs without an estimate: the group fails whatever its limit, and the mean over
        # the four others is not what decides.
        partial = self.tmp / "one_null"
        shutil.copytree(self.good, partial)
        with open(partial / "runs.csv", newline="") as fh:
            first = next(r["id"] for r in csv.DictReader(fh) if r["id"].startswith("ci_tracking"))
        f = partial / "runs" / first / "summary.json"
        s = json.loads(f.read_text())
        s["robots"][0]["position_m"]["rmse"] = None
        f.write_text(json.dumps(s))
        rules = self.rules([{"metric": "r0/position_m/rmse", "max": 1.0, "scenario": "ci_tracking"}])
        p = self.gate(partial, "--rules", rules)
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        (line,) = self.verdicts(p.stdout)
        self.assertTrue(line.startswith("FAIL"), line)
        self.assertIn("(n=4 of 5)", line)
        self.assertIn("[no estimate in 1 of 5 runs]", line)
        # Regression against a complete baseline: fails the same way.
        self.assertEqual(self.gate(partial, "--rules", rules, "--baseline", self.good).returncode, 1)
        # A baseline without an estimate in one run: compared on the others, and said.
        p = self.gate(self.good, "--rules", rules, "--baseline", partial)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("[baseline: no estimate in 1 of 5 runs]", p.stdout)

    # ---- through the omniloc binary ------------------------------------------------------------

    def test_cli_forwarding(self):
        p = run([OMNILOC, "gate", "--help"])
        self.assertEqual(p.returncode, 0)
        self.assertTrue(p.stdout.startswith("usage: omniloc gate"), p.stdout[:80])
        p = run([OMNILOC, "gate", str(self.good), "--rules", self.rules([{"metric": "position_m/rmse", "max": 1}])])
        self.assertEqual(p.returncode, 0, p.stderr)
        p = run([OMNILOC, "gate", str(self.good)])
        self.assertEqual(p.returncode, 2)

    def test_sweep_localizer_option_errors(self):
        p = run([OMNILOC, "sweep", str(SUITE), "--localizer", '{"type": "nope"}', "-o", str(self.tmp / "x")])
        self.assertEqual(p.returncode, 2)
        self.assertIn("--localizer/0/type", p.stderr)
        p = run([OMNILOC, "sweep", str(SUITE), "--localizer", "[1]", "-o", str(self.tmp / "x")])
        self.assertEqual(p.returncode, 2)
        self.assertIn("a localizer object", p.stderr)
        p = run([OMNILOC, "sweep", str(SUITE), "--localizer", '{"type": "mcl"}', "--slurm", "--tasks", "2", "--dry-run"])
        self.assertEqual(p.returncode, 2)
        self.assertIn("Slurm", p.stderr)
        self.assertFalse((self.tmp / "x").exists())


@needs_omniloc
class NoEstimate(unittest.TestCase):
    """mcl as paper 002 sets it (600 particles, without the adaptation to a missing compass) answers
    none of the hand-written recording's 30 frames: summary.json has every error statistic null
    (never 0), recall 0 and valid_fraction 0; matching answers every frame."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = pathlib.Path(tempfile.mkdtemp(prefix="gate_none_"))
        spec = {"name": "handwritten", "scenarios": [{"recording": str(HANDWRITTEN)}], "localizers": [{"type": "mcl", "adapt_to_no_compass": False}, {"type": "matching"}]}
        (cls.tmp / "sweep.json").write_text(json.dumps(spec))
        cls.sweep = cls.tmp / "sweep"
        p = run([OMNILOC, "sweep", str(cls.tmp / "sweep.json"), "-o", str(cls.sweep)])
        assert p.returncode == 0, p.stdout + p.stderr
        cls.mcl = next(d for d in (cls.sweep / "runs").iterdir() if "__mcl__" in d.name)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def rules(self, rules, name="rules.json"):
        f = self.tmp / name
        f.write_text(json.dumps({"rules": rules}))
        return str(f)

    def gate(self, *args):
        return run(GATE + [str(a) for a in args])

    def lines(self, out, localizer):
        return [ln for ln in out.splitlines() if ln.startswith(("PASS", "FAIL")) and f" / {localizer} " in ln]

    def test_the_fixture_has_no_estimate(self):
        r = json.loads((self.mcl / "summary.json").read_text())["robots"][0]
        self.assertIsNone(r["position_m"]["rmse"])
        self.assertEqual(r["frames"], 0)
        self.assertEqual(r["valid_fraction"], 0.0)
        self.assertIn("no estimate", r["why_null"])

    def test_a_run_without_estimates_fails_an_accuracy_limit(self):
        junit = self.tmp / "junit.xml"
        p = self.gate(self.mcl, "--rules", self.rules([{"metric": "position_m/rmse", "max": 0.10}]), "--junit", junit)
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        (line,) = self.lines(p.stdout, "mcl")
        self.assertTrue(line.startswith("FAIL"), line)
        self.assertIn("no estimate in 1 of 1 runs", line)
        self.assertNotIn("mean 0 ", line)
        self.assertIn("gate: 0 of 1 checks passed, 1 failed", p.stdout)
        (case,) = ET.parse(junit).getroot().iter("testcase")
        fail = case.find("failure")
        self.assertIsNotNone(fail)
        self.assertIn("no estimate in 1 of 1 runs", fail.get("message"))
        self.assertEqual(fail.get("type"), "no estimate")
        if shutil.which("xmllint"):
            v = run(["xmllint", "--noout", "--schema", str(XSD), str(junit)])
            self.assertEqual(v.returncode, 0, v.stderr)

    def test_every_kind_of_rule_fails_without_an_estimate(self):
        rules = self.rules([{"metric": "r0/position_m/rmse", "max": 0.10}, {"metric": "r0/theta_rmse_rad", "min": 0.0},
                            {"metric": "r0/x_cm/max", "stat": "max", "max": 100.0}, {"metric": "r0/first_within_s", "max": 1.0}])
        p = self.gate(self.sweep, "--rules", rules)
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        mcl, matching = self.lines(p.stdout, "mcl"), self.lines(p.stdout, "matching")
        self.assertEqual(len(mcl), 4)
        self.assertTrue(all(ln.startswith("FAIL") and "no estimate in 1 of 1 runs" in ln for ln in mcl), mcl)
        self.assertTrue(all(ln.startswith("PASS") for ln in matching), matching)
        # A baseline-only rule (the run against itself): no estimate still fails.
        p = self.gate(self.sweep, "--rules", self.rules([{"metric": "r0/position_m/rmse"}]), "--baseline", self.sweep)
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        self.assertTrue(self.lines(p.stdout, "mcl")[0].startswith("FAIL"))
        self.assertTrue(self.lines(p.stdout, "matching")[0].startswith("PASS"))

    def test_a_min_recall_rule(self):
        rules = self.rules([{"metric": "recall/25cm_10deg", "min": 0.9}, {"metric": "r0/valid_fraction", "min": 0.9}])
        p = self.gate(self.sweep, "--rules", rules)
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        for ln in self.lines(p.stdout, "mcl"):  # recall and valid_fraction are 0, not null: a number below the limit
            self.assertTrue(ln.startswith("FAIL"), ln)
            self.assertIn("mean 0 (n=1)", ln)
            self.assertIn("< min 0.9", ln)
        self.assertTrue(all(ln.startswith("PASS") for ln in self.lines(p.stdout, "matching")))
        only = self.rules([{"metric": "r0/recall/25cm_10deg", "min": 0.9, "localizer": "matching"}])
        self.assertEqual(self.gate(self.sweep, "--rules", only).returncode, 0)

    def test_benchmark_json_leaves_out_a_check_without_value(self):
        out = self.tmp / "bench.json"
        p = self.gate(self.sweep, "--rules", self.rules([{"metric": "r0/position_m/rmse", "max": 0.10}]), "--benchmark-json", out)
        self.assertEqual(p.returncode, 1)
        data = json.loads(out.read_text())
        self.assertEqual([e["name"] for e in data], ["handwritten / matching: r0/position_m/rmse (mean)"])
        self.assertIn("1 check(s) without a value (no estimate) are not in", p.stdout)


if __name__ == "__main__":
    unittest.main()
