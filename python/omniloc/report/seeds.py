"""Few seeds: every seed's value beside the mean, intervals that say their method, outlying seeds with
their cause read from frames.csv and events.jsonl, and the strip plot of the seeds.
"""
from __future__ import annotations

import math
import statistics
from typing import Collection, Optional, Sequence

from omniloc.core import metrics, stats
from omniloc.core.bound import null_text, share_text
from omniloc.core.events import read_events
from omniloc.core.rundir import Run
from omniloc.core.stats import SeedStats, fnum
from omniloc.report import viewers
from omniloc.report.runs import run_title
from omniloc.tools import plot
from omniloc.tools.markup import Cell, Writer

# A row of a seed table: its label and its runs, sorted by seed.
RowRuns = tuple[str, list[Run]]


SEED_METRICS: list[tuple[str, str, int]] = [("x_cm/mean", "mean x cm", 2), ("y_cm/mean", "mean y cm", 2), ("theta_rad/mean", "mean th rad", 4)]


def coverage_cols(runs: list[Run]) -> list[tuple[str, str]]:
    """The coverage columns of a table of these runs, shown before its errors: [(metric, header)]
    for the recall at the runs' headline threshold and the share of frames answered, each where the
    runs record it (runs made before recall was scored: answered only, or nothing)."""
    head = metrics.headline_key(runs)
    cols = [(f"recall/{head}", f"within {metrics.recall_label(head)}")] if head else []
    if any(r.lookup("valid_fraction")[0] for r in runs):
        cols.append(("valid_fraction", "answered"))
    return cols


def seed_values_text(sel: list[Run], values: Sequence[Optional[float]], flagged: Collection[int], digits: int, nulls: Collection[int] = (),
                     metric: str = "") -> str:
    """'s1 3.10, s2 806.00 (outlier), s3 no estimate': every seed's value beside the mean ('no bound'
    for a null of the accuracy limit)."""
    null_set = set(nulls)
    return ", ".join(f"s{r.seed}\u00a0" + (null_text(metric) if i in null_set else fnum(v, digits)) + ("\u00a0(outlier)" if i in flagged else "")
                     for i, (r, v) in enumerate(zip(sel, values)))


def interval_text(st: SeedStats, digits: int) -> str:
    """One metric over seeds as every tool prints it (stats.interval_text: t95 for n >= 5, the seeds'
    range below, n = 1 marked)."""
    return stats.interval_text(st, digits)


def flag_outliers(sel: list[Run], metric: str = "x_cm/mean", phase: str = "tracking") -> list[Run]:
    """The runs of one row (seeds) whose error is far above the others' (stats.outliers)."""
    vals = [r.metric(metric, phase) for r in sel]
    return [sel[i] for i in stats.outliers(vals)] if None not in vals else []


