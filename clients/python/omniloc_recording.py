"""Read and write omniloc recordings (docs/recording.md, format "omniloc-recording/1") with the Python
standard library only.

A recording is a folder: recording.json (the header), frames.jsonl.gz (one JSON object a camera
frame: odometry, heading, line points, ... of every robot, and its true pose when known) and, when
recorded with images, images/r<robot>_<k>.png. `omniloc replay FOLDER --localizer JSON` runs any
localizer on it and writes the run folder `omniloc run` would; with true poses it is scored like a
simulated run, without them the estimates are written and nothing is scored.

Reading:

    import omniloc_recording as rec
    header, frames = rec.read("results/recordings/tracking/1")
    for f in frames:                       # one dict a frame, in order
        r = f["robots"][0]
        print(f["k"], f["t"], r["odometry"], len(r["line_points"]), r.get("truth"))

Writing a real robot's log (the papers' robots logged odometry, compass and line points):

    with rec.Writer("my_log", name="hall_run_3", field="msl2012", camera_rate_hz=30,
                    robots=[{"id": 0, "start": (0.0, -2.0, 0.0)}], ground_truth=True) as w:
        for t, odo, heading, points, truth in my_log:
            w.frame(t, [{"robot": 0, "odometry": odo, "heading": heading, "line_points": points, "truth": truth}])

Units and frames as in olp/1 (docs/protocol.md section 4): metres, radians, seconds; odometry is the
motion since the previous frame in the robot frame of the previous frame; line points in the robot
frame; heading and truth in the world frame.
"""
import gzip
import hashlib
import json
import math
import os
import shutil
import tempfile
from typing import Any, Dict, Iterator, List, Optional, Sequence, Tuple

FORMAT = "omniloc-recording/1"


class RecordingError(Exception):
    """A recording that is not one, of another version, or whose frames do not match its header."""


def read(folder: str) -> Tuple[Dict[str, Any], Iterator[Dict[str, Any]]]:
    """The header and an iterator over the frames (checked against the header's count and hash)."""
    with open(os.path.join(folder, "recording.json"), encoding="utf-8") as fh:
        header = json.load(fh)
    if header.get("format") != FORMAT:
        raise RecordingError(f"{folder}: format {header.get('format')!r}, this reader reads {FORMAT!r}")
    name = header.get("frames_file", "frames.jsonl")
    path = os.path.join(folder, name)
    with (gzip.open(path, "rb") if name.endswith(".gz") else open(path, "rb")) as fh:
        data = fh.read()
    if "frames_sha256" in header and hashlib.sha256(data).hexdigest() != header["frames_sha256"]:
        raise RecordingError(f"{path}: SHA-256 differs from recording.json's (changed or cut short)")
    lines = data.splitlines()
    if len(lines) != header["frames"]:
        raise RecordingError(f"{path}: {len(lines)} frames, recording.json says {header['frames']}")
    return header, (json.loads(line) for line in lines)


def _finite(v: Any, what: str) -> float:
    x = float(v)
    if not math.isfinite(x):
        raise RecordingError(f"{what}: {v!r} is not a finite number")
    return x


def _pose(p: Sequence[float], what: str) -> List[float]:
    if len(p) != 3:
        raise RecordingError(f"{what}: expected (x, y, theta), got {p!r}")
    return [_finite(v, what) for v in p]


