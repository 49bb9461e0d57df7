"""Pass or fail a result set against rules: limits on metrics and, with a baseline, regressions.

Run as `omniloc gate RESULTS --rules FILE [--baseline DIR] [--junit FILE] [--benchmark-json FILE]
[--alpha P]` or `python3 -m omniloc.commands.gate ...` (the same). docs/ci.md documents the rules file and the outputs.

RESULTS and DIR are sweep folders with final aggregates, run folders, or folders holding them.
Runs group by scenario, localizer and effective configuration as in `omniloc compare`; a rule
applies to every group its optional "scenario" / "localizer" filters select, and judges the mean
over seeds of its metric (or "stat": median / max / min over seeds) against "max" and / or "min".
With --baseline each group pairs with a baseline group as `omniloc compare` pairs them, and the
metric regresses when it is worse than the baseline's beyond the rule's tolerance AND beyond the
seed-to-seed spread (Welch's t-test over seeds, p < alpha, default 0.05; with fewer than two seeds
on a side there is no spread, and any worsening beyond the tolerance counts).

Metrics are spelled as in aggregate.csv's metric column: "r0/position_m/rmse" (robot 0's all-frames
RMSE), "r0/tracking_phase/position_m/rmse", "r0/recall/25cm_10deg" (the share of all scored frames
within 25 cm and 10 deg), or a sweep-level metric; without an "r<N>/" prefix, a name that is not a
sweep-level metric means robot 0's.

No estimate: a statistic over zero answered frames is null in summary.json (never 0). A rule whose
metric is null in any run of a group FAILS that group, "no estimate in N of M runs", whatever its
limits, and so does a regression check: a run without estimates never passes an accuracy limit.
recall/..., valid_fraction and recovered_fraction are higher-is-better: a rule on them regresses
when they fall (unless the rule says "better").

The accuracy limit (docs/results.md): "r0/efficiency/position" is the position RMSE over the
Cramer-Rao bound of the same frames (1 is the limit; {"metric": "efficiency/position", "max": 1.5}
fails a localizer more than 50 % above it), "efficiency/heading" the same for the heading,
"efficiency_single_frame/..." against the single-frame bound, "bound/posterior/position_rms_m" the
bound itself; "efficiency.position" may be written for "efficiency/position". Where a run has no
bound (no truth, no frame with a finite bound) the efficiency is null and the rule fails the group,
"no bound in N of M runs".

Exit 0 when every rule holds, 1 when any limit or regression fails, 2 on bad input (a missing or
incomplete result folder, bad rules, an unknown metric, a rule that selects nothing) before any
verdict is printed.
"""
from __future__ import annotations

import json
import math
import os
import pathlib
from xml.etree import ElementTree
from dataclasses import dataclass, field
from typing import Optional, Sequence, Union

from omniloc import compare
from omniloc.core import bound, metrics, pathcheck, rundir, stats
from omniloc.core.jsonvalue import JSON, JSONObject, parse
from omniloc.core.rundir import Run


ALPHA = 0.05


STATS = ("mean", "median", "max", "min")


# Metrics where a larger value is the better one: a regression is a fall (the rule's "better" default).
HIGHER_IS_BETTER = ("recall", "valid_fraction", "recovered_fraction")


RULE_KEYS = {"metric", "max", "min", "scenario", "localizer", "stat", "better", "tolerance", "tolerance_fraction", "name", "comment"}


# The accuracy limit's figures a rule names (summary.json's blocks, core.bound), each block with the
# numbers it holds: a misspelt one is bad input naming the rule's JSON path, before any results are
# read. The bound's other blocks (the noise it measured, the compass, the odometry) are checked
# against the results' metrics like any other name.
LIMIT_BLOCKS: dict[str, tuple[str, ...]] = {
    "efficiency": ("position", "heading", "share", "frames"),
    "efficiency_single_frame": ("position", "heading", "share", "frames"),
    "bound/single_frame": ("position_rms_m", "heading_rms_rad", "frames", "share"),
    "bound/posterior": ("position_rms_m", "heading_rms_rad", "frames", "share"),
    "bound/no_bound": ("frames",),
    "rpe/frame": ("translation_rms_m", "rotation_rms_rad", "pairs"),
    "rpe/1s": ("translation_rms_m", "rotation_rms_rad", "pairs"),
}


