"""The papers' published tables beside the runs that reproduce them, paired by key.

- pair_table(): a published error table's rows beside the runs that reproduce them (by key), with
  the external localizers run on the same scenario and configuration placed beside the rows of
  their own start-pose task.
- timing_ms(): our median time per cycle / frame for a "timings_ms" row.
- Context: the papers, runs and experiments a judgement reads.
"""
from __future__ import annotations

import json
import pathlib
import statistics
from typing import Any, Optional

from omniloc.core import metrics as M
from omniloc.core import pairing as PR
from omniloc.paper.data import COVERAGE_METRICS, GLOBAL_START
from omniloc.core.rundir import Run


def row_key(papers: dict[str, Any], table: str, label: str) -> Any:
    """(key, defaults, command) of one published or extra row of a table. A row labelled "(global
    start)" takes only runs that were not given the start pose (key "start_pose_given": false)."""
    rb = papers[table]["reproduced_by"]
    key = (rb.get("rows") or {}).get(label) or (rb.get("extra_rows") or {}).get(label)
    if key is None:
        raise KeyError(f"{table} has no row \"{label}\" (rows: {', '.join(list(rb.get('rows', {})) + list(rb.get('extra_rows', {})))})")
    if GLOBAL_START in label and "start_pose_given" not in key:
        key = dict(key, start_pose_given=False)
    return key, rb.get("config_defaults", {}), rb.get("command", "")


def runs_given(sel: list[Run]) -> Any:
    """The start_pose_given the runs share (True / False), None when unknown or mixed."""
    vals = {r.start_pose_given for r in sel}
    return vals.pop() if len(vals) == 1 else None


def row_stats(runs: list[Run], key: Any, defaults: Optional[dict[str, Any]], metrics: Any, phase: str = "tracking") -> Any:
    """Per metric path: M.run_stats over the matched runs (one value per run = seed; "no_value":
    runs where the statistic is null, no estimate)."""
    sel = PR.select(runs, key, defaults)
    out = {}
    for m in metrics:
        out[m] = M.run_stats(sel, m, phase)
    return sel, out


def coverage_metrics(runs: list[Run]) -> Any:
    """The coverage metrics a table of these runs shows before its errors: recall at the runs'
    headline threshold (when they record one) and the share of frames answered."""
    head = M.headline_key(runs)
    return ([f"recall/{head}"] if head else []) + COVERAGE_METRICS


def external_peers(runs: list[Run], key: Any, defaults: Optional[dict[str, Any]], metrics: Any) -> Any:
    """The external localizers (summary.json localizer_type "external", docs/protocol.md) that ran
    a row's scenario and configuration: [{"name", "runs", "stats", "start_pose_given"}], by name
    and by whether the client was given the start pose (two rows when one name ran both ways).
    They pair by the same key with the localizer replaced by the client's name, whatever the row's
    start pose; pair_table decides which may sit beside the row."""
    names = sorted({r.localizer for r in runs if r.summary.get("localizer_type") == "external" and r.localizer != key.get("localizer")})
    peers = []
    base = {k: v for k, v in key.items() if k != "start_pose_given"}
    for name in names:
        everything = PR.select(runs, dict(base, localizer=name), defaults)
        for given in sorted({r.start_pose_given for r in everything}, key=lambda g: (g is None, g is True)):
            sel = [r for r in everything if r.start_pose_given is given]
            st = {m: M.run_stats(sel, m) for m in metrics}
            peers.append({"name": name, "runs": sel, "stats": st, "start_pose_given": given,
                          "version": (sel[0].summary.get("external") or {}).get("version", "")})
    return peers


