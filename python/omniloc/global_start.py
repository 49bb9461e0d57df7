"""Global localisation from an unknown start, judged per run.

A mean error over every frame of a global-start run mixes two things that a reader must see apart:
how often the localizer finds the right pose at all, and how well it tracks once it has. One run
that settles on a wrong pose 8 m away lifts the mean of twenty runs by 40 cm while the other
nineteen track at 3 cm. So, per localizer over the runs (seeds) given:

- **ended right**: runs that give a valid estimate in the last second and every valid one there
  within 0.3 m / 0.2 rad of the truth (the recovery tolerances of harness/scoring/recovery.hpp; a frame
  the localizer marks invalid, e.g. MCL's spread briefly over its threshold, says "not sure", not
  "wrong"), with the Wilson score 95 %
  interval (Wilson 1927; the interval Brown, Cai and DasGupta 2001 recommend for small n: unlike
  the normal approximation it stays inside [0, 1] and does not collapse to a point at 0 or n);
- **first correct convergence**: the first time from which the estimate stays valid and within
  those tolerances for 1 s (as a kidnap's recovery time, counted from t = 0); median and max over
  the runs that got there;
- **error while right**: mean |x|, |y| (cm), |theta| (rad) and the position RMSE over the valid
  frames that are not wrong (below), pooled over the runs: the papers' table, on correct frames;
- **wrong frames**: valid frames more than 0.5 m or 0.35 rad off (the `wrong_frames` definition of
  harness/scoring/metrics.cpp), as a fraction of all frames, and the number of runs with any;
- **mean over all**: mean position error over every valid frame, the statistic that hides both;
- **beyond the walls**: frames whose estimate lies outside the floor (field.json beside the run),
  valid ones and all (an invalid MCL estimate is still the set's mean, written to frames.csv);
- **recall** (first column): the mean over runs of summary.json's recall at the headline threshold
  (the share of ALL frames within 25 cm / 10 deg, a frame without an estimate counting as outside),
  the share of frames answered, and the median time to the first estimate within that threshold
  (summary.json first_within_s; runs that never got there are counted, not averaged).
A statistic over no frame (no valid frame, no right frame) is None in the JSON and "-" or "no
estimate" in the table, never 0.

Usage: python3 -m omniloc.commands.global_start FOLDER... [--markdown] [--json OUT]
(folders: sweep folders or run folders, e.g. results/sweeps/global_tracking). Plain python3 (PYTHONPATH=<share>/python).
"""
from __future__ import annotations

import dataclasses
import math
import pathlib
from dataclasses import dataclass
from typing import Iterable, Optional, Sequence, Union

from omniloc.core import metrics, rundir
from omniloc.core.jsonvalue import JSON, number, obj
from omniloc.core.rundir import Run
from omniloc.core.stats import wilson


POS_TOL, THETA_TOL, HOLD_S = 0.3, 0.2, 1.0      # harness/scoring/recovery.hpp RecoveryCriteria


WRONG_POS, WRONG_THETA = 0.5, 0.35              # harness/scoring/metrics.cpp wrong_frames


@dataclass
class RunScore:
    """One run judged from its frames.csv (robot 0), score_run(): whether it ended right, when it first
    converged (t_first, None: never), the sums over its right frames, its wrong, valid and total frame
    counts, the frames beyond the walls, and a particle filter's spread on right frames. collect()
    adds what summary.json states: recall at the headline threshold, the share answered, and
    first_within_s (has_first_within: whether summary.json has the key at all)."""
    frames: int
    ended_right: bool
    t_first: Optional[float]
    wrong_frames: int
    right_frames: int
    sum_x: float
    sum_y: float
    sum_th: float
    sum_p2: float
    max_x: Optional[float]
    max_y: Optional[float]
    valid_frames: int
    sum_pos_all: float
    outside_walls_frames: int
    outside_walls_any_frames: int
    sum_spread: float
    spread_frames: int
    recall_key: Optional[str] = None
    recall: Optional[float] = None
    valid_fraction: Optional[float] = None
    first_within_s: Optional[float] = None
    has_first_within: bool = False


