"""The papers' published tables and claims, evaluated against our results by key.

- pair_table(): a published error table's rows beside the runs that reproduce them (by key).
- timing_ms(): our median time per cycle / frame for a "timings_ms" row.
- evaluate_claims(): the reproduction scorecard: for each claim in papers.json, our figure, the
  paper's, the ratio, and the verdict (holds / partly / does not / not run) computed by the rule
  written next to the claim in papers.json. The rules are data: "range" (the value, or for
  "ratio_to_published" ours / paper, lies in "holds" or "partly"), and "checks" (every check
  holds: holds; some: partly; none: does not).

A claim judged from runs of which some have no estimate (the statistic is null in summary.json: no
frame answered) is not judged on the others: its figure is "no estimate in k of n runs" and its
verdict "does not" (a localizer that does not answer does not reproduce an accuracy figure).
row_coverage() gives the coverage of the runs behind a claim (recall at the headline threshold,
share answered), which the scorecard shows before our figure.
"""
import json
import math
import pathlib
import re
import statistics

import global_start as G
import omniloc_results as R


GLOBAL_START = "(global start)"  # in a row's label: its localizer starts from an unknown pose


def row_key(papers, table, label):
    """(key, defaults, command) of one published or extra row of a table. A row labelled "(global
    start)" takes only runs that were not given the start pose (key "start_pose_given": false)."""
    rb = papers[table]["reproduced_by"]
    key = (rb.get("rows") or {}).get(label) or (rb.get("extra_rows") or {}).get(label)
    if key is None:
        raise KeyError(f"{table} has no row \"{label}\" (rows: {', '.join(list(rb.get('rows', {})) + list(rb.get('extra_rows', {})))})")
    if GLOBAL_START in label and "start_pose_given" not in key:
        key = dict(key, start_pose_given=False)
    return key, rb.get("config_defaults", {}), rb.get("command", "")


def runs_given(sel):
    """The start_pose_given the runs share (True / False), None when unknown or mixed."""
    vals = {r.start_pose_given for r in sel}
    return vals.pop() if len(vals) == 1 else None


def row_stats(runs, key, defaults, metrics, phase="tracking"):
    """Per metric path: R.run_stats over the matched runs (one value per run = seed; "no_value":
    runs where the statistic is null, no estimate)."""
    sel = R.select(runs, key, defaults)
    out = {}
    for m in metrics:
        out[m] = R.run_stats(sel, m, phase)
    return sel, out


COVERAGE_METRICS = ["valid_fraction"]  # with recall/<headline> (coverage_metrics)


def coverage_metrics(runs):
    """The coverage metrics a table of these runs shows before its errors: recall at the runs'
    headline threshold (when they record one) and the share of frames answered."""
    head = R.headline_key(runs)
    return ([f"recall/{head}"] if head else []) + COVERAGE_METRICS


def external_peers(runs, key, defaults, metrics):
    """The external localizers (summary.json localizer_type "external", docs/protocol.md) that ran
    a row's scenario and configuration: [{"name", "runs", "stats", "start_pose_given"}], by name
    and by whether the client was given the start pose (two rows when one name ran both ways).
    They pair by the same key with the localizer replaced by the client's name, whatever the row's
    start pose; pair_table decides which may sit beside the row."""
    names = sorted({r.localizer for r in runs if r.summary.get("localizer_type") == "external" and r.localizer != key.get("localizer")})
    peers = []
    base = {k: v for k, v in key.items() if k != "start_pose_given"}
    for name in names:
        everything = R.select(runs, dict(base, localizer=name), defaults)
        for given in sorted({r.start_pose_given for r in everything}, key=lambda g: (g is None, g is True)):
            sel = [r for r in everything if r.start_pose_given is given]
            st = {m: R.run_stats(sel, m) for m in metrics}
            peers.append({"name": name, "runs": sel, "stats": st, "start_pose_given": given,
                          "version": (sel[0].summary.get("external") or {}).get("version", "")})
    return peers


