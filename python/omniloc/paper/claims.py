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

from typing import Any


from omniloc.core import metrics as M
from omniloc.core import stats as ST
from omniloc.paper.data import AXES, KINDS, ROBUSTNESS, WEAK_TEXT
from omniloc.paper.quantity import _row_runs, evidence_seeds, quantity
from omniloc.paper.tables import Context


def verdict_text(c: Any) -> Any:
    """A claim's verdict as printed: "holds", or "holds (1 seed: weak evidence)" when the verdict
    rests on one run or trial (evaluate_claims' "weak")."""
    return c["verdict"] + (f" {WEAK_TEXT}" if c.get("weak") else "")


def no_estimate(note: Any) -> Any:
    """Whether a quantity's note says its runs had no estimate (quantity() returns None then)."""
    return str(note or "").startswith(M.NO_ESTIMATE)


def judge(value: Any, rule: Any, published: Any = None, note: Any = None) -> Any:
    """The verdict of a value by a claim's rule: holds / partly / does not; "not run" without a
    value, except where the runs were made and gave no estimate (`note` says so): "does not"."""
    if rule is None:
        return "n/a"
    if value is None:
        return "does not" if no_estimate(note) else "not run"
    v = value / published if rule["kind"] == "ratio_to_published" else value
    inside = lambda iv: iv is not None and iv[0] - 1e-12 <= v <= iv[1] + 1e-12
    if inside(rule.get("holds")):
        return "holds"
    if inside(rule.get("partly")):
        return "partly"
    return "does not"


def _has(q: Any, key: Any) -> Any:
    """Whether a quantity selector (or any of its parts) uses `key` ("row", "timing", "experiment")."""
    if not isinstance(q, dict):
        return False
    if key in q or (key == "row" and "global_start" in q):
        return True
    parts = list(q.get("ratio") or q.get("fraction") or []) + list((q.get("vars") or {}).values())
    return any(_has(x, key) for x in parts)


def claim_kind(c: Any) -> Any:
    if c.get("kind") in KINDS:
        return c["kind"]
    qs = [c.get("ours")] + [ch.get("ours") for ch in c.get("checks", [])]
    if any(_has(q, "timing") for q in qs):
        return "timing"
    return "robustness" if c["id"] in ROBUSTNESS else "accuracy"


def uses_runs(c: Any) -> Any:
    """Whether a claim is judged from runs (which have a noise profile) rather than experiments."""
    qs = [c.get("ours")] + [ch.get("ours") for ch in c.get("checks", [])]
    return any(_has(q, "row") or _has(q, "timing") for q in qs)


def _published_cell(papers: dict[str, Any], row: Any, metric: Any) -> Any:
    """The paper's number of a published error-table row for one metric (None for our extra rows)."""
    table, label = row
    t = papers.get(table) or {}
    values = (t.get("rows") or {}).get(label)
    if not isinstance(values, list):
        return None
    keys = [f"{a}/{s}" for a, s in M.TABLE_KEYS]
    return values[keys.index(metric)] if metric in keys else None


def _on_axis(q: Any, metric: Any) -> Any:
    """The selector q with its mean-x metric replaced by `metric` (None when q is not all mean-x rows)."""
    if "row" in q:
        return dict(q, metric=metric) if q.get("metric") == "x_cm/mean" else None
    for k in ("ratio", "fraction"):
        if k in q:
            parts = [_on_axis(x, metric) for x in q[k]]
            return None if None in parts else {k: parts}
    return None


def _published_value(papers: dict[str, Any], q: Any) -> Any:
    """What the paper's own table gives for a selector (a row's cell or a ratio of cells)."""
    if "row" in q:
        return _published_cell(papers, q["row"], q["metric"])
    for k in ("ratio", "fraction"):
        if k in q:
            a, b = (_published_value(papers, x) for x in q[k])
            return a / b if a is not None and b else None
    return None


