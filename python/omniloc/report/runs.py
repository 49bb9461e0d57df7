"""One run in the report: its table (coverage first, then errors, recovery) and its plot.
"""
from __future__ import annotations

from typing import Optional

from omniloc.core import metrics, pairing, rundir, stats
from omniloc.core.events import read_events
from omniloc.core.files import InputFileError
from omniloc.core.jsonvalue import JSON, JSONObject, number, obj
from omniloc.core.pairing import profile_of
from omniloc.core.rundir import Run
from omniloc.core.stats import fnum
from omniloc.report import limit, viewers
from omniloc.tools import plot
from omniloc.tools.markup import Cell, Writer


def plot_run(rep: Writer, run: Run, title: str, link: bool = True) -> None:
    """The run's figure (once per report) and, with link, the line to its viewer page below it."""
    try:
        frames = run.frames()
    except (ValueError, OSError) as e:  # frames.csv unreadable (not text): no plot, the report goes on
        frames = []
        if run.folder not in rep.plotted:
            rep.plotted.add(run.folder)
            rep.para(f"No plot for this run: frames.csv: {e.__class__.__name__}")
    if not frames or run.folder in rep.plotted:  # each run's figure once (an outlier is plotted where it is flagged first)
        return
    rep.plotted.add(run.folder)
    try:
        fig = plot.run_figure(run, frames, read_events(run.folder / "events.jsonl"))
    except (ValueError, KeyError, TypeError, IndexError, OSError, InputFileError) as e:  # a malformed field.json or events.jsonl: the report goes on
        rep.para(f"No plot for this run: {e.__class__.__name__}: {str(e)[:200]}")
    else:
        rep.figure(fig, "run", f"{title}: trajectory over the field, position and heading error over time"
                   + (" (shaded: carried, blind or recovering, left out of the tracking phase)" if any("tracking_phase" in r for r in run.summary.robots) else ""))
    if link:
        viewers.line(rep, run, own=True, title=run_title(run))


def params_text(params: Optional[str]) -> str:
    """A sweep's parameters of a run ('occlusion={"fraction":0.5}') as code: configuration keys are
    what a reader writes in a sweep file, not prose."""
    return f"`{params}`" if params and params != "default" else (params or "")


def run_title(run: Run, params: Optional[str] = None, name: Optional[str] = None) -> str:
    """'scenario / localizer / params / seed N (profile)'; name: the sweep's row name of the localizer
    (its label: two configurations of one localizer type in a sweep, e.g. mcl and mcl_as_published)."""
    s = run.summary
    parts = [s.scenario, name or s.localizer] + ([params_text(params)] if params and params != "default" else []) + [f"seed {s.seed}"]
    if s.replay.get("recorded_with") == "not omniloc":
        return " / ".join(str(p) for p in parts) + " (a log not made by omniloc: no noise profile)"
    prof = profile_of(run)
    return " / ".join(str(p) for p in parts) + (f" ({prof} profile)" if prof != pairing.SCENARIO_DEFAULT_PROFILE else "")


# Position error statistics of a run's table (summary.json position_m): the mean is the typical
# error, the RMSE weighs the large ones more; a run from before position_m.mean shows "-".
POSITION_COLS: list[str] = ["position mean m", "position RMSE m", "position p95 m"]


def block_cell(block: JSONObject, path: str, digits: int) -> str:
    """A statistic of one summary.json block: its value; where it is null, the block's why_null in
    short ("no estimate", "no kidnap recovered"); "-" where the block lacks it (an older run)."""
    found, v = rundir.find(block, path)
    if found and v is None:
        why = str(block.get("why_null") or "")
        return why if why and not why.startswith(metrics.NO_ESTIMATE) else metrics.NO_ESTIMATE
    return fnum(v if stats.is_number(v) else None, digits)


def position_cells(block: JSONObject) -> list[str]:
    return [block_cell(block, f"position_m/{k}", 3) for k in ("mean", "rmse", "p95")]


def coverage_cells(block: JSONObject, key: Optional[str], with_answered: bool) -> list[str]:
    """The share of the block's frames within the headline threshold and the share answered."""
    return ([metrics.percent(obj(block.get("recall") or {}).get(key))] if key else []) + ([metrics.percent(block.get("valid_fraction"))] if with_answered else [])


