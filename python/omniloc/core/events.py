"""events.jsonl of a run folder (docs/results.md): one JSON object per event, in time order, each
with its time `t` (s) and `type` (kidnap, cover, teleport, occlude, lights, camera, mode, ...).
"""
from __future__ import annotations

import pathlib
from dataclasses import dataclass
from typing import Optional

from omniloc.core.files import InputFileError, json_lines, read_text
from omniloc.core.jsonvalue import JSONObject, finite, text

# The events that the report and the viewer mark on a run, with their colours.
EVENT_COLOURS = {"kidnap": "red", "cover": "black", "teleport": "red", "occlude": "grey", "lights": "orange", "camera": "purple"}


@dataclass(frozen=True)
class Event:
    """One line of events.jsonl. t keeps the file's number (an int where it wrote one); type is None
    where the line has no string type; raw is the whole object (the viewer's label reads its
    other keys)."""
    t: float
    type: Optional[str]
    robot: Optional[int]
    duration: Optional[float]
    raw: JSONObject

    @property
    def marked(self) -> bool:
        """Whether the report and the viewer mark the event (EVENT_COLOURS)."""
        return self.type in EVENT_COLOURS


def read_events(path: pathlib.Path, skip_bad: bool = False) -> list[Event]:
    """The events of events.jsonl at `path`; [] without the file. A line that is not a JSON object
    with a number `t` raises InputFileError naming the line, or with skip_bad is left out (the
    report's cause of an outlying seed reads what it can)."""
    events: list[Event] = []
    if not path.exists():
        return events
    content = path.read_text() if skip_bad else read_text(path, "events, one JSON object per line")
    for n, e in json_lines(content, path, skip_bad=skip_bad):
        t = e.get("t") if isinstance(e, dict) else None
        if not isinstance(e, dict) or not finite(t):
            if skip_bad:
                continue
            raise InputFileError(path, "expected a JSON object with a number `t`", n)
        robot, duration = e.get("robot"), e.get("duration")
        events.append(Event(t=t, type=text(e.get("type")), robot=robot if isinstance(robot, int) else None,
                            duration=float(duration) if finite(duration) else None, raw=e))
    return events
