"""What one frame's perception holds where view.jsonl and a recording's frames store it (docs/viewer.md,
docs/recording.md): line points and other point lists, blobs (olp/1 frame.blobs), a covariance.
Each parser takes the raw JSON of one key and raises InputFileError naming the file, the line and
the key where the value is not what the format says.
"""
from __future__ import annotations

import json
import math
import pathlib
from dataclasses import dataclass
from typing import Optional, cast

from omniloc.core.files import InputFileError
from omniloc.core.jsonvalue import JSON, finite


@dataclass(frozen=True)
class Blob:
    """A coloured region seen in a frame: its bearing (rad, robot frame) and distance (m) where known."""
    colour: str
    kind: str
    bearing: float
    distance: Optional[float]


def point_list(v: JSON, width: int, path: pathlib.Path, line: int, key: str) -> list[tuple[float, ...]]:
    """`key`'s value as points of `width` finite numbers each ([x, y], or [x, y, theta, weight])."""
    what = f"`{key}`: expected a list of [{', '.join(['x', 'y', 'theta', 'weight'][:width])}] number lists"
    if not isinstance(v, list):
        raise InputFileError(path, what, line)
    # The common case, a well-formed list, checked in bulk (a 60 s run's view.jsonl has some 150 000
    # points); the loop below names the first bad point otherwise.
    if all(type(p) is list and len(p) == width for p in v):
        flat = [x for p in v if isinstance(p, list) for x in p]
        if set(map(type, flat)) <= {int, float}:  # bool is not: a JSON true is no number
            xs = cast(list[float], flat)
            if all(map(math.isfinite, xs)):
                return [tuple(map(float, cast(list[float], p))) for p in v]
    out: list[tuple[float, ...]] = []
    for p in v:
        if not isinstance(p, list) or len(p) != width or not all(finite(x) for x in p):
            raise InputFileError(path, what + f", got {json.dumps(p)[:60]}", line)
        out.append(tuple(float(x) for x in p if finite(x)))
    return out


def pairs(v: JSON, path: pathlib.Path, line: int, key: str) -> list[tuple[float, float]]:
    """`key`'s value as [x, y] points."""
    return [(p[0], p[1]) for p in point_list(v, 2, path, line, key)]


def blobs(v: JSON, path: pathlib.Path, line: int) -> list[Blob]:
    """The `blobs` of a frame (olp/1 frame.blobs); none where the key is null or absent."""
    if v is None:
        return []
    if not isinstance(v, list):
        raise InputFileError(path, "`blobs`: expected a list of olp/1 blob objects", line)
    out: list[Blob] = []
    for b in v:
        bearing = b.get("bearing") if isinstance(b, dict) else None
        if not isinstance(b, dict) or not finite(bearing):
            raise InputFileError(path, "`blobs`: expected objects with a number `bearing` (olp/1 frame.blobs)", line)
        d = b.get("distance")
        if d is not None and not finite(d):
            raise InputFileError(path, "`blobs`: expected `distance` a number or null", line)
        out.append(Blob(colour=str(b.get("colour", "")), kind=str(b.get("kind", "region")), bearing=float(bearing),
                        distance=None if d is None else float(d)))
    return out


def covariance(v: JSON, path: pathlib.Path, line: int) -> Optional[list[float]]:
    """A pose covariance (x, y, theta; m^2, rad^2) as 9 numbers row-major, from 3 rows of 3 or 9 numbers."""
    if v is None:
        return None
    what = "`covariance`: expected 3 rows of 3 numbers (x, y, theta; m^2, rad^2) or 9 numbers row-major"
    flat: list[JSON]
    if isinstance(v, list) and len(v) == 3 and all(isinstance(r, list) and len(r) == 3 for r in v):
        flat = [x for r in v if isinstance(r, list) for x in r]
    elif isinstance(v, list) and len(v) == 9:
        flat = list(v)
    else:
        raise InputFileError(path, what, line)
    out = [float(x) for x in flat if finite(x)]
    if len(out) != len(flat):
        raise InputFileError(path, what + " (finite)", line)
    return out
