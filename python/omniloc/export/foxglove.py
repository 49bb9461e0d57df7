"""The Foxglove message types the export writes, in Foxglove's JSON encoding: each type's JSON Schema
(the MCAP schema record's data, encoding "jsonschema"; written here from Foxglove's message
reference, https://docs.foxglove.dev/docs/visualization/message-schemas, for the fields the export
fills) and builders for the messages. Foxglove decodes a channel by the schema's name
("foxglove.PointCloud") and reads byte fields as base64 where the schema says contentEncoding
"base64", which is why the byte fields carry it.

Times are {"sec", "nsec"}; poses are planar (z 0, rotation about z).
"""
from __future__ import annotations

import array
import base64
import json
import math
import sys
from typing import Optional, Sequence

from omniloc.core.jsonvalue import JSON, JSONObject

# ------------------------------------------------------------------------------------------ schemas

_NUMBER: JSONObject = {"type": "number"}


def _object(title: Optional[str], props: JSONObject, required: Optional[list[str]] = None) -> JSONObject:
    o: JSONObject = {"type": "object", "properties": props, "required": list(props) if required is None else list(required)}
    if title is not None:
        o["title"] = title
    return o


def _array(items: JSONObject) -> JSONObject:
    return {"type": "array", "items": items}


_TIME = _object("time", {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}})
_VECTOR3 = _object("foxglove.Vector3", {"x": _NUMBER, "y": _NUMBER, "z": _NUMBER})
_POINT3 = _object("foxglove.Point3", {"x": _NUMBER, "y": _NUMBER, "z": _NUMBER})
_QUATERNION = _object("foxglove.Quaternion", {"x": _NUMBER, "y": _NUMBER, "z": _NUMBER, "w": _NUMBER})
_POSE = _object("foxglove.Pose", {"position": _VECTOR3, "orientation": _QUATERNION})
_COLOR = _object("foxglove.Color", {"r": _NUMBER, "g": _NUMBER, "b": _NUMBER, "a": _NUMBER})
_DURATION = _object("duration", {"sec": {"type": "integer"}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}})
_STRING: JSONObject = {"type": "string"}
_BOOL: JSONObject = {"type": "boolean"}
_BYTES: JSONObject = {"type": "string", "contentEncoding": "base64"}


def _enum(title: str, values: Sequence[tuple[str, int]]) -> JSONObject:
    return {"title": title, "oneOf": [{"title": name, "const": v} for name, v in values]}


LINE_STRIP, LINE_LOOP, LINE_LIST = 0, 1, 2
FLOAT32, FLOAT64 = 7, 8
LOG_INFO, LOG_WARNING = 2, 3

_LINE = _object("foxglove.LinePrimitive", {
    "type": _enum("foxglove.LineType", [("LINE_STRIP", LINE_STRIP), ("LINE_LOOP", LINE_LOOP), ("LINE_LIST", LINE_LIST)]),
    "pose": _POSE, "thickness": _NUMBER, "scale_invariant": _BOOL, "points": _array(_POINT3), "color": _COLOR,
    "colors": _array(_COLOR), "indices": _array({"type": "integer", "minimum": 0})})
_SPHERE = _object("foxglove.SpherePrimitive", {"pose": _POSE, "size": _VECTOR3, "color": _COLOR})
_CUBE = _object("foxglove.CubePrimitive", {"pose": _POSE, "size": _VECTOR3, "color": _COLOR})
_CYLINDER = _object("foxglove.CylinderPrimitive", {"pose": _POSE, "size": _VECTOR3, "bottom_scale": _NUMBER, "top_scale": _NUMBER,
                                                   "color": _COLOR})
_PRIMITIVES = ("arrows", "cubes", "spheres", "cylinders", "lines", "triangles", "texts", "models")
# The primitive lists the export fills; the others are always empty (any items would do).
_FILLED: JSONObject = {"cubes": _array(_CUBE), "spheres": _array(_SPHERE), "cylinders": _array(_CYLINDER), "lines": _array(_LINE)}
_ENTITY = _object("foxglove.SceneEntity", {
    "timestamp": _TIME, "frame_id": _STRING, "id": _STRING, "lifetime": _DURATION, "frame_locked": _BOOL,
    "metadata": _array(_object("foxglove.KeyValuePair", {"key": _STRING, "value": _STRING})),
    **{k: _FILLED.get(k, {"type": "array", "maxItems": 0}) for k in _PRIMITIVES}})

