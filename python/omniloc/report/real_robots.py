"""The report's "Real robots" section: omniloc's localizers on real robots' frames, and the
sim-to-real check of the line-point noise. A section of omniloc.report.

Real-robot runs are replays of a recording whose header carries a reference pose found by an
exhaustive search ("reference": {"reference", "twin", ...}; data/real/nubot/README.md,
omniloc.data.nubot): the four NuBot calibration frames of data/real/nubot, each one real
frame held for 10 s, robot standing still, no compass, no start pose. scenarios/sweeps/real_robots.json
replays them with the global localizers. The field is point-symmetric, so without a compass the twin
(-x, -y, theta + pi) is as right as the reference; summary.json scores against the reference only (a
localizer on the twin shows about 9 m there), so each run is classified here from its frames.csv:

  found  the final estimate lies within FIX_M (0.25 m) and FIX_DEG (10 deg) of the reference;
  twin   within them of the twin;
  wrong  neither;
  no estimate at the end: the last frame has no valid estimate.

Beside it: the final error against the nearer of reference and twin, the share of frames answered, and
the time to the first fix (the first valid frame within 0.25 m / 10 deg of either).

The noise check: the distance of each line point, placed with the pose it was seen from, to the
nearest marking's centre line (omniloc.data.nubot.distance_to_markings, the distance omniloc's
distance map holds), by range from the robot, median and 90th percentile. Real: the recording's own
points at its reference pose (the same figures as its header's reference.line_point_noise). Simulated:
the tracking path's recordings that sweeps draw into <sweep>/recordings/ (docs/recording.md "Sweeps"),
every frame, at the true pose, per noise profile (robot: results/sweeps/paper_suite; field_robot:
results/sweeps/paper_suite_field_robot).
"""
from __future__ import annotations

import math
import pathlib
import re
import statistics
from dataclasses import dataclass
from typing import Callable, Optional, Sequence

import numpy as np

from omniloc.core import metrics, paths, recording
from omniloc.core.framedata import pairs
from omniloc.core.jsonvalue import JSON, number, numbers, obj
from omniloc.core.recording import RecordingHeader
from omniloc.core.rundir import Run
from omniloc.data import nubot
from omniloc.report import viewers
from omniloc.report.runs import run_title
from omniloc.tools.markup import Cell, Writer


FIX_M, FIX_DEG = 0.25, 10.0


BANDS = ((0.0, 1.5), (1.5, 3.0), (3.0, 5.0), (5.0, 7.5))


REAL_DATA = paths.ROOT / "data" / "real" / "nubot"


RUN_REAL = "build/omniloc sweep scenarios/sweeps/real_robots.json -j 2"


RUN_SIM = {"robot": "build/omniloc sweep scenarios/sweeps/paper_suite.json -j 2",
           "field_robot": "build/omniloc sweep scenarios/sweeps/paper_suite_field_robot.json -j 2"}


PROFILES = ("robot", "field_robot")


# Row order: the defaults first, then variants (paper 002's MCL as published).
ORDER = ("mcl", "hybrid", "grid_global")


# recording.json of the recordings this report has read, by folder (None: not a readable one).
HEADERS: dict[pathlib.Path, Optional[RecordingHeader]] = {}


@dataclass(frozen=True)
class Judgement:
    """A real-robot run classified from its frames.csv (judge()): found / twin / wrong / none, the
    final estimate's error to the nearer of reference and twin, the share answered, the time of the
    first fix (None: never) and the frame count."""
    outcome: str
    error_m: float
    error_deg: float
    answered: float
    first_fix_s: Optional[float]
    frames: int


@dataclass(frozen=True)
class Band:
    """The line points of one range band (bands()): how many, and the median and 90th percentile of
    their distance to the nearest marking (cm; None without points)."""
    range_m: list[float]
    points: int
    median_cm: Optional[float]
    p90_cm: Optional[float]


@dataclass(frozen=True)
class RealRun:
    """A run that replayed a real recording with a reference pose: the recording's folder and
    header, the localizer's row name, and the run classified."""
    run: Run
    folder: pathlib.Path
    header: RecordingHeader
    label: str
    judged: Judgement


def read_header(folder: pathlib.Path) -> Optional[RecordingHeader]:
    """recording.json of a recording folder (read once per report), or None."""
    if folder not in HEADERS:
        HEADERS[folder] = recording.read_header(folder)
    return HEADERS[folder]


def has_reference(header: Optional[RecordingHeader]) -> bool:
    return header is not None and header.reference is not None