def place_peers(rows: Any) -> None:
    """Every external peer under a row whose start pose it shares ("row": that row's label). A peer
    that shares no row's task on its scenario and configuration (a client given the start pose
    beside global-start rows, or one starting globally beside tracking rows) gets a row of its own,
    "<scenario / configuration> (given the start pose)" or "(global start)": never a row that ran
    the other task."""
    placed = set()  # (name, given, run folders) already beside a row that shares its task
    for p in rows:
        for q in p["peers"]:
            if PR.start_pose_compatible(p["start_pose_given"], q["start_pose_given"]):
                placed.add((q["name"], q["start_pose_given"], tuple(str(r.folder) for r in q["runs"])))
    own = set()
    for p in rows:
        kept = []
        for q in p["peers"]:
            ident = (q["name"], q["start_pose_given"], tuple(str(r.folder) for r in q["runs"]))
            if PR.start_pose_compatible(p["start_pose_given"], q["start_pose_given"]):
                kept.append(dict(q, row=p["shown"]))
            elif ident not in placed and ident not in own:
                own.add(ident)
                where = PR.describe_key({k: v for k, v in p["key"].items() if k not in ("localizer", "start_pose_given")})
                kept.append(dict(q, row=f"{where} ({PR.start_pose_text(q['start_pose_given'])})"))
        p["peers"] = kept


def shown_labels(rows: Any) -> None:
    """A row's printed label: where a table holds rows given the start pose and rows that were not,
    those given it say "(given the start pose)" (global-start rows say so in papers.json already)."""
    kinds = {p["start_pose_given"] for p in rows} | {q["start_pose_given"] for p in rows for q in p["peers"]}
    both = True in kinds and False in kinds
    for p in rows:
        p["shown"] = p["label"] + (" (given the start pose)" if both and p["start_pose_given"] is True and GLOBAL_START not in p["label"] else "")


def pair_table(papers: dict[str, Any], table: str, runs: list[Run], labels: Any = None, include_extra: Any = True) -> Any:
    """Rows of a 9-column error table: [{"label", "shown", "published" (list or None), "runs", "stats"
    (per column), "key", "command", "start_pose_given", "peers"}], published rows first in the
    paper's order, then our extra rows; "peers" are the external localizers run on the row's
    scenario and configuration, each with the "row" label it is printed under (place_peers: never
    beside a row that ran the other start-pose task). "shown": the label to print (shown_labels)."""
    t = papers[table]
    rb = t["reproduced_by"]
    metrics = [f"{a}/{s}" for a, s in M.TABLE_KEYS] + coverage_metrics(runs)
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


def table_coverage(rows: Any) -> Any:
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
        heads.append(f"within {M.recall_label(m.split('/', 1)[1])}" if m.startswith("recall/") else "answered")
    return metrics, heads


def row_cells(st: Any, cov: Any, runs: list[Run]) -> Any:
    """One of our rows: coverage (percent over all frames), the nine errors over answered frames
    ("no estimate" where no run has one), line points, and the seeds with those that had no estimate."""
    note = M.no_value_note([st[f"{c}/{s}"] for c, s in M.TABLE_KEYS])
    return ([M.percent(st[m]["mean"]) if st.get(m) else "-" for m in cov] + [M.stat_cell(st[f"{c}/{s}"], 3) for c, s in M.TABLE_KEYS]
            + [M.stat_cell(st["line_points/mean"], 0), str(len(runs)) + (f"; {note}" if note else "")])


def timing_ms(papers: dict[str, Any], row: Any, runs: list[Run]) -> Any:
    """Median ms per cycle over the matched runs' timing.csv (stages summed per frame), filtered by
    the localizer's mode in frames.csv ("modes": only these; "modes_not": all but these). Returns
    (median or None, frames, runs)."""
    key = papers["timings_ms"]["reproduced_by"]["rows"][row]
    sel = PR.select(runs, key)
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
    def __init__(self, papers: dict[str, Any], runs: list[Run], experiments: list[Any]) -> None:
        self.papers, self.runs = papers, runs
        self.experiments = {}
        for e in experiments:  # by name; the last one given wins (they are sorted)
            self.experiments[pathlib.Path(e).name] = pathlib.Path(e)
        self._json: dict[Any, Any] = {}

    def experiment_json(self, name: str, file: Any) -> Any:
        k = (name, file)
        if k not in self._json:
            d = self.experiments.get(name)
            f = d / file if d else None
            self._json[k] = json.loads(f.read_text()) if f and f.exists() else None
        return self._json[k]
