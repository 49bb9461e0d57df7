"""The accuracy limit in the report (docs/results.md): beside each score how far it is from the
Cramer-Rao bound ("3.8 cm, 1.32x the limit (bound in 97 % of frames)"), the headline's sentence per
localizer and scenario family, and the run's and the sweep's cells.

Results made before the bound have none of it, and then nothing here writes a word: their report is
what it was. A bound that is null reads "no bound" with its reason, never 0.
"""
from __future__ import annotations

import math
import statistics
from dataclasses import dataclass
from typing import Optional

from omniloc.core import bound
from omniloc.core.aggregate import AggregateGroup, AggregateMetric
from omniloc.core.bound import RobotBound, read_robot_bound
from omniloc.core.jsonvalue import JSONObject
from omniloc.core.rundir import Run
from omniloc.core.stats import fnum
from omniloc.tools.markup import Cell, Writer


def any_bound(runs: list[Run]) -> bool:
    """Whether any of the runs carries the accuracy limit (made by an omniloc that scores it)."""
    return any(r.bound() is not None for r in runs)


@dataclass(frozen=True)
class FamilyLimit:
    """One localizer on one scenario family: the mean over its runs of the efficiency (None where no
    run has a bound), the mean share of frames it covers, the runs with one and without, and the
    scenario of the family whose runs are furthest from the limit with its mean efficiency and how
    far the RMSE is above the bound there (m)."""
    localizer: str
    family: str
    efficiency: Optional[float]
    share: Optional[float]
    runs: int
    without: int
    worst_scenario: Optional[str]
    worst_efficiency: Optional[float]
    worst_gap_m: Optional[float]


def mean(values: list[float]) -> Optional[float]:
    return statistics.fmean(values) if values else None


def family_limits(runs: list[Run]) -> list[FamilyLimit]:
    """Per localizer and scenario family (core.bound.family), the runs' efficiency (robot 0, tracking
    phase where a run has one); only runs that carry the bound count."""
    by: dict[tuple[str, str], list[tuple[Run, RobotBound]]] = {}
    for r in runs:
        rb = r.bound()
        if rb is not None:
            by.setdefault((str(r.localizer), bound.family(r.scenario)), []).append((r, rb))
    out = []
    for (loc, fam), items in sorted(by.items()):
        effs = [rb.efficiency.position for _, rb in items if rb.efficiency is not None and rb.efficiency.position is not None]
        shares = [rb.efficiency.share for _, rb in items if rb.efficiency is not None and rb.efficiency.position is not None
                  and rb.efficiency.share is not None]
        per_scenario: dict[str, list[tuple[float, Optional[float]]]] = {}
        for r, rb in items:
            e = rb.efficiency.position if rb.efficiency else None
            if e is not None:
                gap = rb.error_m - rb.limit_m if rb.error_m is not None and rb.limit_m is not None else None
                per_scenario.setdefault(str(r.scenario), []).append((e, gap))
        worst: Optional[tuple[str, float, Optional[float]]] = None
        for sc, vals in sorted(per_scenario.items()):
            e_mean = statistics.fmean(v for v, _ in vals)
            gaps = [g for _, g in vals if g is not None]
            if worst is None or e_mean > worst[1]:
                worst = (sc, e_mean, mean(gaps))
        out.append(FamilyLimit(localizer=loc, family=fam, efficiency=mean(effs), share=mean(shares), runs=len(effs),
                               without=len(items) - len(effs), worst_scenario=worst[0] if worst else None,
                               worst_efficiency=worst[1] if worst else None, worst_gap_m=worst[2] if worst else None))
    return out


def headline_sentence(runs: list[Run]) -> str:
    """'Against the accuracy limit (...): matching is 1.32x it on tracking (5 runs, bound in 97 % of
    frames) and 1.6x on occlusion, where occlusion_002 leaves most on the table (1.8x, 2.1 cm above
    the bound); ...' ('' for results made before the bound)."""
    fams = family_limits(runs)
    if not fams:
        return ""
    per_loc: dict[str, list[FamilyLimit]] = {}
    for f in fams:
        per_loc.setdefault(f.localizer, []).append(f)
    said = []
    for loc, fs in per_loc.items():
        parts = []
        for f in fs:
            if f.efficiency is None:
                parts.append(f"{bound.NO_BOUND} on {f.family} ({f.without} run{'s' if f.without != 1 else ''})")
                continue
            ratio = bound.ratio_text(f.efficiency) if not parts else bound.ratio_text(f.efficiency).replace(" the limit", "")
            s = (f"{ratio} on {f.family} ({f.runs} run{'s' if f.runs != 1 else ''}, {bound.share_text(f.share)}"
                 + (f"; {f.without} without a bound" if f.without else "") + ")")
            parts.append(s)
        worst = max((f for f in fs if f.worst_efficiency is not None), key=lambda f: f.worst_efficiency or 0.0, default=None)
        text = f"{loc} is " + "; ".join(parts)
        scenarios = {r.scenario for r in runs if str(r.localizer) == loc and r.bound() is not None}
        if worst is not None and worst.worst_scenario is not None and len(scenarios) > 1:
            gap = worst.worst_gap_m
            text += (f"; the scenario that leaves most on the table is {worst.worst_scenario} ({bound.ratio_text(worst.worst_efficiency)}"
                     + (f", {bound.cm_text(gap)} above the bound" if gap is not None and gap > 0 else "") + ")")
        said.append(text)
    return ("Against the accuracy limit (each frame's Cramer-Rao bound at the truth; posterior bound where the run tracks; "
            "1x is the limit): " + ". ".join(said) + ".")