SCHEMAS: dict[str, JSONObject] = {
    "foxglove.SceneUpdate": _object("foxglove.SceneUpdate", {
        "deletions": _array(_object("foxglove.SceneEntityDeletion", {"timestamp": _TIME, "type": {"type": "integer"}, "id": _STRING})),
        "entities": _array(_ENTITY)}),
    "foxglove.PoseInFrame": _object("foxglove.PoseInFrame", {"timestamp": _TIME, "frame_id": _STRING, "pose": _POSE}),
    "foxglove.PosesInFrame": _object("foxglove.PosesInFrame", {"timestamp": _TIME, "frame_id": _STRING, "poses": _array(_POSE)}),
    "foxglove.FrameTransform": _object("foxglove.FrameTransform", {
        "timestamp": _TIME, "parent_frame_id": _STRING, "child_frame_id": _STRING, "translation": _VECTOR3, "rotation": _QUATERNION}),
    "foxglove.PointCloud": _object("foxglove.PointCloud", {
        "timestamp": _TIME, "frame_id": _STRING, "pose": _POSE, "point_stride": {"type": "integer", "minimum": 0},
        "fields": _array(_object("foxglove.PackedElementField", {
            "name": _STRING, "offset": {"type": "integer", "minimum": 0},
            "type": _enum("foxglove.NumericType", [("FLOAT32", FLOAT32), ("FLOAT64", FLOAT64)])})),
        "data": _BYTES}),
    "foxglove.CompressedImage": _object("foxglove.CompressedImage", {"timestamp": _TIME, "frame_id": _STRING, "data": _BYTES,
                                                                     "format": _STRING}),
    "foxglove.Log": _object("foxglove.Log", {
        "timestamp": _TIME, "level": _enum("foxglove.LogLevel", [("INFO", LOG_INFO), ("WARNING", LOG_WARNING)]),
        "message": _STRING, "name": _STRING, "file": _STRING, "line": {"type": "integer", "minimum": 0}}),
}

# omniloc's own per-frame numbers (frames.csv's columns, a recording's per-frame values): flat, so a
# Plot panel plots each by path (/r0/numbers.err_pos) and the State Transitions panel shows `mode`.
# A key is left out of a frame where frames.csv's cell is empty.
FRAME_NUMBERS = "omniloc.FrameNumbers"
SCHEMAS[FRAME_NUMBERS] = {
    "title": FRAME_NUMBERS, "type": "object", "required": ["timestamp", "t", "k"],
    "description": "One frame's numbers: frames.csv's columns (docs/results.md) or a recording's per-frame values",
    "properties": {"timestamp": _TIME, "t": _NUMBER, "k": {"type": "integer", "minimum": 0}, "mode": _STRING},
    "additionalProperties": {"type": ["number", "boolean", "string"]}}

# ------------------------------------------------------------------------------------------ builders


