"""The papers' published tables beside the runs that reproduce them, paired by key.

- pair_table(): a published error table's rows beside the runs that reproduce them (by key), with
  the external localizers run on the same scenario and configuration placed beside the rows of
  their own start-pose task.
- timing_ms(): our median time per cycle / frame for a "timings_ms" row.
- Context: the papers, runs and experiments a judgement reads.
- TableRow, Peer: a published row beside ours, and an external localizer beside it.
"""
from __future__ import annotations

import dataclasses
import pathlib
import statistics
from dataclasses import dataclass, field
from typing import Optional, Sequence

from omniloc.core import metrics, pairing
from omniloc.core.jsonvalue import JSON, JSONObject, flag, load_file, lst, numbers, obj
from omniloc.core.pairing import RowKey
from omniloc.core.rundir import Run
from omniloc.core.stats import SeedStats
from omniloc.paper.data import COVERAGE_METRICS, GLOBAL_START


@dataclass
class Peer:
    """An external localizer (docs/protocol.md) run on a row's scenario and configuration: its name
    (the client's), runs, statistics per metric, whether it was given the start pose, its version,
    and the label of the row it is printed under (place_peers)."""
    name: str
    runs: list[Run]
    stats: dict[str, SeedStats]
    start_pose_given: Optional[bool]
    version: JSON
    row: str = ""


@dataclass
class TableRow:
    """One row of a published error table beside ours (pair_table): its label and the label to print
    (shown), the paper's nine numbers (None for our extra rows), the runs that reproduce it and
    their statistics per metric (metrics.run_stats), its key, the command that runs it, whether its
    runs have a tracking phase, its start-pose task, and the external localizers beside it."""
    label: str
    published: Optional[list[float]]
    runs: list[Run]
    stats: dict[str, SeedStats]
    key: RowKey
    command: str
    phased: bool
    start_pose_given: Optional[bool]
    peers: list[Peer] = field(default_factory=list)
    shown: str = ""


def row_key(papers: JSONObject, table: str, label: str) -> tuple[RowKey, JSONObject, str]:
    """(key, defaults, command) of one published or extra row of a table. A row labelled "(global
    start)" takes only runs that were not given the start pose (key "start_pose_given": false)."""
    rb = obj(obj(papers[table])["reproduced_by"])
    found = obj(rb.get("rows")).get(label) or obj(rb.get("extra_rows")).get(label)
    if found is None:
        raise KeyError(f"{table} has no row \"{label}\" (rows: {', '.join(list(obj(rb.get('rows', {}))) + list(obj(rb.get('extra_rows', {}))))})")
    key = obj(found)
    if GLOBAL_START in label and "start_pose_given" not in key:
        key = dict(key, start_pose_given=False)
    return key, obj(rb.get("config_defaults", {})), str(rb.get("command", ""))


def runs_given(sel: list[Run]) -> Optional[bool]:
    """The start_pose_given the runs share (True / False), None when unknown or mixed."""
    vals = {r.start_pose_given for r in sel}
    return vals.pop() if len(vals) == 1 else None


def row_stats(runs: list[Run], key: RowKey, defaults: Optional[JSONObject], wanted: Sequence[str],
              phase: str = "tracking") -> tuple[list[Run], dict[str, SeedStats]]:
    """The runs that reproduce a row and, per metric path, metrics.run_stats over them (one value per
    run = seed; no_value: runs where the statistic is null, no estimate)."""
    sel = pairing.select(runs, key, defaults)
    out = {}
    for m in wanted:
        out[m] = metrics.run_stats(sel, m, phase)
    return sel, out


def coverage_metrics(runs: list[Run]) -> list[str]:
    """The coverage metrics a table of these runs shows before its errors: recall at the runs'
    headline threshold (when they record one) and the share of frames answered."""
    head = metrics.headline_key(runs)
    return ([f"recall/{head}"] if head else []) + COVERAGE_METRICS