# The modern reference localizer and the efficiency it is built to reach (docs/modern_localizer.md).
REFERENCE_LOCALIZER = "ukf_mh"
REFERENCE_TARGET = 1.3


def reference_sentence(runs: list[Run]) -> str:
    """Where the modern reference stands against its target, per scenario family, with the bound's own
    filter on the same frames beside each family above it (what any filter could have there):
    'The modern reference ukf_mh is within its 1.3x target on tracking (1.08x); above it on occlusion
    (1.36x), where the bound's own filter on the same frames is at 1.23x: ukf_mh is 1.11x what that
    filter has.' ('' without ukf_mh runs that carry the bound; runs with kidnaps are left out.)"""
    # The target is set for tracking (a run with kidnaps is scored over its tracking phase, and the
    # bound's own filter there over the whole run: the two are not on the same frames).
    runs = [r for r in runs if str(r.localizer) == REFERENCE_LOCALIZER and r.summary.robots
            and bound.tracking_phase_block(r.summary.robots[0]) is None]
    fams = [f for f in family_limits(runs) if f.efficiency is not None]
    if not fams:
        return ""
    within = [f for f in fams if (f.efficiency or 0.0) <= REFERENCE_TARGET]
    above = [f for f in fams if (f.efficiency or 0.0) > REFERENCE_TARGET]
    parts = []
    if within:
        parts.append("within it on " + ", ".join(f"{f.family} ({bound.ratio_text(f.efficiency).replace(' the limit', '')})" for f in within))
    for f in above:
        checks = []
        for r in runs:
            if bound.family(r.scenario) != f.family:
                continue
            rb = r.bound()
            if rb is not None and rb.bound is not None and rb.bound.check_position is not None:
                checks.append(rb.bound.check_position)
        eff = bound.ratio_text(f.efficiency).replace(" the limit", "")
        if checks:
            c = statistics.fmean(checks)
            parts.append(f"above it on {f.family} ({eff}), where the bound's own filter on the same frames (true association, the "
                         f"measured noise) is at {c:.2f}x: {REFERENCE_LOCALIZER} is {(f.efficiency or 0.0) / c:.2f}x what that filter has")
        else:
            parts.append(f"above it on {f.family} ({eff}; no check of the bound's own filter in these results)")
    return f"The modern reference {REFERENCE_LOCALIZER} is, against its target of {REFERENCE_TARGET:g}x the limit, " + "; ".join(parts) + "."


def run_cells(robot: JSONObject) -> list[str]:
    """The cell beside a robot block's scores: '3.8 cm, 1.32x the limit (bound in 97 % of frames)'."""
    return [bound.robot_limit_text(read_robot_bound(robot))]


def robot_rows(run: Run) -> list[list[Cell]]:
    """One row per robot block (and its tracking phase) for the run's table of the limit."""
    rows: list[list[Cell]] = []
    for r in run.summary.robots:
        blocks = [(f"r{r.get('robot', 0)}" + (" all frames" if "tracking_phase" in r else ""), r)]
        tp = bound.tracking_phase_block(r)
        if tp is not None:
            blocks.append((f"r{r.get('robot', 0)} tracking phase", tp))
        for name, block in blocks:
            rb = read_robot_bound(block)
            if rb is None:
                continue
            b = rb.bound
            post = b.posterior if b else None
            single = b.single_frame if b else None
            eff = rb.efficiency
            rpe = rb.rpe

            def fig(f: Optional[bound.BoundFigure]) -> str:
                if f is None:
                    return "-"
                if f.position_rms_m is None:
                    return bound.NO_BOUND
                return f"{bound.cm_text(f.position_rms_m)} ({bound.share_text(f.share)})"

            def rpe_text(f: Optional[bound.RpeFigure]) -> str:
                if f is None:
                    return "-"
                if f.translation_rms_m is None:
                    return "no pair"
                return f"{bound.cm_text(f.translation_rms_m)}, {fnum(f.rotation_rms_rad, 4)} rad ({f.pairs} pairs)"
            rows.append([name, bound.robot_limit_text(rb), fig(post), fig(single),
                         bound.ratio_text(eff.heading) if eff and eff.heading is not None else bound.NO_BOUND,
                         (b.no_bound.text() or "none") if b else "-", rpe_text(rpe.frame if rpe else None),
                         rpe_text(rpe.one_second if rpe else None)])
    return rows


LIMIT_HEADER = ["robot", "position RMSE against the limit", "posterior bound", "single-frame bound", "heading against the limit",
                "frames without a bound", "relative pose error over a frame", "over 1 s"]


