"""The published tables beside ours: the papers' error tables (by key), kidnap recovery and timings,
for the robot profile and again for the field_robot runs.
"""
from __future__ import annotations

from omniloc.core import metrics, pairing
from omniloc.core.jsonvalue import JSONObject, lst, number, obj
from omniloc.core.pairing import profile_of
from omniloc.core.rundir import Run
from omniloc.core.stats import fnum
from omniloc.paper import labels, tables
from omniloc.paper.tables import Context
from omniloc.report.experiments import experiment_tables
from omniloc.report.provenance import machine_text
from omniloc.report.runs import plot_run, run_title
from omniloc.report.seeds import outlier_cause, seed_table, strip_plot
from omniloc.tools.markup import Cell, Writer


def command(cmd: str) -> str:
    """The command that runs a missing row: under the field_robot profile, its own suite."""
    if pairing.DEFAULT_PROFILE == "field_robot":
        return cmd.replace("sweeps/paper_suite.json", "sweeps/paper_suite_field_robot.json")
    return cmd


def error_table(rep: Writer, papers: JSONObject, table: str, runs: list[Run]) -> None:
    t = obj(papers[table])
    rep.heading(labels.table_label(table) + profile_suffix(), 3, table)
    pairs = tables.pair_table(papers, table, runs)
    cov, cov_head = tables.table_coverage(pairs)
    rep.para(f"Published: {t.get('source', table)} (results/reference/papers.json); th: heading. Ours: mean over seeds of each run's statistic (robot 0), with n; "
             "runs with kidnaps or covers use their tracking phase (see docs/results.md). Paper rows in italics, then ours / paper."
             + (" Our rows lead with the share of all frames within the headline threshold (a frame without an estimate counts as outside) "
                "and the share answered: the errors after them, like the papers', are over the answered frames only; 'no estimate' where "
                "a run answered no frame." if cov else ""))
    header = ["row", "source"] + cov_head + metrics.TABLE_COLS + ["line points / frame", "seeds"]
    rows: list[list[Cell]] = []
    classes: list[str] = []
    for p in pairs:
        st = p.stats
        if p.runs:
            label = p.shown + (" (tracking phase)" if p.phased else "")
            rows.append([label, "omniloc", *tables.row_cells(st, cov, p.runs)])
            classes.append("")
        else:
            rows.append([p.label, "not run", *(["-"] * (len(cov) + 9)), "-", 0])
            classes.append("missing")
        for peer in p.peers:  # external localizers (docs/protocol.md), same scenario, configuration and start pose
            rows.append([peer.row, f"external: {peer.name}", *tables.row_cells(peer.stats, cov, peer.runs)])
            classes.append("")
        if p.published:
            rows.append([p.label, "paper", *(["-"] * len(cov)), *[fnum(v, 3) for v in p.published], "-", "-"])
            classes.append("paper")
            if p.runs:
                means = [st[f"{a}/{s}"].mean for a, s in metrics.TABLE_KEYS]
                rows.append([p.label, "ours / paper", *([""] * len(cov)), *[fnum(m / v, 2) if v and m is not None else "-"
                                                                            for m, v in zip(means, p.published)], "", ""])
                classes.append("ratio")
    rep.table(header, rows, row_classes=classes)
    missing = [p for p in pairs if not p.runs]
    if missing:  # one line each, collapsed: the command is what a reader needs, not a page of it
        rep.details(f"{len(missing)} row(s) not run, and the command that runs them")
        for p in missing:
            rep.para(f"Not run: \"{p.label}\" ({pairing.describe_key(p.key)}). Run: `{command(p.command)}`")
        rep.end_details()
    # Every seed beside its mean, and the outlying seeds plotted with their cause.
    rows_runs = [(p.shown, p.runs) for p in pairs] + [(f"{q.row} (external: {q.name})", q.runs) for p in pairs for q in p.peers]
    flagged = seed_table(rep, rows_runs)
    strip_plot(rep, str(t.get("source", table)), rows_runs)
    for run in flagged:
        plot_run(rep, run, f"outlying seed: {run_title(run)}: {outlier_cause(run)}")


def profile_suffix() -> str:
    """' (field_robot profile)' in a heading of a table paired under another profile than the
    scenarios' own: each section heading once in the report."""
    return "" if pairing.DEFAULT_PROFILE == pairing.SCENARIO_DEFAULT_PROFILE else f" ({pairing.DEFAULT_PROFILE} profile)"


