"""A sweep folder's own files (docs/results.md): aggregate.json (per group of scenario, localizer and
parameters, every metric's mean and interval over seeds; written only when final) and runs.csv (one
row per run: its id, index, parameters and localizer name).
"""
from __future__ import annotations

import pathlib
from dataclasses import dataclass
from typing import Optional, Union

from omniloc.core.bound import AGGREGATE_KEYS
from omniloc.core.files import read_csv
from omniloc.core.jsonvalue import JSON, JSONObject, integer, load_file, lst, number, obj, text
from omniloc.core.stats import NO_INTERVAL


@dataclass(frozen=True)
class AggregateMetric:
    """One metric of a group: {"n", "mean", "ci95", "interval", "no_value"}. n counts the runs with
    a value, no_value those where it was null (no estimate); mean and ci95 are null when n = 0.
    interval is None in aggregates written before the interval rule."""
    n: int
    mean: Optional[float]
    ci95: tuple[Optional[float], Optional[float]]
    interval: Optional[str]
    no_value: int

    def bounds(self) -> tuple[Optional[float], Optional[float], str]:
        """(lo, hi, kind) of the metric's interval. Aggregates written before the rule have no
        "interval" and hold an unclipped Student t interval for every n >= 2: the kind is then
        "t95 (old aggregate)" for n >= 2, so a reader never takes it for the current rule's."""
        kind = self.interval
        if kind is None:
            kind = NO_INTERVAL if self.n < 2 else "t95 (old aggregate)"
        return self.ci95[0], self.ci95[1], kind

    @staticmethod
    def from_json(raw: JSON) -> AggregateMetric:
        m = obj(raw)
        ci = m.get("ci95") or [None, None]
        lo, hi = (ci[0], ci[1]) if isinstance(ci, list) and len(ci) >= 2 else (None, None)
        return AggregateMetric(n=integer(m.get("n")) or 0, mean=number(m.get("mean")), ci95=(number(lo), number(hi)),
                               interval=text(m.get("interval")), no_value=integer(m.get("no_value")) or 0)


@dataclass(frozen=True)
class AggregateGroup:
    """One group: its scenario, localizer row name and parameters, whether its runs were given the
    start pose (true / false, None before the key, "mixed"), its run counts and metrics."""
    scenario: Optional[str]
    localizer: Optional[str]
    params: Optional[str]
    start_pose_given: Union[bool, str, None]
    finished: JSON  # a count; "-" where the aggregate does not say
    failed: JSON    # a count; 0 where the aggregate does not say
    metrics: dict[str, AggregateMetric]

    @staticmethod
    def from_json(raw: JSON) -> AggregateGroup:
        g = obj(raw)
        given = g.get("start_pose_given")
        metrics = {k: AggregateMetric.from_json(v) for k, v in obj(g.get("metrics")).items()}
        # The bound's per-group figures, where an aggregate keeps them beside "metrics" rather than in it.
        for k in AGGREGATE_KEYS:
            if isinstance(g.get(k), dict) and k not in metrics:
                metrics[k] = AggregateMetric.from_json(g.get(k))
        return AggregateGroup(scenario=text(g.get("scenario")), localizer=text(g.get("localizer")), params=text(g.get("params")),
                              start_pose_given=given if isinstance(given, (bool, str)) else None,
                              finished=g.get("finished", "-"), failed=g.get("failed", 0), metrics=metrics)

    def limit_metric(self, which: str, phase: bool = False) -> Optional[AggregateMetric]:
        """The group's figure of the accuracy limit over seeds: which "efficiency_position" (RMSE /
        bound) or "bound_position_rms_m" (the bound, m), under the name the aggregate gives it
        (batch/aggregate.cpp's key, or robot 0's summary.json path, posterior bound first); None
        for an aggregate of runs made before the bound (never 0)."""
        # The tracking phase's (runs with kidnaps or covers) is kept inside the efficiency block:
        # r0/efficiency/tracking_phase/position and .../bound_rms_m (the bound over its frames).
        phased = {"efficiency_position": ["r0/efficiency/tracking_phase/position"],
                  "bound_position_rms_m": ["r0/efficiency/tracking_phase/bound_rms_m"]}[which] if phase else []
        paths = {"efficiency_position": ["efficiency/position"],
                 "bound_position_rms_m": ["bound/posterior/position_rms_m", "bound/single_frame/position_rms_m"]}[which]
        for name in phased + [which, "r0/" + which] + ["r0/" + p for p in paths]:
            if name in self.metrics:
                return self.metrics[name]
        return None


@dataclass(frozen=True)
class Aggregate:
    """aggregate.json. complete is False (and done < expected) only in a merge that is not final."""
    name: JSON
    version: JSON
    runs: JSON
    run_versions: dict[str, JSON]
    groups: list[AggregateGroup]
    complete: Optional[bool]
    done: JSON
    expected: JSON

    @staticmethod
    def from_json(raw: JSON, folder_name: str) -> Aggregate:
        a = obj(raw)
        complete = a.get("complete")
        return Aggregate(name=a.get("sweep", a.get("name", folder_name)), version=obj(a.get("omniloc")).get("version", "unrecorded"),
                         runs=a.get("runs"), run_versions=obj(a.get("run_versions")),
                         groups=[AggregateGroup.from_json(g) for g in lst(a.get("groups"))],
                         complete=complete if isinstance(complete, bool) else None, done=a.get("done"), expected=a.get("expected"))


def read_aggregate(sweep: pathlib.Path) -> Aggregate:
    """The aggregate.json of sweep folder `sweep` (OSError, ValueError as reading and json.loads raise them)."""
    return Aggregate.from_json(load_file(sweep / "aggregate.json"), sweep.name)


@dataclass(frozen=True)
class SweepRun:
    """One row of runs.csv: the run's folder name under runs/, its index in the sweep, its parameters
    ("default" without any) and its localizer's row name (None in sweeps from before the column).
    Only the id is needed to list a sweep's runs (read_run_ids)."""
    id: str
    index: int
    params: str
    localizer: Optional[str]


def read_runs_csv(sweep: pathlib.Path) -> list[SweepRun]:
    """The rows of runs.csv ([] without the file)."""
    return [SweepRun(id=row["id"], index=int(row["index"]), params=row["params"], localizer=row.get("localizer"))
            for row in read_csv(sweep / "runs.csv")]


def read_run_ids(sweep: pathlib.Path) -> set[str]:
    """The run ids runs.csv lists (an empty set without the file)."""
    return {row["id"] for row in read_csv(sweep / "runs.csv")}


def summary_metrics(summary: JSONObject) -> dict[str, Optional[float]]:
    """Every number of a summary.json under its aggregate.csv name (batch/aggregate.cpp run_metrics):
    "r<robot>/<path>" for the robots' blocks, "<path>" for the sweep-level "metrics" block. A null
    (a statistic over no answered frame) is kept as None: the metric exists and has no value."""
    out: dict[str, Optional[float]] = {}

    def flat(value: JSON, prefix: str) -> None:
        if isinstance(value, bool):
            return
        if value is None:
            out[prefix] = None
        elif isinstance(value, (int, float)):
            out[prefix] = float(value)
        elif isinstance(value, dict):
            for k, v in value.items():
                flat(v, f"{prefix}/{k}" if prefix else k)

    for robot in lst(summary.get("robots")):
        r = obj(robot)
        flat({k: v for k, v in r.items() if k != "robot"}, f"r{r.get('robot', 0)}")
    flat(summary.get("metrics") or {}, "")
    return out
