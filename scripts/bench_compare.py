#!/usr/bin/env python3
"""Compares Google Benchmark JSON files against a stored baseline and flags slowdowns.

usage: bench_compare.py BASELINE_DIR NEW_DIR [--ratio 1.3] [--strict]

For every benchmark present in both (median aggregate when repetitions were run, else the single
result), prints new/baseline real-time ratios. Ratios above --ratio are flagged. CI machines are
noisy, so this is advisory: the exit code is 0 unless --strict is given and something is flagged.
Benchmarks are compared by name only within one run of this script; quote the ratios, not times.
"""
import argparse
import json
import pathlib
import sys


def medians(folder):
    out = {}
    for f in sorted(pathlib.Path(folder).glob("*.json")):
        try:
            data = json.loads(f.read_text())
        except (OSError, json.JSONDecodeError) as e:
            print(f"warning: cannot read {f}: {e}", file=sys.stderr)
            continue
        for b in data.get("benchmarks", []):
            if b.get("error_occurred"):
                continue
            agg = b.get("aggregate_name")
            if agg and agg != "median":
                continue
            name = b.get("run_name", b["name"])
            out[f"{f.stem}/{name}"] = (b["real_time"], b.get("time_unit", "ns"))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("baseline")
    ap.add_argument("new")
    ap.add_argument("--ratio", type=float, default=1.3)
    ap.add_argument("--strict", action="store_true")
    a = ap.parse_args()
    for d in (a.baseline, a.new):
        if not pathlib.Path(d).is_dir():
            print(f"error: {d} is not a folder of benchmark JSON", file=sys.stderr)
            return 2
    base, new = medians(a.baseline), medians(a.new)
    common = sorted(set(base) & set(new))
    if not common:
        print("no benchmark in common")
        return 0
    flagged = 0
    print(f"{'benchmark':60s} {'baseline':>12s} {'new':>12s} {'ratio':>7s}")
    for k in common:
        (b, ub), (n, un) = base[k], new[k]
        if ub != un:
            print(f"{k:60s} unit mismatch ({ub} vs {un})")
            continue
        r = n / b if b > 0 else float("inf")
        mark = "  SLOWER" if r > a.ratio else ""
        flagged += r > a.ratio
        print(f"{k:60s} {b:10.3f}{ub:>2s} {n:10.3f}{un:>2s} {r:7.2f}{mark}")
    print(f"{flagged} of {len(common)} benchmarks slower than {a.ratio}x the baseline (advisory)")
    return 1 if (a.strict and flagged) else 0


if __name__ == "__main__":
    sys.exit(main())
