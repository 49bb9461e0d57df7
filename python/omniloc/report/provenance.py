"""The report's provenance section: which builds made the results, on what machine, when.
"""
from __future__ import annotations

import os
import pathlib
import platform
import time
from typing import Any

from omniloc.core.rundir import Run
from omniloc.tools.markup import Writer


def cpu_model() -> Any:
    """The CPU model of this machine (from /proc/cpuinfo; the platform's name elsewhere)."""
    try:
        for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine_text() -> Any:
    return f"{cpu_model()}, {os.cpu_count()} cores, {platform.system()} {platform.machine()}"


def provenance(rep: Writer, runs: list[Run], sweeps: list[Any]) -> None:
    """Which builds made the results, on what, when. summary.json's "omniloc" block names the build
    (version, compiler, build type) and, where the build records them, the machine (cpu, cores) and
    date; where it does not, the machine is the one that made this report (scripts/run.sh makes both
    on the same machine) and the date is the run files' modification time."""
    versions: dict[Any, Any] = {}
    for r in runs:
        o = dict(r.summary.get("omniloc") or {})
        o.update(o.get("host") or {})  # the run's machine (summary.json omniloc.host: cpu, cores)
        when = o.get("date") or time.strftime("%Y-%m-%d", time.gmtime((r.folder / "summary.json").stat().st_mtime))
        k = (o.get("version", "unrecorded"), o.get("compiler", "-"), o.get("build_type", "-"),
             f"{o['cpu']}, {o.get('cores', '?')} cores" if o.get("cpu") else "this report's machine (below)")
        d = versions.setdefault(k, {"n": 0, "dates": set()})
        d["n"] += 1
        d["dates"].add(when)
    rep.heading("Provenance", 2, "provenance")
    rows = [[v, c, b, m, " to ".join(sorted({min(d["dates"]), max(d["dates"])})), d["n"]] for (v, c, b, m), d in sorted(versions.items())]
    rep.table(["omniloc version (git describe)", "compiler", "build type", "machine", "runs dated (UTC)", "runs"], rows,
              f"Builds that made these results. This report: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} on {machine_text()}.")
    if len(versions) > 1:
        rep.para("Warning: the results come from more than one build; compare like with like (omniloc compare).")
