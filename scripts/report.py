#!/usr/bin/env python3
"""Comparison report of omniloc results: report.md and a self-contained report.html.

usage: report.py RESULTS... -o DIR [--title TEXT] [--max-runs N]

RESULTS are folders: a run (summary.json), a sweep (aggregate.json with runs/ inside), an
experiment (PNG / JSON / markdown files written by `omniloc experiment`), or any folder holding
such folders (searched recursively). The report shows
  - the papers' tables beside ours (published numbers come only from results/reference/papers.json),
  - every sweep's aggregate (mean and 95 % interval over seeds) and every run's error table,
  - trajectory plots (truth vs estimate) and error over time with the events marked,
  - error CDFs per localizer, timing per stage (render, vision, localize),
  - the pictures the experiments produced.
Everything except the published numbers is read from the result files. Needs Python 3 and
Debian's python3-matplotlib (no PyPI).
"""
import argparse
import base64
import csv
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

ROOT = pathlib.Path(__file__).resolve().parent.parent
PAPER_KEYS = [("x_cm", "mean"), ("y_cm", "mean"), ("theta_rad", "mean"), ("x_cm", "std"), ("y_cm", "std"), ("theta_rad", "std"),
              ("x_cm", "max"), ("y_cm", "max"), ("theta_rad", "max")]
PAPER_COLS = ["mean x cm", "mean y cm", "mean th rad", "std x", "std y", "std th", "max x", "max y", "max th"]
# Which published table a sweep or scenario reproduces, and how our rows map to its rows.
SWEEP_TABLES = {
    "occlusion_002": ("002_table1_occlusion", None),
    "lighting_002": ("002_table2_lighting", None),
}
SCENARIO_TABLES = {"tracking": ("000_tracking", "tracking")}
EVENT_COLOURS = {"kidnap": "red", "cover": "black", "teleport": "red", "occlude": "grey", "lights": "orange", "camera": "purple"}


def find(paths):
    runs, sweeps, experiments = [], [], []
    for p in paths:
        p = pathlib.Path(p)
        if not p.is_dir():
            sys.exit(f"report.py: {p}: not a folder")
        for d, subdirs, files in os.walk(p):
            d = pathlib.Path(d)
            if d.name.startswith(".") or ".staging" in d.name or d.name.endswith(".tmp"):
                subdirs[:] = []
                continue
            if "aggregate.json" in files:
                sweeps.append(d)
                subdirs[:] = []  # its runs are reported through the sweep
            elif "summary.json" in files:
                runs.append(d)
                subdirs[:] = []
            elif any(f.endswith(".png") for f in files) and d.name != "img":
                experiments.append(d)
    return sorted(set(runs)), sorted(set(sweeps)), sorted(set(experiments))


def load_frames(run):
    f = run / "frames.csv"
    if not f.exists():
        return []
    with f.open() as fh:
        return list(csv.DictReader(fh))


def load_events(run):
    f = run / "events.jsonl"
    if not f.exists():
        return []
    return [json.loads(line) for line in f.read_text().splitlines() if line.strip()]


def fnum(v, digits=3):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    return f"{v:.{digits}f}"


class Report:
    def __init__(self, out, title):
        self.out = pathlib.Path(out)
        (self.out / "img").mkdir(parents=True, exist_ok=True)
        self.md = [f"# {title}", ""]
        self.html = []
        self.n_img = 0
        self.title = title

    def heading(self, text, level=2):
        self.md += ["#" * level + " " + text, ""]
        self.html.append(f"<h{level}>{html.escape(text)}</h{level}>")

    def para(self, text):
        self.md += [text, ""]
        self.html.append(f"<p>{html.escape(text)}</p>")

    def table(self, header, rows, caption=None):
        if caption:
            self.para(caption)
        self.md.append("| " + " | ".join(header) + " |")
        self.md.append("|" + "|".join("---" for _ in header) + "|")
        for r in rows:
            self.md.append("| " + " | ".join(str(c) for c in r) + " |")
        self.md.append("")
        h = "<table><tr>" + "".join(f"<th>{html.escape(str(c))}</th>" for c in header) + "</tr>"
        for r in rows:
            cls = ' class="paper"' if r and str(r[0]).startswith("paper") else ""
            h += f"<tr{cls}>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>"
        self.html.append(h + "</table>")

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
        (self.out / "report.md").write_text("\n".join(self.md) + "\n")
        style = ("body{font-family:sans-serif;max-width:1100px;margin:auto;padding:1em;color:#222}"
                 "table{border-collapse:collapse;margin:0.5em 0 1.2em;font-size:13px}td,th{border:1px solid #bbb;padding:3px 7px;text-align:right}"
                 "th{background:#eee}tr.paper td{background:#fff6dc;font-style:italic}figure{margin:1em 0}img{max-width:100%}"
                 "figcaption{font-size:13px;color:#555}h2{border-bottom:1px solid #ccc;padding-top:0.6em}")
        doc = (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(self.title)}</title><style>{style}</style></head>"
               f"<body><h1>{html.escape(self.title)}</h1>" + "\n".join(self.html) + "</body></html>\n")
        tmp = self.out / "report.html.tmp"
        tmp.write_text(doc)
        tmp.replace(self.out / "report.html")


