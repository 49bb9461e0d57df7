"""Two result sets side by side per metric: the difference and whether it exceeds the seed-to-seed spread.

Run as `omniloc compare A B [--markdown] [--alpha P]` or `python3 -m omniloc.commands.compare A B ...`
(the same).

A and B are result folders (runs, sweeps, or folders holding them), e.g. the paper suite of two
commits. Runs are grouped by scenario, localizer and effective configuration (config.json without
the seed and the run's name): the same condition on both sides pairs BY KEY, whatever folder or
position a run has. Conditions left over pair with their nearest counterpart (same scenario and
localizer, fewest differing values; then the same scenario with another localizer, to compare
two localizers), and every value that differs is named ("differs: /occlusion/fraction: 0.125 ->
0.25"). A condition given the true start pose (summary.json start_pose_given) never pairs with one
that started from an unknown pose: tracking and global localization are different tasks; such a
condition is listed as unpaired with the reason ("not comparable: ..."). Runs made before omniloc
recorded start_pose_given pair as before. The text output fits 100 columns; --markdown gives one wide table. Per group and metric: mean over seeds of A and of B (n each), B - A, and
Welch's unequal-variance t-test over the seeds; "yes" where p < alpha (default 0.05), i.e. the
difference exceeds the seed-to-seed spread. With fewer than two seeds on a side there is no spread
to compare with, and the difference is shown alone ("n < 2"). Identical numbers give "same".

Coverage first: each condition's metrics start with the recall at the headline threshold
(recall/25cm_10deg: the share of ALL scored frames within 25 cm and 10 deg, a frame without an
estimate counting as outside) and the share of frames answered (valid_fraction); the errors
(position RMSE, mean x / y / heading, ...) follow and are over the answered frames only. A
statistic that is null in some run (no estimate: no frame answered) is never averaged away: its
row says "no estimate in k of n runs" for that side instead of a t-test on the remaining seeds.

The accuracy limit (docs/results.md), where the runs carry it: after the errors, the efficiency (RMSE
/ Cramer-Rao bound of the same frames: 1 is the limit), the share of frames it covers, the bound and
the relative pose error over a frame and a second; a run without a bound reads "no bound in k of n
runs", never 0. Runs made before the bound have none of these rows.
Exit code 0; 2 on bad arguments or folders without results.
"""
from __future__ import annotations

import json
import textwrap
from typing import Callable, Iterator, NamedTuple, Optional, Sequence, Union

from omniloc.core import bound, metrics, pairing, stats
from omniloc.core.jsonvalue import JSON
from omniloc.core.rundir import Run
from omniloc.core.stats import SeedStats, Welch

# A cell of compare_rows' table: text, or a count of runs.
Cell = Union[str, int]


class GroupKey(NamedTuple):
    """A condition: scenario, localizer, configuration (config.json without the seed and the run's
    name, as sorted JSON text) and whether the runs were given the start pose (True, False, or None
    for runs from before omniloc recorded it). Runs of one condition are its seeds."""
    scenario: Optional[str]
    localizer: Optional[str]
    config: str
    start_pose_given: Optional[bool]


# The pairs of compare_pairs: (A's key, B's key, what differs between them).
Pair = tuple[GroupKey, GroupKey, list[str]]


# The accuracy limit (core.bound), after the errors: how far the RMSE is from the Cramer-Rao bound
# (efficiency, posterior bound where the run tracks), the bound itself, the share of frames both
# cover, and the relative pose error over a frame and a second. Runs made before the bound lack them
# and their rows are left out.
LIMIT_METRICS = ["efficiency/position", "efficiency/heading", "efficiency/share", "bound/posterior/position_rms_m",
                 "rpe/frame/translation_rms_m", "rpe/1s/translation_rms_m"]


# After the coverage metrics (recall at the headline threshold, valid_fraction: metrics_for), in this order.
METRICS = ["position_m/rmse", "x_cm/mean", "y_cm/mean", "theta_rad/mean", "position_m/mean", "position_m/p95", "line_points/mean", "wrong_frames",
           "coasting_frames", "recovery/recovered", "recovery/recovery_time_s/median"] + LIMIT_METRICS


