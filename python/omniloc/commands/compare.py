"""`omniloc compare`: the command line of omniloc.compare, whose docstring is this command's help."""
from __future__ import annotations

import argparse
import os
import sys
from typing import Optional, Sequence

from omniloc import compare
from omniloc.core import rundir


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog=os.environ.get("OMNILOC_COMPARE_PROG", "python3 -m omniloc.commands.compare"), description=compare.__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--markdown", action="store_true", help="a markdown table instead of aligned text")
    ap.add_argument("--alpha", type=float, default=compare.ALPHA, help="significance level of the t-test (default 0.05)")
    ap.add_argument("--accept-incomplete", action="store_true", help="use sweep folders whose aggregate is not final (said in the output)")
    a = ap.parse_args(argv)
    if not 0 < a.alpha < 1:
        ap.error("--alpha must lie in (0, 1)")
    try:
        ra, _, _ = rundir.discover([a.a], a.accept_incomplete)
        rb, _, _ = rundir.discover([a.b], a.accept_incomplete)
        for d in rundir.INCOMPLETE:
            print(f"note: {d} is an incomplete sweep; only its finished runs are compared")
    except SystemExit as e:
        print(f"compare: {e}", file=sys.stderr)
        return 2
    for name, rs in ((a.a, ra), (a.b, rb)):
        if not rs:
            print(f"compare: no runs (summary.json) under {name}", file=sys.stderr)
            return 2
    print(f"A: {a.a}: {len(ra)} runs, omniloc {compare.versions(ra)}")
    print(f"B: {a.b}: {len(rb)} runs, omniloc {compare.versions(rb)}")
    if a.markdown:
        header, rows = compare.compare_rows(ra, rb, a.alpha)
        print("| " + " | ".join(header) + " |")
        print("|" + "---|" * len(header))
        for r in rows:
            print("| " + " | ".join(str(c) for c in r) + " |")
        print("\n" + compare.explanation(ra + rb))
    else:
        print()
        compare.print_text(ra, rb, a.alpha)
    return 0



if __name__ == "__main__":
    sys.exit(main())
