"""The developers' page: instruction counts and benchmark wall times per workload over the commits.
"""
from __future__ import annotations

import pathlib
from typing import Callable, Optional, Union

from omniloc.core import paths
from omniloc.core.files import read_json_lines
from omniloc.core.jsonvalue import JSON, obj
from omniloc.core.stats import fnum
from omniloc.tools import plot
from omniloc.tools.markup import Cell, Writer


def load_jsonl(path: pathlib.Path) -> list[dict[str, JSON]]:
    """The records of a history file (icount.jsonl, bench.jsonl): every line that is a JSON object; a
    line cut by an interrupted append does not hide the others."""
    return [r for r in read_json_lines(path) if isinstance(r, dict)]


def history_plot(rep: Writer, records: list[dict[str, JSON]], field: str, key: str, ylabel: str, caption: str, fmt: Callable[[float], str]) -> None:
    """One line per workload: `field` of every record, relative to the workload's first record, in
    the order the records were appended (one point per measured commit)."""
    series: dict[str, list[tuple[int, float]]] = {}
    for i, rec in enumerate(records):
        for w, v in obj(rec.get(field, {})).items():
            if isinstance(v, (int, float)) and v > 0:
                series.setdefault(w, []).append((i, v))
    if not series:
        return
    rep.figure(plot.history_figure(series, records, ylabel), key, caption)
    rows: list[list[Cell]] = []
    for w, pts in sorted(series.items()):
        (i0, v0), (i1, v1) = pts[0], pts[-1]
        rows.append([w, str(records[i0].get("commit", "?")), fmt(v0), str(records[i1].get("commit", "?")), fmt(v1), fnum(v1 / v0, 3)])
    rep.table(["workload", "first commit", "first", "last commit", "last", "last / first"], rows)


def report_history(rep: Writer, folder: pathlib.Path, reference: Optional[Union[str, pathlib.Path]] = None) -> bool:
    """The developers' page: instruction counts and benchmark wall times over the commits; False
    (nothing written) where there are no records."""
    # The committed baseline history (one record per baseline change) first, then this machine's runs.
    reference = pathlib.Path(reference or paths.ROOT / "results" / "reference" / "icount_history.jsonl")
    icount = load_jsonl(reference) + load_jsonl(folder / "icount.jsonl")
    bench = load_jsonl(folder / "bench.jsonl")
    if not (icount or bench):
        return False
    rep.heading("Speed over commits", 2, "history")
    rep.para(f"From {reference} (committed baselines) and {folder} (this machine): every run of scripts/icount.sh and scripts/bench.sh appends its figures with the commit. "
             "Instruction counts (callgrind, fixed work) do not depend on the machine's load; wall times do, so compare "
             "wall times only between records measured in the same minutes.")
    if icount:
        history_plot(rep, icount, "instructions", "history_icount", "instructions / first record",
                     "instructions per workload (scripts/icount.sh), relative to each workload's first record",
                     lambda v: f"{v:,.0f}")
    if bench:
        history_plot(rep, bench, "real_time_ns", "history_bench", "median wall time / first record",
                     "Google Benchmark median wall time per benchmark (scripts/bench.sh), relative to its first record",
                     lambda v: f"{v:,.1f} ns")
    return True