def place_peers(rows):
    """Every external peer under a row whose start pose it shares ("row": that row's label). A peer
    that shares no row's task on its scenario and configuration (a client given the start pose
    beside global-start rows, or one starting globally beside tracking rows) gets a row of its own,
    "<scenario / configuration> (given the start pose)" or "(global start)": never a row that ran
    the other task."""
    placed = set()  # (name, given, run folders) already beside a row that shares its task
    for p in rows:
        for q in p["peers"]:
            if R.start_pose_compatible(p["start_pose_given"], q["start_pose_given"]):
                placed.add((q["name"], q["start_pose_given"], tuple(str(r.folder) for r in q["runs"])))
    own = set()
    for p in rows:
        kept = []
        for q in p["peers"]:
            ident = (q["name"], q["start_pose_given"], tuple(str(r.folder) for r in q["runs"]))
            if R.start_pose_compatible(p["start_pose_given"], q["start_pose_given"]):
                kept.append(dict(q, row=p["shown"]))
            elif ident not in placed and ident not in own:
                own.add(ident)
                where = R.describe_key({k: v for k, v in p["key"].items() if k not in ("localizer", "start_pose_given")})
                kept.append(dict(q, row=f"{where} ({R.start_pose_text(q['start_pose_given'])})"))
        p["peers"] = kept


def shown_labels(rows):
    """A row's printed label: where a table holds rows given the start pose and rows that were not,
    those given it say "(given the start pose)" (global-start rows say so in papers.json already)."""
    kinds = {p["start_pose_given"] for p in rows} | {q["start_pose_given"] for p in rows for q in p["peers"]}
    both = True in kinds and False in kinds
    for p in rows:
        p["shown"] = p["label"] + (" (given the start pose)" if both and p["start_pose_given"] is True and GLOBAL_START not in p["label"] else "")


def pair_table(papers, table, runs, labels=None, include_extra=True):
    """Rows of a 9-column error table: [{"label", "shown", "published" (list or None), "runs", "stats"
    (per column), "key", "command", "start_pose_given", "peers"}], published rows first in the
    paper's order, then our extra rows; "peers" are the external localizers run on the row's
    scenario and configuration, each with the "row" label it is printed under (place_peers: never
    beside a row that ran the other start-pose task). "shown": the label to print (shown_labels)."""
    t = papers[table]
    rb = t["reproduced_by"]
    metrics = [f"{a}/{s}" for a, s in R.TABLE_KEYS] + coverage_metrics(runs)
    wanted = list(rb["rows"]) + (list(rb.get("extra_rows", {})) if include_extra else [])
    if labels:
        unknown = [l for l in labels if l not in wanted]
        if unknown:
            raise KeyError(f"{table} has no row {', '.join(repr(u) for u in unknown)}; its rows: {', '.join(repr(w) for w in wanted)}")
        wanted = [w for w in wanted if w in labels]
    rows = []
    for label in wanted:
        key, defaults, command = row_key(papers, table, label)
        sel, st = row_stats(runs, key, defaults, metrics + ["line_points/mean", "frames"])
        given = key.get("start_pose_given", runs_given(sel))
        rows.append({"label": label, "published": t["rows"].get(label) if label in rb["rows"] else None, "runs": sel, "stats": st,
                     "key": key, "command": command, "phased": any("tracking_phase" in (r.robot() or {}) for r in sel),
                     "start_pose_given": given if sel or "start_pose_given" in key else None,
                     "peers": external_peers(runs, key, defaults, metrics + ["line_points/mean", "frames"])})
    shown_labels(rows)
    place_peers(rows)
    return rows