@dataclass
class Summary:
    """One localizer over its runs, summarise(): the columns of the table (the module's docstring
    defines each); a statistic over no frame is None, never 0. to_json() in this order."""
    runs: int
    ended_right: int
    ended_right_fraction: Optional[float]
    wilson95: list[float]
    converged_runs: int
    t_first_median_s: Optional[float]
    t_first_max_s: Optional[float]
    right_frames: int
    right_mean_x_cm: Optional[float]
    right_mean_y_cm: Optional[float]
    right_mean_theta_rad: Optional[float]
    right_pos_rmse_cm: Optional[float]
    right_max_x_cm: Optional[float]
    right_max_y_cm: Optional[float]
    wrong_frame_fraction: Optional[float]
    runs_with_wrong_frames: int
    all_mean_pos_cm: Optional[float]
    outside_walls_frames: int
    outside_walls_any_frames: int
    right_mean_spread_cm: Optional[float]
    runs_without_estimate: int
    recall_key: Optional[str]
    recall_mean: Optional[float]
    answered_mean: Optional[float]
    first_within_median_s: Optional[float]
    runs_never_within: int

    def to_json(self) -> dict[str, JSON]:
        return dataclasses.asdict(self)

    def stat(self, name: str) -> Optional[float]:
        """A number of the summary by its name (a claim's selector names one), None where it is none."""
        return number(self.to_json().get(name))


Frame = tuple[float, bool, float, float, float, float]  # t, valid, |err x|, |err y|, |err theta|, err pos


def frame_of(row: dict[str, str]) -> Frame:
    return (float(row["t"]), row["valid"] == "1", abs(float(row["err_x"])), abs(float(row["err_y"])),
            abs(float(row["err_theta"])), float(row["err_pos"]))


def score_run(rows: Sequence[dict[str, str]], half_floor: Optional[tuple[float, float]] = None) -> RunScore:
    """Per-run figures from frames.csv rows (robot 0): ended_right, t_first (None when never), the
    sums over right frames, the wrong and total frame counts, the mean over all, and (with
    half_floor = (half x, half y) of the floor inside the walls, metres) the valid frames whose
    estimate lies beyond the walls."""
    rows = [r for r in rows if r.get("robot", "0") == "0" and r.get("err_pos") not in (None, "")]  # scored frames (with truth)
    fr = [frame_of(r) for r in rows]
    outside = outside_any = 0
    if half_floor:
        beyond = [abs(float(r["est_x"])) > half_floor[0] or abs(float(r["est_y"])) > half_floor[1] for r in rows]
        outside = sum(1 for r, b in zip(rows, beyond) if b and r["valid"] == "1")
        outside_any = sum(beyond)
    ok = [v and ep <= POS_TOL and et <= THETA_TOL for (_, v, _, _, et, ep) in fr]
    t_end = fr[-1][0] if fr else 0.0
    last = [o for (f, o) in zip(fr, ok) if f[0] > t_end - HOLD_S and f[1]]
    ended_right = bool(last) and all(last)
    # First t from which every frame for HOLD_S is ok (the run's end counts only if a full second fits).
    t_first: Optional[float] = None
    start: Optional[float] = None
    for (f, o) in zip(fr, ok):
        if not o:
            start = None
            continue
        if start is None:
            start = f[0]
        if f[0] - start >= HOLD_S - 1e-9:
            t_first = start
            break
    right = [f for f in fr if f[1] and not (f[5] > WRONG_POS or f[4] > WRONG_THETA)]
    # A particle filter's spread (frames.csv spread_m, MCL) on the right frames: what sets its error there.
    spreads = [float(r["spread_m"]) for r, f in zip(rows, fr) if r.get("spread_m") not in (None, "")
               and f[1] and not (f[5] > WRONG_POS or f[4] > WRONG_THETA)]
    wrong = sum(1 for f in fr if f[1] and (f[5] > WRONG_POS or f[4] > WRONG_THETA))
    valid = [f for f in fr if f[1]]
    return RunScore(
        frames=len(fr), ended_right=ended_right, t_first=t_first, wrong_frames=wrong,
        right_frames=len(right), sum_x=sum(f[2] for f in right), sum_y=sum(f[3] for f in right),
        sum_th=sum(f[4] for f in right), sum_p2=sum(f[5] ** 2 for f in right),
        max_x=max((f[2] for f in right), default=None), max_y=max((f[3] for f in right), default=None),
        valid_frames=len(valid), sum_pos_all=sum(f[5] for f in valid),
        outside_walls_frames=outside, outside_walls_any_frames=outside_any,
        sum_spread=sum(spreads), spread_frames=len(spreads),
    )


