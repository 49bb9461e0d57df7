"""Writes the viewer page: one self-contained HTML file (no network, no server) holding the run as
JSON and the page's JavaScript and CSS (viewer.js + viewer_controls.js, viewer.css beside this file) inlined.

Size (docs/viewer.md "Size"): poses and per-frame values are JSON numbers at the run files' own
precision; the bulky per-frame point sets are packed as little-endian int16 in base64 (2.7
characters a number instead of about 7 in JSON):
  - line points (robot frame) and extra points (world frame): millimetres;
  - particles: x, y in millimetres, theta in milliradians (wrapped to [-pi, pi)), the weight scaled
    to 0..32767 by the frame's largest weight (for the colour only); at most `max_particles` per
    frame (an even stride through the localizer's list, which keeps its spread), every
    `particles_every`-th frame;
  - the covariance as its 2-sigma position ellipse (semi-axes, angle) and the heading's sigma.
"""
from __future__ import annotations

import array
import base64
import html
import json
import re
import math
import sys
from pathlib import Path
from typing import Dict, Iterable, List, Optional, Sequence, Tuple, TypeVar

from omniloc.core.viewlog import Debug
from omniloc.view.model import RobotRun, RunData

HERE = Path(__file__).resolve().parent
INT16 = 32767


def _num(v: Optional[float], digits: int) -> Optional[float | int]:
    """v rounded to `digits` decimals, as an int when whole (shorter JSON); None stays None."""
    if v is None:
        return None
    r = round(v, digits)
    return int(r) if r == int(r) and abs(r) < 1e15 else r


def _i16(v: float) -> int:
    return max(-INT16, min(INT16, int(round(v))))


def _pack(values: Iterable[int]) -> str:
    a = array.array("h", values)
    if sys.byteorder != "little":
        a.byteswap()
    return base64.b64encode(a.tobytes()).decode("ascii")


def _wrap(theta: float) -> float:
    return (theta + math.pi) % (2 * math.pi) - math.pi


# The page's JSON as it is built: numbers, text, lists and objects of them (json.dumps writes it).
PageJSON = Dict[str, object]
Item = TypeVar("Item")


def _packed_points(per_frame: Sequence[Optional[Sequence[Tuple[float, ...]]]], scale: Sequence[float]) -> PageJSON:
    """{"counts": [points per frame], "data": base64 int16, "width": numbers per point}."""
    counts: List[int] = []
    values: List[int] = []
    for pts in per_frame:
        pts = pts or []
        counts.append(len(pts))
        for p in pts:
            values.extend(_i16(x * s) for x, s in zip(p, scale))
    return {"counts": counts, "data": _pack(values), "width": len(scale)}


