"""What the results package's tests share: synthetic run and sweep folders written as omniloc writes
them (docs/results.md: summary.json, config.json, frames.csv, aggregate.json), the interpreter and
the built omniloc a test runs, and how it loads a developer's tool from scripts/.
"""
import json
import math
import os
import pathlib
import sys
import importlib.util
from types import ModuleType

import pytest

from omniloc.report import provenance as RPROV

ROOT = pathlib.Path(__file__).resolve().parents[2]
PY = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
# The built omniloc: tests that run it skip, saying why, where it is not given.
OMNILOC = os.path.abspath(os.environ["OMNILOC_BIN"]) if os.environ.get("OMNILOC_BIN") else ""
needs_omniloc = pytest.mark.skipif(not OMNILOC, reason="OMNILOC_BIN is not set: this test runs the built omniloc "
                                   "(ctest results_pytest sets it; by hand: OMNILOC_BIN=build/omniloc)")


def load_script(name: str, folder: pathlib.Path = ROOT / "scripts") -> ModuleType:
    """A developer's tool of scripts/ (check_report_html, icount_compare), or another module of the
    repository outside the package (clients/python's omniloc_recording), by its path."""
    spec = importlib.util.spec_from_file_location(name, folder / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def robot(x_mean, y_mean=1.0, th=0.01, extra=None):
    axis = lambda m: {"mean": m, "std": m / 2, "max": 3 * m}
    r = {"robot": 0, "frames": 100, "x_cm": axis(x_mean), "y_cm": axis(y_mean), "theta_rad": axis(th),
         "position_m": {"mean": x_mean / 125, "rmse": x_mean / 100, "p50": 0, "p90": 0, "p95": 0, "max": 0}, "line_points": {"mean": 80, "min": 50},
         "wrong_frames": 0, "coasting_frames": 0}
    r.update(extra or {})
    return r


def write_run(folder, scenario, localizer, seed, config, rob, version="abc123", start_pose_given=None, external=False, scoring=None):
    """A run folder; start_pose_given None: a run from before omniloc recorded it (no key); scoring:
    summary.json's "scoring" block (SCORING; None: a run from before recall was scored)."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    summary = {"scenario": scenario, "localizer": localizer, "seed": seed, "robots": [rob],
               "omniloc": {"version": version, "compiler": "GNU", "build_type": "Release"}}
    if scoring is not None:
        summary["scoring"] = scoring
    if start_pose_given is not None:
        summary["start_pose_given"] = start_pose_given
    if external:
        summary["localizer_type"] = "external"
    (folder / "summary.json").write_text(json.dumps(summary))
    (folder / "config.json").write_text(json.dumps(dict(config, seed=seed, name=scenario)))


# The coverage keys of a current summary.json (docs/results.md "Coverage and recall").
SCORING = {"recall": [{"position_m": 0.1, "heading_deg": 5.0}, {"position_m": 0.25, "heading_deg": 10.0},
                      {"position_m": 0.5, "heading_deg": 20.0}], "headline": "25cm_10deg"}


RECALL_KEYS = ("10cm_5deg", "25cm_10deg", "50cm_20deg")


def scored(rob, answered=1.0, within=1.0, total=100):
    """robot() with the coverage a current omniloc writes: frames_total, valid_fraction, recall."""
    return dict(rob, frames=round(answered * total), frames_total=total, valid_fraction=answered, recall=dict.fromkeys(RECALL_KEYS, within),
                first_estimate_s=0.0, first_within_s=0.0 if within else None)


def without_estimate(total=100):
    """A robot block of a run whose localizer answered none of its frames, as omniloc writes it:
    every error statistic null (never 0), why_null beside them, recall and valid_fraction 0."""
    r = robot(1.0)
    for axis in ("x_cm", "y_cm", "theta_rad"):
        r[axis] = dict.fromkeys(("mean", "std", "max"))
    r["position_m"] = dict.fromkeys(("mean", "rmse", "p50", "p90", "p95", "max"))
    r.update(theta_rmse_rad=None, frames=0, frames_total=total, valid_fraction=0.0, recall=dict.fromkeys(RECALL_KEYS, 0.0),
             why_null=f"no estimate in any of the {total} scored frames", first_estimate_s=None, first_within_s=None)
    return r


OCCLUSION = {0.0: 2.0, 0.125: 2.5, 0.25: 3.0, 0.5: 4.0}  # mean x cm per fraction (+ seed / 100)


def write_occlusion_sweep(folder, order, seeds=(1, 2, 3)):
    """A sweep folder like scenarios/sweeps/occlusion_002.json's, its runs written in `order`."""
    folder = pathlib.Path(folder)
    lines = ["index,id,scenario,localizer,params,seed,status"]
    k = 0
    for frac in order:
        for s in seeds:
            rid = f"tracking__matching__occ{frac}__s{s}"
            cfg = {} if frac == 0.0 else {"occlusion": {"fraction": frac, "sectors": 2}}
            write_run(folder / "runs" / rid, "tracking", "matching", s, cfg, robot(OCCLUSION[frac] + s / 100))
            params = json.dumps({"fraction": frac}, separators=(",", ":"))
            lines.append(",".join([str(k), rid, "tracking", "matching", '"occlusion=' + params.replace('"', '""') + '"', str(s), "ok"]))
            k += 1
    (folder / "runs.csv").write_text("\n".join(lines) + "\n")
    (folder / "aggregate.json").write_text(json.dumps({"sweep": "occ", "runs": k, "groups": []}))


def write_frames(folder, rows, events=()):
    """frames.csv (robot 0) from (t, err_pos m, valid, mode) and events.jsonl for an outlier's cause."""
    folder = pathlib.Path(folder)
    head = "t,robot,gt_x,gt_y,gt_theta,est_x,est_y,est_theta,err_x,err_y,err_theta,err_pos,valid,mode"
    lines = [head] + [f"{t},0,0,0,0,0,0,0,{e},0,0,{e},{1 if v else 0},{m}" for t, e, v, m in rows]
    (folder / "frames.csv").write_text("\n".join(lines) + "\n")
    (folder / "events.jsonl").write_text("".join(json.dumps(e) + "\n" for e in events))


def mcl_runs_with_outlier(folder):
    """Three MCL seeds on the tracking path: 3.0, 806.0 (converged to a wrong pose), 3.1 cm."""
    folder = pathlib.Path(folder)
    for seed, x in ((1, 3.0), (2, 806.0), (3, 3.1)):
        write_run(folder / f"mcl_s{seed}", "tracking", "mcl", seed, {}, robot(x))
    write_frames(folder / "mcl_s2", [(0.0, 6.7, False, "global")] + [(0.5 * k, 8.06, True, "converged") for k in range(1, 11)])


def report_cpu():
    return RPROV.cpu_model()


REAL = ROOT / "data" / "real" / "nubot"


def real_reference(robot):
    return json.loads((REAL / robot / "recording.json").read_text())["reference"]


def write_real_run(folder, frame, label, seed, estimates, localizer=None, config=None):
    """A run folder of a replay of the real recording data/real/nubot/<frame> (as omniloc writes
    one): frames.csv at 30 Hz with the reference pose as truth and `estimates`, one (x, y, theta) or
    None (no estimate) per frame."""
    folder = pathlib.Path(folder) / f"nubot_{frame}__{label}__recording__s{seed}"
    ref = real_reference(frame)["reference"]
    n = len(estimates)
    answered = sum(e is not None for e in estimates)
    write_run(folder, f"nubot_{frame}", localizer or label, seed, config or {"localizer": {"type": localizer or label}},
              scored(robot(1.0), answered=answered / n, within=0.0, total=n), start_pose_given=False, scoring=SCORING)
    summary = json.loads((folder / "summary.json").read_text())
    summary["omniloc"]["replay"] = {"format": "omniloc-recording/1", "recorded_seed": 1, "recorded_with": "not omniloc",
                                    "recording": str(REAL / frame)}
    (folder / "summary.json").write_text(json.dumps(summary))
    head = "t,robot,gt_x,gt_y,gt_theta,est_x,est_y,est_theta,err_x,err_y,err_theta,err_pos,valid,mode"
    lines = [head]
    for k, e in enumerate(estimates):
        est = e if e is not None else (0.0, 0.0, 0.0)
        err = math.hypot(est[0] - ref[0], est[1] - ref[1])
        lines.append(f"{k / 30:.4f},0,{ref[0]},{ref[1]},{ref[2]},{est[0]},{est[1]},{est[2]},0,0,0,{err},{1 if e is not None else 0},"
                     + ("converged" if e is not None else "global"))
    (folder / "frames.csv").write_text("\n".join(lines) + "\n")
    return folder


def write_sim_recording(sweep, profile="robot"):
    """A sweep folder holding one recording of the tracking path (as `omniloc sweep` draws it into
    recordings/) with one frame of hand-placed line points, robot at (-4.5, 0, 0) on msl2012, whose
    distances to the nearest marking are known: 0-1.5 m: 22.5 cm (the penalty spot's rim);
    1.5-3 m: 5 and 4 cm; 3-5 m: 0 and 3 cm (the centre line); 5-7.5 m: 5 and 10 cm (the touch lines).
    A second frame without a usable image is left out."""
    sweep = pathlib.Path(sweep)
    rec = sweep / "recordings" / "tracking__s1__0123456789abcdef"
    rec.mkdir(parents=True)
    (sweep / "runs.csv").write_text("index,id,scenario,localizer,params,seed,status\n")
    (sweep / "aggregate.json").write_text(json.dumps({"sweep": sweep.name, "runs": 0, "groups": []}))
    head = {"format": "omniloc-recording/1", "name": "tracking", "seed": 1, "field": "msl2012", "camera_rate_hz": 30.0, "duration_s": 0.1,
            "frames": 2, "frames_file": "frames.jsonl", "ground_truth": True, "robots": [{"id": 0}],
            "scenario": {"name": "tracking", "noise_profile": profile, "field": "msl2012"}}
    (rec / "recording.json").write_text(json.dumps(head))
    pts = [[-1.2, 0.0], [-2.2, 0.0], [2.46, 0.0], [4.5, 0.5], [4.53, 0.5], [0.0, 5.95], [0.0, -5.9]]
    frames = [{"k": 0, "t": 0.0, "robots": [{"robot": 0, "odometry": [0, 0, 0], "heading": 0.0, "camera_ok": True, "line_points": pts,
                                             "truth": [-4.5, 0.0, 0.0]}]},
              {"k": 1, "t": 0.0333, "robots": [{"robot": 0, "odometry": [0, 0, 0], "heading": 0.0, "camera_ok": False, "line_points": [[3.0, 3.0]],
                                                "truth": [-4.5, 0.0, 0.0]}]}]
    (rec / "frames.jsonl").write_text("".join(json.dumps(f) + "\n" for f in frames))
    return sweep


def write_viewable_run(folder, scenario="quickstart", localizer="odometry_only", seed=1, frames=30, rob=None):
    """A run folder holding what the run viewer (omniloc.view) reads, as omniloc writes it: field.json,
    frames.csv, gt.tum, est.tum (every frame answered) and events.jsonl beside summary.json and
    config.json; the robot drives along x at 1 m/s, its estimate 2 cm to the side."""
    folder = pathlib.Path(folder)
    write_run(folder, scenario, localizer, seed, {"localizer": {"type": localizer}}, rob or scored(robot(2.0)), start_pose_given=True,
              scoring=SCORING)
    (folder / "field.json").write_text(json.dumps({"name": "msl2012", "length": 18.0, "width": 12.0, "margin": 1.0, "line_width": 0.125,
                                                   "segments": [[-9.0, -6.0, 9.0, -6.0], [-9.0, 6.0, 9.0, 6.0], [0.0, -6.0, 0.0, 6.0]],
                                                   "arcs": [[0.0, 0.0, 2.0, 0.0, 6.283185307179586]], "goals": [[-9.0, 2.0, 0.6], [9.0, 2.0, 0.6]]}))
    head = "t,robot,gt_x,gt_y,gt_theta,est_x,est_y,est_theta,err_x,err_y,err_theta,err_pos,valid,mode,camera_ok,line_points,match_error,contact"
    rows, gt, est = [head], [], []
    for k in range(frames):
        t, x = k / 30, -2.0 + k / 30
        rows.append(f"{t:.4f},0,{x:.5f},0.00000,0.00000,{x:.5f},0.02000,0.00000,0.00000,0.02000,0.00000,0.02000,1,tracking,1,80,0.01,0")
        gt.append(f"{t:.6f} {x:.6f} 0.000000 0 0 0 0.000000000 1.000000000")
        est.append(f"{t:.6f} {x:.6f} 0.020000 0 0 0 0.000000000 1.000000000")
    (folder / "frames.csv").write_text("\n".join(rows) + "\n")
    (folder / "gt.tum").write_text("\n".join(gt) + "\n")
    (folder / "est.tum").write_text("\n".join(est) + "\n")
    (folder / "events.jsonl").write_text(json.dumps({"mode": "tracking", "robot": 0, "t": 0.0, "type": "mode"}) + "\n")
    return folder


def limit_blocks(rmse_m, efficiency=1.3, share=0.97, scored_frames=100, heading_efficiency=1.1, against="posterior"):
    """summary.json's blocks of the accuracy limit for one robot (docs/results.md), as omniloc writes
    them: a bound `efficiency` times below the RMSE over `share` of the scored frames, the frames
    without one said with their reasons, the noise it assumed, and the relative pose error."""
    frames = round(share * scored_frames)
    bound_m = rmse_m / efficiency
    figure = {"position_rms_m": bound_m, "heading_rms_rad": 0.004, "frames": frames, "share": share}
    single = dict(figure, position_rms_m=bound_m * 1.4, heading_rms_rad=0.006)
    missing = scored_frames - frames
    return {"bound": {"single_frame": single, "posterior": figure,
                      "no_bound": {"frames": missing, "why": {"points on one line": missing} if missing else {}},
                      "noise": {"bands_m": [0, 1.5, 3, 5, 7.5], "measured_sigma_m": [0.032, 0.042, 0.087, 0.2],
                                "declared_sigma_m": [0.03, 0.04, 0.08, None], "points": 9000, "false_points": 12,
                                "common_mode": {"sigma_rad": 0.002}},
                      "assumptions": "known association, the measured noise, unbiased estimators"},
            "efficiency": {"position": efficiency, "heading": heading_efficiency, "against": against, "frames": frames, "share": share,
                           "rmse_m": rmse_m, "bound_rms_m": bound_m, "heading_rmse_rad": 0.004 * heading_efficiency, "heading_bound_rms_rad": 0.004},
            "efficiency_single_frame": {"position": efficiency / 1.4, "heading": heading_efficiency / 1.5, "against": "single_frame",
                                        "frames": frames, "share": share},
            "rpe": {"frame": {"translation_rms_m": 0.004, "rotation_rms_rad": 0.001, "pairs": scored_frames - 1},
                    "1s": {"translation_rms_m": 0.03, "rotation_rms_rad": 0.008, "pairs": scored_frames - 30}}}


def no_limit_blocks(scored_frames=100, why="no truth to place the line points at"):
    """The accuracy limit's blocks of a run where no frame has a bound (a recording without truth):
    every figure null with the reason, never 0."""
    null_fig = {"position_rms_m": None, "heading_rms_rad": None, "frames": 0, "share": 0.0}
    eff = {"position": None, "heading": None, "against": "posterior", "frames": 0, "share": 0.0, "why_null": why}
    return {"bound": {"single_frame": null_fig, "posterior": null_fig,
                      "no_bound": {"frames": scored_frames, "why": {why: scored_frames}}, "noise": None, "assumptions": None},
            "efficiency": eff, "efficiency_single_frame": dict(eff, against="single_frame"),
            "rpe": {"frame": {"translation_rms_m": 0.004, "rotation_rms_rad": 0.001, "pairs": scored_frames - 1},
                    "1s": {"translation_rms_m": 0.03, "rotation_rms_rad": 0.008, "pairs": scored_frames - 30}}}
