"""The error CDF and the timing per stage, per localizer and noise profile (never pooled across profiles).
"""
from __future__ import annotations

import statistics
from typing import Any

from omniloc.core import metrics as M
from omniloc.core import stats as ST
from omniloc.core.pairing import profile_of
from omniloc.core.stats import fnum
from omniloc.report.provenance import machine_text
from omniloc.tools import plot
from omniloc.core.rundir import Run
from omniloc.tools.markup import Writer


def tracking_errors(run: Run, counts: Any = None) -> Any:
    """Position errors (m) of the valid frames of the tracking phase (outside the excluded intervals).
    `counts`, a dict, receives "frames": every tracking-phase frame, answered or not."""
    excl = {}
    for r in run.summary.get("robots", []):
        excl[str(r.get("robot"))] = (r.get("tracking_phase") or {}).get("excluded", [])
    out, total = [], 0
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


def pooled_coverage(runs: list[Run], key: Any) -> Any:
    """(recall at threshold `key`, share answered) pooled over every robot's tracking-phase frames
    of the runs, from their summary.json (recall x frames_total summed); None where unknown."""
    within = answered = total = 0.0
    for run in runs:
        for r in run.summary.get("robots", []):
            b = r.get("tracking_phase") if isinstance(r.get("tracking_phase"), dict) else r
            n = b.get("frames_total")
            if not ST.is_number(n) or not n:
                continue
            rec, vf = (b.get("recall") or {}).get(key), b.get("valid_fraction")
            if not (ST.is_number(rec) and ST.is_number(vf)):
                continue
            within, answered, total = within + rec * n, answered + vf * n, total + n
    return (within / total, answered / total) if total else (None, None)


def cdf_and_timing(rep: Writer, runs: list[Run]) -> None:
    """Error CDF and timing per localizer AND noise profile: frames of robot and
    field_robot runs are never pooled into one curve, row or bar; every row names its profile and
    how many runs its frames come from."""
    errs: dict[tuple[str, str], list[float]]
    timing: dict[tuple[str, str], dict[str, list[float]]]
    nruns: dict[tuple[str, str], int]
    frames: dict[tuple[str, str], dict[str, int]]
    by_key: dict[tuple[str, str], list[Run]]
    errs, timing, nruns, frames, by_key = {}, {}, {}, {}, {}
    for run in runs:
        key = (run.localizer, profile_of(run))  # (localizer, noise profile)
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
    head = M.headline_key(runs)
    name = lambda key: f"{key[0]} ({key[1]} profile)"
    runs_text = lambda key: f"{nruns[key]} run{'s' if nruns[key] != 1 else ''}"
    apart = (f"Per localizer and noise profile ({', '.join(profiles)}): runs of different profiles are never pooled." if len(profiles) > 1
             else f"All runs here are of the {profiles[0]} profile." if profiles else "")
    if errs:
        rep.heading("Error CDF per localizer and noise profile (tracking phase)", 2)
        curve = lambda key, answered, n: f"{name(key)}: {answered} of {n} frames answered, {runs_text(key)}"
        rep.figure(plot.cdf_figure(errs, frames, profiles, curve), "cdf", "position error CDF over the reported runs' tracking phases (carried periods and recoveries left out), "
                   "one curve per localizer and noise profile (line style: profile), over all their frames: a frame without an estimate "
                   "counts as never within, so each curve levels off at the share of frames answered. " + apart)
        q = lambda e, f: fnum(sorted(e)[int(f * (len(e) - 1))], 4) if e else M.NO_ESTIMATE
        cov = {key: pooled_coverage(by_key[key], head) if head else (None, None) for key in errs}
        rep.table(["localizer", "profile", "runs"] + ([f"within {M.recall_label(head)}", "answered"] if head else []) + ["frames", "median m", "p90 m", "p99 m"],
                  [[key[0], key[1], nruns[key]] + ([M.percent(cov[key][0]), M.percent(cov[key][1])] if head else []) +
                   [len(e), fnum(statistics.median(e), 4) if e else M.NO_ESTIMATE, q(e, 0.9), q(e, 0.99)] for key, e in sorted(errs.items())],
                  ("Coverage first: the share of all tracking-phase frames within the headline threshold (a frame without an estimate "
                   "counts as outside) and the share answered, pooled over the localizer's runs; then " if head else "")
                  + "the errors of the valid (answered) tracking-phase frames pooled over the localizer's runs (seeds and scenarios) under that one profile. " + apart)
    if timing:
        rep.heading("Timing per stage, per localizer and noise profile", 2)
        rows = []
        for key, d in sorted(timing.items()):
            rows.append([key[0], key[1], nruns[key]] + [fnum(statistics.median(v), 3) if v else "-" for v in d.values()] + [len(d["render_ms"])])
        rep.table(["localizer", "profile", "runs", "render ms (median)", "vision ms", "localize ms", "client's own ms", "frames"], rows,
                  f"wall time per frame on {machine_text()}; runs in a sweep share the cores. " + apart + " "
                  "For an external localizer (docs/protocol.md) 'localize' is the protocol's round trip: frame sent to estimate read, "
                  "the client's own computation included; 'client's own ms' is the time the client reported for its computation "
                  "(estimate.compute_ms; '-' where it reports none, and for the built-in localizers, whose 'localize' is their computation)")
        rep.figure(plot.timing_figure(timing, statistics.median), "timing", "median time per frame and stage, per localizer and noise profile (under each bar)")
