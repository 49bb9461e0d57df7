"""Comparison report of omniloc results: report.md and a self-contained report.html.

usage: omniloc report RESULTS... -o DIR [--title TEXT] [--max-runs N] [--baseline RESULTS] [--history DIR]

RESULTS are folders: a run (summary.json), a sweep (aggregate.json with runs/ inside), an
experiment (PNG / JSON / markdown files written by `omniloc experiment`), or any folder holding
such folders (searched recursively). The report is laid out for a reader with ten minutes
(docs/results.md), in this order:
  - a headline of two or three sentences, computed from the results: what reproduces and what does
    not, our error against the papers' (median ratio), the main gap and its measured cause;
  - the reproduction scorecard: every claim of results/reference/papers.json with our figure, the
    paper's, the ratio and the verdict computed by the rule written next to the claim, counted
    apart by kind (accuracy / robustness / timing), judged on every axis a published row states,
    with the field_robot runs judged by the same rules in their own column; then the contents;
  - real robots (omniloc.report.real_robots): the global localizers on real robots' frames
    (scenarios/sweeps/real_robots.json: data/real/nubot), each run classified found / twin / wrong
    against the reference pose and its 180-degree twin, and the real line points' noise by range
    beside the simulated robot and field_robot profiles' (from the paper suite sweeps' recordings);
    without those results it says what to run;
  - provenance: which omniloc builds (git describe, compiler, build type) made the results, when,
    and the machine (CPU model, cores);
  - every published table beside the runs that reproduce it, paired BY KEY (scenario, localizer,
    configuration values; omniloc.core.pairing), never by position; a row whose runs are
    missing says "not run" and prints the command that runs it; below each, every seed beside the
    mean (intervals by the one rule of docs/results.md "Intervals": t95 for n >= 5, the seeds' range below), a strip plot of the seeds, and each outlying seed
    plotted with its cause read from its frames.csv and events.jsonl;
  - with --baseline: our metrics against another result set (e.g. another commit), per metric
    with the difference and Welch's t-test over seeds (omniloc.compare);
  - every sweep's aggregate and per-seed table, each run's table and plots (collapsed), error
    CDFs, timing per stage;
  - every experiment's pictures and notes (tables a section above shows are not repeated);
  - each run the report shows links to its run viewer page, written beside the report in
    DIR/viewers/ (`omniloc view`, docs/viewer.md: the run frame by frame, its line points and, with
    --debug-view runs, its particles);
  - on a page of its own (history.html, linked), for developers: instruction counts and benchmark
    wall times per workload over the commits (--history DIR, default results/history);
  - the references: the five papers, cited in the text as 'Lu et al. 2013 [3]' (omniloc.tools.citations.BIBLIOGRAPHY).
Coverage first (docs/results.md "Coverage and recall"): an error is over the frames a localizer
answered, so wherever the report shows one it shows the share of frames answered beside it, and
wherever localizers or conditions stand side by side (the scorecard, the published tables, the sweep
tables, the per-seed tables, the global-start table, the error CDF) the recall at the headline
threshold ("within 25 cm / 10 deg": the share of ALL frames within it, a frame without an estimate
counting as outside) comes first. A statistic over no answered frame reads "no estimate" (or "no
estimate in k of n runs"), never a number; results made before recall was scored show as before.
The text speaks to a reader: claims and tables by readable labels, never papers.json keys or tracker
numbers, abbreviations spelled out at first use (omniloc.paper.labels, omniloc.tools.citations; scripts/check_report_html.py checks).
Pictures are embedded, compressed (palette PNG, JPEG for camera frames) so that report.html stays
under 3 MB; no absolute path reaches the report (omniloc.tools.markup.Report.clean).
Everything except the published numbers is read from the result files. Needs Python 3 and
Debian's python3-matplotlib (no PyPI).
"""
from __future__ import annotations

import argparse
import os
import sys
from typing import Optional, Sequence

from omniloc.core import pathcheck


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog=os.environ.get("OMNILOC_REPORT_PROG", "python3 -m omniloc.commands.report"), description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", nargs="+")
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--title", default="omniloc report")
    ap.add_argument("--max-runs", type=int, default=24, help="trajectory plots for at most this many conditions per sweep, first seed of each (default 24)")
    ap.add_argument("--baseline", nargs="+", help="result folders to compare with (e.g. another commit's), per metric with Welch's t")
    ap.add_argument("--accept-incomplete", action="store_true", help="use sweep folders whose aggregate is not final (the report says so)")
    ap.add_argument("--history", help="folder with icount.jsonl / bench.jsonl (default results/history if it exists; 'none' to leave out)")
    a = ap.parse_args(argv)
    prog = ap.prog
    # Every folder named is checked before the (long) reading and drawing: a bad one is exit 2 with
    # the option and the reason.
    try:
        for r in a.results:
            pathcheck.require_folder(r, "RESULTS", "a folder of results")
        for r in a.baseline or []:
            pathcheck.require_folder(r, "--baseline", "a folder of results")
        if a.history and a.history != "none":
            pathcheck.require_folder(a.history, "--history", "a folder with icount.jsonl / bench.jsonl")
        pathcheck.require_writable(a.out, "-o", True)
    except pathcheck.PathError as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        return 2
    from omniloc.report.assemble import build  # after the checks: its imports take a second
    try:
        build(a)
    except SystemExit as e:  # discover(): an incomplete sweep, a summary.json that cannot be read; no results
        if isinstance(e.code, str):
            print(e.code if e.code.startswith(prog) else f"{prog}: error: {e.code}", file=sys.stderr)
            return 2
        raise
    return 0


if __name__ == "__main__":
    sys.exit(main())
