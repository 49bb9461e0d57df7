"""The accuracy limit of a run as summary.json and frames.csv carry it (docs/results.md): the
Cramer-Rao bound per frame (single frame, and the posterior bound of tracking), the efficiency
(RMSE / bound) and the relative pose error.

A bound that does not exist is None, never 0: a run made before omniloc scored the bound has no
"bound" block (read_robot_bound returns None), a run without truth or whose frames all lack a finite
bound has nulls with a reason (why_null, no_bound.why). Every figure here carries the share of
frames it covers, and every text made of one says it (limit_text).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Optional

from omniloc.core.jsonvalue import JSON, JSONObject, integer, number, numbers, obj, text

# frames.csv's bound columns: single-frame and posterior bound on the position (m) and heading
# (rad) of that frame, empty where the frame has no finite bound.
FRAME_COLUMNS = ["bound_pos_m", "bound_heading_rad", "pbound_pos_m", "pbound_heading_rad"]

# The summary.json blocks this module reads beside a robot's errors.
BLOCKS = ("bound", "efficiency", "efficiency_single_frame", "rpe")

# What a statistic of the bound reads as where it has no value (the counterpart of "no estimate").
NO_BOUND = "no bound"


@dataclass(frozen=True)
class BoundFigure:
    """One bound over a run's scored frames (summary.json bound.single_frame / bound.posterior): the
    RMS over frames of the per-frame bound on position (m) and heading (rad), None where no frame
    has a finite one; the frames with a finite bound and their share of the scored frames."""
    position_rms_m: Optional[float]
    heading_rms_rad: Optional[float]
    frames: int
    share: Optional[float]

    @staticmethod
    def from_json(raw: JSON) -> Optional[BoundFigure]:
        b = obj(raw)
        if not b:
            return None
        return BoundFigure(position_rms_m=number(b.get("position_rms_m")), heading_rms_rad=number(b.get("heading_rms_rad")),
                           frames=integer(b.get("frames")) or 0, share=number(b.get("share")))


@dataclass(frozen=True)
class NoBound:
    """The scored frames without a finite bound, and how many for each reason ("no points",
    "points on one line": unbounded along it, ...)."""
    frames: int
    why: dict[str, int]

    @staticmethod
    def from_json(raw: JSON) -> NoBound:
        b = obj(raw)
        why: dict[str, int] = {}
        for k, v in obj(b.get("why")).items():
            n = integer(v)
            if n is not None:
                why[k] = n
        return NoBound(frames=integer(b.get("frames")) or 0, why=why)

    def text(self) -> str:
        """'12 frames without a bound: 10 no points, 2 points on one line' ('' when there are none)."""
        if not self.frames:
            return ""
        reasons = ", ".join(f"{n} {k}" for k, n in sorted(self.why.items(), key=lambda kv: (-kv[1], kv[0])) if n)
        return f"{self.frames} frame{'s' if self.frames != 1 else ''} without a bound" + (f": {reasons}" if reasons else "")


@dataclass(frozen=True)
class Noise:
    """The line points' noise the bound assumes: per range band (bands_m holds the bands' edges) the
    sigma measured from the run's residuals at the truth, the declared profile's beside it (None
    where the profile declares none), the points used and the false detections left out."""
    bands_m: list[float]
    measured_sigma_m: list[Optional[float]]
    declared_sigma_m: Optional[list[Optional[float]]]
    points: int
    false_points: int
    common_mode: JSONObject

    @staticmethod
    def from_json(raw: JSON) -> Optional[Noise]:
        n = obj(raw)
        if not n:
            return None
        declared = n.get("declared_sigma_m")
        return Noise(bands_m=numbers(n.get("bands_m")) or [], measured_sigma_m=optional_numbers(n.get("measured_sigma_m")),
                     declared_sigma_m=optional_numbers(declared) if isinstance(declared, list) else None,
                     points=integer(n.get("points")) or 0, false_points=integer(n.get("false_points")) or 0,
                     common_mode=obj(n.get("common_mode")))


@dataclass(frozen=True)
class Bound:
    """summary.json's "bound" block of one robot. `carried_share`: the share of each frame's error the
    posterior bound carries to the next frames (measured from the run; 0 where it took the frames
    as independent; None for a run scored before the bound carried errors); `posterior_white`: the
    posterior bound with the frames taken as independent, beside for comparison; `check_position`:
    the bound's own filter on the run's data (true association, the measured noise) against the
    posterior bound, position RMSE / bound (None where the run has no such check)."""
    single_frame: Optional[BoundFigure]
    posterior: Optional[BoundFigure]
    no_bound: NoBound
    noise: Optional[Noise]
    assumptions: Optional[str]
    carried_share: Optional[float] = None
    posterior_white: Optional[BoundFigure] = None
    check_position: Optional[float] = None

    @staticmethod
    def from_json(raw: JSON) -> Bound:
        b = obj(raw)
        post = obj(b.get("posterior"))
        carried = obj(post.get("carried_errors"))
        return Bound(single_frame=BoundFigure.from_json(b.get("single_frame")), posterior=BoundFigure.from_json(b.get("posterior")),
                     no_bound=NoBound.from_json(b.get("no_bound")), noise=Noise.from_json(b.get("noise")),
                     assumptions=text(b.get("assumptions")), carried_share=number(carried.get("share")),
                     posterior_white=BoundFigure.from_json(b.get("posterior_white")),
                     check_position=number(obj(post.get("check")).get("position_ratio")))


@dataclass(frozen=True)
class Efficiency:
    """RMSE / bound (summary.json "efficiency" against the posterior bound where the run tracks,
    "efficiency_single_frame" against the single-frame one): 1 is the limit, 1.3 is 30 % above it.
    None with why_null where undefined (no bound, no estimate). frames / share: the frames both the
    error and the bound cover; rmse_m and bound_rms_m: the position RMSE and the bound's RMS over
    those frames (None in a block that does not give them)."""
    position: Optional[float]
    heading: Optional[float]
    against: Optional[str]
    frames: int
    share: Optional[float]
    why_null: Optional[str]
    rmse_m: Optional[float] = None
    bound_rms_m: Optional[float] = None

    @staticmethod
    def from_json(raw: JSON) -> Optional[Efficiency]:
        e = obj(raw)
        if not e:
            return None
        return Efficiency(position=number(e.get("position")), heading=number(e.get("heading")), against=text(e.get("against")),
                          frames=integer(e.get("frames")) or 0, share=number(e.get("share")), why_null=text(e.get("why_null")),
                          rmse_m=number(e.get("rmse_m")), bound_rms_m=number(e.get("bound_rms_m")))


@dataclass(frozen=True)
class RpeFigure:
    """Relative pose error over one step (TUM / evo RPE, no alignment): RMS of the translation (m)
    and rotation (rad) errors over `pairs` pairs of frames."""
    translation_rms_m: Optional[float]
    rotation_rms_rad: Optional[float]
    pairs: int

    @staticmethod
    def from_json(raw: JSON) -> Optional[RpeFigure]:
        r = obj(raw)
        if not r:
            return None
        return RpeFigure(translation_rms_m=number(r.get("translation_rms_m")), rotation_rms_rad=number(r.get("rotation_rms_rad")),
                         pairs=integer(r.get("pairs")) or 0)


@dataclass(frozen=True)
class Rpe:
    """summary.json's "rpe": over one frame and over one second."""
    frame: Optional[RpeFigure]
    one_second: Optional[RpeFigure]

    @staticmethod
    def from_json(raw: JSON) -> Optional[Rpe]:
        r = obj(raw)
        if not r:
            return None
        return Rpe(frame=RpeFigure.from_json(r.get("frame")), one_second=RpeFigure.from_json(r.get("1s")))


