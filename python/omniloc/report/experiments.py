"""Sections read from experiments (`omniloc experiment`): the published tables an experiment
reproduces, the error budget, and each experiment's own pictures and notes.
"""
from __future__ import annotations

import json
import math
from typing import Any

from omniloc.core import metrics as M
from omniloc.core import rundir as RD
from omniloc.core import stats as ST
from omniloc.core.files import read_csv
from omniloc.core.stats import fnum
from omniloc.paper import claims as C
from omniloc.paper import labels as L
from omniloc.paper import quantity as Q
from omniloc.tools import plot
from omniloc.paper.tables import Context
from omniloc.tools.markup import Writer


def experiment_section(rep: Writer, ctx: Context, key: Any, title: str) -> Any:
    """Heading of a published table reproduced by an experiment; (table, the experiment's JSON or None)."""
    t = ctx.papers[key]
    rb = t["reproduced_by"]
    j = ctx.experiment_json(rb["experiment"], rb["file"])
    rep.heading(title, 3, key)
    if j is None:
        rep.para(f"Not run: {rb['command']}")
    return t, j


def experiment_tables(rep: Writer, papers: dict[str, Any], ctx: Context) -> None:
    # 001: equal vs 1/L weights.
    t, j = experiment_section(rep, ctx, "001_cooperative_mean_error_mm", "Paper 001: cooperative ball localisation, equal vs 1/L weights")
    rb = t["reproduced_by"]
    if j is not None:
        eq, w = RD.pointer(j, rb["equal_weights"])[1], RD.pointer(j, rb["weighted"])[1]
        rows = [["omniloc", fnum(eq, 1), fnum(w, 1), fnum(w / eq, 3) if eq else "-", (j.get("trials") or {}).get("path", "-")],
                ["paper", fnum(t["equal_weights"], 1), fnum(t["weighted"], 1), fnum(t["weighted"] / t["equal_weights"], 3), "-"],
                ["ours / paper", fnum(eq / t["equal_weights"], 2), fnum(w / t["weighted"], 2), "", ""]]
        rep.table(["source", "equal weights mm", "1/L weights mm", "1/L / equal", "trials"], rows,
                  "Published: results/reference/papers.json; ours from results/experiments/cooperative_001/cooperative_001.json (headline).",
                  ["", "paper", "ratio"])
    g = (j or {}).get("growth_model") or {}
    rep.heading("Paper 001: FBPF vs MFBPF on the growth model", 3, "001_growth_model")
    if g:
        rows = [[k, fnum(v.get("mean"), 3), fnum(v.get("std"), 3), fnum(v.get("median"), 3)] for k, v in g.items() if isinstance(v, dict) and "std" in v]
        rep.table(["filter", "mean RMSE", "std", "median"], rows, f"paper: {papers['001_growth_model']['claim']} ({papers['001_growth_model']['setup']}); "
                  f"ours: {g.get('verdict', '')}")
    else:
        rep.para(f"Not run: {papers['001_growth_model']['reproduced_by']['command']}")
    rv = (j or {}).get("robots_vs_error") or []
    rep.heading("Paper 001: error against the number of robots (fig. 10)", 3, "001_simulation_setup")
    if rv:
        rep.table(["robots", "equal, all subsets mm", "1/L, all subsets mm", "1/L median mm"],
                  [[r["robots"], fnum(r["equal_all_mm"], 1), fnum(r["weighted_all_mm"], 1), fnum(r["weighted_median_all_mm"], 1)] for r in rv],
                  f"paper: {papers['001_simulation_setup']['robots_vs_error']}")
        rep.figure(plot.robots_vs_error_figure(rv), "robots_vs_error", "paper 001 fig. 10 reproduced: mean ball error against the number of robots (all subsets)")
    else:
        rep.para(f"Not run: {papers['001_simulation_setup']['reproduced_by']['command']}")
    rep.para(f"{L.table_label('001_real_mean_error_cm')} (8.6 -> 4.5 cm) needs real robots and is not reproduced.")

    # 004 table 1.
    t, j = experiment_section(rep, ctx, "004_table1_cm", "Paper 004 table 1: two-circle and three-point fixes (cm)")
    if j is not None:
        tab = (j.get("tables") or [{}])[0]
        rows, classes = [], []
        for k, r in enumerate(tab.get("rows", [])):
            ours = r.get("ours", {})
            err = lambda solver: (ours.get(solver) or {}).get("mean_err_cm")
            tc, tp = err("two_circle_004"), err("three_point_004")
            pub = t["rows"][k] if k < len(t["rows"]) else None
            rows.append([f"({r['true_cm'][0]:.0f}, {r['true_cm'][1]:.0f})", "omniloc", fnum(tc, 2), fnum(tp, 2),
                         fnum(err("two_circle_eq8_literal"), 1), fnum(err("two_circle_eq9_literal"), 1)])
            classes.append("")
            if pub:
                rows.append(["", "paper", fnum(pub[4], 2), fnum(pub[7], 2), "", ""])
                classes.append("paper")
                rows.append(["", "ours / paper", fnum(tc / pub[4], 2) if tc is not None else "-", fnum(tp / pub[7], 2) if tp is not None else "-", "", ""])
                classes.append("ratio")
        rep.table(["true position", "source", "two-circle error", "three-point error", "eq. (8) as printed", "eq. (9) as printed"], rows,
                  f"mean error (cm) over {tab.get('trials', '-')} trials per position, bearing noise N(0, {tab.get('bearing_sigma_deg', '-')} deg); "
                  f"the last two columns evaluate paper 004's two-circle equations literally (diagnostic, see docs/landmarks.md); {tab.get('trend', '')}", classes)

    # 003 simulation.
    t, j = experiment_section(rep, ctx, "003_simulation", "Paper 003: landmark groups with voting (simulation)")
    if j is not None:
        rows = []
        for case, v in j.items():
            s = v.get("all_paths") if isinstance(v, dict) else None
            if s:
                rows.append([case.replace("_", " "), s.get("frames"), s.get("group_fixes"), fnum(s.get("fixes_max_m"), 2), fnum(s.get("no_voting_mean_m"), 3),
                             fnum(s.get("no_voting_max_m"), 2), fnum(s.get("voting_mean_m"), 3), fnum(s.get("voting_max_m"), 2)])
        rep.table(["case", "frames", "group fixes", "worst fix m", "no voting: mean m", "max m", "voting: mean m", "max m"], rows,
                  f"paper: {t['source']}; max error after voting about {t['max_error_m_after_voting']} m")


