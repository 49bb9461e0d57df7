"""The viewer's data model: the dicts load.py fills for the page, the input error, and the small
readers every input file shares (docs/viewer.md)."""
from __future__ import annotations

import errno
import math
import os
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple, TypedDict, TypeGuard

from omniloc.core import pathcheck as PC

# frames.csv's own columns (docs/results.md); the others are the localizer's and are shown as given.
FRAMES_COLUMNS = ["t", "robot", "gt_x", "gt_y", "gt_theta", "est_x", "est_y", "est_theta", "err_x", "err_y", "err_theta",
                  "err_pos", "valid", "mode", "camera_ok", "line_points", "match_error", "contact"]
REQUIRED_COLUMNS = ["t", "robot", "est_x", "est_y", "est_theta", "valid", "mode"]
# How far a time in view.jsonl or a recording may be from frames.csv's (written with 4 decimals).
T_TOLERANCE = 1e-3


class ViewInputError(Exception):
    """Bad input: `path` (and `line`, 1-based) and what was expected. str() is one line."""

    def __init__(self, path: Path | str, what: str, line: Optional[int] = None) -> None:
        self.path = str(path)
        self.line = line
        self.what = what
        where = self.path if line is None else f"{self.path} line {line}"
        super().__init__(f"{where}: {what}")


class Pose(TypedDict):
    x: float
    y: float
    theta: float


class Blob(TypedDict):
    colour: str
    kind: str
    bearing: float
    distance: Optional[float]


class Debug(TypedDict):
    """One (frame, robot) of the debug data; absent parts are None."""
    line_points: List[Tuple[float, float]]
    blobs: List[Blob]
    covariance: Optional[List[float]]  # 9 numbers, row-major (x, y, theta)
    particles: Optional[List[Tuple[float, float, float, float]]]  # world frame x, y, theta, weight
    points: Optional[List[Tuple[float, float]]]  # world frame


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
    summary: Dict[str, Any]
    field: Dict[str, Any]
    frames: int
    robots: List[RobotRun]
    events: List[Event]
    debug_source: Optional[str]  # "view.jsonl", "recording" or None
    recording: Optional[str]
    recording_images: bool
    image_every: int
    notes: List[str]


# ----------------------------------------------------------------------------------------- helpers

def _finite(v: Any) -> TypeGuard[float]:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _check_file(path: Path, what: str) -> None:
    """ViewInputError unless `path` is a readable regular file: asked before reading, as reading a
    FIFO blocks for ever. "missing" is kept for a file that is not there (the common case)."""
    why = PC.why_not_readable_file(path)
    if why == os.strerror(errno.ENOENT):
        raise ViewInputError(path, f"missing: expected {what}")
    if why:
        raise ViewInputError(path, f"{why}: expected {what}")


def _read_text(path: Path, what: str) -> str:
    _check_file(path, what)
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise ViewInputError(path, f"unreadable ({e.__class__.__name__}): expected {what}") from None


def _cell(text: str, path: Path, line: int, column: str) -> Optional[float]:
    if text == "":
        return None
    try:
        v = float(text)
    except ValueError:
        raise ViewInputError(path, f"column {column}: expected a number, got {text[:40]!r}", line) from None
    if not math.isfinite(v):
        raise ViewInputError(path, f"column {column}: expected a finite number, got {text[:40]!r}", line)
    return v