def summarise(per_run: Sequence[RunScore]) -> Summary:
    """Aggregate of score_run results (one localizer)."""
    n = len(per_run)
    k = sum(r.ended_right for r in per_run)
    lo, hi = wilson(k, n)
    times = sorted(r.t_first for r in per_run if r.t_first is not None)
    nr = sum(r.right_frames for r in per_run)
    frames = sum(r.frames for r in per_run)
    nv = sum(r.valid_frames for r in per_run)
    med = None
    if times:
        m = len(times) // 2
        med = times[m] if len(times) % 2 else 0.5 * (times[m - 1] + times[m])
    ns = sum(r.spread_frames for r in per_run)
    return Summary(
        runs=n, ended_right=k, ended_right_fraction=k / n if n else None, wilson95=[lo, hi],
        converged_runs=len(times), t_first_median_s=med, t_first_max_s=times[-1] if times else None,
        right_frames=nr,
        right_mean_x_cm=100 * sum(r.sum_x for r in per_run) / nr if nr else None,
        right_mean_y_cm=100 * sum(r.sum_y for r in per_run) / nr if nr else None,
        right_mean_theta_rad=sum(r.sum_th for r in per_run) / nr if nr else None,
        right_pos_rmse_cm=100 * math.sqrt(sum(r.sum_p2 for r in per_run) / nr) if nr else None,
        right_max_x_cm=max_cm(r.max_x for r in per_run),  # None: no right frame in any run (never 0)
        right_max_y_cm=max_cm(r.max_y for r in per_run),
        wrong_frame_fraction=sum(r.wrong_frames for r in per_run) / frames if frames else None,
        runs_with_wrong_frames=sum(1 for r in per_run if r.wrong_frames > 0),
        all_mean_pos_cm=100 * sum(r.sum_pos_all for r in per_run) / nv if nv else None,
        outside_walls_frames=sum(r.outside_walls_frames for r in per_run),
        outside_walls_any_frames=sum(r.outside_walls_any_frames for r in per_run),
        right_mean_spread_cm=100 * sum(r.sum_spread for r in per_run) / ns if ns else None,
        runs_without_estimate=sum(1 for r in per_run if r.valid_frames == 0),
        # From summary.json (collect() adds them): the coverage-aware figures, None where no run has them.
        recall_key=next((r.recall_key for r in per_run if r.recall_key), None),
        recall_mean=mean_of(r.recall for r in per_run),
        answered_mean=mean_of(r.valid_fraction for r in per_run),
        first_within_median_s=median_or_none([r.first_within_s for r in per_run if r.first_within_s is not None]),
        runs_never_within=sum(1 for r in per_run if r.has_first_within and r.first_within_s is None),
    )


def max_cm(values: Iterable[Optional[float]]) -> Optional[float]:
    v = [x for x in values if x is not None]
    return 100 * max(v) if v else None


def mean_of(values: Iterable[Optional[float]]) -> Optional[float]:
    v = [x for x in values if isinstance(x, (int, float)) and not isinstance(x, bool)]
    return sum(v) / len(v) if v else None


def median_or_none(values: Sequence[float]) -> Optional[float]:
    v = sorted(values)
    if not v:
        return None
    m = len(v) // 2
    return v[m] if len(v) % 2 else 0.5 * (v[m - 1] + v[m])


def floor_half(run: Run) -> Optional[tuple[float, float]]:
    """(half x, half y) of the floor inside the walls (metres) from the run's field.json; None without
    the file. ValueError where it is not JSON or lacks the field's length and width."""
    raw = run.field_json()
    if raw is None:
        return None
    j = obj(raw)
    length, width, margin = number(j.get("length")), number(j.get("width")), number(j.get("margin", 1.0))
    if length is None or width is None or margin is None:
        raise ValueError(f"{run.folder / 'field.json'}: expected numbers length, width and margin")
    return (0.5 * length + margin, 0.5 * width + margin)


