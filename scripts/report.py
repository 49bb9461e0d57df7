#!/usr/bin/env python3
"""Comparison report of omniloc results: report.md and a self-contained report.html.

usage: report.py RESULTS... -o DIR [--title TEXT] [--max-runs N] [--baseline RESULTS] [--history DIR]

RESULTS are folders: a run (summary.json), a sweep (aggregate.json with runs/ inside), an
experiment (PNG / JSON / markdown files written by `omniloc experiment`), or any folder holding
such folders (searched recursively). The report shows, in this order:
  - provenance: which omniloc builds (git describe, compiler, build type) made the results;
  - the reproduction scorecard: every claim of results/reference/papers.json with our figure, the
    paper's, the ratio and the verdict computed by the rule written next to the claim;
  - every published table beside the runs that reproduce it, paired BY KEY (scenario, localizer,
    configuration values; scripts/omniloc_results.py), never by position; a row whose runs are
    missing says "not run" and prints the command that runs it;
  - with --baseline: our metrics against another result set (e.g. another commit), per metric
    with the difference and Welch's t-test over seeds (scripts/compare.py);
  - every sweep's aggregate and every run's error table (headings carry the swept parameters,
    in the aggregate's order), trajectory plots over the field, position and heading error over
    time with the events marked, error CDFs, timing per stage;
  - every experiment's tables (as HTML tables) and pictures;
  - with --history DIR (default results/history when it exists): instruction counts
    (scripts/icount.sh, icount.jsonl) and benchmark wall times (scripts/bench.sh, bench.jsonl)
    per workload over the commits that were measured.
Everything except the published numbers is read from the result files. Needs Python 3 and
Debian's python3-matplotlib (no PyPI).
"""
import argparse
import base64
import html
import json
import math
import os
import pathlib
import platform
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import omniloc_results as R  # noqa: E402
import paper_claims as C  # noqa: E402

EVENT_COLOURS = {"kidnap": "red", "cover": "black", "teleport": "red", "occlude": "grey", "lights": "orange", "camera": "purple"}
VERDICT_CLASS = {"holds": "ok", "partly": "partly", "does not": "no", "not run": "notrun", "n/a": "notrun"}
fnum = R.fnum


def numeric_class(cell):
    """Numbers right-aligned, text left-aligned."""
    try:
        float(str(cell).split(" ")[0])
        return " class='num'"
    except ValueError:
        return ""


