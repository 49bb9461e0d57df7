"""A run folder or a recording as Foxglove messages on topics (docs/viewer.md section "Foxglove"):

  /field                   foxglove.SceneUpdate   the field's markings, once at the first frame (latched)
  /tf                      foxglove.FrameTransform world -> r<id>/truth, world -> r<id>/estimate
                                                   (a recording without truth: world -> r<id>/odometry)
  /r<id>/truth             foxglove.PoseInFrame   the true pose (world)
  /r<id>/estimate          foxglove.PoseInFrame   the estimate of each valid frame: est.tum's rows
  /r<id>/line_points       foxglove.PointCloud    the frame's line points (robot frame, at the estimate)
  /r<id>/particles         foxglove.PosesInFrame  the localizer's particles (world; view.jsonl)
  /r<id>/points            foxglove.PointCloud    the localizer's own points (world; view.jsonl)
  /r<id>/uncertainty       foxglove.SceneUpdate   the estimate's 2-sigma position ellipse (view.jsonl's covariance)
  /r<id>/blobs             foxglove.SceneUpdate   blobs as bearing rays, a blob of kind "ball" as a sphere
  /r<id>/camera            foxglove.CompressedImage the camera image (PNG as recorded with --images)
  /r<id>/numbers           omniloc.FrameNumbers   frames.csv's numbers (errors, valid, mode, match error,
                                                   bounds, the localizer's columns) for Plot panels
  /events                  foxglove.Log           events.jsonl (a recording: its frames' events)

Every message's log and publish time is its frame's t (nanoseconds from the run's start).
"""
from __future__ import annotations

import json
import math
import pathlib
from dataclasses import dataclass, field
from typing import Optional, Sequence

from omniloc.core import events
from omniloc.core.files import InputFileError, check_file
from omniloc.core.framedata import Blob, blobs, pairs
from omniloc.core.jsonvalue import JSON, JSONObject, finite, lst, numbers, obj, text
from omniloc.core.recording import RecordingHeader, read_frames
from omniloc.core.runfiles import FrameTable
from omniloc.core.viewlog import Debug
from omniloc.export import foxglove
from omniloc.view.load import event_label
from omniloc.view.model import RunData

WORLD = "world"
LINE_WHITE = foxglove.color(1.0, 1.0, 1.0, 1.0)
BLOB_COLOURS = {"yellow": (1.0, 0.84, 0.0), "blue": (0.16, 0.38, 1.0), "red": (0.9, 0.22, 0.21), "white": (1.0, 1.0, 1.0),
                "orange": (1.0, 0.43, 0.0), "green": (0.0, 0.78, 0.33)}
# A blob without a distance is drawn as a ray this long (m): its bearing is all the frame knows.
RAY_M = 3.0


