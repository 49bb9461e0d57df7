"""The value of a quantity selector of papers.json's claims (a published row's runs, an experiment's
JSON, a global-start row judged per run, a timing, a ratio or formula of others) and how many seeds
it rests on.
"""
from __future__ import annotations

import math
from typing import Any

from omniloc import global_start as G
from omniloc.core import metrics as M
from omniloc.core import pairing as PR
from omniloc.core import rundir as RD
from omniloc.core import stats as ST
from omniloc.paper.tables import row_key, timing_ms
from omniloc.paper.tables import Context


def _row_runs(ctx: Context, row: Any) -> Any:
    """(runs reproducing a published row [table, label], note): the note says why there are none."""
    try:
        key, defaults, command = row_key(ctx.papers, *row)
    except KeyError as e:
        return [], str(e)
    sel = PR.select(ctx.runs, key, defaults)
    return sel, ("" if sel else f"not run: {command}")


def _number(v: Any) -> Any:
    """v as a float when it is a JSON number (not a bool), else None."""
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else None


def quantity(q: Any, ctx: Context) -> Any:
    """(value or None, note) of a quantity selector of papers.json's claims."""
    per_run: list[Any]
    vals: Any
    if q is None:
        return None, "not reproducible here"
    if "ratio" in q or "fraction" in q:
        a, na = quantity((q.get("ratio") or q.get("fraction"))[0], ctx)
        b, nb = quantity((q.get("ratio") or q.get("fraction"))[1], ctx)
        if a is None or b is None:
            return None, na if a is None else nb
        if b == 0:
            return (math.inf if a > 0 else None), f"{ST.fnum(a)} / 0"
        return a / b, f"{ST.fnum(a)} / {ST.fnum(b)}" + (f" ({na})" if na == nb and na else "")
    if "row" in q:
        sel, note = _row_runs(ctx, q["row"])
        if not sel:
            return None, note
        metrics = q["metric"] if isinstance(q["metric"], list) else [q["metric"]]
        per_run, no_value = [], 0
        for r in sel:
            found = [r.lookup(m, q.get("phase", "tracking")) for m in metrics]
            if any(f and v is None for f, v in found):  # null: no estimate in this run
                no_value += 1
                continue
            vals = [r.metric(m, q.get("phase", "tracking")) for m in metrics]
            per_run.append(None if any(v is None for v in vals) else sum(vals))
        if no_value:  # never judged on the runs that answered alone
            return None, M.no_estimate_text(no_value, len(sel))
        per_run = [v for v in per_run if v is not None]
        if not per_run:
            return None, f"{'+'.join(metrics)} absent in {len(sel)} run(s)"
        if q.get("sum"):
            return sum(per_run), f"n={len(per_run)}"
        return sum(per_run) / len(per_run), f"n={len(per_run)}"
    if "where" in q:
        # A row of a list in an experiment's JSON picked by its fields, e.g. the error budget's
        # {"source": "vibration", "localizer": "matching"}: robust to rows added or reordered.
        j = ctx.experiment_json(q["experiment"], q["file"])
        if j is None:
            return None, f"not run: build/omniloc experiment {q['experiment']}"
        found, rows = RD.pointer(j, q.get("list", ""))
        hit = [r for r in (rows if found and isinstance(rows, list) else []) if isinstance(r, dict) and all(r.get(k) == v for k, v in q["where"].items())]
        v = _number(hit[0].get(q["field"]) if hit else None)
        return (v, q["experiment"]) if v is not None else (None, f"{q['file']}{q.get('list', '')} has no {q['field']} where {q['where']}")
    if "experiment" in q:
        j = ctx.experiment_json(q["experiment"], q["file"])
        if j is None:
            return None, f"not run: build/omniloc experiment {q['experiment']}"
        found, v = RD.pointer(j, q["pointer"])
        v = _number(v) if found else None
        return (v, q["experiment"]) if v is not None else (None, f"{q['file']}{q['pointer']} absent")
    if "global_start" in q:
        # Per-run judgement of a global-start row (omniloc.global_start): success rate, error
        # while right, wrong frames; the statistic a mean over every frame hides.
        sel, note = _row_runs(ctx, q["global_start"])
        if not sel:
            return None, note
        per_run = [G.score_run(r.frames()) for r in sel]
        if not any(p["frames"] for p in per_run):
            return None, f"no frames.csv in {len(sel)} run(s)"
        if not any(p["valid_frames"] for p in per_run):
            return None, M.no_estimate_text(len(sel), len(sel))
        v = _number(G.summarise(per_run).get(q["stat"]))
        return (v, f"n={len(sel)} runs, per run") if v is not None else (None, f"{q['stat']} undefined over {len(sel)} run(s)")
    if "expr" in q:
        # A formula over other quantities (names in "vars", math functions only), for evidence
        # such as a quadrature gap: written out in papers.json next to what it argues.
        vals, notes = {}, []
        for name, sub in q["vars"].items():
            v, note = (float(sub), "") if isinstance(sub, (int, float)) else quantity(sub, ctx)
            if v is None:
                return None, note
            vals[name] = v
            if note:
                notes.append(note)
        env = {k: getattr(math, k) for k in ("sqrt", "log", "exp", "pi", "atan2", "degrees", "radians", "hypot")}
        env.update(max=max, min=min, abs=abs)
        try:
            return float(eval(q["expr"], {"__builtins__": {}}, dict(env, **vals))), "; ".join(dict.fromkeys(notes))  # noqa: S307 (our own data file)
        except (ZeroDivisionError, ValueError) as e:
            return None, f"{q['expr']}: {e}"
    if "timing" in q:
        med, frames, sel = timing_ms(ctx.papers, q["timing"][1], ctx.runs)
        if not sel:
            return None, f"not run: {ctx.papers['timings_ms']['reproduced_by']['command']}"
        return med, f"median of {frames} frames, {len(sel)} run(s)"
    raise ValueError(f"unknown quantity {q}")


def evidence_seeds(q: Any, ctx: Context) -> Any:
    """How many runs (seeds) or trials the value of selector `q` rests on: for a row, a global-start
    row or a timing, the matched runs; for an experiment, its JSON's "seeds" (or "trials") where it
    records one; for ratios and formulas the fewest of their parts. None when unknown (an experiment
    that does not say) or nothing is measured."""
    if not isinstance(q, dict):
        return None
    parts = list(q.get("ratio") or q.get("fraction") or []) + [v for v in (q.get("vars") or {}).values() if isinstance(v, dict)]
    if parts:
        counts = [n for n in (evidence_seeds(x, ctx) for x in parts) if n is not None]
        return min(counts) if counts else None
    if "row" in q or "global_start" in q:
        sel, _ = _row_runs(ctx, q.get("row") or q["global_start"])
        return len(sel) or None
    if "timing" in q:
        _, _, sel = timing_ms(ctx.papers, q["timing"][1], ctx.runs)
        return len(sel) or None
    if "experiment" in q:
        j = ctx.experiment_json(q["experiment"], q["file"])
        n = (j or {}).get("seeds", (j or {}).get("trials")) if isinstance(j, dict) else None
        return n if isinstance(n, int) and not isinstance(n, bool) and n > 0 else None
    return None
