"""Sweeps in the report: each sweep's aggregate and per-seed tables, its runs; and the global-start
sweeps judged per run (omniloc.global_start).
"""
from __future__ import annotations

import pathlib
from typing import Optional

from omniloc import global_start
from omniloc.core import metrics, rundir
from omniloc.core.aggregate import Aggregate, AggregateMetric, read_aggregate, read_runs_csv
from omniloc.core.rundir import Run
from omniloc.core.stats import fnum
from omniloc.report import limit, viewers
from omniloc.report.runs import params_text, report_run, run_title
from omniloc.report.seeds import RowRuns, flag_outliers, outlier_cause, seed_table
from omniloc.tools.markup import Cell, Writer

# A run of a sweep with the parameters of its row (runs.csv) and its localizer's row name.
SweepRun = tuple[Run, str, Optional[str]]


def sweep_runs(sweep: pathlib.Path, all_runs: list[Run]) -> list[SweepRun]:
    """The sweep's runs in the aggregate's order (group by group, seeds in run order), with their
    params and the localizer name of their row: runs.csv's, the name the aggregate gives the row
    (docs/protocol.md "Which name"; a run missing from runs.csv: the name in its summary.json)."""
    by_folder = {r.folder: r for r in all_runs}
    order = {row.id: (row.index, row.params, row.localizer) for row in read_runs_csv(sweep)}
    agg = read_aggregate(sweep)
    group_rank = {(g.scenario, g.localizer, g.params): k for k, g in enumerate(agg.groups)}
    out: list[tuple[int, int, Run, str, Optional[str]]] = []
    for folder, run in by_folder.items():
        if folder.parent != sweep / "runs":
            continue
        idx, params, label = order.get(folder.name, (10 ** 9, "default", None))
        name = label or run.localizer
        rank = group_rank.get((run.scenario, name, params), 10 ** 9)
        out.append((rank, idx, run, params, name))
    return [(r, p, n) for _, _, r, p, n in sorted(out, key=lambda x: (x[0], x[1]))]


def aggregate_cell(metric: Optional[AggregateMetric], digits: int) -> str:
    """One metric of an aggregate.json group: its mean; "no estimate" where no run had a value; "-"
    where the group lacks the metric."""
    if not metric:
        return "-"
    if metric.mean is None:
        return metrics.NO_ESTIMATE if metric.no_value else "-"
    return fnum(metric.mean, digits)