def limit_path(metric: str) -> Optional[tuple[str, str]]:
    """(block, rest) of a metric of the accuracy limit ("r0/efficiency/position" -> ("efficiency",
    "position")); None for any other metric."""
    parts = metric.strip("/").split("/")
    if parts and parts[0][:1] == "r" and parts[0][1:].isdigit():
        parts = parts[1:]
    if parts and parts[0] == "tracking_phase":
        parts = parts[1:]
    if not parts or parts[0] not in ("efficiency", "efficiency_single_frame", "bound", "rpe"):
        return None
    depth = 1 if parts[0].startswith("efficiency") else 2
    return "/".join(parts[:depth]), "/".join(parts[depth:])


def check_limit_metric(metric: str, where: str) -> None:
    """BadInput naming the rule's metric where it names a block of the accuracy limit that does not
    exist, or a number the block does not hold."""
    found = limit_path(metric)
    if found is None:
        return
    block, rest = found
    if block.startswith("bound/") and block not in LIMIT_BLOCKS:
        return  # the bound's other blocks (its noise, compass, odometry): checked against the results' metrics
    expected = [f"{b}/{k}" for b, ks in LIMIT_BLOCKS.items() for k in ks]
    if block not in LIMIT_BLOCKS or rest not in LIMIT_BLOCKS[block]:
        raise BadInput(f"{where}/metric: got {json.dumps(metric)}, expected a number of the accuracy limit (docs/results.md): "
                       + ", ".join(expected))


def is_ratio(metric: str) -> bool:
    """Whether a metric is an efficiency ratio (RMSE / bound) rather than a share or a count."""
    found = limit_path(metric)
    return found is not None and found[0].startswith("efficiency") and found[1] in ("position", "heading")


def spelt(metric: str) -> str:
    """A metric as aggregate.csv spells it: "efficiency.position" (the accuracy limit's blocks
    written with dots, as docs and papers name them) is read as "efficiency/position"."""
    m = metric.strip("/")
    if "/" not in m and "." in m and m.split(".", 1)[0] in ("efficiency", "efficiency_single_frame", "bound", "rpe"):
        return m.replace(".", "/")
    return m


class BadInput(Exception):
    """Input the gate cannot judge: exit 2 before any verdict."""


@dataclass(frozen=True)
class Rule:
    """One rule of the rules file (docs/ci.md), checked and with its defaults: index (its place in
    the file), the metric (aggregate.csv's name), the group filters, the limits, the statistic over
    seeds, which direction is better, the regression tolerances, the JUnit title."""
    index: int
    metric: str
    scenario: Optional[str]
    localizer: Optional[str]
    name: Optional[str]
    max: Optional[float]
    min: Optional[float]
    stat: str
    better: str
    tolerance: float
    tolerance_fraction: float


@dataclass(frozen=True)
class Regression:
    """A check's comparison with its baseline group: the baseline's statistic over its n seeds, how
    much worse the candidate is, what the tolerance allows, Welch's p and the configuration values
    that differ between the paired groups."""
    baseline: float
    baseline_n: int
    worse_by: float
    allowed: float
    p: Optional[float]
    differs: list[str]