@dataclass
class Scene:
    """Messages by topic, each topic with its schema name and channel metadata, in the order added."""
    topics: dict[str, tuple[str, dict[str, str]]] = field(default_factory=dict)
    messages: list[tuple[str, int, JSONObject | bytes]] = field(default_factory=list)  # bytes: already JSON
    # Camera images: topic, ns, frame id, the PNG's path (checked to be a readable file; read while
    # the file is written, one chunk at a time).
    images: list[tuple[str, int, str, pathlib.Path]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def add(self, topic: str, schema: str, ns: int, message: JSONObject | bytes, latched: bool = False) -> None:
        if topic not in self.topics:
            self.topics[topic] = (schema, {"latching": "1"} if latched else {})
        self.messages.append((topic, ns, message))


# ------------------------------------------------------------------------------------------ the field

def _arc_points(cx: float, cy: float, r: float, start: float, sweep: float) -> list[tuple[float, float]]:
    n = max(8, int(abs(sweep) / (2 * math.pi) * 96))
    return [(cx + r * math.cos(start + sweep * i / n), cy + r * math.sin(start + sweep * i / n)) for i in range(n + 1)]


def _num(v: JSON, default: float) -> float:
    return float(v) if finite(v) else default


def field_update(ns: int, f: JSONObject) -> JSONObject:
    """The field's markings (field.json or a recording's field_markings) as one scene entity: lines
    and arcs as lines of the painted width, spots as flat discs, goals as the net's outline."""
    width = _num(f.get("line_width"), 0.125)
    segments = [s for s in (numbers(v) for v in lst(f.get("segments"))) if s is not None and len(s) == 4]
    lines: list[JSON] = []
    if segments:
        lines.append(foxglove.line(foxglove.LINE_LIST, [p for s in segments for p in ((s[0], s[1]), (s[2], s[3]))], LINE_WHITE, width))
    for a in (numbers(v) for v in lst(f.get("arcs"))):
        if a is not None and len(a) == 5:
            lines.append(foxglove.line(foxglove.LINE_STRIP, _arc_points(*a), LINE_WHITE, width))
    colours = [text(c) or "white" for c in lst(f.get("goal_colours"))]
    for i, g in enumerate(numbers(v) for v in lst(f.get("goals"))):
        if g is None or len(g) != 3:
            continue
        x, w, depth = g
        back = x + math.copysign(depth, x)
        rgb = BLOB_COLOURS.get(colours[i] if i < len(colours) else "white", (1.0, 1.0, 1.0))
        lines.append(foxglove.line(foxglove.LINE_STRIP, [(x, -w / 2), (back, -w / 2), (back, w / 2), (x, w / 2)], foxglove.color(*rgb), 0.08, 0.01))
    cylinders: list[JSON] = []
    for s in (numbers(v) for v in lst(f.get("spots"))):
        if s is not None and len(s) == 3:
            cylinders.append(foxglove.cylinder(s[0], s[1], 0.0, 2 * s[2], 2 * s[2], 0.005, LINE_WHITE))
    spheres: list[JSON] = []
    for lm in lst(f.get("landmarks")):
        pos = numbers(obj(lm).get("position"))
        if pos is not None and len(pos) >= 2:
            rgb = BLOB_COLOURS.get(text(obj(lm).get("colour")) or "", (1.0, 1.0, 1.0))
            size = obj(lm).get("size")
            spheres.append(foxglove.sphere(pos[0], pos[1], 0.1, float(size) if finite(size) else 0.2, foxglove.color(*rgb)))
    length, wide = f.get("length"), f.get("width")
    cubes: list[JSON] = []
    if finite(length) and finite(wide):  # the carpet, just below the lines
        margin = _num(f.get("margin"), 0.0)
        carpet = foxglove.cube(0.0, 0.0, 0.0, (float(length) + 2 * margin, float(wide) + 2 * margin, 0.002), foxglove.color(0.13, 0.45, 0.2, 1.0))
        carpet["pose"] = foxglove.planar_pose(0.0, 0.0, 0.0, -0.002)
        cubes.append(carpet)
    return foxglove.scene_update([foxglove.entity(ns, WORLD, "field", lines=lines, cylinders=cylinders, spheres=spheres, cubes=cubes)])


# ------------------------------------------------------------------------------------------ per frame

def ellipse_2sigma(cov: Sequence[float]) -> Optional[tuple[float, float, float]]:
    """The 2-sigma position ellipse of a covariance (x, y, theta; 9 numbers row-major): full axes
    (m) and the major axis's angle; None where the xy block is not positive semi-definite."""
    a, b, d = cov[0], cov[1], cov[4]
    mean, diff = (a + d) / 2, math.hypot((a - d) / 2, b)
    l1, l2 = mean + diff, mean - diff
    if l2 < -1e-12 or not math.isfinite(l1):
        return None
    return 4 * math.sqrt(max(l1, 0.0)), 4 * math.sqrt(max(l2, 0.0)), 0.5 * math.atan2(2 * b, a - d)


def blob_update(ns: int, frame: str, found: Sequence[Blob]) -> JSONObject:
    """Blobs in the robot frame: a ray along each bearing to its distance (RAY_M where unknown); a
    ball (kind "ball") also as a 22 cm sphere where its distance is known."""
    lines: list[JSON] = []
    spheres: list[JSON] = []
    for b in found:
        rgb = BLOB_COLOURS.get(b.colour, (0.8, 0.8, 0.8))
        reach = b.distance if b.distance is not None else RAY_M
        end = (reach * math.cos(b.bearing), reach * math.sin(b.bearing))
        lines.append(foxglove.line(foxglove.LINE_STRIP, [(0.0, 0.0), end], foxglove.color(*rgb, 0.8), 0.02, 0.05))
        if b.kind == "ball" and b.distance is not None:
            spheres.append(foxglove.sphere(end[0], end[1], 0.11, 0.22, foxglove.color(*rgb)))
    return foxglove.scene_update([foxglove.entity(ns, frame, "blobs", lines=lines, spheres=spheres)])


def add_debug(scene: Scene, rid: int, ns: int, frame: str, d: Debug, estimate: tuple[float, float, float], particles: int) -> None:
    """One frame's view.jsonl (or recording) data of robot `rid`; `frame` is where its robot-frame data sits."""
    scene.add(f"/r{rid}/line_points", "foxglove.PointCloud", ns, foxglove.point_cloud(ns, frame, d.line_points))
    if d.blobs or f"/r{rid}/blobs" in scene.topics:
        scene.add(f"/r{rid}/blobs", "foxglove.SceneUpdate", ns, blob_update(ns, frame, d.blobs))
    if d.particles is not None and particles > 0:
        step = max(1, math.ceil(len(d.particles) / particles))
        scene.add(f"/r{rid}/particles", "foxglove.PosesInFrame", ns,
                  foxglove.poses_in_frame(ns, WORLD, [(p[0], p[1], p[2]) for p in d.particles[::step]]))
    if d.points is not None:
        scene.add(f"/r{rid}/points", "foxglove.PointCloud", ns, foxglove.point_cloud(ns, WORLD, d.points))
    if d.covariance is not None:
        e = ellipse_2sigma(d.covariance)
        cyl: list[JSON] = [] if e is None else [
            foxglove.cylinder(estimate[0], estimate[1], e[2], e[0], e[1], 0.01, foxglove.color(1.0, 0.9, 0.0, 0.35))]
        update = foxglove.scene_update([foxglove.entity(ns, WORLD, "ellipse_2sigma", cylinders=cyl)])
        scene.add(f"/r{rid}/uncertainty", "foxglove.SceneUpdate", ns, update)


def _number_value(v: Optional[float]) -> JSON:
    """A frames.csv number as JSON: an integer where it is one (valid 1, a count), else the float."""
    if v is None:
        return None
    return int(v) if v.is_integer() and abs(v) < 2**53 else v


def run_scene(run: RunData, table: FrameTable, images: dict[int, dict[int, pathlib.Path]], particles: int) -> Scene:
    """The run (omniloc.view.load.load_run) as messages; `table`: its frames.csv (each frame's
    numbers); `images`: per robot, frame k -> its PNG."""
    scene = Scene(notes=list(run["notes"]))
    robots = run["robots"]
    first = foxglove.nanoseconds(robots[0]["t"][0]) if robots and robots[0]["t"] else 0
    scene.add("/field", "foxglove.SceneUpdate", first, field_update(first, run["field"]), latched=True)
    for r in robots:
        rid = r["id"]
        debug = r["debug"]
        est_frame, truth_frame = f"r{rid}/estimate", f"r{rid}/truth"
        # Every column of frames.csv, whatever the build wrote (the localizer's own, the accuracy
        # bounds): a Plot panel can then plot any of them.
        columns = {name: col for name, col in table.columns[rid].items() if name != "t"}
        for k, t in enumerate(r["t"]):
            ns = foxglove.nanoseconds(t)
            e = r["estimate"][k]
            if r["truth"] is not None:
                g = r["truth"][k]
                scene.add("/tf", "foxglove.FrameTransform", ns, foxglove.frame_transform(ns, WORLD, truth_frame, g.x, g.y, g.theta))
                scene.add(f"/r{rid}/truth", "foxglove.PoseInFrame", ns, foxglove.pose_in_frame(ns, WORLD, g.x, g.y, g.theta))
            scene.add("/tf", "foxglove.FrameTransform", ns, foxglove.frame_transform(ns, WORLD, est_frame, e.x, e.y, e.theta))
            if r["est_from_tum"][k]:
                scene.add(f"/r{rid}/estimate", "foxglove.PoseInFrame", ns, foxglove.pose_in_frame(ns, WORLD, e.x, e.y, e.theta))
            nums: JSONObject = {"timestamp": foxglove.stamp(ns), "t": t, "k": k, "mode": table.modes[rid][k]}
            for name, col in columns.items():
                v = _number_value(col[k])
                if v is not None:
                    nums[name] = v
            scene.add(f"/r{rid}/numbers", foxglove.FRAME_NUMBERS, ns, nums)
            if debug is not None:
                add_debug(scene, rid, ns, est_frame, debug[k], (e.x, e.y, e.theta), particles)
            png = images.get(rid, {}).get(k)
            if png is not None:
                scene.images.append((f"/r{rid}/camera", ns, f"r{rid}/camera", png))
    for n, ev in enumerate(run["events"], 1):
        ns = foxglove.nanoseconds(ev["t"])
        scene.add("/events", "foxglove.Log", ns, foxglove.log(ns, _level(ev["type"]), ev["label"], "omniloc", "events.jsonl", n))
    return scene


def _level(kind: Optional[str]) -> int:
    """Events that move or blind a robot are warnings in a Log panel; the rest information."""
    return foxglove.LOG_WARNING if kind in ("kidnap", "teleport", "cover") else foxglove.LOG_INFO


# ------------------------------------------------------------------------------------------ a recording

def image_path(folder: pathlib.Path, rid: int, k: int) -> pathlib.Path:
    """A recording's image of robot `rid` in frame k, checked to be a readable file."""
    path = folder / "images" / f"r{rid}_{k:06d}.png"
    check_file(path, "the frame's image (the recording says it holds every image)")
    return path


def read_png(path: pathlib.Path) -> bytes:
    """A recorded camera image's bytes; InputFileError unless it is a readable PNG."""
    check_file(path, "the frame's image (the recording says it holds every image)")
    try:
        data = path.read_bytes()
    except OSError as err:
        raise InputFileError(path, f"unreadable ({err.strerror}): expected the frame's PNG") from None
    if not data.startswith(b"\x89PNG\r\n\x1a\n"):
        raise InputFileError(path, "expected a PNG image")
    return data


def _triple(robot: JSONObject, key: str, path: pathlib.Path, line: int) -> Optional[list[float]]:
    """`key`'s [x, y, theta] of a recording's robot; None where absent or null; InputFileError where
    it is something else (docs/recording.md section 4)."""
    v = robot.get(key)
    if v is None:
        return None
    xs = numbers(v)
    if xs is None or len(xs) != 3 or not all(math.isfinite(x) for x in xs):
        raise InputFileError(path, f"`{key}`: expected [x, y, theta], three finite numbers, got {json.dumps(v)[:60]}", line)
    return xs


def recording_scene(head: RecordingHeader, image_every: int, with_images: bool) -> Scene:
    """A recording (omniloc record, or a real robot's log) as messages: truth (where recorded), else
    the odometry integrated from each robot's start (or the origin), with line points and blobs in
    that robot frame; the frames' numbers; events; images."""
    frames = read_frames(head)
    fpath = head.frames_path
    scene = Scene()
    first = foxglove.nanoseconds(frames[0].t) if frames else 0
    markings = head.field_markings
    raw_field = head.raw.get("field")
    field_obj = markings if markings is not None else (raw_field if isinstance(raw_field, dict) else None)
    if field_obj is not None:
        scene.add("/field", "foxglove.SceneUpdate", first, field_update(first, field_obj), latched=True)
    else:
        scene.notes.append(f"recording.json holds no field_markings (field {raw_field!r}): no /field")
    ids = head.robot_ids
    starts: dict[int, tuple[float, float, float]] = {}
    for r in lst(head.raw.get("robots")):
        rid, start = obj(r).get("id"), numbers(obj(r).get("start"))
        if isinstance(rid, int) and start is not None and len(start) == 3 and all(math.isfinite(x) for x in start):
            starts[rid] = (start[0], start[1], start[2])
    odo: dict[int, tuple[float, float, float]] = {}
    for f in frames:
        ns = foxglove.nanoseconds(f.t)
        n = f.line
        for i, rid_json in enumerate(ids):
            r = f.robot(i)
            rid = r.get("robot")
            if not isinstance(rid, int) or rid != rid_json:
                raise InputFileError(fpath, f"expected robot {rid_json} in place {i}", n)
            truth = _triple(r, "truth", fpath, n)
            if truth is not None and len(truth) == 3:
                frame = f"r{rid}/truth"
                pose = (truth[0], truth[1], truth[2])
                scene.add(f"/r{rid}/truth", "foxglove.PoseInFrame", ns, foxglove.pose_in_frame(ns, WORLD, *pose))
            else:
                frame = f"r{rid}/odometry"
                step = _triple(r, "odometry", fpath, n)
                if step is None:
                    raise InputFileError(fpath, "`odometry`: expected [dx, dy, dtheta]", n)
                x, y, th = odo.get(rid, starts.get(rid, (0.0, 0.0, 0.0)))
                pose = (x + step[0] * math.cos(th) - step[1] * math.sin(th), y + step[0] * math.sin(th) + step[1] * math.cos(th),
                        th + step[2])
                odo[rid] = pose
            scene.add("/tf", "foxglove.FrameTransform", ns, foxglove.frame_transform(ns, WORLD, frame, *pose))
            lp = pairs(r.get("line_points"), fpath, n, "line_points")
            d = Debug(line_points=lp, blobs=blobs(r.get("blobs"), fpath, n), covariance=None, particles=None, points=None)
            add_debug(scene, rid, ns, frame, d, pose, 0)
            nums: JSONObject = {"timestamp": foxglove.stamp(ns), "t": f.t, "k": f.k, "line_points": len(lp)}
            for key in ("camera_ok", "covered", "contact", "stop_robot"):
                v = r.get(key)
                if isinstance(v, bool):
                    nums[key] = 1 if v else 0
            heading = r.get("heading")
            if finite(heading):
                nums["heading"] = heading
            step_o = _triple(r, "odometry", fpath, n)
            if step_o is not None and len(step_o) == 3:
                nums["odometry_dx"], nums["odometry_dy"], nums["odometry_dtheta"] = step_o
            cam = obj(r.get("camera"))
            for key in ("exposure_ms", "gain"):
                if finite(cam.get(key)):
                    nums[key] = cam[key]
            scene.add(f"/r{rid}/numbers", foxglove.FRAME_NUMBERS, ns, nums)
            if with_images and head.images and f.k % image_every == 0:
                scene.images.append((f"/r{rid}/camera", ns, f"r{rid}/camera", image_path(head.folder, rid, f.k)))
        for ev in f.events + [e for i in range(len(ids)) for e in lst(f.robot(i).get("events"))]:
            e = obj(ev)
            t = e.get("t")
            if not finite(t):
                raise InputFileError(fpath, "`events`: expected objects with a number `t`", n)
            robot = e.get("robot")
            label = event_label(events.Event(t=t, type=text(e.get("type")), robot=robot if isinstance(robot, int) else None,
                                             duration=None, raw=e))
            ev_ns = foxglove.nanoseconds(t)
            scene.add("/events", "foxglove.Log", ev_ns, foxglove.log(ev_ns, _level(text(e.get("type"))), label, "omniloc", fpath.name, n))
    return scene