def table_coverage(rows):
    """(metrics, headers) of the coverage columns a table shows before its errors: recall at the
    headline threshold and the share answered, each where some run of the table has it (none for
    runs made before they were scored)."""
    metrics, heads = [], []
    for p in rows:
        for st_of in [p["stats"]] + [q["stats"] for q in p["peers"]]:
            for m, st in st_of.items():
                if (m.startswith("recall/") or m == "valid_fraction") and st.get("of") and m not in metrics:
                    metrics.append(m)
    metrics.sort(key=lambda m: m == "valid_fraction")  # recall first
    for m in metrics:
        heads.append(f"within {R.recall_label(m.split('/', 1)[1])}" if m.startswith("recall/") else "answered")
    return metrics, heads


def row_cells(st, cov, runs):
    """One of our rows: coverage (percent over all frames), the nine errors over answered frames
    ("no estimate" where no run has one), line points, and the seeds with those that had no estimate."""
    note = R.no_value_note([st[f"{c}/{s}"] for c, s in R.TABLE_KEYS])
    return ([R.percent(st[m]["mean"]) if st.get(m) else "-" for m in cov] + [R.stat_cell(st[f"{c}/{s}"], 3) for c, s in R.TABLE_KEYS]
            + [R.stat_cell(st["line_points/mean"], 0), str(len(runs)) + (f"; {note}" if note else "")])


def timing_ms(papers, row, runs):
    """Median ms per cycle over the matched runs' timing.csv (stages summed per frame), filtered by
    the localizer's mode in frames.csv ("modes": only these; "modes_not": all but these). Returns
    (median or None, frames, runs)."""
    key = papers["timings_ms"]["reproduced_by"]["rows"][row]
    sel = R.select(runs, key)
    vals = []
    for r in sel:
        timing, frames = r.timing(), r.frames()
        for k, t in enumerate(timing):
            mode = frames[k]["mode"] if k < len(frames) else ""
            if "modes" in key and mode not in key["modes"]:
                continue
            if "modes_not" in key and mode in key["modes_not"]:
                continue
            vals.append(sum(float(t[s]) for s in key["stages"]))
    return (statistics.median(vals) if vals else None), len(vals), sel


class Context:
    def __init__(self, papers, runs, experiments):
        self.papers, self.runs = papers, runs
        self.experiments = {}
        for e in experiments:  # by name; the last one given wins (they are sorted)
            self.experiments[pathlib.Path(e).name] = pathlib.Path(e)
        self._json = {}

    def experiment_json(self, name, file):
        k = (name, file)
        if k not in self._json:
            d = self.experiments.get(name)
            f = d / file if d else None
            self._json[k] = json.loads(f.read_text()) if f and f.exists() else None
        return self._json[k]


def _row_runs(ctx, row):
    """(runs reproducing a published row [table, label], note): the note says why there are none."""
    try:
        key, defaults, command = row_key(ctx.papers, *row)
    except KeyError as e:
        return [], str(e)
    sel = R.select(ctx.runs, key, defaults)
    return sel, ("" if sel else f"not run: {command}")


def _number(v):
    """v as a float when it is a JSON number (not a bool), else None."""
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else None