def summary_row(robot):
    return [fnum(robot[a][s], 3) for a, s in PAPER_KEYS]


def paper_rows(papers, key, labels=None):
    t = papers.get(key)
    if not t:
        return []
    names = labels or list(t["rows"].keys())
    return [[f"paper: {n}"] + [fnum(v, 3) for v in t["rows"][n]] for n in names if n in t["rows"]]


def plot_run(rep, run, summary, frames, events):
    name = f"{summary['scenario']} / {summary['localizer']} / seed {summary['seed']}"
    if not frames:
        return
    by_robot = {}
    for f in frames:
        by_robot.setdefault(f["robot"], []).append(f)
    fig, axes = plt.subplots(1, 2, figsize=(12, 4))
    ax = axes[0]
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
    ax.set_title("trajectory")
    ax.legend(fontsize=7)
    ax = axes[1]
    for rid, fr in sorted(by_robot.items()):
        t = [float(f["t"]) for f in fr if f["valid"] == "1"]
        e = [max(1e-4, float(f["err_pos"])) for f in fr if f["valid"] == "1"]
        ax.semilogy(t, e, lw=0.8, label=f"position error r{rid}")
    for e in events:
        c = EVENT_COLOURS.get(e.get("type"))
        if c:
            ax.axvline(e["t"], color=c, lw=0.8, alpha=0.7)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("position error (m)")
    kinds = sorted({e["type"] for e in events if e.get("type") in EVENT_COLOURS})
    ax.set_title("error over time" + (" (lines: " + ", ".join(f"{k} {EVENT_COLOURS[k]}" for k in kinds) + ")" if kinds else ""), fontsize=9)
    rep.figure(fig, "run", f"{name}: trajectory and error over time")


def report_run(rep, run, papers, plots):
    s = json.loads((run / "summary.json").read_text())
    rep.heading(f"Run {s['scenario']} / {s['localizer']} / seed {s['seed']}", 3)
    rows = []
    for r in s.get("robots", []):
        rows.append([f"r{r['robot']}"] + summary_row(r) + [r.get("frames", "-")])
    key = SCENARIO_TABLES.get(s["scenario"])
    if key:
        rows += [p + ["-"] for p in paper_rows(papers, key[0], [key[1]])]
    rep.table(["robot"] + PAPER_COLS + ["frames"], rows, f"noise profile {s.get('noise_profile')}, {s.get('duration_s')} s at {s.get('camera_rate_hz')} Hz")
    for r in s.get("robots", []):
        rec = r.get("recovery")
        if rec:
            rt = rec.get("recovery_time_s", {})
            rep.table(["robot", "kidnaps", "recovered", "false", "mirrored", "median s", "max s", "after: mean x cm", "mean y cm"],
                      [[f"r{r['robot']}", rec["episodes"], rec["recovered"], rec["false_recoveries"], rec["mirrored"], fnum(rt.get("median"), 2),
                        fnum(rt.get("max"), 2), fnum(rec["after_recovery"]["x_cm"]["mean"], 2), fnum(rec["after_recovery"]["y_cm"]["mean"], 2)]],
                      "kidnap recovery (error under 0.3 m and 0.2 rad for 1 s)")
    if plots:
        plot_run(rep, run, s, load_frames(run), load_events(run))
    return s