class Report:
    def __init__(self, out, title):
        self.out = pathlib.Path(out)
        (self.out / "img").mkdir(parents=True, exist_ok=True)
        for old in (self.out / "img").glob("*.png"):  # pictures of an earlier report in the same folder
            old.unlink()
        self.md = [f"# {title}", ""]
        self.html = []
        self.n_img = 0
        self.title = title

    def heading(self, text, level=2, anchor=None):
        self.md += ["#" * level + " " + text, ""]
        a = f' id="{html.escape(anchor)}"' if anchor else ""
        self.html.append(f"<h{level}{a}>{html.escape(text)}</h{level}>")

    def para(self, text, cls=None):
        self.md += [text, ""]
        c = f' class="{cls}"' if cls else ""
        self.html.append(f"<p{c}>{html.escape(text)}</p>")

    def table(self, header, rows, caption=None, row_classes=None):
        """rows: lists of cells; row_classes: one CSS class per row (e.g. "paper" for published rows)."""
        if caption:
            self.para(caption, "caption")
        self.md.append("| " + " | ".join(header) + " |")
        self.md.append("|" + "|".join("---" for _ in header) + "|")
        for k, r in enumerate(rows):
            cells = [str(c) for c in r]
            if row_classes and row_classes[k] == "paper":
                cells = [f"*{c}*" if c not in ("", "-") else c for c in cells]
            self.md.append("| " + " | ".join(cells) + " |")
        self.md.append("")
        h = "<div class='scroll'><table><tr>" + "".join(f"<th>{html.escape(str(c))}</th>" for c in header) + "</tr>"
        for k, r in enumerate(rows):
            cls = row_classes[k] if row_classes and row_classes[k] else ""
            h += (f"<tr class='{cls}'>" if cls else "<tr>") + "".join(f"<td{numeric_class(c)}>{html.escape(str(c))}</td>" for c in r) + "</tr>"
        self.html.append(h + "</table></div>")

    def markdown(self, text):
        """An experiment's markdown: headings, paragraphs and pipe tables as real HTML."""
        self.md += [text, ""]
        lines = text.splitlines()
        i, para = 0, []

        def flush():
            if para:
                self.html.append("<p>" + html.escape(" ".join(para)) + "</p>")
                para.clear()
        while i < len(lines):
            ln = lines[i].rstrip()
            if ln.startswith("#"):
                flush()
                level = min(6, len(ln) - len(ln.lstrip("#")) + 2)
                self.html.append(f"<h{level}>{html.escape(ln.lstrip('#').strip())}</h{level}>")
            elif ln.startswith("|"):
                flush()
                rows = []
                while i < len(lines) and lines[i].strip().startswith("|"):
                    cells = [c.strip() for c in lines[i].strip().strip("|").split("|")]
                    if not all(set(c) <= set("-: ") for c in cells):
                        rows.append(cells)
                    i += 1
                if rows:
                    h = "<div class='scroll'><table><tr>" + "".join(f"<th>{html.escape(c.replace('**', ''))}</th>" for c in rows[0]) + "</tr>"
                    for r in rows[1:]:
                        h += "<tr>" + "".join(f"<td>{html.escape(c.replace('**', ''))}</td>" for c in r) + "</tr>"
                    self.html.append(h + "</table></div>")
                continue
            elif not ln.strip():
                flush()
            else:
                para.append(ln.replace("**", ""))
            i += 1
        flush()

    def figure(self, fig, name, caption):
        self.n_img += 1
        path = self.out / "img" / f"{self.n_img:03d}_{name}.png"
        fig.savefig(path, dpi=90, bbox_inches="tight")
        plt.close(fig)
        self.image(path, caption)

    def image(self, path, caption):
        path = pathlib.Path(path)
        if path.parent != self.out / "img":
            self.n_img += 1
            dst = self.out / "img" / f"{self.n_img:03d}_{path.name}"
            dst.write_bytes(path.read_bytes())
            path = dst
        rel = path.relative_to(self.out)
        self.md += [f"![{caption}]({rel.as_posix()})", "", f"*{caption}*", ""]
        b64 = base64.b64encode(path.read_bytes()).decode()
        self.html.append(f'<figure><img src="data:image/png;base64,{b64}" alt="{html.escape(caption)}"><figcaption>{html.escape(caption)}</figcaption></figure>')

    def write(self):
        tmp = self.out / "report.md.tmp"
        tmp.write_text("\n".join(self.md) + "\n")
        tmp.replace(self.out / "report.md")
        style = ("body{font-family:sans-serif;max-width:1200px;margin:auto;padding:1em;color:#222}"
                 ".scroll{overflow-x:auto}table{border-collapse:collapse;margin:0.5em 0 1.2em;font-size:13px}"
                 "td,th{border:1px solid #bbb;padding:3px 7px;text-align:left;vertical-align:top}td.num{text-align:right}"
                 "th{background:#eee}tr.paper td{background:#fff6dc;font-style:italic}tr.ratio td{color:#555;font-size:12px}"
                 "tr.missing td{color:#999}tr.ok td:nth-last-child(2){background:#d8f5d8}tr.partly td:nth-last-child(2){background:#fff0b3}"
                 "tr.no td:nth-last-child(2){background:#f8d0d0}tr.notrun td:nth-last-child(2){background:#e8e8e8}"
                 "figure{margin:1em 0}img{max-width:100%}p.caption{font-size:13px;color:#444;margin-bottom:0.2em}"
                 "figcaption{font-size:13px;color:#555}h2{border-bottom:1px solid #ccc;padding-top:0.6em}code{background:#f3f3f3}")
        doc = (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(self.title)}</title><style>{style}</style></head>"
               f"<body><h1>{html.escape(self.title)}</h1>" + "\n".join(self.html) + "</body></html>\n")
        tmp = self.out / "report.html.tmp"
        tmp.write_text(doc)
        tmp.replace(self.out / "report.html")


# ---- provenance ---------------------------------------------------------------------------

def provenance(rep, runs, sweeps):
    versions = {}
    for r in runs:
        o = r.summary.get("omniloc") or {}
        k = (o.get("version", "unrecorded"), o.get("compiler", "-"), o.get("build_type", "-"))
        versions[k] = versions.get(k, 0) + 1
    rep.heading("Provenance", 2, "provenance")
    rows = [[v, c, b, n] for (v, c, b), n in sorted(versions.items())]
    rep.table(["omniloc version (git describe)", "compiler", "build type", "runs"], rows,
              f"Builds that made these results; machine of this report: {platform.node()}, {os.cpu_count()} cores, {platform.platform()}.")
    if len(versions) > 1:
        rep.para("Warning: the results come from more than one build; compare like with like (scripts/compare.py).")


# ---- scorecard and published tables ----------------------------------------------------------

