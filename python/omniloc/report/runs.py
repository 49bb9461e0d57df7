"""One run in the report: its table (coverage first, then errors, recovery) and its plot.
"""
from __future__ import annotations

import math
from typing import Any, Optional

from omniloc.core import metrics as M
from omniloc.core import pairing as PR
from omniloc.core import rundir as RD
from omniloc.core import stats as ST
from omniloc.core.events import read_events
from omniloc.core.files import InputFileError
from omniloc.tools import plot
from omniloc.core.pairing import profile_of
from omniloc.core.stats import fnum
from omniloc.core.rundir import Run
from omniloc.report import viewers as V
from omniloc.tools.markup import Writer


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
                   + (" (shaded: carried, blind or recovering, left out of the tracking phase)" if any("tracking_phase" in r for r in run.summary.get("robots", [])) else ""))
    if link:
        V.line(rep, run, own=True, title=run_title(run))


def params_text(params: Any) -> Any:
    """A sweep's parameters of a run ('occlusion={"fraction":0.5}') as code: configuration keys are
    what a reader writes in a sweep file, not prose."""
    return f"`{params}`" if params and params != "default" else (params or "")


def run_title(run: Run, params: Any = None, name: Optional[str] = None) -> Any:
    """'scenario / localizer / params / seed N (profile)'; name: the sweep's row name of the localizer
    (its label: two configurations of one localizer type in a sweep, e.g. mcl and mcl_as_published)."""
    s = run.summary
    parts = [s["scenario"], name or s["localizer"]] + ([params_text(params)] if params and params != "default" else []) + [f"seed {s['seed']}"]
    if ((s.get("omniloc") or {}).get("replay") or {}).get("recorded_with") == "not omniloc":
        return " / ".join(str(p) for p in parts) + " (a log not made by omniloc: no noise profile)"
    prof = profile_of(run)
    return " / ".join(str(p) for p in parts) + (f" ({prof} profile)" if prof != PR.SCENARIO_DEFAULT_PROFILE else "")


# Position error statistics of a run's table (summary.json position_m): the mean is the typical
# error, the RMSE weighs the large ones more; a run from before position_m.mean shows "-".
POSITION_COLS = ["position mean m", "position RMSE m", "position p95 m"]


def block_cell(block: Any, path: Any, digits: int) -> Any:
    """A statistic of one summary.json block: its value; where it is null, the block's why_null in
    short ("no estimate", "no kidnap recovered"); "-" where the block lacks it (an older run)."""
    found, v = RD.find(block or {}, path)
    if found and v is None:
        why = (block or {}).get("why_null") or ""
        return why if why and not why.startswith(M.NO_ESTIMATE) else M.NO_ESTIMATE
    return fnum(v if ST.is_number(v) else None, digits)


def position_cells(block: Any) -> Any:
    return [block_cell(block, f"position_m/{k}", 3) for k in ("mean", "rmse", "p95")]


def coverage_cells(block: Any, key: Any, with_answered: Any) -> Any:
    """The share of the block's frames within the headline threshold and the share answered."""
    return ([M.percent((block.get("recall") or {}).get(key))] if key else []) + ([M.percent(block.get("valid_fraction"))] if with_answered else [])


def first_fix_text(s: Any, key: Any) -> Any:
    """'robot 0: first estimate at 0.03 s, first within 25 cm / 10 deg at 0.50 s' (never: 'never')."""
    parts = []
    for r in s.get("robots", []):
        if "first_estimate_s" not in r and "first_within_s" not in r:
            continue
        t = lambda k: "never" if r.get(k) is None else f"at {r[k]:.2f} s"
        parts.append(f"robot {r.get('robot', 0)}: first estimate {t('first_estimate_s')}"
                     + (f", first within {M.recall_label(key)} {t('first_within_s')}" if key else ""))
    return "; ".join(parts)


def report_run(rep: Writer, run: Run, plots: bool, params: Any = None, note: Any = None, name: Optional[str] = None) -> None:
    s = run.summary
    title = run_title(run, params, name) + (f" ({note})" if note else "")
    rep.heading(f"Run {title}", 3)
    V.line(rep, run, own=plots, title=title)  # its viewer page (a report of many runs: the plotted ones)
    rows = []
    key = run.headline
    answered = any("valid_fraction" in r for r in s.get("robots", []))
    for r in s.get("robots", []):
        rows.append([f"r{r['robot']}" + (" all frames" if "tracking_phase" in r else "")] + coverage_cells(r, key, answered) +
                    [block_cell(r, f"{a}/{st}", 3) for a, st in M.TABLE_KEYS] + position_cells(r) + [r.get("frames", "-")])
        if "tracking_phase" in r:
            tp = r["tracking_phase"]
            rows.append([f"r{r['robot']} tracking phase"] + coverage_cells(tp, key, answered) + [block_cell(tp, f"{a}/{st}", 3) for a, st in M.TABLE_KEYS]
                        + position_cells(tp) + [tp.get("frames", "-")])
    task = PR.start_pose_text(run.start_pose_given)
    first = first_fix_text(s, key)
    rep.table(["robot"] + ([f"within {M.recall_label(key)}"] if key else []) + (["answered"] if answered else []) + M.TABLE_COLS + POSITION_COLS + ["frames"], rows,
              f"noise profile {s.get('noise_profile')}, {s.get('duration_s')} s at {s.get('camera_rate_hz')} Hz" + (f"; {task}" if task else "") +
              f"; omniloc {(s.get('omniloc') or {}).get('version', 'unrecorded')}"
              + ("; errors over the frames answered" if answered else "") + (f"; {first}" if first else ""))
    for r in s.get("robots", []):
        rec = r.get("recovery")
        if rec:
            rt = rec.get("recovery_time_s") or {}
            after = rec.get("after_recovery") or {}
            none = lambda v: "none recovered" if v is None and "recovery_time_s" in rec else fnum(v, 2)
            rep.table(["robot", "kidnaps", "recovered", "false", "mirrored", "median s", "max s", "after: mean x cm", "mean y cm"],
                      [[f"r{r['robot']}", rec.get("episodes", "-"), rec.get("recovered", "-"), rec.get("false_recoveries", "-"), rec.get("mirrored", "-"),
                        none(rt.get("median")), none(rt.get("max")), block_cell(after, "x_cm/mean", 2), block_cell(after, "y_cm/mean", 2)]],
                      "kidnap recovery (error under 0.3 m and 0.2 rad for 1 s)")
    if plots:
        plot_run(rep, run, title, link=False)
