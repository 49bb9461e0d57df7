"""omniloc_client: write an external localizer for omniloc in Python (protocol olp/1).

The contract is docs/protocol.md. This module speaks it for you: subclass `Localizer`, implement
`reset(seed, start)` and `update(frame) -> Estimate`, and call `serve(MyLocalizer())`::

    import omniloc_client as olp

    class DeadReckoning(olp.Localizer):
        name = "my_dead_reckoning"
        version = "1.0"
        needs_start_pose = True

        def reset(self, seed, start):
            self.pose = start

        def update(self, frame):
            self.pose = olp.compose_odometry(self.pose, frame.odometry)
            return olp.Estimate(self.pose)

    olp.serve(DeadReckoning())

Standard library only. numpy is optional: when it can be imported, `Frame.image` is a read-only
`numpy.ndarray` of shape (height, width, 3), dtype uint8; without numpy it is the raw `bytes`
(row-major HWC, RGB).

Units and frames (docs/protocol.md section 4): metres, radians, seconds, angles anticlockwise.
World frame: origin at the centre spot, x towards the goal at x > 0, y left. Robot frame: origin at
the robot centre on the floor, x forward, y left. Image: u right (column), v down (row), pixel
centres at integer + 0.5.

stdout belongs to the protocol: while `serve` runs, `print()` (and anything else written to file
descriptor 1) goes to stderr, which omniloc keeps in the run folder as client_r<robot>.stderr.log.
Before `serve` starts nothing protects it: do not print at import or in your constructor (do heavy
set-up in `Localizer.ready`, which also has hello's params and field).
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import sys
import time
import traceback
from dataclasses import dataclass, field as dataclass_field
from typing import Any, BinaryIO, Dict, List, Optional, Sequence, Tuple

try:  # optional: only used to present the image as an array
    import numpy as _np
except ImportError:  # pragma: no cover - depends on the installation
    _np = None

__all__ = [
    "PROTOCOL", "__version__", "Pose", "Camera", "Calibration", "Field", "Hello", "Blob", "Frame",
    "Estimate", "Localizer", "ProtocolError", "compose_odometry", "wrap_angle", "run", "serve",
]

PROTOCOL = "olp/1"
__version__ = "1.0.0"

#: A pose (x, y, theta): metres, metres, radians.
Pose = Tuple[float, float, float]

MAX_LINE_BYTES = 16 * 1024 * 1024  # docs/protocol.md section 3
_NAME_RE = re.compile(r"^[A-Za-z0-9_.-]{1,64}$")
_MODE_RE = re.compile(r"^[a-z0-9_]{1,32}$")
_EXTRA_KEY_RE = re.compile(r"^[A-Za-z0-9_]{1,32}$")
#: frames.csv's own columns: omniloc refuses them as `extra` names
RESERVED_EXTRA = frozenset(["t", "robot", "gt_x", "gt_y", "gt_theta", "est_x", "est_y", "est_theta", "err_x", "err_y",
                            "err_theta", "err_pos", "valid", "mode", "camera_ok", "line_points", "match_error", "contact",
                            "exposure_ms", "gain"])


class ProtocolError(Exception):
    """omniloc sent something this client cannot follow (or the client broke the protocol)."""


# --------------------------------------------------------------------------------------------------
# Geometry helpers


def wrap_angle(a: float) -> float:
    """Wraps an angle to (-pi, pi], with the same floating-point steps as omniloc's wrap_angle."""
    a = math.fmod(a + math.pi, 2.0 * math.pi)
    if a <= 0.0:
        a += 2.0 * math.pi
    return a - math.pi


def compose_odometry(pose: Sequence[float], odometry: Sequence[float]) -> Pose:
    """Dead reckoning: moves `pose` (world frame) by `odometry` = [dx, dy, dtheta] expressed in the
    robot frame of `pose` (docs/protocol.md, frame.odometry).

    x += dx cos th - dy sin th;  y += dx sin th + dy cos th;  th += dtheta, wrapped to (-pi, pi].
    The operations are in the same order as omniloc's Pose2::compose, so omniloc's built-in
    `odometry_only` and this function give bit-identical poses.
    """
    x, y, th = float(pose[0]), float(pose[1]), float(pose[2])
    dx, dy, dth = float(odometry[0]), float(odometry[1]), float(odometry[2])
    c, s = math.cos(th), math.sin(th)
    return (x + c * dx - s * dy, y + s * dx + c * dy, wrap_angle(th + dth))