def run_table(rep: Writer, run: Run) -> None:
    """The run's accuracy limit (nothing for a run made before the bound)."""
    rows = robot_rows(run)
    if not rows:
        return
    rb = run.bound()
    assumptions = rb.bound.assumptions if rb is not None and rb.bound is not None else None
    noise = rb.bound.noise if rb is not None and rb.bound is not None else None
    noise_text = ""
    if noise is not None and noise.bands_m:
        bands = [f"{a:g}-{b:g} m: {bound.cm_text(s)}" for a, b, s in zip(noise.bands_m, noise.bands_m[1:], noise.measured_sigma_m)]
        noise_text = (f" Line points' noise measured at the truth ({noise.points} points, {noise.false_points} false detections left out): "
                      + ", ".join(bands) + ".")
    carried_text = bound.carried_errors_text(rb.bound) if rb is not None and rb.bound is not None else ""
    carried_text = f" {carried_text}" if carried_text else ""
    rep.table(LIMIT_HEADER, rows,
              "the accuracy limit: the position RMSE over the Cramer-Rao bound of the same frames (1x is the limit; posterior bound where "
              "the run tracks), each figure with the share of scored frames it covers; 'no bound' where there is none (no truth, or no "
              "frame with a finite bound), never 0." + noise_text + carried_text + (f" Assumes: {assumptions}" if assumptions else ""))


def aggregate_limit_cell(g: AggregateGroup, phase: bool) -> str:
    """A sweep group's efficiency over seeds: '1.32x (bound 2.9 cm)'; 'no bound' where no run has
    one; '-' for a group of runs made before the bound."""
    eff = g.limit_metric("efficiency_position", phase)
    bm = g.limit_metric("bound_position_rms_m", phase)
    if eff is None and bm is None:
        return "-"
    if eff is None or eff.mean is None:
        return bound.NO_BOUND + no_value_note(eff)
    return f"{eff.mean:.2f}x" + (f" (bound {bound.cm_text(bm.mean)})" if bm is not None and bm.mean is not None else "") + no_value_note(eff)


def no_value_note(m: Optional[AggregateMetric]) -> str:
    return f"; {bound.NO_BOUND} in {m.no_value} of {m.n + m.no_value} runs" if m is not None and m.no_value else ""


def aggregate_share_cell(g: AggregateGroup, phase: bool) -> str:
    """The mean share of frames the group's efficiency covers ('97 %'; '-' where it has none)."""
    m = (g.metrics.get("r0/efficiency/tracking_phase/share") if phase else None) or g.metrics.get("r0/efficiency/share")
    return "-" if m is None or m.mean is None else f"{100.0 * m.mean:.0f} %"


def sweep_has_limit(groups: list[AggregateGroup]) -> bool:
    return any(g.limit_metric("efficiency_position") is not None or g.limit_metric("bound_position_rms_m") is not None for g in groups)



def cm_cell(m: float) -> str:
    """Metres as centimetres with three significant figures ('3.79 cm', '0.561 cm', '138 cm')."""
    return f"{100.0 * m:.3g} cm"


LOCALIZER_HEADER = ["localizer", "scenario family", "runs", "position RMSE / bound", "heading RMSE / bound", "position RMSE", "bound",
                    "frames with a bound", "runs without a bound"]


def localizer_rows(runs: list[Run]) -> list[list[str]]:
    """Per localizer and scenario family: the mean over runs of the position and heading efficiency,
    the mean share of frames they cover, and the runs without a bound (docs/localizers.md's table of
    the built-in localizers on the paper suite is made of these rows; scripts/limit_table.py)."""
    by: dict[tuple[str, str], list[RobotBound]] = {}
    for r in runs:
        rb = r.bound()
        if rb is not None:
            by.setdefault((str(r.localizer), bound.family(r.scenario)), []).append(rb)
    rows = []
    for (loc, fam), rbs in sorted(by.items()):
        effs = [rb.efficiency for rb in rbs if rb.efficiency is not None and rb.efficiency.position is not None]
        pos = mean([e.position for e in effs if e.position is not None])
        head = mean([e.heading for e in effs if e.heading is not None])
        share = mean([e.share for e in effs if e.share is not None])
        # The RMSE and the bound the ratio is of, over the same runs (means of the runs' figures over
        # their frames with both an estimate and a bound), so a ratio is read beside its size.
        err = mean([rb.error_m for rb in rbs if rb.efficiency is not None and rb.efficiency.position is not None and rb.error_m is not None])
        lim = mean([rb.limit_m for rb in rbs if rb.efficiency is not None and rb.efficiency.position is not None and rb.limit_m is not None])
        rows.append([loc, fam, str(len(rbs)), "no bound" if pos is None else f"{pos:.2f}x", "no bound" if head is None else f"{head:.2f}x",
                     "-" if err is None else cm_cell(err), "no bound" if lim is None else cm_cell(lim),
                     "-" if share is None else f"{math.floor(100.0 * share + 1e-9):d} %", str(len(rbs) - len(effs))])
    return rows
