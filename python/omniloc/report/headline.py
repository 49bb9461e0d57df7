"""The report's first words: two or three sentences computed from the results.
"""
from __future__ import annotations

import statistics
from typing import Optional, Sequence

from omniloc.core import metrics, pairing
from omniloc.core.jsonvalue import JSONObject
from omniloc.core.rundir import Run
from omniloc.core.stats import fnum
from omniloc.core.verdicts import EXPLAINED
from omniloc.paper import causes, labels, tables
from omniloc.paper.causes import Cause
from omniloc.paper.claims import Claim
from omniloc.paper.tables import Context
from omniloc.report import limit
from omniloc.report.scorecard import field_robot_runs, ratio_text
from omniloc.tools.markup import Writer


# The claim the headline names as the main gap: the first of these that does not hold, else the
# first accuracy claim that does not.
MAIN_GAP = ("tracking_accuracy", "occlusion_mild", "mcl_alone", "lighting_autoadjust", "kidnap_002", "kidnap_000")


def error_ratios(papers: JSONObject, runs: list[Run], used: Optional[list[Run]] = None) -> tuple[Optional[float], Optional[float], int]:
    """Ours / paper over the published error-table rows these runs reproduce (each set of runs
    once): (median over mean x and mean y, median over mean heading, rows). `used`, a list, receives
    the runs of those rows (for their coverage)."""
    pos: list[float]
    head: list[float]
    seen: set[tuple[str, ...]]
    pos, head, seen = [], [], set()
    keys = [f"{a}/{s}" for a, s in metrics.TABLE_KEYS]
    for table in ("002_table1_occlusion", "002_table2_lighting", "000_tracking"):
        for p in tables.pair_table(papers, table, runs, include_extra=False):
            ident = tuple(sorted(str(r.folder) for r in p.runs))
            if not p.runs or not p.published or ident in seen:
                continue
            seen.add(ident)
            if used is not None:
                used.extend(p.runs)
            pub = dict(zip(keys, p.published))
            for m, bucket in (("x_cm/mean", pos), ("y_cm/mean", pos), ("theta_rad/mean", head)):
                v = p.stats[m].mean
                if v is not None and pub.get(m):
                    bucket.append(v / pub[m])

    def med(v: list[float]) -> Optional[float]:
        return statistics.median(v) if v else None
    return med(pos), med(head), len(seen)


def coverage_sentence(runs: list[Run]) -> str:
    """'errors over the frames answered: those runs answered 100.0 % of their frames, 97.3 % within
    25 cm / 10 deg' (means over the runs; '' for runs made before coverage was scored)."""
    key = metrics.headline_key(runs)
    ans = metrics.run_stats(runs, "valid_fraction").mean
    rec = metrics.run_stats(runs, f"recall/{key}").mean if key else None
    if ans is None and rec is None:
        return ""
    return ("errors over the frames answered: those runs answered " + metrics.percent(ans) + " of their frames"
            + (f", {metrics.percent(rec)} within {metrics.recall_label(key)}" if rec is not None else ""))


def lower_first(label: str) -> str:
    return label if label[:2].isupper() or not label[:1].isalpha() else label[0].lower() + label[1:]


def headline(rep: Writer, ctx: Context, claims: Sequence[Claim], field_claims: Optional[dict[str, Claim]], explained: Sequence[Cause]) -> None:
    """Two or three sentences a researcher can quote, first after the title, all computed from the
    results: what reproduces and what does not, how our error compares with the papers', and the
    main gap with its measured cause."""
    judged = [c for c in claims if c.verdict in ("holds", "partly", "does not")]

    def names(cs: Sequence[Claim]) -> str:
        return ", ".join(lower_first(labels.claim_label(c.id)) for c in cs)
    parts = []
    if not judged:
        parts.append(f"None of the {len(claims)} published claims can be judged from these results: each needs runs or experiments "
                     "that are not among them (the scorecard names the command for each).")
    else:
        by = {v: [c for c in judged if c.verdict == v] for v in ("holds", "partly", "does not")}
        verb = {"holds": ("holds", "hold"), "partly": ("holds partly", "hold partly"), "does not": ("does not", "do not")}
        said = [f"{len(by[v])} {verb[v][len(by[v]) != 1]} ({names(by[v])})" for v in ("holds", "partly", "does not") if by[v]]
        rest = len(claims) - len(judged)
        s = (f"Of the {len(judged)} published claims these results judge (robot profile), " + (", ".join(said[:-1]) + " and " if len(said) > 1 else "")
             + said[-1] + (f"; {rest} more need runs or experiments not included here" if rest else "") + ".")
        if field_claims:
            fj = [f for f in field_claims.values() if f.verdict in ("holds", "partly", "does not")]
            if fj:
                cnt = {v: sum(f.verdict == v for f in fj) for v in ("holds", "partly", "does not")}
                s += (f" Under the field_robot profile (the camera blurred, defocused and tilted, its mirror decentred) {cnt['holds']} of "
                      f"{len(fj)} hold, {cnt['partly']} partly, {cnt['does not']} do not.")
        parts.append(s)
    used: list[Run] = []
    pos, head, n = error_ratios(ctx.papers, ctx.runs, used)
    if pos is not None and head is not None:
        s = (f"Our simulated tracking error is about {fnum(pos, 2)}x the papers' in position and {fnum(head, 2)}x in heading "
             f"(median of ours / paper over the {n} published error-table row{'s' if n != 1 else ''} we ran, robot profile")
        cov = coverage_sentence(used)
        if cov:
            s += f"; {cov}"
        field = field_robot_runs(ctx.runs)
        if field:
            with pairing.pairing_profile("field_robot"):
                fp, fh, fn = error_ratios(ctx.papers, field)
            if fp is not None and fh is not None:
                s += f"; field_robot: {fnum(fp, 2)}x and {fnum(fh, 2)}x over {fn} row{'s' if fn != 1 else ''}"
        parts.append(s + ").")
    failing = {c.id: c for c in judged if c.verdict != "holds"}
    gap = next((failing[i] for i in MAIN_GAP if i in failing), None) or next((c for c in judged if c.verdict != "holds" and c.kind == "accuracy"), None)
    if gap:
        k = next((k for k in explained if k.id == gap.id and k.profile == "robot"), None)
        s = f"The main gap is {lower_first(labels.claim_label(gap.id))} ({gap.verdict}; ours / paper: {ratio_text(gap)}). "
        if k and k.summary:
            measured = next((e for e in k.evidence if e.value is not None), None)
            s += "Cause: " + k.summary.rstrip(".") + "." + (f" Measured here: {causes.evidence_text(measured)}." if measured else "")
            if k.status != EXPLAINED:
                s += f" (Cause status: {k.status}.)"
        else:
            s += "no cause is recorded for it yet."
        parts.append(s)
    elif judged:
        parts.append("Every claim these results judge holds.")
    near = limit.headline_sentence(ctx.runs)  # results made before the bound: nothing
    if near:
        parts.append(near)
    reference = limit.reference_sentence(ctx.runs)
    if reference:
        parts.append(reference)
    rep.para("**In short.** " + " ".join(parts), "headline", "headline")