def stamp(ns: int) -> JSONObject:
    return {"sec": ns // 1_000_000_000, "nsec": ns % 1_000_000_000}


def nanoseconds(t: float) -> int:
    """A frame's time (s from the start) as MCAP's log time; times before 0 are not written."""
    return max(0, round(t * 1e9))


def yaw_quaternion(theta: float) -> JSONObject:
    return {"x": 0.0, "y": 0.0, "z": math.sin(theta / 2.0), "w": math.cos(theta / 2.0)}


def planar_pose(x: float, y: float, theta: float, z: float = 0.0) -> JSONObject:
    return {"position": {"x": x, "y": y, "z": z}, "orientation": yaw_quaternion(theta)}


IDENTITY = planar_pose(0.0, 0.0, 0.0)


def color(r: float, g: float, b: float, a: float = 1.0) -> JSONObject:
    return {"r": r, "g": g, "b": b, "a": a}


def pose_in_frame(ns: int, frame: str, x: float, y: float, theta: float) -> JSONObject:
    return {"timestamp": stamp(ns), "frame_id": frame, "pose": planar_pose(x, y, theta)}


def frame_transform(ns: int, parent: str, child: str, x: float, y: float, theta: float) -> JSONObject:
    return {"timestamp": stamp(ns), "parent_frame_id": parent, "child_frame_id": child,
            "translation": {"x": x, "y": y, "z": 0.0}, "rotation": yaw_quaternion(theta)}


def poses_in_frame(ns: int, frame: str, poses: Sequence[tuple[float, float, float]]) -> bytes:
    """A foxglove.PosesInFrame, JSON-encoded here: a 60 s MCL run has some 360 000 particles, and
    formatting each pose directly takes a fraction of building and encoding dicts. The text is what
    json.dumps writes (floats by repr), compact."""
    sin, cos = math.sin, math.cos
    items = ",".join(f'{{"position":{{"x":{float(x)!r},"y":{float(y)!r},"z":0.0}},'
                     f'"orientation":{{"x":0.0,"y":0.0,"z":{sin(th / 2.0)!r},"w":{cos(th / 2.0)!r}}}}}' for x, y, th in poses)
    for v in (x for p in poses for x in p):
        if not math.isfinite(v):
            raise ValueError("a pose that is not finite")
    head = f'{{"timestamp":{{"sec":{ns // 1_000_000_000},"nsec":{ns % 1_000_000_000}}},"frame_id":{json.dumps(frame)},"poses":['
    return (head + items + "]}").encode("utf-8")


def point_cloud(ns: int, frame: str, points: Sequence[tuple[float, float]]) -> JSONObject:
    """Planar points (x, y) in `frame`. Stored as float32 where every coordinate is a float32 value
    (view.jsonl's points, which the C++ side holds as float), else as float64, so that a reader
    gets the file's numbers exactly either way."""
    flat = [v for p in points for v in p]
    try:
        packed = array.array("f", flat)
        exact32 = packed.tolist() == flat
    except OverflowError:
        exact32 = False
    if not exact32:
        packed = array.array("d", flat)
    if sys.byteorder != "little":
        packed.byteswap()
    size, code = (4, FLOAT32) if exact32 else (8, FLOAT64)
    fields: list[JSON] = [{"name": "x", "offset": 0, "type": code}, {"name": "y", "offset": size, "type": code}]
    return {"timestamp": stamp(ns), "frame_id": frame, "pose": IDENTITY, "point_stride": 2 * size, "fields": fields,
            "data": base64.b64encode(packed.tobytes()).decode("ascii")}


def compressed_image(ns: int, frame: str, png: bytes) -> JSONObject:
    return {"timestamp": stamp(ns), "frame_id": frame, "data": base64.b64encode(png).decode("ascii"), "format": "png"}


def log(ns: int, level: int, message: str, name: str, file: str, line: int) -> JSONObject:
    return {"timestamp": stamp(ns), "level": level, "message": message, "name": name, "file": file, "line": line}


def entity(ns: int, frame: str, ident: str, lines: Optional[list[JSON]] = None, spheres: Optional[list[JSON]] = None,
           cylinders: Optional[list[JSON]] = None, cubes: Optional[list[JSON]] = None,
           lifetime_ns: int = 0) -> JSONObject:
    """A scene entity: lifetime 0 keeps it until an entity with the same id replaces it."""
    e: JSONObject = {"timestamp": stamp(ns), "frame_id": frame, "id": ident,
                     "lifetime": {"sec": lifetime_ns // 1_000_000_000, "nsec": lifetime_ns % 1_000_000_000},
                     "frame_locked": False, "metadata": []}
    given: dict[str, Optional[list[JSON]]] = {"cubes": cubes, "spheres": spheres, "cylinders": cylinders, "lines": lines}
    for k in _PRIMITIVES:
        e[k] = given.get(k) or []
    return e


def scene_update(entities: list[JSON]) -> JSONObject:
    return {"deletions": [], "entities": entities}


def line(kind: int, points: Sequence[tuple[float, float]], rgba: JSONObject, thickness: float, z: float = 0.0) -> JSONObject:
    """A line primitive in metres (thickness too: not scale invariant)."""
    pts: list[JSON] = [{"x": x, "y": y, "z": z} for x, y in points]
    return {"type": kind, "pose": IDENTITY, "thickness": thickness, "scale_invariant": False, "points": pts, "color": rgba,
            "colors": [], "indices": []}


def sphere(x: float, y: float, z: float, diameter: float, rgba: JSONObject) -> JSONObject:
    return {"pose": planar_pose(x, y, 0.0, z), "size": {"x": diameter, "y": diameter, "z": diameter}, "color": rgba}


def cylinder(x: float, y: float, theta: float, size_x: float, size_y: float, height: float, rgba: JSONObject) -> JSONObject:
    return {"pose": planar_pose(x, y, theta, height / 2.0), "size": {"x": size_x, "y": size_y, "z": height},
            "bottom_scale": 1.0, "top_scale": 1.0, "color": rgba}


def cube(x: float, y: float, theta: float, size: tuple[float, float, float], rgba: JSONObject) -> JSONObject:
    return {"pose": planar_pose(x, y, theta, size[2] / 2.0), "size": {"x": size[0], "y": size[1], "z": size[2]}, "color": rgba}
