"""Reading result folders: run folders (summary.json, config.json, frames.csv, timing.csv), sweep
folders (aggregate.json, runs.csv, runs/) and experiment folders (docs/results.md).

discover() finds them under any folders given; Run reads one run folder on demand. A sweep folder
whose aggregate is not final stops discover() unless the caller accepts incomplete sweeps; those
are listed in INCOMPLETE so a tool can say so. find() / pointer() read a value by path or JSON
pointer and tell a null (a statistic over no frame: (True, None)) from an absent key.
"""
from __future__ import annotations

import json
import os
import pathlib
from typing import Any, Iterable, Sequence

from omniloc.core.aggregate import read_aggregate, read_run_ids
from omniloc.core.files import read_csv

def _skip_dir(d: Any) -> Any:
    return d.name.startswith(".") or ".staging" in d.name or d.name.endswith(".tmp") or ".partial" in d.name


# Sweep folders used although their aggregate was not final (discover(..., accept_incomplete=True)),
# so a tool can say so in its output.
INCOMPLETE = []


def incomplete_reason(d: Any, files: Any) -> Any:
    """Why sweep folder `d` is not final, or None: only the merge (or a local sweep that ran every
    run) writes aggregate.json, with "complete" (batch/aggregate.hpp); a folder with runs/ and
    specs/ but no aggregate.json is a sweep whose shards or merge have not finished."""
    if "aggregate.json" in files:
        try:
            agg = read_aggregate(d)
        except (OSError, ValueError):
            return "its aggregate.json cannot be read"
        if agg.complete is False:
            return f"its aggregate covers {agg.done} of {agg.expected} runs"
        return None
    if (d / "runs").is_dir() and (d / "specs").is_dir():
        return "it has no final aggregate yet (shards still running, or the merge `omniloc sweep SPEC --aggregate-only` not run)"
    return None


def discover(paths: Sequence[Any], accept_incomplete: bool = False) -> Any:
    """(runs, sweeps, experiments) under the given folders: run folders (summary.json, including those
    inside sweeps), sweep folders (aggregate.json) and experiment folders (PNG / JSON pictures).
    A sweep folder whose aggregate is not final stops it (SystemExit naming the folder) unless
    `accept_incomplete`; then its finished runs are used and the folder is listed in INCOMPLETE."""
    runs, sweeps, experiments = [], [], []
    stale: set[Any] = set()
    for p in paths:
        p = pathlib.Path(p)
        if not p.is_dir():
            raise SystemExit(f"{p}: not a folder")
        for d, subdirs, files in os.walk(p):
            d = pathlib.Path(d)
            if _skip_dir(d):
                subdirs[:] = []
                continue
            subdirs.sort()
            why = incomplete_reason(d, files)
            if why:
                if not accept_incomplete:
                    raise SystemExit(f"{d}: an incomplete sweep: {why}; see `omniloc sweep SPEC --status`, "
                                     "or pass --accept-incomplete to use its finished runs anyway")
                if d not in INCOMPLETE:
                    INCOMPLETE.append(d)
            if "aggregate.json" in files:
                sweeps.append(d)
                # Only the runs this sweep lists: a folder reused with another spec keeps old runs.
                listed = read_run_ids(d)
                if listed and (d / "runs").is_dir():
                    stale.update(str(x) for x in (d / "runs").iterdir() if x.name not in listed)
            if str(d) in stale:
                subdirs[:] = []
                continue
            if "summary.json" in files:
                runs.append(d)
                subdirs[:] = []
            elif "aggregate.json" not in files and d.name != "img" and (any(f.endswith(".png") for f in files) or d.name + ".json" in files):
                experiments.append(d)  # an experiment's folder: its pictures, or its JSON named after it
    uniq = lambda xs: sorted(set(xs))
    return [Run(r) for r in uniq(runs)], uniq(sweeps), uniq(experiments)


