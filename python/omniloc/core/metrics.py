"""A run's metrics over several runs, and how every tool names them.

No estimate (docs/results.md "Coverage and recall"): an error statistic over zero answered frames is
null in summary.json, with "why_null" beside it; it is never 0. Run.lookup() tells a null (found,
None) from an absent key (not found: a run from before the key); run_stats() counts the runs with a
value ("n") and those without ("no_value"), and every tool says "no estimate in k of n runs"
(no_estimate_text) where a statistic has none, never a number. recall/<threshold> is the share of
ALL scored frames within a (position, heading) threshold, valid_fraction the share answered; the
headline threshold (summary.json scoring.headline, headline_key()) is the one tables lead with.
"""
from __future__ import annotations

import math
import re
from typing import Iterable, Optional

from omniloc.core.bound import null_text
from omniloc.core.jsonvalue import JSON
from omniloc.core.rundir import Run
from omniloc.core.stats import SeedStats, fnum, is_number, stats


# The papers' error-table layout: (summary field, statistic), in the published column order.
TABLE_KEYS: list[tuple[str, str]] = [("x_cm", "mean"), ("y_cm", "mean"), ("theta_rad", "mean"), ("x_cm", "std"), ("y_cm", "std"), ("theta_rad", "std"),
              ("x_cm", "max"), ("y_cm", "max"), ("theta_rad", "max")]


TABLE_COLS = ["mean x cm", "mean y cm", "mean th rad", "std x cm", "std y cm", "std th rad", "max x cm", "max y cm", "max th rad"]


def no_estimate_text(k: int, n: int, path: str = "") -> str:
    """'no estimate in 1 of 3 runs': how every tool names runs whose statistic is null ('no bound in
    1 of 3 runs' for a metric of the accuracy limit, core.bound)."""
    return f"{null_text(path)} in {k} of {n} runs"


def run_values(runs: list[Run], path: str, phase: str = "tracking") -> tuple[list[float], int, int]:
    """(values, no_value, of) of one statistic over runs: the numbers of the runs that have one, how
    many runs have it null (no estimate), and how many have the key at all (a run made before the
    key counts in neither)."""
    values: list[float] = []
    no_value, of = 0, 0
    for r in runs:
        found, v = r.lookup(path, phase)
        if not found:
            continue
        of += 1
        if is_number(v):
            values.append(v)
        elif v is None:
            no_value += 1
    return values, no_value, of


def run_stats(runs: list[Run], path: str, phase: str = "tracking") -> SeedStats:
    """stats() over the runs that have a value, with no_value (runs where the statistic is null:
    no estimate), of (runs that have the key) and why (the reason to print where no run has a
    value: the runs' why_null where they agree on one that is not about estimates, e.g. "no kidnap
    recovered"; else "no estimate")."""
    values, no_value, of = run_values(runs, path, phase)
    st = stats(values)
    st.no_value, st.of, st.why = no_value, of, None
    if no_value:
        whys = {r.why_null(path, phase) for r in runs if r.lookup(path, phase) == (True, None)}
        one = whys.pop() if len(whys) == 1 else None
        st.why = one if one and not one.startswith("no estimate") else null_text(path, one)
    return st


NO_ESTIMATE = "no estimate"


def stat_cell(st: SeedStats, digits: int = 3, scale: float = 1.0) -> str:
    """A table cell for run_stats() output: the mean; "no estimate" (or the runs' shared reason)
    where no run has a value; "-" where no run has the key. Runs without a value beside runs with one
    are not noted here: the caller names them once per row (no_value_note)."""
    if st.n and st.mean is not None:
        return fnum(st.mean * scale, digits)
    if st.no_value:
        return st.why or NO_ESTIMATE
    return "-"


def no_value_note(sts: Iterable[SeedStats]) -> str:
    """'no estimate in 1 of 3 runs' for the worst of several run_stats() results of one row ('' when
    every run has every value)."""
    worst = max(sts, key=lambda s: (s.no_value, s.of), default=None)
    if not worst or not worst.no_value:
        return ""
    return no_estimate_text(worst.no_value, worst.of)


DEFAULT_HEADLINE = "25cm_10deg"


def headline_key(runs: list[Run]) -> Optional[str]:
    """The headline recall threshold of a set of runs (the one most of them name in
    summary.json scoring.headline); None when none of them records one (runs made before recall)."""
    counts: dict[str, int] = {}
    for r in runs:
        h = r.headline
        if h:
            counts[h] = counts.get(h, 0) + 1
    return max(sorted(counts), key=lambda h: counts[h]) if counts else None


def recall_keys(runs: list[Run]) -> list[str]:
    """Every recall threshold key the runs have (robot 0), tightest first."""
    keys: set[str] = set()
    for r in runs:
        rob = r.robot() or {}
        recall = rob.get("recall") or {}
        keys |= {k for k in (recall if isinstance(recall, dict) else {})}
    return sorted(keys, key=recall_order)


def recall_order(key: str) -> tuple[float, float, str]:
    m = _RECALL_KEY.fullmatch(str(key))
    return (float(m.group(1)), float(m.group(2)), key) if m else (math.inf, math.inf, str(key))


_RECALL_KEY = re.compile(r"(\d+(?:\.\d+)?(?:e[-+]?\d+)?)cm_(\d+(?:\.\d+)?(?:e[-+]?\d+)?)deg")


def recall_label(key: Optional[str]) -> str:
    """'25 cm / 10 deg' for the key "25cm_10deg" (a reader's words, no underscore)."""
    m = _RECALL_KEY.fullmatch(str(key or ""))
    return f"{m.group(1)} cm / {m.group(2)} deg" if m else str(key).replace("_", " ")


def percent(v: JSON, digits: int = 1) -> str:
    """'93.3 %' for 0.933; '-' for None."""
    return "-" if not is_number(v) else f"{100.0 * v:.{digits}f} %"