def quantity(q, ctx):
    """(value or None, note) of a quantity selector of papers.json's claims."""
    if q is None:
        return None, "not reproducible here"
    if "ratio" in q or "fraction" in q:
        a, na = quantity((q.get("ratio") or q.get("fraction"))[0], ctx)
        b, nb = quantity((q.get("ratio") or q.get("fraction"))[1], ctx)
        if a is None or b is None:
            return None, na if a is None else nb
        if b == 0:
            return (math.inf if a > 0 else None), f"{R.fnum(a)} / 0"
        return a / b, f"{R.fnum(a)} / {R.fnum(b)}" + (f" ({na})" if na == nb and na else "")
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
            return None, R.no_estimate_text(no_value, len(sel))
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
        found, rows = R.pointer(j, q.get("list", ""))
        hit = [r for r in (rows if found and isinstance(rows, list) else []) if isinstance(r, dict) and all(r.get(k) == v for k, v in q["where"].items())]
        v = _number(hit[0].get(q["field"]) if hit else None)
        return (v, q["experiment"]) if v is not None else (None, f"{q['file']}{q.get('list', '')} has no {q['field']} where {q['where']}")
    if "experiment" in q:
        j = ctx.experiment_json(q["experiment"], q["file"])
        if j is None:
            return None, f"not run: build/omniloc experiment {q['experiment']}"
        found, v = R.pointer(j, q["pointer"])
        v = _number(v) if found else None
        return (v, q["experiment"]) if v is not None else (None, f"{q['file']}{q['pointer']} absent")
    if "global_start" in q:
        # Per-run judgement of a global-start row (scripts/global_start.py): success rate, error
        # while right, wrong frames; the statistic a mean over every frame hides (issue 29).
        sel, note = _row_runs(ctx, q["global_start"])
        if not sel:
            return None, note
        per_run = [G.score_run(r.frames()) for r in sel]
        if not any(p["frames"] for p in per_run):
            return None, f"no frames.csv in {len(sel)} run(s)"
        if not any(p["valid_frames"] for p in per_run):
            return None, R.no_estimate_text(len(sel), len(sel))
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


def evidence_seeds(q, ctx):
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


WEAK_TEXT = "(1 seed: weak evidence)"


def verdict_text(c):
    """A claim's verdict as printed: "holds", or "holds (1 seed: weak evidence)" when the verdict
    rests on one run or trial (evaluate_claims' "weak")."""
    return c["verdict"] + (f" {WEAK_TEXT}" if c.get("weak") else "")


def no_estimate(note):
    """Whether a quantity's note says its runs had no estimate (quantity() returns None then)."""
    return str(note or "").startswith(R.NO_ESTIMATE)


def judge(value, rule, published=None, note=None):
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


# What a claim is about, so that the scorecard counts them apart: four timing claims that hold by a
# factor of 100 on another CPU say nothing about accuracy. A claim may name its own "kind" in
# papers.json; otherwise: a timing quantity makes it "timing", these ids "robustness", the rest
# "accuracy".
KINDS = ("accuracy", "robustness", "timing")
ROBUSTNESS = {"occlusion_mild", "lighting_autoadjust", "kidnap_002", "kidnap_000", "entropy_peak"}

# The other axes of a published error-table row: a claim stated on mean x is judged on mean y and
# mean heading too, since the paper states them in the same row.
AXES = [("x_cm/mean", "x"), ("y_cm/mean", "y"), ("theta_rad/mean", "heading")]


def _has(q, key):
    """Whether a quantity selector (or any of its parts) uses `key` ("row", "timing", "experiment")."""
    if not isinstance(q, dict):
        return False
    if key in q or (key == "row" and "global_start" in q):
        return True
    parts = list(q.get("ratio") or q.get("fraction") or []) + list((q.get("vars") or {}).values())
    return any(_has(x, key) for x in parts)


def claim_kind(c):
    if c.get("kind") in KINDS:
        return c["kind"]
    qs = [c.get("ours")] + [ch.get("ours") for ch in c.get("checks", [])]
    if any(_has(q, "timing") for q in qs):
        return "timing"
    return "robustness" if c["id"] in ROBUSTNESS else "accuracy"


def uses_runs(c):
    """Whether a claim is judged from runs (which have a noise profile) rather than experiments."""
    qs = [c.get("ours")] + [ch.get("ours") for ch in c.get("checks", [])]
    return any(_has(q, "row") or _has(q, "timing") for q in qs)


def _published_cell(papers, row, metric):
    """The paper's number of a published error-table row for one metric (None for our extra rows)."""
    table, label = row
    t = papers.get(table) or {}
    values = (t.get("rows") or {}).get(label)
    if not isinstance(values, list):
        return None
    keys = [f"{a}/{s}" for a, s in R.TABLE_KEYS]
    return values[keys.index(metric)] if metric in keys else None


