"""Pairing runs with published rows by key, aggregates and CSV, compare and paper-table, start pose and position mean.
"""
import csv
import io
import json
import re
import pathlib
import random
import subprocess
import tempfile
import unittest

from helpers import OCCLUSION, OMNILOC, PY, ROOT, needs_omniloc, robot, write_occlusion_sweep, write_run
from omniloc import compare as CMP
from omniloc.core import pairing as PR
from omniloc.core import rundir as RD
from omniloc.paper import tables as T


class Pairing(unittest.TestCase):
    def test_rows_pair_by_key_whatever_the_order_of_the_sweep(self):
        papers = PR.load_papers()
        orders = [[0.0, 0.125, 0.25, 0.5], [0.5, 0.0, 0.25, 0.125]]
        random.Random(7).shuffle(orders[1])
        tables = []
        with tempfile.TemporaryDirectory() as tmp:
            for i, order in enumerate(orders):
                write_occlusion_sweep(pathlib.Path(tmp) / f"s{i}", order)
                runs, sweeps, _ = RD.discover([pathlib.Path(tmp) / f"s{i}"])
                self.assertEqual(len(sweeps), 1)
                self.assertEqual(len(runs), 12)
                rows = T.pair_table(papers, "002_table1_occlusion", runs, include_extra=False)
                tables.append([(p.label, p.stats["x_cm/mean"].mean, p.stats["x_cm/mean"].n) for p in rows])
        self.assertEqual(tables[0], tables[1])
        got = {label: (m, n) for label, m, n in tables[0]}
        for label, frac in (("0 %", 0.0), ("12.5 %", 0.125), ("25 %", 0.25), ("50 %", 0.5)):
            self.assertAlmostEqual(got[label][0], OCCLUSION[frac] + 0.02, places=9, msg=label)  # mean of seeds 1..3: +0.02
            self.assertEqual(got[label][1], 3)

    def test_runs_of_another_noise_profile_do_not_mix_into_the_rows(self):
        # The published rows pair runs of the robot profile; the same rows under field_robot are a
        # table of their own (omniloc.report.published.field_robot_tables), never averaged into the robot rows.
        papers = PR.load_papers()
        with tempfile.TemporaryDirectory() as tmp:
            write_occlusion_sweep(pathlib.Path(tmp) / "robot", [0.0], seeds=(1, 2))
            write_run(pathlib.Path(tmp) / "field" / "tracking__field", "tracking", "matching", 1, {"noise_profile": "field_robot"}, robot(50.0))
            runs, _, _ = RD.discover([pathlib.Path(tmp)])
            self.assertEqual(len(runs), 3)
            row = T.pair_table(papers, "002_table1_occlusion", runs, labels=["0 %"])[0]
            self.assertEqual(row.stats["x_cm/mean"].n, 2)
            self.assertAlmostEqual(row.stats["x_cm/mean"].mean, OCCLUSION[0.0] + 0.015, places=9)
            with PR.pairing_profile("field_robot"):
                row = T.pair_table(papers, "002_table1_occlusion", runs, labels=["0 %"])[0]
            self.assertEqual(row.stats["x_cm/mean"].n, 1)
            self.assertAlmostEqual(row.stats["x_cm/mean"].mean, 50.0, places=9)

    def test_missing_rows_say_not_run_with_the_command(self):
        papers = PR.load_papers()
        with tempfile.TemporaryDirectory() as tmp:
            write_occlusion_sweep(pathlib.Path(tmp) / "s", [0.0])
            out = subprocess.run([PY, "-m", "omniloc.commands.paper_table", tmp, "--paper", "002_table1_occlusion"], capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertIn("not run: 50 %", out.stdout)
            self.assertIn(papers["002_table1_occlusion"]["reproduced_by"]["command"], out.stdout)
            bad = subprocess.run([PY, "-m", "omniloc.commands.paper_table", tmp, "--paper", "002_table1_occlusion", "--rows", "strong sun"],
                                 capture_output=True, text=True)
            self.assertEqual(bad.returncode, 2)
            self.assertIn("'12.5 %'", bad.stderr)  # the valid rows are listed
            bad = subprocess.run([PY, "-m", "omniloc.commands.paper_table", tmp, "--paper", "nope"], capture_output=True, text=True)
            self.assertEqual(bad.returncode, 2)
            self.assertIn("002_table2_lighting", bad.stderr)

    def test_stale_runs_of_an_older_spec_are_not_reported(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_occlusion_sweep(pathlib.Path(tmp) / "s", [0.0])
            write_run(pathlib.Path(tmp) / "s" / "runs" / "old_run", "tracking", "matching", 1, {}, robot(99.0))
            runs, _, _ = RD.discover([tmp])
            self.assertEqual(len(runs), 3)
            self.assertNotIn(99.0, [r.metric("x_cm/mean") for r in runs])

    def test_every_published_row_is_run_by_the_paper_suite(self):
        # Each reproduced_by key must name a condition the default suite runs (scenario name,
        # localizer type and configuration values applied as the sweep applies them).
        papers = PR.load_papers()
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
                        found, have = RD.pointer(cfg, ptr)
                        if not found:
                            found, have = ptr in rb.get("config_defaults", {}), rb.get("config_defaults", {}).get(ptr)
                        good = good and found and RD.same_value(have, want)
                    ok = ok or good
                self.assertTrue(ok, f"{table} / {label}: no condition of the paper suite matches {PR.describe_key(key)}")


class ValidCsv(unittest.TestCase):
    @needs_omniloc
    def test_real_sweep_specs_write_rfc4180_csv(self):
        for spec in ("occlusion_002", "lighting_002", "paper_suite"):
            with tempfile.TemporaryDirectory() as tmp:
                path = str(ROOT / "scenarios/sweeps" / f"{spec}.json")
                # The final aggregate needs every run done or failed (batch/aggregate.hpp): record each as failed.
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


class Compare(unittest.TestCase):
    @needs_omniloc
    def test_known_difference_is_found_and_equal_sets_are_same(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            for s, (xa, xb) in enumerate([(2.00, 3.01), (2.10, 3.12), (1.90, 2.93)], start=1):
                cfg = {"duration": 60}
                write_run(tmp / "A" / f"r{s}", "tracking", "matching", s, cfg, robot(xa), "commitA")
                write_run(tmp / "B" / f"other_folder_{4 - s}", "tracking", "matching", s, cfg, robot(xb), "commitB")
                write_run(tmp / "C" / f"r{s}", "tracking", "matching", s, cfg, robot(xa), "commitC")
            ra, _, _ = RD.discover([tmp / "A"])
            rb, _, _ = RD.discover([tmp / "B"])
            rc, _, _ = RD.discover([tmp / "C"])
            header, rows = CMP.compare_rows(ra, rb)
            x = [r for r in rows if r[1] == "x_cm/mean"][0]
            self.assertEqual(x[0], "tracking / matching")
            self.assertAlmostEqual(float(x[header.index("B - A")]), 1.02, places=4)
            self.assertEqual(x[header.index("exceeds spread")], "yes")
            y = [r for r in rows if r[1] == "y_cm/mean"][0]
            self.assertEqual(y[header.index("exceeds spread")], "same")
            _, rows = CMP.compare_rows(ra, rc)
            self.assertTrue(all(r[-1] == "same" for r in rows if r[1] != "(only in A)"))
            # A single seed per side: the difference alone, no verdict on spread.
            _, rows = CMP.compare_rows(ra[:1], rb[:1])
            self.assertEqual([r for r in rows if r[1] == "x_cm/mean"][0][-1], "n < 2")
            # The CLI, through omniloc itself.
            out = subprocess.run([OMNILOC, "compare", str(tmp / "A"), str(tmp / "B")], capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertIn("commitA", out.stdout)
            self.assertIn("commitB", out.stdout)
            self.assertIn("yes", out.stdout)
            out = subprocess.run([OMNILOC, "compare", str(tmp / "A"), str(tmp / "nothing_here")], capture_output=True, text=True)
            self.assertEqual(out.returncode, 2)


class Tools(unittest.TestCase):
    def test_paper_table_reads_the_profile_from_the_runs_and_prints_every_table(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_run(pathlib.Path(tmp) / "field", "tracking", "matching", 1, {"noise_profile": "field_robot"}, robot(7.25))
            run = lambda *args: subprocess.run([PY, "-m", "omniloc.commands.paper_table", tmp] + list(args), capture_output=True, text=True)
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
            self.assertEqual(run("--paper", "list").stdout.split(), [k for k in PR.load_papers() if k not in ("comment", "claims")])

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
            out = subprocess.run([PY, "-m", "omniloc.commands.compare", str(tmp / "A"), str(tmp / "B")], capture_output=True, text=True)
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
            _, rows = CMP.compare_rows(*(RD.discover([tmp / d])[0] for d in ("A", "C")))
            xr = [r for r in rows if r[1] == "x_cm/mean"]
            self.assertEqual(len(xr), 2)
            self.assertIn("localizer: matching -> mcl", xr[0][0])
            self.assertAlmostEqual(float(xr[0][6]), 25.0 - 2.52, places=4)


class StartPoseAndPositionMean(unittest.TestCase):
    """position_m.mean is carried and shown; a run given the true start pose never shares a
    row with one that started globally (paper_table, report, compare)."""

    def tracking_table(self, tmp, external_given=True, mcl_given=False):
        for s in (1, 2):
            write_run(tmp / "res" / f"matching{s}", "tracking", "matching", s, {}, robot(3.0 + s / 10), start_pose_given=True)
            write_run(tmp / "res" / f"mcl{s}", "tracking", "mcl", s, {}, robot(30.0 + s), start_pose_given=mcl_given)
            write_run(tmp / "res" / f"ext{s}", "tracking", "js_client", s, {}, robot(5.0 + s / 10), start_pose_given=external_given, external=True)
        return RD.discover([tmp / "res"])[0]

    def test_a_client_given_the_start_pose_is_never_in_a_global_start_row(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            runs = self.tracking_table(tmp)
            rows = {p.label: p for p in T.pair_table(PR.load_papers(), "000_tracking", runs)}
            mcl = rows["tracking path, MCL alone (global start)"]
            self.assertEqual([q.name for q in mcl.peers], [])
            self.assertEqual(mcl.stats["x_cm/mean"].n, 2)
            track = rows["tracking"]
            self.assertEqual([(q.name, q.row) for q in track.peers], [("js_client", "tracking (given the start pose)")])
            self.assertEqual(track.shown, "tracking (given the start pose)")  # the table holds both kinds
            # A global-start row with only a given client beside it: the client gets a row of its own.
            only = T.pair_table(PR.load_papers(), "000_tracking", runs, labels=["tracking path, MCL alone (global start)"])[0]
            self.assertEqual(len(only.peers), 1)
            self.assertNotIn("global start", only.peers[0].row)
            self.assertTrue(only.peers[0].row.endswith("(given the start pose)"))
            # A built-in MCL run somebody gave the start pose is not taken into the global-start row.
            write_run(tmp / "res" / "mcl_given", "tracking", "mcl", 9, {}, robot(1.0), start_pose_given=True)
            runs = RD.discover([tmp / "res"])[0]
            mcl = {p.label: p for p in T.pair_table(PR.load_papers(), "000_tracking", runs)}["tracking path, MCL alone (global start)"]
            self.assertEqual(sorted(r.seed for r in mcl.runs), [1, 2])
            out = subprocess.run([PY, "-m", "omniloc.commands.paper_table", str(tmp / "res"), "--paper", "000_tracking"], capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            ext = [l for l in out.stdout.splitlines() if "external: js_client" in l]
            self.assertEqual(len(ext), 1, out.stdout)
            self.assertTrue(ext[0].startswith("tracking (given the start pose)"), out.stdout)

    def test_a_global_client_sits_beside_the_global_start_rows(self):
        with tempfile.TemporaryDirectory() as tmp:
            runs = self.tracking_table(pathlib.Path(tmp), external_given=False)
            rows = {p.label: p for p in T.pair_table(PR.load_papers(), "000_tracking", runs)}
            self.assertEqual(rows["tracking"].peers, [])
            self.assertEqual([q.name for q in rows["tracking path, MCL alone (global start)"].peers], ["js_client"])

    def test_runs_without_the_new_keys_are_read_as_before(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            old = robot(4.0)
            del old["position_m"]["mean"]
            for s in (1, 2):
                write_run(tmp / "res" / f"mcl{s}", "tracking", "mcl", s, {}, old)  # no start_pose_given either
                write_run(tmp / "res" / f"ext{s}", "tracking", "js_client", s, {}, robot(5.0), external=True)
            runs = RD.discover([tmp / "res"])[0]
            self.assertIsNone(runs[0].start_pose_given)
            self.assertIsNone(runs[2].metric("position_m/mean"))
            rows = {p.label: p for p in T.pair_table(PR.load_papers(), "000_tracking", runs)}
            self.assertEqual(rows["tracking path, MCL alone (global start)"].stats["x_cm/mean"].n, 2)
            self.assertEqual([q.name for q in rows["tracking path, MCL alone (global start)"].peers], ["js_client"])
            out = subprocess.run([PY, "-m", "omniloc.commands.report", str(tmp / "res"), "-o", str(tmp / "rep"), "--history", "none"],
                                 capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)

    def test_the_report_and_compare_show_the_position_mean(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            for s in (1, 2):
                write_run(tmp / "A" / f"r{s}", "tracking", "matching", s, {}, robot(2.5), start_pose_given=True)
                write_run(tmp / "B" / f"r{s}", "tracking", "matching", s, {}, robot(5.0), start_pose_given=True)
            header, rows = CMP.compare_rows(RD.discover([tmp / "A"])[0], RD.discover([tmp / "B"])[0])
            pm = [r for r in rows if r[1] == "position_m/mean"]
            self.assertEqual(len(pm), 1)
            self.assertAlmostEqual(float(pm[0][header.index("B - A")]), 0.02, places=4)  # 5/125 - 2.5/125
            out = subprocess.run([PY, "-m", "omniloc.commands.report", str(tmp / "A"), "-o", str(tmp / "rep"), "--history", "none"],
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
            header, rows = CMP.compare_rows(RD.discover([tmp / "A"])[0], RD.discover([tmp / "B"])[0])
            self.assertEqual([r[1] for r in rows if r[1].startswith("(only")],
                             ["(only in A: not comparable: global start here, given the start pose on the other side "
                              "(tracking from the true start pose and global localization are different tasks))",
                              "(only in B: not comparable: given the start pose here, global start on the other side "
                              "(tracking from the true start pose and global localization are different tasks))"])
            self.assertFalse([r for r in rows if r[1] == "x_cm/mean"])
            # An older run of the same condition, without the key: still paired.
            _, rows = CMP.compare_rows(RD.discover([tmp / "old"])[0], RD.discover([tmp / "A"])[0])
            self.assertEqual(len([r for r in rows if r[1] == "x_cm/mean"]), 1)
            self.assertFalse([r for r in rows if r[1].startswith("(only")])
