"""The report's provenance section: which builds made the results, on what machine, when.
"""
from __future__ import annotations

import os
import pathlib
import platform
import time

from omniloc.core.jsonvalue import JSON, obj
from omniloc.core.rundir import Run
from omniloc.tools.markup import Cell, Writer


def cpu_model() -> str:
    """The CPU model of this machine (from /proc/cpuinfo; the platform's name elsewhere)."""
    try:
        for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine_text() -> str:
    return f"{cpu_model()}, {os.cpu_count()} cores, {platform.system()} {platform.machine()}"


def provenance(rep: Writer, runs: list[Run], sweeps: list[pathlib.Path]) -> None:
    """Which builds made the results, on what, when. summary.json's "omniloc" block names the build
    (version, compiler, build type) and, where the build records them, the machine (cpu, cores) and
    date; where it does not, the machine is the one that made this report (scripts/run.sh makes both
    on the same machine) and the date is the run files' modification time."""
    counts: dict[tuple[str, str, str, str], int] = {}
    dates: dict[tuple[str, str, str, str], set[str]] = {}
    for r in runs:
        o = dict(r.summary.omniloc)
        o.update(obj(o.get("host") or {}))  # the run's machine (summary.json omniloc.host: cpu, cores)
        date: JSON = o.get("date")
        when = str(date) if date else time.strftime("%Y-%m-%d", time.gmtime((r.folder / "summary.json").stat().st_mtime))
        k = (str(o.get("version", "unrecorded")), str(o.get("compiler", "-")), str(o.get("build_type", "-")),
             f"{o['cpu']}, {o.get('cores', '?')} cores" if o.get("cpu") else "this report's machine (below)")
        counts[k] = counts.get(k, 0) + 1
        dates.setdefault(k, set()).add(when)
    rep.heading("Provenance", 2, "provenance")
    # A row per build and machine: version, compiler, build type, machine, the runs' dates, how many.
    rows: list[list[Cell]] = [[*k, " to ".join(sorted({min(dates[k]), max(dates[k])})), counts[k]] for k in sorted(counts)]
    rep.table(["omniloc version (git describe)", "compiler", "build type", "machine", "runs dated (UTC)", "runs"], rows,
              f"Builds that made these results. This report: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} on {machine_text()}.")
    if len(counts) > 1:
        rep.para("Warning: the results come from more than one build; compare like with like (omniloc compare).")