def row_of(run: Run) -> str:
    """The row a run counts in: in a sweep the folder is scenario__label__params__sN, and the label
    tells variants of one type apart; an external client's run records its name (docs/protocol.md
    "Which name"). A run that was given the start pose did not start globally: a row of its own
    ("... (given the start pose)"), never averaged into a global-start one."""
    parts = run.folder.name.split("__")
    key = parts[1] if len(parts) == 4 and run.summary.localizer_type != "external" else str(run.localizer)
    return key + (" (given the start pose)" if run.start_pose_given else "")


def collect(folders: Sequence[Union[str, pathlib.Path]]) -> dict[str, list[tuple[Optional[int], RunScore]]]:
    """Every run under the folders scored (score_run), by row (row_of), with its seed."""
    runs, _, _ = rundir.discover(folders)
    by: dict[str, list[tuple[Optional[int], RunScore]]] = {}
    for run in runs:
        scored = score_run(run.frames(), floor_half(run))
        # The coverage summary.json states (robot 0): recall at the run's headline threshold, the
        # share answered, when it first answered within that threshold (None: never).
        head = run.headline
        scored.recall_key = head
        scored.recall = run.metric(f"recall/{head}", "all") if head else None
        scored.valid_fraction = run.metric("valid_fraction", "all")
        found, first = run.lookup("first_within_s", "all")
        if found:
            scored.has_first_within = True
            scored.first_within_s = number(first)
        by.setdefault(row_of(run), []).append((run.seed, scored))
    return by


def cell(v: Optional[float], fmt: str, scale: float = 1.0) -> str:
    return "-" if v is None else fmt % (scale * v)


def no_estimate_cell(v: Optional[float], fmt: str, s: Summary) -> str:
    """A statistic over the valid frames, "no estimate" where no run had one."""
    return ("no estimate" if s.runs_without_estimate == s.runs else "-") if v is None else fmt % v


def recall_header(table: dict[str, Summary]) -> str:
    key = next((s.recall_key for s in table.values() if s.recall_key), None)
    return f"within {metrics.recall_label(key)}" if key else "within the headline threshold"


def markdown(table: dict[str, Summary]) -> str:
    out = [f"| localizer | runs | {recall_header(table)}: mean over runs (answered) | first within it: median s (runs never) | ended right | "
           "Wilson 95 % | first correct convergence median / max s | "
           "error while right: mean x / y cm, th rad, pos RMSE cm | wrong frames (runs with any) | mean pos error over all valid frames cm | frames beyond the walls: valid / all |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    for loc, s in table.items():
        out.append(f"| {loc} | {s.runs} | {metrics.percent(s.recall_mean)} ({metrics.percent(s.answered_mean)}) | "
                   f"{cell(s.first_within_median_s, '%.2f')} ({s.runs_never_within}) | "
                   f"{s.ended_right} ({cell(s.ended_right_fraction, '%.0f', 100)} %) | "
                   f"{100 * s.wilson95[0]:.0f}-{100 * s.wilson95[1]:.0f} % | "
                   f"{cell(s.t_first_median_s, '%.2f')} / {cell(s.t_first_max_s, '%.2f')} ({s.converged_runs} runs) | "
                   f"{no_estimate_cell(s.right_mean_x_cm, '%.2f', s)} / {no_estimate_cell(s.right_mean_y_cm, '%.2f', s)}, "
                   f"{no_estimate_cell(s.right_mean_theta_rad, '%.4f', s)}, "
                   f"{no_estimate_cell(s.right_pos_rmse_cm, '%.2f', s)} | {cell(s.wrong_frame_fraction, '%.2f', 100)} % ({s.runs_with_wrong_frames}) | "
                   f"{no_estimate_cell(s.all_mean_pos_cm, '%.1f', s)} | {s.outside_walls_frames} / {s.outside_walls_any_frames} |")
    return "\n".join(out)
