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

Exit 0 when every rule holds, 1 when any limit or regression fails, 2 on bad input (a missing or
incomplete result folder, bad rules, an unknown metric, a rule that selects nothing) before any
verdict is printed.
"""
from __future__ import annotations

import json
import math
import os
import pathlib
from typing import Any, Sequence
import xml.etree.ElementTree as ET

from omniloc import compare as CMP
from omniloc.core import metrics as M
from omniloc.core import pathcheck as PC
from omniloc.core import rundir as RD
from omniloc.core import stats as ST
from omniloc.core.rundir import Run


ALPHA = 0.05


STATS = ("mean", "median", "max", "min")


# Metrics where a larger value is the better one: a regression is a fall (the rule's "better" default).
HIGHER_IS_BETTER = ("recall", "valid_fraction", "recovered_fraction")


RULE_KEYS = {"metric", "max", "min", "scenario", "localizer", "stat", "better", "tolerance", "tolerance_fraction", "name", "comment"}


class BadInput(Exception):
    """Input the gate cannot judge: exit 2 before any verdict."""


def _number(rule: Any, key: Any, where: Any) -> Any:
    v = rule[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise BadInput(f"{where}/{key}: got {json.dumps(v)}, expected a finite number")
    return float(v)


def load_rules(path: Any, have_baseline: Any) -> Any:
    """The rules of `path`, checked key by key; BadInput names the JSON path, the value and what was expected."""
    why = PC.why_not_readable_file(path)
    if why:  # before open(): a FIFO would block it for ever
        raise BadInput(f"{PC.shown(path)}: cannot be read ({why})")
    try:
        doc = json.loads(pathlib.Path(path).read_text())
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
    out = []
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
        r: dict[str, Any] = {"index": i, "metric": m.strip("/")}
        for k in ("scenario", "localizer", "name"):
            if k in rule and (not isinstance(rule[k], str) or not rule[k]):
                raise BadInput(f"{where}/{k}: got {json.dumps(rule[k])}, expected a non-empty string")
            r[k] = rule.get(k)
        r["max"] = _number(rule, "max", where) if "max" in rule else None
        r["min"] = _number(rule, "min", where) if "min" in rule else None
        if r["max"] is not None and r["min"] is not None and r["min"] > r["max"]:
            raise BadInput(f"{where}/min: got {r['min']:g}, expected at most max ({r['max']:g})")
        r["stat"] = rule.get("stat", "mean")
        if r["stat"] not in STATS:
            raise BadInput(f"{where}/stat: got {json.dumps(r['stat'])}, expected one of {', '.join(STATS)}")
        better = rule.get("better", "higher" if higher_is_better(r["metric"]) or (r["min"] is not None and r["max"] is None) else "lower")
        if better not in ("lower", "higher"):
            raise BadInput(f"{where}/better: got {json.dumps(better)}, expected \"lower\" or \"higher\"")
        r["better"] = better
        for k in ("tolerance", "tolerance_fraction"):
            r[k] = _number(rule, k, where) if k in rule else 0.0
            if r[k] < 0:
                raise BadInput(f"{where}/{k}: got {r[k]:g}, expected a number >= 0")
        if r["max"] is None and r["min"] is None and not have_baseline:
            raise BadInput(f"{where}: has neither \"max\" nor \"min\", and no --baseline was given: it would judge nothing")
        out.append(r)
    return out


def higher_is_better(metric: Any) -> Any:
    """Whether a larger value of `metric` is better: recall at a threshold ("r0/recall/25cm_10deg"),
    the share of frames answered (valid_fraction) and of kidnaps recovered (recovered_fraction)."""
    parts = metric.strip("/").split("/")
    return "recall" in parts[:-1] or parts[-1] in HIGHER_IS_BETTER


def run_metrics(summary: Any) -> Any:
    """Every number of a summary.json under its aggregate.csv name (batch/aggregate.cpp run_metrics):
    "r<robot>/<path>" for the robots' blocks, "<path>" for the sweep-level "metrics" block. A null
    (a statistic over no answered frame) is kept as None: the metric exists and has no value."""
    out: dict[Any, Any] = {}

    def flat(obj: Any, prefix: Any) -> None:
        if isinstance(obj, bool):
            return
        if obj is None:
            out[prefix] = None
        elif isinstance(obj, (int, float)):
            out[prefix] = float(obj)
        elif isinstance(obj, dict):
            for k, v in obj.items():
                flat(v, f"{prefix}/{k}" if prefix else k)

    for robot in summary.get("robots") or []:
        block = {k: v for k, v in robot.items() if k != "robot"}
        flat(block, f"r{robot.get('robot', 0)}")
    flat(summary.get("metrics") or {}, "")
    return out


def resolve_metric(name: str, known: Any) -> Any:
    """`name` as a key of `known`: itself, or "r0/" + name when it has no robot prefix."""
    if name in known:
        return name
    head = name.split("/", 1)[0]
    if not (head[:1] == "r" and head[1:].isdigit()) and "r0/" + name in known:
        return "r0/" + name
    return None


def metrics_of(run: Run) -> Any:
    """run_metrics of a Run, flattened once per run (every rule reads it)."""
    cache = run.__dict__  # kept on the run: every rule reads it
    if "gate_metrics" not in cache:
        cache["gate_metrics"] = run_metrics(run.summary)
    return cache["gate_metrics"]


def seed_values(runs: list[Run], metric: Any) -> Any:
    """The values of `metric` over the runs that have one (see seed_counts for the others)."""
    return seed_counts(runs, metric)[0]


def seed_counts(runs: list[Run], metric: Any) -> Any:
    """(values, no_value, of): the numbers, how many runs have the metric null (no estimate), and how
    many have it at all (a run made before the metric existed counts in neither)."""
    vals, no_value, of = [], 0, 0
    for r in runs:
        m = metrics_of(r)
        if metric not in m:
            continue
        of += 1
        v = m[metric]
        if v is None or math.isnan(v):
            no_value += 1
        else:
            vals.append(v)
    return vals, no_value, of


def statistic(values: Sequence[Any], stat: Any) -> Any:
    if not values:
        return None
    if stat == "mean":
        return sum(values) / len(values)
    if stat == "median":
        return ST.percentile(sorted(values), 0.5)
    return max(values) if stat == "max" else min(values)


def load_runs(folder: Any, what: Any) -> Any:
    """The runs under `folder`; BadInput when it is missing, holds no run or an incomplete sweep."""
    why = PC.why_not_readable_folder(folder)
    if why:
        raise BadInput(f"{what} {PC.shown(folder)}: {why}, expected a folder of results")
    try:
        runs, _, _ = RD.discover([folder])
    except SystemExit as e:
        raise BadInput(f"{what} {e}")
    if not runs:
        raise BadInput(f"{what} {folder}: no finished run (summary.json) under it")
    return runs


def judge(rules: Any, runs: list[Run], base_runs: list[Run], alpha: float) -> Any:
    """One check per rule and selected group: a dict with the values, the verdicts and the text."""
    groups = CMP.groups(runs)
    names = CMP.labels(set(groups))
    pair_of, base_groups = {}, {}
    if base_runs is not None:
        pairs, _, _, ga, gb = CMP.compare_pairs(base_runs, runs)
        base_groups = ga
        pair_of = {kb: (ka, diffs) for ka, kb, diffs in pairs}
    known = set()
    for r in runs:
        known.update(metrics_of(r))
    checks = []
    for rule in rules:
        metric = resolve_metric(rule["metric"], known)
        if metric is None:
            near = sorted(k for k in known if k.split("/")[-1] == rule["metric"].split("/")[-1])[:4]
            raise BadInput(f"rule {rule['index']}: metric \"{rule['metric']}\" is not among the results' metrics"
                           + (f" (did you mean {', '.join(near)}?)" if near else " (see aggregate.csv's metric column)"))
        keys = [k for k in sorted(groups, key=CMP.sort_key)
                if (rule["scenario"] is None or k[0] == rule["scenario"]) and (rule["localizer"] is None or k[1] == rule["localizer"])]
        if not keys:
            have = sorted({f"{k[0]} / {k[1]}" for k in groups})
            raise BadInput(f"rule {rule['index']} (scenario {rule['scenario'] or 'any'}, localizer {rule['localizer'] or 'any'}) "
                           f"selects no group of the results; they hold: {'; '.join(have)}")
        paired_any = False
        for k in keys:
            vals, no_value, of = seed_counts(groups[k], metric)
            if not of:
                raise BadInput(f"rule {rule['index']}: no run of {names[k]} has the metric {metric}")
            c = {"rule": rule, "metric": metric, "key": k, "label": names[k], "values": vals, "no_value": no_value, "of": of,
                 "value": statistic(vals, rule["stat"]), "interval": ST.interval(vals), "failures": [], "notes": []}
            if no_value:  # a run without estimates never passes: whatever the limits and the baseline
                c["failures"].append((NO_ESTIMATE, M.no_estimate_text(no_value, of)))
            check_limits(c)
            if base_runs is not None:
                if k in pair_of:
                    paired_any = True
                    ka, diffs = pair_of[k]
                    check_regression(c, seed_counts(base_groups[ka], metric), diffs, alpha)
                else:
                    c["notes"].append("no baseline counterpart: regression not checked")
                    c["regression"] = None
            checks.append(c)
        if base_runs is not None and not paired_any and rule["max"] is None and rule["min"] is None:
            raise BadInput(f"rule {rule['index']} ({metric}) has only a baseline test, and no group it selects pairs with one of the baseline")
    return checks


NO_ESTIMATE = "no estimate"  # the kind of failure of a metric that is null in some run


def check_limits(c: Any) -> None:
    r, v = c["rule"], c["value"]
    if v is None:  # no run has a value: failed already (no estimate)
        return
    if r["max"] is not None and v > r["max"]:
        c["failures"].append(("limit", f"{r['stat']} {v:.6g} > max {r['max']:.6g}"))
    if r["min"] is not None and v < r["min"]:
        c["failures"].append(("limit", f"{r['stat']} {v:.6g} < min {r['min']:.6g}"))


def check_regression(c: Any, base: Any, diffs: Any, alpha: float) -> None:
    """Regression of check `c` against the baseline's (values, no_value, of). A candidate without an
    estimate in some run has failed already; a baseline without one in some run is compared on the
    runs that have one, and the line says how many had none."""
    r = c["rule"]
    base_vals, base_none, base_of = base
    if base_none:
        c["notes"].append(f"baseline: {M.no_estimate_text(base_none, base_of)}")
    if not base_vals or c["value"] is None:
        if not base_vals:
            c["notes"].append("the baseline group has no value of this metric: regression not checked")
        c["regression"] = None
        return
    b = statistic(base_vals, r["stat"])
    worse = (c["value"] - b) if r["better"] == "lower" else (b - c["value"])
    allowed = r["tolerance"] + r["tolerance_fraction"] * abs(b)
    w = ST.welch(base_vals, c["values"])
    same = sorted(base_vals) == sorted(c["values"])
    c["regression"] = {"baseline": b, "baseline_n": len(base_vals), "worse_by": worse, "allowed": allowed, "p": w["p"], "differs": diffs}
    if same or worse <= allowed:
        return
    if w["p"] is None:
        why = f"no spread (n < 2), worse by {worse:.6g} > tolerance {allowed:.6g}"
    elif w["p"] < alpha:
        why = f"worse by {worse:.6g} > tolerance {allowed:.6g}, p {w['p']:.3g} < alpha {alpha:g}"
    else:
        c["notes"].append(f"worse by {worse:.6g} but within the seed spread (p {w['p']:.3g} >= {alpha:g})")
        return
    c["failures"].append(("regression", f"{r['stat']} {c['value']:.6g} vs baseline {b:.6g} (n={len(base_vals)}): {why}"))


def rule_text(r: Any) -> Any:
    limits = []
    if r["min"] is not None:
        limits.append(f">= {r['min']:.6g}")
    if r["max"] is not None:
        limits.append(f"<= {r['max']:.6g}")
    return " and ".join(limits) if limits else f"no worse than baseline ({r['better']} is better)"


def value_text(c: Any) -> Any:
    """'mean 0.0453 (n=5)', or 'no estimate (n=0 of 1)' where no run has a value."""
    if c["value"] is None:
        return f"no estimate (n=0 of {c['of']})"
    return f"{c['rule']['stat']} {c['value']:.6g} (n={len(c['values'])}" + (f" of {c['of']}" if c.get("no_value") else "") + ")"


def failure_text(kind: Any, msg: Any) -> Any:
    return msg if kind == NO_ESTIMATE else f"{kind}: {msg}"


def line(c: Any) -> Any:
    r = c["rule"]
    verdict = "FAIL" if c["failures"] else "PASS"
    s = f"{verdict}  {c['label']}  {c['metric']}  {value_text(c)}  limit {rule_text(r)}"
    reg = c.get("regression")
    if reg:
        p = "-" if reg["p"] is None else f"{reg['p']:.3g}"
        s += f"  baseline {reg['baseline']:.6g} (n={reg['baseline_n']}, p {p})"
    for kind, msg in c["failures"]:
        s += f"  [{failure_text(kind, msg)}]"
    for n in c["notes"]:
        s += f"  [{n}]"
    return s


def write_atomic(path: Any, text: str) -> None:
    """Temp file + rename beside the target: an interrupted gate never leaves half a report."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def junit_xml(checks: Any, results: Any, baseline: Any) -> Any:
    """JUnit XML as GitHub Actions' test reporters, GitLab CI and Jenkins read it: <testsuites>, a
    <testsuite> per scenario, a <testcase> per rule and group, a <failure> naming the metric, the
    value, the limit or baseline and the p-value. No timestamps: the same results give the same file."""
    root = ET.Element("testsuites", name="omniloc gate", tests=str(len(checks)),
                      failures=str(sum(1 for c in checks if c["failures"])), errors="0", skipped="0", time="0")
    by_scenario: dict[Any, Any] = {}
    for c in checks:
        by_scenario.setdefault(c["key"][0], []).append(c)
    for scenario, cs in sorted(by_scenario.items()):
        suite = ET.SubElement(root, "testsuite", name=scenario, tests=str(len(cs)),
                              failures=str(sum(1 for c in cs if c["failures"])), errors="0", skipped="0", time="0")
        props = ET.SubElement(suite, "properties")
        ET.SubElement(props, "property", name="results", value=str(results))
        if baseline:
            ET.SubElement(props, "property", name="baseline", value=str(baseline))
        for c in cs:
            r = c["rule"]
            title = r["name"] or f"{c['metric']} {rule_text(r)}"
            case = ET.SubElement(suite, "testcase", name=f"{c['label']}: {title}",
                                 classname=f"omniloc.{scenario}.{c['key'][1]}", time="0")
            if c["failures"]:
                msg = "; ".join(f"{c['metric']}: {m}" if kind == NO_ESTIMATE else f"{kind}: {c['metric']} {m}" for kind, m in c["failures"])
                fail = ET.SubElement(case, "failure", message=msg, type=" and ".join(sorted({k for k, _ in c["failures"]})))
                fail.text = line(c) + "\nseed values: " + (", ".join(f"{v:.6g}" for v in c["values"]) or "none") + (
                    f"; {M.no_estimate_text(c['no_value'], c['of'])}" if c.get("no_value") else "")
            else:
                out = ET.SubElement(case, "system-out")
                out.text = line(c)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