def _on_axis(q, metric):
    """The selector q with its mean-x metric replaced by `metric` (None when q is not all mean-x rows)."""
    if "row" in q:
        return dict(q, metric=metric) if q.get("metric") == "x_cm/mean" else None
    for k in ("ratio", "fraction"):
        if k in q:
            parts = [_on_axis(x, metric) for x in q[k]]
            return None if None in parts else {k: parts}
    return None


def _published_value(papers, q):
    """What the paper's own table gives for a selector (a row's cell or a ratio of cells)."""
    if "row" in q:
        return _published_cell(papers, q["row"], q["metric"])
    for k in ("ratio", "fraction"):
        if k in q:
            a, b = (_published_value(papers, x) for x in q[k])
            return a / b if a is not None and b else None
    return None


def axis_checks(papers, label, q, rule, published=None):
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
            notes.append(f"{axis} not judged: the paper's own value {R.fnum(pub, 2)} is outside the rule")
            continue
        checks.append({"label": f"{label}{axis}", "ours": qa, "rule": rule, "published": pub})
    return checks, notes


def _combine(verdicts):
    if any(v == "not run" for v in verdicts):
        return "not run"
    if all(v == "holds" for v in verdicts):
        return "holds"
    if any(v in ("holds", "partly") for v in verdicts):
        return "partly"
    return "does not"


def evaluate_claims(ctx):
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
            row["ours_text"] = "; ".join(f"{ch['label']}: " + (R.fnum(ch["ours"], 3) if ch["ours"] is not None or not no_estimate(ch["note"]) else ch["note"])
                                         + (f" ({R.fnum(ch['ratio'], 2)}x the paper's)" if ch["ratio"] is not None else "")
                                         + f" {ch['verdict']}" for ch in row["checks"])
            if all(ch["ours"] is None for ch in row["checks"]):  # nothing measured: say why once, not per axis
                row["ours_text"] = "; ".join(dict.fromkeys(ch["note"] for ch in row["checks"]))
            ratios = [ch["ratio"] for ch in row["checks"] if ch["ratio"] is not None]
            row["ratio"] = ratios[0] if len(ratios) == 1 else None
        else:
            v, note = quantity(c.get("ours"), ctx)
            row["ours"] = v
            row["ours_text"] = (R.fnum(v, 3) + (f" {row['unit']}" if row["unit"] not in ("x", "") else "") + (f" ({note})" if note else "")) if v is not None else note
            if isinstance(c.get("published"), (int, float)) and v is not None and c["published"]:
                row["ratio"] = v / c["published"]
            row["verdict"] = judge(v, c.get("rule"), c.get("published") if isinstance(c.get("published"), (int, float)) else None, note)
            row["seeds"] = evidence_seeds(c.get("ours"), ctx)
        if row["checks"]:
            counts = [ch["seeds"] for ch in row["checks"] if ch["seeds"] is not None]
            row["seeds"] = min(counts) if counts else None
        # A verdict that rests on one seed or trial is weak evidence, and says so (issue 38).
        row["weak"] = row["verdict"] in ("holds", "partly", "does not") and row["seeds"] == 1
        row["coverage"] = claim_coverage(c, ctx)
        out.append(row)
    return out


def claim_rows(q, out=None):
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


def row_coverage(ctx, row):
    """{"recall", "answered", "key", "runs", "no_value"} of the runs reproducing one published row:
    the mean over runs of the recall at their headline threshold and of the share of frames
    answered (tracking phase where a run has one); None where the row has no runs."""
    sel, _ = _row_runs(ctx, row)
    if not sel:
        return None
    key = R.headline_key(sel)
    rec = R.run_stats(sel, f"recall/{key}") if key else None
    ans = R.run_stats(sel, "valid_fraction")
    return {"key": key, "recall": rec["mean"] if rec else None, "answered": ans["mean"], "runs": len(sel),
            "no_value": R.run_stats(sel, "position_m/rmse")["no_value"]}