def _subsample(items: Sequence[Item], n: int) -> List[Item]:
    """At most n items, an even stride through the list (keeps the spread of a particle set)."""
    if len(items) <= n:
        return list(items)
    if n <= 0:
        return []
    return [items[(i * len(items)) // n] for i in range(n)]


def _particles(debug: Sequence[Debug], max_particles: int, every: int) -> Optional[PageJSON]:
    if not any(d.particles for d in debug) or max_particles <= 0:
        return None
    frames: List[Optional[List[Tuple[float, ...]]]] = []
    for k, d in enumerate(debug):
        ps = d.particles
        if not ps or k % every:
            frames.append(None)
            continue
        wmax = max(p[3] for p in ps) or 1.0
        frames.append([(p[0], p[1], _wrap(p[2]), p[3] / wmax) for p in _subsample(ps, max_particles)])
    return _packed_points(frames, (1000.0, 1000.0, 1000.0, INT16))


def _ellipse(cov: Optional[List[float]]) -> Optional[List[Optional[float | int]]]:
    """[a, b, angle, sigma_theta]: the 2-sigma ellipse of the position block (semi-axes in metres,
    the major axis' angle in rad) and the heading's standard deviation (rad)."""
    if cov is None:
        return None
    a, b, c = cov[0], 0.5 * (cov[1] + cov[3]), cov[4]
    mid, half = 0.5 * (a + c), math.hypot(0.5 * (a - c), b)
    l1, l2 = mid + half, mid - half
    angle = 0.5 * math.atan2(2 * b, a - c)
    return [_num(2 * math.sqrt(max(l1, 0.0)), 5), _num(2 * math.sqrt(max(l2, 0.0)), 5), _num(angle, 4),
            _num(math.sqrt(max(cov[8], 0.0)), 5)]


def robot_json(r: RobotRun, max_particles: int, particles_every: int) -> PageJSON:
    modes: List[str] = []
    for m in r["mode"]:
        if m not in modes:
            modes.append(m)
    out: PageJSON = {
        "id": r["id"], "radius": r["radius"],
        "t": [_num(t, 6) for t in r["t"]],
        "est": [_num(v, 8) for p in r["estimate"] for v in (p.x, p.y, p.theta)],
        "gt": [_num(v, 8) for p in r["truth"] for v in (p.x, p.y, p.theta)] if r["truth"] is not None else None,
        "valid": [int(v) for v in r["valid"]],
        "modes": modes, "mode": [modes.index(m) for m in r["mode"]],
        "camOk": [None if v is None else int(v) for v in r["camera_ok"]],
        "contact": [None if v is None else int(v) for v in r["contact"]],
        "lpCount": [_num(v, 0) for v in r["line_points"]],
        "matchErr": [_num(v, 6) for v in r["match_error"]],
        "errPos": [_num(v, 5) for v in r["err_pos"]],
        "errTh": [_num(v, 5) for v in r["err_theta"]],
        "extra": {k: [_num(v, 9) for v in vs] for k, vs in r["extra"].items()},
        "lp": None, "particles": None, "points": None, "blobs": {}, "cov": None, "images": {str(k): v for k, v in r["images"].items()},
    }
    if r["bound_pos"] is not None:  # a run made before the bound: the page's data as it was
        out["boundPos"] = [_num(v, 5) for v in r["bound_pos"]]
        out["boundTh"] = [_num(v, 5) for v in (r["bound_theta"] or [])]
        out["boundKind"] = r["bound_kind"]
    debug = r["debug"]
    if debug is not None:
        out["lp"] = _packed_points([d.line_points for d in debug], (1000.0, 1000.0))
        if any(d.points for d in debug):
            out["points"] = _packed_points([d.points for d in debug], (1000.0, 1000.0))
        out["particles"] = _particles(debug, max_particles, particles_every)
        out["blobs"] = {str(k): [[b.colour, b.kind, _num(b.bearing, 4), _num(b.distance, 3)] for b in d.blobs]
                        for k, d in enumerate(debug) if d.blobs}
        if any(d.covariance is not None for d in debug):
            out["cov"] = [_ellipse(d.covariance) for d in debug]
    return out


def page_json(run: RunData, max_particles: int, particles_every: int) -> PageJSON:
    s = run["summary"]
    om = s.get("omniloc") if isinstance(s.get("omniloc"), dict) else {}
    return {
        "format": "omniloc-view-page/1",
        "title": run["title"],
        "version": om.get("version") if isinstance(om, dict) else None,
        "field": run["field"],
        "frames": run["frames"],
        "robots": [robot_json(r, max_particles, particles_every) for r in run["robots"]],
        "events": [dict(e) for e in run["events"]],
        "debugSource": run["debug_source"],
        "recording": Path(run["recording"]).name if run["recording"] else None,
        "recordingImages": run["recording_images"],
        "imageEvery": run["image_every"],
        "particlesMax": max_particles,
        "particlesEvery": particles_every,
        "notes": run["notes"],
    }


# The lines of viewer.js that draw the accuracy limit, between "// <bound>" and "// </bound>".
BOUND_JS = re.compile(r"^[ \t]*// <bound>.*?// </bound>\n", re.S | re.M)


def _script_safe(text: str) -> str:
    """JSON or JS that cannot end its <script> element early."""
    return text.replace("<!--", "\\u003c!--").replace("</", "<\\/")


def render(run: RunData, max_particles: int = 100, particles_every: int = 1) -> str:
    data = json.dumps(page_json(run, max_particles, particles_every), separators=(",", ":"), allow_nan=False)
    template = (HERE / "viewer.html").read_text(encoding="utf-8")
    css = (HERE / "viewer.css").read_text(encoding="utf-8")
    # One script in two files (each under 500 lines): viewer.js opens it, viewer_controls.js closes it.
    js = (HERE / "viewer.js").read_text(encoding="utf-8") + (HERE / "viewer_controls.js").read_text(encoding="utf-8")
    if not any(r["bound_pos"] is not None for r in run["robots"]):
        # The bound's drawing only where a robot has one: a run made before the bound gets the page it got before.
        js = BOUND_JS.sub("", js)
    head, rest = template.split("{{DATA}}", 1)
    head = head.replace("{{TITLE}}", html.escape(run["title"])).replace("{{CSS}}", css)
    rest = rest.replace("{{JS}}", _script_safe(js))
    return head + _script_safe(data) + rest
