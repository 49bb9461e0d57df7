"""Reads one run folder (docs/results.md), its optional view.jsonl (docs/viewer.md) and an optional
recording (docs/recording.md) into plain dicts for the page.

Sources, per frame and robot:
  - frames.csv: which frames exist (the j-th row of a robot is frame k = j), time, valid, mode,
    camera_ok, line-point count, match_error, errors and the localizer's own columns;
  - gt.tum / est.tum (gt_r<id>.tum / est_r<id>.tum for the second robot on): the poses drawn, at the
    TUM files' precision (6 decimals; yaw from the quaternion). gt.tum has one row per frame, est.tum
    one per *valid* frame, in order; an invalid frame's estimate comes from frames.csv (5 decimals);
  - view.jsonl (written by `omniloc run --debug-view`), else the recording's frames: line points,
    blobs, and (view.jsonl only) covariance, particles and extra points.

Every problem with the input raises ViewInputError naming the file (and line) and what was expected.
"""
from __future__ import annotations

import base64
import csv
import gzip
import json
import math
import os
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple, TypedDict, TypeGuard

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


def _read_text(path: Path, what: str) -> str:
    if not path.exists():
        raise ViewInputError(path, f"missing: expected {what}")
    if not path.is_file():
        raise ViewInputError(path, f"not a file: expected {what}")
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


def tum_yaw(qz: float, qw: float) -> float:
    """Yaw (rad, in (-pi, pi]) of a rotation about z given as the quaternion (0, 0, qz, qw)."""
    return math.atan2(2.0 * qw * qz, qw * qw - qz * qz)