UNITS = [("_cm/", "cm"), ("_m/", "m"), ("_rad/", "rad"), ("_rad", "rad"), ("_s/", "s"), ("_s", "s")]


def unit_of(metric: Any) -> Any:
    m = metric + "/"
    for tag, unit in UNITS:
        if tag in m:
            return unit
    return "count" if metric.endswith(("frames", "relocalisations")) else ""


def benchmark_json(checks: Any) -> Any:
    """github-action-benchmark's "customSmallerIsBetter" input: [{name, unit, value, range, extra}].
    Only rules where lower is better can be expressed; the others are left out (returned), and so
    are checks without a value (no run had an estimate: returned too). One entry per group, metric
    and statistic (the action keys its series by name): two rules on the same number share it, with
    both limits in "extra"; a value over fewer runs than the group has says so in "extra"."""
    entries: dict[str, dict[str, Any]]
    left: list[dict[str, Any]]
    entries, left = {}, []
    for c in checks:
        if c["rule"]["better"] != "lower" or c["value"] is None:
            left.append(c)
            continue
        name = f"{c['label']}: {c['metric']} ({c['rule']['stat']})"
        verdict = f"limit {rule_text(c['rule'])}: " + ("FAIL" if c["failures"] else "PASS")
        if name in entries:
            entries[name]["extra"] += "; " + verdict
            continue
        iv = c["interval"]
        e = {"name": name, "unit": unit_of(c["metric"]), "value": c["value"]}
        if iv["kind"] in (ST.T95, ST.RANGE):
            e["range"] = f"{iv['lo']:.6g} to {iv['hi']:.6g} ({'95 % t interval' if iv['kind'] == ST.T95 else 'seeds range'})"
        e["extra"] = f"n={len(c['values'])} seeds; " + (f"{M.no_estimate_text(c['no_value'], c['of'])}; " if c.get("no_value") else "") + verdict
        entries[name] = e
    return list(entries.values()), left
