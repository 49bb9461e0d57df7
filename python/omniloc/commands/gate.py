"""`omniloc gate`: the command line of omniloc.gate, whose docstring is this command's help."""
from __future__ import annotations

import argparse
import json
import sys
import os
from typing import Optional, Sequence

from omniloc import compare, gate
from omniloc.core import pathcheck


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog=os.environ.get("OMNILOC_GATE_PROG", "python3 -m omniloc.commands.gate"), description=gate.__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", help="sweep or run folder(s) with final results (the candidate)")
    ap.add_argument("--rules", required=True, help="rules file (JSON, docs/ci.md)")
    ap.add_argument("--baseline", help="result folder to compare with: a metric regresses when worse beyond the seed spread and the tolerance")
    ap.add_argument("--alpha", type=float, default=gate.ALPHA, help="significance level of the regression test (default 0.05)")
    ap.add_argument("--junit", help="write JUnit XML here")
    ap.add_argument("--benchmark-json", help="write github-action-benchmark's customSmallerIsBetter JSON here")
    try:
        a = ap.parse_args(argv)
    except SystemExit as e:
        return 0 if e.code == 0 else 2
    try:
        if not 0 < a.alpha < 1:
            raise gate.BadInput(f"--alpha: got {a.alpha:g}, expected a number in (0, 1)")
        for option, out in (("--junit", a.junit), ("--benchmark-json", a.benchmark_json)):
            why = pathcheck.why_not_writable(out, False) if out is not None else None
            if why:
                raise gate.BadInput(f"{option} {pathcheck.shown(out)}: {why}")
        rules = gate.load_rules(a.rules, a.baseline is not None)
        runs = gate.load_runs(a.results, "results")
        base = gate.load_runs(a.baseline, "baseline") if a.baseline else None
        checks = gate.judge(rules, runs, base, a.alpha)
    except gate.BadInput as e:
        print(f"gate: error: {e}", file=sys.stderr)
        return 2
    print(f"results: {a.results}: {len(runs)} runs, omniloc {compare.versions(runs)}")
    if base is not None:
        print(f"baseline: {a.baseline}: {len(base)} runs, omniloc {compare.versions(base)}")
    for c in checks:
        print(gate.line(c))
    failed = sum(1 for c in checks if c.failures)
    if a.junit:
        gate.write_atomic(a.junit, gate.junit_xml(checks, a.results, a.baseline))
    if a.benchmark_json:
        entries, left = gate.benchmark_json(checks)
        gate.write_atomic(a.benchmark_json, json.dumps(entries, indent=2) + "\n")
        higher = sum(1 for c in left if c.rule.better != "lower")
        if higher:
            print(f"note: {higher} check(s) where higher is better are not in {a.benchmark_json} (customSmallerIsBetter)")
        if len(left) > higher:
            print(f"note: {len(left) - higher} check(s) without a value (no estimate) are not in {a.benchmark_json}")
    print(f"gate: {len(checks) - failed} of {len(checks)} checks passed" + (f", {failed} failed" if failed else ""))
    return 1 if failed else 0



if __name__ == "__main__":
    sys.exit(main())
