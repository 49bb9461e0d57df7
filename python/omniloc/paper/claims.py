"""The reproduction scorecard's judging code; the claims and their rules are data (papers.json).

- evaluate_claims(): for each claim in papers.json, our figure, the paper's, the ratio, and the
  verdict (holds / partly / does not / not run) computed by the rule written next to the claim in
  papers.json. The rules are data: "range" (the value, or for "ratio_to_published" ours / paper,
  lies in "holds" or "partly"), and "checks" (every check holds: holds; some: partly; none: does not).

A claim judged from runs of which some have no estimate (the statistic is null in summary.json: no
frame answered) is not judged on the others: its figure is "no estimate in k of n runs" and its
verdict "does not" (a localizer that does not answer does not reproduce an accuracy figure).
row_coverage() gives the coverage of the runs behind a claim (recall at the headline threshold,
share answered), which the scorecard shows before our figure.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional, Sequence

from omniloc.core import metrics, stats
from omniloc.core.jsonvalue import JSON, JSONObject, lst, number, obj
from omniloc.paper.data import AXES, KINDS, ROBUSTNESS, WEAK_TEXT
from omniloc.paper.quantity import Selector, evidence_seeds, quantity, row_runs
from omniloc.paper.tables import Context


@dataclass(frozen=True)
class CheckSpec:
    """A check to judge: a claim's own "checks" entry of papers.json, or one axis of a claim stated
    on mean x (axis_checks): its label, the selector of our figure, its rule (raw JSON: "kind",
    "holds", "partly") and the paper's figure where the rule compares with it."""
    label: str
    ours: Selector
    rule: JSONObject
    published: JSON = None


@dataclass(frozen=True)
class ClaimCheck:
    """One check of a claim judged: our figure (None: not measured, note says why), its verdict, ours
    / paper's, and how many seeds it rests on."""
    label: str
    ours: Optional[float]
    note: str
    verdict: str
    ratio: Optional[float]
    published: JSON
    seeds: Optional[int]


@dataclass(frozen=True)
class RowCoverage:
    """The coverage of the runs reproducing one published row (row_coverage): the headline recall
    threshold, the mean over runs of the recall there and of the share answered, how many runs, and
    how many had no estimate."""
    key: Optional[str]
    recall: Optional[float]
    answered: Optional[float]
    runs: int
    no_value: int


@dataclass
class Claim:
    """One claim of papers.json judged (evaluate_claims): what it is (id, paper, kind, claim), our
    figure and its text, the paper's, ours / paper's, the verdict by its rule and the rule's text,
    the checks of a claim judged on several checks or axes, notes, how many seeds the verdict rests
    on (weak: one), whether it is judged from runs, and the coverage of those runs."""
    id: str
    paper: JSON
    kind: str
    claim: str
    published: JSON
    unit: str
    rule_text: str
    uses_runs: bool
    checks: list[ClaimCheck] = field(default_factory=list)
    ratio: Optional[float] = None
    notes: list[str] = field(default_factory=list)
    verdict: str = ""
    ours: Optional[float] = None
    ours_text: str = ""
    seeds: Optional[int] = None
    weak: bool = False
    coverage: list[tuple[str, RowCoverage]] = field(default_factory=list)


def verdict_text(c: Claim) -> str:
    """A claim's verdict as printed: "holds", or "holds (1 seed: weak evidence)" when the verdict
    rests on one run or trial (evaluate_claims' "weak")."""
    return c.verdict + (f" {WEAK_TEXT}" if c.weak else "")


def no_estimate(note: Optional[str]) -> bool:
    """Whether a quantity's note says its runs had no estimate (quantity() returns None then)."""
    return str(note or "").startswith(metrics.NO_ESTIMATE)