@dataclass(frozen=True)
class RobotBound:
    """What one robot block of summary.json says about the limit: its bound, efficiencies and RPE
    (each None where the block lacks it), and its position RMSE (m) for the texts."""
    bound: Optional[Bound]
    efficiency: Optional[Efficiency]
    efficiency_single_frame: Optional[Efficiency]
    rpe: Optional[Rpe]
    rmse_m: Optional[float]

    @property
    def error_m(self) -> Optional[float]:
        """The position RMSE the efficiency is of: over the frames with both an estimate and a bound
        where the efficiency block gives it, else the run's RMSE over its answered frames."""
        if self.efficiency is not None and self.efficiency.rmse_m is not None:
            return self.efficiency.rmse_m
        return self.rmse_m

    @property
    def limit_m(self) -> Optional[float]:
        """The position bound the efficiency is taken against (posterior or single frame), over the
        efficiency's frames where its block gives it."""
        if self.efficiency is not None and self.efficiency.bound_rms_m is not None:
            return self.efficiency.bound_rms_m
        if self.bound is None:
            return None
        against = self.efficiency.against if self.efficiency else None
        fig = self.bound.single_frame if against == "single_frame" else self.bound.posterior or self.bound.single_frame
        return fig.position_rms_m if fig else None

    @property
    def limit_share(self) -> Optional[float]:
        """The share of frames the efficiency covers (else the bound's)."""
        if self.efficiency is not None and self.efficiency.share is not None:
            return self.efficiency.share
        if self.bound is None:
            return None
        fig = self.bound.posterior or self.bound.single_frame
        return fig.share if fig else None