def middle_recall_key(agg: Aggregate) -> Optional[str]:
    """The middle recall threshold an aggregate names (its runs' headline where they do not say)."""
    keys = sorted({k.split("/")[-1] for g in agg.groups for k in g.metrics if k.startswith("r0/recall/")}, key=metrics.recall_order)
    return keys[len(keys) // 2] if keys else None


def report_sweep(rep: Writer, sweep: pathlib.Path, all_runs: list[Run], max_runs: int) -> list[Run]:
    agg = read_aggregate(sweep)
    name = agg.name
    rep.heading(f"Sweep {name}", 2)
    rep.para(f"{sweep}: {agg.runs} runs; aggregated by omniloc {agg.version}; runs made by "
             + ", ".join(f"{v} ({n})" for v, n in agg.run_versions.items()) + ".")
    rows: list[list[Cell]] = []
    # Groups given the start pose say so where the sweep also has groups that were not (a sweep
    # from before start_pose_given has neither).
    kinds = {g.start_pose_given for g in agg.groups}
    mark = True in kinds and (False in kinds or "mixed" in kinds)
    runs = sweep_runs(sweep, all_runs)
    key = metrics.headline_key([r for r, _, _ in runs]) or middle_recall_key(agg)
    answered = any("r0/valid_fraction" in g.metrics for g in agg.groups)
    bounded = limit.sweep_has_limit(agg.groups)  # aggregates of runs made before the bound: no columns
    for g in agg.groups:
        m = g.metrics
        phase = "r0/tracking_phase/x_cm/mean" in m

        def metric(path: str) -> Optional[AggregateMetric]:
            return m.get(f"r0/tracking_phase/{path}" if phase else f"r0/{path}")

        def cell(path: str, digits: int) -> str:
            return aggregate_cell(metric(path), digits)

        def mean_of(path: str) -> Optional[float]:
            found = metric(path)
            return found.mean if found else None
        x = m.get("r0/x_cm/mean")
        n, without = (x.n, x.no_value) if x else (0, 0)
        given = g.start_pose_given
        task = " (given the start pose)" if mark and given is True else " (start pose: mixed)" if given == "mixed" else ""
        rows.append([f"{g.scenario or ''} / {g.localizer or ''}{task} / {params_text(g.params or '')}" + (" (tracking phase)" if phase else ""),
                     *([metrics.percent(mean_of(f"recall/{key}"))] if key else []),
                     *([metrics.percent(mean_of("valid_fraction"))] if answered else []),
                     *[cell(f"{a}/{s}", 3) for a, s in metrics.TABLE_KEYS], cell("position_m/mean", 3), cell("position_m/rmse", 3),
                     *([limit.aggregate_limit_cell(g, phase), limit.aggregate_share_cell(g, phase)] if bounded else []),
                     f"{g.finished}/{g.failed}", f"{n}; {metrics.no_estimate_text(without, n + without)}" if without else n])
    rep.table(["group"] + ([f"within {metrics.recall_label(key)}"] if key else []) + (["answered"] if answered else []) + metrics.TABLE_COLS +
              ["position mean m", "position RMSE m"] + (["RMSE against the limit", "frames with a bound"] if bounded else []) + ["runs ok/failed", "n"], rows,
              "mean over seeds of each run's statistics (robot 0); runs with kidnaps or covers: tracking phase. Published rows: see 'Published tables beside ours'."
              + (f" 'within {metrics.recall_label(key)}': the share of all frames within that threshold (a frame without an estimate counts as outside); "
                 "'answered': the share of frames with an estimate; the errors are over the answered frames, 'no estimate' where no run of the "
                 "group answered any, and n counts the runs with a value (aggregate.csv also counts those without one)." if key or answered else "")
              + (" 'RMSE against the limit': the mean over seeds of the RMSE over the Cramer-Rao bound of the same frames (1x is the limit; "
                 "posterior bound where the runs track), 'no bound' where no run has one; 'frames with a bound': the mean share of scored "
                 "frames it covers." if bounded else ""))
    groups: dict[tuple[Optional[str], Optional[str], str], list[Run]] = {}
    for run, params, row_name in runs:
        groups.setdefault((run.scenario, row_name, params), []).append(run)
    rows_runs: list[RowRuns] = [(f"{k[0]} / {k[1]} / {params_text(k[2])}", sorted(v, key=lambda r: r.seed or 0)) for k, v in groups.items()]
    # Groups whose every seed a published table above already showed are not shown again.
    seeded = rep.seeded
    shown = [k for k, (_, sel) in enumerate(rows_runs) if sel and all(r.folder in seeded for r in sel)]
    if shown:
        rep.para(f"{len(shown)} of this sweep's {len(rows_runs)} groups have every seed in a published table above (with their outlying seeds); "
                 "they are not repeated here.")
    shown_flagged = [r for k in shown for r in flag_outliers(rows_runs[k][1])]
    rows_runs = [rr for k, rr in enumerate(rows_runs) if k not in shown]
    flagged = shown_flagged + seed_table(rep, rows_runs, caption_extra=" The sweep's aggregate.json and aggregate.csv hold the same intervals by the same rule (column interval: t95 or range).")
    # Per run: its tables always; plots for the first seed of each group (every condition shown
    # once, at most max_runs) and for every outlying seed, collapsed: a reader opens what they need.
    rep.details(f"Runs of sweep {name}: {len(runs)} runs, tables and plots")
    plotted = 0
    seen: set[tuple[Optional[str], Optional[str], str]] = set()
    for run, params, row_name in runs:
        first = (run.scenario, row_name, params) not in seen
        seen.add((run.scenario, row_name, params))
        report_run(rep, run, plots=(first and plotted < max_runs) or run in flagged, params=params,
                   note=f"outlying seed: {outlier_cause(run)}" if run in flagged else None, name=row_name)
        plotted += first
    rep.end_details()
    return [r for r, _, _ in runs]


def global_start_section(rep: Writer, sweeps: list[pathlib.Path]) -> None:
    """Sweeps of scenarios/sweeps/global_tracking.json, each run judged apart by
    omniloc.global_start. A mean over all frames hides one run 8 m off among nineteen at 3 cm, so
    MCL alone is shown as a success rate (Wilson 95 %), the error while right, and the mean over all."""
    for sw in sweeps:
        if not sw.name.startswith("global_tracking"):
            continue
        by = global_start.collect([sw])
        if not by:
            continue
        rep.heading(f"Global start, judged per run: {sw.name}", 2, "global_start")
        rows: list[list[Cell]] = []
        table = {loc: global_start.summarise([r for _, r in by[loc]]) for loc in sorted(by, key=lambda k: (k not in ("mcl", "hybrid", "grid_global"), k))}
        with_recall = any(g.recall_key for g in table.values())

        def none(v: Optional[float], d: int, g: global_start.Summary) -> str:
            return (metrics.NO_ESTIMATE if g.runs_without_estimate == g.runs else "-") if v is None else fnum(v, d)
        for loc, g in table.items():
            rows.append([loc, *([metrics.percent(g.recall_mean), metrics.percent(g.answered_mean),
                                 fnum(g.first_within_median_s, 2) + (f" ({g.runs_never_within} never)" if g.runs_never_within else "")]
                                if with_recall else []),
                         f"{g.ended_right} / {g.runs}", f"{100 * g.wilson95[0]:.0f}-{100 * g.wilson95[1]:.0f} %",
                         fnum(g.t_first_median_s, 2), none(g.right_mean_x_cm, 2, g), none(g.right_mean_y_cm, 2, g),
                         none(g.right_mean_theta_rad, 4, g), fnum(g.wrong_frame_fraction * 100 if g.wrong_frame_fraction is not None else None, 2),
                         none(g.all_mean_pos_cm, 1, g)])
        head = global_start.recall_header(table)
        rep.table(["localizer"] + ([head, "answered", "first within it: median s"] if with_recall else []) +
                  ["ended right", "Wilson 95 %", "first correct convergence median s", "while right: mean x cm", "mean y cm",
                   "mean th rad", "wrong frames %", "mean position error over all valid frames cm"], rows,
                  "omniloc global-start (definitions in docs/global_localization.md). Paper 002's 'MCL alone 15-40 cm' "
                  "is to be read on the success rate and the error while right, not on the mean over all frames."
                  + (f" '{head}': the share of all frames within it (a frame without an estimate counts as outside), mean over runs; "
                     "'answered': the share of frames with an estimate." if with_recall else ""))
        per_run_table(rep, sw)


def per_run_table(rep: Writer, sweep: pathlib.Path) -> None:
    """Each run of a global-start sweep as omniloc.global_start judges it (ended right, first
    correct convergence, wrong frames), with its viewer page: the runs behind the rates above,
    collapsed."""
    runs, _, _ = rundir.discover([sweep])
    rows: list[list[Cell]] = []
    for run in sorted(runs, key=lambda r: (global_start.row_of(r), r.seed or 0)):
        sc = global_start.score_run(run.frames(), global_start.floor_half(run))
        rows.append([global_start.row_of(run), str(run.seed), "yes" if sc.ended_right else "no", fnum(sc.t_first, 2) if sc.t_first is not None else "never",
                     f"{sc.wrong_frames} / {sc.frames}", f"{sc.valid_frames} / {sc.frames}", viewers.cell(rep, run, title=run_title(run))])
    if not rows:
        return
    rep.details(f"Each run of {sweep.name}: judged apart, with its viewer page ({len(rows)} runs)")
    rep.table(["localizer", "seed", "ended right", "first correct convergence s", "wrong frames", "answered frames", "viewer"], rows,
              "Per run, as above: 'ended right': every answered frame of the last second within 0.3 m and 0.2 rad; the first correct "
              "convergence: the first time from which every frame of a second was; wrong frames: answered more than 0.5 m or 0.35 rad off. "
              "'viewer': the run frame by frame.")
    rep.end_details()

