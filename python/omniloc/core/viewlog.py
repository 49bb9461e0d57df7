"""view.jsonl of a run folder (`omniloc run --debug-view`, docs/viewer.md section 4): one JSON object
per (frame, robot), in frame order, every one present: the frame's line points and blobs and the
localizer's covariance, particles and extra points.
"""
from __future__ import annotations

import json
import pathlib
from dataclasses import dataclass
from typing import Optional, Sequence

from omniloc.core.files import InputFileError, json_lines, read_text
from omniloc.core.framedata import Blob, blobs, covariance, pairs, point_list
from omniloc.core.jsonvalue import finite

# How far a time in view.jsonl or a recording may be from frames.csv's (written with 4 decimals).
T_TOLERANCE = 1e-3


@dataclass(frozen=True)
class Debug:
    """One (frame, robot) of the debug data; absent parts are None."""
    line_points: list[tuple[float, float]]
    blobs: list[Blob]
    covariance: Optional[list[float]]  # 9 numbers, row-major (x, y, theta)
    particles: Optional[list[tuple[float, float, float, float]]]  # world frame x, y, theta, weight
    points: Optional[list[tuple[float, float]]]  # world frame


def read_view_jsonl(path: pathlib.Path, ids: Sequence[int], times: dict[int, list[float]]) -> dict[int, list[Debug]]:
    """view.jsonl checked against the run's frames.csv (`ids`: its robots; `times`: each robot's frame
    times): every (frame, robot) once, in frame order, at the frame's time."""
    frames = len(times[ids[0]])
    out: dict[int, list[Optional[Debug]]] = {rid: [None] * frames for rid in ids}
    text = read_text(path, "view.jsonl, one JSON object per frame and robot (docs/viewer.md)")
    last_k = -1
    for n, o in json_lines(text, path, column=True):
        if not isinstance(o, dict):
            raise InputFileError(path, "expected a JSON object {\"k\", \"t\", \"robot\", \"line_points\", ...}", n)
        k, t, rid = o.get("k"), o.get("t"), o.get("robot")
        if not isinstance(k, int) or isinstance(k, bool) or k < 0:
            raise InputFileError(path, "`k`: expected the frame index, an integer >= 0", n)
        if k >= frames:
            raise InputFileError(path, f"`k` {k}: the run has frames 0 to {frames - 1} (frames.csv)", n)
        if k < last_k:
            raise InputFileError(path, f"`k` {k} after {last_k}: expected frame order", n)
        last_k = k
        if not isinstance(rid, int) or isinstance(rid, bool) or rid not in out:
            raise InputFileError(path, f"`robot`: expected one of the run's robots {list(ids)}, got {json.dumps(rid)}", n)
        if not finite(t):
            raise InputFileError(path, "`t`: expected the frame's time in seconds", n)
        if abs(float(t) - times[rid][k]) > T_TOLERANCE:
            raise InputFileError(path, f"`t` {t}: frames.csv has t = {times[rid][k]:.4f} for frame {k} of r{rid}", n)
        if out[rid][k] is not None:
            raise InputFileError(path, f"frame {k} of r{rid} a second time: expected one line per frame and robot", n)
        if "line_points" not in o:
            raise InputFileError(path, "`line_points`: expected a list of [x, y] (robot frame, metres)", n)
        lp = pairs(o["line_points"], path, n, "line_points")
        particles = point_list(o["particles"], 4, path, n, "particles") if o.get("particles") is not None else None
        if particles is not None and any(p[3] < 0 for p in particles):
            raise InputFileError(path, "`particles`: expected weights >= 0", n)
        points = pairs(o["points"], path, n, "points") if o.get("points") is not None else None
        out[rid][k] = Debug(line_points=lp, blobs=blobs(o.get("blobs"), path, n), covariance=covariance(o.get("covariance"), path, n),
                            particles=[(p[0], p[1], p[2], p[3]) for p in particles] if particles is not None else None,
                            points=points)
    for rid in ids:
        for k, d in enumerate(out[rid]):
            if d is None:
                raise InputFileError(path, f"no line for frame {k} of r{rid}: expected one line per frame and robot "
                                           f"({frames} frames x {len(ids)} robots)")
    return {rid: [d for d in out[rid] if d is not None] for rid in ids}
