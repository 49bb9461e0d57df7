"""The report links each run it shows to the run's viewer page (omniloc.report.viewers): the page
exists beside the report in viewers/, is a viewer page, and a run whose files do not make one gets
no link and a line saying why."""
import json
import pathlib
import re
import shutil
import subprocess
import tempfile
import unittest

from helpers import OMNILOC, ROOT, load_script, needs_omniloc, scored, robot, write_run, write_viewable_run
from omniloc.commands import report as REPORT
from omniloc.report import viewers as V
from omniloc.tools import markup as MU

VIEWER_MARK = 'id="omniloc-data"'
PAGE_FORMAT = '"format":"omniloc-view-page/1"'


def make_report(results, out, *extra):
    REPORT.main([str(r) for r in results] + ["-o", str(out), "--history", "none", *extra])
    return (out / "report.md").read_text(), (out / "report.html").read_text()


def md_viewer_links(md):
    return re.findall(r"\]\((viewers/[^)]+)\)", md)


def break_est_tum(folder):
    """est.tum with its third row cut to four fields: the viewer refuses it, naming the line."""
    est = folder / "est.tum"
    lines = est.read_text().splitlines()
    lines[2] = " ".join(lines[2].split()[:4])
    est.write_text("\n".join(lines) + "\n")


class ReportViewerTest(unittest.TestCase):
    def check_page(self, out, link):
        page = out / link
        self.assertTrue(page.is_file(), link)
        text = page.read_text()
        self.assertIn(VIEWER_MARK, text)
        self.assertIn(PAGE_FORMAT, text)
        script = (ROOT / "python" / "omniloc" / "view" / "viewer.js").read_text()
        self.assertIn(script.strip().splitlines()[0], text)  # the viewer's script, inlined
        self.assertNotIn("<script src=", text)  # self-contained
        return text

    @needs_omniloc
    def test_a_real_run_links_to_its_viewer_and_a_broken_one_says_why(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            res = tmp / "results"
            subprocess.run([OMNILOC, "run", str(ROOT / "scenarios" / "quickstart.json"), "-o", str(res / "quick"), "--draw-each"],
                           check=True, capture_output=True, cwd=tmp)
            shutil.copytree(res / "quick", res / "broken")
            break_est_tum(res / "broken")
            out = tmp / "report"
            md, doc = make_report([res], out)
            self.assertEqual(md_viewer_links(md), ["viewers/results--quick.html"])  # one link per run with a page
            self.assertIn("href='viewers/results--quick.html'", doc)
            page = self.check_page(out, "viewers/results--quick.html")
            self.assertIn("quickstart, seed 1", page)  # the run's title
            self.assertEqual(sorted(p.name for p in (out / "viewers").iterdir()), ["results--quick.html"])
            self.assertIn("No viewer page for this run: est.tum line 3: expected 8 numbers", md)
            self.assertIn("`results/broken`): est.tum line 3", md)  # and in the section on the viewer pages
            self.assertNotIn("viewers/results--broken", doc)
            checker = load_script("check_report_html")
            ok, detail = checker.check_links(out / "report.html", require_viewer=True)
            self.assertTrue(ok, detail)

    def test_every_run_shown_links_its_page(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            res = tmp / "results"
            write_viewable_run(res / "loose" / "a", seed=1)
            write_viewable_run(res / "loose" / "odd name (2)", seed=2)
            break_est_tum(write_viewable_run(res / "loose" / "broken", seed=3))
            write_run(res / "loose" / "old", "quickstart", "odometry_only", 4, {}, scored(robot(2.0)))  # summary.json only
            (write_viewable_run(res / "loose" / "bad field", seed=5) / "field.json").write_text("{nope")  # nor a plot
            out = tmp / "report"
            md, doc = make_report([res], out)
            links = md_viewer_links(md)
            self.assertIn("viewers/results--loose--a.html", links)
            self.assertIn("viewers/results--loose--odd_name__2_.html", links)  # file-safe
            for link in set(links):
                self.check_page(out, link)
                self.assertIn(f"href='{link}'", doc)
            self.assertEqual(len(list((out / "viewers").glob("*.html"))), 2)
            self.assertIn("No viewer page for this run: est.tum line 3: expected 8 numbers", md)
            self.assertIn("No viewer page for this run: field.json: missing", md)
            self.assertIn("## Run viewers", md)
            self.assertIn("No viewer page for this run: field.json line 1: expected the field's markings", md)
            self.assertIn("No plot for this run: JSONDecodeError", md)
            self.assertIn("3 run(s) have no viewer page", md)
            # A second report into the same folder leaves no page of the first behind.
            shutil.rmtree(res / "loose" / "a")
            md2, _ = make_report([res], out)
            self.assertEqual(sorted(p.name for p in (out / "viewers").glob("*.html")), ["results--loose--odd_name__2_.html"])

    def test_seed_table_and_global_start_runs_link_their_pages(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            sweep = tmp / "global_tracking"
            lines = ["index,id,scenario,localizer,params,seed,status"]
            for k, seed in enumerate((1, 2, 3)):
                rid = f"tracking__mcl__default__s{seed}"
                write_viewable_run(sweep / "runs" / rid, "tracking", "mcl", seed)
                lines.append(f"{k},{rid},tracking,mcl,default,{seed},ok")
            (sweep / "runs.csv").write_text("\n".join(lines) + "\n")
            (sweep / "aggregate.json").write_text(json.dumps({"sweep": "global_tracking", "runs": 3, "groups": []}))
            out = tmp / "report"
            md, doc = make_report([sweep], out)
            names = [f"viewers/global_tracking--runs--tracking__mcl__default__s{s}.html" for s in (1, 2, 3)]
            for n in names:
                self.check_page(out, n)
            # The global-start section lists each run with its page.
            self.assertIn("Each run of global_tracking: judged apart", doc)
            rows = [ln for ln in md.splitlines() if ln.startswith("| mcl (given the start pose) | ") and "[view](" in ln]
            self.assertEqual(len(rows), 3)
            for row, n in zip(rows, names):
                self.assertIn(f"[view]({n})", row)
            # The per-seed table: each seed a link.
            self.assertRegex(md, r"\[s1\]\(viewers/global_tracking--runs--tracking__mcl__default__s1\.html\), \[s2\]")
            # Each run's block in the sweep's runs.
            for n in names:
                self.assertIn(f"[Run viewer]({n})", md)

    def test_a_report_of_many_runs_links_those_shown_on_their_own(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            sweep = tmp / "sweep"
            lines = ["index,id,scenario,localizer,params,seed,status"]
            for k, seed in enumerate((1, 2, 3)):
                rid = f"tracking__matching__default__s{seed}"
                write_viewable_run(sweep / "runs" / rid, "tracking", "matching", seed)
                lines.append(f"{k},{rid},tracking,matching,default,{seed},ok")
            (sweep / "runs.csv").write_text("\n".join(lines) + "\n")
            (sweep / "aggregate.json").write_text(json.dumps({"sweep": "sweep", "runs": 3, "groups": []}))
            old = V.LIMIT
            V.LIMIT = 2  # three runs: more than the limit
            try:
                md, _ = make_report([sweep], tmp / "report")
            finally:
                V.LIMIT = old
            # Only the plotted run (the first seed of its group) has a page; the others are counted,
            # and the report says how to make them.
            self.assertEqual(sorted(set(md_viewer_links(md))), ["viewers/sweep--runs--tracking__matching__default__s1.html"])
            self.assertIn("2 run(s) shown in this report have no page here", md)
            self.assertIn("`omniloc view RUN_DIR`", md)

    def test_page_names_are_stable_file_safe_and_unique(self):
        roots = [pathlib.Path("/r/results"), pathlib.Path("/r/results/sweeps/s")]
        self.assertEqual(V.page_name(pathlib.Path("/r/results/sweeps/s/runs/a__b__c__s1"), roots), "s--runs--a__b__c__s1")
        self.assertEqual(V.page_name(pathlib.Path("/r/results/loose/x y"), roots), "results--loose--x_y")
        self.assertEqual(V.page_name(pathlib.Path("/r/results"), roots), "results")
        self.assertEqual(V.page_name(pathlib.Path("/elsewhere/run"), roots), "run")
        long = V.page_name(pathlib.Path("/r/results/" + "a" * 300), roots)
        self.assertLessEqual(len(long), V.MAX_NAME)
        self.assertRegex(long, r"^[A-Za-z0-9._-]+$")
        with tempfile.TemporaryDirectory() as tmp:
            v = V.Viewers(pathlib.Path(tmp), ["/r/a/results", "/r/b/results"], 2)
            one, two = v._name(pathlib.Path("/r/a/results")), v._name(pathlib.Path("/r/b/results"))
            self.assertEqual(one, "results")
            self.assertNotEqual(one, two)  # two results folders of one name
            self.assertEqual(v._name(pathlib.Path("/r/a/results")), "results")

    def test_the_terminal_writer_gets_no_links(self):
        with tempfile.TemporaryDirectory() as tmp:
            run_dir = write_viewable_run(pathlib.Path(tmp) / "run")
            from omniloc.core.rundir import Run
            self.assertEqual(V.cell(MU.TextReport(), Run.read(run_dir)), "-")
            V.line(MU.TextReport(), Run.read(run_dir), own=True)  # prints nothing, writes nothing
            self.assertFalse((pathlib.Path(tmp) / "viewers").exists())

    def test_the_link_check_catches_missing_and_wrong_pages(self):
        checker = load_script("check_report_html")
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            (tmp / "viewers").mkdir()
            (tmp / "viewers" / "a.html").write_text(f'<html><script type="application/json" {VIEWER_MARK}>{{}}</script></html>')
            (tmp / "viewers" / "b.html").write_text("<html>not a viewer</html>")
            page = tmp / "report.html"

            def links(body, md=None):
                page.write_text(f"<html><body>{body}</body></html>")
                (tmp / "report.md").write_text(md if md is not None else "".join(f"[view]({h})\n" for h in re.findall(r"href='([^']+)'", body)))
                return checker.check_links(page, require_viewer=True)
            self.assertTrue(links("<a href='viewers/a.html'>view</a><a href='#x'>x</a>")[0])
            ok, detail = links("<a href='viewers/missing.html'>view</a>")
            self.assertFalse(ok)
            self.assertIn("no such file in viewers/: viewers/missing.html", detail)
            ok, detail = links("<a href='viewers/b.html'>view</a>")
            self.assertFalse(ok)
            self.assertIn("not a viewer page", detail)
            self.assertFalse(links("<a href='viewers/../report.html'>view</a>")[0])
            self.assertFalse(links("<a href='/work/x/viewers/a.html'>view</a><a href='viewers/a.html'>v</a>")[0])
            self.assertFalse(links("<a href='file:///tmp/a.html'>view</a><a href='viewers/a.html'>v</a>")[0])
            self.assertFalse(links("<a href='#x'>x</a>")[0])  # the self-test's report must link a page
            ok, detail = links("<a href='viewers/a.html'>view</a>", md="[view](viewers/gone.html)\n")
            self.assertFalse(ok)
            (tmp / "viewers" / "c.html").write_text(f'<html><script {VIEWER_MARK}>"/home/someone/run"</script></html>')
            ok, detail = links("<a href='viewers/c.html'>view</a>")
            self.assertFalse(ok)
            self.assertIn("an absolute path inside", detail)


if __name__ == "__main__":
    unittest.main()