# --------------------------------------------------------------------------------------------------
# hello: field, camera, calibration


@dataclass
class Field:
    """The field markings (hello.field; the run folder's field.json). Metres, world frame."""

    name: str = ""
    length: float = 0.0      #: between the outer line centres, along x
    width: float = 0.0       #: between the outer line centres, along y
    margin: float = 0.0      #: floor beyond the outer line centres up to the walls
    line_width: float = 0.0  #: painted width of every line
    segments: List[Tuple[float, float, float, float]] = dataclass_field(default_factory=list)  #: [x1, y1, x2, y2]
    arcs: List[Tuple[float, float, float, float, float]] = dataclass_field(default_factory=list)  #: [cx, cy, r, start, sweep]
    spots: List[Tuple[float, float, float]] = dataclass_field(default_factory=list)  #: [cx, cy, radius]
    goals: List[Tuple[float, float, float]] = dataclass_field(default_factory=list)  #: [goal_line_x, width, depth]
    goal_colours: List[str] = dataclass_field(default_factory=list)
    landmarks: List[Dict[str, Any]] = dataclass_field(default_factory=list)
    raw: Dict[str, Any] = dataclass_field(default_factory=dict, repr=False)  #: the object as sent

    @classmethod
    def from_json(cls, j: Dict[str, Any]) -> "Field":
        return cls(
            name=str(j.get("name", "")), length=float(j.get("length", 0.0)), width=float(j.get("width", 0.0)),
            margin=float(j.get("margin", 0.0)), line_width=float(j.get("line_width", 0.0)),
            segments=[tuple(float(v) for v in s) for s in j.get("segments", [])],
            arcs=[tuple(float(v) for v in a) for a in j.get("arcs", [])],
            spots=[tuple(float(v) for v in s) for s in j.get("spots", [])],
            goals=[tuple(float(v) for v in g) for g in j.get("goals", [])],
            goal_colours=[str(c) for c in j.get("goal_colours", [])],
            landmarks=list(j.get("landmarks", [])), raw=j)

    def bounds(self) -> Tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) of the floor inside the walls."""
        hx, hy = 0.5 * self.length + self.margin, 0.5 * self.width + self.margin
        return (-hx, hx, -hy, hy)

    def line_samples(self, spacing: float = 0.02) -> List[Tuple[float, float]]:
        """Points along every line centre (segments and arcs), at most `spacing` metres apart,
        both ends included: e.g. to build a distance map by nearest-sample search."""
        pts: List[Tuple[float, float]] = []
        for x1, y1, x2, y2 in self.segments:
            n = max(1, int(math.ceil(math.hypot(x2 - x1, y2 - y1) / spacing)))
            pts.extend((x1 + (x2 - x1) * i / n, y1 + (y2 - y1) * i / n) for i in range(n + 1))
        for cx, cy, r, start, sweep in self.arcs:
            n = max(1, int(math.ceil(abs(sweep) * r / spacing)))
            pts.extend((cx + r * math.cos(start + sweep * i / n), cy + r * math.sin(start + sweep * i / n))
                       for i in range(n + 1))
        return pts

    def distance_to_lines(self, x: float, y: float) -> float:
        """Exact distance (metres) from the world point (x, y) to the nearest marking: a line's or an
        arc's centre line, or a spot's rim (0 inside a spot): the distance omniloc's own distance map
        holds (core/field.hpp, Field::distance_to_marking)."""
        best = math.inf
        for x1, y1, x2, y2 in self.segments:
            ex, ey = x2 - x1, y2 - y1
            ll = ex * ex + ey * ey
            t = 0.0 if ll == 0.0 else min(1.0, max(0.0, ((x - x1) * ex + (y - y1) * ey) / ll))
            best = min(best, math.hypot(x - (x1 + t * ex), y - (y1 + t * ey)))
        for cx, cy, r, start, sweep in self.arcs:
            a = math.atan2(y - cy, x - cx)
            rel = (a - start) % (2.0 * math.pi) if sweep >= 0 else (start - a) % (2.0 * math.pi)
            if rel <= abs(sweep):
                best = min(best, abs(math.hypot(x - cx, y - cy) - r))
            else:  # nearest end of the arc
                for e in (start, start + sweep):
                    best = min(best, math.hypot(x - (cx + r * math.cos(e)), y - (cy + r * math.sin(e))))
        for cx, cy, r in self.spots:  # centre and penalty marks: filled discs
            best = min(best, max(0.0, math.hypot(x - cx, y - cy) - r))
        return best


class Calibration:
    """The camera's image-radius -> floor-distance map from hello.camera (docs/protocol.md,
    `camera.calibration`): maps an image pixel to the robot-frame floor point it shows.

    Linear interpolation along the radius within each calibrated bearing and between the two
    neighbouring bearings; within a few millimetres of omniloc's own 4-point Lagrange map.
    """

    def __init__(self, camera: Dict[str, Any]):
        cal = camera["calibration"]
        self.width = int(camera["width"])
        self.height = int(camera["height"])
        self.cu, self.cv = (float(c) for c in camera["mirror_centre_px"])
        self.bearings = [float(b) for b in cal["bearings_rad"]]
        self.radii = [[float(r) for r in rs] for rs in cal["radii_px"]]
        self.distances = [[float(d) for d in ds] for ds in cal["distances_m"]]
        if not self.radii or len(self.radii) != len(self.distances) or len(self.radii) != len(self.bearings):
            raise ProtocolError("hello.camera.calibration: bearings_rad, radii_px and distances_m differ in length")
        for rs, ds in zip(self.radii, self.distances):
            if len(rs) != len(ds) or len(rs) < 2:
                raise ProtocolError("hello.camera.calibration: a bearing's radii_px and distances_m differ in length")
        self.min_radius = float(cal["min_radius_px"])
        self.max_radius = float(cal["max_radius_px"])
        self.step = 2.0 * math.pi / len(self.radii)

    @staticmethod
    def _interp(rs: List[float], ds: List[float], r: float) -> float:
        # binary search for the interval [rs[i], rs[i+1]] holding r; linear beyond the ends
        lo, hi = 0, len(rs) - 1
        if r <= rs[0]:
            hi = 1
        elif r >= rs[-1]:
            lo = hi - 1
        else:
            while hi - lo > 1:
                mid = (lo + hi) // 2
                if rs[mid] <= r:
                    lo = mid
                else:
                    hi = mid
        w = (r - rs[lo]) / (rs[hi] - rs[lo])
        return ds[lo] + w * (ds[hi] - ds[lo])

    def pixel_polar(self, u: float, v: float) -> Tuple[float, float]:
        """(radius in pixels from the mirror centre, robot bearing in radians) of pixel (u, v)
        (column, row; its centre is at u + 0.5, v + 0.5)."""
        du, dv = u + 0.5 - self.cu, v + 0.5 - self.cv
        return math.hypot(du, dv), math.atan2(-du, -dv)

    def distance(self, radius_px: float, bearing: float) -> Optional[float]:
        """Floor distance (metres) seen at image radius `radius_px` along robot bearing `bearing`;
        None outside [min_radius, max_radius]."""
        if not (self.min_radius <= radius_px <= self.max_radius):
            return None
        x = (bearing % (2.0 * math.pi)) / self.step
        i = int(math.floor(x)) % len(self.radii)
        j = (i + 1) % len(self.radii)
        w = x - math.floor(x)
        di = self._interp(self.radii[i], self.distances[i], radius_px)
        dj = self._interp(self.radii[j], self.distances[j], radius_px)
        return di + w * (dj - di)

    def to_robot(self, u: float, v: float) -> Optional[Tuple[float, float]]:
        """Robot-frame floor point (x forward, y left; metres) seen at pixel (u, v); None when the
        pixel lies outside the calibrated radii (robot body inside, nothing known beyond)."""
        r, b = self.pixel_polar(u, v)
        d = self.distance(r, b)
        return None if d is None else (d * math.cos(b), d * math.sin(b))

    def pixel_of(self, radius_px: float, bearing: float) -> Tuple[float, float]:
        """The pixel (u, v) (index coordinates, as to_robot takes them) at `radius_px` from the
        mirror centre along robot bearing `bearing`: direction (-sin b, -cos b) in the image."""
        return (self.cu - radius_px * math.sin(bearing) - 0.5, self.cv - radius_px * math.cos(bearing) - 0.5)

    def radius_for_distance(self, distance: float, bearing: float) -> Optional[float]:
        """The image radius (pixels) at which the floor at `distance` metres along `bearing` is
        seen; None outside the calibrated range. Bisection on the monotone map."""
        lo, hi = self.min_radius, self.max_radius
        dlo, dhi = self.distance(lo, bearing), self.distance(hi, bearing)
        if dlo is None or dhi is None or not (dlo <= distance <= dhi):
            return None
        for _ in range(50):
            mid = 0.5 * (lo + hi)
            if self.distance(mid, bearing) < distance:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)


@dataclass
class Camera:
    """hello.camera: what a client needs to do its own vision on the image."""

    width: int = 0
    height: int = 0
    channels: int = 3
    layout: str = "HWC"
    mirror_centre_px: Tuple[float, float] = (0.0, 0.0)  #: (cu, cv), pixels, image frame
    latency_s: float = 0.0  #: the camera's declared latency: the image is this much older than the frame's odometry (0: not declared)
    mount_height_m: Optional[float] = None  #: metres: the mirror viewpoint's declared height above the floor (None: not told)
    vibration_rad: Optional[float] = None  #: radians: the declared per-frame tilt's standard deviation, each of roll and pitch (None: not told)
    raw: Dict[str, Any] = dataclass_field(default_factory=dict, repr=False)

    @classmethod
    def from_json(cls, j: Dict[str, Any]) -> "Camera":
        c = j.get("mirror_centre_px", [0.0, 0.0])
        return cls(width=int(j.get("width", 0)), height=int(j.get("height", 0)), channels=int(j.get("channels", 3)),
                   layout=str(j.get("layout", "HWC")), mirror_centre_px=(float(c[0]), float(c[1])),
                   latency_s=float(j.get("latency_s", 0.0)),
                   mount_height_m=float(j["mount_height_m"]) if "mount_height_m" in j else None,
                   vibration_rad=float(j["vibration_rad"]) if "vibration_rad" in j else None, raw=j)

    def calibration(self) -> Calibration:
        """The pixel -> robot-frame floor map (raises ProtocolError when hello had none)."""
        if "calibration" not in self.raw:
            raise ProtocolError("hello.camera has no calibration")
        return Calibration(self.raw)


@dataclass
class Hello:
    """The `hello` message: the run, the robot, the field, the camera and your params."""

    protocol: str
    robot: int
    scenario: str = ""
    omniloc: str = ""
    camera_rate_hz: float = 30.0  #: frame k is taken at the first physics step at or after k / camera_rate_hz
    duration_s: float = 0.0       #: the last frame has k = floor(duration_s * camera_rate_hz)
    hello_timeout_s: float = 60.0
    frame_timeout_s: float = 10.0
    exit_timeout_s: float = 5.0
    params: Dict[str, Any] = dataclass_field(default_factory=dict)  #: the scenario's localizer params
    field: Field = dataclass_field(default_factory=Field)
    camera: Camera = dataclass_field(default_factory=Camera)
    vision: Dict[str, Any] = dataclass_field(default_factory=dict)  #: {"line_points": true, "blobs": bool}
    raw: Dict[str, Any] = dataclass_field(default_factory=dict, repr=False)  #: the message as sent

    @classmethod
    def from_json(cls, j: Dict[str, Any]) -> "Hello":
        return cls(
            protocol=str(j.get("protocol", "")), robot=int(j.get("robot", 0)), scenario=str(j.get("scenario", "")),
            omniloc=str(j.get("omniloc", "")), camera_rate_hz=float(j.get("camera_rate_hz", 30.0)),
            duration_s=float(j.get("duration_s", 0.0)), hello_timeout_s=float(j.get("hello_timeout_s", 60.0)),
            frame_timeout_s=float(j.get("frame_timeout_s", 10.0)), exit_timeout_s=float(j.get("exit_timeout_s", 5.0)),
            params=dict(j.get("params") or {}), field=Field.from_json(j.get("field") or {}),
            camera=Camera.from_json(j.get("camera") or {}), vision=dict(j.get("vision") or {}), raw=j)


# --------------------------------------------------------------------------------------------------
# frame and estimate


@dataclass
class Blob:
    """A coloured region (or one edge of a goal) found by omniloc's blob detection. Bearings are
    robot-frame radians (anticlockwise from forward); distance in metres or None."""

    colour: str
    kind: str
    bearing: float
    left_bearing: float
    right_bearing: float
    distance: Optional[float]
    area_px: int
    left_occluded: bool
    right_occluded: bool

    @classmethod
    def from_json(cls, j: Dict[str, Any]) -> "Blob":
        d = j.get("distance")
        return cls(colour=str(j.get("colour", "")), kind=str(j.get("kind", "region")), bearing=float(j.get("bearing", 0.0)),
                   left_bearing=float(j.get("left_bearing", 0.0)), right_bearing=float(j.get("right_bearing", 0.0)),
                   distance=None if d is None else float(d), area_px=int(j.get("area_px", 0)),
                   left_occluded=bool(j.get("left_occluded", False)), right_occluded=bool(j.get("right_occluded", False)))


@dataclass
class Frame:
    """One camera frame: exactly what omniloc's built-in localizers get."""

    k: int                          #: frame number, 0, 1, 2, ...
    t: float                        #: seconds since the start: the first physics step at or after k / camera_rate_hz (0.035 for k = 1 at 30 Hz, 200 Hz physics)
    odometry: Pose                  #: (dx, dy, dtheta) since the previous frame, in its robot frame
    heading: Optional[float]        #: compass heading, world frame, radians; None without compass
    camera_ok: bool                 #: False: image unusable (covered), line_points empty
    line_points: List[Tuple[float, float]]  #: white line points, robot frame, metres
    blobs: List[Blob]
    #: The RGB image when the localizer set wants_image: numpy.ndarray (H, W, 3) uint8 (read-only)
    #: when numpy is importable, else bytes (row-major HWC). None otherwise.
    image: Any = None
    image_shape: Optional[Tuple[int, ...]] = None  #: (height, width, 3) when an image came
    raw: Dict[str, Any] = dataclass_field(default_factory=dict, repr=False)  #: the message as sent