def scorecard(rep, ctx):
    rep.heading("Reproduction scorecard", 2, "scorecard")
    rep.para("One line per published claim. The verdict is computed by the rule written next to the claim in "
             "results/reference/papers.json (claims); claims that do not hold stay visible, and no model is tuned to turn one. "
             "Timings compare our machine with the papers' 1.66 GHz CPU.")
    rows, classes = [], []
    claims = C.evaluate_claims(ctx)
    for c in claims:
        pub = c["published"]
        pub_text = (fnum(pub, 3) + ("" if c["unit"] in ("x", "", "recovered") else f" {c['unit']}")) if isinstance(pub, (int, float)) else (pub or "-")
        rows.append([c["paper"], c["claim"], c["ours_text"], pub_text, fnum(c["ratio"], 2) if c["ratio"] is not None else "-", c["verdict"], c["rule_text"]])
        classes.append(VERDICT_CLASS.get(c["verdict"], ""))
    rep.table(["paper", "claim", "ours", "paper's", "ours / paper", "verdict", "rule"], rows, row_classes=classes)
    counts = {}
    for c in claims:
        counts[c["verdict"]] = counts.get(c["verdict"], 0) + 1
    rep.para("Verdicts: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())) + ".")
    return claims


def error_table(rep, papers, table, runs):
    t = papers[table]
    rep.heading(f"{t.get('source', table)}", 3, table)
    rep.para(f"papers.json key: {table}. Ours: mean over seeds of each run's statistic (robot 0), with n; "
             "runs with kidnaps or covers use their tracking phase (see docs/results.md). Paper rows in italics, then ours / paper.")
    header = ["row", "source"] + R.TABLE_COLS + ["line points / frame", "seeds"]
    rows, classes = [], []
    for p in C.pair_table(papers, table, runs):
        st = p["stats"]
        if p["runs"]:
            label = p["label"] + (" (tracking phase)" if p["phased"] else "")
            rows.append([label, "omniloc"] + [fnum(st[f"{a}/{s}"]["mean"], 3) for a, s in R.TABLE_KEYS] +
                        [fnum(st["line_points/mean"]["mean"], 0), st["x_cm/mean"]["n"]])
            classes.append("")
        else:
            rows.append([p["label"], "not run"] + ["-"] * 9 + ["-", 0])
            classes.append("missing")
        if p["published"]:
            rows.append([p["label"], "paper"] + [fnum(v, 3) for v in p["published"]] + ["-", "-"])
            classes.append("paper")
            if p["runs"]:
                rows.append([p["label"], "ours / paper"] + [fnum(st[f"{a}/{s}"]["mean"] / v, 2) if v else "-" for (a, s), v in zip(R.TABLE_KEYS, p["published"])] + ["", ""])
                classes.append("ratio")
    rep.table(header, rows, row_classes=classes)
    missing = [p for p in C.pair_table(papers, table, runs) if not p["runs"]]
    for p in missing:
        rep.para(f"Not run: \"{p['label']}\" ({R.describe_key(p['key'])}). Run: {p['command']}")
    # Intervals where there are at least two seeds.
    ci = []
    for p in C.pair_table(papers, table, runs):
        if p["runs"]:
            ci.append([p["label"], R.fstat(p["stats"]["x_cm/mean"], 3), R.fstat(p["stats"]["y_cm/mean"], 3), R.fstat(p["stats"]["theta_rad/mean"], 4)])
    if ci:
        rep.table(["row", "mean x cm [95 % interval]", "mean y cm", "mean th rad"], ci, "Seed-to-seed spread: Student-t 95 % interval over seeds, only where n >= 2.")


def kidnap_table(rep, papers, runs):
    rep.heading("Kidnap recovery (papers 002 and 000)", 3, "kidnapping")
    rows, classes = [], []
    for table in ("002_kidnapping", "000_kidnapping"):
        t = papers[table]
        for label, key in t["reproduced_by"]["rows"].items():
            sel = R.select(runs, key)
            if sel:
                ep = sum(r.metric("recovery/episodes", "all") or 0 for r in sel)
                rec = sum(r.metric("recovery/recovered", "all") or 0 for r in sel)
                fal = sum(r.metric("recovery/false_recoveries", "all") or 0 for r in sel)
                med = R.stats([r.metric("recovery/recovery_time_s/median", "all") for r in sel])
                after = R.stats([r.metric("recovery/after_recovery/x_cm/mean", "all") for r in sel])
                phase = R.stats([r.metric("x_cm/mean", "tracking") for r in sel])
                allf = R.stats([r.metric("x_cm/mean", "all") for r in sel])
                rows.append([f"{table}: {label}", "omniloc", f"{rec:.0f} / {ep:.0f}", f"{fal:.0f}", fnum(med["mean"], 2), fnum(after["mean"], 2),
                             fnum(phase["mean"], 2), fnum(allf["mean"], 1), len(sel)])
                classes.append("")
            else:
                rows.append([f"{table}: {label}", "not run", "-", "-", "-", "-", "-", "-", 0])
                classes.append("missing")
            rows.append([f"{table}: {label}", "paper", f"{t['recovered']} / {t['kidnaps']}", "-", "-", "-", "-", "-", "-"])
            classes.append("paper")
    rep.table(["case", "source", "recovered / kidnaps", "false recoveries", "median recovery s", "after recovery: mean x cm",
               "tracking phase: mean x cm", "all frames: mean x cm", "seeds"], rows,
              "Over all seeds. Recovered: error under 0.3 m and 0.2 rad for 1 s. The tracking phase leaves out the carried period and the time to recovery; "
              "'all frames' includes them (that is why it is large).", classes)


def timing_table(rep, papers, runs):
    t = papers["timings_ms"]
    rep.heading("Timings (papers 002 and 000)", 3, "timings_ms")
    rows, classes = [], []
    for row, key in t["reproduced_by"]["rows"].items():
        med, frames, sel = C.timing_ms(papers, row, runs)
        lo, hi = t[row]
        rows.append([row, key["what"], fnum(med, 2) if med is not None else "not run", f"{lo}-{hi}", fnum(med / hi, 2) if med is not None else "-", frames])
        classes.append("" if med is not None else "missing")
    rep.table(["papers.json row", "what", "ours: median ms", "paper ms", "ours / paper's upper bound", "frames"], rows,
              f"Ours: wall time on {platform.node()} ({os.cpu_count()} cores, {platform.machine()}), runs of a sweep share the cores; paper: {t['cpu']}.", classes)


def experiment_section(rep, ctx, key, title):
    """Heading of a published table reproduced by an experiment; (table, the experiment's JSON or None)."""
    t = ctx.papers[key]
    rb = t["reproduced_by"]
    j = ctx.experiment_json(rb["experiment"], rb["file"])
    rep.heading(title, 3, key)
    if j is None:
        rep.para(f"Not run: {rb['command']}")
    return t, j


def experiment_tables(rep, papers, ctx):
    # 001: equal vs 1/L weights.
    t, j = experiment_section(rep, ctx, "001_cooperative_mean_error_mm", "Paper 001: cooperative ball localisation, equal vs 1/L weights")
    rb = t["reproduced_by"]
    if j is not None:
        eq, w = R.pointer(j, rb["equal_weights"])[1], R.pointer(j, rb["weighted"])[1]
        rows = [["omniloc", fnum(eq, 1), fnum(w, 1), fnum(w / eq, 3) if eq else "-", (j.get("trials") or {}).get("path", "-")],
                ["paper", fnum(t["equal_weights"], 1), fnum(t["weighted"], 1), fnum(t["weighted"] / t["equal_weights"], 3), "-"],
                ["ours / paper", fnum(eq / t["equal_weights"], 2), fnum(w / t["weighted"], 2), "", ""]]
        rep.table(["source", "equal weights mm", "1/L weights mm", "1/L / equal", "trials"], rows,
                  "papers.json key 001_cooperative_mean_error_mm; ours from results/experiments/cooperative_001/cooperative_001.json (headline).",
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
        fig, ax = plt.subplots(figsize=(6.5, 3.6))
        ks = [r["robots"] for r in rv]
        ax.plot(ks, [r["equal_all_mm"] for r in rv], "o-", label="equal weights")
        ax.plot(ks, [r["weighted_all_mm"] for r in rv], "s-", label="1/L weights")
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_ylim(bottom=0)
        ax.set_xlabel("number of robots")
        ax.set_ylabel("mean ball error (mm)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        rep.figure(fig, "robots_vs_error", "paper 001 fig. 10 reproduced: mean ball error against the number of robots (all subsets)")
    else:
        rep.para(f"Not run: {papers['001_simulation_setup']['reproduced_by']['command']}")
    rep.para("Paper 001's real-robot result (001_real_mean_error_cm: 8.6 -> 4.5 cm) needs real robots and is not reproduced.")

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
                rows.append([case, s.get("frames"), s.get("group_fixes"), fnum(s.get("fixes_max_m"), 2), fnum(s.get("no_voting_mean_m"), 3),
                             fnum(s.get("no_voting_max_m"), 2), fnum(s.get("voting_mean_m"), 3), fnum(s.get("voting_max_m"), 2)])
        rep.table(["case", "frames", "group fixes", "worst fix m", "no voting: mean m", "max m", "voting: mean m", "max m"], rows,
                  f"paper: {t['source']}; max error after voting about {t['max_error_m_after_voting']} m")


def profile_of(run):
    found, prof = R.pointer(run.config, "/noise_profile")
    return prof if found else R.SCENARIO_DEFAULT_PROFILE


def field_robot_tables(rep, papers, runs):
    """The published rows again, from runs under the field_robot profile (issue 17)."""
    field = [r for r in runs if profile_of(r) == "field_robot"]
    if not field:
        return
    rep.heading("Published tables under the field_robot profile", 2, "field_robot")
    rep.para("The same keyed rows from runs under noise_profile field_robot: the robot profile plus defocus, motion blur, tilt "
             "from acceleration and a 9 px decentred mirror that calibration estimates (docs/camera.md). Compare with the tables "
             "above (robot profile). Nothing here is tuned to the papers' numbers; what moves is reported as measured.")
    with R.pairing_profile("field_robot"):  # the same keys, these runs
        for table in ("002_table1_occlusion", "002_table2_lighting", "000_tracking"):
            error_table(rep, papers, table, field)
        kidnap_table(rep, papers, field)


def error_budget_section(rep, ctx):
    """Table and bar chart of `omniloc experiment error_budget` (issue 17)."""
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
    rows_by_source, locs = {}, []
    for r in j["rows"]:
        rows_by_source.setdefault(r["source"], {})[r["localizer"]] = r
        if r["localizer"] not in locs:
            locs.append(r["localizer"])
    table = []
    for src, per in rows_by_source.items():
        line = [src]
        for l in locs:
            r = per.get(l, {})
            line += [fnum(r.get("position_rmse_cm"), 2) if "position_rmse_cm" in r else "failed",
                     fnum(r.get("position_p50_cm"), 2) if "position_p50_cm" in r else "-",
                     fnum(r.get("heading_rmse_deg"), 2) if "heading_rmse_deg" in r else "-"]
        table.append(line)
    header = ["source"] + [f"{l} {m}" for l in locs for m in ("RMSE cm", "p50 cm", "heading RMSE deg")]
    rep.table(header, table, f"Runs: {j['sweep']}; description: {j['config_file']}.")
    import matplotlib.pyplot as plt
    sources = list(rows_by_source)
    fig, ax = plt.subplots(figsize=(9, 0.45 * len(sources) + 1.5))
    h = 0.8 / max(1, len(locs))
    for i, l in enumerate(locs):
        vals = [rows_by_source[s].get(l, {}).get("position_rmse_cm", float("nan")) for s in sources]
        ax.barh([k + i * h for k in range(len(sources))], vals, height=h, label=l)
    ax.set_yticks([k + 0.4 - h / 2 for k in range(len(sources))])
    ax.set_yticklabels(sources)
    ax.invert_yaxis()
    ax.set_xscale("log")
    ax.set_xlabel("position RMSE, cm (log scale)")
    ax.legend()
    ax.grid(axis="x", alpha=0.3)
    rep.figure(fig, "error_budget", "Position RMSE of the tracking path with each error source alone and all together.")


def published_tables(rep, papers, ctx):
    rep.heading("Published tables beside ours", 2, "published")
    for table in ("002_table1_occlusion", "002_table2_lighting", "000_tracking"):
        error_table(rep, papers, table, ctx.runs)
    kidnap_table(rep, papers, ctx.runs)
    timing_table(rep, papers, ctx.runs)
    rep.para(f"mcl_only_mean_position_error_cm: MCL-only teams' {papers['mcl_only_mean_position_error_cm']} cm, beside our MCL-alone row of the "
             "000_tracking table above and the scorecard's mcl_alone claim.")
    experiment_tables(rep, papers, ctx)


# ---- sweeps, runs, plots -------------------------------------------------------------------------

def global_start_section(rep, sweeps):
    """Issue 29: sweeps of scenarios/sweeps/global_tracking.json, each run judged apart by
    scripts/global_start.py. A mean over all frames hides one run 8 m off among nineteen at 3 cm, so
    MCL alone is shown as a success rate (Wilson 95 %), the error while right, and the mean over all."""
    import global_start as G
    for sw in sweeps:
        if not sw.name.startswith("global_tracking"):
            continue
        by = G.collect([sw])
        if not by:
            continue
        rep.heading(f"Global start, judged per run: {sw.name}", 2, "global_start")
        rows = []
        for loc in sorted(by, key=lambda k: (k not in ("mcl", "hybrid", "grid_global"), k)):
            g = G.summarise([r for _, r in by[loc]])
            rows.append([loc, f"{g['ended_right']} / {g['runs']}", f"{100 * g['wilson95'][0]:.0f}-{100 * g['wilson95'][1]:.0f} %",
                         fnum(g["t_first_median_s"], 2), fnum(g["right_mean_x_cm"], 2), fnum(g["right_mean_y_cm"], 2),
                         fnum(g["right_mean_theta_rad"], 4), fnum(100 * g["wrong_frame_fraction"], 2), fnum(g["all_mean_pos_cm"], 1)])
        rep.table(["localizer", "ended right", "Wilson 95 %", "first correct convergence median s", "while right: mean x cm", "mean y cm",
                   "mean th rad", "wrong frames %", "mean position error over all valid frames cm"], rows,
                  "scripts/global_start.py (definitions there and in docs/global_localization.md). Paper 002's 'MCL alone 15-40 cm' "
                  "is to be read on the success rate and the error while right, not on the mean over all frames.")


def field_lines(ax, run):
    f = run.folder / "field.json"
    if not f.exists():
        return
    fj = json.loads(f.read_text())
    kw = dict(color="#9a9a9a", lw=0.8, zorder=0)
    for ax_, ay, bx, by in fj.get("segments", []):
        ax.plot([ax_, bx], [ay, by], **kw)
    for cx, cy, r, start, sweep in fj.get("arcs", []):
        n = max(8, int(abs(sweep) / 0.05))
        ts = [start + sweep * i / n for i in range(n + 1)]
        ax.plot([cx + r * math.cos(t) for t in ts], [cy + r * math.sin(t) for t in ts], **kw)
    for gx, gw, gd in fj.get("goals", []):
        s = 1 if gx >= 0 else -1
        ax.plot([gx, gx + s * gd, gx + s * gd, gx], [-gw / 2, -gw / 2, gw / 2, gw / 2], color="#6a6a6a", lw=0.8, zorder=0)
    hx, hy = fj["length"] / 2 + fj["margin"], fj["width"] / 2 + fj["margin"]
    ax.set_xlim(-hx, hx)
    ax.set_ylim(-hy, hy)


def plot_run(rep, run, title):
    frames = run.frames()
    if not frames:
        return
    events = [json.loads(l) for l in (run.folder / "events.jsonl").read_text().splitlines() if l.strip()] if (run.folder / "events.jsonl").exists() else []
    by_robot = {}
    for f in frames:
        by_robot.setdefault(f["robot"], []).append(f)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2), gridspec_kw={"width_ratios": [1.3, 1, 1]})
    ax = axes[0]
    field_lines(ax, run)
    for rid, fr in sorted(by_robot.items()):
        gx, gy = [], []
        for f in fr:  # a break where the truth jumps (teleport / kidnap), not a line across the field
            x, y = float(f["gt_x"]), float(f["gt_y"])
            if gx and not math.isnan(gx[-1]) and math.hypot(x - gx[-1], y - gy[-1]) > 0.5:
                gx.append(float("nan"))
                gy.append(float("nan"))
            gx.append(x)
            gy.append(y)
        ax.plot(gx, gy, "-", lw=1.2, label=f"truth r{rid}")
        v = [f for f in fr if f["valid"] == "1"]
        ax.plot([float(f["est_x"]) for f in v], [float(f["est_y"]) for f in v], ".", ms=1.5, label=f"estimate r{rid}")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("trajectory on the field", fontsize=10)
    ax.legend(fontsize=7, loc="upper right")
    kinds = sorted({e["type"] for e in events if e.get("type") in EVENT_COLOURS})
    for k, (col, label, unit, scale) in enumerate([("err_pos", "position error", "cm", 100.0), ("err_theta", "heading error", "deg", 180.0 / math.pi)]):
        ax = axes[1 + k]
        for rid, fr in sorted(by_robot.items()):
            v = [f for f in fr if f["valid"] == "1"]
            ax.plot([float(f["t"]) for f in v], [abs(float(f[col])) * scale for f in v], lw=0.8, label=f"r{rid}")
        for e in events:
            c = EVENT_COLOURS.get(e.get("type"))
            if c:
                ax.axvline(e["t"], color=c, lw=0.8, alpha=0.7)
        t_end = max(float(f["t"]) for f in frames)
        for r in run.summary.get("robots", []):  # left out of the tracking phase: shaded
            for a, b in (r.get("tracking_phase") or {}).get("excluded", []):
                ax.axvspan(a, min(b, t_end), color="#999999", alpha=0.15, lw=0)
        ax.set_ylim(bottom=0)
        ax.set_xlabel("t (s)")
        ax.set_ylabel(f"{label} ({unit})")
        ax.grid(alpha=0.3)
        ax.set_title(label + (" (lines: " + ", ".join(f"{k} {EVENT_COLOURS[k]}" for k in kinds) + ")" if kinds else ""), fontsize=9)
    rep.figure(fig, "run", f"{title}: trajectory over the field, position and heading error over time"
               + (" (shaded: carried, blind or recovering, left out of the tracking phase)" if any("tracking_phase" in r for r in run.summary.get("robots", [])) else ""))


def run_title(run, params=None):
    s = run.summary
    parts = [s["scenario"], s["localizer"]] + ([params] if params and params != "default" else []) + [f"seed {s['seed']}"]
    return " / ".join(str(p) for p in parts)


def report_run(rep, run, plots, params=None):
    s = run.summary
    title = run_title(run, params)
    rep.heading(f"Run {title}", 3)
    rows = []
    for r in s.get("robots", []):
        rows.append([f"r{r['robot']}" + (" all frames" if "tracking_phase" in r else "")] + [fnum(r[a][st], 3) for a, st in R.TABLE_KEYS] + [r.get("frames", "-")])
        if "tracking_phase" in r:
            tp = r["tracking_phase"]
            rows.append([f"r{r['robot']} tracking phase"] + [fnum(tp[a][st], 3) for a, st in R.TABLE_KEYS] + [tp.get("frames", "-")])
    rep.table(["robot"] + R.TABLE_COLS + ["frames"], rows,
              f"noise profile {s.get('noise_profile')}, {s.get('duration_s')} s at {s.get('camera_rate_hz')} Hz; omniloc {(s.get('omniloc') or {}).get('version', 'unrecorded')}")
    for r in s.get("robots", []):
        rec = r.get("recovery")
        if rec:
            rt = rec.get("recovery_time_s", {})
            rep.table(["robot", "kidnaps", "recovered", "false", "mirrored", "median s", "max s", "after: mean x cm", "mean y cm"],
                      [[f"r{r['robot']}", rec["episodes"], rec["recovered"], rec["false_recoveries"], rec["mirrored"], fnum(rt.get("median"), 2),
                        fnum(rt.get("max"), 2), fnum(rec["after_recovery"]["x_cm"]["mean"], 2), fnum(rec["after_recovery"]["y_cm"]["mean"], 2)]],
                      "kidnap recovery (error under 0.3 m and 0.2 rad for 1 s)")
    if plots:
        plot_run(rep, run, title)


def sweep_runs(sweep, all_runs):
    """The sweep's runs in the aggregate's order (group by group, seeds in run order), with their params."""
    by_folder = {r.folder: r for r in all_runs}
    order = {}
    for row in R.read_csv(sweep / "runs.csv"):
        order[row["id"]] = (int(row["index"]), row["params"])
    agg = json.loads((sweep / "aggregate.json").read_text())
    group_rank = {(g.get("scenario"), g.get("localizer"), g.get("params")): k for k, g in enumerate(agg["groups"])}
    out = []
    for folder, run in by_folder.items():
        if folder.parent != sweep / "runs":
            continue
        idx, params = order.get(folder.name, (10 ** 9, "default"))
        rank = group_rank.get((run.scenario, folder.name.split("__")[1] if "__" in folder.name else run.localizer, params), 10 ** 9)
        out.append((rank, idx, run, params))
    return [(r, p) for _, _, r, p in sorted(out, key=lambda x: (x[0], x[1]))]


def report_sweep(rep, sweep, all_runs, max_runs):
    agg = json.loads((sweep / "aggregate.json").read_text())
    name = agg.get("sweep", agg.get("name", sweep.name))
    rep.heading(f"Sweep {name}", 2)
    o = agg.get("omniloc") or {}
    rep.para(f"{sweep}: {agg.get('runs')} runs; aggregated by omniloc {o.get('version', 'unrecorded')}; runs made by "
             + ", ".join(f"{v} ({n})" for v, n in (agg.get("run_versions") or {}).items()) + ".")
    rows = []
    for g in agg["groups"]:
        m = g["metrics"]
        phase = "r0/tracking_phase/x_cm/mean" in m
        val = lambda a, s: m.get(f"r0/tracking_phase/{a}/{s}" if phase else f"r0/{a}/{s}", {}).get("mean")
        n = m.get("r0/x_cm/mean", {}).get("n", 0)
        rows.append([f"{g.get('scenario', '')} / {g.get('localizer', '')} / {g.get('params', '')}" + (" (tracking phase)" if phase else "")] +
                    [fnum(val(a, s), 3) for a, s in R.TABLE_KEYS] + [f"{g.get('finished', '-')}/{g.get('failed', 0)}", n])
    rep.table(["group"] + R.TABLE_COLS + ["runs ok/failed", "n"], rows,
              "mean over seeds of each run's statistics (robot 0); runs with kidnaps or covers: tracking phase. Published rows: see 'Published tables beside ours'.")
    ci = []
    for g in agg["groups"]:
        v = g["metrics"].get("r0/position_m/rmse")
        if v and v["n"] >= 2:
            ci.append([f"{g.get('scenario')} / {g.get('localizer')} / {g.get('params')}", fnum(v["mean"], 4), f"[{fnum(v['ci95'][0], 4)}, {fnum(v['ci95'][1], 4)}]", v["n"]])
    if ci:
        rep.table(["group", "position RMSE m (all frames)", "95 % interval", "n"], ci, "intervals only where n >= 2")
    runs = sweep_runs(sweep, all_runs)
    # Plots for the first seed of each group (every condition shown once), at most max_runs.
    plotted, seen = 0, set()
    for run, params in runs:
        first = (run.scenario, run.localizer, params) not in seen
        seen.add((run.scenario, run.localizer, params))
        report_run(rep, run, plots=first and plotted < max_runs, params=params)
        plotted += first
    return [r for r, _ in runs]


def tracking_errors(run):
    """Position errors (m) of the valid frames of the tracking phase (outside the excluded intervals)."""
    excl = {}
    for r in run.summary.get("robots", []):
        excl[str(r.get("robot"))] = (r.get("tracking_phase") or {}).get("excluded", [])
    out = []
    for f in run.frames():
        if f["valid"] != "1":
            continue
        t = float(f["t"])
        if any(a - 1e-9 <= t < b - 1e-9 for a, b in excl.get(f["robot"], [])):
            continue
        out.append(float(f["err_pos"]))
    return out


def cdf_and_timing(rep, runs):
    errs, timing = {}, {}
    for run in runs:
        loc = run.localizer
        errs.setdefault(loc, []).extend(tracking_errors(run))
        for r in run.timing():
            d = timing.setdefault(loc, {"render_ms": [], "vision_ms": [], "localize_ms": []})
            for k in d:
                d[k].append(float(r[k]))
    errs = {k: v for k, v in errs.items() if v}
    if errs:
        rep.heading("Error CDF per localizer (tracking phase)", 2)
        fig, ax = plt.subplots(figsize=(7, 4))
        for loc, e in sorted(errs.items()):
            e = sorted(max(x, 1e-4) for x in e)
            ax.plot(e, [(i + 1) / len(e) for i in range(len(e))], label=f"{loc} ({len(e)} frames)")
        ax.set_xscale("log")
        ax.set_ylim(0, 1)
        ax.set_xlabel("position error (m, log scale)")
        ax.set_ylabel("fraction of valid frames")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        rep.figure(fig, "cdf", "position error CDF over the reported runs' tracking phases (carried periods and recoveries left out), per localizer")
        rep.table(["localizer", "frames", "median m", "p90 m", "p99 m"],
                  [[loc, len(e), fnum(statistics.median(e), 4), fnum(sorted(e)[int(0.9 * (len(e) - 1))], 4), fnum(sorted(e)[int(0.99 * (len(e) - 1))], 4)]
                   for loc, e in sorted(errs.items())])
    if timing:
        rep.heading("Timing per stage", 2)
        rows = []
        for loc, d in sorted(timing.items()):
            rows.append([loc] + [fnum(statistics.median(v), 3) if v else "-" for v in d.values()] + [len(d["render_ms"])])
        rep.table(["localizer", "render ms (median)", "vision ms", "localize ms", "frames"], rows,
                  f"wall time per frame on {platform.node()} ({os.cpu_count()} cores, {platform.machine()}); runs in a sweep share the cores")
        fig, ax = plt.subplots(figsize=(7, 3.5))
        locs = sorted(timing)
        bottom = [0.0] * len(locs)
        for k in ["render_ms", "vision_ms", "localize_ms"]:
            vals = [statistics.median(timing[l][k]) if timing[l][k] else 0 for l in locs]
            ax.bar(locs, vals, bottom=bottom, label=k.replace("_ms", ""))
            bottom = [b + v for b, v in zip(bottom, vals)]
        ax.set_ylim(bottom=0)
        ax.set_ylabel("ms per frame (median)")
        ax.legend(fontsize=8)
        rep.figure(fig, "timing", "median time per frame and stage")


def load_jsonl(path):
    out = []
    if path.exists():
        for line in path.read_text().splitlines():
            if line.strip():
                try:
                    out.append(json.loads(line))
                except json.JSONDecodeError:
                    pass  # a line cut by an interrupted append: the others still count
    return out


def history_plot(rep, records, field, key, ylabel, caption, fmt):
    """One line per workload: `field` of every record, relative to the workload's first record, in
    the order the records were appended (one point per measured commit)."""
    series = {}
    for i, rec in enumerate(records):
        for w, v in rec.get(field, {}).items():
            if isinstance(v, (int, float)) and v > 0:
                series.setdefault(w, []).append((i, v))
    if not series:
        return
    fig, ax = plt.subplots(figsize=(8, 4))
    for w, pts in sorted(series.items()):
        base = pts[0][1]
        ax.plot([i for i, _ in pts], [v / base for _, v in pts], marker="o", ms=3, label=w)
    ax.axhline(1.0, color="grey", lw=0.8)
    ax.set_xticks(range(len(records)))
    ax.set_xticklabels([r.get("commit", "?") for r in records], rotation=60, ha="right", fontsize=7)
    ax.set_ylim(bottom=0)
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=6, ncol=2)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    rep.figure(fig, key, caption)
    rows = []
    for w, pts in sorted(series.items()):
        (i0, v0), (i1, v1) = pts[0], pts[-1]
        rows.append([w, records[i0].get("commit", "?"), fmt(v0), records[i1].get("commit", "?"), fmt(v1), fnum(v1 / v0, 3)])
    rep.table(["workload", "first commit", "first", "last commit", "last", "last / first"], rows)