def recording_of(run: Run) -> Optional[tuple[pathlib.Path, RecordingHeader]]:
    """(folder, header) of the real recording a run replayed, or None: summary.json's
    omniloc.replay.recording, else (results made on another machine) the shipped folder of that name."""
    path = run.summary.replay.get("recording")
    if not isinstance(path, str):
        return None
    for folder in (pathlib.Path(path), REAL_DATA / pathlib.Path(path).name):
        h = read_header(folder)
        if h is not None and has_reference(h):
            return folder, h
    return None


def label_of(run: Run) -> str:
    """The localizer's row name: the sweep's label (run id <scenario>__<label>__recording__s<seed>),
    else the localizer type."""
    m = re.fullmatch(re.escape(str(run.scenario)) + r"__(.+)__recording__s\d+", run.folder.name)
    return m.group(1) if m else str(run.localizer)


def as_published(run: Run) -> bool:
    """Whether the run is MCL with adapt_to_no_compass false: paper 002's MCL whatever the sensors."""
    loc = obj(run.config.get("localizer") or {})
    return loc.get("type") == "mcl" and loc.get("adapt_to_no_compass") is False


def frame_name(folder: pathlib.Path) -> str:
    """data/real/nubot/robot1 (relative to the repository), or the folder's last three parts."""
    folder = pathlib.Path(folder).resolve()
    try:
        return folder.relative_to(paths.ROOT).as_posix()
    except ValueError:
        return "/".join(folder.parts[-3:])


def wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


Pose = tuple[float, float, float]


def off(est: Sequence[float], pose: Sequence[float]) -> tuple[float, float]:
    """(metres, degrees) from est to pose."""
    return math.hypot(est[0] - pose[0], est[1] - pose[1]), abs(math.degrees(wrap(est[2] - pose[2])))


def within(d: tuple[float, float]) -> bool:
    return d[0] <= FIX_M and d[1] <= FIX_DEG


def judge(run: Run, reference: Optional[Sequence[float]] = None) -> Optional[Judgement]:
    """A run's outcome from its frames.csv (robot 0): found / twin / wrong / none, the final
    estimate's error to the nearer of reference and twin, the share answered, the first fix. The
    reference is the frames' truth (what the run was scored against) unless given; the twin is (-x,
    -y, theta + pi). None without frames."""
    rows = [f for f in run.frames() if f.get("robot", "0") == "0"]
    if not rows:
        return None

    def num(f: dict[str, str], k: str) -> float:
        return float(f[k])
    ref = tuple(reference) if reference else (num(rows[0], "gt_x"), num(rows[0], "gt_y"), num(rows[0], "gt_theta"))
    twin = (-ref[0], -ref[1], wrap(ref[2] + math.pi))
    t0 = num(rows[0], "t")
    valid = [f for f in rows if f.get("valid") == "1"]
    first = None
    for f in valid:
        est = (num(f, "est_x"), num(f, "est_y"), num(f, "est_theta"))
        if within(off(est, ref)) or within(off(est, twin)):
            first = num(f, "t") - t0
            break
    last = rows[-1]
    est = (num(last, "est_x"), num(last, "est_y"), num(last, "est_theta"))
    dr, dt = off(est, ref), off(est, twin)
    near = min(dr, dt)
    if last.get("valid") != "1":
        outcome = "none"
    else:
        outcome = "found" if within(dr) else "twin" if within(dt) else "wrong"
    return Judgement(outcome=outcome, error_m=near[0], error_deg=near[1], answered=len(valid) / len(rows), first_fix_s=first, frames=len(rows))


def real_runs(runs: list[Run]) -> list[RealRun]:
    """The runs that replay a real recording with a reference, each classified."""
    out = []
    for run in runs:
        rec = recording_of(run)
        if rec is None:
            continue
        ref = rec[1].reference
        j = judge(run, ref.reference if ref else None)
        if j is not None:
            out.append(RealRun(run=run, folder=rec[0], header=rec[1], label=label_of(run), judged=j))
    return out


def markings_of(header: RecordingHeader) -> nubot.Markings:
    """The field markings of a recording: its own field_markings, else drawn from its field."""
    fm = header.field_markings
    return nubot.field_markings(fm if fm is not None and "segments" in fm else header.raw.get("field", "msl2012"))


# A frame of a recording as the noise check reads it: the pose (truth) and the line points (N, 2).
PosedPoints = tuple[list[float], "np.ndarray"]


