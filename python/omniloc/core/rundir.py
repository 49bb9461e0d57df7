"""Reading result folders: run folders (summary.json, config.json, frames.csv, timing.csv, field.json),
sweep folders (aggregate.json, runs.csv, runs/) and experiment folders (docs/results.md).

discover() finds them under any folders given; Run is one run folder, its summary.json read as a
Summary and the rest on demand. A sweep folder whose aggregate is not final stops discover() unless
the caller accepts incomplete sweeps; those are listed in INCOMPLETE so a tool can say so. find() /
pointer() read a value by path or JSON pointer and tell a null (a statistic over no frame: (True,
None)) from an absent key.
"""
from __future__ import annotations

import os
import pathlib
from dataclasses import dataclass, field
from typing import Iterable, Optional, Sequence, Union

from omniloc.core import pathcheck
from omniloc.core.aggregate import read_aggregate, read_run_ids, summary_metrics
from omniloc.core.bound import RobotBound, robot_bound
from omniloc.core.files import read_csv
from omniloc.core.jsonvalue import JSON, JSONObject, flag, integer, load_file, lst, number, obj, parse, text

# A robot's block of summary.json (statistics by path: "x_cm/mean", "recall/25cm_10deg", and its
# "tracking_phase" block of the same shape), or any other object of it.
Block = JSONObject


def skip_dir(d: pathlib.Path) -> bool:
    """Folders discover() never enters: hidden ones and those of an unfinished write."""
    return d.name.startswith(".") or ".staging" in d.name or d.name.endswith(".tmp") or ".partial" in d.name


# Sweep folders used although their aggregate was not final (discover(..., accept_incomplete=True)),
# so a tool can say so in its output.
INCOMPLETE: list[pathlib.Path] = []


def incomplete_reason(d: pathlib.Path, files: Sequence[str]) -> Optional[str]:
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


def discover(paths: Sequence[Union[str, pathlib.Path]], accept_incomplete: bool = False) -> tuple[list[Run], list[pathlib.Path], list[pathlib.Path]]:
    """(runs, sweeps, experiments) under the given folders: run folders (summary.json, including those
    inside sweeps), sweep folders (aggregate.json) and experiment folders (PNG / JSON pictures).
    A sweep folder whose aggregate is not final stops it (SystemExit naming the folder) unless
    `accept_incomplete`; then its finished runs are used and the folder is listed in INCOMPLETE."""
    runs: list[pathlib.Path] = []
    sweeps: list[pathlib.Path] = []
    experiments: list[pathlib.Path] = []
    stale: set[str] = set()
    for given in paths:
        why = pathcheck.why_not_readable_folder(given)
        if why:
            raise SystemExit(f"{pathcheck.shown(given)}: {why}, expected a folder of results")
        p = pathlib.Path(given)
        for dirpath, subdirs, files in os.walk(p):
            d = pathlib.Path(dirpath)
            if skip_dir(d):
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
    return [Run.read(r) for r in sorted(set(runs))], sorted(set(sweeps)), sorted(set(experiments))


@dataclass(frozen=True)
class Summary:
    """summary.json of a run (docs/results.md): what ran (scenario, localizer, seed, the build in
    `omniloc`), per robot its statistics (robots: the blocks, read by path with find()), and the
    sweep-level `metrics`. raw is the whole document."""
    raw: JSONObject
    scenario: Optional[str]
    localizer: Optional[str]
    localizer_type: Optional[str]
    seed: Optional[int]
    start_pose_given: Optional[bool]
    headline: Optional[str]
    omniloc: JSONObject
    robots: list[Block]
    metrics: JSONObject

    @staticmethod
    def from_json(raw: JSON) -> Summary:
        s = obj(raw)
        return Summary(raw=s, scenario=text(s.get("scenario")), localizer=text(s.get("localizer")), localizer_type=text(s.get("localizer_type")),
                       seed=integer(s.get("seed")), start_pose_given=flag(s.get("start_pose_given")),
                       headline=text(obj(s.get("scoring")).get("headline")), omniloc=obj(s.get("omniloc")),
                       robots=[obj(r) for r in lst(s.get("robots"))], metrics=obj(s.get("metrics")))

    @property
    def version(self) -> JSON:
        """The build that made the run (git describe), "unrecorded" where summary.json does not say."""
        return self.omniloc.get("version", "unrecorded")

    @property
    def replay(self) -> JSONObject:
        """omniloc.replay of a replayed run: the recording's path, what recorded it; {} for a live run."""
        return obj(self.omniloc.get("replay"))

    @property
    def external_version(self) -> JSON:
        """An external client's version (summary.json external.version), "" where it gives none."""
        return obj(self.raw.get("external")).get("version", "")


