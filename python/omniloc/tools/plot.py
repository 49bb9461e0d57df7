"""Every figure of the report: the one module of the package that imports matplotlib.

Each function takes the numbers a section computed and returns a matplotlib figure; the section
hands it to the writer (omniloc.tools.markup.Report.figure), which saves it through save() and
closes it. Nothing here reads result files beyond the run folder's own field.json.
"""
from __future__ import annotations

import math
import pathlib
from typing import Callable, Sequence, Union

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator, MaxNLocator, NullFormatter  # noqa: E402

from matplotlib.axes import Axes  # noqa: E402
from matplotlib.axis import Axis  # noqa: E402

from omniloc.core import metrics, stats  # noqa: E402
from omniloc.core.events import EVENT_COLOURS, Event  # noqa: E402
from omniloc.core.jsonvalue import JSON, lst, number, obj  # noqa: E402
from omniloc.core.rundir import Run  # noqa: E402


def save(fig: Figure, path: Union[str, pathlib.Path], dpi: int) -> None:
    """Writes the figure as a PNG and closes it."""
    fig.savefig(path, dpi=dpi, bbox_inches="tight")
    plt.close(fig)


def close(fig: Figure) -> None:
    """Closes a figure that is not written (the terminal's TextReport)."""
    plt.close(fig)


