"""Reference pose of one frame of robot-frame line points on an MSL field, by exhaustive search.

This is deliberately *not* one of omniloc's localizers (no particles, no RPROP, no grid of 1 m
samples): every pose of the floor is scored, (x, y) on a grid of `xy_step` (5 cm) and theta every
`theta_step_deg` (1 degree), then the best poses are refined locally. It gives the reference ("truth")
pose of real frames (data/real/nubot/, scripts/nubot_to_recording.py) whose true pose nobody measured.

Score of a pose (x, y, theta): the mean over the points of min(d_i, c)^2, d_i the distance of point i
(moved into the world by the pose) to the nearest marking's centre line (straight lines, the centre
circle and corner arcs, and the filled penalty / centre spots, as omniloc's distance map holds it,
core/field.cpp and clients/python/omniloc_client.py Field.distance_to_lines). The truncation at c
(0.30 m) makes the measure robust: a point that belongs to nothing (a robot's white part, a badly
calibrated far point) costs at most c^2 and cannot drag the pose. The *residual* reported is
sqrt(score) in metres (the RMS of the truncated distances).

How the exhaustive stage is made fast: for a fixed theta the score over all (x, y) on the grid is the
cross-correlation of the truncated cost map with an image of the rotated points, computed with FFTs
(one pair of 2-D FFTs per theta: 360 thetas in about 10 s with numpy). Points are rounded to the
grid (at most 3.5 cm off at 5 cm), so the stage is followed by a local pattern search on a 1 cm
distance map (bilinear) and a last polish on exact distances.

The MSL field is point-symmetric: (x, y, theta) and its twin (-x, -y, theta + pi) score the same.
`search()` returns the reference (the twin with x >= 0 is reported, ties by y >= 0), the twin, and the
best *distinct* pose: the lowest-scoring refined pose more than `distinct_m` (0.5 m) or `distinct_deg`
(20 degrees) away from both; its residual against the reference's is the frame's ambiguity.

Standard library and numpy only. Units: metres and radians; world frame of docs/protocol.md
(origin at the centre spot, x towards the goal at x > 0, y left, theta anticlockwise); robot frame
x forward, y left.

    scripts/nubot_reference_pose.py POINTS.json [--field msl2012]   # POINTS.json: [[x, y], ...]
"""
from __future__ import annotations

import json
import math
import os
import sys
import time
from typing import Optional, Sequence, TypedDict, Union

import numpy as np

from omniloc.core import paths
from omniloc.core.jsonvalue import JSON, JSONObject, lst, number, obj


REPO = str(paths.ROOT)


class Markings(TypedDict):
    """A field's markings (a recording's "field_markings"): its size, and the centre lines of its
    segments [x1, y1, x2, y2], arcs [cx, cy, r, start, sweep] and filled spots [cx, cy, r] (metres,
    radians)."""
    name: str
    length: float
    width: float
    margin: float
    segments: list[list[float]]
    arcs: list[list[float]]
    spots: list[list[float]]


Pose = Sequence[float]  # x, y (m), theta (rad)


def floats(v: JSON) -> list[float]:
    """A marking's numbers (ValueError where one is not a number)."""
    return [float(x) if isinstance(x, (int, float)) else float(str(x)) for x in lst(v)]