def axis_checks(papers: dict[str, Any], label: str, q: Any, rule: Any, published: Any = None) -> Any:
    """A check stated on mean x of published rows, split into one check per axis (x, y, heading)
    that the paper states. An axis is judged only where the paper's own numbers satisfy the rule
    (else the claim is not the paper's for that axis, and a note says so). Returns (checks, notes)
    or (None, None) when the selector is not of that form."""
    if _on_axis(q, "y_cm/mean") is None:
        return None, None
    checks, notes = [], []
    for metric, axis in AXES:
        qa = _on_axis(q, metric)
        pub = _published_value(papers, qa)
        if pub is None:
            return None, None
        if rule["kind"] == "ratio_to_published":
            checks.append({"label": f"{label}{axis}", "ours": qa, "rule": rule, "published": pub})
            continue
        if judge(pub, rule) != "holds":
            notes.append(f"{axis} not judged: the paper's own value {ST.fnum(pub, 2)} is outside the rule")
            continue
        checks.append({"label": f"{label}{axis}", "ours": qa, "rule": rule, "published": pub})
    return checks, notes


def _combine(verdicts: Any) -> Any:
    if any(v == "not run" for v in verdicts):
        return "not run"
    if all(v == "holds" for v in verdicts):
        return "holds"
    if any(v in ("holds", "partly") for v in verdicts):
        return "partly"
    return "does not"


def evaluate_claims(ctx: Context) -> Any:
    """One dict per claim: id, paper, kind, claim, ours (number or None), ours_text, published,
    ratio, verdict, rule_text, checks (for claims judged on several checks or axes), notes."""
    out = []
    for c in ctx.papers.get("claims", []):
        row = {"id": c["id"], "paper": c["paper"], "kind": claim_kind(c), "claim": c["claim"], "published": c.get("published"),
               "unit": c.get("unit", ""), "rule_text": c.get("rule_text", ""), "checks": [], "ratio": None, "notes": [],
               "uses_runs": uses_runs(c)}
        checks = [dict(ch) for ch in c.get("checks", [])]
        if not checks and c.get("ours") is not None and c.get("rule"):
            pub = c.get("published") if isinstance(c.get("published"), (int, float)) else None
            split, notes = axis_checks(ctx.papers, "mean ", c["ours"], c["rule"], pub)
            if split:
                checks, row["notes"] = split, notes
        elif checks:
            split_checks = []
            for ch in checks:
                split, notes = axis_checks(ctx.papers, ch["label"] + ": ", ch["ours"], ch["rule"])
                split_checks += split if split else [ch]
                row["notes"] += [f"{ch['label']}: {n}" for n in (notes or [])]
            checks = split_checks
        if checks:
            verdicts = []
            for ch in checks:
                v, note = quantity(ch["ours"], ctx)
                pub = ch.get("published") if ch["rule"]["kind"] == "ratio_to_published" else None
                verdict = judge(v, ch["rule"], pub, note)
                verdicts.append(verdict)
                ratio = v / pub if v is not None and pub else None
                row["checks"].append({"label": ch["label"], "ours": v, "note": note, "verdict": verdict, "ratio": ratio,
                                      "published": ch.get("published"), "seeds": evidence_seeds(ch["ours"], ctx)})
            row["verdict"] = _combine(verdicts)
            row["ours"] = None
            row["ours_text"] = "; ".join(f"{ch['label']}: " + (ST.fnum(ch["ours"], 3) if ch["ours"] is not None or not no_estimate(ch["note"]) else ch["note"])
                                         + (f" ({ST.fnum(ch['ratio'], 2)}x the paper's)" if ch["ratio"] is not None else "")
                                         + f" {ch['verdict']}" for ch in row["checks"])
            if all(ch["ours"] is None for ch in row["checks"]):  # nothing measured: say why once, not per axis
                row["ours_text"] = "; ".join(dict.fromkeys(ch["note"] for ch in row["checks"]))
            ratios = [ch["ratio"] for ch in row["checks"] if ch["ratio"] is not None]
            row["ratio"] = ratios[0] if len(ratios) == 1 else None
        else:
            v, note = quantity(c.get("ours"), ctx)
            row["ours"] = v
            row["ours_text"] = (ST.fnum(v, 3) + (f" {row['unit']}" if row["unit"] not in ("x", "") else "") + (f" ({note})" if note else "")) if v is not None else note
            if isinstance(c.get("published"), (int, float)) and v is not None and c["published"]:
                row["ratio"] = v / c["published"]
            row["verdict"] = judge(v, c.get("rule"), c.get("published") if isinstance(c.get("published"), (int, float)) else None, note)
            row["seeds"] = evidence_seeds(c.get("ours"), ctx)
        if row["checks"]:
            counts = [ch["seeds"] for ch in row["checks"] if ch["seeds"] is not None]
            row["seeds"] = min(counts) if counts else None
        # A verdict that rests on one seed or trial is weak evidence, and says so.
        row["weak"] = row["verdict"] in ("holds", "partly", "does not") and row["seeds"] == 1
        row["coverage"] = claim_coverage(c, ctx)
        out.append(row)
    return out