def error_budget_section(rep: Writer, ctx: Context) -> None:
    """Table and bar chart of `omniloc experiment error_budget` (docs/error_budget.md)."""
    d = ctx.experiments.get("error_budget")
    f = d / "error_budget.json" if d else None
    if not f or not f.exists():
        return
    j = json.loads(f.read_text())
    rep.heading("Error budget: which source dominates", 2, "error_budget")
    rep.para(f"`omniloc experiment error_budget`{' --quick' if j.get('quick') else ''}: the tracking path for {j['duration_s']:.0f} s, "
             f"{j['seeds']} seed(s) from {j['first_seed']}; each row adds one error source to the baseline (ideal camera, exact odometry "
             "and compass, exact calibration map), the last rows put them all together. Position RMSE in cm (mean over seeds). "
             "`decentring` goes through the model-free calibration: compare it with `calibration map`.")
    rows_by_source: dict[str, dict[str, dict[str, Any]]]
    locs: list[str]
    rows_by_source, locs = {}, []
    for r in j["rows"]:
        rows_by_source.setdefault(r["source"], {})[r["localizer"]] = r
        if r["localizer"] not in locs:
            locs.append(r["localizer"])
    def cell(r: Any, key: Any) -> Any:
        """mean [95 % interval] over the seeds, or the mean alone for one seed or an old file."""
        if key not in r:
            return "failed" if key == "position_rmse_cm" else "-"
        if r[key] is None:  # over no answered frame: never a number
            return M.NO_ESTIMATE
        seeds = [x.get(key) for x in r.get("per_seed", [])]
        if len(seeds) < 2:
            return fnum(r[key], 2)
        if any(v is None for v in seeds):
            return fnum(r[key], 2) + f" ({M.no_estimate_text(sum(v is None for v in seeds), len(seeds))})"
        st = ST.stats(seeds)
        if max(seeds) - min(seeds) <= 1e-9 * max(1.0, abs(st["mean"])):
            return f"{fnum(st['mean'], 2)} (= every seed)"
        return ST.interval_text(st, 2)
    table = []
    for src, per in rows_by_source.items():
        line = [src]
        for l in locs:
            r = per.get(l, {})
            line += [cell(r, "position_rmse_cm"), cell(r, "position_p50_cm"), cell(r, "heading_rmse_deg")]
        table.append(line)
    header = ["source"] + [f"{l} {m}" for l in locs for m in ("RMSE cm", "p50 cm", "heading RMSE deg")]
    seeds_text = (f"Mean over {j['seeds']} seeds; {ST.INTERVAL_RULE_TEXT}; "
                  "'= every seed' where every seed gave the same figure (the ideal baseline has no random source for "
                  "matching, so a row that adds a deterministic source is a systematic difference, not noise). ") if j.get("seeds", 1) > 1 else \
                 "One seed (quick mode): no interval; `omniloc experiment error_budget` runs three. "
    rep.table(header, table, seeds_text + f"Runs: {j['sweep']}; description: {j['config_file']}.")
    reference_error_text(rep, rows_by_source, ctx)
    rep.figure(plot.error_budget_figure(rows_by_source, locs), "error_budget", "Position RMSE of the tracking path with each error source alone and all together.")