def report_sweep(rep, sweep, papers):
    agg = json.loads((sweep / "aggregate.json").read_text())
    name = agg.get("name", sweep.name)
    rep.heading(f"Sweep {name}", 2)
    rows = []
    for g in agg["groups"]:
        m = g["metrics"]
        label = f"{g.get('scenario', '')} / {g.get('localizer', '')} / {g.get('params', '')}"
        rows.append([label] + [fnum(m.get(f"r0/{a}/{s}", {}).get("mean"), 3) for a, s in PAPER_KEYS] +
                    [f"{g.get('finished', '-')}/{g.get('failed', 0)}"])
    key = SWEEP_TABLES.get(name)
    if key:
        rows += [p + ["-"] for p in paper_rows(papers, key[0], key[1])]
    rep.table(["group"] + PAPER_COLS + ["runs ok/failed"], rows, "mean over seeds of each run's statistics (robot 0); papers' rows in italics")
    # Recovery and position RMSE with 95 % intervals, where present.
    rrows = []
    for g in agg["groups"]:
        m = g["metrics"]
        if "r0/recovery/episodes" in m:
            def tot(k):
                v = m.get(k)
                return v["mean"] * v["n"] if v else float("nan")
            rrows.append([f"{g.get('scenario')} / {g.get('localizer')}", f"{tot('r0/recovery/episodes'):.0f}", f"{tot('r0/recovery/recovered'):.0f}",
                          f"{tot('r0/recovery/false_recoveries'):.0f}", f"{tot('r0/recovery/mirrored'):.0f}",
                          fnum(m.get("r0/recovery/recovery_time_s/median", {}).get("mean"), 2)])
    if rrows:
        rep.table(["group", "kidnaps", "recovered", "false", "mirrored", "mean of run medians s"], rrows, "kidnap recovery over all runs")
    ci = []
    for g in agg["groups"]:
        v = g["metrics"].get("r0/position_m/rmse")
        if v:
            ci.append([f"{g.get('scenario')} / {g.get('localizer')} / {g.get('params')}", fnum(v["mean"], 4), f"[{fnum(v['ci95'][0], 4)}, {fnum(v['ci95'][1], 4)}]", v["n"]])
    if ci:
        rep.table(["group", "position RMSE m", "95 % interval", "seeds"], ci)
    runs = sorted(p.parent for p in (sweep / "runs").glob("*/summary.json")) if (sweep / "runs").exists() else []
    return runs


def cdf_and_timing(rep, runs):
    errs, timing = {}, {}
    for run in runs:
        s = json.loads((run / "summary.json").read_text())
        loc = s["localizer"]
        for f in load_frames(run):
            if f["valid"] == "1":
                errs.setdefault(loc, []).append(float(f["err_pos"]))
        t = run / "timing.csv"
        if t.exists():
            with t.open() as fh:
                for r in csv.DictReader(fh):
                    d = timing.setdefault(loc, {"render_ms": [], "vision_ms": [], "localize_ms": []})
                    for k in d:
                        d[k].append(float(r[k]))
    if errs:
        rep.heading("Error CDF per localizer", 2)
        fig, ax = plt.subplots(figsize=(7, 4))
        for loc, e in sorted(errs.items()):
            e = sorted(e)
            ax.plot(e, [(i + 1) / len(e) for i in range(len(e))], label=f"{loc} ({len(e)} frames)")
        ax.set_xscale("log")
        ax.set_xlabel("position error (m)")
        ax.set_ylabel("fraction of valid frames")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        rep.figure(fig, "cdf", "position error CDF over all reported runs, per localizer")
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
        ax.set_ylabel("ms per frame (median)")
        ax.legend(fontsize=8)
        rep.figure(fig, "timing", "median time per frame and stage")


def report_experiment(rep, exp):
    rep.heading(f"Experiment {exp.name}", 2)
    for md in sorted(exp.glob("*.md")):
        rep.md += [md.read_text(), ""]
        rep.html.append("<pre>" + html.escape(md.read_text()) + "</pre>")
    for png in sorted(exp.glob("*.png")):
        rep.image(png, f"{exp.name}: {png.stem}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", nargs="+")
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--title", default="omniloc report")
    ap.add_argument("--max-runs", type=int, default=12, help="trajectory plots for at most this many runs per sweep (default 12)")
    a = ap.parse_args()
    papers = json.loads((ROOT / "results/reference/papers.json").read_text())
    runs, sweeps, experiments = find(a.results)
    if not (runs or sweeps or experiments):
        sys.exit("report.py: no results (summary.json, aggregate.json or experiment pictures) under " + " ".join(a.results))
    rep = Report(a.out, a.title)
    rep.para(f"{len(sweeps)} sweep(s), {len(runs)} run(s), {len(experiments)} experiment(s). Published numbers: results/reference/papers.json; "
             f"everything else is read from the result files. Machine: {platform.node()}, {os.cpu_count()} cores, {platform.platform()}.")
    all_runs = []
    for sw in sweeps:
        sub = report_sweep(rep, sw, papers)
        all_runs += sub
        for k, run in enumerate(sub):
            report_run(rep, run, papers, plots=k < a.max_runs)
    if runs:
        rep.heading("Runs", 2)
        for run in runs:
            report_run(rep, run, papers, plots=True)
        all_runs += runs
    cdf_and_timing(rep, all_runs)
    for exp in experiments:
        report_experiment(rep, exp)
    rep.write()
    print(f"report: {rep.out / 'report.md'} and {rep.out / 'report.html'} ({rep.n_img} pictures)")


if __name__ == "__main__":
    main()
