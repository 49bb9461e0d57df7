"""The reproduction scorecard: every claim of papers.json with our figure, the paper's, the ratio and
the verdict, counted apart by kind, for the robot profile and the field_robot runs; and why each
claim that does not hold does not (its causes, with the evidence read from these results).
"""
from __future__ import annotations

import re
from typing import Optional, Sequence

from omniloc.core import pairing
from omniloc.core.jsonvalue import number
from omniloc.core.pairing import profile_of
from omniloc.core.rundir import Run
from omniloc.core.stats import fnum
from omniloc.core.verdicts import CONTRADICTED, EXPLAINED, NOT_MEASURED, UNEXPLAINED
from omniloc.paper import causes, claims, labels, tables
from omniloc.paper.causes import Cause
from omniloc.paper.claims import Claim
from omniloc.paper.data import KINDS
from omniloc.paper.tables import Context
from omniloc.report.provenance import machine_text
from omniloc.tools.markup import Cell, Writer

# What judge_claims gives: the claims for the robot profile, those for the field_robot runs by id
# (None without such runs), and the causes of every verdict other than holds.
Judged = tuple[list[Claim], Optional[dict[str, Claim]], list[Cause]]


KIND_TEXT = {"accuracy": "Accuracy", "robustness": "Robustness",
             "timing": "Timing (indicative: the papers' 1.66 GHz CPU against ours; not evidence of accuracy)"}


def field_robot_runs(runs: list[Run]) -> list[Run]:
    return [r for r in runs if profile_of(r) == "field_robot"]


def judge_claims(ctx: Context) -> Judged:
    """(claims, field_claims by id or None, causes): the verdicts for the robot profile and, where
    there are field_robot runs, for those by the same rules; with the causes of every verdict other
    than holds, each profile's evidence read from its own runs."""
    robot = claims.evaluate_claims(ctx)
    field = field_robot_runs(ctx.runs)
    field_claims: Optional[dict[str, Claim]] = None
    fctx: Optional[Context] = None
    if field:
        with pairing.pairing_profile("field_robot"):
            fctx = tables.Context(ctx.papers, field, [])
            fctx.experiments = ctx.experiments
            field_claims = {c.id: c for c in claims.evaluate_claims(fctx)}
    explained = causes.explain(robot, ctx, "robot")
    if field_claims and fctx is not None:
        with pairing.pairing_profile("field_robot"):  # the evidence of the field_robot verdicts is read from its own runs
            explained += causes.explain([field_claims[c.id] for c in robot if c.uses_runs], fctx, "field_robot")
    return robot, field_claims, explained


def scorecard(rep: Writer, ctx: Context, judged: Optional[Judged] = None) -> tuple[list[Claim], Optional[dict[str, Claim]], str]:
    """The papers' claims with our verdicts, counted apart by kind (accuracy / robustness / timing),
    for the robot profile and, in a column of their own by the same rules, the field_robot runs.
    judged: judge_claims(ctx) when the caller has it. Returns (claims, field_claims or None, totals
    text) for the summary and the terminal."""
    robot, field_claims, explained = judged or judge_claims(ctx)
    rep.heading("Reproduction scorecard", 2, "scorecard")
    totals = claims.totals_text(claims.totals(robot))
    ftotals = claims.totals_text(claims.totals([field_claims[c.id] for c in robot if c.uses_runs])) if field_claims else None
    rep.para(f"**Robot profile** — {totals}." + (f" **field_robot profile** (claims judged from runs) — {ftotals}." if ftotals else ""), "totals")
    rep.para("One line per published claim, grouped by what it is about. The verdict is computed by the rule written next to the "
             "claim in results/reference/papers.json; a claim stated on a row of a published error table is judged on every axis "
             "the paper states there (mean x, y and heading): all hold: holds, some: partly. Claims that do not hold stay "
             "visible, and no model is tuned to turn one.")
    # Coverage of the runs behind each claim first (recall at the headline threshold, share answered):
    # the papers' figures are errors over the frames answered. Results made before recall: no column.
    def cov(c: Claim) -> str:
        return claims.coverage_text(c.coverage)
    show_cov = any(cov(c) != "-" for c in robot)
    show_fcov = field_claims is not None and any(cov(f) != "-" for f in field_claims.values())
    if show_cov:
        rep.para("'Our runs' gives, for a claim judged from runs, the share of their frames within the headline threshold and the share "
                 "answered (docs/results.md, coverage and recall): our figure beside it is an error over the answered frames only; a claim "
                 "whose runs gave no estimate in some run is not judged on the others (does not).")
    for kind in KINDS:
        mine = [c for c in robot if c.kind == kind]
        if not mine:
            continue
        rows: list[list[Cell]] = []
        for c in mine:
            pub = c.published
            pub_text = (fnum(number(pub), 3) + ("" if c.unit in ("x", "", "recovered") else f" {c.unit}")) if isinstance(pub, (int, float)) else str(pub or "-")
            row: list[Cell] = [labels.cite_field(c.paper), c.claim, *([cov(c)] if show_cov else []),
                               c.ours_text + ("" if not c.notes else " (" + "; ".join(c.notes) + ")"), pub_text,
                               fnum(c.ratio, 2) if c.ratio is not None else "-", claims.verdict_text(c)]
            if field_claims is not None:
                f = field_claims[c.id]
                row += ([cov(f) if c.uses_runs else "-"] if show_fcov else []) + (
                    [f.ours_text.replace("sweeps/paper_suite.json", "sweeps/paper_suite_field_robot.json"), claims.verdict_text(f)]
                    if c.uses_runs else ["same as robot (experiment)", "-"])
            rows.append(row + [c.rule_text])
        header = ["paper", "claim"] + (["our runs: coverage"] if show_cov else []) + [
            "ours (robot profile)", "paper's", "ours / paper", "verdict"]
        if field_claims is not None:
            header += (["our runs: coverage (field_robot)"] if show_fcov else []) + ["ours (field_robot)", "verdict (field_robot)"]
        cap = f"{KIND_TEXT[kind]}: " + claims.totals_text({kind: claims.totals(mine)[kind]}).split(": ", 1)[1] + "."
        if kind == "timing":
            cap += f" Ours: median wall time on {machine_text()}."
        rep.table(header + ["rule"], rows, cap)
    causes_section(rep, robot, field_claims, explained)
    ctext = causes_totals(explained)
    return robot, field_claims, totals + (f" | field_robot: {ftotals}" if ftotals else "") + (f" | {ctext}" if ctext else "")


