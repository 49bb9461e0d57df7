"""Sections read from experiments (`omniloc experiment`): the published tables an experiment
reproduces, the error budget, and each experiment's own pictures and notes.
"""
from __future__ import annotations

import math
import pathlib
from typing import Optional

from omniloc.core import metrics, rundir, stats
from omniloc.core.files import read_csv
from omniloc.core.jsonvalue import JSON, JSONObject, load_file, lst, number, obj
from omniloc.core.stats import fnum
from omniloc.paper import claims, labels, quantity
from omniloc.paper.tables import Context
from omniloc.tools import plot
from omniloc.tools.markup import Cell, Writer


def experiment_section(rep: Writer, ctx: Context, key: str, title: str) -> tuple[JSONObject, JSON]:
    """Heading of a published table reproduced by an experiment; (table, the experiment's JSON or None)."""
    t = obj(ctx.papers[key])
    rb = obj(t["reproduced_by"])
    j = ctx.experiment_json(str(rb["experiment"]), str(rb["file"]))
    rep.heading(title, 3, key)
    if j is None:
        rep.para(f"Not run: {rb['command']}")
    return t, j


def at(value: JSON, ptr: JSON) -> Optional[float]:
    """The number at JSON pointer `ptr` of an experiment's JSON (None where there is none)."""
    return number(rundir.pointer(value, str(ptr))[1])


def experiment_tables(rep: Writer, papers: JSONObject, ctx: Context) -> None:
    # 001: equal vs 1/L weights.
    t, j = experiment_section(rep, ctx, "001_cooperative_mean_error_mm", "Paper 001: cooperative ball localisation, equal vs 1/L weights")
    rb = obj(t["reproduced_by"])
    rows: list[list[Cell]]
    if j is not None:
        eq, w = at(j, rb["equal_weights"]), at(j, rb["weighted"])
        pub_eq, pub_w = (math.nan if v is None else v for v in (number(t["equal_weights"]), number(t["weighted"])))
        rows = [["omniloc", fnum(eq, 1), fnum(w, 1), fnum(w / eq, 3) if eq and w is not None else "-", str(obj(obj(j).get("trials") or {}).get("path", "-"))],
                ["paper", fnum(pub_eq, 1), fnum(pub_w, 1), fnum(pub_w / pub_eq, 3), "-"],
                ["ours / paper", fnum(eq / pub_eq if eq is not None else None, 2), fnum(w / pub_w if w is not None else None, 2), "", ""]]
        rep.table(["source", "equal weights mm", "1/L weights mm", "1/L / equal", "trials"], rows,
                  "Published: results/reference/papers.json; ours from results/experiments/cooperative_001/cooperative_001.json (headline).",
                  ["", "paper", "ratio"])
    g = obj(obj(j).get("growth_model") or {})
    rep.heading("Paper 001: FBPF vs MFBPF on the growth model", 3, "001_growth_model")
    growth = obj(papers["001_growth_model"])
    if g:
        rows = [[k, fnum(number(v.get("mean")), 3), fnum(number(v.get("std")), 3), fnum(number(v.get("median")), 3)]
                for k, v in g.items() if isinstance(v, dict) and "std" in v]
        rep.table(["filter", "mean RMSE", "std", "median"], rows, f"paper: {growth['claim']} ({growth['setup']}); "
                  f"ours: {g.get('verdict', '')}")
    else:
        rep.para(f"Not run: {obj(growth['reproduced_by'])['command']}")
    rv = [obj(r) for r in lst(obj(j).get("robots_vs_error") or [])]
    rep.heading("Paper 001: error against the number of robots (fig. 10)", 3, "001_simulation_setup")
    setup = obj(papers["001_simulation_setup"])
    if rv:
        rep.table(["robots", "equal, all subsets mm", "1/L, all subsets mm", "1/L median mm"],
                  [[str(r["robots"]), fnum(number(r["equal_all_mm"]), 1), fnum(number(r["weighted_all_mm"]), 1), fnum(number(r["weighted_median_all_mm"]), 1)]
                   for r in rv],
                  f"paper: {setup['robots_vs_error']}")
        figures = [{k: number(r[k]) or 0.0 for k in ("robots", "equal_all_mm", "weighted_all_mm")} for r in rv]
        rep.figure(plot.robots_vs_error_figure(figures), "robots_vs_error", "paper 001 fig. 10 reproduced: mean ball error against the number of robots (all subsets)")
    else:
        rep.para(f"Not run: {obj(setup['reproduced_by'])['command']}")
    rep.para(f"{labels.table_label('001_real_mean_error_cm')} (8.6 -> 4.5 cm) needs real robots and is not reproduced.")

    # 004 table 1.
    t, j = experiment_section(rep, ctx, "004_table1_cm", "Paper 004 table 1: two-circle and three-point fixes (cm)")
    if j is not None:
        tab = obj((lst(obj(j).get("tables")) or [{}])[0])
        published_rows = lst(t["rows"])
        rows = []
        classes: list[str] = []
        for k, raw in enumerate(lst(tab.get("rows", []))):
            r = obj(raw)
            ours = obj(r.get("ours", {}))

            def err(solver: str) -> Optional[float]:
                return number(obj(ours.get(solver) or {}).get("mean_err_cm"))
            tc, tp = err("two_circle_004"), err("three_point_004")
            pub = lst(published_rows[k]) if k < len(published_rows) else None
            true_cm = lst(r["true_cm"])
            rows.append([f"({number(true_cm[0]):.0f}, {number(true_cm[1]):.0f})", "omniloc", fnum(tc, 2), fnum(tp, 2),
                         fnum(err("two_circle_eq8_literal"), 1), fnum(err("two_circle_eq9_literal"), 1)])
            classes.append("")
            if pub:
                p4, p7 = number(pub[4]), number(pub[7])
                rows.append(["", "paper", fnum(p4, 2), fnum(p7, 2), "", ""])
                classes.append("paper")
                rows.append(["", "ours / paper", fnum(tc / p4, 2) if tc is not None and p4 else "-", fnum(tp / p7, 2) if tp is not None and p7 else "-", "", ""])
                classes.append("ratio")
        rep.table(["true position", "source", "two-circle error", "three-point error", "eq. (8) as printed", "eq. (9) as printed"], rows,
                  f"mean error (cm) over {tab.get('trials', '-')} trials per position, bearing noise N(0, {tab.get('bearing_sigma_deg', '-')} deg); "
                  f"the last two columns evaluate paper 004's two-circle equations literally (diagnostic, see docs/landmarks.md); {tab.get('trend', '')}", classes)

    # 003 simulation.
    t, j = experiment_section(rep, ctx, "003_simulation", "Paper 003: landmark groups with voting (simulation)")
    if j is not None:
        rows = []
        for case, v in obj(j).items():
            s = v.get("all_paths") if isinstance(v, dict) else None
            if isinstance(s, dict) and s:
                rows.append([case.replace("_", " "), str(s.get("frames")), str(s.get("group_fixes")), fnum(number(s.get("fixes_max_m")), 2),
                             fnum(number(s.get("no_voting_mean_m")), 3), fnum(number(s.get("no_voting_max_m")), 2),
                             fnum(number(s.get("voting_mean_m")), 3), fnum(number(s.get("voting_max_m")), 2)])
        rep.table(["case", "frames", "group fixes", "worst fix m", "no voting: mean m", "max m", "voting: mean m", "max m"], rows,
                  f"paper: {t['source']}; max error after voting about {t['max_error_m_after_voting']} m")