def external_peers(runs: list[Run], key: RowKey, defaults: Optional[JSONObject], wanted: Sequence[str]) -> list[Peer]:
    """The external localizers (summary.json localizer_type "external", docs/protocol.md) that ran
    a row's scenario and configuration: [{"name", "runs", "stats", "start_pose_given"}], by name
    and by whether the client was given the start pose (two rows when one name ran both ways).
    They pair by the same key with the localizer replaced by the client's name, whatever the row's
    start pose; pair_table decides which may sit beside the row."""
    names = sorted({str(r.localizer) for r in runs if r.summary.localizer_type == "external" and r.localizer != key.get("localizer")})
    peers = []
    base = {k: v for k, v in key.items() if k != "start_pose_given"}
    for name in names:
        everything = pairing.select(runs, dict(base, localizer=name), defaults)
        for given in sorted({r.start_pose_given for r in everything}, key=lambda g: (g is None, g is True)):
            sel = [r for r in everything if r.start_pose_given is given]
            st = {m: metrics.run_stats(sel, m) for m in wanted}
            peers.append(Peer(name=name, runs=sel, stats=st, start_pose_given=given, version=sel[0].summary.external_version))
    return peers


def place_peers(rows: list[TableRow]) -> None:
    """Every external peer under a row whose start pose it shares ("row": that row's label). A peer
    that shares no row's task on its scenario and configuration (a client given the start pose
    beside global-start rows, or one starting globally beside tracking rows) gets a row of its own,
    "<scenario / configuration> (given the start pose)" or "(global start)": never a row that ran
    the other task."""
    placed = set()  # (name, given, run folders) already beside a row that shares its task
    for p in rows:
        for q in p.peers:
            if pairing.start_pose_compatible(p.start_pose_given, q.start_pose_given):
                placed.add((q.name, q.start_pose_given, tuple(str(r.folder) for r in q.runs)))
    own = set()
    for p in rows:
        kept = []
        for q in p.peers:
            ident = (q.name, q.start_pose_given, tuple(str(r.folder) for r in q.runs))
            if pairing.start_pose_compatible(p.start_pose_given, q.start_pose_given):
                kept.append(dataclasses.replace(q, row=p.shown))
            elif ident not in placed and ident not in own:
                own.add(ident)
                where = pairing.describe_key({k: v for k, v in p.key.items() if k not in ("localizer", "start_pose_given")})
                kept.append(dataclasses.replace(q, row=f"{where} ({pairing.start_pose_text(q.start_pose_given)})"))
        p.peers = kept


def shown_labels(rows: list[TableRow]) -> None:
    """A row's printed label: where a table holds rows given the start pose and rows that were not,
    those given it say "(given the start pose)" (global-start rows say so in papers.json already)."""
    kinds = {p.start_pose_given for p in rows} | {q.start_pose_given for p in rows for q in p.peers}
    both = True in kinds and False in kinds
    for p in rows:
        p.shown = p.label + (" (given the start pose)" if both and p.start_pose_given is True and GLOBAL_START not in p.label else "")


def pair_table(papers: JSONObject, table: str, runs: list[Run], labels: Optional[Sequence[str]] = None, include_extra: bool = True) -> list[TableRow]:
    """Rows of a 9-column error table, published rows first in the paper's order, then our extra
    rows; peers are the external localizers run on the row's scenario and configuration, each with
    the row label it is printed under (place_peers: never beside a row that ran the other start-pose
    task); shown: the label to print (shown_labels)."""
    t = obj(papers[table])
    rb = obj(t["reproduced_by"])
    published = obj(rb["rows"])
    wanted_metrics = [f"{a}/{s}" for a, s in metrics.TABLE_KEYS] + coverage_metrics(runs)
    wanted = list(published) + (list(obj(rb.get("extra_rows", {}))) if include_extra else [])
    if labels:
        unknown = [l for l in labels if l not in wanted]
        if unknown:
            raise KeyError(f"{table} has no row {', '.join(repr(u) for u in unknown)}; its rows: {', '.join(repr(w) for w in wanted)}")
        wanted = [w for w in wanted if w in labels]
    rows = []
    for label in wanted:
        key, defaults, command = row_key(papers, table, label)
        sel, st = row_stats(runs, key, defaults, wanted_metrics + ["line_points/mean", "frames"])
        given = flag(key["start_pose_given"]) if "start_pose_given" in key else runs_given(sel)
        paper = obj(t["rows"]).get(label) if label in published else None
        rows.append(TableRow(label=label, published=numbers(paper) if paper is not None else None, runs=sel, stats=st,
                             key=key, command=command, phased=any("tracking_phase" in (r.robot() or {}) for r in sel),
                             start_pose_given=given if sel or "start_pose_given" in key else None,
                             peers=external_peers(runs, key, defaults, wanted_metrics + ["line_points/mean", "frames"])))
    shown_labels(rows)
    place_peers(rows)
    return rows


