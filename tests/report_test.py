"""Tests of the comparison side (scripts/omniloc_results.py, paper_claims.py, compare.py, report.py,
paper_table.py): pairing by key under a shuffled sweep, valid CSV of real sweep specs, the phase
split used by the tables, `compare` on result sets that differ by a known amount, and the
statistics. Run by ctest (tests/CMakeLists.txt) with OMNILOC_BIN = the built omniloc."""
import csv
import io
import json
import math
import re
import os
import pathlib
import random
import subprocess
import sys
import tempfile
import unittest

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
import compare  # noqa: E402
import omniloc_results as R  # noqa: E402
import paper_claims as C  # noqa: E402

PY = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
OMNILOC = os.environ.get("OMNILOC_BIN", str(ROOT / "build" / "omniloc"))


def robot(x_mean, y_mean=1.0, th=0.01, extra=None):
    axis = lambda m: {"mean": m, "std": m / 2, "max": 3 * m}
    r = {"robot": 0, "frames": 100, "x_cm": axis(x_mean), "y_cm": axis(y_mean), "theta_rad": axis(th),
         "position_m": {"mean": x_mean / 125, "rmse": x_mean / 100, "p50": 0, "p90": 0, "p95": 0, "max": 0}, "line_points": {"mean": 80, "min": 50},
         "wrong_frames": 0, "coasting_frames": 0}
    r.update(extra or {})
    return r


def write_run(folder, scenario, localizer, seed, config, rob, version="abc123", start_pose_given=None, external=False, scoring=None):
    """A run folder; start_pose_given None: a run from before omniloc recorded it (no key); scoring:
    summary.json's "scoring" block (SCORING; None: a run from before recall was scored)."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    summary = {"scenario": scenario, "localizer": localizer, "seed": seed, "robots": [rob],
               "omniloc": {"version": version, "compiler": "GNU", "build_type": "Release"}}
    if scoring is not None:
        summary["scoring"] = scoring
    if start_pose_given is not None:
        summary["start_pose_given"] = start_pose_given
    if external:
        summary["localizer_type"] = "external"
    (folder / "summary.json").write_text(json.dumps(summary))
    (folder / "config.json").write_text(json.dumps(dict(config, seed=seed, name=scenario)))


# The coverage keys of a current summary.json (docs/results.md "Coverage and recall").
SCORING = {"recall": [{"position_m": 0.1, "heading_deg": 5.0}, {"position_m": 0.25, "heading_deg": 10.0},
                      {"position_m": 0.5, "heading_deg": 20.0}], "headline": "25cm_10deg"}
RECALL_KEYS = ("10cm_5deg", "25cm_10deg", "50cm_20deg")


def scored(rob, answered=1.0, within=1.0, total=100):
    """robot() with the coverage a current omniloc writes: frames_total, valid_fraction, recall."""
    return dict(rob, frames=round(answered * total), frames_total=total, valid_fraction=answered, recall=dict.fromkeys(RECALL_KEYS, within),
                first_estimate_s=0.0, first_within_s=0.0 if within else None)


def without_estimate(total=100):
    """A robot block of a run whose localizer answered none of its frames, as omniloc writes it:
    every error statistic null (never 0), why_null beside them, recall and valid_fraction 0."""
    r = robot(1.0)
    for axis in ("x_cm", "y_cm", "theta_rad"):
        r[axis] = dict.fromkeys(("mean", "std", "max"))
    r["position_m"] = dict.fromkeys(("mean", "rmse", "p50", "p90", "p95", "max"))
    r.update(theta_rmse_rad=None, frames=0, frames_total=total, valid_fraction=0.0, recall=dict.fromkeys(RECALL_KEYS, 0.0),
             why_null=f"no estimate in any of the {total} scored frames", first_estimate_s=None, first_within_s=None)
    return r


OCCLUSION = {0.0: 2.0, 0.125: 2.5, 0.25: 3.0, 0.5: 4.0}  # mean x cm per fraction (+ seed / 100)


def write_occlusion_sweep(folder, order, seeds=(1, 2, 3)):
    """A sweep folder like scenarios/sweeps/occlusion_002.json's, its runs written in `order`."""
    folder = pathlib.Path(folder)
    lines = ["index,id,scenario,localizer,params,seed,status"]
    k = 0
    for frac in order:
        for s in seeds:
            rid = f"tracking__matching__occ{frac}__s{s}"
            cfg = {} if frac == 0.0 else {"occlusion": {"fraction": frac, "sectors": 2}}
            write_run(folder / "runs" / rid, "tracking", "matching", s, cfg, robot(OCCLUSION[frac] + s / 100))
            params = json.dumps({"fraction": frac}, separators=(",", ":"))
            lines.append(",".join([str(k), rid, "tracking", "matching", '"occlusion=' + params.replace('"', '""') + '"', str(s), "ok"]))
            k += 1
    (folder / "runs.csv").write_text("\n".join(lines) + "\n")
    (folder / "aggregate.json").write_text(json.dumps({"sweep": "occ", "runs": k, "groups": []}))