def frames_of(header: RecordingHeader, limit: Optional[int] = None) -> list[PosedPoints]:
    """The frames of a recording (robot 0): [(truth, line points (N, 2))], frames without a usable
    image, without truth or without points left out; at most `limit` of them."""
    out: list[PosedPoints] = []
    for frame in recording.read_frames(header):
        if limit is not None and len(out) >= limit:
            break
        r = frame.robot(0)
        truth = numbers(r.get("truth"))
        if r.get("camera_ok", True) and r.get("truth") and r.get("line_points") and truth is not None:
            points = pairs(r["line_points"], header.frames_path, frame.line, "line_points")
            out.append((truth, np.asarray(points, dtype=float).reshape(-1, 2)))
    return out


def distances(markings: nubot.Markings, frames: Sequence[PosedPoints]) -> tuple["np.ndarray", "np.ndarray"]:
    """(distance to the nearest marking's centre line, range from the robot) of every point of the
    frames, each placed with its frame's pose."""
    ds, rs = [], []
    for pose, pts in frames:
        wx, wy = nubot.world_points(pose, pts)
        ds.append(nubot.distance_to_markings(markings, wx, wy))
        rs.append(np.hypot(pts[:, 0], pts[:, 1]))
    return (np.concatenate(ds), np.concatenate(rs)) if ds else (np.zeros(0), np.zeros(0))


def bands(d: "np.ndarray", r: "np.ndarray") -> list[Band]:
    """Per range band: its range, points, median and 90th percentile (as the real recordings' headers
    give them, numpy's median and linear 90th percentile, but not rounded)."""
    out = []
    for lo, hi in BANDS:
        sel = (r >= lo) & (r < hi)
        n = int(sel.sum())
        out.append(Band(range_m=[lo, hi], points=n, median_cm=float(np.median(d[sel])) * 100 if n else None,
                        p90_cm=float(np.percentile(d[sel], 90)) * 100 if n else None))
    return out


def real_noise(header: RecordingHeader) -> list[Band]:
    """The real frame's bands: its first frame's points (every frame holds the same) at the reference pose."""
    frames = frames_of(header, limit=1)
    pose = header.reference.reference if header.reference else []
    return bands(*distances(markings_of(header), [(pose, pts) for _, pts in frames]))


def sim_recordings(sweeps: list[pathlib.Path]) -> dict[str, list[pathlib.Path]]:
    """{profile: [recording folders]}: the tracking path without occlusion, drawn by the given sweeps
    into their recordings/ folders (docs/recording.md "Sweeps")."""
    out: dict[str, list[pathlib.Path]] = {}
    for sw in sweeps:
        for rec in sorted(pathlib.Path(sw).glob("recordings/*/recording.json")):
            h = read_header(rec.parent)
            sc = h.scenario if h is not None else None
            if h is None or sc is None or h.name != "tracking" or not h.ground_truth:
                continue
            occ = sc.get("occlusion")
            if isinstance(occ, dict) and (number(occ.get("fraction", 0)) or 0) > 0:
                continue
            out.setdefault(str(sc.get("noise_profile", "robot")), []).append(rec.parent)
    return out


def sim_noise(folders: Sequence[pathlib.Path]) -> tuple[list[Band], int, list[JSON]]:
    """(bands, frames, seeds) over every frame of the given simulated recordings, pooled."""
    d: list["np.ndarray"] = []
    r: list["np.ndarray"] = []
    nframes = 0
    seeds: list[JSON] = []
    for folder in folders:
        h = read_header(folder)
        if h is None:
            continue
        frames = frames_of(h)
        nframes += len(frames)
        if h.seed not in seeds:
            seeds.append(h.seed)
        di, ri = distances(markings_of(h), frames)
        d.append(di)
        r.append(ri)
    return bands(np.concatenate(d), np.concatenate(r)), nframes, sorted((s for s in seeds if s is not None), key=seed_order)


def seed_order(seed: JSON) -> float:
    """A recording's seed as a sort key (its number)."""
    return float(seed) if isinstance(seed, (int, float)) else math.inf


def cm_or_m(m: float) -> str:
    return f"{m * 100:.1f} cm" if m < 1.0 else f"{m:.2f} m"


OUTCOME = {"found": "found", "twin": "twin", "wrong": "wrong", "none": "no estimate at the end"}


def outcome_cell(js: Sequence[Judgement]) -> str:
    """'found' for one run; '4 of 5 found or twin (3 found, 1 twin, 1 wrong)' for several."""
    if len(js) == 1:
        return OUTCOME[js[0].outcome]
    counts = {k: sum(j.outcome == k for j in js) for k in OUTCOME}
    good = counts["found"] + counts["twin"]
    return f"{good} of {len(js)} found or twin (" + ", ".join(f"{counts[k]} {OUTCOME[k]}" for k in OUTCOME if counts[k]) + ")"


