#!/usr/bin/env python3
"""Prints omniloc results in a paper's table layout, each published row beside the runs that reproduce it.

usage: paper_table.py RESULTS... --paper KEY [--rows LABEL ...] [--markdown]

RESULTS are run or sweep folders, or folders holding them (e.g. results/sweeps/paper_suite). KEY
names an error table of results/reference/papers.json: 002_table1_occlusion, 002_table2_lighting
or 000_tracking. Rows pair BY KEY: each published row in papers.json names its scenario,
localizer and configuration values ("reproduced_by"), and our runs are found by those, never by
their position in a sweep. --rows keeps only the named rows (published or extra). A row without
runs says "not run" and prints the command that runs it. Ours: mean over seeds (n shown); runs with
kidnaps or covers use their tracking phase. Only the published numbers come from papers.json.
External localizers (docs/protocol.md) found in RESULTS on a row's scenario and configuration are
printed beside it, named "external: <the client's name>".
"""
import argparse
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
    ap.add_argument("--markdown", action="store_true")
    ap.add_argument("--accept-incomplete", action="store_true", help="use sweep folders whose aggregate is not final (said in the output)")
    a = ap.parse_args()
    papers = R.load_papers()
    tables = [k for k, v in papers.items() if isinstance(v, dict) and "columns" in v and "reproduced_by" in v and isinstance(v.get("rows"), dict)]
    if a.paper not in tables:
        print(f"error: no error table \"{a.paper}\" in papers.json; tables: {', '.join(tables)}", file=sys.stderr)
        return 2
    try:
        runs, _, _ = R.discover(a.results, a.accept_incomplete)
        rows = C.pair_table(papers, a.paper, runs, a.rows)
    except KeyError as e:
        print(f"error: {e.args[0]}", file=sys.stderr)
        return 2
    except SystemExit as e:
        print(f"error: cannot read results: {e}", file=sys.stderr)
        return 2
    head = ["row", "source"] + SHORT + ["line points / frame", "seeds"]
    lines, notes = [], []
    for p in rows:
        st = p["stats"]
        if p["runs"]:
            lines.append([p["label"] + (" (tracking phase)" if p["phased"] else ""), "omniloc"] +
                         [f"{st[f'{c}/{s}']['mean']:.3f}" for c, s in R.TABLE_KEYS] + [f"{st['line_points/mean']['mean']:.0f}", str(st["x_cm/mean"]["n"])])
        else:
            lines.append([p["label"], "not run"] + ["-"] * 9 + ["-", "0"])
            notes.append(f"not run: {p['label']} ({R.describe_key(p['key'])}); run: {p['command']}")
        for peer in p["peers"]:  # external localizers (docs/protocol.md) on the same scenario and configuration
            pst = peer["stats"]
            lines.append([p["label"], f"external: {peer['name']}"] + [f"{pst[f'{c}/{s}']['mean']:.3f}" for c, s in R.TABLE_KEYS] +
                         [f"{pst['line_points/mean']['mean']:.0f}", str(pst["x_cm/mean"]["n"])])
        if p["published"]:
            lines.append([p["label"], "paper"] + [f"{v:.3f}" for v in p["published"]] + ["-", "-"])
            if p["runs"]:
                lines.append([p["label"], "ours/paper"] + [f"{st[f'{c}/{s}']['mean'] / v:.2f}" if v else "-"
                                                            for (c, s), v in zip(R.TABLE_KEYS, p["published"])] + ["", ""])
    if a.markdown:
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
    print(f"\nunits: x, y in cm, th in rad; paper: {papers[a.paper]['source']}")
    for d in R.INCOMPLETE:
        print(f"note: {d} is an incomplete sweep (--accept-incomplete): only its finished runs are in this table")
    return 0


if __name__ == "__main__":
    sys.exit(main())