def judge(value: Optional[float], rule: Optional[JSONObject], published: Optional[float] = None, note: Optional[str] = None) -> str:
    """The verdict of a value by a claim's rule: holds / partly / does not; "not run" without a
    value, except where the runs were made and gave no estimate (`note` says so): "does not"."""
    if rule is None:
        return "n/a"
    if value is None:
        return "does not" if no_estimate(note) else "not run"
    v = value / published if rule["kind"] == "ratio_to_published" and published is not None else value

    def inside(iv: JSON) -> bool:
        bounds = lst(iv)
        lo, hi = (number(bounds[0]), number(bounds[1])) if len(bounds) >= 2 else (None, None)
        return iv is not None and lo is not None and hi is not None and lo - 1e-12 <= v <= hi + 1e-12
    if inside(rule.get("holds")):
        return "holds"
    if inside(rule.get("partly")):
        return "partly"
    return "does not"


def uses(q: Selector, key: str) -> bool:
    """Whether a quantity selector (or any of its parts) uses `key` ("row", "timing", "experiment")."""
    if not isinstance(q, dict):
        return False
    if key in q or (key == "row" and "global_start" in q):
        return True
    parts = lst(q.get("ratio") or q.get("fraction") or []) + list(obj(q.get("vars") or {}).values())
    return any(uses(x, key) for x in parts)


def selectors(c: JSONObject) -> list[Selector]:
    """The selectors a claim of papers.json reads: its own and its checks'."""
    return [c.get("ours")] + [obj(ch).get("ours") for ch in lst(c.get("checks", []))]


def claim_kind(c: JSONObject) -> str:
    kind = c.get("kind")
    if isinstance(kind, str) and kind in KINDS:
        return kind
    if any(uses(q, "timing") for q in selectors(c)):
        return "timing"
    return "robustness" if c["id"] in ROBUSTNESS else "accuracy"


def uses_runs(c: JSONObject) -> bool:
    """Whether a claim is judged from runs (which have a noise profile) rather than experiments."""
    return any(uses(q, "row") or uses(q, "timing") for q in selectors(c))


def published_cell(papers: JSONObject, row: JSON, metric: str) -> Optional[float]:
    """The paper's number of a published error-table row for one metric (None for our extra rows)."""
    table, label = (str(x) for x in lst(row)[:2])
    t = obj(papers.get(table))
    values = obj(t.get("rows")).get(label)
    if not isinstance(values, list):
        return None
    keys = [f"{a}/{s}" for a, s in metrics.TABLE_KEYS]
    return number(values[keys.index(metric)]) if metric in keys else None


def on_axis(q: JSONObject, metric: str) -> Optional[JSONObject]:
    """The selector q with its mean-x metric replaced by `metric` (None when q is not all mean-x rows)."""
    if "row" in q:
        return dict(q, metric=metric) if q.get("metric") == "x_cm/mean" else None
    for k in ("ratio", "fraction"):
        if k in q:
            parts = [on_axis(obj(x), metric) for x in lst(q[k])]
            return None if None in parts else {k: [p for p in parts if p is not None]}
    return None


def published_value(papers: JSONObject, q: JSONObject) -> Optional[float]:
    """What the paper's own table gives for a selector (a row's cell or a ratio of cells)."""
    if "row" in q:
        return published_cell(papers, q["row"], str(q["metric"]))
    for k in ("ratio", "fraction"):
        if k in q:
            a, b = (published_value(papers, obj(x)) for x in lst(q[k]))
            return a / b if a is not None and b else None
    return None


def axis_checks(papers: JSONObject, label: str, selector: Selector, rule: JSONObject,
                published: Optional[float] = None) -> tuple[Optional[list[CheckSpec]], Optional[list[str]]]:
    """A check stated on mean x of published rows, split into one check per axis (x, y, heading)
    that the paper states. An axis is judged only where the paper's own numbers satisfy the rule
    (else the claim is not the paper's for that axis, and a note says so). Returns (checks, notes)
    or (None, None) when the selector is not of that form."""
    q = obj(selector)
    if on_axis(q, "y_cm/mean") is None:
        return None, None
    checks: list[CheckSpec] = []
    notes: list[str] = []
    for metric, axis in AXES:
        qa = on_axis(q, metric)
        pub = published_value(papers, qa) if qa is not None else None
        if pub is None:
            return None, None
        if rule["kind"] == "ratio_to_published":
            checks.append(CheckSpec(label=f"{label}{axis}", ours=qa, rule=rule, published=pub))
            continue
        if judge(pub, rule) != "holds":
            notes.append(f"{axis} not judged: the paper's own value {stats.fnum(pub, 2)} is outside the rule")
            continue
        checks.append(CheckSpec(label=f"{label}{axis}", ours=qa, rule=rule, published=pub))
    return checks, notes


