"""A recording folder (omniloc-recording/1, docs/recording.md): recording.json (the header) and its
frames (frames.jsonl or frames.jsonl.gz: one JSON object per frame, {"k", "t", "robots": [...]},
each robot's odometry, line points, blobs, truth ...), and images/ where recorded with --images.

read_header() is lenient (None where the folder holds no readable header: the report looks for
recordings among many folders); load_header() and read_frames() are strict and raise
InputFileError naming the file and line (the run viewer, and the report once it has a recording).
"""
from __future__ import annotations

import gzip
import json
import pathlib
from dataclasses import dataclass, field
from typing import Optional

from omniloc.core.files import InputFileError, check_file, json_lines, read_text
from omniloc.core.jsonvalue import JSON, JSONObject, finite, lst, numbers, obj, parse, text

FORMAT = "omniloc-recording/1"


@dataclass(frozen=True)
class Reference:
    """A real recording's reference pose (found by an exhaustive search, not measured) and its
    180-degree twin (-x, -y, theta + pi), which fits the points of a point-symmetric field as well."""
    reference: list[float]
    twin: list[float]


@dataclass(frozen=True)
class RecordingHeader:
    """recording.json; raw holds every key (the scenario as recorded, the field, the robots)."""
    folder: pathlib.Path
    raw: JSONObject

    @property
    def name(self) -> Optional[str]:
        return text(self.raw.get("name"))

    @property
    def seed(self) -> JSON:
        return self.raw.get("seed")

    @property
    def scenario(self) -> Optional[JSONObject]:
        """The scenario the recording was made from, where it records one (a JSON object)."""
        sc = self.raw.get("scenario")
        return sc if isinstance(sc, dict) else None

    @property
    def ground_truth(self) -> bool:
        """Whether every robot of every frame has its truth (true where the header does not say)."""
        return bool(self.raw.get("ground_truth", True))

    @property
    def images(self) -> bool:
        """Whether images/ holds every frame's camera image (recorded with --images)."""
        return self.raw.get("images") is True

    @property
    def robot_ids(self) -> list[JSON]:
        """The ids of the robots the recording holds, in the frames' order."""
        return [r.get("id") for r in lst(self.raw.get("robots")) if isinstance(r, dict)]

    @property
    def frames(self) -> JSON:
        """How many frames the header says the recording holds."""
        return self.raw.get("frames")

    @property
    def frames_file(self) -> JSON:
        return self.raw.get("frames_file", "frames.jsonl")

    @property
    def frames_path(self) -> pathlib.Path:
        return self.folder / str(self.frames_file)

    @property
    def field_markings(self) -> Optional[JSONObject]:
        """The field's markings the recording carries (goal colours, landmarks beyond field.json's)."""
        fm = self.raw.get("field_markings")
        return fm if isinstance(fm, dict) else None

    @property
    def reference(self) -> Optional[Reference]:
        """The reference pose and its twin of a real recording; None where it has neither."""
        ref = self.raw.get("reference")
        if not isinstance(ref, dict) or not isinstance(ref.get("reference"), list) or not isinstance(ref.get("twin"), list):
            return None
        return Reference(reference=numbers(ref.get("reference")) or [], twin=numbers(ref.get("twin")) or [])


def read_header(folder: pathlib.Path) -> Optional[RecordingHeader]:
    """The header of the recording in `folder`, or None where there is no readable JSON object."""
    try:
        raw = parse((folder / "recording.json").read_text())
    except (OSError, ValueError):
        return None
    return RecordingHeader(folder=folder, raw=raw) if isinstance(raw, dict) else None


def load_header(folder: pathlib.Path) -> RecordingHeader:
    """The header of the recording in `folder`: InputFileError unless it is an omniloc-recording/1 one."""
    head_path = folder / "recording.json"
    if not folder.is_dir():
        raise InputFileError(folder, "not a folder: expected a recording (omniloc record, docs/recording.md)")
    head_text = read_text(head_path, "recording.json of a recording (docs/recording.md)")
    try:
        head = parse(head_text)
    except json.JSONDecodeError as err:
        raise InputFileError(head_path, f"expected a JSON object ({err.msg})", err.lineno) from None
    if not isinstance(head, dict) or head.get("format") != FORMAT:
        raise InputFileError(head_path, f"expected `format` \"{FORMAT}\"")
    return RecordingHeader(folder=folder, raw=head)


@dataclass(frozen=True)
class RecordingFrame:
    """One frame of a recording: its line in the frames file, index k, time t, each robot's raw
    object (in the header's robot order) and the scenario's events applied on the way to it."""
    line: int
    k: int
    t: float
    robots: list[JSON]
    events: list[JSON] = field(default_factory=list)

    def robot(self, index: int) -> JSONObject:
        """The `index`-th robot's object ({} where there is none or it is not an object)."""
        return obj(self.robots[index]) if index < len(self.robots) else {}


def read_frames(header: RecordingHeader) -> list[RecordingFrame]:
    """Every frame of the recording, in order; InputFileError where the file is missing, unreadable,
    or a line is not a frame {"k": its index, "t", "robots": [...]}."""
    fpath = header.frames_path
    check_file(fpath, "the recording's frames (docs/recording.md section 4)")
    try:
        if str(header.frames_file).endswith(".gz"):
            with gzip.open(fpath) as fh:
                raw = fh.read()
        else:
            raw = fpath.read_bytes()
        content = raw.decode("utf-8")
    except (OSError, EOFError, UnicodeDecodeError) as e:
        raise InputFileError(fpath, f"unreadable ({e.__class__.__name__}): expected gzip of JSON lines") from None
    out: list[RecordingFrame] = []
    for n, f in json_lines(content, fpath, expected="one JSON object per frame", skip_blank=False):
        t = f.get("t") if isinstance(f, dict) else None
        robots = f.get("robots") if isinstance(f, dict) else None
        if not isinstance(f, dict) or f.get("k") != n - 1 or not finite(t) or not isinstance(robots, list):
            raise InputFileError(fpath, f"expected a frame {{\"k\": {n - 1}, \"t\", \"robots\": [...]}}", n)
        events = f.get("events", [])
        if not isinstance(events, list):
            raise InputFileError(fpath, "`events`: expected a list of event objects (docs/recording.md section 4)", n)
        out.append(RecordingFrame(line=n, k=n - 1, t=t, robots=lst(robots), events=events))
    return out
