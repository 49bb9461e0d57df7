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

import csv
import json
import math
import os
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple

from omniloc.view.model import (FRAMES_COLUMNS, REQUIRED_COLUMNS, T_TOLERANCE, ViewInputError, Pose, Debug, RobotRun, Event, RunData, _finite, _read_text, _cell, Blob)
from omniloc.view.debug_inputs import read_frame_images, read_images, read_recording, read_view_jsonl

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


def load_run(run_dir: Path, recording: Optional[Path] = None, image_every: int = 30, images: bool = True,
             frames_dir: Optional[Path] = None) -> RunData:
    """The run folder and what is given beside it: a recording (line points, blobs, images) and the
    PNGs of `omniloc run --frames DIR` (images; they win over a recording's)."""
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
        if images and rec_images and frames_dir is None:
            imgs = read_images(recording, ids, frames, image_every)
            for r in robots:
                r["images"] = imgs[r["id"]]
        elif images and frames_dir is None:
            notes.append("the recording holds no images (record with --images)")
    if images and frames_dir is not None:
        imgs = read_frame_images(frames_dir, ids, frames, image_every)
        for r in robots:
            r["images"] = imgs[r["id"]]
    if debug is not None:
        for r in robots:
            r["debug"] = debug[r["id"]]

    name = summary.get("scenario") or run_dir.resolve().name
    title = f"{name}, seed {summary.get('seed', '?')}, {summary.get('localizer', 'localizer ?')}"
    return RunData(title=title, run_dir=os.fspath(run_dir), summary=summary, field=field, frames=frames, robots=robots,
                   events=read_events(run_dir / "events.jsonl"), debug_source=debug_source,
                   recording=os.fspath(recording) if recording is not None else None, recording_images=rec_images,
                   image_every=image_every, notes=notes)