def error_budget_section(rep: Writer, ctx: Context) -> None:
    """Table and bar chart of `omniloc experiment error_budget` (docs/error_budget.md)."""
    d = ctx.experiments.get("error_budget")
    f = d / "error_budget.json" if d else None
    if not f or not f.exists():
        return
    j = obj(load_file(f))
    rep.heading("Error budget: which source dominates", 2, "error_budget")
    rep.para(f"`omniloc experiment error_budget`{' --quick' if j.get('quick') else ''}: the tracking path for {j['duration_s']:.0f} s, "
             f"{j['seeds']} seed(s) from {j['first_seed']}; each row adds one error source to the baseline (ideal camera, exact odometry "
             "and compass, exact calibration map), the last rows put them all together. Position RMSE in cm (mean over seeds). "
             "`decentring` goes through the model-free calibration: compare it with `calibration map`.")
    rows_by_source: dict[str, dict[str, JSONObject]] = {}
    locs: list[str] = []
    for raw in lst(j["rows"]):
        r = obj(raw)
        loc = str(r["localizer"])
        rows_by_source.setdefault(str(r["source"]), {})[loc] = r
        if loc not in locs:
            locs.append(loc)

    def cell(r: JSONObject, key: str) -> str:
        """mean [95 % interval] over the seeds, or the mean alone for one seed or an old file."""
        if key not in r:
            return "failed" if key == "position_rmse_cm" else "-"
        if r[key] is None:  # over no answered frame: never a number
            return metrics.NO_ESTIMATE
        seeds = [obj(x).get(key) for x in lst(r.get("per_seed", []))]
        if len(seeds) < 2:
            return fnum(number(r[key]), 2)
        if any(v is None for v in seeds):
            return fnum(number(r[key]), 2) + f" ({metrics.no_estimate_text(sum(v is None for v in seeds), len(seeds))})"
        values = [number(v) for v in seeds]
        st = stats.stats(values)
        present = [v for v in values if v is not None]
        if present and st.mean is not None and max(present) - min(present) <= 1e-9 * max(1.0, abs(st.mean)):
            return f"{fnum(st.mean, 2)} (= every seed)"
        return stats.interval_text(st, 2)
    table: list[list[Cell]] = []
    for src, per in rows_by_source.items():
        line: list[Cell] = [src]
        for l in locs:
            r = per.get(l, {})
            line += [cell(r, "position_rmse_cm"), cell(r, "position_p50_cm"), cell(r, "heading_rmse_deg")]
        table.append(line)
    header = ["source"] + [f"{l} {m}" for l in locs for m in ("RMSE cm", "p50 cm", "heading RMSE deg")]
    seeds_text = (f"Mean over {j['seeds']} seeds; {stats.INTERVAL_RULE_TEXT}; "
                  "'= every seed' where every seed gave the same figure (the ideal baseline has no random source for "
                  "matching, so a row that adds a deterministic source is a systematic difference, not noise). ") if (number(j.get("seeds", 1)) or 0) > 1 else \
                 "One seed (quick mode): no interval; `omniloc experiment error_budget` runs three. "
    rep.table(header, table, seeds_text + f"Runs: {j['sweep']}; description: {j['config_file']}.")
    reference_error_text(rep, rows_by_source, ctx)
    rep.figure(plot.error_budget_figure(rows_by_source, locs), "error_budget", "Position RMSE of the tracking path with each error source alone and all together.")