@dataclass
class Check:
    """One rule judged on one group: the seeds' values of the metric (and how many runs had it null:
    no estimate, of how many that have it), the statistic, its interval, the failures (kind, text),
    notes, and the regression test where a baseline was given."""
    rule: Rule
    metric: str
    key: compare.GroupKey
    label: str
    values: list[float]
    no_value: int
    of: int
    value: Optional[float]
    interval: stats.Interval
    failures: list[tuple[str, str]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    regression: Optional[Regression] = None

    @property
    def failed(self) -> bool:
        return bool(self.failures)


def _number(rule: JSONObject, key: str, where: str) -> float:
    v = rule[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise BadInput(f"{where}/{key}: got {json.dumps(v)}, expected a finite number")
    return float(v)


def load_rules(path: Union[str, pathlib.Path], have_baseline: bool) -> list[Rule]:
    """The rules of `path`, checked key by key; BadInput names the JSON path, the value and what was expected."""
    why = pathcheck.why_not_readable_file(path)
    if why:  # before open(): a FIFO would block it for ever
        raise BadInput(f"{pathcheck.shown(path)}: cannot be read ({why})")
    try:
        doc = parse(pathlib.Path(path).read_text())
    except OSError as e:
        raise BadInput(f"{path}: cannot be read ({e.strerror})")
    except ValueError as e:
        raise BadInput(f"{path}: not JSON ({e})")
    if not isinstance(doc, dict):
        raise BadInput(f"{path}: /: got {json.dumps(doc)[:60]}, expected an object {{\"rules\": [...]}}")
    extra = sorted(set(doc) - {"rules", "comment"})
    if extra:
        raise BadInput(f"{path}: /{extra[0]}: unknown key, expected \"rules\" (or \"comment\")")
    rules = doc.get("rules")
    if not isinstance(rules, list) or not rules:
        raise BadInput(f"{path}: /rules: got {json.dumps(rules)[:60]}, expected a non-empty array of rules")
    out: list[Rule] = []
    for i, rule in enumerate(rules):
        where = f"{path}: /rules/{i}"
        if not isinstance(rule, dict):
            raise BadInput(f"{where}: got {json.dumps(rule)[:60]}, expected an object {{\"metric\": ..., \"max\": ...}}")
        unknown = sorted(set(rule) - RULE_KEYS)
        if unknown:
            raise BadInput(f"{where}/{unknown[0]}: unknown key, expected one of {', '.join(sorted(RULE_KEYS))}")
        m = rule.get("metric")
        if not isinstance(m, str) or not m.strip("/"):
            raise BadInput(f"{where}/metric: got {json.dumps(m)}, expected a metric name as in aggregate.csv (e.g. \"r0/position_m/rmse\")")
        names: dict[str, Optional[str]] = {}
        for k in ("scenario", "localizer", "name"):
            v = rule.get(k)
            if k in rule and (not isinstance(v, str) or not v):
                raise BadInput(f"{where}/{k}: got {json.dumps(rule[k])}, expected a non-empty string")
            names[k] = v if isinstance(v, str) else None
        metric = spelt(m)
        check_limit_metric(metric, where)
        high = _number(rule, "max", where) if "max" in rule else None
        low = _number(rule, "min", where) if "min" in rule else None
        if is_ratio(metric):
            for k, v in (("max", high), ("min", low)):
                if v is not None and v <= 0:
                    raise BadInput(f"{where}/{k}: got {v:g}, expected a positive ratio of the RMSE to the bound (1 is the limit, 1.5 is 50 % above it)")
        if high is not None and low is not None and low > high:
            raise BadInput(f"{where}/min: got {low:g}, expected at most max ({high:g})")
        stat = rule.get("stat", "mean")
        if not isinstance(stat, str) or stat not in STATS:
            raise BadInput(f"{where}/stat: got {json.dumps(stat)}, expected one of {', '.join(STATS)}")
        better = rule.get("better", "higher" if higher_is_better(metric) or (low is not None and high is None) else "lower")
        if not isinstance(better, str) or better not in ("lower", "higher"):
            raise BadInput(f"{where}/better: got {json.dumps(better)}, expected \"lower\" or \"higher\"")
        tolerances: dict[str, float] = {}
        for k in ("tolerance", "tolerance_fraction"):
            tolerances[k] = _number(rule, k, where) if k in rule else 0.0
            if tolerances[k] < 0:
                raise BadInput(f"{where}/{k}: got {tolerances[k]:g}, expected a number >= 0")
        if high is None and low is None and not have_baseline:
            raise BadInput(f"{where}: has neither \"max\" nor \"min\", and no --baseline was given: it would judge nothing")
        out.append(Rule(index=i, metric=metric, scenario=names["scenario"], localizer=names["localizer"], name=names["name"], max=high, min=low,
                        stat=stat, better=better, tolerance=tolerances["tolerance"], tolerance_fraction=tolerances["tolerance_fraction"]))
    return out


def higher_is_better(metric: str) -> bool:
    """Whether a larger value of `metric` is better: recall at a threshold ("r0/recall/25cm_10deg"),
    the share of frames answered (valid_fraction) and of kidnaps recovered (recovered_fraction), and
    the share of frames the accuracy limit covers ("r0/efficiency/share")."""
    parts = metric.strip("/").split("/")
    return "recall" in parts[:-1] or parts[-1] in HIGHER_IS_BETTER or (limit_path(metric) is not None and parts[-1] == "share")


def resolve_metric(name: str, known: set[str]) -> Optional[str]:
    """`name` as a key of `known`: itself, or "r0/" + name when it has no robot prefix."""
    if name in known:
        return name
    head = name.split("/", 1)[0]
    if not (head[:1] == "r" and head[1:].isdigit()) and "r0/" + name in known:
        return "r0/" + name
    return None


def seed_values(runs: list[Run], metric: str) -> list[float]:
    """The values of `metric` over the runs that have one (see seed_counts for the others)."""
    return seed_counts(runs, metric)[0]


def seed_counts(runs: list[Run], metric: str) -> tuple[list[float], int, int]:
    """(values, no_value, of): the numbers, how many runs have the metric null (no estimate), and how
    many have it at all (a run made before the metric existed counts in neither)."""
    vals: list[float] = []
    no_value, of = 0, 0
    for r in runs:
        m = r.aggregate_metrics()
        if metric not in m:
            continue
        of += 1
        v = m[metric]
        if v is None or math.isnan(v):
            no_value += 1
        else:
            vals.append(v)
    return vals, no_value, of


def statistic(values: Sequence[float], stat: str) -> Optional[float]:
    if not values:
        return None
    if stat == "mean":
        return sum(values) / len(values)
    if stat == "median":
        return stats.percentile(sorted(values), 0.5)
    return max(values) if stat == "max" else min(values)


def load_runs(folder: str, what: str) -> list[Run]:
    """The runs under `folder`; BadInput when it is missing, holds no run or an incomplete sweep."""
    why = pathcheck.why_not_readable_folder(folder)
    if why:
        raise BadInput(f"{what} {pathcheck.shown(folder)}: {why}, expected a folder of results")
    try:
        runs, _, _ = rundir.discover([folder])
    except SystemExit as e:
        raise BadInput(f"{what} {e}")
    if not runs:
        raise BadInput(f"{what} {folder}: no finished run (summary.json) under it")
    return runs


def judge(rules: Sequence[Rule], runs: list[Run], base_runs: Optional[list[Run]], alpha: float) -> list[Check]:
    """One check per rule and selected group: the values, the verdicts and the text."""
    groups = compare.groups(runs)
    names = compare.labels(set(groups))
    pair_of: dict[compare.GroupKey, tuple[compare.GroupKey, list[str]]] = {}
    base_groups: dict[compare.GroupKey, list[Run]] = {}
    if base_runs is not None:
        pairs, _, _, ga, gb = compare.compare_pairs(base_runs, runs)
        base_groups = ga
        pair_of = {kb: (ka, diffs) for ka, kb, diffs in pairs}
    known: set[str] = set()
    for r in runs:
        known.update(r.aggregate_metrics())
    checks = []
    for rule in rules:
        metric = resolve_metric(rule.metric, known)
        if metric is None and limit_path(rule.metric) is not None and not any(limit_path(k) for k in known):
            raise BadInput(f"rule {rule.index}: metric \"{rule.metric}\" is not among the results' metrics: none of their runs carries the "
                           "accuracy limit (runs made by an omniloc before the bound was scored; docs/results.md)")
        if metric is None:
            near = sorted(k for k in known if k.split("/")[-1] == rule.metric.split("/")[-1])[:4]
            raise BadInput(f"rule {rule.index}: metric \"{rule.metric}\" is not among the results' metrics"
                           + (f" (did you mean {', '.join(near)}?)" if near else " (see aggregate.csv's metric column)"))
        keys = [k for k in sorted(groups, key=compare.sort_key)
                if (rule.scenario is None or k.scenario == rule.scenario) and (rule.localizer is None or k.localizer == rule.localizer)]
        if not keys:
            have = sorted({f"{k.scenario} / {k.localizer}" for k in groups})
            raise BadInput(f"rule {rule.index} (scenario {rule.scenario or 'any'}, localizer {rule.localizer or 'any'}) "
                           f"selects no group of the results; they hold: {'; '.join(have)}")
        paired_any = False
        for k in keys:
            vals, no_value, of = seed_counts(groups[k], metric)
            if not of and limit_path(metric) is not None:
                # Runs of a recording without truth score nothing, so they have no bound: "no bound", not bad input.
                unscored = [r for r in groups[k] if r.summary.robots and all(rob.get("scored") is False for rob in r.summary.robots)]
                no_value, of = len(unscored), len(unscored)
            if not of:
                raise BadInput(f"rule {rule.index}: no run of {names[k]} has the metric {metric}")
            c = Check(rule=rule, metric=metric, key=k, label=names[k], values=vals, no_value=no_value, of=of,
                      value=statistic(vals, rule.stat), interval=stats.interval(vals))
            if no_value:  # a run without estimates (or without a bound) never passes: whatever the limits and the baseline
                c.failures.append((bound.null_text(metric), metrics.no_estimate_text(no_value, of, metric)))
            check_limits(c)
            if base_runs is not None:
                if k in pair_of:
                    paired_any = True
                    ka, diffs = pair_of[k]
                    check_regression(c, seed_counts(base_groups[ka], metric), diffs, alpha)
                else:
                    c.notes.append("no baseline counterpart: regression not checked")
            checks.append(c)
        if base_runs is not None and not paired_any and rule.max is None and rule.min is None:
            raise BadInput(f"rule {rule.index} ({metric}) has only a baseline test, and no group it selects pairs with one of the baseline")
    return checks


NO_ESTIMATE = "no estimate"  # the kind of failure of a metric that is null in some run


NULL_KINDS = (NO_ESTIMATE, bound.NO_BOUND)  # ... and of a metric of the accuracy limit


def check_limits(c: Check) -> None:
    r, v = c.rule, c.value
    if v is None:  # no run has a value: failed already (no estimate)
        return
    if r.max is not None and v > r.max:
        c.failures.append(("limit", f"{r.stat} {v:.6g} > max {r.max:.6g}"))
    if r.min is not None and v < r.min:
        c.failures.append(("limit", f"{r.stat} {v:.6g} < min {r.min:.6g}"))


def check_regression(c: Check, base: tuple[list[float], int, int], diffs: list[str], alpha: float) -> None:
    """Regression of check `c` against the baseline's (values, no_value, of). A candidate without an
    estimate in some run has failed already; a baseline without one in some run is compared on the
    runs that have one, and the line says how many had none."""
    r = c.rule
    base_vals, base_none, base_of = base
    if base_none:
        c.notes.append(f"baseline: {metrics.no_estimate_text(base_none, base_of, c.metric)}")
    b = statistic(base_vals, r.stat)
    if b is None or c.value is None:
        if not base_vals:
            c.notes.append("the baseline group has no value of this metric: regression not checked")
        c.regression = None
        return
    worse = (c.value - b) if r.better == "lower" else (b - c.value)
    allowed = r.tolerance + r.tolerance_fraction * abs(b)
    w = stats.welch(base_vals, c.values)
    same = sorted(base_vals) == sorted(c.values)
    c.regression = Regression(baseline=b, baseline_n=len(base_vals), worse_by=worse, allowed=allowed, p=w.p, differs=diffs)
    if same or worse <= allowed:
        return
    if w.p is None:
        why = f"no spread (n < 2), worse by {worse:.6g} > tolerance {allowed:.6g}"
    elif w.p < alpha:
        why = f"worse by {worse:.6g} > tolerance {allowed:.6g}, p {w.p:.3g} < alpha {alpha:g}"
    else:
        c.notes.append(f"worse by {worse:.6g} but within the seed spread (p {w.p:.3g} >= {alpha:g})")
        return
    c.failures.append(("regression", f"{r.stat} {c.value:.6g} vs baseline {b:.6g} (n={len(base_vals)}): {why}"))


def rule_text(r: Rule) -> str:
    limits = []
    if r.min is not None:
        limits.append(f">= {r.min:.6g}")
    if r.max is not None:
        limits.append(f"<= {r.max:.6g}")
    return " and ".join(limits) if limits else f"no worse than baseline ({r.better} is better)"


def value_text(c: Check) -> str:
    """'mean 0.0453 (n=5)', or 'no estimate (n=0 of 1)' where no run has a value."""
    if c.value is None:
        return f"{bound.null_text(c.metric)} (n=0 of {c.of})"
    return f"{c.rule.stat} {c.value:.6g} (n={len(c.values)}" + (f" of {c.of}" if c.no_value else "") + ")"


def failure_text(kind: str, msg: str) -> str:
    return msg if kind in NULL_KINDS else f"{kind}: {msg}"


def line(c: Check) -> str:
    r = c.rule
    verdict = "FAIL" if c.failures else "PASS"
    s = f"{verdict}  {c.label}  {c.metric}  {value_text(c)}  limit {rule_text(r)}"
    reg = c.regression
    if reg:
        p = "-" if reg.p is None else f"{reg.p:.3g}"
        s += f"  baseline {reg.baseline:.6g} (n={reg.baseline_n}, p {p})"
    for kind, msg in c.failures:
        s += f"  [{failure_text(kind, msg)}]"
    for n in c.notes:
        s += f"  [{n}]"
    return s


def write_atomic(path: Union[str, pathlib.Path], text: str) -> None:
    """Temp file + rename beside the target: an interrupted gate never leaves half a report."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def junit_xml(checks: Sequence[Check], results: str, baseline: Optional[str]) -> str:
    """JUnit XML as GitHub Actions' test reporters, GitLab CI and Jenkins read it: <testsuites>, a
    <testsuite> per scenario, a <testcase> per rule and group, a <failure> naming the metric, the
    value, the limit or baseline and the p-value. No timestamps: the same results give the same file."""
    root = ElementTree.Element("testsuites", name="omniloc gate", tests=str(len(checks)),
                      failures=str(sum(1 for c in checks if c.failures)), errors="0", skipped="0", time="0")
    by_scenario: dict[str, list[Check]] = {}
    for c in checks:
        by_scenario.setdefault(str(c.key.scenario), []).append(c)
    for scenario, cs in sorted(by_scenario.items()):
        suite = ElementTree.SubElement(root, "testsuite", name=scenario, tests=str(len(cs)),
                              failures=str(sum(1 for c in cs if c.failures)), errors="0", skipped="0", time="0")
        props = ElementTree.SubElement(suite, "properties")
        ElementTree.SubElement(props, "property", name="results", value=str(results))
        if baseline:
            ElementTree.SubElement(props, "property", name="baseline", value=str(baseline))
        for c in cs:
            r = c.rule
            title = r.name or f"{c.metric} {rule_text(r)}"
            case = ElementTree.SubElement(suite, "testcase", name=f"{c.label}: {title}",
                                 classname=f"omniloc.{scenario}.{c.key.localizer}", time="0")
            if c.failures:
                msg = "; ".join(f"{c.metric}: {m}" if kind in NULL_KINDS else f"{kind}: {c.metric} {m}" for kind, m in c.failures)
                fail = ElementTree.SubElement(case, "failure", message=msg, type=" and ".join(sorted({k for k, _ in c.failures})))
                fail.text = line(c) + "\nseed values: " + (", ".join(f"{v:.6g}" for v in c.values) or "none") + (
                    f"; {metrics.no_estimate_text(c.no_value, c.of, c.metric)}" if c.no_value else "")
            else:
                out = ElementTree.SubElement(case, "system-out")
                out.text = line(c)
    ElementTree.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ElementTree.tostring(root, encoding="unicode") + "\n"


UNITS = [("_cm/", "cm"), ("_m/", "m"), ("_rad/", "rad"), ("_rad", "rad"), ("_s/", "s"), ("_s", "s")]


def unit_of(metric: str) -> str:
    if is_ratio(metric):
        return "x bound"
    m = metric + "/"
    for tag, unit in UNITS:
        if tag in m:
            return unit
    return "count" if metric.endswith(("frames", "relocalisations")) else ""


def benchmark_json(checks: Sequence[Check]) -> tuple[list[dict[str, JSON]], list[Check]]:
    """github-action-benchmark's "customSmallerIsBetter" input: [{name, unit, value, range, extra}].
    Only rules where lower is better can be expressed; the others are left out (returned), and so
    are checks without a value (no run had an estimate: returned too). One entry per group, metric
    and statistic (the action keys its series by name): two rules on the same number share it, with
    both limits in "extra"; a value over fewer runs than the group has says so in "extra"."""
    entries: dict[str, dict[str, JSON]] = {}
    left: list[Check] = []
    for c in checks:
        if c.rule.better != "lower" or c.value is None:
            left.append(c)
            continue
        name = f"{c.label}: {c.metric} ({c.rule.stat})"
        verdict = f"limit {rule_text(c.rule)}: " + ("FAIL" if c.failures else "PASS")
        if name in entries:
            entries[name]["extra"] = f"{entries[name]['extra']}; {verdict}"
            continue
        iv = c.interval
        e: dict[str, JSON] = {"name": name, "unit": unit_of(c.metric), "value": c.value}
        if iv.kind in (stats.T95, stats.RANGE):
            e["range"] = f"{iv.lo:.6g} to {iv.hi:.6g} ({'95 % t interval' if iv.kind == stats.T95 else 'seeds range'})"
        e["extra"] = f"n={len(c.values)} seeds; " + (f"{metrics.no_estimate_text(c.no_value, c.of, c.metric)}; " if c.no_value else "") + verdict
        entries[name] = e
    return list(entries.values()), left