class Run:
    """One run folder: summary.json (+ config.json, frames.csv, timing.csv on demand)."""

    def __init__(self, folder: Any) -> None:
        self.folder = pathlib.Path(folder)
        self.summary = json.loads((self.folder / "summary.json").read_text())
        self._config = None

    scenario = property(lambda self: self.summary.get("scenario"))
    localizer = property(lambda self: self.summary.get("localizer"))
    seed = property(lambda self: self.summary.get("seed"))
    version = property(lambda self: (self.summary.get("omniloc") or {}).get("version", "unrecorded"))

    @property
    def start_pose_given(self) -> Any:
        """Whether the localizer was reset with the true start pose (summary.json start_pose_given):
        True, False, or None for a run made before omniloc recorded it."""
        v = self.summary.get("start_pose_given")
        return v if isinstance(v, bool) else None

    @property
    def config(self) -> Any:
        if self._config is None:
            f = self.folder / "config.json"
            self._config = json.loads(f.read_text()) if f.exists() else {}
        return self._config

    def robot(self, index: int = 0) -> Any:
        robots = self.summary.get("robots") or []
        return robots[index] if index < len(robots) else None

    def metric(self, path: Any, phase: str = "tracking", robot: int = 0) -> Any:
        """A number of robot `robot`'s summary, e.g. "x_cm/mean" or "recovery/recovered". With
        phase "tracking" it is read from the tracking-phase block where the run has one (kidnaps,
        covers) and the block has the key; otherwise from the all-frames figures. None when absent
        AND when null (no estimate): lookup() tells the two apart. A null of the tracking phase is
        never replaced by the all-frames figure."""
        found, v = self.lookup(path, phase, robot)
        return _plain(v) if found else None

    def lookup(self, path: Any, phase: str = "tracking", robot: int = 0) -> Any:
        """(found, value): found False when the summary has no such key (a run made before it);
        (True, None) when the statistic is null: no frame with an estimate (see why_null())."""
        r = self.robot(robot)
        if r is None:
            return False, None
        if phase == "tracking" and isinstance(r.get("tracking_phase"), dict):
            found, v = find(r["tracking_phase"], path)
            if found:
                return True, v
        return find(r, path)

    def why_null(self, path: Any, phase: str = "tracking", robot: int = 0) -> Any:
        """The reason summary.json gives beside a null statistic ("no estimate in any of the 30
        scored frames", "no kidnap recovered"): the "why_null" of the innermost block on the path
        that has one; None when there is none."""
        r = self.robot(robot)
        if r is None:
            return None
        block = r
        if phase == "tracking" and isinstance(r.get("tracking_phase"), dict) and find(r["tracking_phase"], path)[0]:
            block = r["tracking_phase"]
        why = block.get("why_null")
        for part in path.strip("/").split("/")[:-1]:
            block = block.get(part) if isinstance(block, dict) else None
            if not isinstance(block, dict):
                break
            why = block.get("why_null", why)
        return why if isinstance(why, str) else None

    @property
    def headline(self) -> Any:
        """The key of the headline recall threshold ("25cm_10deg", summary.json scoring.headline);
        None for a run made before recall was scored."""
        h = (self.summary.get("scoring") or {}).get("headline")
        return h if isinstance(h, str) else None

    def frames(self) -> Any:
        return read_csv(self.folder / "frames.csv")

    def timing(self) -> Any:
        return read_csv(self.folder / "timing.csv")


def dig(obj: Any, path: Any) -> Any:
    """obj["a"]["b"] for path "a/b" (numbers only); None when absent or null."""
    found, v = find(obj, path)
    return _plain(v) if found else None


def find(obj: Any, path: Any) -> Any:
    """(found, value) of obj["a"]["b"] for path "a/b": (True, None) for a null (a statistic over no
    frame), (False, None) for an absent key."""
    return _walk(obj, path.strip("/").split("/"))


def _walk(obj: Any, parts: Iterable[str]) -> tuple[bool, Any]:
    """(found, value) of obj[part0][part1]...: a list is indexed by a part of digits."""
    for part in parts:
        if isinstance(obj, dict) and part in obj:
            obj = obj[part]
        elif isinstance(obj, list) and part.isdigit() and int(part) < len(obj):
            obj = obj[int(part)]
        else:
            return False, None
    return True, obj


def _plain(v: Any) -> Any:
    return v if isinstance(v, (int, float)) and not isinstance(v, bool) else (v if isinstance(v, (dict, list, str, bool)) else None)


def pointer(obj: Any, ptr: str) -> Any:
    """(found, value) of a JSON pointer (RFC 6901) in obj."""
    if ptr in ("", "/"):
        return True, obj
    return _walk(obj, (raw.replace("~1", "/").replace("~0", "~") for raw in ptr[1:].split("/")))


def same_value(a: Any, b: Any) -> Any:
    if isinstance(a, bool) or isinstance(b, bool):
        return a is b or a == b and type(a) is type(b)
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_value(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same_value(x, y) for x, y in zip(a, b))
    return a == b
