"""The value of a quantity selector of papers.json's claims (a published row's runs, an experiment's
JSON, a global-start row judged per run, a timing, a ratio or formula of others) and how many seeds
it rests on.
"""
from __future__ import annotations

import math
from typing import Optional

from omniloc import global_start
from omniloc.core import metrics, pairing, rundir, stats
from omniloc.core.jsonvalue import JSON, lst, obj
from omniloc.core.rundir import Run
from omniloc.paper.tables import Context, row_key, timing_ms

# A quantity selector of papers.json's claims (raw JSON: {"row": [table, label], "metric": ...},
# {"ratio": [a, b]}, {"experiment", "file", "pointer"}, {"expr", "vars"}, {"timing": ...}, ...).
Selector = JSON


def row_runs(ctx: Context, row: JSON) -> tuple[list[Run], str]:
    """(runs reproducing a published row [table, label], note): the note says why there are none."""
    table, label = (str(x) for x in lst(row)[:2])
    try:
        key, defaults, command = row_key(ctx.papers, table, label)
    except KeyError as e:
        return [], str(e)
    sel = pairing.select(ctx.runs, key, defaults)
    return sel, ("" if sel else f"not run: {command}")


def as_float(v: JSON) -> Optional[float]:
    """v as a float when it is a JSON number (not a bool), else None."""
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else None


def parts_of(q: JSON) -> list[JSON]:
    """The two selectors of a "ratio" (or "fraction") selector."""
    sel = obj(q)
    return lst(sel.get("ratio") or sel.get("fraction"))