def reference_error_text(rep: Writer, rows_by_source: dict[str, dict[str, JSONObject]], ctx: Context) -> None:
    """Which real-robot error the simulation lacks (docs/error_budget.md): the papers' heading error per
    cm of position error against every budget row's, and the reference wander the gap needs."""
    ratios = []
    for src, per in rows_by_source.items():
        r = per.get("matching", {})
        rmse, heading = number(r.get("position_rmse_cm")), r.get("heading_rmse_deg")
        if rmse and stats.is_number(heading):
            ratios.append((heading / rmse, src))
    if not ratios:
        return
    top, top_src = max(ratios)
    # The paper 000 / 002 tracking row, ours (robot profile: the pairing default) and published.
    row: list[JSON] = ["000_tracking", "tracking"]
    pub_x, pub_th = (math.nan if v is None else v for v in (claims.published_cell(ctx.papers, row, m) for m in ("x_cm/mean", "theta_rad/mean")))
    x, n_note = quantity.quantity({"row": row, "metric": "x_cm/mean"}, ctx)
    th, _ = quantity.quantity({"row": row, "metric": "theta_rad/mean"}, ctx)
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


def picture_order(p: pathlib.Path) -> str:
    # Before / after pairs in that order (alphabetically "after" would come first).
    return str(p).replace("_before", "_0before").replace("_after", "_1after")


# Tables of an experiment's markdown that a published-table section already shows (from the
# experiment's JSON): (text of the heading they stand under, that section's anchor).
SHOWN_ELSEWHERE: dict[str, list[tuple[str, str]]] = {
    "cooperative_001": [("Error against the number of robots", "001_simulation_setup"), ("Growth-model benchmark", "001_growth_model")],
    "error_budget": [("error_budget: which error source dominates", "error_budget")],
}


def identical_maps(exp: pathlib.Path) -> dict[str, list[str]]:
    """{solver: [solvers whose error map is the same cell for cell]} from an experiment's
    maps_004.csv (landmark_maps: the exact solvers are one estimator, so their heat maps are one
    picture under different titles). Empty without the file."""
    rows = read_csv(exp / "maps_004.csv") if (exp / "maps_004.csv").exists() else []
    cols = [k[:-len("_mean_err_cm")] for k in (rows[0] if rows else {}) if k.endswith("_mean_err_cm")]
    groups: dict[tuple[Optional[float], ...], list[str]] = {}
    for s in cols:
        try:
            vals = tuple(round(float(r[f"{s}_mean_err_cm"]), 3) if r[f"{s}_mean_err_cm"] != "nan" else None for r in rows)
        except ValueError:
            continue
        groups.setdefault(vals, []).append(s)
    return {g[0]: g for g in groups.values()}


def shown_elsewhere(exp: pathlib.Path) -> list[tuple[str, str]]:
    """SHOWN_ELSEWHERE, and for landmark_maps the noise level of paper 004's table 1 that the
    published-table section shows from table1_004.json."""
    skip = list(SHOWN_ELSEWHERE.get(exp.name, ()))
    f = exp / "table1_004.json"
    if f.exists():
        try:
            sigma = rundir.pointer(load_file(f), "/tables/0/bearing_sigma_deg")
            if not sigma[0]:
                raise KeyError("bearing_sigma_deg")
            skip.append((f"Bearing noise N(0, {sigma[1]:.1f} deg)", "004_table1_cm"))
        except (ValueError, KeyError, IndexError, TypeError):
            pass
    return skip


def report_experiment(rep: Writer, exp: pathlib.Path) -> None:
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
