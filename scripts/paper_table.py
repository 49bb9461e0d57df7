#!/usr/bin/env python3
"""Prints omniloc results in a paper's table layout, each published row beside the runs that reproduce it.

usage: paper_table.py RESULTS... --paper KEY [--rows LABEL ...] [--profile NAME] [--markdown]

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
import argparse
import json
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import omniloc_results as R  # noqa: E402
import paper_claims as C  # noqa: E402

SHORT = ["mean x", "mean y", "mean th", "std x", "std y", "std th", "max x", "max y", "max th"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", nargs="+")
    ap.add_argument("--paper", required=True, help="a table key of results/reference/papers.json")
    ap.add_argument("--rows", nargs="+", metavar="LABEL", help="only these rows (published or extra row labels)")
    ap.add_argument("--profile", help="noise profile of the runs to pair (default: read from the runs)")
    ap.add_argument("--markdown", action="store_true")
    ap.add_argument("--accept-incomplete", action="store_true", help="use sweep folders whose aggregate is not final (said in the output)")
    a = ap.parse_args()
    papers = R.load_papers()
    tables = error_tables(papers)
    published = [k for k in papers if k not in ("comment", "claims")]
    if a.paper == "list":
        print("\n".join(published))
        return 0
    if a.paper not in published + ["all"]:
        print(f"error: no published table \"{a.paper}\" in papers.json; tables: {', '.join(published)}", file=sys.stderr)
        return 2
    try:
        runs, _, experiments = R.discover(a.results, a.accept_incomplete)
    except SystemExit as e:
        print(f"error: cannot read results: {e}", file=sys.stderr)
        return 2
    profile, how = choose_profile(runs, a.profile)
    if profile is None:
        print(f"error: {how}", file=sys.stderr)
        return 2
    with R.pairing_profile(profile):
        for key in (published if a.paper == "all" else [a.paper]):
            if key in tables:
                code = print_error_table(papers, key, runs, a.rows, a.markdown)
            else:
                code = print_other_table(papers, key, runs, experiments, a.markdown)
            if code:
                return code
    print(f"noise profile: {profile} ({how})")
    for d in R.INCOMPLETE:
        print(f"note: {d} is an incomplete sweep (--accept-incomplete): only its finished runs are in these tables")
    return 0


def error_tables(papers):
    return [k for k, v in papers.items() if isinstance(v, dict) and "columns" in v and "reproduced_by" in v and isinstance(v.get("rows"), dict)
            and len(v.get("columns", [])) == len(R.TABLE_KEYS)]


def profile_of(run):
    found, prof = R.pointer(run.config, "/noise_profile")
    return prof if found else R.SCENARIO_DEFAULT_PROFILE


def choose_profile(runs, wanted):
    """(profile, how it was chosen) or (None, error): robot where the runs have it, else their one profile."""
    have = sorted({profile_of(r) for r in runs})
    if wanted:
        return wanted, "--profile" + ("" if wanted in have else f"; no runs of it here (the runs have: {', '.join(have) or 'none'})")
    if not have or R.SCENARIO_DEFAULT_PROFILE in have:
        return R.SCENARIO_DEFAULT_PROFILE, "the default" + (f"; the runs also have {', '.join(p for p in have if p != 'robot')}: --profile picks one"
                                                           if len(have) > 1 else "")
    if len(have) == 1:
        return have[0], "read from the runs"
    return None, f"the runs have several noise profiles ({', '.join(have)}) and none is robot: name one with --profile"


def print_other_table(papers, key, runs, experiments, markdown):
    """A kidnap, timing or experiment table, as the report shows it (scripts/report.py's section
    functions, written as text): one implementation of each table."""
    import report
    ctx = C.Context(papers, runs, experiments)
    anchor = "kidnapping" if key in ("002_kidnapping", "000_kidnapping") else key
    rep = report.TextReport(only=anchor, markdown=markdown)
    report.published_tables(rep, papers, ctx)
    if not rep.printed:  # a published record without a table of its own (e.g. real-robot numbers)
        t = papers[key]
        print(f"{key}: " + (json.dumps(t) if not isinstance(t, dict) else "; ".join(f"{k}: {v}" for k, v in t.items() if k != "reproduced_by")))
        print("not reproduced by a run or an experiment (see the report's scorecard)")
    print()
    return 0


def report_command(cmd):
    import report
    return report.command(cmd)  # under field_robot: the field_robot suite's command


def print_error_table(papers, key, runs, labels, markdown):
    try:
        rows = C.pair_table(papers, key, runs, labels)
    except KeyError as e:
        print(f"error: {e.args[0]}", file=sys.stderr)
        return 2
    cov, cov_head = C.table_coverage(rows)
    head = ["row", "source"] + cov_head + SHORT + ["line points / frame", "seeds"]
    lines, notes = [], []
    for p in rows:
        st = p["stats"]
        if p["runs"]:
            lines.append([p["shown"] + (" (tracking phase)" if p["phased"] else ""), "omniloc"] + C.row_cells(st, cov, p["runs"]))
        else:
            lines.append([p["label"], "not run"] + ["-"] * (len(cov) + 9) + ["-", "0"])
            notes.append(f"not run: {p['label']} ({R.describe_key(p['key'])}); run: {report_command(p['command'])}")
        for peer in p["peers"]:  # external localizers (docs/protocol.md) on the same scenario, configuration and start pose
            lines.append([peer["row"], f"external: {peer['name']}"] + C.row_cells(peer["stats"], cov, peer["runs"]))
        if p["published"]:
            lines.append([p["label"], "paper"] + ["-"] * len(cov) + [f"{v:.3f}" for v in p["published"]] + ["-", "-"])
            if p["runs"]:
                mean = lambda m: st[m]["mean"]
                lines.append([p["label"], "ours/paper"] + [""] * len(cov) + [f"{mean(f'{c}/{s}') / v:.2f}" if v and mean(f"{c}/{s}") is not None else "-"
                                                                            for (c, s), v in zip(R.TABLE_KEYS, p["published"])] + ["", ""])
    if markdown:
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for l in lines:
            print("| " + " | ".join(l) + " |")
    else:
        w = [max(len(x[i]) for x in [head] + lines) for i in range(len(head))]
        for l in [head] + lines:
            print("  ".join(x.ljust(w[i]) if i < 2 else x.rjust(w[i]) for i, x in enumerate(l)))
    for n in notes:
        print(n)
    print(f"\nunits: x, y in cm, th in rad; paper: {papers[key]['source']}"
          + ("; ours: errors over the frames answered, " + ", ".join(
              f"'{h}': share of all frames " + ("within that threshold (a frame without an estimate counts as outside)" if h != "answered" else "with an estimate")
              for h in cov_head) + ", means over seeds" if cov_head else "") + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
