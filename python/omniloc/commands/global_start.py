"""Global localisation from an unknown start, judged per run: the table of omniloc.global_start
(its docstring defines every column) for sweep or run folders, as JSON or markdown."""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import sys
from typing import Optional, Sequence

from omniloc import global_start
from omniloc.core import pathcheck


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog=os.environ.get("OMNILOC_GLOBAL_START_PROG", "python3 -m omniloc.commands.global_start"),
                                 description=(global_start.__doc__ or "").splitlines()[0])
    ap.add_argument("folders", nargs="+")
    ap.add_argument("--json", help="write the table (and the per-run figures) as JSON here")
    ap.add_argument("--markdown", action="store_true", help="print a Markdown table (default: JSON)")
    a = ap.parse_args(argv)
    prog = ap.prog
    try:
        if a.json is not None:
            pathcheck.require_writable(a.json, "--json", False)
        by = global_start.collect(a.folders)
    except pathcheck.PathError as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        return 2
    except SystemExit as e:  # discover(): a folder that is not one, an incomplete sweep
        if isinstance(e.code, str):
            print(f"{prog}: error: {e.code}", file=sys.stderr)
            return 2
        raise
    order = [loc for loc in ("mcl", "hybrid", "grid_global") if loc in by] + sorted(set(by) - {"mcl", "hybrid", "grid_global"})
    table = {loc: global_start.summarise([r for _, r in by[loc]]) for loc in order}
    summary = {loc: s.to_json() for loc, s in table.items()}
    per_run = {loc: [{"seed": seed, "recall": r.recall, "valid_fraction": r.valid_fraction, "first_within_s": r.first_within_s,
                      "ended_right": r.ended_right, "t_first_s": r.t_first, "wrong_frames": r.wrong_frames,
                      "outside_walls_frames": r.outside_walls_frames,
                      "outside_walls_any_frames": r.outside_walls_any_frames, "frames": r.frames}
                     for seed, r in sorted(by[loc], key=lambda x: x[0] or 0)] for loc in order}
    if a.json:
        pathlib.Path(a.json).write_text(json.dumps({"summary": summary, "runs": per_run}, indent=1) + "\n")
    if a.markdown:
        print(global_start.markdown(table))
        for loc in order:
            bad = [p["seed"] for p in per_run[loc] if not p["ended_right"]]
            print(f"\n{loc}: seeds not ending right: {bad if bad else 'none'}")
    else:
        print(json.dumps({"summary": summary, "runs": per_run}, indent=1))
    return 0



if __name__ == "__main__":
    sys.exit(main())
