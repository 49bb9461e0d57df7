"""Pairing runs with the papers' published rows BY KEY (results/reference/papers.json).

A published row names the runs that reproduce it:

    "reproduced_by": {"rows": {"12.5 %": {"scenario": "tracking", "localizer": "matching",
                                          "config": {"/occlusion/fraction": 0.125}}, ...},
                      "config_defaults": {"/occlusion/fraction": 0.0}, "command": "..."}

A run matches a key when its summary's scenario and localizer are the key's and every JSON pointer
of "config" has that value in the run's effective configuration (config.json); a pointer absent
from the configuration takes its value from "config_defaults" (absent and no default: no match).
A key may say "start_pose_given" (true / false); a run that recorded the other value never matches
it (omniloc.paper.tables.row_key gives every "(global start)" row false).
"scenario" may be a list of names: the first name that has matching runs is taken (the same
condition may be run under two names, e.g. the 50 % row as occlusion_002 or as tracking with a
swept occlusion; taking one avoids counting a seed twice). Where a run comes from (which sweep, its
position in it) never matters.

Noise profiles: a key without /noise_profile pairs runs of DEFAULT_PROFILE, which pairing_profile()
changes for a block. DEFAULT_PROFILE is rebound there: read it as pairing.DEFAULT_PROFILE, never
import the name.
"""
from __future__ import annotations

import contextlib
import json
from typing import Iterator, Optional

from omniloc.core.jsonvalue import JSON, JSONObject, flag, load_file, lst, obj
from omniloc.core.paths import PAPERS
from omniloc.core.rundir import Run, pointer, same_value

# A published row's key ("reproduced_by"'s rows of papers.json): scenario (a name or a list of
# names), localizer, config ({JSON pointer: value}), start_pose_given. Raw JSON of papers.json.
RowKey = JSONObject


def load_papers() -> JSONObject:
    """papers.json (the published figures and the rules that judge ours), with each claim's causes
    from causes.json beside it (our explanations of the verdicts that do not hold: kept apart, so the
    papers' record holds only what the papers say)."""
    papers = obj(load_file(PAPERS))
    causes_file = PAPERS.with_name("causes.json")
    if causes_file.exists():
        causes = obj(obj(load_file(causes_file)).get("claims", {}))
        claims = [obj(c) for c in lst(papers.get("claims", []))]
        ids = {str(c["id"]) for c in claims}
        unknown = sorted(set(causes) - ids)
        if unknown:
            raise ValueError(f"{causes_file}: causes for unknown claim(s) {', '.join(unknown)} (claims: {', '.join(sorted(ids))})")
        for c in claims:
            if str(c["id"]) in causes:
                c["causes"] = causes[str(c["id"])]
    return papers


SCENARIO_DEFAULT_PROFILE = "robot"  # what a scenario without "noise_profile" runs under


DEFAULT_PROFILE = "robot"  # the profile published rows pair by default (pairing_profile changes it)


@contextlib.contextmanager
def pairing_profile(name: str) -> Iterator[None]:
    """Within the block, keys without a /noise_profile pair runs of profile `name`."""
    global DEFAULT_PROFILE
    old, DEFAULT_PROFILE = DEFAULT_PROFILE, name
    try:
        yield
    finally:
        DEFAULT_PROFILE = old


def key_matches(run: Run, key: RowKey, defaults: Optional[JSONObject] = None, scenario: JSON = None) -> bool:
    """A published row's key matches runs of its scenario, localizer and configuration values; a key
    that names no /noise_profile means the default profile ("robot"), so runs under another profile
    (field_robot, ideal) never mix into the row."""
    defaults = defaults or {}
    if run.scenario != (scenario or key.get("scenario")):
        return False
    config = obj(key.get("config"))
    if "/noise_profile" not in config:
        if profile_of(run) != DEFAULT_PROFILE:
            return False
    if "localizer" in key and run.localizer != key["localizer"]:
        return False
    if not start_pose_compatible(flag(key.get("start_pose_given")), run.start_pose_given):
        return False
    for ptr, want in config.items():
        found, have = pointer(run.config, ptr)
        if not found:
            if ptr not in defaults:
                return False
            have = defaults[ptr]
        if not same_value(have, want):
            return False
    return True


def start_pose_compatible(a: Optional[bool], b: Optional[bool]) -> bool:
    """Whether two start_pose_given values may share a row or be compared: equal, or either unknown
    (None: a key that does not say, a run made before omniloc recorded it). A run that tracked from
    the true start pose never pairs with one that had to find itself."""
    return a is None or b is None or a == b


def start_pose_text(given: Optional[bool]) -> str:
    """How a row says which task it ran: "given the start pose", "global start", or "" unknown."""
    return "" if given is None else "given the start pose" if given else "global start"


def select(runs: list[Run], key: RowKey, defaults: Optional[JSONObject] = None) -> list[Run]:
    """The runs that reproduce one published row (see the module's docstring), sorted by seed."""
    names = key["scenario"] if isinstance(key["scenario"], list) else [key["scenario"]]
    for name in names:
        hit = [r for r in runs if key_matches(r, key, defaults, scenario=name)]
        if hit:
            # One run per seed: the same run reported from two folders (a sweep and a copy) counts once.
            by_seed: dict[Optional[int], Run] = {}
            for r in sorted(hit, key=lambda r: str(r.folder)):
                by_seed.setdefault(r.seed, r)
            return [by_seed[s] for s in sorted(by_seed, key=seed_order)]
    return []


def seed_order(seed: Optional[int]) -> int:
    """A seed as a sort key (runs without one have no place among seeds: they sort as 0)."""
    return seed if seed is not None else 0


def describe_key(key: RowKey) -> str:
    """'tracking / matching / /occlusion/fraction=0.125': a published row's key as a reader reads it."""
    names = key["scenario"] if isinstance(key["scenario"], list) else [key["scenario"]]
    parts = [" or ".join(str(n) for n in names)]
    if "localizer" in key:
        parts.append(str(key["localizer"]))
    parts += [f"{p}={json.dumps(v)}" for p, v in obj(key.get("config")).items()]
    return " / ".join(parts)


def profile_of(run: Run) -> str:
    """The noise profile a run ran under: its configuration's /noise_profile, the scenarios' default
    where it has none (a value that is not a name, e.g. null, reads as its JSON text: no profile's)."""
    found, prof = pointer(run.config, "/noise_profile")
    if not found:
        return SCENARIO_DEFAULT_PROFILE
    return prof if isinstance(prof, str) else str(prof)
