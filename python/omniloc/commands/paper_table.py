"""Prints omniloc results in a paper's table layout, each published row beside the runs that reproduce it.

usage: omniloc paper-table RESULTS... --paper KEY [--rows LABEL ...] [--profile NAME] [--markdown]

RESULTS are run or sweep folders, or folders holding them (e.g. results/sweeps/paper_suite). KEY
names any published table of results/reference/papers.json (`--paper list` lists them, `--paper
all` prints every one): the error tables 002_table1_occlusion, 002_table2_lighting and
000_tracking in the papers' nine-column layout; the kidnap, timing and experiment tables as the
report shows them. Rows pair BY KEY: each published row in papers.json names its scenario,
localizer and configuration values ("reproduced_by"), and our runs are found by those, never by
their position in a sweep. --rows keeps only the named rows (published or extra) of an error table.
A row without runs says "not run" and prints the command that runs it. Ours: mean over seeds (n
shown); runs with kidnaps or covers use their tracking phase. Only the published numbers come from
papers.json. External localizers (docs/protocol.md) found in RESULTS on a row's scenario and
configuration are printed beside it, named "external: <the client's name>", but only beside a row
of the same task: a run given the true start pose (summary.json start_pose_given) never sits in a
"(global start)" row, nor a globally started one beside a tracking row; such a client gets a row
of its own, labelled "(given the start pose)" or "(global start)". Where a table holds both kinds,
its rows given the start pose say "(given the start pose)".

Coverage: the papers' errors are over the frames a localizer answered. Beside them each of our rows
shows first the share of all scored frames within the headline recall threshold ("within 25 cm /
10 deg", summary.json recall) and the share of frames answered ("answered"), means over seeds; an
error with no value (no frame answered) reads "no estimate", and a row where some seeds had none
says "no estimate in k of n runs" in its seeds column (its errors are then over the others).

Noise profile: rows pair runs of one profile. --profile NAME picks it (robot, field_robot, ...);
without it the profile is read from the runs: robot where there are robot runs, else the one
profile the runs have (e.g. the field_robot sweep), and the table says which.
"""
from __future__ import annotations

import argparse
import os
import sys
from typing import Optional, Sequence

from omniloc.core import pairing, rundir


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog=os.environ.get("OMNILOC_PAPER_TABLE_PROG", "python3 -m omniloc.commands.paper_table"), description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", nargs="+")
    ap.add_argument("--paper", required=True, help="a table key of results/reference/papers.json")
    ap.add_argument("--rows", nargs="+", metavar="LABEL", help="only these rows (published or extra row labels)")
    ap.add_argument("--profile", help="noise profile of the runs to pair (default: read from the runs)")
    ap.add_argument("--markdown", action="store_true")
    ap.add_argument("--accept-incomplete", action="store_true", help="use sweep folders whose aggregate is not final (said in the output)")
    a = ap.parse_args(argv)
    papers = pairing.load_papers()
    published = [k for k in papers if k not in ("comment", "claims")]
    if a.paper == "list":
        print("\n".join(published))
        return 0
    if a.paper not in published + ["all"]:
        print(f"error: no published table \"{a.paper}\" in papers.json; tables: {', '.join(published)}", file=sys.stderr)
        return 2
    try:
        runs, _, experiments = rundir.discover(a.results, a.accept_incomplete)
    except SystemExit as e:
        print(f"error: cannot read results: {e}", file=sys.stderr)
        return 2
    from omniloc.report import text_tables  # after the results are found: its imports take a second
    tables = text_tables.error_tables(papers)
    profile, how = text_tables.choose_profile(runs, a.profile)
    if profile is None:
        print(f"error: {how}", file=sys.stderr)
        return 2
    with pairing.pairing_profile(profile):
        for key in (published if a.paper == "all" else [a.paper]):
            if key in tables:
                code = text_tables.print_error_table(papers, key, runs, a.rows, a.markdown)
            else:
                code = text_tables.print_other_table(papers, key, runs, experiments, a.markdown)
            if code:
                return code
    print(f"noise profile: {profile} ({how})")
    for d in rundir.INCOMPLETE:
        print(f"note: {d} is an incomplete sweep (--accept-incomplete): only its finished runs are in these tables")
    return 0



if __name__ == "__main__":
    sys.exit(main())