@dataclass
class Estimate:
    """The answer to a frame. pose: (x, y, theta) in the world frame (any finite theta).
    valid: False while you have no pose you stand behind (such frames are not scored as localized).
    covariance: 9 numbers, row-major 3x3 over (x, y, theta), m^2/rad^2. mode: a short word
    ([a-z0-9_], <= 32) written to frames.csv. extra: up to 32 named numbers, columns of frames.csv.
    compute_ms: your own computation time for this frame in milliseconds (timing.csv, beside the round
    trip); run() fills in the time update() took when you leave it None.
    particles: optional rows (x, y, theta, weight >= 0), world frame, at most 10000 (send a subsample),
    and points: optional rows (x, y), world frame: what the run viewer draws at this frame when the run
    is made with --debug-view (view.jsonl; docs/protocol.md section 6, docs/viewer.md)."""

    pose: Sequence[float]
    valid: bool = True
    covariance: Optional[Sequence[float]] = None
    mode: Optional[str] = None
    extra: Optional[Dict[str, float]] = None
    compute_ms: Optional[float] = None
    particles: Optional[Sequence[Sequence[float]]] = None
    points: Optional[Sequence[Sequence[float]]] = None

    def to_message(self, k: int) -> Dict[str, Any]:
        """The `estimate` message for frame k; ProtocolError when a field would be rejected."""
        pose = [float(v) for v in self.pose]
        if len(pose) != 3 or not all(math.isfinite(v) for v in pose):
            raise ProtocolError(f"estimate for frame {k}: pose must be 3 finite numbers, got {pose}")
        m: Dict[str, Any] = {"type": "estimate", "k": int(k), "pose": pose, "valid": bool(self.valid)}
        if self.covariance is not None:
            cov = [float(v) for v in (self.covariance.ravel() if hasattr(self.covariance, "ravel") else self.covariance)]
            if len(cov) != 9 or not all(math.isfinite(v) for v in cov):
                raise ProtocolError(f"estimate for frame {k}: covariance must be 9 finite numbers")
            m["covariance"] = cov
        if self.mode is not None:
            if not _MODE_RE.match(self.mode):
                raise ProtocolError(f"estimate for frame {k}: mode {self.mode!r} is not [a-z0-9_]{{1,32}}")
            m["mode"] = self.mode
        if self.extra:
            if len(self.extra) > 32:
                raise ProtocolError(f"estimate for frame {k}: extra has {len(self.extra)} entries, at most 32")
            extra = {}
            for key in sorted(self.extra):  # a fixed order: byte-identical output for identical runs
                value = float(self.extra[key])
                if not _EXTRA_KEY_RE.match(key) or not math.isfinite(value):
                    raise ProtocolError(f"estimate for frame {k}: extra {key!r}: {value} (names [A-Za-z0-9_], finite numbers)")
                if key in RESERVED_EXTRA:
                    raise ProtocolError(f"estimate for frame {k}: extra {key!r} is a column of frames.csv already; choose another name")
                extra[key] = value
            m["extra"] = extra
        if self.compute_ms is not None:
            ms = float(self.compute_ms)
            if not math.isfinite(ms) or ms < 0:
                raise ProtocolError(f"estimate for frame {k}: compute_ms must be a finite number >= 0, got {self.compute_ms!r}")
            m["compute_ms"] = ms
        for key, rows, width in (("particles", self.particles, 4), ("points", self.points, 2)):
            if rows is None:
                continue
            out = [[float(v) for v in row] for row in rows]
            if len(out) > 10000 or not all(len(r) == width and all(math.isfinite(v) for v in r) for r in out):
                raise ProtocolError(f"estimate for frame {k}: {key} must be at most 10000 rows of {width} finite numbers")
            if key == "particles" and any(r[3] < 0 for r in out):
                raise ProtocolError(f"estimate for frame {k}: a particle weight below 0")
            m[key] = out
        return m