def combine(verdicts: Sequence[str]) -> str:
    """The verdict of a claim judged on several checks: all hold: holds; some: partly."""
    if any(v == "not run" for v in verdicts):
        return "not run"
    if all(v == "holds" for v in verdicts):
        return "holds"
    if any(v in ("holds", "partly") for v in verdicts):
        return "partly"
    return "does not"


def evaluate_claims(ctx: Context) -> list[Claim]:
    """Every claim of papers.json judged: our figure and the paper's, ours / paper's, the verdict
    by the claim's rule, the checks (for claims judged on several checks or axes) and notes."""
    out = []
    for raw in lst(ctx.papers.get("claims", [])):
        c = obj(raw)
        published = c.get("published")
        pub_number = number(published) if isinstance(published, (int, float)) else None
        row = Claim(id=str(c["id"]), paper=c["paper"], kind=claim_kind(c), claim=str(c["claim"]), published=published,
                    unit=str(c.get("unit", "")), rule_text=str(c.get("rule_text", "")), uses_runs=uses_runs(c))
        rule = obj(c["rule"]) if isinstance(c.get("rule"), dict) else None
        checks = [CheckSpec(label=str(obj(ch)["label"]), ours=obj(ch).get("ours"), rule=obj(obj(ch)["rule"]), published=obj(ch).get("published"))
                  for ch in lst(c.get("checks", []))]
        if not checks and c.get("ours") is not None and c.get("rule"):
            split, notes = axis_checks(ctx.papers, "mean ", c["ours"], obj(c["rule"]), pub_number)
            if split:
                checks, row.notes = split, notes or []
        elif checks:
            split_checks: list[CheckSpec] = []
            for ch in checks:
                split, notes = axis_checks(ctx.papers, ch.label + ": ", ch.ours, ch.rule)
                split_checks += split if split else [ch]
                row.notes += [f"{ch.label}: {n}" for n in (notes or [])]
            checks = split_checks
        if checks:
            verdicts = []
            for ch in checks:
                v, note = quantity(ch.ours, ctx)
                pub = number(ch.published) if ch.rule["kind"] == "ratio_to_published" else None
                verdict = judge(v, ch.rule, pub, note)
                verdicts.append(verdict)
                ratio = v / pub if v is not None and pub else None
                row.checks.append(ClaimCheck(label=ch.label, ours=v, note=note, verdict=verdict, ratio=ratio,
                                             published=ch.published, seeds=evidence_seeds(ch.ours, ctx)))
            row.verdict = combine(verdicts)
            row.ours = None
            row.ours_text = "; ".join(f"{ch.label}: " + (stats.fnum(ch.ours, 3) if ch.ours is not None or not no_estimate(ch.note) else ch.note)
                                      + (f" ({stats.fnum(ch.ratio, 2)}x the paper's)" if ch.ratio is not None else "")
                                      + f" {ch.verdict}" for ch in row.checks)
            if all(ch.ours is None for ch in row.checks):  # nothing measured: say why once, not per axis
                row.ours_text = "; ".join(dict.fromkeys(ch.note for ch in row.checks))
            ratios = [ch.ratio for ch in row.checks if ch.ratio is not None]
            row.ratio = ratios[0] if len(ratios) == 1 else None
        else:
            v, note = quantity(c.get("ours"), ctx)
            row.ours = v
            row.ours_text = (stats.fnum(v, 3) + (f" {row.unit}" if row.unit not in ("x", "") else "") + (f" ({note})" if note else "")) if v is not None else note
            if pub_number is not None and v is not None and pub_number:
                row.ratio = v / pub_number
            row.verdict = judge(v, rule, pub_number, note)
            row.seeds = evidence_seeds(c.get("ours"), ctx)
        if row.checks:
            counts = [ch.seeds for ch in row.checks if ch.seeds is not None]
            row.seeds = min(counts) if counts else None
        # A verdict that rests on one seed or trial is weak evidence, and says so.
        row.weak = row.verdict in ("holds", "partly", "does not") and row.seeds == 1
        row.coverage = claim_coverage(c, ctx)
        out.append(row)
    return out