def outlier_cause(run: Run, wrong_m: float = 0.5) -> str:
    """What happened in an outlying run, read from frames.csv (robot 0) and events.jsonl: when the
    position error went above `wrong_m` for good and what the localizer said it was doing then."""
    frames = [f for f in run.frames() if f.get("robot", "0") == "0" and f.get("err_pos") not in (None, "")]  # scored frames (with truth)
    if not frames:
        return "no frames.csv to read the cause from"
    events = [e for e in read_events(run.folder / "events.jsonl", skip_bad=True) if e.marked]
    err = [(float(f["t"]), float(f["err_pos"]) if f.get("valid") == "1" else math.nan, f.get("mode", "")) for f in frames]

    def bad(e: float) -> bool:
        return not (e <= wrong_m)  # a frame without an estimate counts as wrong
    e_end = err[-1][1]
    if bad(e_end):
        k = len(err) - 1
        while k > 0 and bad(err[k - 1][1]):
            k -= 1
        stretch = err[k:]
        t0 = stretch[0][0]
        valid = sorted(e for _, e, _ in stretch if not math.isnan(e))
        typical = f"{fnum(stats.percentile(valid, 0.5), 2)} m from the truth (median)" if valid else "no estimate"
        before = [e for e in events if e.t <= t0 + 0.5]
        after_event = f", after the {before[-1].type} at t = {before[-1].t:.1f} s" if before else ""
        since = "from the start" if k == 0 else f"from t = {t0:.1f} s{after_event}"
        # The localizer claimed a pose (a mode other than searching / lost) that was wrong: the
        # worst failure, as it does not know it is lost.
        sure = [(t, e, m) for t, e, m in stretch if not math.isnan(e) and m not in ("global", "lost", "coasting", "searching", "")]
        if sure:
            share = 100.0 * len(sure) / len(stretch)
            return (f"converged to a wrong pose at t = {sure[0][0]:.1f} s: {typical}, mode '{sure[0][2]}' in {share:.0f} % of the frames "
                    f"{since} to the end; " + (f"never within {wrong_m} m" if k == 0 else f"not within {wrong_m} m again"))
        return f"lost {since}: {typical}, no confident estimate (mode '{stretch[-1][2]}') to the end"
    # Right at the end: what made the seed's mean large is the time it spent on a wrong pose, not a
    # momentary "peak" (a seed 8.8 m off for 37 s of 60 is a failure of 37 s): say how long, when and how far.
    times = [t for t, _, _ in err]
    steps = [b - a for a, b in zip(times, times[1:])]
    dt = statistics.median(steps) if steps else 0.0

    def dur(k: int) -> float:
        return (times[k + 1] - times[k]) if k + 1 < len(times) else dt  # a frame lasts to the next one
    total = times[-1] - times[0] + dt
    wrong = [k for k, (_, e, _) in enumerate(err) if not math.isnan(e) and e > wrong_m]
    if not wrong:
        worst = max(err, key=lambda x: -1 if math.isnan(x[1]) else x[1])
        return f"never on a wrong pose (> {wrong_m} m off): at most {fnum(worst[1], 2)} m at t = {worst[0]:.1f} s"
    # The longest stretch of consecutive wrong frames: from its first frame to the next right one.
    stretches: list[list[int]] = []
    cur = [wrong[0]]
    for k in wrong[1:]:
        if k == cur[-1] + 1:
            cur.append(k)
        else:
            stretches.append(cur)
            cur = [k]
    stretches.append(cur)
    longest = max(stretches, key=lambda st: sum(dur(k) for k in st))
    a, b = times[longest[0]], times[longest[-1]] + dur(longest[-1])
    before = [e for e in events if e.t <= a + 0.5]
    off = statistics.median(err[k][1] for k in longest)
    return (f"on a wrong pose (> {wrong_m} m off) for {sum(dur(k) for k in wrong):.1f} s of {total:.1f} s"
            + (", longest" if len(stretches) > 1 else ",") + f" from t = {a:.1f} to {b:.1f} s"
            + (f" (after the {before[-1].type} at t = {before[-1].t:.1f} s)" if before else "")
            + f", {fnum(off, 2)} m off (median); within {wrong_m} m at the end")