def kidnap_table(rep: Writer, papers: JSONObject, runs: list[Run]) -> None:
    rep.heading("Kidnap recovery (papers 002 and 000)" + profile_suffix(), 3, "kidnapping")
    rows: list[list[Cell]] = []
    classes: list[str] = []
    for table in ("002_kidnapping", "000_kidnapping"):
        t = obj(papers[table])
        for label, key in obj(obj(t["reproduced_by"])["rows"]).items():
            sel = pairing.select(runs, obj(key))
            if sel:
                # Counts: a run without a recovery block counts none. Statistics: run_stats, so that a
                # null (no kidnap recovered, no estimate) reads as such, never as 0.
                ep = sum(r.metric("recovery/episodes", "all") or 0 for r in sel)
                rec = sum(r.metric("recovery/recovered", "all") or 0 for r in sel)
                fal = sum(r.metric("recovery/false_recoveries", "all") or 0 for r in sel)
                med = metrics.run_stats(sel, "recovery/recovery_time_s/median", "all")
                after = metrics.run_stats(sel, "recovery/after_recovery/x_cm/mean", "all")
                phase = metrics.run_stats(sel, "x_cm/mean", "tracking")
                allf = metrics.run_stats(sel, "x_cm/mean", "all")
                per_seed = ", ".join(f"s{r.seed}\u00a0{r.metric('recovery/recovered', 'all') or 0:.0f}/{r.metric('recovery/episodes', 'all') or 0:.0f}"
                                     f"\u00a0{seed_cell(r, 'x_cm/mean', 'tracking', 2)}" for r in sel)
                rows.append([f"{labels.table_label(table)}: {label}", "omniloc", f"{rec:.0f} / {ep:.0f}", f"{fal:.0f}",
                             metrics.stat_cell(med, 2) if med.n or not med.no_value else "none recovered", metrics.stat_cell(after, 2),
                             answered_beside(metrics.stat_cell(phase, 2), sel, "tracking"), answered_beside(metrics.stat_cell(allf, 1), sel, "all"), per_seed, len(sel)])
                classes.append("")
            else:
                rows.append([f"{labels.table_label(table)}: {label}", "not run", "-", "-", "-", "-", "-", "-", "-", 0])
                classes.append("missing")
            rows.append([f"{labels.table_label(table)}: {label}", "paper", f"{t['recovered']} / {t['kidnaps']}", "-", "-", "-", "-", "-", "-", "-"])
            classes.append("paper")
    rep.table(["case", "source", "recovered / kidnaps", "false recoveries", "median recovery s", "after recovery: mean x cm",
               "tracking phase: mean x cm", "all frames: mean x cm", "per seed: recovered, tracking-phase mean x cm", "seeds"], rows,
              "Over all seeds, and every seed beside the means. Recovered: error under 0.3 m and 0.2 rad for 1 s. The tracking phase leaves out the carried period and the time to recovery; "
              "'all frames' includes them (that is why it is large). The errors are over the frames answered (their share beside them); "
              "'no estimate' where a run answered none, 'no kidnap recovered' where no recovery left a frame to score.", classes)


def seed_cell(run: Run, path: str, phase: str, digits: int) -> str:
    """One run's statistic: its value, or "no estimate" where it is null (see Run.lookup)."""
    found, v = run.lookup(path, phase)
    return metrics.NO_ESTIMATE if found and v is None else fnum(run.metric(path, phase), digits)


def answered_beside(cell: str, runs: list[Run], phase: str) -> str:
    """An error cell with the share of frames answered beside it: '2.31 (answered 98.0 %)' (mean
    over the runs; the cell alone for runs made before valid_fraction)."""
    st = metrics.run_stats(runs, "valid_fraction", phase)
    return f"{cell} (answered {metrics.percent(st.mean)})" if st.n else cell


def timing_table(rep: Writer, papers: JSONObject, runs: list[Run]) -> None:
    t = obj(papers["timings_ms"])
    rep.heading("Timings (papers 002 and 000)", 3, "timings_ms")
    rows: list[list[Cell]] = []
    classes: list[str] = []
    for row, key in obj(obj(t["reproduced_by"])["rows"]).items():
        med, frames, sel = tables.timing_ms(papers, row, runs)
        lo, hi = lst(t[row])[:2]
        upper = number(hi)
        rows.append([labels.timing_label(row), str(obj(key)["what"]), fnum(med, 2) if med is not None else "not run", f"{lo}-{hi}",
                     fnum(med / upper, 2) if med is not None and upper is not None else "-", frames])
        classes.append("" if med is not None else "missing")
    rep.table(["published figure", "what", "ours: median ms", "paper ms", "ours / paper's upper bound", "frames"], rows,
              f"Ours: wall time on {machine_text()}, runs of a sweep share the cores; paper: {t['cpu']}.", classes)


def published_tables(rep: Writer, papers: JSONObject, ctx: Context) -> None:
    rep.heading("Published tables beside ours", 2, "published")
    for table in ("002_table1_occlusion", "002_table2_lighting", "000_tracking"):
        error_table(rep, papers, table, ctx.runs)
    kidnap_table(rep, papers, ctx.runs)
    timing_table(rep, papers, ctx.runs)
    lo, hi = lst(papers["mcl_only_mean_position_error_cm"])[:2]
    rep.para(f"{labels.table_label('mcl_only_mean_position_error_cm')}: {lo}-{hi} cm, beside our MCL-alone row of the "
             f"{labels.table_label('000_tracking')} above and the scorecard's claim \"{labels.claim_label('mcl_alone')}\".")
    experiment_tables(rep, papers, ctx)


def field_robot_tables(rep: Writer, papers: JSONObject, runs: list[Run]) -> None:
    """The published rows again, from runs under the field_robot profile (docs/camera.md)."""
    field = [r for r in runs if profile_of(r) == "field_robot"]
    if not field:
        return
    rep.heading("Published tables under the field_robot profile", 2, "field_robot")
    rep.para("The same keyed rows from runs under the field_robot noise profile: the robot profile plus defocus, motion blur, tilt "
             "from acceleration and a 9 px decentred mirror that calibration estimates (docs/camera.md). Compare with the tables "
             "above (robot profile). Nothing here is tuned to the papers' numbers; what moves is reported as measured.")
    with pairing.pairing_profile("field_robot"):  # the same keys, these runs
        for table in ("002_table1_occlusion", "002_table2_lighting", "000_tracking"):
            error_table(rep, papers, table, field)
        kidnap_table(rep, papers, field)