def read_tum(path: Path) -> List[Tuple[float, Pose]]:
    """TUM rows `t x y z qx qy qz qw` as (t, pose); yaw from the quaternion."""
    rows: List[Tuple[float, Pose]] = []
    for n, line in enumerate(_read_text(path, "a TUM trajectory (t x y z qx qy qz qw per line)").splitlines(), 1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        parts = s.split()
        if len(parts) != 8:
            raise ViewInputError(path, f"expected 8 numbers `t x y z qx qy qz qw`, got {len(parts)} fields", n)
        try:
            v = [float(p) for p in parts]
        except ValueError:
            raise ViewInputError(path, "expected 8 numbers `t x y z qx qy qz qw`, got a field that is not a number", n) from None
        if not all(math.isfinite(x) for x in v):
            raise ViewInputError(path, "expected 8 finite numbers `t x y z qx qy qz qw`", n)
        rows.append((v[0], Pose(x=v[1], y=v[2], theta=tum_yaw(v[6], v[7]))))
    return rows


def _event_label(e: Dict[str, Any]) -> str:
    kind = str(e.get("type", "event"))
    parts = [kind]
    if "mode" in e:
        parts = [f"mode {e['mode']}"]
    if isinstance(e.get("robot"), int):
        parts.append(f"r{e['robot']}")
    pose = e.get("pose")
    if isinstance(pose, list) and len(pose) == 3 and all(_finite(p) for p in pose):
        parts.append("to ({:.2f}, {:.2f}, {:.2f} rad)".format(*pose))
    for key in ("duration", "fraction", "level", "transition", "scale"):
        if _finite(e.get(key)):
            unit = " s" if key in ("duration", "transition") else ""
            parts.append(f"{key} {e[key]:g}{unit}")
    for key in ("message", "comment", "reason", "what"):
        if isinstance(e.get(key), str):
            parts.append(e[key][:120])
    parts.append(f"at {e['t']:.3f} s")
    return ", ".join(parts[:1]) + (" " + ", ".join(parts[1:]) if len(parts) > 1 else "")


def read_events(path: Path) -> List[Event]:
    events: List[Event] = []
    if not path.exists():
        return events
    for n, line in enumerate(_read_text(path, "events, one JSON object per line").splitlines(), 1):
        if not line.strip():
            continue
        try:
            e = json.loads(line)
        except json.JSONDecodeError as err:
            raise ViewInputError(path, f"expected one JSON object per line ({err.msg})", n) from None
        if not isinstance(e, dict) or not _finite(e.get("t")):
            raise ViewInputError(path, "expected a JSON object with a number `t`", n)
        robot = e.get("robot")
        duration = e.get("duration")
        events.append(Event(t=float(e["t"]), type=str(e.get("type", "event")), robot=robot if isinstance(robot, int) else None,
                            duration=float(duration) if _finite(duration) else None, label=_event_label(e)))
    return events


# ------------------------------------------------------------------------------------- frames.csv

def read_frames_csv(path: Path) -> Tuple[List[int], Dict[int, Dict[str, List[Optional[float]]]], Dict[int, List[str]], List[str]]:
    """Per robot (ids in the order of first appearance): columns of numbers, the modes, and the names
    of the localizer's own columns."""
    text = _read_text(path, "frames.csv of a run folder (docs/results.md)")
    reader = csv.reader(text.splitlines())
    try:
        header = next(reader)
    except StopIteration:
        raise ViewInputError(path, "empty: expected a header `t,robot,gt_x,...` and one row per frame and robot") from None
    missing = [c for c in REQUIRED_COLUMNS if c not in header]
    if missing:
        raise ViewInputError(path, f"header: expected the columns {', '.join(REQUIRED_COLUMNS)}; missing {', '.join(missing)}", 1)
    extra = [c for c in header if c not in FRAMES_COLUMNS]
    ids: List[int] = []
    cols: Dict[int, Dict[str, List[Optional[float]]]] = {}
    modes: Dict[int, List[str]] = {}
    for n, row in enumerate(reader, 2):
        if not row:
            continue
        if len(row) != len(header):
            raise ViewInputError(path, f"expected {len(header)} cells as in the header, got {len(row)}", n)
        cells = dict(zip(header, row))
        try:
            rid = int(cells["robot"])
        except ValueError:
            raise ViewInputError(path, f"column robot: expected an integer id, got {cells['robot'][:40]!r}", n) from None
        if rid not in cols:
            ids.append(rid)
            cols[rid] = {c: [] for c in header if c not in ("robot", "mode")}
            modes[rid] = []
        for c, v in cells.items():
            if c in ("robot", "mode"):
                continue
            cols[rid][c].append(_cell(v, path, n, c))
        if cols[rid]["t"][-1] is None or cols[rid]["est_x"][-1] is None:
            raise ViewInputError(path, "expected a time and an estimate in every row", n)
        modes[rid].append(cells["mode"])
    if not ids:
        raise ViewInputError(path, "no rows: expected one row per frame and robot")
    counts = {rid: len(modes[rid]) for rid in ids}
    if len(set(counts.values())) != 1:
        raise ViewInputError(path, "expected the same number of frames for every robot, got " +
                             ", ".join(f"r{r}: {c}" for r, c in counts.items()))
    return ids, cols, modes, extra


# ----------------------------------------------------------------------------------- debug inputs

def _points(v: Any, width: int, path: Path, line: int, key: str) -> List[Tuple[float, ...]]:
    what = f"`{key}`: expected a list of [{', '.join(['x', 'y', 'theta', 'weight'][:width])}] number lists"
    if not isinstance(v, list):
        raise ViewInputError(path, what, line)
    out: List[Tuple[float, ...]] = []
    for p in v:
        if not isinstance(p, list) or len(p) != width or not all(_finite(x) for x in p):
            raise ViewInputError(path, what + f", got {json.dumps(p)[:60]}", line)
        out.append(tuple(float(x) for x in p))
    return out


def _blobs(v: Any, path: Path, line: int) -> List[Blob]:
    if v is None:
        return []
    if not isinstance(v, list):
        raise ViewInputError(path, "`blobs`: expected a list of olp/1 blob objects", line)
    out: List[Blob] = []
    for b in v:
        if not isinstance(b, dict) or not _finite(b.get("bearing")):
            raise ViewInputError(path, "`blobs`: expected objects with a number `bearing` (olp/1 frame.blobs)", line)
        d = b.get("distance")
        if d is not None and not _finite(d):
            raise ViewInputError(path, "`blobs`: expected `distance` a number or null", line)
        out.append(Blob(colour=str(b.get("colour", "")), kind=str(b.get("kind", "region")), bearing=float(b["bearing"]),
                        distance=None if d is None else float(d)))
    return out


def _covariance(v: Any, path: Path, line: int) -> Optional[List[float]]:
    if v is None:
        return None
    what = "`covariance`: expected 3 rows of 3 numbers (x, y, theta; m^2, rad^2) or 9 numbers row-major"
    if isinstance(v, list) and len(v) == 3 and all(isinstance(r, list) and len(r) == 3 for r in v):
        flat = [x for r in v for x in r]
    elif isinstance(v, list) and len(v) == 9:
        flat = list(v)
    else:
        raise ViewInputError(path, what, line)
    if not all(_finite(x) for x in flat):
        raise ViewInputError(path, what + " (finite)", line)
    return [float(x) for x in flat]


def read_view_jsonl(path: Path, ids: Sequence[int], times: Dict[int, List[float]]) -> Dict[int, List[Debug]]:
    """view.jsonl: one object per (frame, robot), in frame order, every one present (docs/viewer.md)."""
    frames = len(times[ids[0]])
    out: Dict[int, List[Optional[Debug]]] = {rid: [None] * frames for rid in ids}
    text = _read_text(path, "view.jsonl, one JSON object per frame and robot (docs/viewer.md)")
    last_k = -1
    for n, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        try:
            o = json.loads(line)
        except json.JSONDecodeError as err:
            raise ViewInputError(path, f"expected one JSON object per line ({err.msg} at column {err.colno})", n) from None
        if not isinstance(o, dict):
            raise ViewInputError(path, "expected a JSON object {\"k\", \"t\", \"robot\", \"line_points\", ...}", n)
        k, t, rid = o.get("k"), o.get("t"), o.get("robot")
        if not isinstance(k, int) or isinstance(k, bool) or k < 0:
            raise ViewInputError(path, "`k`: expected the frame index, an integer >= 0", n)
        if k >= frames:
            raise ViewInputError(path, f"`k` {k}: the run has frames 0 to {frames - 1} (frames.csv)", n)
        if k < last_k:
            raise ViewInputError(path, f"`k` {k} after {last_k}: expected frame order", n)
        last_k = k
        if not isinstance(rid, int) or isinstance(rid, bool) or rid not in out:
            raise ViewInputError(path, f"`robot`: expected one of the run's robots {list(ids)}, got {json.dumps(rid)}", n)
        if not _finite(t):
            raise ViewInputError(path, "`t`: expected the frame's time in seconds", n)
        if abs(float(t) - times[rid][k]) > T_TOLERANCE:
            raise ViewInputError(path, f"`t` {t}: frames.csv has t = {times[rid][k]:.4f} for frame {k} of r{rid}", n)
        if out[rid][k] is not None:
            raise ViewInputError(path, f"frame {k} of r{rid} a second time: expected one line per frame and robot", n)
        if "line_points" not in o:
            raise ViewInputError(path, "`line_points`: expected a list of [x, y] (robot frame, metres)", n)
        lp = _points(o["line_points"], 2, path, n, "line_points")
        particles = _points(o["particles"], 4, path, n, "particles") if o.get("particles") is not None else None
        if particles is not None and any(p[3] < 0 for p in particles):
            raise ViewInputError(path, "`particles`: expected weights >= 0", n)
        points = _points(o["points"], 2, path, n, "points") if o.get("points") is not None else None
        out[rid][k] = Debug(line_points=[(p[0], p[1]) for p in lp], blobs=_blobs(o.get("blobs"), path, n),
                            covariance=_covariance(o.get("covariance"), path, n),
                            particles=[(p[0], p[1], p[2], p[3]) for p in particles] if particles is not None else None,
                            points=[(p[0], p[1]) for p in points] if points is not None else None)
    for rid in ids:
        for k, d in enumerate(out[rid]):
            if d is None:
                raise ViewInputError(path, f"no line for frame {k} of r{rid}: expected one line per frame and robot "
                                           f"({frames} frames x {len(ids)} robots)")
    return {rid: [d for d in out[rid] if d is not None] for rid in ids}


def read_recording(folder: Path, ids: Sequence[int], times: Dict[int, List[float]]) -> Tuple[Dict[int, List[Debug]], Dict[str, Any]]:
    """A recording's line points and blobs per robot and frame, and its header."""
    head_path = folder / "recording.json"
    if not folder.is_dir():
        raise ViewInputError(folder, "not a folder: expected a recording (omniloc record, docs/recording.md)")
    try:
        head = json.loads(_read_text(head_path, "recording.json of a recording (docs/recording.md)"))
    except json.JSONDecodeError as err:
        raise ViewInputError(head_path, f"expected a JSON object ({err.msg})", err.lineno) from None
    if not isinstance(head, dict) or head.get("format") != "omniloc-recording/1":
        raise ViewInputError(head_path, "expected `format` \"omniloc-recording/1\"")
    rec_ids = [r.get("id") for r in head.get("robots", []) if isinstance(r, dict)]
    if rec_ids != list(ids):
        raise ViewInputError(head_path, f"robots {rec_ids}: the run localized robots {list(ids)}")
    frames = len(times[ids[0]])
    if head.get("frames") != frames:
        raise ViewInputError(head_path, f"`frames` {head.get('frames')}: the run has {frames} frames (frames.csv)")
    name = head.get("frames_file", "frames.jsonl")
    fpath = folder / str(name)
    if not fpath.is_file():
        raise ViewInputError(fpath, "missing: expected the recording's frames (docs/recording.md section 4)")
    try:
        raw = gzip.open(fpath).read() if str(name).endswith(".gz") else fpath.read_bytes()
        lines = raw.decode("utf-8").splitlines()
    except (OSError, EOFError, UnicodeDecodeError) as e:
        raise ViewInputError(fpath, f"unreadable ({e.__class__.__name__}): expected gzip of JSON lines") from None
    out: Dict[int, List[Debug]] = {rid: [] for rid in ids}
    for n, line in enumerate(lines, 1):
        try:
            f = json.loads(line)
        except json.JSONDecodeError as err:
            raise ViewInputError(fpath, f"expected one JSON object per frame ({err.msg})", n) from None
        if not isinstance(f, dict) or f.get("k") != n - 1 or not _finite(f.get("t")) or not isinstance(f.get("robots"), list):
            raise ViewInputError(fpath, f"expected a frame {{\"k\": {n - 1}, \"t\", \"robots\": [...]}}", n)
        if len(f["robots"]) != len(ids):
            raise ViewInputError(fpath, f"expected {len(ids)} robots per frame, got {len(f['robots'])}", n)
        for rid, r in zip(ids, f["robots"]):
            if n - 1 >= frames:
                break
            if abs(float(f["t"]) - times[rid][n - 1]) > T_TOLERANCE:
                raise ViewInputError(fpath, f"`t` {f['t']}: the run's frame {n - 1} has t = {times[rid][n - 1]:.4f} "
                                            "(a recording of another scenario or seed?)", n)
            if not isinstance(r, dict) or r.get("robot") != rid:
                raise ViewInputError(fpath, f"expected robot {rid} in place {ids.index(rid)}", n)
            lp = _points(r.get("line_points"), 2, fpath, n, "line_points")
            out[rid].append(Debug(line_points=[(p[0], p[1]) for p in lp], blobs=_blobs(r.get("blobs"), fpath, n),
                                  covariance=None, particles=None, points=None))
    if len(out[ids[0]]) != frames:
        raise ViewInputError(fpath, f"{len(out[ids[0]])} frames: the run has {frames} (frames.csv)")
    return out, head


def read_images(folder: Path, ids: Sequence[int], frames: int, every: int) -> Dict[int, Dict[int, str]]:
    """Every `every`-th frame's PNG of each robot, base64."""
    out: Dict[int, Dict[int, str]] = {rid: {} for rid in ids}
    for rid in ids:
        for k in range(0, frames, every):
            p = folder / "images" / f"r{rid}_{k:06d}.png"
            try:
                data = p.read_bytes()
            except OSError:
                raise ViewInputError(p, "missing: expected the frame's image (the recording says it holds every image)") from None
            if not data.startswith(b"\x89PNG\r\n\x1a\n"):
                raise ViewInputError(p, "expected a PNG image")
            out[rid][k] = base64.b64encode(data).decode("ascii")
    return out


# ------------------------------------------------------------------------------------------ a run

def _json_file(path: Path, what: str, required: bool) -> Dict[str, Any]:
    if not path.exists() and not required:
        return {}
    try:
        v = json.loads(_read_text(path, what))
    except json.JSONDecodeError as err:
        raise ViewInputError(path, f"expected {what} ({err.msg})", err.lineno) from None
    if not isinstance(v, dict):
        raise ViewInputError(path, f"expected {what}")
    return v


def _check_field(field: Dict[str, Any], path: Path) -> None:
    for key in ("length", "width"):
        if not _finite(field.get(key)) or field[key] <= 0:
            raise ViewInputError(path, f"`{key}`: expected a positive number (metres)")
    if not _finite(field.get("margin", 0)):
        raise ViewInputError(path, "`margin`: expected a number (metres)")
    for key, width in (("segments", 4), ("arcs", 5), ("spots", 3), ("goals", 3)):
        v = field.get(key, [])
        if not isinstance(v, list) or not all(isinstance(s, list) and len(s) == width and all(_finite(x) for x in s) for s in v):
            raise ViewInputError(path, f"`{key}`: expected a list of {width}-number lists")


def load_run(run_dir: Path, recording: Optional[Path] = None, image_every: int = 30, images: bool = True) -> RunData:
    if not run_dir.exists():
        raise ViewInputError(run_dir, "missing: expected a run folder (omniloc run / replay -o DIR)")
    if not run_dir.is_dir():
        raise ViewInputError(run_dir, "not a folder: expected a run folder (omniloc run / replay -o DIR)")
    field_path = run_dir / "field.json"
    field = _json_file(field_path, "the field's markings, a JSON object (docs/results.md)", True)
    _check_field(field, field_path)
    summary = _json_file(run_dir / "summary.json", "summary.json, a JSON object", False)
    config = _json_file(run_dir / "config.json", "config.json, a JSON object", False)
    radius: Dict[int, float] = {}
    for r in config.get("robots", []) if isinstance(config.get("robots"), list) else []:
        if isinstance(r, dict) and isinstance(r.get("id"), int) and _finite(r.get("radius")):
            radius[r["id"]] = float(r["radius"])
    ids, cols, modes, extra = read_frames_csv(run_dir / "frames.csv")
    frames = len(modes[ids[0]])
    times: Dict[int, List[float]] = {rid: [float(x or 0.0) for x in cols[rid]["t"]] for rid in ids}
    notes: List[str] = []

    robots: List[RobotRun] = []
    for i, rid in enumerate(ids):
        suffix = "" if i == 0 else f"_r{rid}"
        c = cols[rid]
        valid = [bool(v) for v in c["valid"]]
        est_path = run_dir / f"est{suffix}.tum"
        est_rows = read_tum(est_path)
        nvalid = sum(valid)
        if len(est_rows) != nvalid:
            raise ViewInputError(est_path, f"{len(est_rows)} rows: expected one per valid frame of r{rid}, "
                                           f"frames.csv has {nvalid}")
        estimate: List[Pose] = []
        from_tum: List[bool] = []
        j = 0
        for k in range(frames):
            if valid[k]:
                t, p = est_rows[j]
                if abs(t - times[rid][k]) > T_TOLERANCE:
                    raise ViewInputError(est_path, f"t {t:.6f}: expected frame {k}'s t = {times[rid][k]:.4f} (frames.csv)", j + 1)
                estimate.append(p)
                from_tum.append(True)
                j += 1
            else:
                estimate.append(Pose(x=c["est_x"][k] or 0.0, y=c["est_y"][k] or 0.0, theta=c["est_theta"][k] or 0.0))
                from_tum.append(False)
        gt_path = run_dir / f"gt{suffix}.tum"
        truth: Optional[List[Pose]] = None
        if gt_path.exists():
            gt_rows = read_tum(gt_path)
            if len(gt_rows) != frames:
                raise ViewInputError(gt_path, f"{len(gt_rows)} rows: expected one per frame of r{rid}, frames.csv has {frames}")
            for k, (t, _) in enumerate(gt_rows):
                if abs(t - times[rid][k]) > T_TOLERANCE:
                    raise ViewInputError(gt_path, f"t {t:.6f}: expected frame {k}'s t = {times[rid][k]:.4f} (frames.csv)", k + 1)
            truth = [p for _, p in gt_rows]
        else:
            notes.append(f"no {gt_path.name}: the truth of r{rid} is not drawn")

        def col(name: str) -> List[Optional[float]]:
            return list(c[name]) if name in c else [None] * frames

        def flag(name: str) -> List[Optional[bool]]:
            return [None if v is None else bool(v) for v in col(name)]

        robots.append(RobotRun(id=rid, radius=radius.get(rid, 0.26), t=times[rid], truth=truth, estimate=estimate, est_from_tum=from_tum, valid=valid,
                               mode=modes[rid], camera_ok=flag("camera_ok"), line_points=col("line_points"),
                               match_error=col("match_error"), err_pos=col("err_pos"), err_theta=col("err_theta"),
                               contact=flag("contact"), extra={name: col(name) for name in extra}, debug=None, images={}))

    debug_source: Optional[str] = None
    view_path = run_dir / "view.jsonl"
    debug: Optional[Dict[int, List[Debug]]] = None
    if view_path.exists():
        debug = read_view_jsonl(view_path, ids, times)
        debug_source = "view.jsonl"
    rec_images = False
    if recording is not None:
        rec_debug, head = read_recording(recording, ids, times)
        if debug is None:
            debug, debug_source = rec_debug, "recording"
        markings = head.get("field_markings")
        if isinstance(markings, dict):  # goal colours and landmarks, which field.json leaves out
            for key in ("goal_colours", "landmarks"):
                if key in markings and key not in field:
                    field[key] = markings[key]
        rec_images = head.get("images") is True
        if images and rec_images:
            imgs = read_images(recording, ids, frames, image_every)
            for r in robots:
                r["images"] = imgs[r["id"]]
        elif images:
            notes.append("the recording holds no images (record with --images)")
    if debug is not None:
        for r in robots:
            r["debug"] = debug[r["id"]]

    name = summary.get("scenario") or run_dir.resolve().name
    title = f"{name}, seed {summary.get('seed', '?')}, {summary.get('localizer', 'localizer ?')}"
    return RunData(title=title, run_dir=os.fspath(run_dir), summary=summary, field=field, frames=frames, robots=robots,
                   events=read_events(run_dir / "events.jsonl"), debug_source=debug_source,
                   recording=os.fspath(recording) if recording is not None else None, recording_images=rec_images,
                   image_every=image_every, notes=notes)