def has_bound(block: JSONObject) -> bool:
    """Whether a robot block carries any of the bound's blocks (a run made by an omniloc that scores it)."""
    return any(k in block for k in BLOCKS)


def read_robot_bound(block: JSONObject) -> Optional[RobotBound]:
    """The bound of one robot block (or of its tracking_phase block); None for a block from before the bound."""
    if not has_bound(block):
        return None
    bound = block.get("bound")
    return RobotBound(bound=Bound.from_json(bound) if isinstance(bound, dict) else None,
                      efficiency=Efficiency.from_json(block.get("efficiency")),
                      efficiency_single_frame=Efficiency.from_json(block.get("efficiency_single_frame")),
                      rpe=Rpe.from_json(block.get("rpe")), rmse_m=number(obj(block.get("position_m")).get("rmse")))


def tracking_phase_block(robot: JSONObject) -> Optional[JSONObject]:
    """The robot block of a run with kidnaps or covers as its tracking phase sees the limit: omniloc
    writes that phase's efficiencies inside the whole run's (efficiency.tracking_phase,
    efficiency_single_frame.tracking_phase) and its errors in tracking_phase; the bound and the RPE
    are the run's. None for a run without a tracking phase or without the bound."""
    tp = robot.get("tracking_phase")
    eff = robot.get("efficiency")
    if not isinstance(tp, dict) or not isinstance(eff, dict) or not isinstance(eff.get("tracking_phase"), dict):
        return None
    single = robot.get("efficiency_single_frame")
    block: JSONObject = {"bound": robot.get("bound"), "efficiency": eff["tracking_phase"], "rpe": robot.get("rpe"),
                         "position_m": tp.get("position_m")}
    if isinstance(single, dict) and isinstance(single.get("tracking_phase"), dict):
        block["efficiency_single_frame"] = single["tracking_phase"]
    return block


def robot_bound(robot: Optional[JSONObject], phase: str = "tracking") -> Optional[RobotBound]:
    """A robot block's bound, over its tracking phase where it has one (runs with kidnaps or covers:
    tracking_phase_block), as Run.lookup reads the other statistics."""
    if robot is None:
        return None
    tp = tracking_phase_block(robot) if phase == "tracking" else None
    return read_robot_bound(tp if tp is not None else robot)


def optional_numbers(v: JSON) -> list[Optional[float]]:
    """An array of numbers and nulls (a band without points has no sigma)."""
    return [number(x) for x in v] if isinstance(v, list) else []