COVERAGE = "valid_fraction"


ALPHA = 0.05


EXPLANATION = ("Runs pair by scenario, localizer and effective configuration (not by folder or position); numbers are robot 0's, "
               "tracking phase where a run has one. recall/T: share of all scored frames within threshold T (a frame without an estimate "
               "counts as outside); valid_fraction: share of frames answered; the errors after them are over answered frames only. "
               "'no estimate in k of n runs': the statistic is null there (no frame answered), so no t-test is made. "
               "'exceeds spread': Welch's t-test over seeds, p < alpha; n < 2: no spread to compare with.")


LIMIT_EXPLANATION = ("efficiency/position: the position RMSE over the Cramer-Rao bound of the same frames (1 is the limit, 1.3 is 30 % above "
                     "it; against the posterior bound where the run tracks), efficiency/share: the share of scored frames with both an "
                     "estimate and a finite bound; 'no bound in k of n runs': the bound is null there (no truth, or no frame with a "
                     "finite bound), never 0. rpe: relative pose error over one frame and one second (no alignment).")


def explanation(runs: Sequence[Run]) -> str:
    """EXPLANATION, and what the accuracy limit's rows mean where any of the runs carries the bound."""
    return EXPLANATION + (" " + LIMIT_EXPLANATION if any(r.bound() is not None for r in runs) else "")


def metrics_for(runs: list[Run], wanted: Optional[Sequence[str]] = None) -> list[str]:
    """The metrics of a pair of conditions, coverage first: recall at the runs' headline threshold,
    the share answered (valid_fraction), then `metrics` (default METRICS: the errors over answered
    frames, position RMSE first), then the other recall thresholds and the time to the first
    estimate within the headline threshold. Runs from before recall was scored: `metrics` alone."""
    names = list(METRICS if wanted is None else wanted)
    head = metrics.headline_key(runs)
    if head is None:
        return [COVERAGE] + names if any(r.lookup(COVERAGE)[0] for r in runs) and COVERAGE not in names else names
    others = [f"recall/{k}" for k in metrics.recall_keys(runs) if k != head]
    return [f"recall/{head}", COVERAGE] + [m for m in names if m != COVERAGE] + others + ["first_within_s"]


def group_key(run: Run) -> GroupKey:
    """The run's condition: the start pose is part of it (True, False, or None for runs from before
    omniloc recorded it)."""
    cfg = dict(run.config)
    cfg.pop("seed", None)
    cfg.pop("name", None)
    return GroupKey(run.scenario, run.localizer, json.dumps(cfg, sort_keys=True), run.start_pose_given)


def same_task(x: GroupKey, y: GroupKey) -> bool:
    """Whether two conditions ran the same start-pose task (pairing.start_pose_compatible)."""
    return pairing.start_pose_compatible(x.start_pose_given, y.start_pose_given)


def flatten(value: JSON, prefix: str = "") -> dict[str, str]:
    """{JSON pointer: the value's compact JSON text} of every leaf (arrays of objects indexed)."""
    out: dict[str, str] = {}
    if isinstance(value, dict):
        for k, v in value.items():
            out.update(flatten(v, f"{prefix}/{k}"))
    elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        for i, v in enumerate(value):
            out.update(flatten(v, f"{prefix}/{i}"))
    else:
        out[prefix] = json.dumps(value, separators=(",", ":"))
    return out


def flat_config(key: GroupKey) -> dict[str, str]:
    parsed: JSON = json.loads(key.config)
    return flatten(parsed)


def differing(fa: dict[str, str], fb: dict[str, str], skip_localizer: bool = False) -> list[str]:
    """The JSON pointers whose values differ between two flattened configurations, all of them."""
    ptrs = sorted(p for p in set(fa) | set(fb) if fa.get(p) != fb.get(p))
    return [p for p in ptrs if not (skip_localizer and p.startswith("/localizer"))]