def claim_rows(q: JSON, out: Optional[list[list[JSON]]] = None) -> list[list[JSON]]:
    """The published rows [table, label] a quantity selector (or claim) reads runs of, in order."""
    out = [] if out is None else out
    if isinstance(q, dict):
        for k in ("row", "global_start"):
            if k in q and lst(q[k]) not in out:
                out.append(list(lst(q[k])))
        for x in lst(q.get("ratio") or q.get("fraction") or []) + list(obj(q.get("vars") or {}).values()):
            claim_rows(x, out)
        if "ours" in q:
            claim_rows(q["ours"], out)
        for ch in lst(q.get("checks") or []):
            claim_rows(ch, out)
    return out


def row_coverage(ctx: Context, row: JSON) -> Optional[RowCoverage]:
    """The coverage of the runs reproducing one published row: the mean over runs of the recall at
    their headline threshold and of the share of frames answered (tracking phase where a run has
    one); None where the row has no runs."""
    sel, _ = row_runs(ctx, row)
    if not sel:
        return None
    key = metrics.headline_key(sel)
    rec = metrics.run_stats(sel, f"recall/{key}") if key else None
    ans = metrics.run_stats(sel, "valid_fraction")
    return RowCoverage(key=key, recall=rec.mean if rec else None, answered=ans.mean, runs=len(sel),
                       no_value=metrics.run_stats(sel, "position_m/rmse").no_value)


def claim_coverage(c: JSONObject, ctx: Context) -> list[tuple[str, RowCoverage]]:
    """[(row label, row_coverage)] of the rows a claim of papers.json is judged on ([] for claims
    judged from experiments or timings)."""
    out = []
    for row in claim_rows(c):
        cov = row_coverage(ctx, row)
        if cov is not None:
            out.append((str(row[1]), cov))
    return out


def coverage_text(cov: Sequence[tuple[str, RowCoverage]]) -> str:
    """'within 25 cm / 10 deg 97.0 %, answered 100.0 %' for row_coverage() output, with the row's
    label where a claim reads several rows; '-' when nothing is known."""
    parts = []
    for label, c in cov or []:
        if c.key is None and c.answered is None:  # runs made before coverage was scored
            continue
        t = (f"within {metrics.recall_label(c.key)} {metrics.percent(c.recall)}, " if c.key else "") + f"answered {metrics.percent(c.answered)}"
        if c.no_value:
            t += f" ({metrics.no_estimate_text(c.no_value, c.runs)})"
        parts.append((f"{label}: " if len(cov) > 1 else "") + t)
    return "; ".join(parts) if parts else "-"


def totals(claims: Sequence[Claim]) -> dict[str, dict[str, int]]:
    """{kind: {verdict: count}} over the claims, for the scorecard's summary and the terminal."""
    out: dict[str, dict[str, int]] = {k: {} for k in KINDS}
    for c in claims:
        d = out.setdefault(c.kind, {})
        d[c.verdict] = d.get(c.verdict, 0) + 1
    return out


def totals_text(t: dict[str, dict[str, int]]) -> str:
    """'accuracy: 3 holds, 1 partly; robustness: ...' (kinds without claims left out)."""
    order = ["holds", "partly", "does not", "not run", "n/a"]
    parts = []
    for kind in KINDS:
        d = t.get(kind) or {}
        if d:
            parts.append(f"{kind}: " + ", ".join(f"{d[v]} {v}" for v in order if d.get(v)))
    return "; ".join(parts)