def claim_rows(q: Any, out: Any = None) -> Any:
    """The published rows [table, label] a quantity selector (or claim) reads runs of, in order."""
    out = [] if out is None else out
    if isinstance(q, dict):
        for k in ("row", "global_start"):
            if k in q and list(q[k]) not in out:
                out.append(list(q[k]))
        for x in list(q.get("ratio") or q.get("fraction") or []) + list((q.get("vars") or {}).values()):
            claim_rows(x, out)
        if "ours" in q:
            claim_rows(q["ours"], out)
        for ch in q.get("checks") or []:
            claim_rows(ch, out)
    return out


def row_coverage(ctx: Context, row: Any) -> Any:
    """{"recall", "answered", "key", "runs", "no_value"} of the runs reproducing one published row:
    the mean over runs of the recall at their headline threshold and of the share of frames
    answered (tracking phase where a run has one); None where the row has no runs."""
    sel, _ = _row_runs(ctx, row)
    if not sel:
        return None
    key = M.headline_key(sel)
    rec = M.run_stats(sel, f"recall/{key}") if key else None
    ans = M.run_stats(sel, "valid_fraction")
    return {"key": key, "recall": rec["mean"] if rec else None, "answered": ans["mean"], "runs": len(sel),
            "no_value": M.run_stats(sel, "position_m/rmse")["no_value"]}


def claim_coverage(c: Any, ctx: Context) -> Any:
    """[(row label, row_coverage)] of the rows a claim of papers.json is judged on ([] for claims
    judged from experiments or timings)."""
    out = []
    for row in claim_rows(c):
        cov = row_coverage(ctx, row)
        if cov is not None:
            out.append((row[1], cov))
    return out


def coverage_text(cov: Any) -> Any:
    """'within 25 cm / 10 deg 97.0 %, answered 100.0 %' for row_coverage() output, with the row's
    label where a claim reads several rows; '-' when nothing is known."""
    parts = []
    for label, c in cov or []:
        if c["key"] is None and c["answered"] is None:  # runs made before coverage was scored
            continue
        t = (f"within {M.recall_label(c['key'])} {M.percent(c['recall'])}, " if c["key"] else "") + f"answered {M.percent(c['answered'])}"
        if c["no_value"]:
            t += f" ({M.no_estimate_text(c['no_value'], c['runs'])})"
        parts.append((f"{label}: " if len(cov) > 1 else "") + t)
    return "; ".join(parts) if parts else "-"


def totals(claims: Any) -> Any:
    """{kind: {verdict: count}} over the claims, for the scorecard's summary and the terminal."""
    out: dict[str, dict[str, int]]
    out = {k: {} for k in KINDS}
    for c in claims:
        d = out.setdefault(c["kind"], {})
        d[c["verdict"]] = d.get(c["verdict"], 0) + 1
    return out


def totals_text(t: Any) -> Any:
    """'accuracy: 3 holds, 1 partly; robustness: ...' (kinds without claims left out)."""
    order = ["holds", "partly", "does not", "not run", "n/a"]
    parts = []
    for kind in KINDS:
        d = t.get(kind) or {}
        if d:
            parts.append(f"{kind}: " + ", ".join(f"{d[v]} {v}" for v in order if d.get(v)))
    return "; ".join(parts)