def field_markings(field: Union[str, JSON]) -> Markings:
    """Markings of a field: a preset name (data/fields/<name>.json), or a field object as a scenario's
    "field" holds it (type "msl" only, as core/field.cpp builds it: touch, goal and centre lines,
    centre circle, penalty and goal areas, penalty and centre spots, corner arcs), or an object that
    already has "segments" (the "field_markings" of an omniloc recording). Returns a dict with
    length, width, margin, segments [x1, y1, x2, y2], arcs [cx, cy, r, start, sweep], spots [cx, cy, r]."""
    f: JSONObject
    if isinstance(field, str):
        with open(os.path.join(REPO, "data", "fields", field + ".json"), encoding="utf-8") as fh:
            f = obj(json.load(fh))
        name = field
    else:
        f = dict(obj(field))
        name = str(f.get("name", "custom"))
    if "segments" in f and "type" not in f:  # already markings
        return Markings(name=str(f.get("name", name)), length=size(f["length"]), width=size(f["width"]),
                        margin=size(f.get("margin", 1.0)), segments=[floats(s) for s in lst(f["segments"])],
                        arcs=[floats(a) for a in lst(f.get("arcs", []))], spots=[floats(s) for s in lst(f.get("spots", []))])
    if f.get("type", "msl") != "msl":
        raise ValueError("only MSL fields (type msl) are supported")
    L, W = size(f.get("length", 18.0)), size(f.get("width", 12.0))
    hx, hy = 0.5 * L, 0.5 * W
    circle_r = size(f.get("centre_circle_radius", 2.0))
    corner_r = size(f.get("corner_arc_radius", 0.75))
    pen_mark = size(f.get("penalty_mark_distance", 3.0))
    spot_r = size(f.get("spot_radius", 0.075))
    raw_pa = f.get("penalty_area", {})
    pa = obj(raw_pa) if raw_pa is not None else None
    ga = obj(f.get("goal_area", {}) or {})
    seg: list[list[float]] = []
    arcs: list[list[float]] = []
    spots: list[list[float]] = []
    seg += [[-hx, -hy, hx, -hy], [-hx, hy, hx, hy], [-hx, -hy, -hx, hy], [hx, -hy, hx, hy], [0.0, -hy, 0.0, hy]]
    arcs.append([0.0, 0.0, circle_r, 0.0, 2 * math.pi])
    ga_d, ga_w = size(ga.get("depth", 0.75)), size(ga.get("width", 3.5))
    for s in (-1, 1):
        gx = s * hx
        if pa is not None:
            pa_d, pa_w = size(pa.get("depth", 2.25)), size(pa.get("width", 6.5))
            seg += [[gx, -0.5 * pa_w, gx - s * pa_d, -0.5 * pa_w], [gx, 0.5 * pa_w, gx - s * pa_d, 0.5 * pa_w],
                    [gx - s * pa_d, -0.5 * pa_w, gx - s * pa_d, 0.5 * pa_w]]
        seg += [[gx, -0.5 * ga_w, gx - s * ga_d, -0.5 * ga_w], [gx, 0.5 * ga_w, gx - s * ga_d, 0.5 * ga_w],
                [gx - s * ga_d, -0.5 * ga_w, gx - s * ga_d, 0.5 * ga_w]]
        if spot_r > 0:
            spots.append([gx - s * pen_mark, 0.0, spot_r])
    if spot_r > 0:
        spots.append([0.0, 0.0, spot_r])
    if corner_r > 0:
        arcs += [[-hx, -hy, corner_r, 0.0, 0.5 * math.pi], [hx, -hy, corner_r, 0.5 * math.pi, 0.5 * math.pi],
                 [hx, hy, corner_r, math.pi, 0.5 * math.pi], [-hx, hy, corner_r, 1.5 * math.pi, 0.5 * math.pi]]
    return Markings(name=name, length=L, width=W, margin=size(f.get("margin", 1.0)), segments=seg, arcs=arcs, spots=spots)


def size(v: JSON) -> float:
    """A size of the field's JSON (metres) as a float (ValueError where it is not a number)."""
    n = number(v)
    return float(n) if n is not None else float(str(v))


def distance_to_markings(m: Markings, px: "np.ndarray", py: "np.ndarray") -> "np.ndarray":
    """Exact distance (m) of the world points (arrays px, py, any shape) to the nearest marking: a
    segment's or arc's centre line, or a spot's rim (0 inside a filled spot)."""
    px = np.asarray(px, dtype=float)
    py = np.asarray(py, dtype=float)
    best = np.full(np.broadcast(px, py).shape, np.inf)
    for x1, y1, x2, y2 in m["segments"]:
        ex, ey = x2 - x1, y2 - y1
        ll = ex * ex + ey * ey
        t = np.zeros_like(best) if ll == 0 else np.clip(((px - x1) * ex + (py - y1) * ey) / ll, 0.0, 1.0)
        np.minimum(best, np.hypot(px - (x1 + t * ex), py - (y1 + t * ey)), out=best)
    for cx, cy, r, start, sweep in m["arcs"]:
        dx, dy = px - cx, py - cy
        rho = np.hypot(dx, dy)
        if sweep >= 2 * math.pi - 1e-12:
            np.minimum(best, np.abs(rho - r), out=best)
            continue
        rel = np.mod(np.arctan2(dy, dx) - start, 2 * math.pi)
        on = rel <= sweep
        d = np.where(on, np.abs(rho - r), np.inf)
        for e in (start, start + sweep):
            d = np.minimum(d, np.hypot(px - (cx + r * math.cos(e)), py - (cy + r * math.sin(e))))
        np.minimum(best, d, out=best)
    for cx, cy, r in m["spots"]:
        np.minimum(best, np.maximum(0.0, np.hypot(px - cx, py - cy) - r), out=best)
    return best