def labels(keys: set[GroupKey]) -> dict[GroupKey, str]:
    """'scenario / localizer', plus EVERY configuration value that tells apart conditions sharing both
    (no '...': two variants must never look identical)."""
    by: dict[tuple[Optional[str], Optional[str]], list[GroupKey]] = {}
    for k in keys:
        by.setdefault((k.scenario, k.localizer), []).append(k)
    out = {}
    for sl, ks in by.items():
        flat = {k: flat_config(k) for k in ks}
        ptrs = sorted({p for f in flat.values() for p in f if len({f.get(p) for f in flat.values()}) > 1})
        # Where one side holds a condition both with and without the start pose, the given one says so.
        both = {k.start_pose_given for k in ks} >= {True, False}
        for k in ks:
            extra = ", ".join(f"{p}={flat[k].get(p, 'absent')}" for p in ptrs)
            out[k] = f"{sl[0]} / {sl[1]}" + (f" / {extra}" if extra else "") + (" (given the start pose)" if both and k.start_pose_given is True else "")
    return out


def groups(runs: list[Run]) -> dict[GroupKey, list[Run]]:
    """The runs by condition (their seeds), in the order of the runs."""
    g: dict[GroupKey, list[Run]] = {}
    for r in runs:
        g.setdefault(group_key(r), []).append(r)
    return g


def verdict(w: Welch, a: Sequence[float], b: Sequence[float], alpha: float, none_a: int = 0, none_b: int = 0, of_a: int = 0, of_b: int = 0,
            metric: str = "") -> str:
    """'yes' / 'no' (Welch, p < alpha), 'n < 2', 'same', '-'; where a side has runs without a value
    (no estimate; no bound for a metric of the accuracy limit), no test is made and the verdict names
    them: 'no estimate in 1 of 3 runs (B)'."""
    if none_a or none_b:
        if (none_a, of_a) == (none_b, of_b):
            return f"{metrics.no_estimate_text(none_a, of_a, metric)} (A and B)"
        return "; ".join(f"{metrics.no_estimate_text(k, n, metric)} ({side})" for side, k, n in (("A", none_a, of_a), ("B", none_b, of_b)) if k)
    if len(a) == len(b) and a and all(x == y for x, y in zip(sorted(a), sorted(b))):
        return "same"
    if w.diff is None:
        return "-"
    if w.p is None:
        return "n < 2"
    return "yes" if w.p < alpha else "no"


def mutual_nearest(left_a: list[GroupKey], left_b: list[GroupKey], same: Callable[[GroupKey, GroupKey], bool],
                   skip_localizer: bool = False) -> list[tuple[GroupKey, GroupKey]]:
    """Pairs (ka, kb) of leftover groups for which same(ka, kb) holds and each is the other's unique
    nearest (fewest differing configuration values): a variant finds its counterpart even when
    every run of one side also differs in some value (e.g. a default a newer build added)."""
    def nearest(k: GroupKey, pool: list[GroupKey], fk: dict[str, str]) -> Optional[GroupKey]:
        cands = [(len(differing(fk, flat_config(o), skip_localizer)), o) for o in pool if same(k, o)]
        if not cands:
            return None
        cands.sort(key=lambda c: c[0])
        return cands[0][1] if len(cands) == 1 or cands[0][0] < cands[1][0] else None
    pairs = []
    for ka in left_a:
        kb = nearest(ka, left_b, flat_config(ka))
        if kb is not None and nearest(kb, left_a, flat_config(kb)) == ka:
            pairs.append((ka, kb))
    return pairs


