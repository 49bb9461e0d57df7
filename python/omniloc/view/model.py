"""The viewer's data model: the dicts load.py fills for the page (docs/viewer.md). The records read
from the run folder (poses, per-frame debug data, events) and the input error are the core's
(omniloc.core.runfiles, viewlog, events, files)."""
from __future__ import annotations

from typing import Dict, List, Optional, TypedDict

from omniloc.core.jsonvalue import JSONObject
from omniloc.core.runfiles import Pose
from omniloc.core.viewlog import Debug


class RobotRun(TypedDict):
    id: int
    radius: float  # footprint radius, metres (config.json; 0.26 when not given)
    t: List[float]
    truth: Optional[List[Pose]]
    estimate: List[Pose]
    est_from_tum: List[bool]  # False: an invalid frame's estimate, from frames.csv
    valid: List[bool]
    mode: List[str]
    camera_ok: List[Optional[bool]]
    line_points: List[Optional[float]]  # frames.csv's count
    match_error: List[Optional[float]]
    err_pos: List[Optional[float]]
    err_theta: List[Optional[float]]
    # The accuracy limit per frame (frames.csv pbound_* where the run has the posterior bound, else
    # bound_*; None where the frame has none); None for a run made before the bound.
    bound_pos: Optional[List[Optional[float]]]
    bound_theta: Optional[List[Optional[float]]]
    bound_kind: Optional[str]  # "posterior", "single frame", or "none" where no frame has a bound
    contact: List[Optional[bool]]
    extra: Dict[str, List[Optional[float]]]  # the localizer's own frames.csv columns
    debug: Optional[List[Debug]]  # per frame
    images: Dict[int, str]  # frame k -> base64 PNG


class Event(TypedDict):
    t: float
    type: str
    robot: Optional[int]
    duration: Optional[float]
    label: str


class RunData(TypedDict):
    title: str
    run_dir: str
    summary: JSONObject
    field: JSONObject
    frames: int
    robots: List[RobotRun]
    events: List[Event]
    debug_source: Optional[str]  # "view.jsonl", "recording" or None
    recording: Optional[str]
    recording_images: bool
    image_every: int
    notes: List[str]
