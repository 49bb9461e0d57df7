#!/usr/bin/env python3
"""Prints each localizer's distance from the accuracy limit per scenario family, as a markdown table.

usage: limit_table.py RESULTS... [--accept-incomplete]

RESULTS are run or sweep folders, or folders holding them (e.g. results/sweeps/paper_suite). Per
localizer and scenario family (a scenario's name without its numbered suffix): the runs, the mean
over runs of the position and heading RMSE over the Cramer-Rao bound of the same frames (summary.json
efficiency: 1x is the limit; posterior bound where the runs track; the tracking phase of runs with
kidnaps or covers) with the mean RMSE and bound they are of, the mean share of frames the bound
covers, and the runs without a bound ("no bound" where none has one, never 0). docs/localizers.md's
efficiency table of the built-in localizers on the paper suite is this table. Runs made before the
bound are left out; exit 2 when no run carries it.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
from omniloc.core import rundir  # noqa: E402
from omniloc.report import limit  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n", 2)[2], formatter_class=argparse.RawDescriptionHelpFormatter,
                                 usage=__doc__.split("\n\n")[1].split("usage: ")[1])
    ap.add_argument("results", nargs="+")
    ap.add_argument("--accept-incomplete", action="store_true", help="use sweep folders whose aggregate is not final")
    a = ap.parse_args()
    try:
        runs, _, _ = rundir.discover(a.results, a.accept_incomplete)
    except SystemExit as e:
        print(f"limit_table.py: error: {e}", file=sys.stderr)
        return 2
    rows = limit.localizer_rows(runs)
    if not rows:
        print(f"limit_table.py: error: no run under {' '.join(a.results)} carries the accuracy limit (summary.json efficiency)", file=sys.stderr)
        return 2
    print("| " + " | ".join(limit.LOCALIZER_HEADER) + " |")
    print("|" + "---|" * len(limit.LOCALIZER_HEADER))
    for r in rows:
        print("| " + " | ".join(r) + " |")
    versions = sorted({str(r.version) for r in runs if r.bound() is not None})
    print(f"\nomniloc {', '.join(versions)}; {sum(1 for r in runs if r.bound() is not None)} runs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