def log_axis(axis: Axis, ax: Axes, which: str) -> None:
    """A log axis with several labelled ticks (1, 2, 5 per decade) in plain numbers, not one lone 10^k."""
    (ax.set_xscale if which == "x" else ax.set_yscale)("log")
    lo, hi = ax.get_xlim() if which == "x" else ax.get_ylim()
    decades = math.log10(hi / lo) if lo > 0 and hi > lo else 1.0
    # 1-2-5 per decade on a short axis; on a long one they would collide: decades only.
    axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0) if decades <= 3.2 else (1.0,), numticks=15))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def seeds_figure(rows_runs: Sequence[tuple[str, list[Run]]], phase: str) -> Figure:
    """Each seed's mean x error (cm) and mean heading error (rad) as dots per row, the mean as a bar:
    a reader sees at once whether a mean is one seed's doing. Log scale where values span > 30x."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 0.42 * len(rows_runs) + 1.3), sharey=True)
    # A seed without an estimate has no dot: its row's label says so (never a dot at 0).
    missing = [sum(1 for r in sel if r.lookup("x_cm/mean", phase) == (True, None)) for _, sel in rows_runs]
    for ax, (metric, unit) in zip(axes, [("x_cm/mean", "mean x error per seed (cm)"), ("theta_rad/mean", "mean heading error per seed (rad)")]):
        allv: list[float] = []
        for k, (label, sel) in enumerate(rows_runs):
            vals = [v for v in (r.metric(metric, phase) for r in sel) if v is not None]
            if not vals:
                continue
            out = set(stats.outliers(vals))
            jitter = [(i - (len(vals) - 1) / 2) * 0.12 for i in range(len(vals))]
            ax.scatter([v for i, v in enumerate(vals) if i not in out], [k + jitter[i] for i in range(len(vals)) if i not in out],
                       s=18, color="#1f77b4", zorder=3)
            if out:
                ax.scatter([vals[i] for i in out], [k + jitter[i] for i in out], s=30, color="#d62728", marker="D", zorder=4,
                           label="outlying seed" if not ax.get_legend_handles_labels()[1] else None)
            m = sum(vals) / len(vals)
            ax.plot([m, m], [k - 0.3, k + 0.3], color="black", lw=1.5, zorder=2)
            allv += vals
        pos = [v for v in allv if v > 0]
        if pos and max(pos) / max(min(pos), 1e-12) > 30:
            log_axis(ax.xaxis, ax, "x")
            unit += ", log scale"
        else:
            ax.set_xlim(left=0)
            ax.xaxis.set_major_locator(MaxNLocator(6))
        ax.set_xlabel(unit)
        ax.grid(axis="x", alpha=0.3)
        if ax.get_legend_handles_labels()[1]:
            ax.legend(fontsize=7, loc="lower right")
    axes[0].set_yticks(range(len(rows_runs)))
    axes[0].set_yticklabels([l + (f" ({metrics.no_estimate_text(k, len(sel))})" if k else "") for (l, sel), k in zip(rows_runs, missing)], fontsize=8)
    axes[0].invert_yaxis()
    return fig


def numbers_of(item: JSON, count: int, what: str) -> list[float]:
    """One marking of field.json: `count` numbers (ValueError where it is anything else)."""
    values = [number(v) for v in lst(item)]
    if len(values) != count or any(v is None for v in values):
        raise ValueError(f"field.json: {what}: expected {count} numbers, got {item}")
    return [v for v in values if v is not None]


def field_lines(ax: Axes, run: Run) -> None:
    raw = run.field_json()
    if raw is None:
        return
    fj = obj(raw)
    for seg in lst(fj.get("segments", [])):
        ax_, ay, bx, by = numbers_of(seg, 4, "segments")
        ax.plot([ax_, bx], [ay, by], color="#9a9a9a", lw=0.8, zorder=0)
    for arc in lst(fj.get("arcs", [])):
        cx, cy, r, start, sweep = numbers_of(arc, 5, "arcs")
        n = max(8, int(abs(sweep) / 0.05))
        ts = [start + sweep * i / n for i in range(n + 1)]
        ax.plot([cx + r * math.cos(t) for t in ts], [cy + r * math.sin(t) for t in ts], color="#9a9a9a", lw=0.8, zorder=0)
    for goal in lst(fj.get("goals", [])):
        gx, gw, gd = numbers_of(goal, 3, "goals")
        s = 1 if gx >= 0 else -1
        ax.plot([gx, gx + s * gd, gx + s * gd, gx], [-gw / 2, -gw / 2, gw / 2, gw / 2], color="#6a6a6a", lw=0.8, zorder=0)
    length, width, margin = numbers_of([fj["length"], fj["width"], fj["margin"]], 3, "length, width, margin")
    hx, hy = length / 2 + margin, width / 2 + margin
    ax.set_xlim(-hx, hx)
    ax.set_ylim(-hy, hy)


def run_figure(run: Run, frames: list[dict[str, str]], events: list[Event]) -> Figure:
    """A run's trajectory over the field, and its position and heading error over time with its events."""
    by_robot: dict[str, list[dict[str, str]]] = {}
    for f in frames:
        by_robot.setdefault(f["robot"], []).append(f)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2), gridspec_kw={"width_ratios": [1.3, 1, 1]})
    ax = axes[0]
    field_lines(ax, run)
    for rid, fr in sorted(by_robot.items()):
        gx: list[float] = []
        gy: list[float] = []
        for f in fr:  # a break where the truth jumps (teleport / kidnap), not a line across the field
            x, y = float(f["gt_x"] or "nan"), float(f["gt_y"] or "nan")  # no truth: a gap
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
    kinds = sorted({e.type for e in events if e.type is not None and e.marked})
    for k, (col, label, unit, scale) in enumerate([("err_pos", "position error", "cm", 100.0), ("err_theta", "heading error", "deg", 180.0 / math.pi)]):
        ax = axes[1 + k]
        for rid, fr in sorted(by_robot.items()):
            v = [f for f in fr if f["valid"] == "1" and f.get(col) not in (None, "")]  # no error without truth
            ax.plot([float(f["t"]) for f in v], [abs(float(f[col])) * scale for f in v], lw=0.8, label=f"r{rid}", zorder=3)
        # Events: a triangle above the plotting area and a faint dashed line BEHIND the data, so a
        # mark never hides the error it explains.
        for e in events:
            c = EVENT_COLOURS.get(e.type or "")
            if c:
                ax.axvline(e.t, color=c, lw=0.6, ls=(0, (3, 3)), alpha=0.45, zorder=1)
                ax.plot([e.t], [1.0], marker="v", color=c, ms=6, transform=ax.get_xaxis_transform(), clip_on=False, zorder=4)
        t_end = max(float(f["t"]) for f in frames)
        for r in run.summary.robots:  # left out of the tracking phase: shaded
            for interval in lst(obj(r.get("tracking_phase")).get("excluded", [])):
                a, b = numbers_of(interval, 2, "tracking_phase.excluded")
                ax.axvspan(a, min(b, t_end), color="#999999", alpha=0.15, lw=0)
        ax.set_ylim(bottom=0)
        ax.xaxis.set_major_locator(MaxNLocator(8))
        ax.yaxis.set_major_locator(MaxNLocator(6))
        ax.set_xlabel("t (s)")
        ax.set_ylabel(f"{label} ({unit})")
        ax.grid(alpha=0.3)
        ax.set_title(label + (" (events, triangles: " + ", ".join(f"{k} {EVENT_COLOURS[k]}" for k in kinds) + ")" if kinds else ""), fontsize=9, pad=9)
    return fig