def causes_totals(explained: Sequence[Cause]) -> str:
    """'5 verdicts other than holds: 4 explained, 1 evidence not in these results' (empty without any)."""
    if not explained:
        return ""
    counts: dict[str, int] = {}
    for c in explained:
        counts[c.status] = counts.get(c.status, 0) + 1
    order = [EXPLAINED, NOT_MEASURED, CONTRADICTED, UNEXPLAINED]
    return f"{len(explained)} verdicts other than holds: " + ", ".join(f"{counts[k]} {k}" for k in order if counts.get(k))


def ratio_text(c: Optional[Claim]) -> str:
    """ours / paper of one claim, short: one ratio per axis the paper states ('x 0.34x, heading
    0.23x'), or the claim's ratio, or our figures; '-' when nothing was measured."""
    if c is None:
        return "-"
    rs = [(ch.label, ch.ratio) for ch in c.checks if ch.ratio is not None]
    if rs:
        return ", ".join(f"{re.sub(r'^mean ', '', l)} {fnum(r, 2)}x" for l, r in rs)
    if c.ratio is not None and c.ours is not None and isinstance(c.published, (int, float)):
        return f"{fnum(c.ours, 2)} / {fnum(c.published, 2)} = {fnum(c.ratio, 2)}x"
    # Runs that gave no estimate: say so, not '-' (which reads as "not measured").
    none = c.ours_text if claims.no_estimate(c.ours_text) else "-"
    if c.checks:
        return "; ".join(f"{ch.label}: {fnum(ch.ours, 3)}" for ch in c.checks if ch.ours is not None) or none
    return fnum(c.ours, 3) if c.ours is not None else none


def per_profile(values: dict[str, str]) -> str:
    """One text where both profiles agree, else 'robot: a; field_robot: b' ({profile: text})."""
    texts = [v for v in values.values() if v]
    if len(set(texts)) <= 1:
        return texts[0] if texts else "-"
    return "; ".join(f"{p}: {v}" for p, v in values.items() if v)


def causes_section(rep: Writer, robot: Sequence[Claim], field_claims: Optional[dict[str, Claim]], explained: Sequence[Cause]) -> None:
    """Why each claim that does not hold does not, as one table: a row per claim with its verdict
    per profile, ours / paper, and the cause in one sentence (results/reference/causes.json: written
    once where it holds for both profiles), whether its evidence, read from these results, bears it
    out; the full argument and the evidence collapsed below. A verdict without a cause, or whose
    evidence now says otherwise, is shown as such, never hidden."""
    if not explained:
        return
    rep.heading("Why a claim does not hold", 3, "causes")
    rep.para(causes_totals(explained) + ". A cause counts as explained only when every measurement it rests on is in these results and "
             "inside the range the argument needs (written next to the claim in results/reference/causes.json); the measurements are "
             "collapsed under the table. No model was tuned to turn a verdict.")
    by_claim: dict[str, dict[str, Cause]] = {}
    for k in explained:
        by_claim.setdefault(k.id, {})[k.profile] = k
    profiles = ["robot"] + (["field_robot"] if field_claims else [])
    header = ["claim", "paper"] + [f"verdict: {p}" for p in profiles] + ["ours / paper", "cause", "cause borne out by these results"]
    rows: list[list[Cell]] = []
    classes: list[str] = []
    for c in robot:
        ks = by_claim.get(c.id)
        if not ks:
            continue
        judged = {"robot": c}
        if field_claims and c.uses_runs:
            judged["field_robot"] = field_claims[c.id]
        verdicts = [claims.verdict_text(judged[p]) if p in judged else "same as robot (experiment)" for p in profiles]
        ratio = per_profile({p: ratio_text(judged[p]) for p in judged if judged[p].verdict not in ("not run", "n/a")})
        cause = per_profile({p: k.summary or "no cause recorded" for p, k in ks.items()})
        status = per_profile({p: k.status for p, k in ks.items()})
        rows.append([labels.claim_label(c.id), labels.cite_field(c.paper), *verdicts, ratio, cause, status])
        classes.append("" if all(k.status == EXPLAINED for k in ks.values()) else "outlier")
    rep.table(header, rows, "Claims whose verdict is not 'holds': one row per claim, its verdict under each noise profile.", classes)
    rep.details("The argument behind each cause and the measurements it rests on")
    for c in robot:
        ks = by_claim.get(c.id)
        if not ks:
            continue
        texts = {p: k.text for p, k in ks.items() if k.text}
        docs = sorted({k.doc for k in ks.values() if k.doc})
        argument = per_profile(texts) if texts else "No cause recorded."
        rep.para(f"**{labels.claim_label(c.id)}** ({labels.cite_field(c.paper)}). {argument}" + (f" Details: {', '.join(docs)}." if docs else ""))
        ev: list[list[Cell]] = [[p, causes.evidence_text(e)] for p, k in ks.items() for e in k.evidence]
        if ev:
            rep.table(["profile", "measured in these results (and the range the argument needs)"], ev)
    rep.end_details()