# --------------------------------------------------------------------------------------------------
# the localizer you subclass


class Localizer:
    """Subclass this. Class attributes (or attributes set in `ready`) go into the `ready` message:

    name: 1-64 characters of [A-Za-z0-9_.-], not a built-in localizer's name (omniloc list).
    version: any string up to 128 characters.
    needs_start_pose: True -> reset() gets the true start pose (tracking), else None (global).
    wants_image: True -> every frame carries the RGB image (Frame.image).

    `self.hello` (a Hello) is set before `ready` is called: robot id, field, camera (with
    `self.hello.camera.calibration()`), params.
    """

    name: str = "python_localizer"
    version: str = "0.0"
    needs_start_pose: bool = False
    wants_image: bool = False
    hello: Optional[Hello] = None

    def ready(self, hello: Hello) -> None:
        """Called once after `hello`, before `ready` is sent: read params, build maps, set
        name/version/needs_start_pose/wants_image from them. Its time counts into hello_timeout_s."""

    def reset(self, seed: int, start: Optional[Pose]) -> None:
        """Called once before frame 0. seed: seed every random generator from it (and nothing
        else). start: (x, y, theta) when needs_start_pose, else None."""
        raise NotImplementedError("Localizer.reset")

    def update(self, frame: Frame) -> Estimate:
        """Called once per frame, in order; return the estimate of this frame."""
        raise NotImplementedError("Localizer.update")

    def end(self) -> None:
        """Called on `end`, before the process exits with status 0 (optional clean-up)."""