def at_time(t: JSON) -> str:
    """'at 0.50 s', or 'never' for a time that is null (the run never got there)."""
    return "never" if t is None else f"at {t:.2f} s"


def first_fix_text(s: rundir.Summary, key: Optional[str]) -> str:
    """'robot 0: first estimate at 0.03 s, first within 25 cm / 10 deg at 0.50 s' (never: 'never')."""
    parts = []
    for r in s.robots:
        if "first_estimate_s" not in r and "first_within_s" not in r:
            continue
        est, within = r.get("first_estimate_s"), r.get("first_within_s")
        parts.append(f"robot {r.get('robot', 0)}: first estimate {at_time(est)}"
                     + (f", first within {metrics.recall_label(key)} {at_time(within)}" if key else ""))
    return "; ".join(parts)


def report_run(rep: Writer, run: Run, plots: bool, params: Optional[str] = None, note: Optional[str] = None, name: Optional[str] = None) -> None:
    s = run.summary
    title = run_title(run, params, name) + (f" ({note})" if note else "")
    rep.heading(f"Run {title}", 3)
    viewers.line(rep, run, own=plots, title=title)  # its viewer page (a report of many runs: the plotted ones)
    rows: list[list[Cell]] = []
    key = run.headline
    answered = any("valid_fraction" in r for r in s.robots)
    # Beside the RMSE, how far it is from the accuracy limit (runs made before the bound: no column).
    bounded = limit.any_bound([run])
    for r in s.robots:
        rows.append([f"r{r['robot']}" + (" all frames" if "tracking_phase" in r else ""), *coverage_cells(r, key, answered),
                     *[block_cell(r, f"{a}/{st}", 3) for a, st in metrics.TABLE_KEYS], *position_cells(r),
                     *(limit.run_cells(r) if bounded else []), str(r.get("frames", "-"))])
        if "tracking_phase" in r:
            tp = obj(r["tracking_phase"])
            rows.append([f"r{r['robot']} tracking phase", *coverage_cells(tp, key, answered), *[block_cell(tp, f"{a}/{st}", 3) for a, st in metrics.TABLE_KEYS],
                         *position_cells(tp), *(limit.run_cells(tp) if bounded else []), str(tp.get("frames", "-"))])
    task = pairing.start_pose_text(run.start_pose_given)
    first = first_fix_text(s, key)
    rep.table(["robot"] + ([f"within {metrics.recall_label(key)}"] if key else []) + (["answered"] if answered else []) + metrics.TABLE_COLS + POSITION_COLS
              + (["RMSE against the limit"] if bounded else []) + ["frames"], rows,
              f"noise profile {s.raw.get('noise_profile')}, {s.raw.get('duration_s')} s at {s.raw.get('camera_rate_hz')} Hz" + (f"; {task}" if task else "") +
              f"; omniloc {s.version}"
              + ("; errors over the frames answered" if answered else "") + (f"; {first}" if first else "")
              + ("; 'against the limit': the RMSE over the Cramer-Rao bound of the same frames (1x is the limit), with the share of frames "
                 "the bound covers" if bounded else ""))
    limit.run_table(rep, run)
    for r in s.robots:
        rec = r.get("recovery")
        if isinstance(rec, dict) and rec:
            rt = obj(rec.get("recovery_time_s") or {})
            after = obj(rec.get("after_recovery") or {})
            timed = "recovery_time_s" in rec

            def none(v: JSON) -> str:
                return "none recovered" if v is None and timed else fnum(number(v), 2)
            rep.table(["robot", "kidnaps", "recovered", "false", "mirrored", "median s", "max s", "after: mean x cm", "mean y cm"],
                      [[f"r{r['robot']}", str(rec.get("episodes", "-")), str(rec.get("recovered", "-")), str(rec.get("false_recoveries", "-")),
                        str(rec.get("mirrored", "-")), none(rt.get("median")), none(rt.get("max")), block_cell(after, "x_cm/mean", 2),
                        block_cell(after, "y_cm/mean", 2)]],
                      "kidnap recovery (error under 0.3 m and 0.2 rad for 1 s)")
    if plots:
        plot_run(rep, run, title, link=False)