class DistanceMap:
    """Exact distances sampled on a lattice of `cell` metres covering the lines plus `pad`; lookups by
    bilinear interpolation; beyond the lattice the distance is taken as `far` (>= any truncation)."""

    def __init__(self, m: Markings, cell: float = 0.01, pad: float = 1.0, far: float = 10.0) -> None:
        self.cell = cell
        self.x0 = -0.5 * m["length"] - pad
        self.y0 = -0.5 * m["width"] - pad
        self.nx = int(round((m["length"] + 2 * pad) / cell)) + 1
        self.ny = int(round((m["width"] + 2 * pad) / cell)) + 1
        xs = self.x0 + cell * np.arange(self.nx)
        ys = self.y0 + cell * np.arange(self.ny)
        self.d = np.empty((self.nx, self.ny), dtype=np.float32)
        for i0 in range(0, self.nx, 256):  # in slabs: modest memory
            gx, gy = np.meshgrid(xs[i0:i0 + 256], ys, indexing="ij")
            self.d[i0:i0 + 256] = distance_to_markings(m, gx, gy)
        self.far = far

    def lookup(self, wx: "np.ndarray", wy: "np.ndarray") -> "np.ndarray":
        fx = (np.asarray(wx) - self.x0) / self.cell
        fy = (np.asarray(wy) - self.y0) / self.cell
        inside = (fx >= 0) & (fy >= 0) & (fx < self.nx - 1) & (fy < self.ny - 1)
        ix = np.clip(np.floor(fx).astype(np.int64), 0, self.nx - 2)
        iy = np.clip(np.floor(fy).astype(np.int64), 0, self.ny - 2)
        ax, ay = fx - ix, fy - iy
        d = self.d
        v = ((1 - ax) * (1 - ay) * d[ix, iy] + ax * (1 - ay) * d[ix + 1, iy] + (1 - ax) * ay * d[ix, iy + 1] + ax * ay * d[ix + 1, iy + 1])
        return np.where(inside, v, self.far)


def world_points(pose: Pose, pts: "np.ndarray") -> tuple["np.ndarray", "np.ndarray"]:
    """Robot-frame points (N, 2) placed in the world with `pose`: (x, y) arrays."""
    x, y, th = pose
    c, s = math.cos(th), math.sin(th)
    return x + c * pts[:, 0] - s * pts[:, 1], y + s * pts[:, 0] + c * pts[:, 1]


def score_exact(m: Markings, pose: Pose, pts: "np.ndarray", c: float) -> float:
    wx, wy = world_points(pose, pts)
    d = distance_to_markings(m, wx, wy)
    return float(np.mean(np.minimum(d, c) ** 2))


def wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def twin_of(pose: Pose) -> tuple[float, float, float]:
    return (-pose[0], -pose[1], wrap(pose[2] + math.pi))


def pose_distance(p: Pose, q: Pose) -> tuple[float, float]:
    """(metres, radians) between two poses."""
    return math.hypot(p[0] - q[0], p[1] - q[1]), abs(wrap(p[2] - q[2]))


def apart(dist: tuple[float, float], metres: float, radians: float) -> bool:
    return dist[0] > metres or dist[1] > radians


def fft_size(n: int) -> int:
    """Smallest 2^a 3^b 5^c >= n (fast FFT sizes)."""
    best = 1 << (n - 1).bit_length()
    f5 = 1
    while f5 < 2 * n:
        f3 = f5
        while f3 < 2 * n:
            f2 = f3
            while f2 < n:
                f2 *= 2
            best = min(best, f2)
            f3 *= 3
        f5 *= 5
    return best