def reference_error_text(rep: Writer, rows_by_source: Any, ctx: Context) -> None:
    """Which real-robot error the simulation lacks (docs/error_budget.md): the papers' heading error per
    cm of position error against every budget row's, and the reference wander the gap needs."""
    ratios = []
    for src, per in rows_by_source.items():
        r = per.get("matching", {})
        if r.get("position_rmse_cm") and ST.is_number(r.get("heading_rmse_deg")):
            ratios.append((r["heading_rmse_deg"] / r["position_rmse_cm"], src))
    if not ratios:
        return
    top, top_src = max(ratios)
    # The paper 000 / 002 tracking row, ours (robot profile: the pairing default) and published.
    row = ["000_tracking", "tracking"]
    pub_x, pub_th = (C._published_cell(ctx.papers, row, m) for m in ("x_cm/mean", "theta_rad/mean"))
    x, n_note = Q.quantity({"row": row, "metric": "x_cm/mean"}, ctx)
    th, _ = Q.quantity({"row": row, "metric": "theta_rad/mean"}, ctx)
    gap = ""
    if x is not None and th is not None:
        wx = math.sqrt(max(0.0, pub_x ** 2 - x ** 2) * math.pi / 2)
        wt = math.degrees(math.sqrt(max(0.0, pub_th ** 2 - th ** 2) * math.pi / 2))
        gap = (f" Our tracking row (robot profile, {n_note}) has mean x {fnum(x, 2)} cm and heading {fnum(math.degrees(th), 2)} deg "
               f"against the papers' {pub_x} cm and {fnum(math.degrees(pub_th), 2)} deg; in quadrature (Gaussian errors, sigma = mean x sqrt(pi/2)) "
               f"the difference needs a reference that wanders by about {fnum(wx, 1)} cm and yaws by about {fnum(wt, 1)} deg per axis. "
               "Those are the magnitudes of a person pushing a 0.5 m robot along a painted line (argued, not measured: no real robot here).")
    rep.para("**Which real-robot error is missing.** The papers scored a robot pushed by hand along straight tracks against "
             "those tracks (paper 002 sec. 6), so their reference itself errs; ours is exact. The papers' table has "
             f"{fnum(math.degrees(pub_th) / pub_x, 2)} deg of heading error per cm of position error; the most any row above gives with "
             f"matching is {fnum(top, 2)} deg/cm (`{top_src}`). Every simulated source moves heading and position together, so none of them, "
             "scaled up to the papers' position error, reaches the papers' heading error: an error of the reference, which has no such "
             f"link, is the missing one.{gap} See docs/error_budget.md.")