# --------------------------------------------------------------------------------------------------
# the protocol loop


def _read_exact(inp: BinaryIO, n: int) -> bytes:
    """n bytes from inp; a read may return fewer, so loop. ProtocolError on end-of-file."""
    chunks, have = [], 0
    while have < n:
        b = inp.read(n - have)
        if not b:
            raise ProtocolError(f"end of input inside a binary part ({have} of {n} bytes read)")
        chunks.append(b)
        have += len(b)
    return b"".join(chunks)


def _read_message(inp: BinaryIO) -> Tuple[Optional[Dict[str, Any]], Dict[str, bytes], Dict[str, Tuple[int, ...]]]:
    """One message and its binary parts; (None, {}, {}) at a clean end-of-file."""
    line = inp.readline(MAX_LINE_BYTES + 1)
    if not line:
        return None, {}, {}
    if not line.endswith(b"\n"):
        if len(line) > MAX_LINE_BYTES:
            raise ProtocolError("a line longer than 16 MiB")
        raise ProtocolError(f"end of input inside a message: {line[:200]!r}")
    try:
        msg = json.loads(line.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as e:
        raise ProtocolError(f"not a JSON line ({e}): {line[:200]!r}") from None
    if not isinstance(msg, dict) or not isinstance(msg.get("type"), str):
        raise ProtocolError(f"not a JSON object with a string 'type': {line[:200]!r}")
    parts: Dict[str, bytes] = {}
    shapes: Dict[str, Tuple[int, ...]] = {}
    for p in msg.get("binary") or []:
        try:
            n = int(p["bytes"])
            name = str(p.get("name", ""))
            shape = tuple(int(s) for s in p.get("shape", [n]))
        except (KeyError, TypeError, ValueError):
            raise ProtocolError(f"malformed binary part description {p!r}") from None
        if n < 0:
            raise ProtocolError(f"binary part {name!r}: negative size {n}")
        parts[name] = _read_exact(inp, n)
        shapes[name] = shape
    return msg, parts, shapes


def _finite(x: Any, what: str) -> float:
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        raise ProtocolError(f"{what}: expected a number, got {x!r}")
    return float(x)


def _parse_frame(msg: Dict[str, Any], parts: Dict[str, bytes], shapes: Dict[str, Tuple[int, ...]]) -> Frame:
    try:
        odo = msg.get("odometry", [0.0, 0.0, 0.0])
        if len(odo) != 3:
            raise ProtocolError(f"frame: odometry must have 3 numbers, got {odo!r}")
        heading = msg.get("heading")
        frame = Frame(
            k=int(msg["k"]), t=_finite(msg.get("t", 0.0), "frame.t"),
            odometry=(_finite(odo[0], "frame.odometry"), _finite(odo[1], "frame.odometry"), _finite(odo[2], "frame.odometry")),
            heading=None if heading is None else _finite(heading, "frame.heading"),
            camera_ok=bool(msg.get("camera_ok", True)),
            line_points=[(float(p[0]), float(p[1])) for p in msg.get("line_points") or []],
            blobs=[Blob.from_json(b) for b in msg.get("blobs") or []], raw=msg)
    except (KeyError, TypeError, IndexError, ValueError) as e:
        raise ProtocolError(f"malformed frame message ({type(e).__name__}: {e})") from None
    if "image" in parts:
        data, shape = parts["image"], shapes["image"]
        frame.image_shape = shape
        frame.image = _np.frombuffer(data, dtype=_np.uint8).reshape(shape) if _np is not None else data
    return frame


class _Writer:
    def __init__(self, out: BinaryIO):
        self.out = out

    def send(self, msg: Dict[str, Any]) -> None:
        try:
            line = json.dumps(msg, allow_nan=False, separators=(",", ":"))
        except ValueError as e:  # NaN / Infinity
            raise ProtocolError(f"{msg.get('type')}: {e}") from None
        self.out.write(line.encode("utf-8") + b"\n")
        self.out.flush()


def _say(err: Any, text: str) -> None:
    try:
        err.write(f"omniloc_client: {text}\n")
        err.flush()
    except Exception:  # pragma: no cover - stderr gone
        pass


def run(localizer: Localizer, inp: BinaryIO, out: BinaryIO, err: Any = None) -> int:
    """Speaks olp/1 on the binary streams `inp` (from omniloc) and `out` (to omniloc) until `end`
    or an error. Returns the exit status: 0 after `end`, 1 on end-of-file before `end`, on a
    protocol error or an exception in the localizer (each explained on `err`, default sys.stderr).
    `serve` is this on the process's stdin/stdout plus sys.exit; `run` is what tests call."""
    err = err if err is not None else sys.stderr
    with contextlib.redirect_stdout(err):  # the localizer's print() goes to err, never into `out`
        return _run(localizer, inp, _Writer(out), err)


def _run(localizer: Localizer, inp: BinaryIO, writer: _Writer, err: Any) -> int:
    stage = "before hello"
    k = None
    try:
        msg, _, _ = _read_message(inp)
        if msg is None:
            _say(err, "end of input before hello")
            return 1
        if msg["type"] != "hello":
            raise ProtocolError(f"expected hello, got {msg['type']!r}")
        if msg.get("protocol") != PROTOCOL:
            raise ProtocolError(f"omniloc speaks {msg.get('protocol')!r}, this client speaks {PROTOCOL!r}")
        hello = Hello.from_json(msg)
        localizer.hello = hello
        stage = "in ready()"
        localizer.ready(hello)
        name, version = str(localizer.name), str(localizer.version)
        if not _NAME_RE.match(name):
            raise ProtocolError(f"Localizer.name {name!r} must be 1-64 characters of [A-Za-z0-9_.-]")
        if len(version) > 128:
            raise ProtocolError("Localizer.version is longer than 128 characters")
        writer.send({"type": "ready", "protocol": PROTOCOL, "name": name, "version": version,
                     "needs_start_pose": bool(localizer.needs_start_pose), "wants_image": bool(localizer.wants_image)})
        was_reset = False
        while True:
            stage = "waiting for a message"
            msg, parts, shapes = _read_message(inp)
            if msg is None:
                _say(err, f"end of input before end (last frame {k}); omniloc has gone")
                return 1
            kind = msg["type"]
            if kind == "reset":
                seed = msg.get("seed")
                if isinstance(seed, bool) or not isinstance(seed, int):
                    raise ProtocolError(f"reset: seed must be an integer, got {seed!r}")
                start = msg.get("start")
                if start is not None:
                    if len(start) != 3:
                        raise ProtocolError(f"reset: start must be [x, y, theta], got {start!r}")
                    start = tuple(_finite(v, "reset.start") for v in start)
                stage = "in reset()"
                localizer.reset(seed, start)
                was_reset = True
            elif kind == "frame":
                if not was_reset:
                    raise ProtocolError("frame before reset")
                frame = _parse_frame(msg, parts, shapes)
                k = frame.k
                stage = f"in update() of frame {k}"
                t0 = time.perf_counter()
                est = localizer.update(frame)
                if not isinstance(est, Estimate):
                    raise ProtocolError(f"update() of frame {k} returned {type(est).__name__}, not an Estimate")
                if est.compute_ms is None:  # the time update() took: the client's own compute time
                    est.compute_ms = (time.perf_counter() - t0) * 1e3
                writer.send(est.to_message(k))
            elif kind == "end":
                stage = "in end()"
                localizer.end()
                return 0
            else:
                raise ProtocolError(f"unexpected message type {kind!r}")
    except ProtocolError as e:
        _say(err, f"protocol error ({stage}): {e}")
        return 1
    except BrokenPipeError:
        _say(err, f"omniloc closed the pipe ({stage})")
        return 1
    except Exception:
        _say(err, f"the localizer raised an exception ({stage}):\n{traceback.format_exc()}")
        return 1


def serve(localizer: Localizer) -> None:
    """Runs `localizer` as an olp/1 client on this process's stdin and stdout and exits: status 0
    after `end`, non-zero on end-of-file, a protocol error or an exception (explained on stderr).

    While it runs, stdout is reserved for the protocol: sys.stdout and file descriptor 1 point to
    stderr, so a stray print() (or a C library writing to stdout) cannot break the stream."""
    inp = sys.stdin.buffer
    sys.stdout.flush()
    try:
        proto_fd = os.dup(1)            # the pipe to omniloc, kept for the protocol only
        os.dup2(2, 1)                   # fd 1 now writes to stderr
        out = os.fdopen(proto_fd, "wb", buffering=1 << 16)
    except OSError:                     # no file descriptors (embedded interpreter): Python level only
        out = sys.stdout.buffer
    sys.stdout = sys.stderr
    status = run(localizer, inp, out, sys.stderr)
    try:
        out.flush()
    except OSError:
        pass
    sys.stderr.flush()
    # os._exit would skip flushing; sys.exit lets atexit handlers of the user's code run.
    sys.exit(status)