def claim_coverage(c, ctx):
    """[(row label, row_coverage)] of the rows a claim of papers.json is judged on ([] for claims
    judged from experiments or timings)."""
    out = []
    for row in claim_rows(c):
        cov = row_coverage(ctx, row)
        if cov is not None:
            out.append((row[1], cov))
    return out


def coverage_text(cov):
    """'within 25 cm / 10 deg 97.0 %, answered 100.0 %' for row_coverage() output, with the row's
    label where a claim reads several rows; '-' when nothing is known."""
    parts = []
    for label, c in cov or []:
        if c["key"] is None and c["answered"] is None:  # runs made before coverage was scored
            continue
        t = (f"within {R.recall_label(c['key'])} {R.percent(c['recall'])}, " if c["key"] else "") + f"answered {R.percent(c['answered'])}"
        if c["no_value"]:
            t += f" ({R.no_estimate_text(c['no_value'], c['runs'])})"
        parts.append((f"{label}: " if len(cov) > 1 else "") + t)
    return "; ".join(parts) if parts else "-"


def totals(claims):
    """{kind: {verdict: count}} over the claims, for the scorecard's summary and the terminal."""
    out = {k: {} for k in KINDS}
    for c in claims:
        d = out.setdefault(c["kind"], {})
        d[c["verdict"]] = d.get(c["verdict"], 0) + 1
    return out


def totals_text(t):
    """'accuracy: 3 holds, 1 partly; robustness: ...' (kinds without claims left out)."""
    order = ["holds", "partly", "does not", "not run", "n/a"]
    parts = []
    for kind in KINDS:
        d = t.get(kind) or {}
        if d:
            parts.append(f"{kind}: " + ", ".join(f"{d[v]} {v}" for v in order if d.get(v)))
    return "; ".join(parts)


# ---- causes: why a verdict is not "holds" (issue 29) ----------------------------------------------
# A claim in papers.json may carry "causes": [{"verdicts": [...], "profiles": [...], "text": ...,
# "doc": "docs/FILE.md#anchor", "evidence": [{"label", "ours": selector, "unit", "expect": [lo, hi]}]}].
# A cause is an argument that rests on measurements: each evidence item is a quantity read from the
# results given to the report, and "expect" is the range in which it supports the argument. So a cause
# whose numbers change under a later model says so ("evidence contradicts") instead of standing as text.

EXPLAINED, NOT_MEASURED, CONTRADICTED, UNEXPLAINED = "explained", "evidence not in these results", "evidence contradicts the cause", "no cause recorded"


def _applies(cause, verdict, profile):
    return verdict in cause.get("verdicts", ["partly", "does not"]) and profile in cause.get("profiles", ["robot", "field_robot"])


def explain(claims, ctx, profile="robot"):
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


def _sig(v):
    """Three significant figures, no exponent for the magnitudes the causes use."""
    if v is None or not math.isfinite(v):
        return "-"
    if v == 0:
        return "0"
    digits = max(0, 2 - int(math.floor(math.log10(abs(v)))))
    return f"{v:.{digits}f}"


def evidence_text(e):
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


# ---- reader's language: citations, readable labels, abbreviations (issue 38) -----------------------
# The report speaks to a researcher: papers by authors and year with a bibliography, claims and
# published tables by what they are (never their papers.json keys), abbreviations spelled out.

