"""The paper tables printed on the terminal (`omniloc paper-table`; the command's help says more).
"""
from __future__ import annotations

import json
import pathlib
import sys
from typing import Optional, Sequence

from omniloc.core import bound, metrics, pairing
from omniloc.core.jsonvalue import JSONObject, lst, obj
from omniloc.core.pairing import profile_of
from omniloc.core.rundir import Run
from omniloc.paper import tables
from omniloc.report import limit
from omniloc.report.published import command, published_tables
from omniloc.tools.markup import TextReport


SHORT = ["mean x", "mean y", "mean th", "std x", "std y", "std th", "max x", "max y", "max th"]


def error_tables(papers: JSONObject) -> list[str]:
    """The papers' error tables in their nine-column layout (the keys of papers.json)."""
    return [k for k, v in papers.items() if isinstance(v, dict) and "columns" in v and "reproduced_by" in v and isinstance(v.get("rows"), dict)
            and len(lst(v.get("columns", []))) == len(metrics.TABLE_KEYS)]


def choose_profile(runs: list[Run], wanted: Optional[str]) -> tuple[Optional[str], str]:
    """(profile, how it was chosen) or (None, error): robot where the runs have it, else their one profile."""
    have = sorted({profile_of(r) for r in runs})
    if wanted:
        return wanted, "--profile" + ("" if wanted in have else f"; no runs of it here (the runs have: {', '.join(have) or 'none'})")
    if not have or pairing.SCENARIO_DEFAULT_PROFILE in have:
        return pairing.SCENARIO_DEFAULT_PROFILE, "the default" + (f"; the runs also have {', '.join(p for p in have if p != 'robot')}: --profile picks one"
                                                           if len(have) > 1 else "")
    if len(have) == 1:
        return have[0], "read from the runs"
    return None, f"the runs have several noise profiles ({', '.join(have)}) and none is robot: name one with --profile"


def print_other_table(papers: JSONObject, key: str, runs: list[Run], experiments: Sequence[pathlib.Path], markdown: bool) -> int:
    """A kidnap, timing or experiment table, as the report shows it (omniloc.report's section
    functions, written as text): one implementation of each table."""
    ctx = tables.Context(papers, runs, experiments)
    anchor = "kidnapping" if key in ("002_kidnapping", "000_kidnapping") else key
    rep = TextReport(only=anchor, markdown=markdown)
    published_tables(rep, papers, ctx)
    if not rep.printed:  # a published record without a table of its own (e.g. real-robot numbers)
        t = papers[key]
        print(f"{key}: " + (json.dumps(t) if not isinstance(t, dict) else "; ".join(f"{k}: {v}" for k, v in t.items() if k != "reproduced_by")))
        print("not reproduced by a run or an experiment (see the report's scorecard)")
    print()
    return 0


def report_command(cmd: str) -> str:
    return command(cmd)  # under field_robot: the field_robot suite's command


def print_error_table(papers: JSONObject, key: str, runs: list[Run], labels: Optional[Sequence[str]], markdown: bool) -> int:
    try:
        rows = tables.pair_table(papers, key, runs, labels)
    except KeyError as e:
        print(f"error: {e.args[0]}", file=sys.stderr)
        return 2
    cov, cov_head = tables.table_coverage(rows)
    # How far our rows are from the accuracy limit, where their runs carry it (older runs: no column).
    bounded = limit.any_bound([r for p in rows for r in p.runs] + [r for p in rows for q in p.peers for r in q.runs])
    head = ["row", "source"] + cov_head + SHORT + ["line points / frame", "seeds"] + (["x the limit"] if bounded else [])

    def near(runs: list[Run]) -> list[str]:
        return [limit_cell(runs)] if bounded else []
    lines: list[list[str]] = []
    notes: list[str] = []
    for p in rows:
        st = p.stats
        if p.runs:
            lines.append([p.shown + (" (tracking phase)" if p.phased else ""), "omniloc"] + tables.row_cells(st, cov, p.runs) + near(p.runs))
        else:
            lines.append([p.label, "not run"] + ["-"] * (len(cov) + 9) + ["-", "0"] + (["-"] if bounded else []))
            notes.append(f"not run: {p.label} ({pairing.describe_key(p.key)}); run: {report_command(p.command)}")
        for peer in p.peers:  # external localizers (docs/protocol.md) on the same scenario, configuration and start pose
            lines.append([peer.row, f"external: {peer.name}"] + tables.row_cells(peer.stats, cov, peer.runs) + near(peer.runs))
        if p.published:
            lines.append([p.label, "paper"] + ["-"] * len(cov) + [f"{v:.3f}" for v in p.published] + ["-", "-"] + (["-"] if bounded else []))
            if p.runs:
                means = [st[f"{c}/{s}"].mean for c, s in metrics.TABLE_KEYS]
                lines.append([p.label, "ours/paper"] + [""] * len(cov) + [f"{m / v:.2f}" if v and m is not None else "-"
                                                                          for m, v in zip(means, p.published)] + ["", ""] + ([""] if bounded else []))
    if markdown:
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for l in lines:
            print("| " + " | ".join(l) + " |")
    else:
        w = [max(len(x[i]) for x in [head] + lines) for i in range(len(head))]
        for l in [head] + lines:
            print("  ".join(x.ljust(w[i]) if i < 2 else x.rjust(w[i]) for i, x in enumerate(l)))
    for n in notes:
        print(n)
    print(f"\nunits: x, y in cm, th in rad; paper: {obj(papers[key])['source']}"
          + ("; ours: errors over the frames answered, " + ", ".join(
              f"'{h}': share of all frames " + ("within that threshold (a frame without an estimate counts as outside)" if h != "answered" else "with an estimate")
              for h in cov_head) + ", means over seeds" if cov_head else "")
          + ("; 'x the limit': our position RMSE over the Cramer-Rao bound of the same frames (1x is the limit; posterior bound where "
             "the runs track), mean over seeds, with the mean share of frames the bound covers; 'no bound' where no run has one" if bounded else "")
          + "\n")
    return 0


def limit_cell(runs: list[Run]) -> str:
    """'1.32x (bound in 96 % of frames)' over a row's seeds; 'no bound' (in k of n runs) where runs have none."""
    eff = metrics.run_stats(runs, "efficiency/position")
    share = metrics.run_stats(runs, "efficiency/share")
    if not eff.of:
        return "-"
    if eff.mean is None:
        return bound.NO_BOUND
    note = f"; {metrics.no_estimate_text(eff.no_value, eff.of, 'efficiency/position')}" if eff.no_value else ""
    return f"{eff.mean:.2f}x ({bound.share_text(share.mean)}{note})"
