#!/usr/bin/env python3
"""Prints omniloc results in the papers' table layout next to the published rows.

usage: paper_table.py RESULT --paper KEY [--rows LABEL=PUBLISHED_ROW ...] [--markdown]

RESULT is a run folder (summary.json) or a sweep folder (aggregate.json; one row per group, in the
sweep's order). KEY names a table in results/reference/papers.json (e.g. 002_table1_occlusion).
--rows maps our rows, in order, to the published row names (default: the paper's rows in order).
Only the published numbers come from papers.json; every other number is read from the results.
"""
import argparse
import json
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
KEYS = [("x_cm", "mean"), ("y_cm", "mean"), ("theta_rad", "mean"), ("x_cm", "std"), ("y_cm", "std"), ("theta_rad", "std"),
        ("x_cm", "max"), ("y_cm", "max"), ("theta_rad", "max")]


def ours(folder):
    folder = pathlib.Path(folder)
    if (folder / "aggregate.json").exists():
        agg = json.loads((folder / "aggregate.json").read_text())
        rows = []
        for g in agg["groups"]:
            m = g["metrics"]
            vals = [m.get(f"r0/{a}/{s}", {}).get("mean", float("nan")) for a, s in KEYS]
            pts = m.get("r0/line_points/mean", {}).get("mean", float("nan"))
            rows.append((g["params"], vals, pts))
        return rows
    s = json.loads((folder / "summary.json").read_text())
    r = s["robots"][0]
    return [(s["scenario"], [r[a][st] for a, st in KEYS], r.get("line_points", {}).get("mean", float("nan")))]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("result")
    ap.add_argument("--paper", required=True)
    ap.add_argument("--labels", nargs="*", help="published row names for our rows, in order")
    ap.add_argument("--markdown", action="store_true")
    a = ap.parse_args()
    papers = json.loads((ROOT / "results/reference/papers.json").read_text())
    if a.paper not in papers:
        print(f"error: no table {a.paper} in papers.json", file=sys.stderr)
        return 2
    pub = papers[a.paper]["rows"]
    try:
        rows = ours(a.result)
    except (OSError, KeyError, json.JSONDecodeError) as e:
        print(f"error: cannot read results in {a.result}: {e}", file=sys.stderr)
        return 2
    labels = a.labels or list(pub.keys())
    head = ["case", "source"] + [f"{s} {c}" for c, s in [("x", "mean"), ("y", "mean"), ("th", "mean"), ("x", "std"), ("y", "std"),
                                                          ("th", "std"), ("x", "max"), ("y", "max"), ("th", "max")]] + ["line points / frame"]
    lines = []
    for i, (name, vals, pts) in enumerate(rows):
        label = labels[i] if i < len(labels) else name
        lines.append([label, "omniloc"] + [f"{v:.3f}" for v in vals] + [f"{pts:.0f}"])
        if label in pub:
            lines.append([label, "paper"] + [f"{v:.3f}" for v in pub[label]] + ["-"])
    if a.markdown:
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for l in lines:
            print("| " + " | ".join(l) + " |")
    else:
        w = [max(len(x[i]) for x in [head] + lines) for i in range(len(head))]
        for l in [head] + lines:
            print("  ".join(x.rjust(w[i]) for i, x in enumerate(l)))
    print(f"\nunits: x, y in cm, th in rad; paper: {papers[a.paper]['source']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