def is_bound_metric(path: str) -> bool:
    """Whether a metric path (summary.json's or aggregate.csv's, with or without "r<N>/") is one of
    the bound's: its null means "no bound", not "no estimate"."""
    parts = path.strip("/").split("/")
    if parts and re.fullmatch(r"r\d+", parts[0]):
        parts = parts[1:]
    if parts and parts[0] == "tracking_phase":
        parts = parts[1:]
    return bool(parts) and (parts[0] in ("bound", "efficiency", "efficiency_single_frame") or parts[0] in AGGREGATE_KEYS)


# The per-group figures of aggregate.json that batch/aggregate.cpp adds for the bound (beside the
# flattened summary.json metrics, which hold the same under r0/bound/... and r0/efficiency/...).
AGGREGATE_KEYS = ("bound_position_rms_m", "efficiency_position")


def null_text(path: str, why: Optional[str] = None) -> str:
    """What a null statistic reads as: "no estimate" where the reason is a missing estimate,
    "no bound" for the bound's metrics otherwise."""
    if why and why.startswith("no estimate"):
        return "no estimate"
    return NO_BOUND if is_bound_metric(path) else "no estimate"


def ratio_text(eff: Optional[float]) -> str:
    """'1.3x the limit'; 'no bound' where there is none."""
    if eff is None:
        return NO_BOUND
    return f"{eff:.2f}x the limit" if eff < 2 else f"{eff:.1f}x the limit" if eff < 10 else f"{eff:.0f}x the limit"


def share_text(share: Optional[float]) -> str:
    """'bound in 97 % of frames' (the share of scored frames the figure covers)."""
    if share is None:
        return "bound in no frame"
    # Rounded down: 99.6 % must not read as every frame.
    return f"bound in {math.floor(100.0 * share + 1e-9):d} % of frames"


def cm_text(v_m: Optional[float]) -> str:
    return "-" if v_m is None else f"{100.0 * v_m:.2g} cm" if v_m < 0.1 else f"{100.0 * v_m:.0f} cm"


def carried_errors_text(b: Bound) -> str:
    """What the posterior bound carries from frame to frame, with the bound the frames would give taken
    as independent: '' for a run that carried nothing or was scored before the bound carried errors."""
    if b.carried_share is None or b.carried_share <= 0:
        return ""
    white = b.posterior_white.position_rms_m if b.posterior_white is not None else None
    return (f"The posterior bound carries {b.carried_share:.2f} of each frame's error variance to the next frames (measured at the "
            "truth: the same lines at nearly the same pixels)"
            + (f"; taking the frames as independent it would be {cm_text(white)}" if white is not None else "") + ".")


def limit_text(rmse_m: Optional[float], eff: Optional[float], share: Optional[float], why: Optional[str] = None) -> str:
    """'3.8 cm, 1.3x the limit (bound in 97 % of frames)': a position RMSE beside how far it is from
    the bound; 'no bound' (with the reason where given) where the efficiency is null."""
    head = cm_text(rmse_m)
    if eff is None:
        return f"{head}, {NO_BOUND}" + (f" ({why})" if why and why != NO_BOUND else "")
    return f"{head}, {ratio_text(eff)} ({share_text(share)})"


def robot_limit_text(rb: Optional[RobotBound]) -> str:
    """limit_text of one robot block's position RMSE and efficiency; '' for a block from before the bound."""
    if rb is None:
        return ""
    e = rb.efficiency
    if e is None:
        return limit_text(rb.rmse_m, None, None, NO_BOUND)
    return limit_text(rb.error_m, e.position, e.share, e.why_null)


_FAMILY = re.compile(r"^(.*?)(?:_\d.*)?$")


def family(scenario: Optional[str]) -> str:
    """A scenario's family: its name without a numbered suffix (occlusion_002 -> occlusion,
    lighting_002_sun -> lighting), so variants of one experiment are read together."""
    m = _FAMILY.match(scenario or "")
    name = m.group(1) if m else ""
    return name or (scenario or "unnamed")
