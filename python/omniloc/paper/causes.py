"""Why a verdict is not "holds": the causes of papers.json's claims (causes.json) judged against the results.

A claim may carry "causes": [{"verdicts": [...], "profiles": [...], "text": ...,
"doc": "docs/FILE.md#anchor", "evidence": [{"label", "ours": selector, "unit", "expect": [lo, hi]}]}].
A cause is an argument that rests on measurements: each evidence item is a quantity read from the
results given to the report, and "expect" is the range in which it supports the argument. So a cause
whose numbers change under a later model says so ("evidence contradicts") instead of standing as text.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional, Sequence

from omniloc.core.jsonvalue import JSON, JSONObject, lst, number, obj, text
from omniloc.core.verdicts import CONTRADICTED, EXPLAINED, NOT_MEASURED, UNEXPLAINED
from omniloc.paper.claims import Claim
from omniloc.paper.labels import cause_summary
from omniloc.paper.quantity import quantity
from omniloc.paper.tables import Context


@dataclass(frozen=True)
class Evidence:
    """One measurement a cause rests on: its label, our value (None: not measured, note says why)
    and unit, the range in which it supports the argument, and whether it lies there."""
    label: str
    value: Optional[float]
    unit: str
    expect: Optional[list[float]]
    ok: Optional[bool]
    note: str


@dataclass
class Cause:
    """Why a claim's verdict under one noise profile is not "holds" (explain()): the claim, its
    verdict, the status of its cause (explained, evidence not in these results, evidence contradicts
    the cause, no cause recorded), the argument, its one-sentence summary, the doc that details it,
    and the evidence read from the results."""
    id: str
    paper: JSON
    claim: str
    verdict: str
    profile: str
    status: str = UNEXPLAINED
    text: str = ""
    summary: str = ""
    doc: str = ""
    evidence: list[Evidence] = field(default_factory=list)


def applies(cause: JSONObject, verdict: str, profile: str) -> bool:
    """Whether a cause of causes.json speaks to this verdict under this profile."""
    return verdict in lst(cause.get("verdicts", ["partly", "does not"])) and profile in lst(cause.get("profiles", ["robot", "field_robot"]))


def explain(claims: Sequence[Claim], ctx: Context, profile: str = "robot") -> list[Cause]:
    """One Cause per claim of `claims` (evaluate_claims' output for ctx) whose verdict is neither
    "holds" nor "not run" / "n/a". Its status is explained where every evidence item is measured
    and inside its range."""
    by_id = {str(obj(c).get("id")): obj(c) for c in lst(ctx.papers.get("claims", []))}
    out = []
    for c in claims:
        if c.verdict in ("holds", "not run", "n/a"):
            continue
        causes = [obj(k) for k in lst(by_id.get(c.id, {}).get("causes", [])) if applies(obj(k), c.verdict, profile)]
        row = Cause(id=c.id, paper=c.paper, claim=c.claim, verdict=c.verdict, profile=profile)
        if causes:
            k = causes[0]
            row.text, row.doc, row.summary = str(k["text"]), str(k.get("doc", "")), cause_summary(k)
            for raw in lst(k.get("evidence", [])):
                ev = obj(raw)
                v, note = quantity(ev["ours"], ctx)
                expect = [number(x) for x in lst(ev["expect"])] if "expect" in ev else None
                lo, hi = (expect[0], expect[1]) if expect and len(expect) >= 2 else (-math.inf, math.inf)
                ok = None if v is None else (lo is not None and hi is not None and lo - 1e-12 <= v <= hi + 1e-12)
                row.evidence.append(Evidence(label=str(ev["label"]), value=v, unit=text(ev.get("unit", "")) or "",
                                             expect=[x for x in expect if x is not None] if expect is not None else None, ok=ok, note=note))
            oks = [e.ok for e in row.evidence]
            row.status = CONTRADICTED if False in oks else NOT_MEASURED if (None in oks or not oks) else EXPLAINED
        out.append(row)
    return out


def significant(v: Optional[float]) -> str:
    """Three significant figures, no exponent for the magnitudes the causes use."""
    if v is None or not math.isfinite(v):
        return "-"
    if v == 0:
        return "0"
    digits = max(0, 2 - int(math.floor(math.log10(abs(v)))))
    return f"{v:.{digits}f}"


def evidence_text(e: Evidence) -> str:
    """'label: 0.12 deg/cm (expected 0-0.2)' for the report and the terminal."""
    if e.value is None:
        return f"{e.label}: not measured ({e.note})"
    rng = ""
    if e.expect:
        lo, hi = e.expect
        rng = f" (argument needs {significant(lo)} to {significant(hi)})" if lo > -1e11 and hi < 1e11 else \
              f" (argument needs at least {significant(lo)})" if hi >= 1e11 else f" (argument needs at most {significant(hi)})"
    mark = "" if e.ok else " — CONTRADICTS"
    return f"{e.label}: {significant(e.value)}{(' ' + e.unit) if e.unit else ''}{rng}{mark}"