def picture_order(p: Any) -> Any:
    # Before / after pairs in that order (alphabetically "after" would come first).
    return str(p).replace("_before", "_0before").replace("_after", "_1after")


# Tables of an experiment's markdown that a published-table section already shows (from the
# experiment's JSON): (text of the heading they stand under, that section's anchor).
SHOWN_ELSEWHERE = {
    "cooperative_001": [("Error against the number of robots", "001_simulation_setup"), ("Growth-model benchmark", "001_growth_model")],
    "error_budget": [("error_budget: which error source dominates", "error_budget")],
}


def identical_maps(exp: Any) -> Any:
    """{solver: [solvers whose error map is the same cell for cell]} from an experiment's
    maps_004.csv (landmark_maps: the exact solvers are one estimator, so their heat maps are one
    picture under different titles). Empty without the file."""
    rows = read_csv(exp / "maps_004.csv") if (exp / "maps_004.csv").exists() else []
    cols = [k[:-len("_mean_err_cm")] for k in (rows[0] if rows else {}) if k.endswith("_mean_err_cm")]
    groups: dict[Any, Any] = {}
    for s in cols:
        try:
            vals = tuple(round(float(r[f"{s}_mean_err_cm"]), 3) if r[f"{s}_mean_err_cm"] != "nan" else None for r in rows)
        except ValueError:
            continue
        groups.setdefault(vals, []).append(s)
    return {g[0]: g for g in groups.values()}


def shown_elsewhere(exp: Any) -> Any:
    """SHOWN_ELSEWHERE, and for landmark_maps the noise level of paper 004's table 1 that the
    published-table section shows from table1_004.json."""
    skip = list(SHOWN_ELSEWHERE.get(exp.name, ()))
    f = exp / "table1_004.json"
    if f.exists():
        try:
            sigma = json.loads(f.read_text())["tables"][0]["bearing_sigma_deg"]
            skip.append((f"Bearing noise N(0, {sigma:.1f} deg)", "004_table1_cm"))
        except (ValueError, KeyError, IndexError, TypeError):
            pass
    return skip


def report_experiment(rep: Writer, exp: Any) -> None:
    rep.heading(f"Experiment {exp.name}", 2)
    pngs = sorted(exp.glob("*.png"), key=picture_order)
    same = identical_maps(exp)
    hidden = {f"map_{s}.png" for g in same.values() for s in g[1:]}
    for png in pngs:
        if png.name in hidden:
            continue
        twins: list[str]
        twins = next((g for g in same.values() if png.name == f"map_{g[0]}.png"), [])
        rep.image(png, f"{exp.name}: `{png.name}`" + (
            f"; the maps of {', '.join(f'`{s}`' for s in twins[1:])} are identical to it, cell for cell (maps_004.csv), and are not shown"
            if len(twins) > 1 else ""))
    mds = sorted(exp.glob("*.md"))
    if mds:  # the experiment's own notes and tables, long: collapsed
        rep.details(f"{exp.name}: the experiment's notes and tables ({', '.join(m.name for m in mds)})")
        rep.raw_html("<div class='quoted'>")  # the experiment's own output, quoted as it wrote it
        for md in mds:
            rep.markdown(md.read_text(), skip=shown_elsewhere(exp))
        rep.raw_html("</div>")
        rep.end_details()
