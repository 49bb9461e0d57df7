"""The error CDF and the timing per stage, per localizer and noise profile (never pooled across profiles).
"""
from __future__ import annotations

import statistics
from typing import Optional

from omniloc.core import metrics, stats
from omniloc.core.jsonvalue import lst, numbers, obj
from omniloc.core.pairing import profile_of
from omniloc.core.rundir import Run
from omniloc.core.stats import fnum
from omniloc.report.provenance import machine_text
from omniloc.tools import plot
from omniloc.tools.markup import Cell, Writer

# (localizer, noise profile): what the CDF and the timing are per.
Key = tuple[str, str]


def tracking_errors(run: Run, counts: Optional[dict[str, int]] = None) -> list[float]:
    """Position errors (m) of the valid frames of the tracking phase (outside the excluded intervals).
    `counts`, a dict, receives "frames": every tracking-phase frame, answered or not."""
    excl: dict[str, list[list[float]]] = {}
    for r in run.summary.robots:
        excl[str(r.get("robot"))] = [numbers(iv) or [] for iv in lst(obj(r.get("tracking_phase") or {}).get("excluded", []))]
    out: list[float] = []
    total = 0
    for f in run.frames():
        if f.get("err_pos") in (None, ""):  # no truth: not scored
            continue
        t = float(f["t"])
        if any(a - 1e-9 <= t < b - 1e-9 for a, b in excl.get(f["robot"], [])):
            continue
        total += 1
        if f["valid"] != "1":
            continue
        out.append(float(f["err_pos"]))
    if counts is not None:
        counts["frames"] = counts.get("frames", 0) + total
    return out


def pooled_coverage(runs: list[Run], key: str) -> tuple[Optional[float], Optional[float]]:
    """(recall at threshold `key`, share answered) pooled over every robot's tracking-phase frames
    of the runs, from their summary.json (recall x frames_total summed); None where unknown."""
    within = answered = total = 0.0
    for run in runs:
        for r in run.summary.robots:
            tp = r.get("tracking_phase")
            b = tp if isinstance(tp, dict) else r
            n = b.get("frames_total")
            if not stats.is_number(n) or not n:
                continue
            rec, vf = obj(b.get("recall") or {}).get(key), b.get("valid_fraction")
            if not (stats.is_number(rec) and stats.is_number(vf)):
                continue
            within, answered, total = within + rec * n, answered + vf * n, total + n
    return (within / total, answered / total) if total else (None, None)


def cdf_and_timing(rep: Writer, runs: list[Run]) -> None:
    """Error CDF and timing per localizer AND noise profile: frames of robot and
    field_robot runs are never pooled into one curve, row or bar; every row names its profile and
    how many runs its frames come from."""
    errs: dict[Key, list[float]] = {}
    timing: dict[Key, dict[str, list[float]]] = {}
    nruns: dict[Key, int] = {}
    frames: dict[Key, dict[str, int]] = {}
    by_key: dict[Key, list[Run]] = {}
    for run in runs:
        key = (str(run.localizer), profile_of(run))  # (localizer, noise profile)
        nruns[key] = nruns.get(key, 0) + 1
        by_key.setdefault(key, []).append(run)
        errs.setdefault(key, []).extend(tracking_errors(run, frames.setdefault(key, {})))
        for r in run.timing():
            d = timing.setdefault(key, {"render_ms": [], "vision_ms": [], "localize_ms": [], "compute_ms": []})
            for k in d:
                if r.get(k) not in (None, ""):  # compute_ms: only an external client that reports its own time
                    d[k].append(float(r[k]))
    # A localizer that answered no frame stays in the table ("no estimate"); it has no curve.
    errs = {k: v for k, v in errs.items() if v or frames[k].get("frames")}
    profiles = sorted({p for _, p in list(errs) + list(timing)})
    head = metrics.headline_key(runs)

    def name(key: Key) -> str:
        return f"{key[0]} ({key[1]} profile)"

    def runs_text(key: Key) -> str:
        return f"{nruns[key]} run{'s' if nruns[key] != 1 else ''}"
    apart = (f"Per localizer and noise profile ({', '.join(profiles)}): runs of different profiles are never pooled." if len(profiles) > 1
             else f"All runs here are of the {profiles[0]} profile." if profiles else "")
    if errs:
        rep.heading("Error CDF per localizer and noise profile (tracking phase)", 2)

        def curve(key: Key, answered: int, n: int) -> str:
            return f"{name(key)}: {answered} of {n} frames answered, {runs_text(key)}"
        rep.figure(plot.cdf_figure(errs, frames, profiles, curve), "cdf", "position error CDF over the reported runs' tracking phases (carried periods and recoveries left out), "
                   "one curve per localizer and noise profile (line style: profile), over all their frames: a frame without an estimate "
                   "counts as never within, so each curve levels off at the share of frames answered. " + apart)

        def q(e: list[float], f: float) -> str:
            return fnum(sorted(e)[int(f * (len(e) - 1))], 4) if e else metrics.NO_ESTIMATE
        cov = {key: pooled_coverage(by_key[key], head) if head else (None, None) for key in errs}
        table: list[list[Cell]] = [[key[0], key[1], nruns[key], *([metrics.percent(cov[key][0]), metrics.percent(cov[key][1])] if head else []),
                                    len(e), fnum(statistics.median(e), 4) if e else metrics.NO_ESTIMATE, q(e, 0.9), q(e, 0.99)]
                                   for key, e in sorted(errs.items())]
        rep.table(["localizer", "profile", "runs"] + ([f"within {metrics.recall_label(head)}", "answered"] if head else []) + ["frames", "median m", "p90 m", "p99 m"],
                  table,
                  ("Coverage first: the share of all tracking-phase frames within the headline threshold (a frame without an estimate "
                   "counts as outside) and the share answered, pooled over the localizer's runs; then " if head else "")
                  + "the errors of the valid (answered) tracking-phase frames pooled over the localizer's runs (seeds and scenarios) under that one profile. " + apart)
    if timing:
        rep.heading("Timing per stage, per localizer and noise profile", 2)
        rows: list[list[Cell]] = []
        for key, d in sorted(timing.items()):
            rows.append([key[0], key[1], nruns[key], *[fnum(statistics.median(v), 3) if v else "-" for v in d.values()], len(d["render_ms"])])
        rep.table(["localizer", "profile", "runs", "render ms (median)", "vision ms", "localize ms", "client's own ms", "frames"], rows,
                  f"wall time per frame on {machine_text()}; runs in a sweep share the cores. " + apart + " "
                  "For an external localizer (docs/protocol.md) 'localize' is the protocol's round trip: frame sent to estimate read, "
                  "the client's own computation included; 'client's own ms' is the time the client reported for its computation "
                  "(estimate.compute_ms; '-' where it reports none, and for the built-in localizers, whose 'localize' is their computation)")
        rep.figure(plot.timing_figure(timing, statistics.median), "timing", "median time per frame and stage, per localizer and noise profile (under each bar)")
