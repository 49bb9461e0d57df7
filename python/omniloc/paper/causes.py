"""Why a verdict is not "holds": the causes of papers.json's claims (causes.json) judged against the results.

A claim may carry "causes": [{"verdicts": [...], "profiles": [...], "text": ...,
"doc": "docs/FILE.md#anchor", "evidence": [{"label", "ours": selector, "unit", "expect": [lo, hi]}]}].
A cause is an argument that rests on measurements: each evidence item is a quantity read from the
results given to the report, and "expect" is the range in which it supports the argument. So a cause
whose numbers change under a later model says so ("evidence contradicts") instead of standing as text.
"""
from __future__ import annotations

import math
from typing import Any

from omniloc.core.verdicts import CONTRADICTED, EXPLAINED, NOT_MEASURED, UNEXPLAINED
from omniloc.paper.labels import cause_summary
from omniloc.paper.quantity import quantity
from omniloc.paper.tables import Context


def _applies(cause: Any, verdict: Any, profile: Any) -> Any:
    return verdict in cause.get("verdicts", ["partly", "does not"]) and profile in cause.get("profiles", ["robot", "field_robot"])


def explain(claims: Any, ctx: Context, profile: Any = "robot") -> Any:
    """One row per claim of `claims` (evaluate_claims' output for ctx) whose verdict is neither
    "holds" nor "not run" / "n/a": {"id", "paper", "claim", "verdict", "profile", "status", "text",
    "doc", "evidence": [{"label", "value", "unit", "expect", "ok", "note"}]}. status: explained (every
    evidence item measured and inside its range), evidence not in these results, evidence contradicts
    the cause, or no cause recorded."""
    by_id = {c["id"]: c for c in ctx.papers.get("claims", [])}
    out = []
    for c in claims:
        if c["verdict"] in ("holds", "not run", "n/a"):
            continue
        causes = [k for k in by_id.get(c["id"], {}).get("causes", []) if _applies(k, c["verdict"], profile)]
        row = {"id": c["id"], "paper": c["paper"], "claim": c["claim"], "verdict": c["verdict"], "profile": profile,
               "status": UNEXPLAINED, "text": "", "summary": "", "doc": "", "evidence": []}
        if causes:
            k = causes[0]
            row["text"], row["doc"], row["summary"] = k["text"], k.get("doc", ""), cause_summary(k)
            for ev in k.get("evidence", []):
                v, note = quantity(ev["ours"], ctx)
                lo, hi = ev.get("expect", [-math.inf, math.inf])
                ok = None if v is None else (lo - 1e-12 <= v <= hi + 1e-12)
                row["evidence"].append({"label": ev["label"], "value": v, "unit": ev.get("unit", ""), "expect": ev.get("expect"), "ok": ok, "note": note})
            oks = [e["ok"] for e in row["evidence"]]
            row["status"] = CONTRADICTED if False in oks else NOT_MEASURED if (None in oks or not oks) else EXPLAINED
        out.append(row)
    return out


def _sig(v: Any) -> Any:
    """Three significant figures, no exponent for the magnitudes the causes use."""
    if v is None or not math.isfinite(v):
        return "-"
    if v == 0:
        return "0"
    digits = max(0, 2 - int(math.floor(math.log10(abs(v)))))
    return f"{v:.{digits}f}"


def evidence_text(e: Any) -> Any:
    """'label: 0.12 deg/cm (expected 0-0.2)' for the report and the terminal."""
    if e["value"] is None:
        return f"{e['label']}: not measured ({e['note']})"
    rng = ""
    if e["expect"]:
        lo, hi = e["expect"]
        rng = f" (argument needs {_sig(lo)} to {_sig(hi)})" if lo > -1e11 and hi < 1e11 else \
              f" (argument needs at least {_sig(lo)})" if hi >= 1e11 else f" (argument needs at most {_sig(hi)})"
    mark = "" if e["ok"] else " — CONTRADICTS"
    return f"{e['label']}: {_sig(e['value'])}{(' ' + e['unit']) if e['unit'] else ''}{rng}{mark}"
