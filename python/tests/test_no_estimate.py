"""Runs without an estimate: a null statistic is never 0, in every tool (docs/results.md "Coverage and recall").
"""
import csv
import io
import json
import pathlib
import subprocess
import tempfile
import unittest

from helpers import OMNILOC, PY, ROOT, SCORING, load_script, needs_omniloc, robot, scored, without_estimate, write_run
from omniloc import compare as CMP
from omniloc.core import metrics as M
from omniloc.core import pairing as PR
from omniloc.core import rundir as RD
from omniloc.paper import claims as C
from omniloc.paper import tables as T
from omniloc.report import experiments as REXP
from omniloc.report import published as RPUB
from omniloc.report import runs as RRUN
from omniloc.tools import markup as MU


class NoEstimate(unittest.TestCase):
    """A statistic over no answered frame is null in summary.json: every tool says "no estimate"
    (or "no estimate in k of n runs"), never 0, never a crash; coverage (recall at the headline
    threshold, the share answered) comes before the errors."""

    def test_lookup_tells_a_null_from_an_absent_key_and_keeps_the_phase(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            rob = scored(robot(3.0))
            rob["tracking_phase"] = without_estimate(40)  # estimates only while carried: none in the tracking phase
            write_run(tmp / "a", "kidnap_002", "hybrid", 1, {}, rob, scoring=SCORING)
            old = robot(3.0)
            del old["position_m"]["mean"]
            write_run(tmp / "b", "kidnap_002", "hybrid", 2, {}, old)
            a, b = RD.discover([tmp])[0]
            self.assertEqual(a.lookup("x_cm/mean"), (True, None))
            self.assertIsNone(a.metric("x_cm/mean"))  # not the all-frames 3.0
            self.assertEqual(a.metric("x_cm/mean", "all"), 3.0)
            self.assertEqual(a.why_null("x_cm/mean"), "no estimate in any of the 40 scored frames")
            self.assertEqual(b.lookup("position_m/mean"), (False, None))
            st = M.run_stats([a, b], "x_cm/mean")
            self.assertEqual((st.n, st.no_value, st.of, st.mean), (1, 1, 2, 3.0))
            st = M.run_stats([a, b], "position_m/mean")
            self.assertEqual((st.n, st.no_value, st.of), (0, 1, 1))
            self.assertEqual(M.stat_cell(st), "no estimate")
            self.assertEqual(M.no_value_note([st]), "no estimate in 1 of 1 runs")
            self.assertEqual((a.headline, b.headline, M.headline_key([a, b])), ("25cm_10deg", None, "25cm_10deg"))
            self.assertEqual(M.recall_label("25cm_10deg"), "25 cm / 10 deg")
            self.assertEqual(M.recall_label("12.5cm_7.5deg"), "12.5 cm / 7.5 deg")

    def test_compare_says_no_estimate_and_leads_with_recall(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            for s in (1, 2, 3):
                write_run(tmp / "A" / f"r{s}", "tracking", "matching", s, {}, scored(robot(2.0 + s / 10)), start_pose_given=True, scoring=SCORING)
                rob = without_estimate() if s == 3 else scored(robot(2.1 + s / 10), answered=0.9, within=0.8)
                write_run(tmp / "B" / f"r{s}", "tracking", "matching", s, {}, rob, start_pose_given=True, scoring=SCORING)
            header, rows = CMP.compare_rows(RD.discover([tmp / "A"])[0], RD.discover([tmp / "B"])[0])
            metrics = [r[1] for r in rows]
            self.assertEqual(metrics[:3], ["recall/25cm_10deg", "valid_fraction", "position_m/rmse"])  # coverage first
            self.assertIn("recall/10cm_5deg", metrics)
            rmse = rows[2]
            self.assertEqual(rmse[header.index("exceeds spread")], "no estimate in 1 of 3 runs (B)")
            self.assertEqual(rmse[header.index("p (Welch)")], "-")
            self.assertEqual(rmse[header.index("B - A")], "-")
            self.assertEqual(rmse[5], 2)  # B's n: the runs with a value
            recall = rows[0]
            self.assertAlmostEqual(float(recall[header.index("B mean")]), 1.6 / 3, places=4)  # 0.8, 0.8 and 0 (no estimate counts as outside)
            self.assertNotIn("no estimate", recall[header.index("exceeds spread")])
            out = subprocess.run([PY, "-m", "omniloc.commands.compare", str(tmp / "A"), str(tmp / "B")], capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertIn("no estimate in 1 of 3 runs (B)", out.stdout)
            self.assertLessEqual(max(len(l) for l in out.stdout.splitlines()[2:]), 100)
            first = [l.split()[0] for l in out.stdout.splitlines() if l.startswith("  ") and l.split()[0] not in ("metric",)][:3]
            self.assertEqual(first, ["recall/25cm_10deg", "valid_fraction", "position_m/rmse"])
            # Every run without an estimate: the mean reads "no estimate", never 0.
            _, rows = CMP.compare_rows(RD.discover([tmp / "B"])[0][2:], RD.discover([tmp / "B"])[0][2:])
            rmse = [r for r in rows if r[1] == "position_m/rmse"][0]
            self.assertEqual(rmse[2:5], ["no estimate", 0, "no estimate"])
            self.assertEqual(rmse[-1], "no estimate in 1 of 1 runs (A and B)")

    def tracking_without_estimate(self, tmp):
        for s in (1, 2, 3):
            write_run(tmp / "res" / f"matching{s}", "tracking", "matching", s, {}, without_estimate(), start_pose_given=True, scoring=SCORING)
            write_run(tmp / "res" / f"mcl{s}", "tracking", "mcl", s, {}, scored(robot(20.0 + s), answered=0.5, within=0.4),
                      start_pose_given=False, scoring=SCORING)
        return RD.discover([tmp / "res"])[0]

    def test_paper_table_and_claims_say_no_estimate(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            runs = self.tracking_without_estimate(tmp)
            rows = {p.label: p for p in T.pair_table(PR.load_papers(), "000_tracking", runs)}
            st = rows["tracking"].stats["x_cm/mean"]
            self.assertEqual((st.n, st.no_value, st.mean), (0, 3, None))
            out = subprocess.run([PY, "-m", "omniloc.commands.paper_table", str(tmp / "res"), "--paper", "000_tracking"], capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            head = out.stdout.splitlines()[0]
            self.assertLess(head.index("within 25 cm / 10 deg"), head.index("answered"))
            self.assertLess(head.index("answered"), head.index("mean x"))
            row = [l for l in out.stdout.splitlines() if l.startswith("tracking ") and "omniloc" in l][0]
            self.assertEqual(row.split("omniloc")[1].split()[:6], ["0.0", "%", "0.0", "%", "no", "estimate"])
            self.assertIn("3; no estimate in 3 of 3 runs", row)
            self.assertNotIn("0.000", row)
            mcl = [l for l in out.stdout.splitlines() if l.startswith("tracking path, MCL alone") and "omniloc" in l][0]
            self.assertEqual(mcl.split("omniloc")[1].split()[:5], ["40.0", "%", "50.0", "%", "22.000"])  # coverage, then the error over answered frames
            ratio = [l for l in out.stdout.splitlines() if l.startswith("tracking ") and "ours/paper" in l][0]
            self.assertNotIn("0.00", ratio)
            # The claim on the tracking row is not judged on nothing: "does not", with the reason.
            claims = {c.id: c for c in C.evaluate_claims(T.Context(PR.load_papers(), runs, []))}
            t = claims["tracking_accuracy"]
            self.assertEqual(t.verdict, "does not")
            self.assertIn("no estimate in 3 of 3 runs", t.ours_text)
            self.assertIn("answered 0.0 %", C.coverage_text(t.coverage))
            self.assertTrue(C.no_estimate("no estimate in 1 of 3 runs"))
            self.assertEqual(C.judge(None, {"kind": "range", "holds": [0, 1]}, note="not run: x"), "not run")

    def test_the_report_shows_no_estimate_never_zero_and_coverage_first(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            self.tracking_without_estimate(tmp)
            out = subprocess.run([PY, "-m", "omniloc.commands.report", str(tmp / "res"), "-o", str(tmp / "rep"), "--history", "none"],
                                 capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            md = (tmp / "rep" / "report.md").read_text()
            self.assertNotRegex(md, r"\bnan\b")
            # Scorecard: the coverage of our runs first, the claim not judged on nothing.
            self.assertIn("| paper | claim | our runs: coverage | ours (robot profile) |", md)
            self.assertIn("| within 25 cm / 10 deg 0.0 %, answered 0.0 % (no estimate in 3 of 3 runs) | no estimate in 3 of 3 runs |", md)
            # The published table: coverage columns lead, errors read "no estimate".
            self.assertIn("| row | source | within 25 cm / 10 deg | answered | mean x cm |", md)
            self.assertIn("| tracking (given the start pose) | omniloc | 0.0 % | 0.0 % | no estimate | no estimate |", md)
            self.assertIn("| 3; no estimate in 3 of 3 runs |", md)
            self.assertIn("| tracking path, MCL alone (global start) | omniloc | 40.0 % | 50.0 % | 22.000 |", md)
            # The seeds: coverage first, then "no estimate in 3 of 3 runs" for the errors.
            self.assertIn("| row | n | within 25 cm / 10 deg, % of frames | answered, % of frames | mean x cm |", md)
            self.assertIn("| no estimate in 3 of 3 runs | no estimate in 3 of 3 runs | no estimate in 3 of 3 runs | - |", md)
            # Each run's table.
            self.assertIn("| r0 | 0.0 % | 0.0 % | no estimate |", md)
            self.assertIn("first estimate never, first within 25 cm / 10 deg never", md)

    def test_runs_that_answer_every_frame_still_show_their_errors(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            for s in (1, 2):
                write_run(tmp / "A" / f"r{s}", "tracking", "matching", s, {}, scored(robot(2.5)), start_pose_given=True, scoring=SCORING)
            out = subprocess.run([PY, "-m", "omniloc.commands.report", str(tmp / "A"), "-o", str(tmp / "rep"), "--history", "none"],
                                 capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            md = (tmp / "rep" / "report.md").read_text()
            self.assertIn("| 0 % | omniloc | 100.0 % | 100.0 % | 2.500 | 1.000 |", md)  # recall leads, the error follows
            self.assertIn("| r0 | 100.0 % | 100.0 % | 2.500 |", md)
            self.assertIn("| 0.020 | 0.025 |", md)  # position mean and RMSE
            self.assertNotIn("| no estimate", md)

    def test_kidnap_without_recovery_and_error_budget_without_estimate(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            rob = scored(robot(150.0), answered=0.5, within=0.3)
            rob["tracking_phase"] = without_estimate(40)
            after = {a: dict.fromkeys(("mean", "std", "max")) for a in ("x_cm", "y_cm", "theta_rad")}
            after.update(position_m=dict.fromkeys(("mean", "rmse")), theta_rmse_rad=None, frames=0, why_null="no kidnap recovered")
            rob["recovery"] = {"episodes": 2, "recovered": 0, "recovered_fraction": 0.0, "false_recoveries": 0, "mirrored": 0,
                               "recovery_time_s": {"median": None, "mean": None, "max": None}, "after_recovery": after}
            write_run(tmp / "res" / "k1", "kidnap_002", "hybrid", 1, {}, rob, start_pose_given=False, scoring=SCORING)
            runs = RD.discover([tmp / "res"])[0]
            rep = MU.Report(tmp / "out", "t")
            RPUB.kidnap_table(rep, PR.load_papers(), runs)
            RRUN.report_run(rep, runs[0], plots=False)
            rep.write()
            md = (tmp / "out" / "report.md").read_text()
            self.assertIn("| 0 / 2 | 0 | none recovered | no kidnap recovered | no estimate (answered 0.0 %) | 150.0 (answered 50.0 %) | s1\u00a00/2\u00a0no estimate | 1 |", md)
            self.assertIn("| r0 | 2 | 0 | 0 | 0 | none recovered | none recovered | no kidnap recovered | no kidnap recovered |", md)
            self.assertIn("| r0 tracking phase | 0.0 % | 0.0 % | no estimate |", md)
            # An error budget row whose runs answered nothing (the experiment writes null): no number.
            e = tmp / "error_budget"
            e.mkdir()
            seeds = [{"seed": 1, "position_rmse_cm": None, "position_p50_cm": None, "heading_rmse_deg": None},
                     {"seed": 2, "position_rmse_cm": 4.0, "position_p50_cm": 2.0, "heading_rmse_deg": 0.1}]
            rows = [{"source": "none (baseline)", "localizer": "matching", "runs": 2, "failed": 0, "position_rmse_cm": None, "position_p50_cm": None,
                     "heading_rmse_deg": None, "per_seed": seeds[:1]},
                    {"source": "vibration", "localizer": "matching", "runs": 2, "failed": 0, "position_rmse_cm": 4.0, "position_p50_cm": 2.0,
                     "heading_rmse_deg": 0.1, "per_seed": seeds}]
            (e / "error_budget.json").write_text(json.dumps({"experiment": "error_budget", "config_file": "x.json", "quick": False, "duration_s": 60.0,
                                                               "seeds": 2, "first_seed": 1, "sweep": "s", "rows": rows}))
            rep = MU.Report(tmp / "out2", "t")
            REXP.error_budget_section(rep, T.Context(PR.load_papers(), [], [str(e)]))
            rep.write()
            md = (tmp / "out2" / "report.md").read_text()
            self.assertIn("| none (baseline) | no estimate | no estimate | no estimate |", md)
            self.assertIn("| vibration | 4.00 (no estimate in 1 of 2 runs) |", md)

    @needs_omniloc
    def test_a_sweep_with_a_localizer_that_never_answers(self):
        # Through the binary: mcl answers none of the hand-written recording's frames, matching all.
        # (Paper 002's 600-particle MCL: with its defaults MCL adapts to the missing compass and answers.)
        K = load_script("check_report_html")
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            spec = {"name": "hw", "scenarios": [{"recording": str(ROOT / "tests" / "data" / "handwritten_recording")}],
                    "localizers": [{"type": "mcl", "adapt_to_no_compass": False}, {"type": "matching"}]}
            (tmp / "hw.json").write_text(json.dumps(spec))
            out = subprocess.run([OMNILOC, "sweep", str(tmp / "hw.json"), "-o", str(tmp / "hw")], capture_output=True, text=True, cwd=tmp, timeout=300)
            self.assertEqual(out.returncode, 0, out.stdout + out.stderr)
            agg = list(csv.DictReader(io.StringIO((tmp / "hw" / "aggregate.csv").read_text())))
            rmse = {r["localizer"]: r for r in agg if r["metric"] == "r0/position_m/rmse"}
            self.assertEqual((rmse["mcl"]["n"], rmse["mcl"]["mean"], rmse["mcl"]["no_value"]), ("0", "", "1"))
            out = subprocess.run([PY, "-m", "omniloc.commands.report", str(tmp / "hw"), "-o", str(tmp / "rep"), "--history", "none",
                                  "--baseline", str(tmp / "hw")], capture_output=True, text=True, cwd=tmp)
            self.assertEqual(out.returncode, 0, out.stderr)
            md = (tmp / "rep" / "report.md").read_text()
            self.assertIn("| group | within 25 cm / 10 deg | answered | mean x cm |", md)
            self.assertIn("| handwritten / mcl / `recording` | 0.0 % | 0.0 % | no estimate |", md)
            self.assertIn("| 1/0 | 0; no estimate in 1 of 1 runs |", md)
            self.assertRegex(md, r"\| handwritten / matching \(given the start pose\) / `recording` \| 100\.0 % \| 100\.0 % \| 0\.0\d\d \|")
            self.assertIn("| mcl | ideal | 1 | 0.0 % | 0.0 % | 0 | no estimate | no estimate | no estimate |", md)  # the CDF table keeps it
            self.assertIn("| `position_m/rmse` |", md)
            self.assertIn("no estimate in 1 of 1 runs (A and B)", md)
            dom = (tmp / "rep" / "report.html").read_text()
            # The collapsed block of the sweep's runs (report.html only) names the sweep, not the
            # localizer of its last row.
            self.assertIn("<summary>Runs of sweep hw: 2 runs, tables and plots</summary>", dom)
            ok, detail = K.check_no_raw_keys(dom, K.reader_names() | {"hw"})
            self.assertTrue(ok, detail)
            self.assertEqual(K.negative_bounds(K.visible_text(dom)), [])