def quantity(selector: Selector, ctx: Context) -> tuple[Optional[float], str]:
    """(value or None, note) of a quantity selector of papers.json's claims."""
    if selector is None:
        return None, "not reproducible here"
    q = obj(selector)
    if "ratio" in q or "fraction" in q:
        a, na = quantity(parts_of(q)[0], ctx)
        b, nb = quantity(parts_of(q)[1], ctx)
        if a is None or b is None:
            return None, na if a is None else nb
        if b == 0:
            return (math.inf if a > 0 else None), f"{stats.fnum(a)} / 0"
        return a / b, f"{stats.fnum(a)} / {stats.fnum(b)}" + (f" ({na})" if na == nb and na else "")
    if "row" in q:
        sel, note = row_runs(ctx, q["row"])
        if not sel:
            return None, note
        names = [str(m) for m in q["metric"]] if isinstance(q["metric"], list) else [str(q["metric"])]
        phase = str(q.get("phase", "tracking"))
        per_run: list[float] = []
        no_value = 0
        for r in sel:
            looked = [r.lookup(m, phase) for m in names]
            if any(f and v is None for f, v in looked):  # null: no estimate in this run
                no_value += 1
                continue
            vals = [r.metric(m, phase) for m in names]
            nums = [v for v in vals if v is not None]
            if len(nums) == len(vals):
                per_run.append(sum(nums))
        if no_value:  # never judged on the runs that answered alone
            return None, metrics.no_estimate_text(no_value, len(sel))
        if not per_run:
            return None, f"{'+'.join(names)} absent in {len(sel)} run(s)"
        if q.get("sum"):
            return sum(per_run), f"n={len(per_run)}"
        return sum(per_run) / len(per_run), f"n={len(per_run)}"
    if "where" in q:
        # A row of a list in an experiment's JSON picked by its fields, e.g. the error budget's
        # {"source": "vibration", "localizer": "matching"}: robust to rows added or reordered.
        experiment, file = str(q["experiment"]), str(q["file"])
        j = ctx.experiment_json(experiment, file)
        if j is None:
            return None, f"not run: build/omniloc experiment {experiment}"
        found, rows = rundir.pointer(j, str(q.get("list", "")))
        where = obj(q["where"])
        hit = [r for r in (rows if found and isinstance(rows, list) else []) if isinstance(r, dict) and all(r.get(k) == v for k, v in where.items())]
        v = as_float(obj(hit[0]).get(str(q["field"])) if hit else None)
        return (v, experiment) if v is not None else (None, f"{q['file']}{q.get('list', '')} has no {q['field']} where {q['where']}")
    if "experiment" in q:
        experiment, file = str(q["experiment"]), str(q["file"])
        j = ctx.experiment_json(experiment, file)
        if j is None:
            return None, f"not run: build/omniloc experiment {experiment}"
        found, raw = rundir.pointer(j, str(q["pointer"]))
        v = as_float(raw) if found else None
        return (v, experiment) if v is not None else (None, f"{q['file']}{q['pointer']} absent")
    if "global_start" in q:
        # Per-run judgement of a global-start row (omniloc.global_start): success rate, error
        # while right, wrong frames; the statistic a mean over every frame hides.
        sel, note = row_runs(ctx, q["global_start"])
        if not sel:
            return None, note
        scores = [global_start.score_run(r.frames()) for r in sel]
        if not any(p.frames for p in scores):
            return None, f"no frames.csv in {len(sel)} run(s)"
        if not any(p.valid_frames for p in scores):
            return None, metrics.no_estimate_text(len(sel), len(sel))
        stat = global_start.summarise(scores).stat(str(q["stat"]))
        v = float(stat) if stat is not None else None
        return (v, f"n={len(sel)} runs, per run") if v is not None else (None, f"{q['stat']} undefined over {len(sel)} run(s)")
    if "expr" in q:
        # A formula over other quantities (names in "vars", math functions only), for evidence
        # such as a quadrature gap: written out in papers.json next to what it argues.
        values: dict[str, object] = {}
        notes: list[str] = []
        for name, sub in obj(q["vars"]).items():
            v, note = (float(sub), "") if isinstance(sub, (int, float)) else quantity(sub, ctx)
            if v is None:
                return None, note
            values[name] = v
            if note:
                notes.append(note)
        env: dict[str, object] = {k: getattr(math, k) for k in ("sqrt", "log", "exp", "pi", "atan2", "degrees", "radians", "hypot")}
        env.update(max=max, min=min, abs=abs)
        try:
            return float(eval(str(q["expr"]), {"__builtins__": {}}, dict(env, **values))), "; ".join(dict.fromkeys(notes))  # noqa: S307 (our own data file)
        except (ZeroDivisionError, ValueError) as e:
            return None, f"{q['expr']}: {e}"
    if "timing" in q:
        med, frames, sel = timing_ms(ctx.papers, str(lst(q["timing"])[1]), ctx.runs)
        if not sel:
            return None, f"not run: {obj(obj(ctx.papers['timings_ms'])['reproduced_by'])['command']}"
        return med, f"median of {frames} frames, {len(sel)} run(s)"
    raise ValueError(f"unknown quantity {q}")


def evidence_seeds(q: Selector, ctx: Context) -> Optional[int]:
    """How many runs (seeds) or trials the value of selector `q` rests on: for a row, a global-start
    row or a timing, the matched runs; for an experiment, its JSON's "seeds" (or "trials") where it
    records one; for ratios and formulas the fewest of their parts. None when unknown (an experiment
    that does not say) or nothing is measured."""
    if not isinstance(q, dict):
        return None
    parts = lst(q.get("ratio") or q.get("fraction") or []) + [v for v in obj(q.get("vars") or {}).values() if isinstance(v, dict)]
    if parts:
        counts = [n for n in (evidence_seeds(x, ctx) for x in parts) if n is not None]
        return min(counts) if counts else None
    if "row" in q or "global_start" in q:
        sel, _ = row_runs(ctx, q.get("row") or q["global_start"])
        return len(sel) or None
    if "timing" in q:
        _, _, sel = timing_ms(ctx.papers, str(lst(q["timing"])[1]), ctx.runs)
        return len(sel) or None
    if "experiment" in q:
        j = ctx.experiment_json(str(q["experiment"]), str(q["file"]))
        n = j.get("seeds", j.get("trials")) if isinstance(j, dict) else None
        return n if isinstance(n, int) and not isinstance(n, bool) and n > 0 else None
    return None
