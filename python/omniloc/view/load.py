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

The files are read by the core's readers (omniloc.core.runfiles, viewlog, recording, events); every
problem with the input raises InputFileError naming the file (and line) and what was expected.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Dict, List, Optional

from omniloc.core import events
from omniloc.core.files import InputFileError, read_json_object
from omniloc.core.jsonvalue import finite
from omniloc.core.runfiles import Pose, check_field, read_frame_table, read_tum
from omniloc.core.viewlog import T_TOLERANCE, Debug, read_view_jsonl
from omniloc.view.debug_inputs import read_frame_images, read_images, read_recording
from omniloc.view.model import Event, RobotRun, RunData


def event_label(event: events.Event) -> str:
    """'mode tracking r0, at 1.000 s': an event as the page's timeline names it."""
    e = event.raw
    kind = str(e.get("type", "event"))
    parts = [kind]
    if "mode" in e:
        parts = [f"mode {e['mode']}"]
    robot = e.get("robot")
    if isinstance(robot, int):
        parts.append(f"r{robot}")
    pose = e.get("pose")
    xyt = [p for p in pose if finite(p)] if isinstance(pose, list) else []
    if isinstance(pose, list) and len(pose) == 3 and len(xyt) == 3:
        parts.append("to ({:.2f}, {:.2f}, {:.2f} rad)".format(*xyt))
    for key in ("duration", "fraction", "level", "transition", "scale"):
        v = e.get(key)
        if finite(v):
            unit = " s" if key in ("duration", "transition") else ""
            parts.append(f"{key} {v:g}{unit}")
    for key in ("message", "comment", "reason", "what"):
        text = e.get(key)
        if isinstance(text, str):
            parts.append(text[:120])
    parts.append(f"at {event.t:.3f} s")
    return ", ".join(parts[:1]) + (" " + ", ".join(parts[1:]) if len(parts) > 1 else "")


def read_events(path: Path) -> List[Event]:
    """events.jsonl (omniloc.core.events) as the page shows it: each event with its label."""
    return [Event(t=float(e.t), type=str(e.raw.get("type", "event")), robot=e.robot, duration=e.duration, label=event_label(e))
            for e in events.read_events(path)]


def load_run(run_dir: Path, recording: Optional[Path] = None, image_every: int = 30, images: bool = True,
             frames_dir: Optional[Path] = None) -> RunData:
    """The run folder and what is given beside it: a recording (line points, blobs, images) and the
    PNGs of `omniloc run --frames DIR` (images; they win over a recording's)."""
    if not run_dir.exists():
        raise InputFileError(run_dir, "missing: expected a run folder (omniloc run / replay -o DIR)")
    if not run_dir.is_dir():
        raise InputFileError(run_dir, "not a folder: expected a run folder (omniloc run / replay -o DIR)")
    field_path = run_dir / "field.json"
    field = read_json_object(field_path, "the field's markings, a JSON object (docs/results.md)", True)
    check_field(field, field_path)
    summary = read_json_object(run_dir / "summary.json", "summary.json, a JSON object", False)
    config = read_json_object(run_dir / "config.json", "config.json, a JSON object", False)
    radius: Dict[int, float] = {}
    robots_config = config.get("robots", [])
    for rc in robots_config if isinstance(robots_config, list) else []:
        rid_config, rad = (rc.get("id"), rc.get("radius")) if isinstance(rc, dict) else (None, None)
        if isinstance(rid_config, int) and finite(rad):
            radius[rid_config] = float(rad)
    table = read_frame_table(run_dir / "frames.csv")
    ids, cols, modes, extra = table.ids, table.columns, table.modes, table.extra
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
            raise InputFileError(est_path, f"{len(est_rows)} rows: expected one per valid frame of r{rid}, "
                                           f"frames.csv has {nvalid}")
        estimate: List[Pose] = []
        from_tum: List[bool] = []
        j = 0
        for k in range(frames):
            if valid[k]:
                t, p = est_rows[j]
                if abs(t - times[rid][k]) > T_TOLERANCE:
                    raise InputFileError(est_path, f"t {t:.6f}: expected frame {k}'s t = {times[rid][k]:.4f} (frames.csv)", j + 1)
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
                raise InputFileError(gt_path, f"{len(gt_rows)} rows: expected one per frame of r{rid}, frames.csv has {frames}")
            for k, (t, _) in enumerate(gt_rows):
                if abs(t - times[rid][k]) > T_TOLERANCE:
                    raise InputFileError(gt_path, f"t {t:.6f}: expected frame {k}'s t = {times[rid][k]:.4f} (frames.csv)", k + 1)
            truth = [p for _, p in gt_rows]
        else:
            notes.append(f"no {gt_path.name}: the truth of r{rid} is not drawn")

        def col(name: str) -> List[Optional[float]]:
            return list(c[name]) if name in c else [None] * frames

        def flag(name: str) -> List[Optional[bool]]:
            return [None if v is None else bool(v) for v in col(name)]

        # The bound under the error curve: the posterior one where the run has it (tracking), else the single-frame one.
        kind: Optional[str] = None
        for prefix, label in (("pbound", "posterior"), ("bound", "single frame")):
            if any(v is not None for v in c.get(f"{prefix}_pos_m", [])):
                kind = label
                break
        if kind is None and "bound_pos_m" in c:
            kind = "none"  # the run scores the bound, and no frame has one (no truth): said, never drawn as 0
        prefix = "pbound" if kind == "posterior" else "bound"
        robots.append(RobotRun(id=rid, radius=radius.get(rid, 0.26), t=times[rid], truth=truth, estimate=estimate, est_from_tum=from_tum, valid=valid,
                               mode=modes[rid], camera_ok=flag("camera_ok"), line_points=col("line_points"),
                               match_error=col("match_error"), err_pos=col("err_pos"), err_theta=col("err_theta"),
                               bound_pos=col(f"{prefix}_pos_m") if kind else None, bound_theta=col(f"{prefix}_heading_rad") if kind else None,
                               bound_kind=kind,
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
        markings = head.field_markings
        if markings is not None:  # goal colours and landmarks, which field.json leaves out
            for key in ("goal_colours", "landmarks"):
                if key in markings and key not in field:
                    field[key] = markings[key]
        rec_images = head.images
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
