#!/usr/bin/env python3
"""Two result sets side by side per metric: the difference and whether it exceeds the seed-to-seed spread.

usage: compare.py A B [--markdown] [--alpha P] [--all-metrics]
       omniloc compare A B ...     (the same)

A and B are result folders (runs, sweeps, or folders holding them), e.g. the paper suite of two
commits. Runs are grouped by scenario, localizer and effective configuration (config.json without
the seed and the run's name): the same condition on both sides pairs BY KEY, whatever folder or
position a run has. Per group and metric: mean over seeds of A and of B (n each), B - A, and
Welch's unequal-variance t-test over the seeds; "yes" where p < alpha (default 0.05), i.e. the
difference exceeds the seed-to-seed spread. With fewer than two seeds on a side there is no spread
to compare with, and the difference is shown alone ("n < 2"). Identical numbers give "same".
Exit code 0; 2 on bad arguments or folders without results.
"""
import argparse
import json
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import omniloc_results as R  # noqa: E402

METRICS = ["x_cm/mean", "y_cm/mean", "theta_rad/mean", "position_m/rmse", "position_m/p95", "line_points/mean", "wrong_frames",
           "coasting_frames", "recovery/recovered", "recovery/recovery_time_s/median"]
EXPLANATION = ("Runs pair by scenario, localizer and effective configuration (not by folder or position); numbers are robot 0's, "
               "tracking phase where a run has one. 'exceeds spread': Welch's t-test over seeds, p < alpha; n < 2: no spread to compare with.")
ALPHA = 0.05


def group_key(run):
    cfg = dict(run.config)
    cfg.pop("seed", None)
    cfg.pop("name", None)
    return (run.scenario, run.localizer, json.dumps(cfg, sort_keys=True))


def flatten(obj, prefix=""):
    out = {}
    if isinstance(obj, dict):
        for k, v in obj.items():
            out.update(flatten(v, f"{prefix}/{k}"))
    elif isinstance(obj, list) and obj and all(isinstance(v, dict) for v in obj):
        for i, v in enumerate(obj):
            out.update(flatten(v, f"{prefix}/{i}"))
    else:
        out[prefix] = json.dumps(obj, separators=(",", ":"))
    return out


def labels(keys):
    """'scenario / localizer', plus the configuration values that tell apart conditions sharing both."""
    by = {}
    for k in keys:
        by.setdefault(k[:2], []).append(k)
    out = {}
    for sl, ks in by.items():
        flat = {k: flatten(json.loads(k[2])) for k in ks}
        ptrs = sorted({p for f in flat.values() for p in f if len({f.get(p) for f in flat.values()}) > 1})
        for k in ks:
            extra = ", ".join(f"{p}={flat[k].get(p, '-')}" for p in ptrs[:3]) + (" ..." if len(ptrs) > 3 else "")
            out[k] = f"{sl[0]} / {sl[1]}" + (f" / {extra}" if extra else "")
    return out


def groups(runs):
    g = {}
    for r in runs:
        g.setdefault(group_key(r), []).append(r)
    return g


def verdict(w, a, b, alpha):
    if w["diff"] is None:
        return "-"
    if all(x == y for x, y in zip(sorted(a), sorted(b))) and len(a) == len(b):
        return "same"
    if w["p"] is None:
        return "n < 2"
    return "yes" if w["p"] < alpha else "no"


def compare_rows(runs_a, runs_b, alpha=ALPHA, metrics=METRICS):
    ga, gb = groups(runs_a), groups(runs_b)
    keys = sorted(set(ga) & set(gb))
    # A condition whose configuration changed between the two sets still pairs by scenario and
    # localizer when that is unambiguous on both sides, marked "config differs".
    loose_a = {k[:2]: k for k in ga if k not in gb}
    loose_b = {k[:2]: k for k in gb if k not in ga}
    pairs = [(k, k, "") for k in keys]
    for sl, ka in loose_a.items():
        if sl in loose_b and sum(1 for k in ga if k[:2] == sl) == 1 and sum(1 for k in gb if k[:2] == sl) == 1:
            pairs.append((ka, loose_b[sl], " (config differs)"))
    names = labels(set(ga) | set(gb))
    header = ["scenario / localizer / differing configuration", "metric", "A mean", "n", "B mean", "n", "B - A", "p (Welch)", "exceeds spread"]
    rows = []
    for ka, kb, note in sorted(pairs, key=lambda p: p[0][:2]):
        label = names[ka] + note
        for m in metrics:
            a = [r.metric(m) for r in ga[ka]]
            b = [r.metric(m) for r in gb[kb]]
            a = [x for x in a if isinstance(x, (int, float))]
            b = [x for x in b if isinstance(x, (int, float))]
            if not a and not b:
                continue
            sa, sb, w = R.stats(a), R.stats(b), R.welch(a, b)
            rows.append([label, m, R.fnum(sa["mean"], 4), sa["n"], R.fnum(sb["mean"], 4), sb["n"],
                         R.fnum(w["diff"], 4), R.fnum(w["p"], 3) if w["p"] is not None else "-", verdict(w, a, b, alpha)])
    only_a = sorted(set(ga) - {p[0] for p in pairs})
    only_b = sorted(set(gb) - {p[1] for p in pairs})
    for k in only_a:
        rows.append([names[k], "(only in A)", "", len(ga[k]), "", "", "", "", ""])
    for k in only_b:
        rows.append([names[k], "(only in B)", "", "", "", len(gb[k]), "", "", ""])
    return header, rows


def versions(runs):
    v = {}
    for r in runs:
        v[r.version] = v.get(r.version, 0) + 1
    return ", ".join(f"{k} ({n} runs)" for k, n in sorted(v.items()))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--markdown", action="store_true", help="a markdown table instead of aligned text")
    ap.add_argument("--alpha", type=float, default=ALPHA, help="significance level of the t-test (default 0.05)")
    ap.add_argument("--accept-incomplete", action="store_true", help="use sweep folders whose aggregate is not final (said in the output)")
    a = ap.parse_args()
    if not 0 < a.alpha < 1:
        ap.error("--alpha must lie in (0, 1)")
    try:
        ra, _, _ = R.discover([a.a], a.accept_incomplete)
        rb, _, _ = R.discover([a.b], a.accept_incomplete)
        for d in R.INCOMPLETE:
            print(f"note: {d} is an incomplete sweep; only its finished runs are compared")
    except SystemExit as e:
        print(f"compare: {e}", file=sys.stderr)
        return 2
    for name, rs in ((a.a, ra), (a.b, rb)):
        if not rs:
            print(f"compare: no runs (summary.json) under {name}", file=sys.stderr)
            return 2
    header, rows = compare_rows(ra, rb, a.alpha)
    print(f"A: {a.a}: {len(ra)} runs, omniloc {versions(ra)}")
    print(f"B: {a.b}: {len(rb)} runs, omniloc {versions(rb)}")
    if a.markdown:
        print("| " + " | ".join(header) + " |")
        print("|" + "---|" * len(header))
        for r in rows:
            print("| " + " | ".join(str(c) for c in r) + " |")
    else:
        cells = [header] + [[str(c) for c in r] for r in rows]
        w = [max(len(r[i]) for r in cells) for i in range(len(header))]
        for r in cells:
            print("  ".join(c.ljust(w[i]) if i < 2 else c.rjust(w[i]) for i, c in enumerate(r)))
    print("\n" + EXPLANATION)
    return 0


if __name__ == "__main__":
    sys.exit(main())