def report_history(rep, folder, reference=None):
    # The committed baseline history (one record per baseline change) first, then this machine's runs.
    reference = pathlib.Path(reference or pathlib.Path(__file__).resolve().parent.parent / "results" / "reference" / "icount_history.jsonl")
    icount = load_jsonl(reference) + load_jsonl(folder / "icount.jsonl")
    bench = load_jsonl(folder / "bench.jsonl")
    if not (icount or bench):
        return
    rep.heading("Speed over commits", 2, "history")
    rep.para(f"From {reference} (committed baselines) and {folder} (this machine): every run of scripts/icount.sh and scripts/bench.sh appends its figures with the commit. "
             "Instruction counts (callgrind, fixed work) do not depend on the machine's load; wall times do, so compare "
             "wall times only between records measured in the same minutes.")
    if icount:
        history_plot(rep, icount, "instructions", "history_icount", "instructions / first record",
                     "instructions per workload (scripts/icount.sh), relative to each workload's first record",
                     lambda v: f"{v:,.0f}")
    if bench:
        history_plot(rep, bench, "real_time_ns", "history_bench", "median wall time / first record",
                     "Google Benchmark median wall time per benchmark (scripts/bench.sh), relative to its first record",
                     lambda v: f"{v:,.1f} ns")


def picture_order(p):
    # Before / after pairs in that order (alphabetically "after" would come first).
    return str(p).replace("_before", "_0before").replace("_after", "_1after")