class Writer:
    """Writes a recording frame by frame; the folder appears whole at close() (staged beside it and
    renamed), so an interrupted writer leaves no recording that looks complete.

    name: the run's name (results/runs/<name>/). field: a field preset name (`omniloc list`) or a
    field object as a scenario's "field" holds it. robots: [{"id": int, "start": (x, y, theta) or
    None, "camera": hello.camera dict or absent}] - the start pose is what tracking localizers are
    given; without it only localizers that search globally can replay the log. ground_truth: whether
    every frame gives each robot's true pose ("truth"); without it nothing is scored."""

    def __init__(self, folder: str, name: str, field: Any, camera_rate_hz: float, robots: Sequence[Dict[str, Any]],
                 ground_truth: bool, seed: int = 1, comment: Optional[str] = None):
        if not robots:
            raise RecordingError("at least one robot")
        self.folder = os.path.abspath(folder)
        self.header: Dict[str, Any] = {
            "format": FORMAT, "name": name, "seed": int(seed), "scenario": None, "field": field,
            "camera_rate_hz": float(camera_rate_hz), "robots": [], "ground_truth": bool(ground_truth), "images": False,
            "frames_file": "frames.jsonl.gz", "written_by": "clients/python/omniloc_recording.py",
        }
        if comment:
            self.header["comment"] = comment
        for r in robots:
            entry: Dict[str, Any] = {"id": int(r["id"])}
            if r.get("start") is not None:
                entry["start"] = _pose(r["start"], f"robot {r['id']} start")
            entry["camera"] = r.get("camera", {})
            entry["blobs"] = False
            self.header["robots"].append(entry)
        self.ids = [r["id"] for r in self.header["robots"]]
        self.lines: List[bytes] = []
        self.last_t: Optional[float] = None

    def frame(self, t: float, robots: Sequence[Dict[str, Any]]) -> None:
        """One camera frame: per robot (in the header's order) "odometry" (dx, dy, dtheta), optional
        "heading" (None: no compass), "line_points" [(x, y), ...], optional "camera_ok" (default True)
        and, with ground_truth, "truth" (x, y, theta)."""
        t = _finite(t, "t")
        if self.last_t is not None and not t > self.last_t:
            raise RecordingError(f"frame {len(self.lines)}: t = {t} is not after the previous frame's {self.last_t}")
        if [r.get("robot") for r in robots] != self.ids:
            raise RecordingError(f"frame {len(self.lines)}: robots {[r.get('robot') for r in robots]}, expected {self.ids}")
        out = []
        for r in robots:
            what = f"frame {len(self.lines)} robot {r['robot']}"
            o: Dict[str, Any] = {
                "robot": int(r["robot"]),
                "odometry": _pose(r["odometry"], what + " odometry"),
                "heading": None if r.get("heading") is None else _finite(r["heading"], what + " heading"),
                "camera_ok": bool(r.get("camera_ok", True)),
                "line_points": [[_finite(x, what + " line point"), _finite(y, what + " line point")] for x, y in r.get("line_points", [])],
                "covered": False, "camera": None, "stop_robot": False, "contact": False,
            }
            if self.header["ground_truth"]:
                if r.get("truth") is None:
                    raise RecordingError(f"{what}: no truth, and the recording says ground_truth")
                o["truth"] = _pose(r["truth"], what + " truth")
            out.append(o)
        self.lines.append(json.dumps({"k": len(self.lines), "t": t, "robots": out}, separators=(",", ":"), allow_nan=False).encode() + b"\n")
        self.last_t = t

    def close(self) -> str:
        if not self.lines:
            raise RecordingError("no frames")
        data = b"".join(self.lines)
        self.header["frames"] = len(self.lines)
        rate = self.header["camera_rate_hz"]
        self.header["duration_s"] = max(self.last_t or 0.0, (len(self.lines) - 1) / rate)
        self.header["frames_sha256"] = hashlib.sha256(data).hexdigest()
        parent = os.path.dirname(self.folder) or "."
        os.makedirs(parent, exist_ok=True)
        stage = tempfile.mkdtemp(prefix="." + os.path.basename(self.folder) + ".partial-", dir=parent)
        try:
            with gzip.open(os.path.join(stage, "frames.jsonl.gz"), "wb") as fh:
                fh.write(data)
            with open(os.path.join(stage, "recording.json"), "w", encoding="utf-8") as fh:
                json.dump(self.header, fh, indent=2)
                fh.write("\n")
            if os.path.exists(self.folder):
                shutil.rmtree(self.folder)
            os.rename(stage, self.folder)
        except BaseException:
            shutil.rmtree(stage, ignore_errors=True)
            raise
        return self.folder

    def __enter__(self) -> "Writer":
        return self

    def __exit__(self, kind, value, tb) -> None:
        if kind is None:
            self.close()