def refine(dmap: DistanceMap, pose: Pose, pts: "np.ndarray", c: float, step_xy: float = 0.04, step_th: float = math.radians(1.0), min_xy: float = 0.0005,
           min_th: float = math.radians(0.01), bounds: Optional[tuple[float, float]] = None) -> tuple[tuple[float, ...], float]:
    """Pattern search (compass search) on the 1 cm map: tries +-step in each coordinate, moves to the
    best improvement, halves the steps when none improves."""
    def f(p: Pose) -> float:
        wx, wy = world_points(p, pts)
        return float(np.mean(np.minimum(dmap.lookup(wx, wy), c) ** 2))
    p = list(pose)
    best = f(p)
    sx, st = step_xy, step_th
    while sx > min_xy or st > min_th:
        improved = False
        for k, st_k in ((0, sx), (1, sx), (2, st)):
            if st_k <= (min_th if k == 2 else min_xy):
                continue
            for sgn in (1, -1):
                q = list(p)
                q[k] += sgn * st_k
                if bounds and (abs(q[0]) > bounds[0] or abs(q[1]) > bounds[1]):
                    continue
                v = f(q)
                if v < best - 1e-12:
                    best, p, improved = v, q, True
        if not improved:
            sx *= 0.5
            st *= 0.5
    p[2] = wrap(p[2])
    return tuple(p), best