# The five papers, numbered as the report's bibliography numbers them. Venue and year as printed on
# the papers; where a paper's text does not print them, "note" says where they come from.
BIBLIOGRAPHY = [
    {"paper": "000", "short": "Xiong et al. 2012", "authors": "Dan Xiong, Huimin Lu, Zhiqiang Zheng",
     "title": "A self-localization method based on omnidirectional vision and MTi for soccer robots",
     "venue": "Proceedings of the 10th World Congress on Intelligent Control and Automation (WCICA), Beijing", "year": 2012,
     "note": "National University of Defense Technology, Changsha; bilingual (English and Chinese). The text prints neither venue nor year "
             "(its latest reference is from 2010): venue and year as we know them, not verified against the paper."},
    {"paper": "001", "short": "Xu et al. 2012", "authors": "Jiaming Xu, Lun Xie, Zhiliang Wang, Shanchao Ni",
     "title": "Target localization algorithm for cooperative multi-soccer robots based on Hough space",
     "venue": "Journal of Image and Graphics (Zhongguo Tuxiang Tuxing Xuebao) 17(6): 687-695", "year": 2012,
     "note": "University of Science and Technology Beijing; in Chinese."},
    {"paper": "002", "short": "Lu et al. 2013", "authors": "Huimin Lu, Xun Li, Hui Zhang, Mei Hu, Zhiqiang Zheng",
     "title": "Robust and real-time self-localization based on omnidirectional vision for soccer robots",
     "venue": "Advanced Robotics (doi:10.1080/01691864.2013.785473)", "year": 2013,
     "note": "National University of Defense Technology, Changsha (the NuBot team)."},
    {"paper": "003", "short": "Zhuang and Cao 2009", "authors": "Huimin Zhuang, Qixin Cao",
     "title": "Global localization of explorer based on visible landmarks",
     "venue": "Journal of Shanghai Jiao Tong University, no. 6, pp. 871-874", "year": 2009,
     "note": "Research Institute of Robotics, Shanghai Jiao Tong University; in Chinese."},
    {"paper": "004", "short": "Luo et al. 2012", "authors": "Jia-Ning Luo, Shu-Ying Chiang, Dong-Liang Li, Ching-Yi Chen, Kun-Yu Chen",
     "title": "Design of a positioning system module for omni-direction soccer robot",
     "venue": "conference paper, Department of Information and Telecommunications Engineering, Ming Chuan University (Taiwan)", "year": 2012,
     "note": "In Chinese. The text prints neither venue nor year: 2012 is inferred from its references (consulted in May 2012); "
             "author names romanised from the Chinese."},
]
_BIB = {b["paper"]: (k + 1, b) for k, b in enumerate(BIBLIOGRAPHY)}


def cite(paper):
    """'Lu et al. 2013 [3]' for a paper number ('002'); the number itself when unknown."""
    if paper not in _BIB:
        return f"paper {paper}"
    n, b = _BIB[paper]
    return f"{b['short']} [{n}]"


def cite_field(field):
    """A claim's "paper" field ('002 / 000', '002 refs [7], [8]') with each paper cited."""
    out = re.sub(r"\b(00[0-4])\b", lambda m: cite(m.group(1)), str(field))
    return out.replace("] refs [", "], its refs [")


_AUTHORS = r"[A-Z][a-z]+(?:(?:, | and | & )[A-Z][a-z]+)*(?: et al\.)?(?: \d{4})?"


def cite_text(text):
    """Prose with every 'paper 00N' (and 'Lu et al. 2013 (paper 002)', 'papers 002 and 000') made
    a citation of the bibliography."""
    text = str(text)
    if "aper" not in text:
        return text
    text = re.sub(_AUTHORS + r" \([Pp]aper (00[0-4])\)", lambda m: cite(m.group(1)), text)
    text = re.sub(r"\b[Pp]aper (00[0-4]) \(" + _AUTHORS + r"\)", lambda m: cite(m.group(1)), text)
    text = re.sub(r"\b[Pp]apers (00[0-4]) and (00[0-4])\b", lambda m: f"{cite(m.group(1))} and {cite(m.group(2))}", text)
    return re.sub(r"\b[Pp]aper (00[0-4])\b", lambda m: cite(m.group(1)), text)