def spread_cell(vals: Sequence[float], fmt: Callable[[float], str]) -> str:
    """One run's value, or 'median a (max b)' of several."""
    if len(vals) == 1:
        return fmt(vals[0])
    return f"median {fmt(statistics.median(vals))} (max {fmt(max(vals))})"


def fix_cell(js: Sequence[Judgement]) -> str:
    fixes = [j.first_fix_s for j in js if j.first_fix_s is not None]
    never = len(js) - len(fixes)
    if not fixes:
        return "never"
    cell = spread_cell(fixes, lambda v: f"{v:.2f} s")
    return cell + (f"; never in {never} of {len(js)}" if never else "")


def row_name(label: str, runs: Sequence[RealRun]) -> str:
    return label + (" (paper 002's 600-particle MCL as published: `adapt_to_no_compass` false)"
                    if runs and all(as_published(x.run) for x in runs) else "")


def viewer_cell(rep: Writer, xs: Sequence[RealRun]) -> str:
    """The runs' viewer pages: 'view' for one run, 's1, s2' (each a link) for several; '-' without."""
    if len(xs) == 1:
        return viewers.cell(rep, xs[0].run, own=True, title=run_title(xs[0].run))
    cells = [(x.run.seed, viewers.cell(rep, x.run, f"s{x.run.seed}", own=True, title=run_title(x.run))) for x in xs]
    return ", ".join(c if c != "-" else f"s{seed}: -" for seed, c in cells)


def section(rep: Writer, runs: list[Run], sweeps: list[pathlib.Path]) -> list[Run]:
    """The "Real robots" section (omniloc.report.assemble calls it after the scorecard). Returns the runs it
    classified (the caller leaves them out of the pooled error CDF: their error there is against
    the reference only)."""
    real = real_runs(runs)
    rep.heading("Real robots", 2, "real-robots")
    rep.para("The only real data in this report: four real omnidirectional-camera frames of NuBot robots (RoboCup Middle Size League; "
             "data/real/nubot/README.md: source, licence, conversion), each one real frame held for 10 s (300 frames at 30 Hz), robot standing "
             "still, no compass, no start pose. The truth of each recording is a **reference pose** found by an exhaustive search over the "
             "whole floor (scripts/nubot_reference_pose.py: every 5 cm and 1 deg, then refined), not by any localizer under test; nobody measured "
             "the robot's pose. The field is point-symmetric, so without a compass the twin (-x, -y, theta + 180 deg) fits the points exactly as "
             "well and is an equally correct answer.")
    if not real:
        rep.para(f"**Not run**: no replay of a real recording among these results. Run `{RUN_REAL}` (a few seconds; it writes "
                 "results/sweeps/real_robots) and give that folder to omniloc report; scripts/run.sh does both.")
    else:
        groups: dict[tuple[str, str], list[RealRun]] = {}
        for x in real:
            groups.setdefault((x.label, str(x.folder)), []).append(x)
        labels = sorted({k[0] for k in groups}, key=lambda l: (ORDER.index(l) if l in ORDER else len(ORDER), l))
        rows: list[list[Cell]] = []
        for label in labels:
            for (lab, folder), xs in sorted(groups.items(), key=lambda kv: kv[0][1]):
                if lab != label:
                    continue
                xs = sorted(xs, key=lambda x: x.run.seed or 0)
                js = [x.judged for x in xs]
                seeds = ", ".join(str(x.run.seed) for x in xs)
                rows.append([row_name(label, xs), frame_name(pathlib.Path(folder)), seeds, outcome_cell(js),
                             spread_cell([j.error_m for j in js], cm_or_m), spread_cell([j.error_deg for j in js], lambda v: f"{v:.1f} deg"),
                             spread_cell([j.answered for j in js], metrics.percent), fix_cell(js), viewer_cell(rep, xs)])
        rep.table(["localizer", "real frame", "seeds", "final estimate", "final error from the nearer of reference and twin",
                   "heading error", "answered", "first fix", "viewer"], rows,
                  f"Each run classified from its frames.csv: **found**: the final estimate lies within {FIX_M:g} m and {FIX_DEG:g} deg of the "
                  f"reference pose; **twin**: within them of its twin; **wrong**: neither; 'no estimate at the end': the last frame has none. "
                  "The final error is measured to the nearer of reference and twin; 'answered': the share of frames with an estimate; "
                  f"'first fix': the time of the first answered frame within {FIX_M:g} m / {FIX_DEG:g} deg of either ('never': none). "
                  "With several seeds a cell counts the runs and gives the median and maximum over them. 'viewer': each run's viewer page (frame by frame), "
                  "one link per seed.")
        tot: list[list[Cell]] = []
        for label in labels:
            xs = [x for (lab, _), v in groups.items() if lab == label for x in v]
            js = [x.judged for x in xs]
            c = {k: sum(j.outcome == k for j in js) for k in OUTCOME}
            tot.append([row_name(label, xs), len(js), len({str(x.folder) for x in xs}), c["found"], c["twin"], c["wrong"], c["none"],
                        f"{c['found'] + c['twin']} of {len(js)}", fix_cell(js)])
        rep.table(["localizer", "runs", "real frames", "found", "twin", "wrong", "no estimate at the end", "found or twin", "first fix"], tot,
                  "Per localizer over every real frame and seed.")
        rep.para("summary.json and the sweep's own table below score every run against the reference only, so a run on the twin shows an "
                 "error of about 9 m there; read the outcome from this section. These runs are left out of the pooled error CDF and "
                 "timing further down for that reason. `matching` is not run: it needs a start pose, and these recordings have none. "
                 "A sweep replays a recording at the recording's own seed (1); other seeds: `omniloc replay DIR --localizer L --seed N -o OUT`, "
                 "whose run folders this section counts as further seeds.")
    noise_table(rep, real, sweeps)
    return [x.run for x in real]