def search(points: "Union[np.ndarray, Sequence[Sequence[float]]]", field: Union[str, JSON] = "msl2012", c: float = 0.30, xy_step: float = 0.05,
           theta_step_deg: float = 1.0, distinct_m: float = 0.5, distinct_deg: float = 20.0, candidates: int = 40, per_theta: int = 6,
           max_range: Optional[float] = None, verbose: bool = False, dmap: Optional[DistanceMap] = None) -> dict[str, JSON]:
    """Exhaustive search for the pose that fits `points` ((N, 2) robot frame, metres) to the field.

    Returns a dict: reference [x, y, theta], twin, residual_m (sqrt of the mean truncated squared
    distance), inliers (share of points within c of a marking), median_distance_m, points, next_best
    {pose, residual_m, from_reference_or_twin_m, from_reference_or_twin_deg} (None if every refined
    candidate is the reference or its twin), method (the settings) and seconds (wall clock). `dmap` may pass a prebuilt DistanceMap (1 cm) of the field."""
    t0 = time.time()
    m = field_markings(field)
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    if max_range is not None:
        pts = pts[np.hypot(pts[:, 0], pts[:, 1]) <= max_range]
    n = len(pts)
    if n < 3:
        raise ValueError("fewer than 3 points")
    hxf, hyf = 0.5 * m["length"] + m["margin"], 0.5 * m["width"] + m["margin"]  # the floor inside the walls
    if dmap is None:
        dmap = DistanceMap(m, cell=0.01, pad=1.0)
    h = xy_step
    # Truncated cost minus c^2: zero wherever the nearest marking is farther than c, so the lattice
    # only has to cover the lines plus c (and a cell).
    pad = c + 2 * h
    gx0, gy0 = -0.5 * m["length"] - pad, -0.5 * m["width"] - pad
    gnx = int(math.ceil((m["length"] + 2 * pad) / h)) + 1
    gny = int(math.ceil((m["width"] + 2 * pad) / h)) + 1
    GX, GY = np.meshgrid(gx0 + h * np.arange(gnx), gy0 + h * np.arange(gny), indexing="ij")
    G = np.minimum(distance_to_markings(m, GX, GY), c) ** 2 - c * c
    rmax = float(np.max(np.hypot(pts[:, 0], pts[:, 1])))
    half = int(math.ceil(rmax / h)) + 1
    npw = 2 * half + 1
    Lx, Ly = fft_size(gnx + npw - 1), fft_size(gny + npw - 1)
    FG = np.fft.rfft2(G, s=(Lx, Ly))
    # Translations (x, y) = (gx0 + a h, gy0 + b h) inside the floor.
    a_lo, a_hi = int(math.ceil((-hxf - gx0) / h)), int(math.floor((hxf - gx0) / h))
    b_lo, b_hi = int(math.ceil((-hyf - gy0) / h)), int(math.floor((hyf - gy0) / h))
    a_idx = np.arange(a_lo, a_hi + 1)
    b_idx = np.arange(b_lo, b_hi + 1)
    rows = (a_idx - half) % Lx  # s = a + umin, umin = -half
    cols = (b_idx - half) % Ly
    thetas = np.radians(np.arange(0.0, 360.0, theta_step_deg))
    cand: list[tuple[float, float, float, float]] = []
    for th in thetas:
        cth, sth = math.cos(th), math.sin(th)
        u = np.rint((cth * pts[:, 0] - sth * pts[:, 1]) / h).astype(np.int64) + half
        v = np.rint((sth * pts[:, 0] + cth * pts[:, 1]) / h).astype(np.int64) + half
        P = np.bincount(u * npw + v, minlength=npw * npw).reshape(npw, npw).astype(float)
        S = np.fft.irfft2(FG * np.conj(np.fft.rfft2(P, s=(Lx, Ly))), s=(Lx, Ly))
        M = S[np.ix_(rows, cols)]
        # Local minima in (x, y) (8-neighbourhood), the per_theta lowest.
        Mp = np.pad(M, 1, constant_values=np.inf)
        core = Mp[1:-1, 1:-1]
        isMin = np.ones_like(core, dtype=bool)
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                if di or dj:
                    isMin &= core <= Mp[1 + di:Mp.shape[0] - 1 + di, 1 + dj:Mp.shape[1] - 1 + dj]
        ii, jj = np.nonzero(isMin)
        vals = core[ii, jj]
        order = np.argsort(vals)[:per_theta]
        for k in order:
            cand.append(((vals[k] + n * c * c) / n, gx0 + h * a_idx[ii[k]], gy0 + h * b_idx[jj[k]], wrap(th)))
    t_grid = time.time() - t0
    cand.sort(key=lambda z: z[0])
    # Greedy suppression in pose space, then local refinement of the best `candidates`.
    kept: list[tuple[float, float, float, float]] = []
    for s_, x, y, th in cand:
        if all(apart(pose_distance((x, y, th), k[1:]), 0.25, math.radians(5)) for k in kept):
            kept.append((s_, x, y, th))
        if len(kept) >= candidates:
            break
    refined = []
    for s_, x, y, th in kept:
        p, v = refine(dmap, (x, y, th), pts, c, bounds=(hxf, hyf))
        refined.append((score_exact(m, p, pts, c), p, s_))
    refined.sort(key=lambda z: z[0])
    best_score, best, _ = refined[0]
    ref = best if (best[0] > 0 or (best[0] == 0 and best[1] >= 0)) else twin_of(best)
    twin = twin_of(ref)
    nb = None
    for sc, p, _ in refined:
        d1, a1 = pose_distance(p, ref)
        d2, a2 = pose_distance(p, twin)
        far1 = d1 > distinct_m or a1 > math.radians(distinct_deg)
        far2 = d2 > distinct_m or a2 > math.radians(distinct_deg)
        if far1 and far2:
            nb = (sc, p, min((d1, a1), (d2, a2)))
            break
    wx, wy = world_points(ref, pts)
    d = distance_to_markings(m, wx, wy)
    out: dict[str, JSON] = {
        "reference": [round(v, 5) for v in ref],
        "twin": [round(v, 5) for v in twin],
        "residual_m": round(math.sqrt(best_score), 5),
        "inliers": round(float(np.mean(d < c)), 4),
        "median_distance_m": round(float(np.median(d)), 5),
        "points": int(n),
        "next_best": None if nb is None else {
            "pose": [round(v, 5) for v in nb[1]], "residual_m": round(math.sqrt(nb[0]), 5),
            "from_reference_or_twin_m": round(nb[2][0], 3), "from_reference_or_twin_deg": round(math.degrees(nb[2][1]), 2)},
        "method": {"score": "mean over points of min(d, c)^2, d = distance to the nearest marking centre line; residual = sqrt(score)",
                   "c_m": c, "xy_step_m": xy_step, "theta_step_deg": theta_step_deg,
                   "search_area": [[-hxf, hxf], [-hyf, hyf]], "refined_candidates": len(kept),
                   "refinement": "compass search on a 1 cm bilinear distance map down to 0.5 mm / 0.01 deg",
                   "distinct": f"more than {distinct_m} m or {distinct_deg} deg from both the reference and its twin",
                   "field": m["name"]},
        "seconds": round(time.time() - t0, 2),
    }
    if verbose:
        print(f"grid {t_grid:.1f} s, total {out['seconds']} s; {n} points", file=sys.stderr)
    return out