def robots_vs_error_figure(rv: list[dict[str, float]]) -> Figure:
    """Paper 001's fig. 10 reproduced: the mean ball error against the number of robots."""
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
    return fig


def error_budget_figure(rows_by_source: dict[str, dict[str, dict[str, JSON]]], locs: list[str]) -> Figure:
    """Position RMSE of each error budget row, one bar per localizer, on a log axis."""
    sources = list(rows_by_source)
    fig, ax = plt.subplots(figsize=(9, 0.45 * len(sources) + 1.5))
    h = 0.8 / max(1, len(locs))
    for i, l in enumerate(locs):
        vals = [v if stats.is_number(v := rows_by_source[s].get(l, {}).get("position_rmse_cm")) else float("nan") for s in sources]
        ax.barh([k + i * h for k in range(len(sources))], vals, height=h, label=l)
    ax.set_yticks([k + 0.4 - h / 2 for k in range(len(sources))])
    ax.set_yticklabels(sources)
    ax.invert_yaxis()
    log_axis(ax.xaxis, ax, "x")
    ax.set_xlabel("position RMSE, cm (log scale)")
    ax.legend()
    ax.grid(axis="x", alpha=0.3)
    return fig


def cdf_figure(errs: dict[tuple[str, str], list[float]], frames: dict[tuple[str, str], dict[str, int]], profiles: list[str],
               label: Callable[[tuple[str, str], int, int], str]) -> Figure:
    """Position error CDFs over ALL tracking-phase frames, one curve per (localizer, noise profile)."""
    fig, ax = plt.subplots(figsize=(7, 4))
    styles = {p: s for p, s in zip(profiles, ["-", "--", ":", "-."] * 4)}
    for key, e in sorted(errs.items()):
        if not e:
            continue
        # Over ALL tracking-phase frames: a frame without an estimate is never within any error,
        # so a curve levels off at the share answered (a localizer that answers only easy frames
        # does not look better).
        n = max(frames[key].get("frames", 0), len(e))
        e = sorted(max(x, 1e-4) for x in e)
        ax.plot(e, [(i + 1) / n for i in range(len(e))], styles[key[1]], label=label(key, len(e), n))
    log_axis(ax.xaxis, ax, "x")
    ax.set_ylim(0, 1)
    ax.set_xlabel("position error (m, log scale)")
    ax.set_ylabel("share of all frames within the error")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def timing_figure(timing: dict[tuple[str, str], dict[str, list[float]]], median: Callable[[list[float]], float]) -> Figure:
    """Median time per frame and stage, stacked, per (localizer, noise profile)."""
    fig, ax = plt.subplots(figsize=(max(7, 1.2 * len(timing)), 3.5))
    keys = sorted(timing)
    labels = [f"{l}\n{p}" for l, p in keys]
    bottom = [0.0] * len(keys)
    for k in ["render_ms", "vision_ms", "localize_ms"]:
        vals = [median(timing[key][k]) if timing[key][k] else 0 for key in keys]
        ax.bar(labels, vals, bottom=bottom, label=k.replace("_ms", ""))
        bottom = [b + v for b, v in zip(bottom, vals)]
    ax.set_ylim(bottom=0)
    ax.set_ylabel("ms per frame (median)")
    ax.legend(fontsize=8)
    return fig


def history_figure(series: dict[str, list[tuple[int, float]]], records: list[dict[str, JSON]], ylabel: str) -> Figure:
    """One line per workload, relative to its first record, one point per measured commit."""
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
    return fig