def noise_table(rep: Writer, real: Sequence[RealRun], sweeps: list[pathlib.Path]) -> None:
    """Real line points against the simulated profiles', by range band."""
    rep.heading("Line-point noise: real frames against the simulated profiles", 3, "real-noise")
    folders = {str(x.folder): (x.folder, x.header) for x in real}
    if not folders:  # no runs: the shipped frames still give the real figures (nothing to run for them)
        for f in sorted(REAL_DATA.glob("robot*")):
            h = read_header(f)
            if h is not None and has_reference(h):
                folders[str(f)] = (f, h)
    real_cols = [(f"real: {pathlib.Path(f).name}", real_noise(h)) for f, h in sorted(folders.values(), key=lambda v: str(v[0]))]
    sims = sim_recordings(sweeps)
    sim_cols: list[tuple[str, list[Band], str]] = []
    missing: list[str] = []
    for prof in PROFILES:
        if sims.get(prof):
            b, nframes, seeds = sim_noise(sims[prof])
            n = len(sims[prof])
            sim_cols.append((f"simulated: {prof} profile", b, f"{prof}: {n} recording{'s' if n != 1 else ''} of the tracking path (seed"
                             f"{'s' if len(seeds) != 1 else ''} {', '.join(map(str, seeds))}), every frame, {nframes} frames"))
        else:
            missing.append(prof)
    def cell(b: Band) -> str:
        return f"{b.points}: {b.median_cm:.1f} / {b.p90_cm:.1f}" if b.points else "0 points"
    header = ["range m"] + [name for name, _ in real_cols] + [name for name, _, _ in sim_cols] + [f"simulated: {p} profile" for p in missing]
    rows: list[list[Cell]] = []
    for k, (lo, hi) in enumerate(BANDS):
        rows.append([f"{lo:g}-{hi:g}", *[cell(b[k]) for _, b in real_cols], *[cell(b[k]) for _, b, _ in sim_cols], *(["not run"] * len(missing))])
    rep.table(header, rows,
              "Distance of each line point, placed with the pose it was seen from, to the nearest marking's centre line (lines, circle and "
              "arcs, filled spots: the distance omniloc's distance map holds; scripts/nubot_reference_pose.py), by range from the robot: "
              "each cell 'points: median / 90th percentile' in cm. Real: the line points of each recording of "
              f"{frame_name(REAL_DATA)} at its reference pose (the figures its header carries under `reference.line_point_noise`). "
              "Simulated: the line points omniloc's vision found in "
              "the sweeps' recordings of the tracking path (the sweep folder's recordings/, docs/recording.md), at the true pose"
              + ("; " + "; ".join(t for _, _, t in sim_cols) if sim_cols else "") + ".")
    if missing:
        rep.para("Not run: " + "; ".join(f"the {p} profile's figures need the recordings of `{RUN_SIM[p]}` (its folder given to omniloc report)"
                                         for p in missing) + ".")
    rep.para("The real figures are a **lower bound** on real line-point noise: NuBot fitted each mirror law (and a pose) to these very pixels, "
             "the reference pose is the best fit of these same points, and a standing calibration frame has no camera vibration, latency "
             "or motion blur; the pixels also look cleaned (no robot or ball pixels), and none lies nearer than 2.3 m (so the first band "
             "is empty).")