def seed_table(rep: Writer, rows_runs: Sequence[RowRuns], phase: str = "tracking", caption_extra: str = "") -> list[Run]:
    """Per row: every seed's value of mean x, y and heading, their median, mean and 95 % interval
    with its method, and the outlying seeds with their cause. rows_runs: [(label, runs sorted by
    seed)]. Returns the outlying runs, which the caller plots."""
    rows: list[list[Cell]] = []
    classes: list[str] = []
    flagged_runs: list[Run] = []
    methods: set[str] = set()
    rep.seeded.update(r.folder for _, sel in rows_runs for r in sel)  # shown once (report_sweep)
    # Coverage first (percent of all frames), then the errors over the answered frames.
    columns = [(m, f"{h}, % of frames", 1, 100.0) for m, h in coverage_cols([r for _, sel in rows_runs for r in sel])] + \
        [(m, name, digits, 1.0) for m, name, digits in SEED_METRICS]
    # Each seed's distance from the accuracy limit, where the runs carry it (runs made before the bound: no column).
    coverage = len(columns) > len(SEED_METRICS)
    bounded = any(r.bound(phase=phase) is not None for _, sel in rows_runs for r in sel)
    if bounded:
        columns.append(("efficiency/position", "position RMSE / bound (x the limit)", 2, 1.0))
    pages = viewers.viewers_of(rep)
    linked = pages is not None and pages.all  # a report of many runs links only those shown on their own
    for label, sel in rows_runs:
        if not sel:
            continue
        out = flag_outliers(sel, phase=phase)
        flagged_runs += out
        row: list[Cell] = [label, len(sel)]
        for metric, _, digits, scale in columns:
            found = [r.lookup(metric, phase) for r in sel]
            vals = [v * scale if stats.is_number(v) else None for _, v in found]
            nulls = [i for i, (f, v) in enumerate(found) if f and v is None]  # no estimate in that seed
            st = stats.stats(vals)
            if st.method:
                methods.add(st.method)
            flagged = {i for i, r in enumerate(sel) if r in out} if metric == "x_cm/mean" else set()  # the metric flagged on
            # One cell per metric (the mean with its interval, the median, every seed): a table a
            # reader takes in without scrolling sideways.
            if not st.n and nulls:
                row.append(metrics.no_estimate_text(len(nulls), len(sel), metric))
                continue
            row.append(f"mean {interval_text(st, digits)}; median {fnum(st.median, digits)}; seeds: {seed_values_text(sel, vals, flagged, digits, nulls, metric)}"
                       + (f" ({metrics.no_estimate_text(len(nulls), len(sel), metric)}: the mean is over the others)" if nulls else "")
                       + (f" ({share_text(metrics.run_stats(sel, 'efficiency/share', phase).mean)}, mean over seeds)" if metric == "efficiency/position" else ""))
        row.append("; ".join(f"s{r.seed}: {outlier_cause(r)}" for r in out) or "-")
        if linked:
            row.append(seed_links(rep, sel))
        rows.append(row)
        classes.append("outlier" if out else "")
    if not rows:
        return []
    if linked and not any(viewers.TOKEN_RE.search(str(r[-1])) for r in rows):  # no seed has a page (their files make none): no column
        rows, linked = [r[:-1] for r in rows], False
    header = ["row", "n"] + [name for _, name, _, _ in columns]
    rep.table(header + ["outlying seeds and cause"] + (["viewers"] if linked else []), rows,
              "Every seed beside the mean: mean with its interval; median; each seed's value. "
              + ("The share of frames within the headline threshold (a frame without an estimate counts as outside) and the share answered come "
                 "first; the errors after them are over the answered frames, and a seed without any says 'no estimate'. "
                 if coverage else "")
              + ("'x the limit': the seed's position RMSE over the Cramer-Rao bound of the same frames (1x is the limit), 'no bound' where "
                 "it has none. " if bounded else "")
              + "The " + stats.INTERVAL_RULE_TEXT + ". A seed is flagged as an outlier when its mean x error lies above 3x "
              "the median of the other seeds and further from it than 3x their range; its cause is read from its frames.csv and events.jsonl."
              + caption_extra + (" 'viewers': each seed's run in the run viewer (frame by frame)." if linked else ""), classes)
    return flagged_runs


def seed_links(rep: Writer, sel: list[Run]) -> str:
    """'s1, s2, s3', each seed a link to its run's viewer page ('s2: none' where it has none)."""
    return ", ".join(c if (c := viewers.cell(rep, r, f"s{r.seed}", title=run_title(r))) != "-" else f"s{r.seed}: none"
                     for r in sel)


def strip_plot(rep: Writer, title: str, rows_runs: Sequence[RowRuns], phase: str = "tracking") -> None:
    """Each seed's mean x error (cm) and mean heading error (rad) as dots per row, the mean as a bar
    (omniloc.tools.plot.seeds_figure): a reader sees at once whether a mean is one seed's doing."""
    rows_runs = [(l, s) for l, s in rows_runs if s]
    if not rows_runs:
        return
    rep.figure(plot.seeds_figure(rows_runs, phase), "seeds", f"{title}: every seed (dots; red diamonds: outlying seeds), the mean over seeds (black bar)")
