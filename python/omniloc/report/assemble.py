"""The report, section by section, in the order a reader with ten minutes wants (docs/results.md).
"""
from __future__ import annotations

import argparse
import html
import os
import pathlib
import sys

from omniloc import compare
from omniloc.core import pairing, paths, rundir
from omniloc.paper import tables
from omniloc.report import real_robots, viewers
from omniloc.report.cdf import cdf_and_timing
from omniloc.report.experiments import error_budget_section, report_experiment
from omniloc.report.headline import headline
from omniloc.report.history import report_history
from omniloc.report.provenance import provenance
from omniloc.report.published import field_robot_tables, published_tables
from omniloc.report.runs import report_run
from omniloc.report.scorecard import judge_claims, scorecard
from omniloc.report.sweeps import global_start_section, report_sweep
from omniloc.report.viewers import ViewerReport
from omniloc.tools.citations import BIBLIOGRAPHY
from omniloc.tools.markup import Cell, Report, Writer


def bibliography(rep: Writer) -> None:
    """The five papers, numbered as the report cites them ('Lu et al. 2013 [3]')."""
    rep.heading("References", 2, "references")
    items = []
    for k, b in enumerate(BIBLIOGRAPHY):
        items.append(f"[{k + 1}] {b.authors}. {b.title}. {b.venue}, {b.year}. {b.note}")
    rep.raw_html("<ol id='bibliography'>" + "".join(f"<li id='ref-{k + 1}'>{html.escape(t.split('] ', 1)[1])}</li>" for k, t in enumerate(items))
                 + "</ol>", "\n".join(f"{t}  " for t in items))


def build(a: argparse.Namespace) -> None:
    """Writes the report of the results a names (the arguments of omniloc.commands.report) and prints
    the scorecard's totals and where the report is."""
    papers = pairing.load_papers()
    runs, sweeps, experiments = rundir.discover(a.results, a.accept_incomplete)
    if not (runs or sweeps or experiments):
        sys.exit(os.environ.get("OMNILOC_REPORT_PROG", "omniloc report") + ": no results (summary.json, aggregate.json or experiment pictures) under " + " ".join(a.results))
    # Each run the report shows links to its viewer page (viewers/ beside the report; omniloc.report.viewers).
    rep = ViewerReport(a.out, a.title, a.results, len(runs))
    for x in a.results + (a.baseline or []):
        rep.add_root(x)
    ctx = tables.Context(papers, runs, experiments)
    judged = judge_claims(ctx)
    headline(rep, ctx, *judged)  # first after the title: what a researcher quotes
    rep.para(f"{len(sweeps)} sweep(s), {len(runs)} run(s), {len(experiments)} experiment(s). Published numbers: results/reference/papers.json; "
             f"everything else is read from the result files. The scorecard comes first, then the contents; details follow.")
    for d in rundir.INCOMPLETE:
        rep.para(f"**Incomplete sweep** (--accept-incomplete): {pathlib.Path(d).name} has no final aggregate; only its finished runs are reported.")
    _, _, totals = scorecard(rep, ctx, judged)
    rep.mark_toc()
    # The only real data: right after the scorecard. Its runs are judged against the reference pose
    # and its twin there, and left out of the pooled CDF (which scores against the reference only).
    real = {r.folder for r in real_robots.section(rep, runs, sweeps)}
    provenance(rep, runs, sweeps)
    published_tables(rep, papers, ctx)
    global_start_section(rep, sweeps)
    field_robot_tables(rep, papers, runs)
    error_budget_section(rep, ctx)
    if a.baseline:
        base_runs, _, _ = rundir.discover(a.baseline, a.accept_incomplete)
        rep.heading("Comparison with the baseline", 2, "baseline")
        header, compared = compare.compare_rows(base_runs, runs)
        # Metric names as the reader types them (aggregate.csv's, summary.json's): code.
        rows: list[list[Cell]] = []
        for cells in compared:
            row: list[Cell] = [c for c in cells]
            if not str(cells[1]).startswith("("):
                row[1] = f"`{cells[1]}`"
            rows.append(row)
        explanation = compare.explanation(base_runs + runs).replace("recall/T", "`recall/T`").replace("valid_fraction", "`valid_fraction`")
        rep.table(header, rows, f"baseline: {' '.join(a.baseline)}; this report's results as 'new'. "
                  + explanation)
    in_sweeps = set()
    for sw in sweeps:
        for swept in report_sweep(rep, sw, runs, a.max_runs):
            in_sweeps.add(swept.folder)
    loose = [r for r in runs if r.folder not in in_sweeps]
    if loose:
        rep.heading("Runs", 2)
        rep.details(f"{len(loose)} runs outside sweeps: tables and plots")
        for run in loose:
            report_run(rep, run, plots=True)
        rep.end_details()
    cdf_and_timing(rep, [r for r in runs if r.folder not in real])
    for exp in experiments:
        report_experiment(rep, exp)
    # Developers' charts (speed over commits) are not results: a page of their own, linked here.
    history = a.history or str(paths.ROOT / "results" / "history")
    if history != "none":
        hist = Report(a.out, f"{a.title}: speed over commits", page="history")
        if report_history(hist, pathlib.Path(history)):
            hist.write()
            rep.heading("For developers", 2, "developers")
            rep.raw_html("<p>Instruction counts and benchmark times over the commits (not results of the papers' experiments): "
                         "<a href='history.html'>history.html</a> beside this report.</p>",
                         "Instruction counts and benchmark times over the commits: [history.md](history.md) beside this report.")
    viewers.section(rep)
    bibliography(rep)
    rep.write()
    html_path = rep.out / "report.html"
    print(f"scorecard: {totals}")
    v = rep.viewers
    print(f"report: {html_path} ({html_path.stat().st_size / 1e6:.1f} MB, {rep.n_img} pictures) and {rep.out / 'report.md'}; "
          f"{len(v.hrefs)} viewer page(s) in {v.dir} ({viewers.size_text(v.bytes)})"
          + (f", {len(v.failed)} run(s) without one (the report says why)" if v.failed else ""))