# Each claim of papers.json by what it says (the report never shows its id).
CLAIM_LABELS = {
    "tracking_accuracy": "Tracking accuracy", "occlusion_mild": "Mild degradation under 50 % occlusion",
    "lighting_autoadjust": "Lighting: camera auto-adjustment", "kidnap_002": "Kidnap recovery (2 kidnaps)",
    "kidnap_000": "Kidnap recovery (5 kidnaps)", "mcl_alone": "MCL alone against matching",
    "weights_1_over_L": "1/L weights beat equal weights", "robots_flatten": "Error flattens at 3-5 robots",
    "mfbpf_vs_fbpf": "MFBPF below FBPF", "three_point_bounded": "Three-point stays bounded where two-circle explodes",
    "voting_bounded": "Voting keeps the error within 1 m", "entropy_peak": "Entropy peak moves in sun",
    "timing_mcl": "MCL time per cycle", "timing_matching": "Matching time per cycle", "timing_global": "Global localization time per frame",
    "timing_tracking": "Tracking time per frame", "real_cooperative": "Cooperation on real robots",
}


def claim_label(cid):
    return CLAIM_LABELS.get(cid, str(cid).replace("_", " "))


# The published tables and figures of papers.json (paper, what), for headings and captions.
TABLE_LABELS = {
    "002_table1_occlusion": ("002", "table 1: tracking error under occlusion"),
    "002_table2_lighting": ("002", "table 2: tracking error under changing light"),
    "000_tracking": ("000", "tracking error table"),
    "002_kidnapping": ("002", "kidnapping"), "000_kidnapping": ("000", "kidnapping"),
    "timings_ms": ("002 000", "time per cycle or frame"),
    "mcl_only_mean_position_error_cm": ("002", "other teams' MCL-only mean position error (its refs [7], [8])"),
    "001_cooperative_mean_error_mm": ("001", "cooperative ball localization: mean error, equal and 1/L weights"),
    "001_simulation_setup": ("001", "simulation set-up and error against the number of robots (fig. 10)"),
    "001_real_mean_error_cm": ("001", "real-robot ball error with and without cooperation"),
    "001_growth_model": ("001", "FBPF and MFBPF on the growth model"),
    "004_table1_cm": ("004", "table 1: two-circle and three-point fixes"),
    "003_simulation": ("003", "simulation with landmark groups and voting"),
}


def table_label(key):
    """'Lu et al. 2013 [3], table 1: tracking error under occlusion' for a papers.json key."""
    if key not in TABLE_LABELS:
        return str(key).replace("_", " ")
    papers, what = TABLE_LABELS[key]
    return " and ".join(cite(p) for p in papers.split()) + f", {what}"


# Rows of papers.json's "timings_ms" by what they time.
TIMING_LABELS = {"002_mcl": ("002", "MCL part per cycle"), "002_matching": ("002", "matching part per cycle"),
                 "000_global_per_frame": ("000", "global localization per frame"), "000_tracking_per_frame": ("000", "tracking per frame")}


def timing_label(row):
    paper, what = TIMING_LABELS.get(row, ("", str(row).replace("_", " ")))
    return f"{what} ({cite(paper)})" if paper else what


# Abbreviations the report uses, spelled out at their first use (Report.expand).
ABBREVIATIONS = {
    "MCL": "Monte Carlo localization", "RPROP": "resilient propagation, a gradient-sign optimiser",
    "MFBPF": "modified fission bootstrap particle filter", "FBPF": "fission bootstrap particle filter",
    "BPF": "bootstrap particle filter", "RMSE": "root mean square error", "MSL": "RoboCup Middle Size League",
    "MTi": "XSens inertial heading sensor", "E_k": "mean matching error of grid sample k",
    "N_th": "resampling threshold on the effective sample size", "N_eff": "effective sample size",
    "CDF": "cumulative distribution function",
}


def cause_summary(cause):
    """One sentence for the why-table: the cause's "summary" (causes.json), else its first sentence."""
    if cause.get("summary"):
        return cause["summary"]
    text = cause.get("text", "")
    m = re.match(r"(.+?[.;])(\s|$)", text)
    return m.group(1) if m else text