def table_coverage(rows: list[TableRow]) -> tuple[list[str], list[str]]:
    """(metrics, headers) of the coverage columns a table shows before its errors: recall at the
    headline threshold and the share answered, each where some run of the table has it (none for
    runs made before they were scored)."""
    names: list[str] = []
    heads: list[str] = []
    for p in rows:
        for st_of in [p.stats] + [q.stats for q in p.peers]:
            for m, st in st_of.items():
                if (m.startswith("recall/") or m == "valid_fraction") and st.of and m not in names:
                    names.append(m)
    names.sort(key=lambda m: m == "valid_fraction")  # recall first
    for m in names:
        heads.append(f"within {metrics.recall_label(m.split('/', 1)[1])}" if m.startswith("recall/") else "answered")
    return names, heads


def row_cells(st: dict[str, SeedStats], cov: Sequence[str], runs: list[Run]) -> list[str]:
    """One of our rows: coverage (percent over all frames), the nine errors over answered frames
    ("no estimate" where no run has one), line points, and the seeds with those that had no estimate."""
    note = metrics.no_value_note([st[f"{c}/{s}"] for c, s in metrics.TABLE_KEYS])
    return ([metrics.percent(st[m].mean) if m in st else "-" for m in cov] + [metrics.stat_cell(st[f"{c}/{s}"], 3) for c, s in metrics.TABLE_KEYS]
            + [metrics.stat_cell(st["line_points/mean"], 0), str(len(runs)) + (f"; {note}" if note else "")])


def timing_ms(papers: JSONObject, row: str, runs: list[Run]) -> tuple[Optional[float], int, list[Run]]:
    """Median ms per cycle over the matched runs' timing.csv (stages summed per frame), filtered by
    the localizer's mode in frames.csv ("modes": only these; "modes_not": all but these). Returns
    (median or None, frames, runs)."""
    key = obj(obj(obj(obj(papers["timings_ms"])["reproduced_by"])["rows"])[row])
    sel = pairing.select(runs, key)
    modes, modes_not, stages = lst(key.get("modes")), lst(key.get("modes_not")), [str(s) for s in lst(key.get("stages"))]
    vals = []
    for r in sel:
        timing, frames = r.timing(), r.frames()
        for k, t in enumerate(timing):
            mode = frames[k]["mode"] if k < len(frames) else ""
            if "modes" in key and mode not in modes:
                continue
            if "modes_not" in key and mode in modes_not:
                continue
            vals.append(sum(float(t[s]) for s in stages))
    return (statistics.median(vals) if vals else None), len(vals), sel


class Context:
    """What a judgement reads: papers.json (with causes.json's causes), the runs, and the experiments'
    folders by name (their JSON read once, on demand)."""

    def __init__(self, papers: JSONObject, runs: list[Run], experiments: Sequence[pathlib.Path]) -> None:
        self.papers, self.runs = papers, runs
        self.experiments: dict[str, pathlib.Path] = {}
        for e in experiments:  # by name; the last one given wins (they are sorted)
            self.experiments[pathlib.Path(e).name] = pathlib.Path(e)
        self.json_cache: dict[tuple[str, str], JSON] = {}

    def experiment_json(self, name: str, file: str) -> JSON:
        """The experiment's JSON file `file` (parsed), None where the experiment or the file is missing."""
        k = (name, file)
        if k not in self.json_cache:
            d = self.experiments.get(name)
            f = d / file if d else None
            self.json_cache[k] = load_file(f) if f and f.exists() else None
        return self.json_cache[k]
