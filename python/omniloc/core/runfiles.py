"""A run folder's per-frame files read strictly (the run viewer draws them; docs/results.md): frames.csv
as numbers per robot, the TUM trajectories gt.tum / est.tum, and field.json checked. Every problem
raises InputFileError naming the file (and line) and what was expected. The report reads frames.csv
leniently, as text (omniloc.core.rundir.Run.frames).
"""
from __future__ import annotations

import csv
import math
import pathlib
from dataclasses import dataclass
from typing import Optional

from omniloc.core.bound import FRAME_COLUMNS as BOUND_COLUMNS
from omniloc.core.files import InputFileError, read_text
from omniloc.core.jsonvalue import JSONObject, finite

# frames.csv's own columns (docs/results.md); the others are the localizer's and are shown as given.
FRAMES_COLUMNS = ["t", "robot", "gt_x", "gt_y", "gt_theta", "est_x", "est_y", "est_theta", "err_x", "err_y", "err_theta",
                  "err_pos", "valid", "mode", "camera_ok", "line_points", "match_error", "contact"] + BOUND_COLUMNS
REQUIRED_COLUMNS = ["t", "robot", "est_x", "est_y", "est_theta", "valid", "mode"]


@dataclass(frozen=True)
class Pose:
    """A pose in the world frame: metres, radians."""
    x: float
    y: float
    theta: float


def tum_yaw(qz: float, qw: float) -> float:
    """Yaw (rad, in (-pi, pi]) of a rotation about z given as the quaternion (0, 0, qz, qw)."""
    return math.atan2(2.0 * qw * qz, qw * qw - qz * qz)


def read_tum(path: pathlib.Path) -> list[tuple[float, Pose]]:
    """TUM rows `t x y z qx qy qz qw` as (t, pose); yaw from the quaternion."""
    rows: list[tuple[float, Pose]] = []
    for n, line in enumerate(read_text(path, "a TUM trajectory (t x y z qx qy qz qw per line)").splitlines(), 1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        parts = s.split()
        if len(parts) != 8:
            raise InputFileError(path, f"expected 8 numbers `t x y z qx qy qz qw`, got {len(parts)} fields", n)
        try:
            v = [float(p) for p in parts]
        except ValueError:
            raise InputFileError(path, "expected 8 numbers `t x y z qx qy qz qw`, got a field that is not a number", n) from None
        if not all(math.isfinite(x) for x in v):
            raise InputFileError(path, "expected 8 finite numbers `t x y z qx qy qz qw`", n)
        rows.append((v[0], Pose(x=v[1], y=v[2], theta=tum_yaw(v[6], v[7]))))
    return rows


@dataclass(frozen=True)
class FrameTable:
    """frames.csv per robot: the robots' ids in the order of first appearance, each robot's columns of
    numbers (None for an empty cell) and modes, and the names of the localizer's own columns."""
    ids: list[int]
    columns: dict[int, dict[str, list[Optional[float]]]]
    modes: dict[int, list[str]]
    extra: list[str]


def read_frame_table(path: pathlib.Path) -> FrameTable:
    """frames.csv as numbers per robot; every robot with the same number of frames."""
    text = read_text(path, "frames.csv of a run folder (docs/results.md)")
    reader = csv.reader(text.splitlines())
    try:
        header = next(reader)
    except StopIteration:
        raise InputFileError(path, "empty: expected a header `t,robot,gt_x,...` and one row per frame and robot") from None
    missing = [c for c in REQUIRED_COLUMNS if c not in header]
    if missing:
        raise InputFileError(path, f"header: expected the columns {', '.join(REQUIRED_COLUMNS)}; missing {', '.join(missing)}", 1)
    extra = [c for c in header if c not in FRAMES_COLUMNS]
    ids: list[int] = []
    cols: dict[int, dict[str, list[Optional[float]]]] = {}
    modes: dict[int, list[str]] = {}
    for n, row in enumerate(reader, 2):
        if not row:
            continue
        if len(row) != len(header):
            raise InputFileError(path, f"expected {len(header)} cells as in the header, got {len(row)}", n)
        cells = dict(zip(header, row))
        try:
            rid = int(cells["robot"])
        except ValueError:
            raise InputFileError(path, f"column robot: expected an integer id, got {cells['robot'][:40]!r}", n) from None
        if rid not in cols:
            ids.append(rid)
            cols[rid] = {c: [] for c in header if c not in ("robot", "mode")}
            modes[rid] = []
        for c, v in cells.items():
            if c in ("robot", "mode"):
                continue
            cols[rid][c].append(number_cell(v, path, n, c))
        if cols[rid]["t"][-1] is None or cols[rid]["est_x"][-1] is None:
            raise InputFileError(path, "expected a time and an estimate in every row", n)
        modes[rid].append(cells["mode"])
    if not ids:
        raise InputFileError(path, "no rows: expected one row per frame and robot")
    counts = {rid: len(modes[rid]) for rid in ids}
    if len(set(counts.values())) != 1:
        raise InputFileError(path, "expected the same number of frames for every robot, got " +
                             ", ".join(f"r{r}: {c}" for r, c in counts.items()))
    return FrameTable(ids=ids, columns=cols, modes=modes, extra=extra)


def check_field(field: JSONObject, path: pathlib.Path) -> None:
    """field.json: the floor's length and width (positive), its margin, and the markings as number lists."""
    for key in ("length", "width"):
        size = field.get(key)
        if not finite(size) or size <= 0:
            raise InputFileError(path, f"`{key}`: expected a positive number (metres)")
    if not finite(field.get("margin", 0)):
        raise InputFileError(path, "`margin`: expected a number (metres)")
    for key, width in (("segments", 4), ("arcs", 5), ("spots", 3), ("goals", 3)):
        v = field.get(key, [])
        if not isinstance(v, list) or not all(isinstance(s, list) and len(s) == width and all(finite(x) for x in s) for s in v):
            raise InputFileError(path, f"`{key}`: expected a list of {width}-number lists")


def number_cell(text: str, path: pathlib.Path, line: int, column: str) -> Optional[float]:
    """A cell of frames.csv as a number: None where empty; InputFileError where not a finite number."""
    if text == "":
        return None
    try:
        v = float(text)
    except ValueError:
        raise InputFileError(path, f"column {column}: expected a number, got {text[:40]!r}", line) from None
    if not math.isfinite(v):
        raise InputFileError(path, f"column {column}: expected a finite number, got {text[:40]!r}", line)
    return v