def compare_pairs(runs_a: list[Run], runs_b: list[Run]) -> tuple[list[Pair], list[GroupKey], list[GroupKey],
                                                                 dict[GroupKey, list[Run]], dict[GroupKey, list[Run]]]:
    """The conditions of A and B paired BY KEY: [(ka, kb, differences)], then A's and B's unpaired
    keys. First identical keys (scenario, localizer, configuration); then, among the rest, the
    same scenario and localizer with the nearest configuration; then the same scenario with
    another localizer (comparing two localizers on one scenario). differences: 'localizer: a -> b'
    and every differing configuration value 'pointer: a -> b'."""
    ga, gb = groups(runs_a), groups(runs_b)
    pairs = [(k, k) for k in sorted(set(ga) & set(gb), key=sort_key)]
    left_a, left_b = [k for k in sorted(ga, key=sort_key) if k not in gb], [k for k in sorted(gb, key=sort_key) if k not in ga]
    # Identical but for a start pose one side did not record (an older build): the same condition.
    found = mutual_nearest(left_a, left_b, lambda x, y: x[:3] == y[:3] and same_task(x, y))
    pairs += found
    left_a = [k for k in left_a if k not in {p[0] for p in found}]
    left_b = [k for k in left_b if k not in {p[1] for p in found}]
    for same, skip in ((lambda x, y: x[:2] == y[:2] and same_task(x, y), False), (lambda x, y: x[0] == y[0] and same_task(x, y), True)):
        found = mutual_nearest(left_a, left_b, same, skip)
        pairs += found
        left_a = [k for k in left_a if k not in {p[0] for p in found}]
        left_b = [k for k in left_b if k not in {p[1] for p in found}]
    out: list[Pair] = []
    for ka, kb in sorted(pairs, key=lambda p: (p[0][0], p[0][1], p[0][2], sort_key(p[0]))):
        diffs = [] if ka[1] == kb[1] else [f"localizer: {ka[1]} -> {kb[1]}"]
        fa, fb = flat_config(ka), flat_config(kb)
        diffs += [f"{p}: {fa.get(p, 'absent')} -> {fb.get(p, 'absent')}" for p in differing(fa, fb, skip_localizer=ka[1] != kb[1])]
        out.append((ka, kb, diffs))
    return out, left_a, left_b, ga, gb


def sort_key(k: GroupKey) -> tuple[Optional[str], Optional[str], str, int]:
    """Keys sort with their start pose (None, False, True do not compare with each other)."""
    return (k.scenario, k.localizer, k.config, 0 if k.start_pose_given is None else 2 if k.start_pose_given else 1)


def unpaired_reason(k: GroupKey, other: Union[dict[GroupKey, list[Run]], list[GroupKey]]) -> str:
    """Why condition `k` of one side has no counterpart: '' (the other side did not run it), or
    'not comparable: ...' when the other side ran the same scenario with the other start-pose task."""
    clash = [o for o in other if o.scenario == k.scenario and not same_task(k, o)]
    if not clash:
        return ""
    return (f"not comparable: {pairing.start_pose_text(k.start_pose_given)} here, {pairing.start_pose_text(clash[0].start_pose_given)} on the other side "
            "(tracking from the true start pose and global localization are different tasks)")


def compare_rows(runs_a: list[Run], runs_b: list[Run], alpha: float = ALPHA, wanted: Sequence[str] = METRICS) -> tuple[list[str], list[list[Cell]]]:
    """[header, rows]: one row per paired condition and metric, then the unpaired conditions."""
    pairs, only_a, only_b, ga, gb = compare_pairs(runs_a, runs_b)
    names = side_labels(ga, gb)
    header = ["scenario / localizer / differing configuration", "metric", "A mean", "n", "B mean", "n", "B - A", "p (Welch)", "exceeds spread"]
    rows: list[list[Cell]] = []
    for ka, kb, diffs in pairs:
        label = names[ka] + (f" (A vs B: {'; '.join(diffs)})" if diffs else "")
        for m, sa, sb, w, v in metric_rows(ga[ka], gb[kb], alpha, wanted):
            rows.append([label, m, mean_text(sa, metric=m), sa.n, mean_text(sb, metric=m), sb.n,
                         stats.fnum(w.diff, 4), stats.fnum(w.p, 3) if w.p is not None else "-", v])
    for k in only_a:
        why = unpaired_reason(k, gb)
        rows.append([names[k], f"(only in A{': ' + why if why else ''})", "", len(ga[k]), "", "", "", "", ""])
    for k in only_b:
        why = unpaired_reason(k, ga)
        rows.append([names[k], f"(only in B{': ' + why if why else ''})", "", "", "", len(gb[k]), "", "", ""])
    return header, rows