def report_experiment(rep, exp):
    rep.heading(f"Experiment {exp.name}", 2)
    for md in sorted(exp.glob("*.md")):
        rep.markdown(md.read_text())
    for png in sorted(exp.glob("*.png"), key=picture_order):
        rep.image(png, f"{exp.name}: {png.stem}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", nargs="+")
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--title", default="omniloc report")
    ap.add_argument("--max-runs", type=int, default=24, help="trajectory plots for at most this many conditions per sweep, first seed of each (default 24)")
    ap.add_argument("--baseline", nargs="+", help="result folders to compare with (e.g. another commit's), per metric with Welch's t")
    ap.add_argument("--history", help="folder with icount.jsonl / bench.jsonl (default results/history if it exists; 'none' to leave out)")
    a = ap.parse_args()
    papers = R.load_papers()
    runs, sweeps, experiments = R.discover(a.results)
    if not (runs or sweeps or experiments):
        sys.exit("report.py: no results (summary.json, aggregate.json or experiment pictures) under " + " ".join(a.results))
    rep = Report(a.out, a.title)
    rep.para(f"{len(sweeps)} sweep(s), {len(runs)} run(s), {len(experiments)} experiment(s). Published numbers: results/reference/papers.json; "
             f"everything else is read from the result files.")
    provenance(rep, runs, sweeps)
    ctx = C.Context(papers, runs, experiments)
    scorecard(rep, ctx)
    published_tables(rep, papers, ctx)
    global_start_section(rep, sweeps)
    field_robot_tables(rep, papers, runs)
    error_budget_section(rep, ctx)
    if a.baseline:
        import compare
        base_runs, _, _ = R.discover(a.baseline)
        rep.heading("Comparison with the baseline", 2, "baseline")
        header, rows = compare.compare_rows(base_runs, runs)
        rep.table(header, rows, f"baseline: {' '.join(a.baseline)}; this report's results as 'new'. "
                  + compare.EXPLANATION)
    in_sweeps = set()
    for sw in sweeps:
        for r in report_sweep(rep, sw, runs, a.max_runs):
            in_sweeps.add(r.folder)
    loose = [r for r in runs if r.folder not in in_sweeps]
    if loose:
        rep.heading("Runs", 2)
        for run in loose:
            report_run(rep, run, plots=True)
    cdf_and_timing(rep, runs)
    for exp in experiments:
        report_experiment(rep, exp)
    history = a.history or str(pathlib.Path(__file__).resolve().parent.parent / "results" / "history")
    if history != "none":
        report_history(rep, pathlib.Path(history))
    rep.write()
    print(f"report: {rep.out / 'report.md'} and {rep.out / 'report.html'} ({rep.n_img} pictures)")


if __name__ == "__main__":
    main()
