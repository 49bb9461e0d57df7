"""The report end to end and section by section: few seeds, profiles apart, external peers, the reader's language, the error budget, the history page.
"""
import json
import re
import pathlib
import subprocess
import tempfile
import unittest

from helpers import PY, ROOT, load_script, mcl_runs_with_outlier, report_cpu, robot, write_frames, write_occlusion_sweep, write_run
from omniloc.core import pairing as PR
from omniloc.core import rundir as RD
from omniloc.paper import data as D
from omniloc.paper import labels as L
from omniloc.paper import tables as T
from omniloc.report import cdf as RCDF
from omniloc.report import experiments as REXP
from omniloc.report import history as RHIST
from omniloc.report import seeds as RSEED
from omniloc.tools import citations
from omniloc.tools import markup as MU


class ReportEndToEnd(unittest.TestCase):
    def test_report_has_scorecard_and_every_table_key(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_occlusion_sweep(pathlib.Path(tmp) / "s", [0.0, 0.5])
            out = subprocess.run([PY, "-m", "omniloc.commands.report", str(pathlib.Path(tmp) / "s"), "-o", str(pathlib.Path(tmp) / "rep")],
                                 capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            doc = (pathlib.Path(tmp) / "rep" / "report.html").read_text()
            self.assertIn('id="scorecard"', doc)
            # Every published table is in the report under its readable label (a section's anchor
            # may keep the key; the text a reader reads never shows it).
            import html as H
            text = H.unescape(re.sub(r"<[^>]+>", " ", doc))
            for k in PR.load_papers():
                if k not in ("comment", "claims"):
                    self.assertTrue(L.table_label(k) in text or f'id="{k}"' in doc, f"{k} is not in the report")
            for key in ("mcl_only_mean_position_error_cm", "001_real_mean_error_cm", "tracking_accuracy", "iss" + "ue 29"):  # spelled apart: no tracker reference in this file
                self.assertNotIn(key, text)
            self.assertIn('id="headline"', doc)
            self.assertIn('id="references"', doc)
            self.assertIn("not run", doc)
            self.assertIn("abc123", doc)  # provenance


class FewSeeds(unittest.TestCase):
    """Few seeds: every seed beside its mean, outlying seeds flagged with their cause."""

    def test_outlier_cause_is_read_from_the_frames(self):
        with tempfile.TemporaryDirectory() as tmp:
            mcl_runs_with_outlier(tmp)
            run = RD.Run.read(pathlib.Path(tmp) / "mcl_s2")
            self.assertEqual(RSEED.outlier_cause(run), "converged to a wrong pose at t = 0.5 s: 8.06 m from the truth (median), "
                             "mode 'converged' in 91 % of the frames from the start to the end; never within 0.5 m")
            lost = pathlib.Path(tmp) / "lost"
            write_run(lost, "kidnap_002", "hybrid", 1, {}, robot(50.0))
            write_frames(lost, [(0.5 * k, 0.1, True, "tracking") for k in range(5)] + [(2.5 + 0.5 * k, 3.0, False, "lost") for k in range(4)],
                         [{"type": "kidnap", "t": 2.4, "robot": 0}])
            self.assertEqual(RSEED.outlier_cause(RD.Run.read(lost)),
                             "lost from t = 2.5 s, after the kidnap at t = 2.4 s: no estimate, no confident estimate (mode 'lost') to the end")
            fine = pathlib.Path(tmp) / "fine"
            write_run(fine, "tracking", "matching", 1, {}, robot(2.0))
            write_frames(fine, [(0.0, 0.1, True, "tracking"), (1.0, 0.9, True, "tracking"), (2.0, 0.2, True, "tracking")])
            self.assertEqual(RSEED.outlier_cause(RD.Run.read(fine)),
                             "on a wrong pose (> 0.5 m off) for 1.0 s of 3.0 s, from t = 1.0 to 2.0 s, 0.90 m off (median); within 0.5 m at the end")
            # A seed 8.8 m off from the start for 37 s of 60, right afterwards, is described by
            # the time it spent on the wrong pose, never as an error "peak".
            back = pathlib.Path(tmp) / "back"
            write_run(back, "tracking", "mcl", 2, {}, robot(300.0))
            write_frames(back, [(0.5 * k, 8.8 if k < 74 else 0.1, True, "converged") for k in range(120)])
            cause = RSEED.outlier_cause(RD.Run.read(back))
            self.assertEqual(cause, "on a wrong pose (> 0.5 m off) for 37.0 s of 60.0 s, from t = 0.0 to 37.0 s, 8.80 m off (median); within 0.5 m at the end")
            self.assertNotIn("peak", cause)
            twice = pathlib.Path(tmp) / "twice"
            write_run(twice, "tracking", "mcl", 3, {}, robot(100.0))
            write_frames(twice, [(1.0 * k, 2.0 if k in (1, 4, 5) else 0.1, k != 7, "tracking") for k in range(10)])
            self.assertEqual(RSEED.outlier_cause(RD.Run.read(twice)),
                             "on a wrong pose (> 0.5 m off) for 3.0 s of 10.0 s, longest from t = 4.0 to 6.0 s, 2.00 m off (median); within 0.5 m at the end")
            calm = pathlib.Path(tmp) / "calm"
            write_run(calm, "tracking", "mcl", 4, {}, robot(10.0))
            write_frames(calm, [(0.0, 0.1, True, "tracking"), (1.0, 0.3, True, "tracking"), (2.0, 0.2, True, "tracking")])
            self.assertEqual(RSEED.outlier_cause(RD.Run.read(calm)), "never on a wrong pose (> 0.5 m off): at most 0.30 m at t = 1.0 s")

    def test_seed_table_shows_every_seed_and_flags_the_outlier(self):
        with tempfile.TemporaryDirectory() as tmp:
            mcl_runs_with_outlier(pathlib.Path(tmp) / "runs")
            runs, _, _ = RD.discover([pathlib.Path(tmp) / "runs"])
            rep = MU.Report(pathlib.Path(tmp) / "out", "t")
            flagged = RSEED.seed_table(rep, [("MCL alone", sorted(runs, key=lambda r: r.seed))])
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
            one = MU.Report(pathlib.Path(tmp) / "one", "t")
            RSEED.seed_table(one, [("one seed", runs[:1])])
            one.write()
            self.assertIn("(n=1, no interval)", (pathlib.Path(tmp) / "one" / "report.md").read_text())


class ProfilesApart(unittest.TestCase):
    """The error CDF and the timing never pool robot and field_robot runs."""

    def test_cdf_and_timing_are_per_profile(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            for prof, err, ms in (("robot", 0.05, 1.0), ("field_robot", 0.5, 3.0)):
                for seed in (1, 2):
                    d = tmp / "runs" / f"{prof}_s{seed}"
                    write_run(d, "tracking", "matching", seed, {} if prof == "robot" else {"noise_profile": prof}, robot(3.0))
                    write_frames(d, [(0.1 * k, err, True, "tracking") for k in range(10)])
                    (d / "timing.csv").write_text("render_ms,vision_ms,localize_ms\n" + "".join(f"{ms},{ms},{ms}\n" for _ in range(10)))
            runs, _, _ = RD.discover([tmp / "runs"])
            rep = MU.Report(tmp / "out", "t")
            RCDF.cdf_and_timing(rep, runs)
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
            out = subprocess.run([PY, "-m", "omniloc.commands.report", str(tmp / "results"), "-o", str(tmp / "rep"), "--history", "none"],
                                 capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            md = (tmp / "rep" / "report.md").read_text()
            self.assertIn("| 0 % | external: perl_client | 4.500 |", md)
            # Two seeds: the 4 resamples have means 4, 4.5, 4.5, 5; the 2.5 % point lies 0.075 of the way from 4 to 4.5.
            self.assertIn("| 0 % (external: perl_client) | 2 | mean 4.50 (seeds' range 4.00 to 5.00, n=2); median 4.50; seeds: s1\u00a04.00, s2\u00a05.00 |", md)
            table = subprocess.run([PY, "-m", "omniloc.commands.paper_table", str(tmp / "results"), "--paper", "002_table1_occlusion", "--rows", "0 %"],
                                   capture_output=True, text=True).stdout
            self.assertIn("external: perl_client", table)


class ReaderReport(unittest.TestCase):
    """The report as a reader sees it: scorecard and contents first, no absolute paths, markdown
    rendered, text left and numbers right, developer charts on their own page."""

    def test_cells_and_inline_markdown(self):
        self.assertEqual(MU.numeric_class("50 % occlusion degrades the mean error only mildly"), "")
        self.assertEqual(MU.numeric_class("002 / 000"), "")  # a paper's number is a name
        for cell in ("50 %", "2.42 [2.36, 2.48]", "3 / 3", "0.296 ms", "-1.5", "4.750 (n=1, no interval)",
                     "4.50 (seeds' range 4.00 to 5.00, n=3)", "3.000 [1.037, 4.963] (n=5, t95)"):
            self.assertEqual(MU.numeric_class(cell), " class='num'", cell)
        self.assertEqual(MU.inline_markdown("run `omniloc x` for **all** <rows> *now*, 5 * 3"),
                         "run <code>omniloc x</code> for <b>all</b> &lt;rows&gt; <i>now</i>, 5 * 3")

    def test_an_experiments_table_shown_in_its_own_section_is_not_repeated(self):
        md = ("# error_budget: which error source dominates\n\nDescription file `/some/checkout/scenarios/experiments/error_budget.json`.\n\n"
              "| source | RMSE cm |\n|---|---:|\n| baseline | 1.00 |\n\n## Notes\n\nText with **bold**.\n\n| other | x |\n|---|---|\n| a | 2 |\n")
        with tempfile.TemporaryDirectory() as tmp:
            rep = MU.Report(tmp, "t")
            rep.markdown(md, skip=REXP.SHOWN_ELSEWHERE["error_budget"])
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
            out = subprocess.run([PY, "-m", "omniloc.commands.report", str(tmp / "results"), "-o", str(tmp / "rep"), "--history", str(tmp / "hist")],
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


class ReaderLanguage(unittest.TestCase):
    """The reader's language: papers cited with a bibliography, no ids or tracker numbers, abbreviations spelled out."""

    def test_citations(self):
        self.assertEqual(citations.cite_text("Lu et al. 2013 (paper 002), Table 1"), "Lu et al. 2013 [3], Table 1")
        self.assertEqual(citations.cite_text("Xiong, Lu, Zheng (paper 000), tracking"), "Xiong et al. 2012 [1], tracking")
        self.assertEqual(citations.cite_text("Kidnap recovery (papers 002 and 000)"), "Kidnap recovery (Lu et al. 2013 [3] and Xiong et al. 2012 [1])")
        self.assertEqual(L.cite_field("002 refs [7], [8]"), "Lu et al. 2013 [3], its refs [7], [8]")
        self.assertEqual(len(citations.BIBLIOGRAPHY), 5)
        self.assertTrue(all(b.year and b.title and b.authors for b in citations.BIBLIOGRAPHY))
        for c in PR.load_papers()["claims"]:
            self.assertIn(c["id"], D.CLAIM_LABELS)

    def test_abbreviations_are_spelled_out_once(self):
        with tempfile.TemporaryDirectory() as tmp:
            rep = MU.Report(tmp, "t")
            rep.para("MCL alone, then MCL again; `MCL` in code")
            rep.para("MCL and RMSE")
            self.assertEqual(rep.md[2], "MCL (Monte Carlo localization) alone, then MCL again; `MCL` in code")
            self.assertEqual(rep.md[4], "MCL and RMSE (root mean square error)")
            rep.para("see docs/results.md#intervals")
            self.assertIn("<a href='", rep.html[-1])
            self.assertIn("docs/results.md#intervals'>docs/results.md</a>", rep.html[-1])

    def test_the_html_checks_catch_what_they_name(self):
        K = load_script("check_report_html")
        good = ("<html><body><h1>t</h1><p id=\"headline\">In short: " + "x" * 80 + "</p><h2 id=\"scorecard\">Scorecard</h2>"
                "<p>Lu et al. 2013 [3] and <code>tracking_accuracy</code> and occlusion_002.json and field_robot</p>"
                "<div class=\"quoted\"><p>total_like</p></div><h2 id=\"references\">References</h2>"
                "<ol id=\"bibliography\">" + "".join(f"<li>A. {2000 + k}</li>" for k in range(5)) + "</ol></body></html>")
        for f in (K.check_headline, K.check_no_issue_numbers, K.check_no_raw_keys, K.check_unique_headings, K.check_bibliography):
            self.assertTrue(f(good)[0], (f.__name__, f(good)))
        self.assertFalse(K.check_no_issue_numbers(good.replace("Scorecard</h2>", "Scorecard</h2><p>see iss" + "ue 29</p>"))[0])
        self.assertFalse(K.check_no_raw_keys(good.replace("and field_robot", "and mcl_only_mean_position_error_cm"))[0])
        self.assertFalse(K.check_unique_headings(good.replace("<h2 id=\"references\">", "<h3 id=\"x\">Scorecard</h3><h2 id=\"references\">"))[0])
        self.assertFalse(K.check_bibliography(good.replace("2013 [3]", "2013 [9]"))[0])
        self.assertFalse(K.check_bibliography(good.replace("<h2 id=\"references\">References</h2>", ""))[0])
        self.assertFalse(K.check_headline(good.replace(" id=\"headline\"", ""))[0])


class ErrorBudgetSeeds(unittest.TestCase):
    """The error budget's cells carry an interval over the seeds."""

    def test_cells_show_an_interval_or_that_every_seed_agrees(self):
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
            ctx = T.Context(PR.load_papers(), [], [str(e)])
            rep = MU.Report(pathlib.Path(tmp) / "out", "t")
            REXP.error_budget_section(rep, ctx)
            rep.write()
            md = (pathlib.Path(tmp) / "out" / "report.md").read_text()
            self.assertIn("| none (baseline) | 0.60 (= every seed) | 0.30 (= every seed) | 0.10 (= every seed) |", md)
            self.assertIn("| vibration | 4.50 (seeds' range 4.00 to 5.00, n=3) |", md)  # three seeds: their range, no interval
            self.assertIn("Mean over 3 seeds; intervals: n >= 5 seeds", md)
            self.assertIn("Which real-robot error is missing", md)


class HistoryTest(unittest.TestCase):
    """The report's "Speed over commits": per workload the first and last record and their ratio, from
    the committed baseline history followed by this machine's runs; a cut line is skipped."""

    def test_first_last_and_ratio_per_workload(self):
        with tempfile.TemporaryDirectory() as d:
            d = pathlib.Path(d)
            ref = d / "icount_history.jsonl"
            ref.write_text(json.dumps({"commit": "aaa", "instructions": {"matching": 200}}) + "\n")
            (d / "hist").mkdir()
            (d / "hist" / "icount.jsonl").write_text(
                json.dumps({"commit": "bbb", "instructions": {"matching": 150, "mcl": 10}}) + "\n{\"commit\": \"cut")
            (d / "hist" / "bench.jsonl").write_text(json.dumps({"commit": "bbb", "real_time_ns": {"BM_X": 5.0}}) + "\n")
            rep = MU.Report(str(d / "out"), "t")
            RHIST.report_history(rep, d / "hist", reference=ref)
            rep.write()
            md = (d / "out" / "report.md").read_text()
            self.assertIn("| matching | aaa | 200 | bbb | 150 | 0.750 |", md)
            self.assertIn("| mcl | bbb | 10 | bbb | 10 | 1.000 |", md)
            self.assertIn("| BM_X | bbb | 5.0 ns | bbb | 5.0 ns | 1.000 |", md)
            self.assertEqual(md.count(".png)"), 2)