@dataclass(eq=False)
class Run:
    """One run folder: summary.json read, config.json, frames.csv, timing.csv and field.json on
    demand. Runs compare by identity (the same folder read twice is two runs)."""
    folder: pathlib.Path
    summary: Summary
    _config: Optional[JSONObject] = field(default=None, repr=False)
    _metrics: Optional[dict[str, Optional[float]]] = field(default=None, repr=False)

    @staticmethod
    def read(folder: Union[str, pathlib.Path]) -> Run:
        folder = pathlib.Path(folder)
        summary = folder / "summary.json"
        why = pathcheck.why_not_readable_file(summary)
        if why:  # a FIFO named summary.json would block read_text() for ever
            raise SystemExit(f"{pathcheck.shown(summary)}: {why}, expected a run's summary")
        return Run(folder=folder, summary=Summary.from_json(parse(summary.read_text())))

    @property
    def scenario(self) -> Optional[str]:
        return self.summary.scenario

    @property
    def localizer(self) -> Optional[str]:
        return self.summary.localizer

    @property
    def seed(self) -> Optional[int]:
        return self.summary.seed

    @property
    def version(self) -> JSON:
        return self.summary.version

    @property
    def start_pose_given(self) -> Optional[bool]:
        """Whether the localizer was reset with the true start pose (summary.json start_pose_given):
        True, False, or None for a run made before omniloc recorded it."""
        return self.summary.start_pose_given

    @property
    def headline(self) -> Optional[str]:
        """The key of the headline recall threshold ("25cm_10deg", summary.json scoring.headline);
        None for a run made before recall was scored."""
        return self.summary.headline

    @property
    def config(self) -> JSONObject:
        """config.json: the effective configuration ({} where the folder has none)."""
        if self._config is None:
            f = self.folder / "config.json"
            self._config = obj(parse(f.read_text())) if f.exists() else {}
        return self._config

    def robot(self, index: int = 0) -> Optional[Block]:
        robots = self.summary.robots
        return robots[index] if index < len(robots) else None

    def metric(self, path: str, phase: str = "tracking", robot: int = 0) -> Optional[float]:
        """A number of robot `robot`'s summary, e.g. "x_cm/mean" or "recovery/recovered". With
        phase "tracking" it is read from the tracking-phase block where the run has one (kidnaps,
        covers) and the block has the key; otherwise from the all-frames figures. None when absent
        AND when null (no estimate): lookup() tells the two apart. A null of the tracking phase is
        never replaced by the all-frames figure."""
        found, v = self.lookup(path, phase, robot)
        return number(v) if found else None

    def lookup(self, path: str, phase: str = "tracking", robot: int = 0) -> tuple[bool, JSON]:
        """(found, value): found False when the summary has no such key (a run made before it);
        (True, None) when the statistic is null: no frame with an estimate (see why_null())."""
        r = self.robot(robot)
        if r is None:
            return False, None
        tp = r.get("tracking_phase")
        if phase == "tracking" and isinstance(tp, dict):
            found, v = find(tp, path)
            if found:
                return True, v
        return find(r, path)

    def why_null(self, path: str, phase: str = "tracking", robot: int = 0) -> Optional[str]:
        """The reason summary.json gives beside a null statistic ("no estimate in any of the 30
        scored frames", "no kidnap recovered"): the "why_null" of the innermost block on the path
        that has one; None when there is none."""
        r = self.robot(robot)
        if r is None:
            return None
        block: JSON = r
        tp = r.get("tracking_phase")
        if phase == "tracking" and isinstance(tp, dict) and find(tp, path)[0]:
            block = tp
        why = obj(block).get("why_null")
        for part in path.strip("/").split("/")[:-1]:
            block = block.get(part) if isinstance(block, dict) else None
            if not isinstance(block, dict):
                break
            why = block.get("why_null", why)
        return why if isinstance(why, str) else None

    def bound(self, robot: int = 0, phase: str = "tracking") -> Optional[RobotBound]:
        """Robot `robot`'s accuracy limit (core.bound: the Cramer-Rao bound, efficiency, relative
        pose error), from its tracking-phase block where that has one; None for a run made before
        omniloc scored the bound."""
        return robot_bound(self.robot(robot), phase)

    def aggregate_metrics(self) -> dict[str, Optional[float]]:
        """Every number of summary.json under its aggregate.csv name (core.aggregate.summary_metrics),
        flattened once per run."""
        if self._metrics is None:
            self._metrics = summary_metrics(self.summary.raw)
        return self._metrics

    def frames(self) -> list[dict[str, str]]:
        """frames.csv: one row per frame and robot, each cell as text ([] without the file)."""
        return read_csv(self.folder / "frames.csv")

    def timing(self) -> list[dict[str, str]]:
        """timing.csv: one row per frame, the stages' wall times in ms as text ([] without the file)."""
        return read_csv(self.folder / "timing.csv")

    def field_json(self) -> Optional[JSON]:
        """field.json (the field's markings); None without the file. ValueError when it is not JSON."""
        f = self.folder / "field.json"
        return load_file(f) if f.exists() else None


def find(value: JSON, path: str) -> tuple[bool, JSON]:
    """(found, value) of value["a"]["b"] for path "a/b": (True, None) for a null (a statistic over
    no frame), (False, None) for an absent key."""
    return walk(value, path.strip("/").split("/"))


def walk(value: JSON, parts: Iterable[str]) -> tuple[bool, JSON]:
    """(found, value) of value[part0][part1]...: a list is indexed by a part of digits."""
    for part in parts:
        if isinstance(value, dict) and part in value:
            value = value[part]
        elif isinstance(value, list) and part.isdigit() and int(part) < len(value):
            value = value[int(part)]
        else:
            return False, None
    return True, value


def pointer(value: JSON, ptr: str) -> tuple[bool, JSON]:
    """(found, value) of a JSON pointer (RFC 6901) in value."""
    if ptr in ("", "/"):
        return True, value
    return walk(value, (raw.replace("~1", "/").replace("~0", "~") for raw in ptr[1:].split("/")))


def same_value(a: JSON, b: JSON) -> bool:
    """Whether two JSON values are the same: numbers to a relative 1e-9, true never equal to 1."""
    if isinstance(a, bool) or isinstance(b, bool):
        return a is b or a == b and type(a) is type(b)
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_value(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same_value(x, y) for x, y in zip(a, b))
    return a == b