def side_labels(ga: dict[GroupKey, list[Run]], gb: dict[GroupKey, list[Run]]) -> dict[GroupKey, str]:
    """Labels made within each side (A's variants told apart among A's, B's among B's): what tells
    A from B is listed separately, as the pair's differences."""
    names = labels(set(gb))
    names.update(labels(set(ga)))
    return names


def mean_text(st: SeedStats, digits: int = 4, metric: str = "") -> str:
    """A side's mean over seeds; 'no estimate' ('no bound' for a metric of the accuracy limit) where
    every run has the statistic null."""
    return bound.null_text(metric) if not st.n and st.no_value else stats.fnum(st.mean, digits)


def metric_rows(ra: list[Run], rb: list[Run], alpha: float, wanted: Optional[Sequence[str]] = None) -> Iterator[tuple[str, SeedStats, SeedStats, Welch, str]]:
    """(metric, stats A, stats B, Welch, verdict) per metric that either side has (metrics_for's
    order: coverage first). stats are metrics.run_stats: n counts the runs with a value, no_value
    those where it is null. No difference and no test where a side has runs without a value."""
    for m in metrics_for(list(ra) + list(rb), wanted):
        sa, sb = metrics.run_stats(ra, m), metrics.run_stats(rb, m)
        if not sa.of and not sb.of:
            continue
        a, b = sa.values, sb.values
        w = stats.welch(a, b)
        if sa.no_value or sb.no_value:
            w = Welch(diff=None, t=None, df=None, p=None)
        yield m, sa, sb, w, verdict(w, a, b, alpha, sa.no_value, sb.no_value, sa.of, sb.of, m)


def print_text(runs_a: list[Run], runs_b: list[Run], alpha: float, width: int = 100) -> None:
    """Readable at `width` columns: a block per paired condition, its name and every difference on
    lines of their own (wrapped, never cut), then the metrics in narrow columns."""
    pairs, only_a, only_b, ga, gb = compare_pairs(runs_a, runs_b)
    names = side_labels(ga, gb)
    def wrap(text: str, indent: str) -> str:
        return textwrap.fill(text, width, initial_indent=indent, subsequent_indent=indent + "    ")
    head = ["metric", "A mean", "n", "B mean", "n", "B - A", "p", "exceeds"]
    widths = [31, 11, 3, 11, 3, 11, 6, 8]

    def line(cells: list[str]) -> str:
        return "  " + "  ".join(c.ljust(w) if i == 0 else c.rjust(w) for i, (c, w) in enumerate(zip(cells, widths))).rstrip()
    for ka, kb, diffs in pairs:
        print(wrap(names[ka], ""))
        for d in diffs:
            print(wrap("differs: " + d, "  "))
        print(line(head))
        for m, sa, sb, w, v in metric_rows(ga[ka], gb[kb], alpha):
            short = v if len(v) <= widths[-1] else "no test"  # the runs without a value: on a line of their own
            print(line([m, mean_text(sa, metric=m), str(sa.n), mean_text(sb, metric=m), str(sb.n), stats.fnum(w.diff, 4),
                        stats.fnum(w.p, 3) if w.p is not None else "-", short]))
            if short != v:
                print(wrap(v, "    "))
        print()
    for side, keys, g, other in (("A", only_a, ga, gb), ("B", only_b, gb, ga)):
        for k in keys:
            why = unpaired_reason(k, other)
            print(wrap(f"only in {side} ({len(g[k])} runs): {names[k]}" + (f"; {why}" if why else ""), ""))
    print()
    print(textwrap.fill(EXPLANATION + " p: Welch's t-test over seeds.", width))
    if any(r.bound() is not None for r in list(runs_a) + list(runs_b)):
        print(textwrap.fill(LIMIT_EXPLANATION, width))


def versions(runs: list[Run]) -> str:
    """'v1.2-3-gabc (20 runs), v1.2 (4 runs)': the builds that made the runs."""
    v: dict[str, int] = {}
    for r in runs:
        v[str(r.version)] = v.get(str(r.version), 0) + 1
    return ", ".join(f"{k} ({n} runs)" for k, n in sorted(v.items()))