class Pairing(unittest.TestCase):
    def test_rows_pair_by_key_whatever_the_order_of_the_sweep(self):
        papers = R.load_papers()
        orders = [[0.0, 0.125, 0.25, 0.5], [0.5, 0.0, 0.25, 0.125]]
        random.Random(7).shuffle(orders[1])
        tables = []
        with tempfile.TemporaryDirectory() as tmp:
            for i, order in enumerate(orders):
                write_occlusion_sweep(pathlib.Path(tmp) / f"s{i}", order)
                runs, sweeps, _ = R.discover([pathlib.Path(tmp) / f"s{i}"])
                self.assertEqual(len(sweeps), 1)
                self.assertEqual(len(runs), 12)
                rows = C.pair_table(papers, "002_table1_occlusion", runs, include_extra=False)
                tables.append([(p["label"], p["stats"]["x_cm/mean"]["mean"], p["stats"]["x_cm/mean"]["n"]) for p in rows])
        self.assertEqual(tables[0], tables[1])
        got = {label: (m, n) for label, m, n in tables[0]}
        for label, frac in (("0 %", 0.0), ("12.5 %", 0.125), ("25 %", 0.25), ("50 %", 0.5)):
            self.assertAlmostEqual(got[label][0], OCCLUSION[frac] + 0.02, places=9, msg=label)  # mean of seeds 1..3: +0.02
            self.assertEqual(got[label][1], 3)

    def test_runs_of_another_noise_profile_do_not_mix_into_the_rows(self):
        # The published rows pair runs of the robot profile; the same rows under field_robot are a
        # table of their own (report.py field_robot_tables), never averaged into the robot rows.
        papers = R.load_papers()
        with tempfile.TemporaryDirectory() as tmp:
            write_occlusion_sweep(pathlib.Path(tmp) / "robot", [0.0], seeds=(1, 2))
            write_run(pathlib.Path(tmp) / "field" / "tracking__field", "tracking", "matching", 1, {"noise_profile": "field_robot"}, robot(50.0))
            runs, _, _ = R.discover([pathlib.Path(tmp)])
            self.assertEqual(len(runs), 3)
            row = C.pair_table(papers, "002_table1_occlusion", runs, labels=["0 %"])[0]
            self.assertEqual(row["stats"]["x_cm/mean"]["n"], 2)
            self.assertAlmostEqual(row["stats"]["x_cm/mean"]["mean"], OCCLUSION[0.0] + 0.015, places=9)
            with R.pairing_profile("field_robot"):
                row = C.pair_table(papers, "002_table1_occlusion", runs, labels=["0 %"])[0]
            self.assertEqual(row["stats"]["x_cm/mean"]["n"], 1)
            self.assertAlmostEqual(row["stats"]["x_cm/mean"]["mean"], 50.0, places=9)

    def test_missing_rows_say_not_run_with_the_command(self):
        papers = R.load_papers()
        with tempfile.TemporaryDirectory() as tmp:
            write_occlusion_sweep(pathlib.Path(tmp) / "s", [0.0])
            out = subprocess.run([PY, str(ROOT / "scripts/paper_table.py"), tmp, "--paper", "002_table1_occlusion"], capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertIn("not run: 50 %", out.stdout)
            self.assertIn(papers["002_table1_occlusion"]["reproduced_by"]["command"], out.stdout)
            bad = subprocess.run([PY, str(ROOT / "scripts/paper_table.py"), tmp, "--paper", "002_table1_occlusion", "--rows", "strong sun"],
                                 capture_output=True, text=True)
            self.assertEqual(bad.returncode, 2)
            self.assertIn("'12.5 %'", bad.stderr)  # the valid rows are listed
            bad = subprocess.run([PY, str(ROOT / "scripts/paper_table.py"), tmp, "--paper", "nope"], capture_output=True, text=True)
            self.assertEqual(bad.returncode, 2)
            self.assertIn("002_table2_lighting", bad.stderr)

    def test_stale_runs_of_an_older_spec_are_not_reported(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_occlusion_sweep(pathlib.Path(tmp) / "s", [0.0])
            write_run(pathlib.Path(tmp) / "s" / "runs" / "old_run", "tracking", "matching", 1, {}, robot(99.0))
            runs, _, _ = R.discover([tmp])
            self.assertEqual(len(runs), 3)
            self.assertNotIn(99.0, [r.metric("x_cm/mean") for r in runs])

    def test_every_published_row_is_run_by_the_paper_suite(self):
        # Each reproduced_by key must name a condition the default suite runs (scenario name,
        # localizer type and configuration values applied as the sweep applies them).
        papers = R.load_papers()
        suite = json.loads((ROOT / "scenarios/sweeps/paper_suite.json").read_text())
        conditions = []
        for e in suite["scenarios"]:
            e = e if isinstance(e, dict) else {"file": e}
            scen = json.loads((ROOT / "scenarios/sweeps" / e["file"]).read_text())
            name = scen.get("name", pathlib.Path(e["file"]).stem)
            locs = [l["type"] for l in e.get("localizers", [])] or [scen.get("localizer", {}).get("type")]
            combos = [scen]
            for ptr, values in (e.get("parameters") or {}).items():
                nxt = []
                for c in combos:
                    for v in values:
                        c2 = json.loads(json.dumps(c))
                        parts = ptr.strip("/").split("/")
                        d = c2
                        for p in parts[:-1]:
                            d = d.setdefault(p, {})
                        d[parts[-1]] = v
                        nxt.append(c2)
                combos = nxt
            for c in combos:
                for l in locs:
                    conditions.append((name, l, c))
        for table, t in papers.items():
            rb = t.get("reproduced_by") if isinstance(t, dict) else None
            if not rb or "rows" not in rb:
                continue
            for label, key in list(rb["rows"].items()) + list(rb.get("extra_rows", {}).items()):
                names = key["scenario"] if isinstance(key["scenario"], list) else [key["scenario"]]
                ok = False
                for name, loc, cfg in conditions:
                    if name not in names or ("localizer" in key and loc != key["localizer"]):
                        continue
                    good = True
                    for ptr, want in (key.get("config") or {}).items():
                        found, have = R.pointer(cfg, ptr)
                        if not found:
                            found, have = ptr in rb.get("config_defaults", {}), rb.get("config_defaults", {}).get(ptr)
                        good = good and found and R.same_value(have, want)
                    ok = ok or good
                self.assertTrue(ok, f"{table} / {label}: no condition of the paper suite matches {R.describe_key(key)}")


class ValidCsv(unittest.TestCase):
    def test_real_sweep_specs_write_rfc4180_csv(self):
        for spec in ("occlusion_002", "lighting_002", "paper_suite"):
            with tempfile.TemporaryDirectory() as tmp:
                path = str(ROOT / "scenarios/sweeps" / f"{spec}.json")
                # The final aggregate needs every run done or failed (issue 31): record each as failed.
                # --status with one shard per run lists every missing run id.
                first = subprocess.run([OMNILOC, "sweep", path, "--status", "-o", tmp], capture_output=True, text=True).stdout
                n = int(re.search(r": (\d+) runs in", first).group(1))
                listing = subprocess.run([OMNILOC, "sweep", path, "--status", "--tasks", str(n), "-o", tmp], capture_output=True, text=True).stdout
                ids = re.findall(r"missing: (\S+)", listing)
                self.assertEqual(len(ids), n, listing)
                (pathlib.Path(tmp) / "failed").mkdir(exist_ok=True)
                for i in ids:
                    (pathlib.Path(tmp) / "failed" / f"{i}.json").write_text("{}\n")
                out = subprocess.run([OMNILOC, "sweep", path, "--aggregate-only", "-o", tmp], capture_output=True, text=True)
                self.assertEqual(out.returncode, 0, out.stderr)  # every run done (failed): the aggregate is final
                for f in ("runs.csv", "aggregate.csv"):
                    rows = list(csv.reader(io.StringIO((pathlib.Path(tmp) / f).read_text(), newline="")))
                    self.assertGreaterEqual(len(rows), 1)
                    for r in rows:
                        self.assertEqual(len(r), len(rows[0]), f"{spec}/{f}: {r}")
                rows = list(csv.DictReader(io.StringIO((pathlib.Path(tmp) / "runs.csv").read_text(), newline="")))
                if spec == "occlusion_002":
                    self.assertEqual(rows[1]["params"], 'occlusion={"fraction":0.125,"sectors":2}')


class Statistics(unittest.TestCase):
    def test_student_t(self):
        self.assertAlmostEqual(R.t_quantile_975(1), 12.706, places=3)
        self.assertAlmostEqual(R.t_quantile_975(10), 2.228, places=3)
        self.assertAlmostEqual(R.t_two_sided_p(2.228, 10), 0.05, places=4)

    def test_intervals_only_with_two_values(self):
        self.assertIsNone(R.stats([4.75])["lo"])
        self.assertEqual(R.fstat(R.stats([4.75])), "4.750 (n=1, no interval)")
        self.assertEqual(R.interval([4.75]), {"n": 1, "mean": 4.75, "lo": 4.75, "hi": 4.75, "kind": R.NO_INTERVAL})
        self.assertEqual(R.interval([None, float("nan")])["kind"], None)


class IntervalRule(unittest.TestCase):
    """Issue 38, item 4: one interval rule everywhere (docs/results.md "Intervals"), the same as
    batch/aggregate.cpp's mean_ci95 (tests/sweep_test.cpp Sweep.ConfidenceInterval: same answers)."""

    def test_five_or_more_seeds_get_the_t_interval(self):
        # 1..5: mean 3, sd 1.58114, t(4) = 2.776445: half width 1.963243.
        iv = R.interval([1.0, 2.0, 3.0, 4.0, 5.0])
        self.assertEqual(iv["kind"], R.T95)
        self.assertAlmostEqual(iv["hi"] - iv["mean"], 1.963243, places=5)
        self.assertAlmostEqual(iv["mean"] - iv["lo"], 1.963243, places=5)
        self.assertEqual(R.interval_text(iv), "3.000 [1.037, 4.963] (n=5, t95)")
        s = R.stats([1.0, 2.0, 3.0, 4.0, 5.0])
        self.assertEqual((s["lo"], s["hi"], s["method"]), (iv["lo"], iv["hi"], R.T95))

    def test_fewer_than_five_seeds_get_their_range_marked_as_such(self):
        # One seed at 806 cm beside two at 3 cm (the issue's MCL row): Student t gives [-881, 1422],
        # the old bootstrap [3.0, 712] (it never leaves the seeds' range and covers the mean ~60 %).
        iv = R.interval([806.0, 3.0, 3.0])
        self.assertEqual((iv["lo"], iv["hi"], iv["kind"]), (3.0, 806.0, R.RANGE))
        self.assertEqual(R.interval_text(iv, 2), "270.67 (seeds' range 3.00 to 806.00, n=3)")
        self.assertEqual(R.interval([1.0, 2.0, 3.0, 4.0])["kind"], R.RANGE)
        self.assertEqual(R.interval_text(R.interval([1.0, 2.0, 3.0, 4.0]), 2), "2.50 (seeds' range 1.00 to 4.00, n=4)")
        s = R.stats([806.0, 3.0, 3.0])
        self.assertEqual((s["lo"], s["hi"], s["method"], s["median"]), (3.0, 806.0, R.RANGE, 3.0))
        self.assertEqual(s["values"], [806.0, 3.0, 3.0])
        self.assertEqual(R.stats([2.0, 2.0, 2.0])["lo"], 2.0)

    def test_a_non_negative_sample_never_gets_a_negative_bound(self):
        # Unclipped t: mean 2.06 - 5.53 < 0; the clipped bound is 0; a signed sample keeps its t bound.
        for v in ([0.05, 0.1, 0.1, 0.05, 10.0], [0.0, 0.0, 0.0, 0.0, 7.0], [806.0, 3.0, 3.0], [1e-3, 5.0], [0.0] * 6, [0.1] * 4 + [40.0] * 2):
            iv = R.interval(v)
            self.assertGreaterEqual(iv["lo"], 0.0, v)
            self.assertLessEqual(iv["lo"], iv["mean"], v)
            self.assertLessEqual(iv["mean"], iv["hi"], v)
        self.assertEqual(R.interval([0.05, 0.1, 0.1, 0.05, 10.0])["lo"], 0.0)
        self.assertLess(R.interval([-1.0, 0.05, 0.1, 0.05, 10.0])["lo"], 0.0)

    def test_old_aggregates_still_read(self):
        # aggregate.json from before the rule: no "interval", an unclipped Student t for every n >= 2.
        self.assertEqual(R.aggregate_interval({"n": 3, "mean": 1.94, "ci95": [-6.19, 10.07]}), (-6.19, 10.07, "t95 (old aggregate)"))
        self.assertEqual(R.aggregate_interval({"n": 1, "mean": 1.0, "ci95": [1.0, 1.0]})[2], R.NO_INTERVAL)
        self.assertEqual(R.aggregate_interval({"n": 3, "mean": 1.0, "ci95": [0.5, 2.0], "interval": "range"}), (0.5, 2.0, R.RANGE))

    def test_check_report_html_flags_negative_bounds_of_non_negative_quantities(self):
        import check_report_html as H
        self.assertEqual(H.negative_bounds("mean 1.94 [0.000, 10.07] (n=5, t95); 270.67 (seeds' range 3.00 to 806.00, n=3)"), [])
        self.assertEqual(H.negative_bounds("rmse 1.94 [-6.19, 10.07] n=3"), ["1.94 [-6.19, 10.07]"])
        with tempfile.TemporaryDirectory() as tmp:
            f = pathlib.Path(tmp) / "aggregate.csv"
            f.write_text("scenario,localizer,params,start_pose_given,metric,n,mean,ci95_low,ci95_high\n"
                         "tracking,mcl,default,true,r0/position_m/rmse,3,1.94,-6.19,10.07\n"
                         "tracking,mcl,default,true,r0/heading_bias,3,0.1,-0.2,0.4\n")  # a signed metric may
            bad = H.negative_bounds("", f)
            self.assertEqual(len(bad), 1)
            self.assertIn("r0/position_m/rmse", bad[0])

    def test_the_coverage_table_in_the_docs_names_the_rule(self):
        text = (ROOT / "docs" / "results.md").read_text()
        self.assertTrue("## Intervals" in text and "scripts/interval_coverage.py" in text, "docs/results.md has no section Intervals")

    def test_outlying_seed(self):
        self.assertEqual(R.outliers([806.0, 3.0, 3.0]), [0])
        self.assertEqual(R.outliers([2.9, 3.0, 3.3]), [])
        self.assertEqual(R.outliers([3.0, 3.1, 2.9, 40.0]), [3])
        self.assertEqual(R.outliers([3.0, 806.0]), [])  # two seeds: neither is "the odd one"
        self.assertEqual(R.outliers([2.0, 3.0, 7.0]), [])  # 7 < 3 x 2.5: spread, not an outlier

    def test_welch(self):
        # Known case: a = 1..5, b = 3..7 (equal spread): t = 2 / sqrt(2.5/5 * 2) = 2, df = 8, p = 0.0805.
        w = R.welch([1, 2, 3, 4, 5], [3, 4, 5, 6, 7])
        self.assertAlmostEqual(w["diff"], 2.0)
        self.assertAlmostEqual(w["t"], 2.0)
        self.assertAlmostEqual(w["df"], 8.0)
        self.assertAlmostEqual(w["p"], 0.0805, places=4)


class Compare(unittest.TestCase):
    def test_known_difference_is_found_and_equal_sets_are_same(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            for s, (xa, xb) in enumerate([(2.00, 3.01), (2.10, 3.12), (1.90, 2.93)], start=1):
                cfg = {"duration": 60}
                write_run(tmp / "A" / f"r{s}", "tracking", "matching", s, cfg, robot(xa), "commitA")
                write_run(tmp / "B" / f"other_folder_{4 - s}", "tracking", "matching", s, cfg, robot(xb), "commitB")
                write_run(tmp / "C" / f"r{s}", "tracking", "matching", s, cfg, robot(xa), "commitC")
            ra, _, _ = R.discover([tmp / "A"])
            rb, _, _ = R.discover([tmp / "B"])
            rc, _, _ = R.discover([tmp / "C"])
            header, rows = compare.compare_rows(ra, rb)
            x = [r for r in rows if r[1] == "x_cm/mean"][0]
            self.assertEqual(x[0], "tracking / matching")
            self.assertAlmostEqual(float(x[header.index("B - A")]), 1.02, places=4)
            self.assertEqual(x[header.index("exceeds spread")], "yes")
            y = [r for r in rows if r[1] == "y_cm/mean"][0]
            self.assertEqual(y[header.index("exceeds spread")], "same")
            _, rows = compare.compare_rows(ra, rc)
            self.assertTrue(all(r[-1] == "same" for r in rows if r[1] != "(only in A)"))
            # A single seed per side: the difference alone, no verdict on spread.
            _, rows = compare.compare_rows(ra[:1], rb[:1])
            self.assertEqual([r for r in rows if r[1] == "x_cm/mean"][0][-1], "n < 2")
            # The CLI, through omniloc itself.
            out = subprocess.run([OMNILOC, "compare", str(tmp / "A"), str(tmp / "B")], capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertIn("commitA", out.stdout)
            self.assertIn("commitB", out.stdout)
            self.assertIn("yes", out.stdout)
            out = subprocess.run([OMNILOC, "compare", str(tmp / "A"), str(tmp / "nothing_here")], capture_output=True, text=True)
            self.assertEqual(out.returncode, 2)


class Claims(unittest.TestCase):
    def test_rules_and_missing_results(self):
        self.assertEqual(C.judge(1.2, {"kind": "range", "holds": [1, 2], "partly": [0.8, 3]}), "holds")
        self.assertEqual(C.judge(0.9, {"kind": "range", "holds": [1, 2], "partly": [0.8, 3]}), "partly")
        self.assertEqual(C.judge(5.0, {"kind": "range", "holds": [1, 2], "partly": [0.8, 3]}), "does not")
        self.assertEqual(C.judge(2.4, {"kind": "ratio_to_published", "holds": [0.5, 2]}, 5.9), "does not")
        self.assertEqual(C.judge(None, {"kind": "range", "holds": [1, 2]}), "not run")
        ctx = C.Context(R.load_papers(), [], [])
        claims = C.evaluate_claims(ctx)
        self.assertGreaterEqual(len(claims), 12)
        self.assertTrue(all(c["verdict"] in ("not run", "n/a") for c in claims))
        self.assertTrue(any("not run: build/omniloc sweep" in c["ours_text"] for c in claims))

    def test_occlusion_claim_from_keyed_rows(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_occlusion_sweep(pathlib.Path(tmp) / "s", [0.5, 0.25, 0.125, 0.0])
            runs, _, _ = R.discover([tmp])
            ctx = C.Context(R.load_papers(), runs, [])
            c = [c for c in C.evaluate_claims(ctx) if c["id"] == "occlusion_mild"][0]
            self.assertEqual(c["kind"], "robustness")
            # Judged on every axis the paper states (its own y and heading ratios are in the rule's
            # 1-2 as well): the fixture's y and heading do not change with occlusion (ratio 1).
            checks = {ch["label"]: ch for ch in c["checks"]}
            self.assertEqual(sorted(checks), ["mean heading", "mean x", "mean y"])
            self.assertAlmostEqual(checks["mean x"]["ours"], 4.02 / 2.02, places=9)
            self.assertAlmostEqual(checks["mean y"]["ours"], 1.0, places=9)
            self.assertEqual(c["verdict"], "holds")


class ReportEndToEnd(unittest.TestCase):
    def test_report_has_scorecard_and_every_table_key(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_occlusion_sweep(pathlib.Path(tmp) / "s", [0.0, 0.5])
            out = subprocess.run([PY, str(ROOT / "scripts/report.py"), str(pathlib.Path(tmp) / "s"), "-o", str(pathlib.Path(tmp) / "rep")],
                                 capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            doc = (pathlib.Path(tmp) / "rep" / "report.html").read_text()
            self.assertIn('id="scorecard"', doc)
            # Every published table is in the report under its readable label (a section's anchor
            # may keep the key; the text a reader reads never shows it).
            import html as H
            text = H.unescape(re.sub(r"<[^>]+>", " ", doc))
            for k in R.load_papers():
                if k not in ("comment", "claims"):
                    self.assertTrue(C.table_label(k) in text or f'id="{k}"' in doc, f"{k} is not in the report")
            for key in ("mcl_only_mean_position_error_cm", "001_real_mean_error_cm", "tracking_accuracy", "issue 29"):
                self.assertNotIn(key, text)
            self.assertIn('id="headline"', doc)
            self.assertIn('id="references"', doc)
            self.assertIn("not run", doc)
            self.assertIn("abc123", doc)  # provenance


def write_frames(folder, rows, events=()):
    """frames.csv (robot 0) from (t, err_pos m, valid, mode) and events.jsonl for an outlier's cause."""
    folder = pathlib.Path(folder)
    head = "t,robot,gt_x,gt_y,gt_theta,est_x,est_y,est_theta,err_x,err_y,err_theta,err_pos,valid,mode"
    lines = [head] + [f"{t},0,0,0,0,0,0,0,{e},0,0,{e},{1 if v else 0},{m}" for t, e, v, m in rows]
    (folder / "frames.csv").write_text("\n".join(lines) + "\n")
    (folder / "events.jsonl").write_text("".join(json.dumps(e) + "\n" for e in events))


def mcl_runs_with_outlier(folder):
    """Three MCL seeds on the tracking path: 3.0, 806.0 (converged to a wrong pose), 3.1 cm."""
    folder = pathlib.Path(folder)
    for seed, x in ((1, 3.0), (2, 806.0), (3, 3.1)):
        write_run(folder / f"mcl_s{seed}", "tracking", "mcl", seed, {}, robot(x))
    write_frames(folder / "mcl_s2", [(0.0, 6.7, False, "global")] + [(0.5 * k, 8.06, True, "converged") for k in range(1, 11)])


class FewSeeds(unittest.TestCase):
    """Issue 30: every seed beside its mean, outlying seeds flagged with their cause."""

    def test_outlier_cause_is_read_from_the_frames(self):
        import report
        with tempfile.TemporaryDirectory() as tmp:
            mcl_runs_with_outlier(tmp)
            run = R.Run(pathlib.Path(tmp) / "mcl_s2")
            self.assertEqual(report.outlier_cause(run), "converged to a wrong pose at t = 0.5 s: 8.06 m from the truth (median), "
                             "mode 'converged' in 91 % of the frames from the start to the end; never within 0.5 m")
            lost = pathlib.Path(tmp) / "lost"
            write_run(lost, "kidnap_002", "hybrid", 1, {}, robot(50.0))
            write_frames(lost, [(0.5 * k, 0.1, True, "tracking") for k in range(5)] + [(2.5 + 0.5 * k, 3.0, False, "lost") for k in range(4)],
                         [{"type": "kidnap", "t": 2.4, "robot": 0}])
            self.assertEqual(report.outlier_cause(R.Run(lost)),
                             "lost from t = 2.5 s, after the kidnap at t = 2.4 s: no estimate, no confident estimate (mode 'lost') to the end")
            fine = pathlib.Path(tmp) / "fine"
            write_run(fine, "tracking", "matching", 1, {}, robot(2.0))
            write_frames(fine, [(0.0, 0.1, True, "tracking"), (1.0, 0.9, True, "tracking"), (2.0, 0.2, True, "tracking")])
            self.assertEqual(report.outlier_cause(R.Run(fine)),
                             "on a wrong pose (> 0.5 m off) for 1.0 s of 3.0 s, from t = 1.0 to 2.0 s, 0.90 m off (median); within 0.5 m at the end")
            # Issue 38: a seed 8.8 m off from the start for 37 s of 60, right afterwards, is described by
            # the time it spent on the wrong pose, never as an error "peak".
            back = pathlib.Path(tmp) / "back"
            write_run(back, "tracking", "mcl", 2, {}, robot(300.0))
            write_frames(back, [(0.5 * k, 8.8 if k < 74 else 0.1, True, "converged") for k in range(120)])
            cause = report.outlier_cause(R.Run(back))
            self.assertEqual(cause, "on a wrong pose (> 0.5 m off) for 37.0 s of 60.0 s, from t = 0.0 to 37.0 s, 8.80 m off (median); within 0.5 m at the end")
            self.assertNotIn("peak", cause)
            twice = pathlib.Path(tmp) / "twice"
            write_run(twice, "tracking", "mcl", 3, {}, robot(100.0))
            write_frames(twice, [(1.0 * k, 2.0 if k in (1, 4, 5) else 0.1, k != 7, "tracking") for k in range(10)])
            self.assertEqual(report.outlier_cause(R.Run(twice)),
                             "on a wrong pose (> 0.5 m off) for 3.0 s of 10.0 s, longest from t = 4.0 to 6.0 s, 2.00 m off (median); within 0.5 m at the end")
            calm = pathlib.Path(tmp) / "calm"
            write_run(calm, "tracking", "mcl", 4, {}, robot(10.0))
            write_frames(calm, [(0.0, 0.1, True, "tracking"), (1.0, 0.3, True, "tracking"), (2.0, 0.2, True, "tracking")])
            self.assertEqual(report.outlier_cause(R.Run(calm)), "never on a wrong pose (> 0.5 m off): at most 0.30 m at t = 1.0 s")

    def test_seed_table_shows_every_seed_and_flags_the_outlier(self):
        import report
        with tempfile.TemporaryDirectory() as tmp:
            mcl_runs_with_outlier(pathlib.Path(tmp) / "runs")
            runs, _, _ = R.discover([pathlib.Path(tmp) / "runs"])
            rep = report.Report(pathlib.Path(tmp) / "out", "t")
            flagged = report.seed_table(rep, [("MCL alone", sorted(runs, key=lambda r: r.seed))])
            self.assertEqual([r.seed for r in flagged], [2])
            rep.write()
            md = (pathlib.Path(tmp) / "out" / "report.md").read_text()
            nb = "\u00a0"
            self.assertIn(f"s1{nb}3.00, s2{nb}806.00{nb}(outlier), s3{nb}3.10", md)
            # Three seeds: no reliable interval, the seeds' range instead (Student t would give [-881, 1422]).
            self.assertIn("270.70 (seeds' range 3.00 to 806.00, n=3)", md)
            self.assertIn(f"s1{nb}1.00, s2{nb}1.00, s3{nb}1.00", md)  # the flag marks the metric it is about (mean x)
            self.assertIn("s2: converged to a wrong pose at t = 0.5 s", md)
            self.assertIn("2 to 4 seeds, no reliable interval exists", md)
            self.assertNotIn("bootstrap", md)
            one = report.Report(pathlib.Path(tmp) / "one", "t")
            report.seed_table(one, [("one seed", runs[:1])])
            one.write()
            self.assertIn("(n=1, no interval)", (pathlib.Path(tmp) / "one" / "report.md").read_text())


class ProfilesApart(unittest.TestCase):
    """Issue 38: the error CDF and the timing never pool robot and field_robot runs."""

    def test_cdf_and_timing_are_per_profile(self):
        import report
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            for prof, err, ms in (("robot", 0.05, 1.0), ("field_robot", 0.5, 3.0)):
                for seed in (1, 2):
                    d = tmp / "runs" / f"{prof}_s{seed}"
                    write_run(d, "tracking", "matching", seed, {} if prof == "robot" else {"noise_profile": prof}, robot(3.0))
                    write_frames(d, [(0.1 * k, err, True, "tracking") for k in range(10)])
                    (d / "timing.csv").write_text("render_ms,vision_ms,localize_ms\n" + "".join(f"{ms},{ms},{ms}\n" for _ in range(10)))
            runs, _, _ = R.discover([tmp / "runs"])
            rep = report.Report(tmp / "out", "t")
            report.cdf_and_timing(rep, runs)
            rep.write()
            md = (tmp / "out" / "report.md").read_text()
            self.assertIn("Error CDF per localizer and noise profile", md)
            self.assertIn("| matching | robot | 2 | 20 | 0.0500 |", md)
            self.assertIn("| matching | field_robot | 2 | 20 | 0.5000 |", md)
            self.assertIn("Timing per stage, per localizer and noise profile", md)
            self.assertIn("| matching | robot | 2 | 1.000 | 1.000 | 1.000 | - | 20 |", md)
            self.assertIn("| matching | field_robot | 2 | 3.000 | 3.000 | 3.000 | - | 20 |", md)
            self.assertIn("runs of different profiles are never pooled", md)
            self.assertNotIn("| matching | 40 |", md)  # the pooled row of before


class ExternalPeers(unittest.TestCase):
    def test_an_external_localizer_sits_beside_the_built_in_row_with_its_seeds(self):
        # docs/protocol.md: a client's runs pair by the row's key with the client's name as localizer.
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            write_occlusion_sweep(tmp / "results" / "s", [0.0])
            for seed, x in ((1, 4.0), (2, 5.0)):
                write_run(tmp / "results" / "ext" / f"s{seed}", "tracking", "perl_client", seed, {}, robot(x))
                summary = json.loads((tmp / "results" / "ext" / f"s{seed}" / "summary.json").read_text())
                summary["localizer_type"] = "external"
                (tmp / "results" / "ext" / f"s{seed}" / "summary.json").write_text(json.dumps(summary))
            out = subprocess.run([PY, str(ROOT / "scripts/report.py"), str(tmp / "results"), "-o", str(tmp / "rep"), "--history", "none"],
                                 capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            md = (tmp / "rep" / "report.md").read_text()
            self.assertIn("| 0 % | external: perl_client | 4.500 |", md)
            # Two seeds: the 4 resamples have means 4, 4.5, 4.5, 5; the 2.5 % point lies 0.075 of the way from 4 to 4.5.
            self.assertIn("| 0 % (external: perl_client) | 2 | mean 4.50 (seeds' range 4.00 to 5.00, n=2); median 4.50; seeds: s1\u00a04.00, s2\u00a05.00 |", md)
            table = subprocess.run([PY, str(ROOT / "scripts/paper_table.py"), str(tmp / "results"), "--paper", "002_table1_occlusion", "--rows", "0 %"],
                                   capture_output=True, text=True).stdout
            self.assertIn("external: perl_client", table)


class Verdicts(unittest.TestCase):
    def test_claims_are_counted_apart_by_kind(self):
        ctx = C.Context(R.load_papers(), [], [])
        kinds = {c["id"]: c["kind"] for c in C.evaluate_claims(ctx)}
        self.assertEqual({k for k, v in kinds.items() if v == "timing"}, {"timing_mcl", "timing_matching", "timing_global", "timing_tracking"})
        self.assertEqual(kinds["tracking_accuracy"], "accuracy")
        self.assertEqual(kinds["kidnap_002"], "robustness")
        t = C.totals([{"kind": "accuracy", "verdict": "holds"}, {"kind": "accuracy", "verdict": "does not"}, {"kind": "timing", "verdict": "holds"}])
        self.assertEqual(C.totals_text(t), "accuracy: 1 holds, 1 does not; timing: 1 holds")

    def test_tracking_claim_is_judged_on_heading_too(self):
        # Mean x and y at the paper's figures, heading 0.15x the paper's: x and y hold, heading does
        # not, so the claim holds only partly (it used to look at mean x alone: "holds").
        with tempfile.TemporaryDirectory() as tmp:
            for seed in (1, 2, 3):
                write_run(pathlib.Path(tmp) / f"t{seed}", "tracking", "matching", seed, {}, robot(5.907, 5.967, 0.0066))
            runs, _, _ = R.discover([tmp])
            c = [c for c in C.evaluate_claims(C.Context(R.load_papers(), runs, [])) if c["id"] == "tracking_accuracy"][0]
            self.assertEqual([(ch["label"], ch["verdict"]) for ch in c["checks"]],
                             [("mean x", "holds"), ("mean y", "holds"), ("mean heading", "does not")])
            self.assertAlmostEqual(c["checks"][2]["ratio"], 0.15, places=9)
            self.assertEqual(c["verdict"], "partly")
            self.assertEqual(c["seeds"], 3)
            self.assertFalse(c["weak"])
            self.assertEqual(C.verdict_text(c), "partly")

    def test_a_verdict_on_one_seed_is_marked_weak_evidence(self):
        # Issue 38: a verdict that rests on one seed says so, in the scorecard's verdict column.
        import report
        with tempfile.TemporaryDirectory() as tmp:
            write_run(pathlib.Path(tmp) / "t1", "tracking", "matching", 1, {}, robot(5.9, 5.9, 0.044))
            runs, _, _ = R.discover([tmp])
            c = [c for c in C.evaluate_claims(C.Context(R.load_papers(), runs, [])) if c["id"] == "tracking_accuracy"][0]
            self.assertEqual((c["verdict"], c["seeds"], c["weak"]), ("holds", 1, True))
            self.assertEqual(C.verdict_text(c), "holds (1 seed: weak evidence)")
            occ = [c for c in C.evaluate_claims(C.Context(R.load_papers(), runs, [])) if c["id"] == "occlusion_mild"][0]
            self.assertEqual(occ["verdict"], "not run")
            self.assertFalse(occ["weak"])  # nothing judged: nothing to call weak
            rep = report.Report(pathlib.Path(tmp) / "out", "t")
            report.scorecard(rep, C.Context(R.load_papers(), runs, []))
            rep.write()
            self.assertIn("| holds (1 seed: weak evidence) |", (pathlib.Path(tmp) / "out" / "report.md").read_text())

    def test_field_robot_rows_are_judged_in_their_own_column(self):
        import report
        with tempfile.TemporaryDirectory() as tmp:
            write_run(pathlib.Path(tmp) / "robot", "tracking", "matching", 1, {}, robot(5.9, 5.9, 0.044))
            write_run(pathlib.Path(tmp) / "field", "tracking", "matching", 1, {"noise_profile": "field_robot"}, robot(30.0, 5.9, 0.044))
            runs, _, _ = R.discover([tmp])
            rep = report.Report(pathlib.Path(tmp) / "out", "t")
            claims, field, totals = report.scorecard(rep, C.Context(R.load_papers(), runs, []))
            robot_c = [c for c in claims if c["id"] == "tracking_accuracy"][0]
            self.assertEqual(robot_c["verdict"], "holds")
            self.assertAlmostEqual(field["tracking_accuracy"]["checks"][0]["ours"], 30.0)
            self.assertEqual(field["tracking_accuracy"]["verdict"], "partly")  # x 5.1x the paper's: does not; y, heading hold
            self.assertIn("| field_robot: accuracy: 1 partly", totals)
            rep.write()
            self.assertIn("verdict (field_robot)", (pathlib.Path(tmp) / "out" / "report.md").read_text())


class ReaderReport(unittest.TestCase):
    """The report as a reader sees it: scorecard and contents first, no absolute paths, markdown
    rendered, text left and numbers right, developer charts on their own page."""

    def test_cells_and_inline_markdown(self):
        import report
        self.assertEqual(report.numeric_class("50 % occlusion degrades the mean error only mildly"), "")
        self.assertEqual(report.numeric_class("002 / 000"), "")  # a paper's number is a name
        for cell in ("50 %", "2.42 [2.36, 2.48]", "3 / 3", "0.296 ms", "-1.5", "4.750 (n=1, no interval)",
                     "4.50 (seeds' range 4.00 to 5.00, n=3)", "3.000 [1.037, 4.963] (n=5, t95)"):
            self.assertEqual(report.numeric_class(cell), " class='num'", cell)
        self.assertEqual(report.inline_markdown("run `omniloc x` for **all** <rows> *now*, 5 * 3"),
                         "run <code>omniloc x</code> for <b>all</b> &lt;rows&gt; <i>now</i>, 5 * 3")

    def test_an_experiments_table_shown_in_its_own_section_is_not_repeated(self):
        import report
        md = ("# error_budget: which error source dominates\n\nDescription file `/some/checkout/scenarios/experiments/error_budget.json`.\n\n"
              "| source | RMSE cm |\n|---|---:|\n| baseline | 1.00 |\n\n## Notes\n\nText with **bold**.\n\n| other | x |\n|---|---|\n| a | 2 |\n")
        with tempfile.TemporaryDirectory() as tmp:
            rep = report.Report(tmp, "t")
            rep.markdown(md, skip=report.SHOWN_ELSEWHERE["error_budget"])
            doc = "\n".join(rep.html)
            self.assertNotIn("baseline", doc)  # the table the error-budget section shows
            self.assertIn("<td class='num'>2</td>", doc)  # another table stays
            self.assertIn("href='#error_budget'", doc)
            self.assertIn("<code>scenarios/experiments/error_budget.json</code>", doc)  # path made relative, markdown rendered
            self.assertIn("<b>bold</b>", doc)
            # A fenced block (landmark_maps' fixed-width table) is kept as preformatted text, not
            # shown as raw backticks (check_report_html.py flagged it).
            rep.markdown("## Set-up\n\n```\nposts | d(1,2) <x>\n(75, 100) | 6.35\n```\n\nAfter.\n")
            doc = "\n".join(rep.html)
            self.assertIn("<pre>posts | d(1,2) &lt;x&gt;\n(75, 100) | 6.35</pre>", doc)
            self.assertNotIn("```", doc)
            self.assertIn("<p>After.</p>", doc)

    def test_layout_paths_and_history_page(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            write_occlusion_sweep(tmp / "results" / "s", [0.0, 0.5])
            mcl_runs_with_outlier(tmp / "results" / "mcl")
            (tmp / "hist").mkdir()
            (tmp / "hist" / "icount.jsonl").write_text(json.dumps({"commit": "bbb", "instructions": {"matching": 150}}) + "\n")
            out = subprocess.run([PY, str(ROOT / "scripts/report.py"), str(tmp / "results"), "-o", str(tmp / "rep"), "--history", str(tmp / "hist")],
                                 capture_output=True, text=True, cwd=str(tmp))
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertIn("scorecard: accuracy:", out.stdout)  # the totals, for the terminal
            doc = (tmp / "rep" / "report.html").read_text()
            md = (tmp / "rep" / "report.md").read_text()
            h2 = [m for m in __import__("re").findall(r"<h2 id=\"([^\"]+)\"", doc)]
            self.assertEqual(h2[:3], ["scorecard", "real-robots", "provenance"])  # the real robots' section (says what to run) after the scorecard
            self.assertLess(doc.index('id="scorecard"'), doc.index('<nav id="contents">'))
            self.assertLess(doc.index('<nav id="contents">'), doc.index('id="provenance"'))
            for text in (doc, md):
                self.assertNotIn(str(tmp), text)
                self.assertNotIn(str(ROOT), text)
            self.assertNotIn("Speed over commits", doc)
            self.assertIn("<a href='history.html'>", doc)
            self.assertIn("Speed over commits", (tmp / "rep" / "history.html").read_text())
            self.assertIn("<details>", doc)
            self.assertIn("outlying seed: tracking / mcl / seed 2", doc)  # the outlier is plotted, with its cause
            self.assertNotIn("**", __import__("re").sub(r"<[^>]+>", "", doc.split("<body>")[1]))
            self.assertIn(report_cpu(), doc)


def report_cpu():
    import report
    return report.cpu_model()


class Tools(unittest.TestCase):
    def test_paper_table_reads_the_profile_from_the_runs_and_prints_every_table(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_run(pathlib.Path(tmp) / "field", "tracking", "matching", 1, {"noise_profile": "field_robot"}, robot(7.25))
            run = lambda *args: subprocess.run([PY, str(ROOT / "scripts/paper_table.py"), tmp] + list(args), capture_output=True, text=True)
            out = run("--paper", "000_tracking")
            self.assertEqual(out.returncode, 0, out.stderr)
            row = [l for l in out.stdout.splitlines() if l.startswith("tracking ") and "omniloc" in l][0]
            self.assertEqual(row.split()[2], "7.250")
            self.assertIn("noise profile: field_robot (read from the runs)", out.stdout)
            out = run("--paper", "000_tracking", "--profile", "robot")
            self.assertIn("not run: tracking (", out.stdout)
            out = run("--paper", "all")
            self.assertEqual(out.returncode, 0, out.stderr)
            for text in ("== Kidnap recovery", "== Timings", "== Paper 004 table 1", "== Paper 003", "001_real_mean_error_cm:"):
                self.assertIn(text, out.stdout)
            self.assertEqual(run("--paper", "list").stdout.split(), [k for k in R.load_papers() if k not in ("comment", "claims")])

    def test_compare_fits_100_columns_names_differences_and_pairs_localizers(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            for frac, x in ((0.125, 2.5), (0.25, 3.0)):
                for s in (1, 2, 3):
                    occ = {"occlusion": {"fraction": frac, "sectors": 2}}
                    write_run(tmp / "A" / f"o{frac}_{s}", "tracking", "matching", s, occ, robot(x + s / 100))
                    # B: a newer build that writes one more default into every configuration.
                    write_run(tmp / "B" / f"o{frac}_{s}", "tracking", "matching", s, dict(occ, new_default=1), robot(x + 1 + s / 100))
                    write_run(tmp / "C" / f"m{frac}_{s}", "tracking", "mcl", s, occ, robot(x * 10))
            out = subprocess.run([PY, str(ROOT / "scripts/compare.py"), str(tmp / "A"), str(tmp / "B")], capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            lines = out.stdout.splitlines()[2:]  # the first two name the folders
            self.assertLessEqual(max(len(l) for l in lines), 100)
            self.assertNotIn("only in", out.stdout)
            self.assertNotIn("...", out.stdout)
            self.assertEqual(out.stdout.count("differs: /new_default: absent -> 1"), 2)
            self.assertIn("tracking / matching / /occlusion/fraction=0.125", out.stdout)
            self.assertIn("tracking / matching / /occlusion/fraction=0.25", out.stdout)
            x = [l.split() for l in lines if l.strip().startswith("x_cm/mean")]
            self.assertEqual([r[5] for r in x], ["1.0000", "1.0000"])  # B - A per variant
            # Two localizers on the same scenario and configuration: paired, with numbers.
            _, rows = compare.compare_rows(*(R.discover([tmp / d])[0] for d in ("A", "C")))
            xr = [r for r in rows if r[1] == "x_cm/mean"]
            self.assertEqual(len(xr), 2)
            self.assertIn("localizer: matching -> mcl", xr[0][0])
            self.assertAlmostEqual(float(xr[0][6]), 25.0 - 2.52, places=4)


class StartPoseAndPositionMean(unittest.TestCase):
    """Issue 37: position_m.mean is carried and shown; a run given the true start pose never shares a
    row with one that started globally (paper_table, report, compare)."""

    def tracking_table(self, tmp, external_given=True, mcl_given=False):
        for s in (1, 2):
            write_run(tmp / "res" / f"matching{s}", "tracking", "matching", s, {}, robot(3.0 + s / 10), start_pose_given=True)
            write_run(tmp / "res" / f"mcl{s}", "tracking", "mcl", s, {}, robot(30.0 + s), start_pose_given=mcl_given)
            write_run(tmp / "res" / f"ext{s}", "tracking", "js_client", s, {}, robot(5.0 + s / 10), start_pose_given=external_given, external=True)
        return R.discover([tmp / "res"])[0]

    def test_a_client_given_the_start_pose_is_never_in_a_global_start_row(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            runs = self.tracking_table(tmp)
            rows = {p["label"]: p for p in C.pair_table(R.load_papers(), "000_tracking", runs)}
            mcl = rows["tracking path, MCL alone (global start)"]
            self.assertEqual([q["name"] for q in mcl["peers"]], [])
            self.assertEqual(mcl["stats"]["x_cm/mean"]["n"], 2)
            track = rows["tracking"]
            self.assertEqual([(q["name"], q["row"]) for q in track["peers"]], [("js_client", "tracking (given the start pose)")])
            self.assertEqual(track["shown"], "tracking (given the start pose)")  # the table holds both kinds
            # A global-start row with only a given client beside it: the client gets a row of its own.
            only = C.pair_table(R.load_papers(), "000_tracking", runs, labels=["tracking path, MCL alone (global start)"])[0]
            self.assertEqual(len(only["peers"]), 1)
            self.assertNotIn("global start", only["peers"][0]["row"])
            self.assertTrue(only["peers"][0]["row"].endswith("(given the start pose)"))
            # A built-in MCL run somebody gave the start pose is not taken into the global-start row.
            write_run(tmp / "res" / "mcl_given", "tracking", "mcl", 9, {}, robot(1.0), start_pose_given=True)
            runs = R.discover([tmp / "res"])[0]
            mcl = {p["label"]: p for p in C.pair_table(R.load_papers(), "000_tracking", runs)}["tracking path, MCL alone (global start)"]
            self.assertEqual(sorted(r.seed for r in mcl["runs"]), [1, 2])
            out = subprocess.run([PY, str(ROOT / "scripts/paper_table.py"), str(tmp / "res"), "--paper", "000_tracking"], capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            ext = [l for l in out.stdout.splitlines() if "external: js_client" in l]
            self.assertEqual(len(ext), 1, out.stdout)
            self.assertTrue(ext[0].startswith("tracking (given the start pose)"), out.stdout)

    def test_a_global_client_sits_beside_the_global_start_rows(self):
        with tempfile.TemporaryDirectory() as tmp:
            runs = self.tracking_table(pathlib.Path(tmp), external_given=False)
            rows = {p["label"]: p for p in C.pair_table(R.load_papers(), "000_tracking", runs)}
            self.assertEqual(rows["tracking"]["peers"], [])
            self.assertEqual([q["name"] for q in rows["tracking path, MCL alone (global start)"]["peers"]], ["js_client"])

    def test_runs_without_the_new_keys_are_read_as_before(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            old = robot(4.0)
            del old["position_m"]["mean"]
            for s in (1, 2):
                write_run(tmp / "res" / f"mcl{s}", "tracking", "mcl", s, {}, old)  # no start_pose_given either
                write_run(tmp / "res" / f"ext{s}", "tracking", "js_client", s, {}, robot(5.0), external=True)
            runs = R.discover([tmp / "res"])[0]
            self.assertIsNone(runs[0].start_pose_given)
            self.assertIsNone(runs[2].metric("position_m/mean"))
            rows = {p["label"]: p for p in C.pair_table(R.load_papers(), "000_tracking", runs)}
            self.assertEqual(rows["tracking path, MCL alone (global start)"]["stats"]["x_cm/mean"]["n"], 2)
            self.assertEqual([q["name"] for q in rows["tracking path, MCL alone (global start)"]["peers"]], ["js_client"])
            out = subprocess.run([PY, str(ROOT / "scripts/report.py"), str(tmp / "res"), "-o", str(tmp / "rep"), "--history", "none"],
                                 capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)

    def test_the_report_and_compare_show_the_position_mean(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            for s in (1, 2):
                write_run(tmp / "A" / f"r{s}", "tracking", "matching", s, {}, robot(2.5), start_pose_given=True)
                write_run(tmp / "B" / f"r{s}", "tracking", "matching", s, {}, robot(5.0), start_pose_given=True)
            header, rows = compare.compare_rows(R.discover([tmp / "A"])[0], R.discover([tmp / "B"])[0])
            pm = [r for r in rows if r[1] == "position_m/mean"]
            self.assertEqual(len(pm), 1)
            self.assertAlmostEqual(float(pm[0][header.index("B - A")]), 0.02, places=4)  # 5/125 - 2.5/125
            out = subprocess.run([PY, str(ROOT / "scripts/report.py"), str(tmp / "A"), "-o", str(tmp / "rep"), "--history", "none"],
                                 capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            md = (tmp / "rep" / "report.md").read_text()
            self.assertIn("position mean m", md)
            self.assertIn("| 0.020 | 0.025 |", md)  # position mean and RMSE of robot(2.5)

    def test_compare_does_not_pair_given_with_global(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            for s in (1, 2):
                write_run(tmp / "A" / f"r{s}", "tracking", "mcl", s, {}, robot(30.0), start_pose_given=False)
                write_run(tmp / "B" / f"r{s}", "tracking", "js_client", s, {}, robot(5.0), start_pose_given=True, external=True)
                write_run(tmp / "old" / f"r{s}", "tracking", "mcl", s, {}, robot(31.0))  # before start_pose_given
            header, rows = compare.compare_rows(R.discover([tmp / "A"])[0], R.discover([tmp / "B"])[0])
            self.assertEqual([r[1] for r in rows if r[1].startswith("(only")],
                             ["(only in A: not comparable: global start here, given the start pose on the other side "
                              "(tracking from the true start pose and global localization are different tasks))",
                              "(only in B: not comparable: given the start pose here, global start on the other side "
                              "(tracking from the true start pose and global localization are different tasks))"])
            self.assertFalse([r for r in rows if r[1] == "x_cm/mean"])
            # An older run of the same condition, without the key: still paired.
            _, rows = compare.compare_rows(R.discover([tmp / "old"])[0], R.discover([tmp / "A"])[0])
            self.assertEqual(len([r for r in rows if r[1] == "x_cm/mean"]), 1)
            self.assertFalse([r for r in rows if r[1].startswith("(only")])


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
            a, b = R.discover([tmp])[0]
            self.assertEqual(a.lookup("x_cm/mean"), (True, None))
            self.assertIsNone(a.metric("x_cm/mean"))  # not the all-frames 3.0
            self.assertEqual(a.metric("x_cm/mean", "all"), 3.0)
            self.assertEqual(a.why_null("x_cm/mean"), "no estimate in any of the 40 scored frames")
            self.assertEqual(b.lookup("position_m/mean"), (False, None))
            st = R.run_stats([a, b], "x_cm/mean")
            self.assertEqual((st["n"], st["no_value"], st["of"], st["mean"]), (1, 1, 2, 3.0))
            st = R.run_stats([a, b], "position_m/mean")
            self.assertEqual((st["n"], st["no_value"], st["of"]), (0, 1, 1))
            self.assertEqual(R.stat_cell(st), "no estimate")
            self.assertEqual(R.no_value_note([st]), "no estimate in 1 of 1 runs")
            self.assertEqual((a.headline, b.headline, R.headline_key([a, b])), ("25cm_10deg", None, "25cm_10deg"))
            self.assertEqual(R.recall_label("25cm_10deg"), "25 cm / 10 deg")
            self.assertEqual(R.recall_label("12.5cm_7.5deg"), "12.5 cm / 7.5 deg")

    def test_compare_says_no_estimate_and_leads_with_recall(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            for s in (1, 2, 3):
                write_run(tmp / "A" / f"r{s}", "tracking", "matching", s, {}, scored(robot(2.0 + s / 10)), start_pose_given=True, scoring=SCORING)
                rob = without_estimate() if s == 3 else scored(robot(2.1 + s / 10), answered=0.9, within=0.8)
                write_run(tmp / "B" / f"r{s}", "tracking", "matching", s, {}, rob, start_pose_given=True, scoring=SCORING)
            header, rows = compare.compare_rows(R.discover([tmp / "A"])[0], R.discover([tmp / "B"])[0])
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
            out = subprocess.run([PY, str(ROOT / "scripts/compare.py"), str(tmp / "A"), str(tmp / "B")], capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertIn("no estimate in 1 of 3 runs (B)", out.stdout)
            self.assertLessEqual(max(len(l) for l in out.stdout.splitlines()[2:]), 100)
            first = [l.split()[0] for l in out.stdout.splitlines() if l.startswith("  ") and l.split()[0] not in ("metric",)][:3]
            self.assertEqual(first, ["recall/25cm_10deg", "valid_fraction", "position_m/rmse"])
            # Every run without an estimate: the mean reads "no estimate", never 0.
            _, rows = compare.compare_rows(R.discover([tmp / "B"])[0][2:], R.discover([tmp / "B"])[0][2:])
            rmse = [r for r in rows if r[1] == "position_m/rmse"][0]
            self.assertEqual(rmse[2:5], ["no estimate", 0, "no estimate"])
            self.assertEqual(rmse[-1], "no estimate in 1 of 1 runs (A and B)")

    def tracking_without_estimate(self, tmp):
        for s in (1, 2, 3):
            write_run(tmp / "res" / f"matching{s}", "tracking", "matching", s, {}, without_estimate(), start_pose_given=True, scoring=SCORING)
            write_run(tmp / "res" / f"mcl{s}", "tracking", "mcl", s, {}, scored(robot(20.0 + s), answered=0.5, within=0.4),
                      start_pose_given=False, scoring=SCORING)
        return R.discover([tmp / "res"])[0]

    def test_paper_table_and_claims_say_no_estimate(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            runs = self.tracking_without_estimate(tmp)
            rows = {p["label"]: p for p in C.pair_table(R.load_papers(), "000_tracking", runs)}
            st = rows["tracking"]["stats"]["x_cm/mean"]
            self.assertEqual((st["n"], st["no_value"], st["mean"]), (0, 3, None))
            out = subprocess.run([PY, str(ROOT / "scripts/paper_table.py"), str(tmp / "res"), "--paper", "000_tracking"], capture_output=True, text=True)
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
            claims = {c["id"]: c for c in C.evaluate_claims(C.Context(R.load_papers(), runs, []))}
            t = claims["tracking_accuracy"]
            self.assertEqual(t["verdict"], "does not")
            self.assertIn("no estimate in 3 of 3 runs", t["ours_text"])
            self.assertIn("answered 0.0 %", C.coverage_text(t["coverage"]))
            self.assertTrue(C.no_estimate("no estimate in 1 of 3 runs"))
            self.assertEqual(C.judge(None, {"kind": "range", "holds": [0, 1]}, note="not run: x"), "not run")

    def test_the_report_shows_no_estimate_never_zero_and_coverage_first(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            self.tracking_without_estimate(tmp)
            out = subprocess.run([PY, str(ROOT / "scripts/report.py"), str(tmp / "res"), "-o", str(tmp / "rep"), "--history", "none"],
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
            out = subprocess.run([PY, str(ROOT / "scripts/report.py"), str(tmp / "A"), "-o", str(tmp / "rep"), "--history", "none"],
                                 capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            md = (tmp / "rep" / "report.md").read_text()
            self.assertIn("| 0 % | omniloc | 100.0 % | 100.0 % | 2.500 | 1.000 |", md)  # recall leads, the error follows
            self.assertIn("| r0 | 100.0 % | 100.0 % | 2.500 |", md)
            self.assertIn("| 0.020 | 0.025 |", md)  # position mean and RMSE
            self.assertNotIn("| no estimate", md)

    def test_kidnap_without_recovery_and_error_budget_without_estimate(self):
        import report
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            rob = scored(robot(150.0), answered=0.5, within=0.3)
            rob["tracking_phase"] = without_estimate(40)
            after = {a: dict.fromkeys(("mean", "std", "max")) for a in ("x_cm", "y_cm", "theta_rad")}
            after.update(position_m=dict.fromkeys(("mean", "rmse")), theta_rmse_rad=None, frames=0, why_null="no kidnap recovered")
            rob["recovery"] = {"episodes": 2, "recovered": 0, "recovered_fraction": 0.0, "false_recoveries": 0, "mirrored": 0,
                               "recovery_time_s": {"median": None, "mean": None, "max": None}, "after_recovery": after}
            write_run(tmp / "res" / "k1", "kidnap_002", "hybrid", 1, {}, rob, start_pose_given=False, scoring=SCORING)
            runs = R.discover([tmp / "res"])[0]
            rep = report.Report(tmp / "out", "t")
            report.kidnap_table(rep, R.load_papers(), runs)
            report.report_run(rep, runs[0], plots=False)
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
            rep = report.Report(tmp / "out2", "t")
            report.error_budget_section(rep, C.Context(R.load_papers(), [], [str(e)]))
            rep.write()
            md = (tmp / "out2" / "report.md").read_text()
            self.assertIn("| none (baseline) | no estimate | no estimate | no estimate |", md)
            self.assertIn("| vibration | 4.00 (no estimate in 1 of 2 runs) |", md)

    def test_a_sweep_with_a_localizer_that_never_answers(self):
        # Through the binary: mcl answers none of the hand-written recording's frames, matching all.
        # (Paper 002's 600-particle MCL: with its defaults MCL adapts to the missing compass and answers.)
        import check_report_html as K
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
            out = subprocess.run([PY, str(ROOT / "scripts/report.py"), str(tmp / "hw"), "-o", str(tmp / "rep"), "--history", "none",
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
            ok, detail = K.check_no_raw_keys(dom, K.reader_names() | {"hw"})
            self.assertTrue(ok, detail)
            self.assertEqual(K.negative_bounds(K.visible_text(dom)), [])


if __name__ == "__main__":
    unittest.main()


import icount_compare  # noqa: E402


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


class HistoryTest(unittest.TestCase):
    """report.py's "Speed over commits": per workload the first and last record and their ratio, from
    the committed baseline history followed by this machine's runs; a cut line is skipped."""

    def test_first_last_and_ratio_per_workload(self):
        import report
        with tempfile.TemporaryDirectory() as d:
            d = pathlib.Path(d)
            ref = d / "icount_history.jsonl"
            ref.write_text(json.dumps({"commit": "aaa", "instructions": {"matching": 200}}) + "\n")
            (d / "hist").mkdir()
            (d / "hist" / "icount.jsonl").write_text(
                json.dumps({"commit": "bbb", "instructions": {"matching": 150, "mcl": 10}}) + "\n{\"commit\": \"cut")
            (d / "hist" / "bench.jsonl").write_text(json.dumps({"commit": "bbb", "real_time_ns": {"BM_X": 5.0}}) + "\n")
            rep = report.Report(str(d / "out"), "t")
            report.report_history(rep, d / "hist", reference=ref)
            rep.write()
            md = (d / "out" / "report.md").read_text()
            self.assertIn("| matching | aaa | 200 | bbb | 150 | 0.750 |", md)
            self.assertIn("| mcl | bbb | 10 | bbb | 10 | 1.000 |", md)
            self.assertIn("| BM_X | bbb | 5.0 ns | bbb | 5.0 ns | 1.000 |", md)
            self.assertEqual(md.count(".png)"), 2)


class Causes(unittest.TestCase):
    """Issue 29: every verdict other than holds carries a cause whose evidence is read from the results."""

    def papers(self, causes):
        return {"claims": [{"id": "c1", "paper": "X", "claim": "something is small", "ours": {"row": ["T", "r"], "metric": "x_cm/mean"},
                            "published": 1.0, "unit": "cm", "rule": {"kind": "range", "holds": [0, 1.0], "partly": [0, 2.0]}, "causes": causes}],
                "T": {"rows": {"r": [1.0] * 9}, "reproduced_by": {"rows": {"r": {"scenario": "tracking", "localizer": "matching"}}, "command": "cmd"}}}

    def verdict_and_cause(self, x_mean, causes, y_mean=2.0):
        with tempfile.TemporaryDirectory() as tmp:
            write_run(pathlib.Path(tmp) / "a", "tracking", "matching", 1, {}, robot(x_mean, y_mean))
            runs, _, _ = R.discover([tmp])
            ctx = C.Context(self.papers(causes), runs, [])
            claims = C.evaluate_claims(ctx)
            return claims[0]["verdict"], C.explain(claims, ctx)

    def test_status_follows_the_evidence(self):
        y = {"row": ["T", "r"], "metric": "y_cm/mean"}
        cause = lambda expect: [{"text": "because y", "doc": "docs/x.md", "evidence": [{"label": "y", "ours": y, "unit": "cm", "expect": expect}]}]
        verdict, ex = self.verdict_and_cause(1.5, cause([1.5, 2.5]))
        self.assertEqual(verdict, "partly")
        self.assertEqual([(e["id"], e["status"]) for e in ex], [("c1", C.EXPLAINED)])
        self.assertAlmostEqual(ex[0]["evidence"][0]["value"], 2.0)
        _, ex = self.verdict_and_cause(1.5, cause([0, 1]))
        self.assertEqual(ex[0]["status"], C.CONTRADICTED)
        self.assertIn("CONTRADICTS", C.evidence_text(ex[0]["evidence"][0]))
        _, ex = self.verdict_and_cause(1.5, [{"text": "t", "evidence": [{"label": "z", "ours": {"row": ["T", "r"], "metric": "nothing/here"}}]}])
        self.assertEqual(ex[0]["status"], C.NOT_MEASURED)
        _, ex = self.verdict_and_cause(1.5, [])
        self.assertEqual(ex[0]["status"], C.UNEXPLAINED)
        # A cause written for "does not" only does not explain a "partly"; a holding claim needs none.
        _, ex = self.verdict_and_cause(1.5, [dict(cause([1.5, 2.5])[0], verdicts=["does not"])])
        self.assertEqual(ex[0]["status"], C.UNEXPLAINED)
        verdict, ex = self.verdict_and_cause(0.5, [], y_mean=0.5)
        self.assertEqual((verdict, ex), ("holds", []))

    def test_expr_and_where_quantities(self):
        with tempfile.TemporaryDirectory() as tmp:
            e = pathlib.Path(tmp) / "error_budget"
            e.mkdir()
            (e / "error_budget.json").write_text(json.dumps({"rows": [{"source": "a", "localizer": "matching", "position_rmse_cm": 4.0},
                                                                      {"source": "b", "localizer": "matching", "position_rmse_cm": 3.0}]}))
            ctx = C.Context({"claims": []}, [], [str(e)])
            where = {"experiment": "error_budget", "file": "error_budget.json", "list": "/rows", "where": {"source": "b", "localizer": "matching"},
                     "field": "position_rmse_cm"}
            self.assertEqual(C.quantity(where, ctx)[0], 3.0)
            self.assertIsNone(C.quantity(dict(where, where={"source": "c"}), ctx)[0])
            v, _ = C.quantity({"expr": "sqrt(a * a - b * b)", "vars": {"a": 5.0, "b": where}}, ctx)
            self.assertAlmostEqual(v, 4.0)
            self.assertIsNone(C.quantity({"expr": "a / b", "vars": {"a": 1.0, "b": dict(where, field="nothing")}}, ctx)[0])

    def test_mcl_alone_is_judged_on_the_error_while_right(self):
        # Two seeds on the right pose at 3 cm, one on a wrong pose 8 m away: the mean over all frames
        # is ~270 cm (inside nothing sensible), the error while right 3 cm.
        with tempfile.TemporaryDirectory() as tmp:
            for seed, wrong in ((1, False), (2, True), (3, False)):
                f = pathlib.Path(tmp) / f"mcl{seed}"
                write_run(f, "tracking", "mcl", seed, {}, robot(800.0 if wrong else 3.0))
                e = 8.0 if wrong else 0.03
                head = "t,robot,gt_x,gt_y,gt_theta,est_x,est_y,est_theta,err_x,err_y,err_theta,err_pos,valid,mode,spread_m"
                rows = [f"{0.1 * k:.1f},0,0,0,0,{e},0,0,{e},0,0,{e},1,converged,0.1" for k in range(40)]
                (f / "frames.csv").write_text("\n".join([head] + rows) + "\n")
            write_run(pathlib.Path(tmp) / "m", "tracking", "matching", 1, {}, robot(2.5))
            runs, _, _ = R.discover([tmp])
            ctx = C.Context(R.load_papers(), runs, [])
            c = [c for c in C.evaluate_claims(ctx) if c["id"] == "mcl_alone"][0]
            self.assertAlmostEqual(c["checks"][0]["ours"], 3.0, places=9)
            self.assertAlmostEqual(c["checks"][1]["ours"], 3.0 / 2.5, places=9)
            self.assertEqual(c["verdict"], "does not")
            ex = [e for e in C.explain([c], ctx) if e["id"] == "mcl_alone"][0]
            ev = {e["label"]: e["value"] for e in ex["evidence"]}
            self.assertAlmostEqual(ev["MCL runs that ended on the right pose"], 2 / 3)
            self.assertAlmostEqual(ev["MCL particle spread while right (mean)"], 10.0)

    def test_every_recorded_cause_is_well_formed(self):
        # causes.json names only claims of papers.json (load_papers checks) and every evidence
        # selector evaluates without results to "not measured", never to an exception.
        papers = R.load_papers()
        ctx = C.Context(papers, [], [])
        n = 0
        for c in papers["claims"]:
            for k in c.get("causes", []):
                self.assertTrue(k["text"] and k.get("evidence"), c["id"])
                self.assertTrue(set(k.get("verdicts", ["partly"])) <= {"partly", "does not"}, c["id"])
                for ev in k["evidence"]:
                    v, note = C.quantity(ev["ours"], ctx)
                    self.assertIsNone(v, ev["label"])
                    self.assertTrue(note, ev["label"])
                    n += 1
                doc = k.get("doc", "").split("#")[0]
                if doc:
                    self.assertTrue((ROOT / doc).exists(), doc)
        self.assertGreater(n, 10)

    def test_the_report_shows_the_cause_table(self):
        import report
        with tempfile.TemporaryDirectory() as tmp:
            for seed in (1, 2, 3):
                write_run(pathlib.Path(tmp) / f"t{seed}", "tracking", "matching", seed, {}, robot(2.5, 2.6, 0.0066))
            runs, _, _ = R.discover([tmp])
            rep = report.Report(pathlib.Path(tmp) / "out", "t")
            _, _, totals = report.scorecard(rep, C.Context(R.load_papers(), runs, []))
            self.assertIn("verdicts other than holds: 1 evidence not in these results", totals)  # the error budget was not run
            rep.write()
            md = (pathlib.Path(tmp) / "out" / "report.md").read_text()
            self.assertIn("Why a claim does not hold", md)
            self.assertIn("pushed by hand", md)
            self.assertIn("not measured (not run: `build/omniloc experiment error_budget`)", md)

    def test_the_why_table_writes_a_cause_shared_by_both_profiles_once(self):
        import report
        with tempfile.TemporaryDirectory() as tmp:
            for seed in (1, 2, 3):
                write_run(pathlib.Path(tmp) / f"t{seed}", "tracking", "matching", seed, {}, robot(2.5, 2.6, 0.0066))
                write_run(pathlib.Path(tmp) / f"f{seed}", "tracking", "matching", seed, {"noise_profile": "field_robot"}, robot(3.5, 3.6, 0.008))
            runs, _, _ = R.discover([tmp])
            ctx = C.Context(R.load_papers(), runs, [])
            rep = report.Report(pathlib.Path(tmp) / "out", "t")
            judged = report.judge_claims(ctx)
            report.headline(rep, ctx, *judged)
            report.scorecard(rep, ctx, judged)
            rep.write()
            md = (pathlib.Path(tmp) / "out" / "report.md").read_text()
            why = md.split("### Why a claim does not hold")[1].split("\n## ")[0]
            row = [l for l in why.splitlines() if l.startswith("| Tracking accuracy |")]
            self.assertEqual(len(row), 1, why)  # one row for both profiles
            self.assertIn("| partly | partly |", row[0])
            self.assertIn("robot: x 0.42x", row[0])  # ours / paper per profile where they differ
            self.assertEqual(why.count("pushed by hand along straight tracks"), 1)  # the argument once
            self.assertNotIn("tracking_accuracy", md)
            # The headline: first after the title, computed from the results.
            first = md.split("\n\n")[1]
            self.assertTrue(first.startswith("**In short.**"), first)
            self.assertIn("about 0.43x the papers' in position and 0.15x in heading", first)  # median of 2.5/5.907, 2.6/5.967; 0.0066/0.044
            self.assertIn("The main gap is tracking accuracy", first)


class ReaderLanguage(unittest.TestCase):
    """Issue 38: papers cited with a bibliography, no ids or issue numbers, abbreviations spelled out."""

    def test_citations(self):
        self.assertEqual(C.cite_text("Lu et al. 2013 (paper 002), Table 1"), "Lu et al. 2013 [3], Table 1")
        self.assertEqual(C.cite_text("Xiong, Lu, Zheng (paper 000), tracking"), "Xiong et al. 2012 [1], tracking")
        self.assertEqual(C.cite_text("Kidnap recovery (papers 002 and 000)"), "Kidnap recovery (Lu et al. 2013 [3] and Xiong et al. 2012 [1])")
        self.assertEqual(C.cite_field("002 refs [7], [8]"), "Lu et al. 2013 [3], its refs [7], [8]")
        self.assertEqual(len(C.BIBLIOGRAPHY), 5)
        self.assertTrue(all(b["year"] and b["title"] and b["authors"] for b in C.BIBLIOGRAPHY))
        for c in R.load_papers()["claims"]:
            self.assertIn(c["id"], C.CLAIM_LABELS)

    def test_abbreviations_are_spelled_out_once(self):
        import report
        with tempfile.TemporaryDirectory() as tmp:
            rep = report.Report(tmp, "t")
            rep.para("MCL alone, then MCL again; `MCL` in code")
            rep.para("MCL and RMSE")
            self.assertEqual(rep.md[2], "MCL (Monte Carlo localization) alone, then MCL again; `MCL` in code")
            self.assertEqual(rep.md[4], "MCL and RMSE (root mean square error)")
            rep.para("see docs/results.md#intervals")
            self.assertIn("<a href='", rep.html[-1])
            self.assertIn("docs/results.md#intervals'>docs/results.md</a>", rep.html[-1])

    def test_the_html_checks_catch_what_they_name(self):
        sys.path.insert(0, str(ROOT / "scripts"))
        import check_report_html as K
        good = ("<html><body><h1>t</h1><p id=\"headline\">In short: " + "x" * 80 + "</p><h2 id=\"scorecard\">Scorecard</h2>"
                "<p>Lu et al. 2013 [3] and <code>tracking_accuracy</code> and occlusion_002.json and field_robot</p>"
                "<div class=\"quoted\"><p>total_like</p></div><h2 id=\"references\">References</h2>"
                "<ol id=\"bibliography\">" + "".join(f"<li>A. {2000 + k}</li>" for k in range(5)) + "</ol></body></html>")
        for f in (K.check_headline, K.check_no_issue_numbers, K.check_no_raw_keys, K.check_unique_headings, K.check_bibliography):
            self.assertTrue(f(good)[0], (f.__name__, f(good)))
        self.assertFalse(K.check_no_issue_numbers(good.replace("Scorecard</h2>", "Scorecard</h2><p>see issue 29</p>"))[0])
        self.assertFalse(K.check_no_raw_keys(good.replace("and field_robot", "and mcl_only_mean_position_error_cm"))[0])
        self.assertFalse(K.check_unique_headings(good.replace("<h2 id=\"references\">", "<h3 id=\"x\">Scorecard</h3><h2 id=\"references\">"))[0])
        self.assertFalse(K.check_bibliography(good.replace("2013 [3]", "2013 [9]"))[0])
        self.assertFalse(K.check_bibliography(good.replace("<h2 id=\"references\">References</h2>", ""))[0])
        self.assertFalse(K.check_headline(good.replace(" id=\"headline\"", ""))[0])


class ErrorBudgetSeeds(unittest.TestCase):
    """Issue 29, item 5: the error budget's cells carry an interval over the seeds."""

    def test_cells_show_an_interval_or_that_every_seed_agrees(self):
        import report
        seeds = lambda vals: [{"seed": k + 1, "position_rmse_cm": v, "position_p50_cm": v / 2, "heading_rmse_deg": 0.1} for k, v in enumerate(vals)]
        rows = [{"source": "none (baseline)", "localizer": "matching", "runs": 3, "failed": 0, "position_rmse_cm": 0.6, "position_p50_cm": 0.3,
                 "heading_rmse_deg": 0.1, "per_seed": seeds([0.6, 0.6, 0.6])},
                {"source": "vibration", "localizer": "matching", "runs": 3, "failed": 0, "position_rmse_cm": 4.5, "position_p50_cm": 2.25,
                 "heading_rmse_deg": 0.1, "per_seed": seeds([4.0, 4.5, 5.0])}]
        with tempfile.TemporaryDirectory() as tmp:
            e = pathlib.Path(tmp) / "error_budget"
            e.mkdir()
            (e / "error_budget.json").write_text(json.dumps({"experiment": "error_budget", "config_file": "x.json", "quick": False, "duration_s": 60.0,
                                                               "seeds": 3, "first_seed": 1, "sweep": "s", "rows": rows}))
            ctx = C.Context(R.load_papers(), [], [str(e)])
            rep = report.Report(pathlib.Path(tmp) / "out", "t")
            report.error_budget_section(rep, ctx)
            rep.write()
            md = (pathlib.Path(tmp) / "out" / "report.md").read_text()
            self.assertIn("| none (baseline) | 0.60 (= every seed) | 0.30 (= every seed) | 0.10 (= every seed) |", md)
            self.assertIn("| vibration | 4.50 (seeds' range 4.00 to 5.00, n=3) |", md)  # three seeds: their range, no interval
            self.assertIn("Mean over 3 seeds; intervals: n >= 5 seeds", md)
            self.assertIn("Which real-robot error is missing", md)


REAL = ROOT / "data" / "real" / "nubot"


def real_reference(robot):
    return json.loads((REAL / robot / "recording.json").read_text())["reference"]


def write_real_run(folder, frame, label, seed, estimates, localizer=None, config=None):
    """A run folder of a replay of the real recording data/real/nubot/<frame> (as omniloc writes
    one): frames.csv at 30 Hz with the reference pose as truth and `estimates`, one (x, y, theta) or
    None (no estimate) per frame."""
    folder = pathlib.Path(folder) / f"nubot_{frame}__{label}__recording__s{seed}"
    ref = real_reference(frame)["reference"]
    n = len(estimates)
    answered = sum(e is not None for e in estimates)
    write_run(folder, f"nubot_{frame}", localizer or label, seed, config or {"localizer": {"type": localizer or label}},
              scored(robot(1.0), answered=answered / n, within=0.0, total=n), start_pose_given=False, scoring=SCORING)
    summary = json.loads((folder / "summary.json").read_text())
    summary["omniloc"]["replay"] = {"format": "omniloc-recording/1", "recorded_seed": 1, "recorded_with": "not omniloc",
                                    "recording": str(REAL / frame)}
    (folder / "summary.json").write_text(json.dumps(summary))
    head = "t,robot,gt_x,gt_y,gt_theta,est_x,est_y,est_theta,err_x,err_y,err_theta,err_pos,valid,mode"
    lines = [head]
    for k, e in enumerate(estimates):
        est = e if e is not None else (0.0, 0.0, 0.0)
        err = math.hypot(est[0] - ref[0], est[1] - ref[1])
        lines.append(f"{k / 30:.4f},0,{ref[0]},{ref[1]},{ref[2]},{est[0]},{est[1]},{est[2]},0,0,0,{err},{1 if e is not None else 0},"
                     + ("converged" if e is not None else "global"))
    (folder / "frames.csv").write_text("\n".join(lines) + "\n")
    return folder


def write_sim_recording(sweep, profile="robot"):
    """A sweep folder holding one recording of the tracking path (as `omniloc sweep` draws it into
    recordings/) with one frame of hand-placed line points, robot at (-4.5, 0, 0) on msl2012, whose
    distances to the nearest marking are known: 0-1.5 m: 22.5 cm (the penalty spot's rim);
    1.5-3 m: 5 and 4 cm; 3-5 m: 0 and 3 cm (the centre line); 5-7.5 m: 5 and 10 cm (the touch lines).
    A second frame without a usable image is left out."""
    sweep = pathlib.Path(sweep)
    rec = sweep / "recordings" / "tracking__s1__0123456789abcdef"
    rec.mkdir(parents=True)
    (sweep / "runs.csv").write_text("index,id,scenario,localizer,params,seed,status\n")
    (sweep / "aggregate.json").write_text(json.dumps({"sweep": sweep.name, "runs": 0, "groups": []}))
    head = {"format": "omniloc-recording/1", "name": "tracking", "seed": 1, "field": "msl2012", "camera_rate_hz": 30.0, "duration_s": 0.1,
            "frames": 2, "frames_file": "frames.jsonl", "ground_truth": True, "robots": [{"id": 0}],
            "scenario": {"name": "tracking", "noise_profile": profile, "field": "msl2012"}}
    (rec / "recording.json").write_text(json.dumps(head))
    pts = [[-1.2, 0.0], [-2.2, 0.0], [2.46, 0.0], [4.5, 0.5], [4.53, 0.5], [0.0, 5.95], [0.0, -5.9]]
    frames = [{"k": 0, "t": 0.0, "robots": [{"robot": 0, "odometry": [0, 0, 0], "heading": 0.0, "camera_ok": True, "line_points": pts,
                                             "truth": [-4.5, 0.0, 0.0]}]},
              {"k": 1, "t": 0.0333, "robots": [{"robot": 0, "odometry": [0, 0, 0], "heading": 0.0, "camera_ok": False, "line_points": [[3.0, 3.0]],
                                                "truth": [-4.5, 0.0, 0.0]}]}]
    (rec / "frames.jsonl").write_text("".join(json.dumps(f) + "\n" for f in frames))
    return sweep


class RealRobots(unittest.TestCase):
    """The report's "Real robots" section (scripts/real_robots.py): runs on the real NuBot frames
    classified found / twin / wrong against the reference pose and its twin, and the line-point
    noise of the real frames beside the simulated profiles'."""

    def test_found_twin_and_wrong_from_a_real_sweep_and_faked_runs(self):
        import real_robots as RR
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            # A tiny real-robots sweep: one real recording, two localizers, by the binary.
            (tmp / "rr.json").write_text(json.dumps({"name": "real_robots", "scenarios": [{"recording": str(REAL / "robot1")}], "localizers": [
                {"type": "grid_global"}, {"type": "mcl", "adapt_to_no_compass": False, "label": "mcl_as_published"}]}))
            out = subprocess.run([OMNILOC, "sweep", str(tmp / "rr.json"), "-o", str(tmp / "results" / "real_robots"), "-j", "2"],
                                 capture_output=True, text=True, timeout=300)
            self.assertEqual(out.returncode, 0, out.stderr)
            loose = tmp / "results" / "loose"
            ref2 = real_reference("robot2")
            twin2 = ref2["twin"]
            # robot 2, mcl: no estimate for 10 frames, then 2 cm and 0.01 rad from the TWIN: found as the twin.
            write_real_run(loose, "robot2", "mcl", 1, [None] * 10 + [(twin2[0] + 0.02, twin2[1], twin2[2] + 0.01)] * 20)
            # robot 4, hybrid: on the reference, then 1.2 m off at the end: wrong.
            ref4 = real_reference("robot4")["reference"]
            write_real_run(loose, "robot4", "hybrid", 1, [tuple(ref4)] * 20 + [(ref4[0] - 1.2, ref4[1], ref4[2])] * 10)
            # robot 5, hybrid: right, then no estimate in the last frame.
            ref5 = real_reference("robot5")["reference"]
            write_real_run(loose, "robot5", "hybrid", 1, [tuple(ref5)] * 29 + [None])
            # robot 1, grid_global at seed 2, ending on the twin: two seeds of one frame are counted.
            twin1 = real_reference("robot1")["twin"]
            write_real_run(loose, "robot1", "grid_global", 2, [tuple(twin1)] * 30)
            runs, sweeps, _ = R.discover([tmp / "results"])
            judged = {(x["label"], x["folder"].name, x["run"].seed): x["judged"] for x in RR.real_runs(runs)}
            self.assertEqual(judged[("grid_global", "robot1", 1)]["outcome"], "found")  # the exhaustive grid: reference or twin, here the reference
            self.assertLess(judged[("grid_global", "robot1", 1)]["error_m"], 0.05)
            self.assertEqual(judged[("grid_global", "robot1", 1)]["first_fix_s"], 0.0)
            self.assertIn(judged[("mcl_as_published", "robot1", 1)]["outcome"], ("found", "twin", "wrong", "none"))
            j = judged[("mcl", "robot2", 1)]
            self.assertEqual(j["outcome"], "twin")
            self.assertAlmostEqual(j["error_m"], 0.02, places=6)
            self.assertAlmostEqual(j["error_deg"], math.degrees(0.01), delta=0.001)  # the header's twin is rounded to 1e-5 rad
            self.assertAlmostEqual(j["answered"], 20 / 30)
            self.assertAlmostEqual(j["first_fix_s"], 10 / 30, places=3)
            self.assertEqual(judged[("hybrid", "robot4", 1)]["outcome"], "wrong")
            self.assertAlmostEqual(judged[("hybrid", "robot4", 1)]["error_m"], 1.2, places=6)
            self.assertEqual(judged[("hybrid", "robot4", 1)]["first_fix_s"], 0.0)
            self.assertEqual(judged[("hybrid", "robot5", 1)]["outcome"], "none")
            self.assertEqual(judged[("grid_global", "robot1", 2)]["outcome"], "twin")
            # The report: the section right after the scorecard, every case as classified.
            out = subprocess.run([PY, str(ROOT / "scripts/report.py"), str(tmp / "results"), "-o", str(tmp / "rep"), "--history", "none"],
                                 capture_output=True, text=True, cwd=str(tmp))
            self.assertEqual(out.returncode, 0, out.stderr)
            md = (tmp / "rep" / "report.md").read_text()
            doc = (tmp / "rep" / "report.html").read_text()
            h2 = re.findall(r"<h2 id=\"([^\"]+)\"", doc)
            self.assertEqual(h2[:3], ["scorecard", "real-robots", "provenance"])
            section = md.split("## Real robots", 1)[1].split("\n## ", 1)[0]
            self.assertIn("| mcl | data/real/nubot/robot2 | 1 | twin | 2.0 cm | 0.6 deg | 66.7 % | 0.33 s |", section)
            self.assertIn("| hybrid | data/real/nubot/robot4 | 1 | wrong | 1.20 m | 0.0 deg | 100.0 % | 0.00 s |", section)
            self.assertIn("| hybrid | data/real/nubot/robot5 | 1 | no estimate at the end |", section)
            self.assertIn("| grid_global | data/real/nubot/robot1 | 1, 2 | 2 of 2 found or twin (1 found, 1 twin) |", section)
            self.assertIn("| mcl_as_published (Lu et al. 2013 [3]'s 600-particle MCL as published: `adapt_to_no_compass` false) | data/real/nubot/robot1 | 1 |",
                          section)
            # Totals per localizer.
            self.assertIn("| grid_global | 2 | 1 | 1 | 1 | 0 | 0 | 2 of 2 |", section)
            self.assertIn("| hybrid | 2 | 2 | 0 | 0 | 1 | 1 | 0 of 2 |", section)
            self.assertIn("not by any localizer under test", section)
            self.assertIn("lower bound", section)
            self.assertNotIn("Not run**: no replay", section)
            # The real runs stay out of the pooled CDF (scored there against the reference only).
            self.assertNotIn("Error CDF per localizer", md)
            for text in (doc, md):
                self.assertNotIn(str(tmp), text)

    def test_noise_table_real_and_simulated(self):
        import real_robots as RR
        import report
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            # The real figures equal those the recordings' headers carry (the converter's).
            for robot in ("robot1", "robot2", "robot4", "robot5"):
                head = json.loads((REAL / robot / "recording.json").read_text())
                got = RR.real_noise(REAL / robot, head)
                for g, want in zip(got, head["reference"]["line_point_noise"]["bands"]):
                    self.assertEqual((g["range_m"], g["points"]), (want["range_m"], want["points"]))
                    for k in ("median_cm", "p90_cm"):
                        if want[k] is None:
                            self.assertIsNone(g[k])
                        else:
                            self.assertAlmostEqual(g[k], want[k], delta=0.006, msg=f"{robot} {k}")
            write_sim_recording(tmp / "paper_suite")
            _, sweeps, _ = R.discover([tmp / "paper_suite"])
            rep = report.Report(tmp / "out", "t")
            RR.section(rep, [], sweeps)
            rep.write()
            md = (tmp / "out" / "report.md").read_text()
            self.assertIn("| range m | real: robot1 | real: robot2 | real: robot4 | real: robot5 | simulated: robot profile | simulated: field_robot profile |", md)
            self.assertIn("| 0-1.5 | 0 points | 0 points | 0 points | 0 points | 1: 22.5 / 22.5 | not run |", md)
            self.assertIn("| 1.5-3 | 261: 2.7 / 5.1 | 332: 1.5 / 3.8 | 318: 2.6 / 6.3 | 327: 1.6 / 3.5 | 2: 4.5 / 4.9 | not run |", md)
            self.assertIn("| 3-5 | 744: 4.4 / 10.1 | 709: 5.4 / 10.4 | 781: 4.5 / 10.8 | 698: 5.4 / 10.5 | 2: 1.5 / 2.7 | not run |", md)
            self.assertIn("| 5-7.5 | 762: 6.2 / 16.2 | 1052: 5.1 / 12.4 | 880: 4.8 / 12.9 | 918: 4.2 / 11.9 | 2: 7.5 / 9.5 | not run |", md)
            self.assertIn("robot: 1 recording of the tracking path (seed 1), every frame, 1 frames", md)
            self.assertIn("build/omniloc sweep scenarios/sweeps/paper_suite_field_robot.json -j 2", md)  # what to run for the missing profile

    def test_without_real_results_the_section_says_what_to_run(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            write_occlusion_sweep(tmp / "results" / "s", [0.0])
            out = subprocess.run([PY, str(ROOT / "scripts/report.py"), str(tmp / "results"), "-o", str(tmp / "rep"), "--history", "none"],
                                 capture_output=True, text=True, cwd=str(tmp))
            self.assertEqual(out.returncode, 0, out.stderr)
            md = (tmp / "rep" / "report.md").read_text()
            section = md.split("## Real robots", 1)[1].split("\n## ", 1)[0]
            self.assertIn("**Not run**: no replay of a real recording among these results. Run `build/omniloc sweep scenarios/sweeps/real_robots.json -j 2`",
                          section)
            self.assertIn("| 3-5 | 744: 4.4 / 10.1 |", section)  # the shipped frames' own figures need no run
            self.assertIn("`build/omniloc sweep scenarios/sweeps/paper_suite.json -j 2`", section)
            self.assertIn("`build/omniloc sweep scenarios/sweeps/paper_suite_field_robot.json -j 2`", section)

    def test_the_shipped_sweep_names_every_real_frame_and_localizer(self):
        spec = json.loads((ROOT / "scenarios/sweeps/real_robots.json").read_text())
        self.assertEqual(sorted(pathlib.Path(e["recording"]).name for e in spec["scenarios"]), ["robot1", "robot2", "robot4", "robot5"])
        for e in spec["scenarios"]:
            self.assertTrue((ROOT / "scenarios/sweeps" / e["recording"] / "recording.json").exists(), e)
        labels = [l.get("label", l["type"]) for l in spec["localizers"]]
        self.assertEqual(labels, ["mcl", "hybrid", "grid_global", "mcl_as_published"])
        self.assertIs(spec["localizers"][3]["adapt_to_no_compass"], False)
