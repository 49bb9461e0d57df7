"""Real NuBot frames (data/real/nubot/, scripts/nubot_to_recording.py, omniloc.data.nubot and
omniloc.data.nubot_frames).

    OMNILOC_BIN=build/omniloc PYTHONPATH=python /usr/bin/python3 -m pytest python/tests/test_real_frames.py

(a) The converter and the reference search on a synthetic NuBot calibration folder written here: a
    known pose, the field's line centres seen from it within 1-6 m, turned into integer image pixels
    through the inverse mirror law (with a centre offset and a correction, like NuBot's files) plus 5 %
    stray pixels; the converted recording's reference must be the known pose (or its 180-degree twin)
    within 3 cm / 0.5 deg. Also the pixel -> robot-frame conventions (column = forward, row = left)
    and the field markings against the ones omniloc wrote into data/recordings/ci_tracking/1.
(b) Every shipped real recording: header and frames as docs/recording.md section 6 wants them, the
    reference's residual recomputed from the points, and `omniloc replay` with the defaults of every
    built-in global localizer, grid_global, hybrid and mcl (which adapts to the missing compass: at
    most 5000 KLD-adaptive particles, clamp 2 m): each must end within 0.25 m / 10 deg of the
    reference or its twin (without a compass the two are the same picture). MCL as paper 002 sets
    it (600 particles, clamp 0.6 m) is run and reported, not asserted (it ends on a wrong pose on
    most of these frames: data/real/nubot/README.md).

Each test runs all of its checks, prints each, and fails naming every check that failed; (b) needs
OMNILOC_BIN and skips without it.
"""
import json
import math
import os
import subprocess

import numpy as np

from helpers import OMNILOC, PY, ROOT, load_script, needs_omniloc
from omniloc.data import nubot as P
from omniloc.data import nubot_frames as NF

omniloc_recording = load_script("omniloc_recording", ROOT / "clients" / "python")  # the recording format's reader

REAL = os.path.join(str(ROOT), "data", "real", "nubot")
# Paper 002's MCL whatever the sensors: 600 particles, 0.6 m clamp, no KLD (run and reported only).
MCL_PAPER = {"type": "mcl", "adapt_to_no_compass": False}


class Checks:
    """Every check of a test runs and is printed; the test fails at the end naming those that failed."""

    def __init__(self):
        self.failed = []

    def __call__(self, name, ok, detail=""):
        if not ok:
            self.failed.append(name)
        print(("ok   " if ok else "FAIL ") + name + (f"  ({detail})" if detail else ""), flush=True)

    def done(self):
        assert not self.failed, "failed: " + "; ".join(self.failed)


def wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def near(p, q, metres, degrees):
    return math.hypot(p[0] - q[0], p[1] - q[1]) <= metres and abs(wrap(p[2] - q[2])) <= math.radians(degrees)


# ---------------------------------------------------------------------------------------------------
# (a) synthetic


def marking_samples(m, step=0.02):
    pts = []
    for x1, y1, x2, y2 in m["segments"]:
        n = max(1, int(math.hypot(x2 - x1, y2 - y1) / step))
        t = np.linspace(0.0, 1.0, n + 1)
        pts.append(np.c_[x1 + t * (x2 - x1), y1 + t * (y2 - y1)])
    for cx, cy, r, start, sweep in m["arcs"]:
        n = max(2, int(abs(sweep) * r / step))
        a = start + np.linspace(0.0, sweep, n + 1)
        pts.append(np.c_[cx + r * np.cos(a), cy + r * np.sin(a)])
    return np.vstack(pts)


def write_synthetic_calib(folder, pose, law, rng):
    m = P.field_markings("msl2012")
    w = marking_samples(m)
    x, y, th = pose
    c, s = math.cos(th), math.sin(th)
    dx, dy = w[:, 0] - x, w[:, 1] - y
    robot = np.c_[c * dx + s * dy, -s * dx + c * dy]
    r = np.hypot(robot[:, 0], robot[:, 1])
    robot = robot[(r >= 1.0) & (r <= 6.0)]
    pix = np.rint(NF.robot_to_pixels(robot, law)).astype(int)
    # 5 % stray white pixels anywhere in the mirror's ring (robots, reflections)
    n_stray = len(pix) // 20
    ang = rng.uniform(-math.pi, math.pi, n_stray)
    rad = rng.uniform(60.0, 190.0, n_stray)
    stray = np.rint(np.c_[law["center_coloum"] + rad * np.cos(ang), law["center_row"] + rad * np.sin(ang)]).astype(int)
    allpix = np.vstack([pix, stray, pix[:50]])  # and some duplicates, as NuBot's files have
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "whites.txt"), "w") as fh:
        for col, row in allpix:
            fh.write(f"{col} {row} \n")
    with open(os.path.join(folder, "mirror_calib.xml"), "w") as fh:
        fh.write('<?xml version="1.0" encoding="utf-8"?>\n<opencv_storage>\n')
        for k in ("center_coloum", "center_row", "para_a", "para_b", "correction_x", "correction_y"):
            fh.write(f"   <{k}>{law[k]:.20e}</{k}>\n")
        fh.write(f"   <max_radius>{math.pi / 2 / law['para_b']:.20e}</max_radius>\n</opencv_storage>")
    with open(os.path.join(folder, "ROI.xml"), "w") as fh:
        fh.write('<?xml version="1.0"?>\n<opencv_storage>\n<center_point_row>240</center_point_row>\n'
                 '<center_point_column>236</center_point_column>\n<rows>480</rows>\n<cols>480</cols>\n</opencv_storage>\n')
    return len(pix), n_stray


def test_conventions():
    check = Checks()
    law = {"center_coloum": 240.0, "center_row": 230.0, "para_a": 1.6, "para_b": 0.0069, "correction_x": 0.0, "correction_y": 0.0}
    p, ok = NF.pixels_to_robot(np.array([[340.0, 230.0], [240.0, 330.0], [140.0, 230.0]]), law)
    d = 1.6 * math.tan(0.69)
    check("a pixel right of the mirror centre (larger column) is in front (+x)", ok.all() and np.allclose(p[0], [d, 0.0]), str(p[0]))
    check("a pixel below the mirror centre (larger row) is to the left (+y)", np.allclose(p[1], [0.0, d]), str(p[1]))
    check("a pixel left of the centre is behind (-x)", np.allclose(p[2], [-d, 0.0], atol=1e-12), str(p[2]))
    law2 = dict(law, correction_x=7.0, correction_y=-3.0)
    q = np.array([[1.0, 2.0], [-3.5, 0.25], [0.5, -5.0]])
    back, _ = NF.pixels_to_robot(NF.robot_to_pixels(q, law2), law2)
    check("pixels_to_robot inverts robot_to_pixels (with a correction)", np.allclose(back, q, atol=1e-9))
    # The correction moves points by -correction / 100 m (NuBot's Transfer::correct_offset, cm).
    p0, _ = NF.pixels_to_robot(np.array([[340.0, 230.0]]), law2)
    check("the correction is subtracted, in cm", np.allclose(p0[0], [d - 0.07, 0.03]), str(p0[0]))
    check.done()


def test_markings():
    check = Checks()
    head = json.load(open(os.path.join(str(ROOT), "data", "recordings", "ci_tracking", "1", "recording.json")))
    fm = head["field_markings"]
    ours = P.field_markings("msl2012")
    same = all(sorted(map(tuple, np.round(fm[k], 9).tolist())) == sorted(map(tuple, np.round(ours[k], 9).tolist()))
               for k in ("segments", "arcs", "spots"))
    check("msl2012 markings equal the field_markings omniloc recorded (ci_tracking/1)", same)
    d = P.distance_to_markings(ours, np.array([0.0, 0.0, 5.0, -9.1, 2.1]), np.array([0.0, 6.0, 0.0, 0.0, 0.0]))
    # (0, 0) inside the centre spot; (0, 6) on the touch line; (5, 0) 0.925 m from the penalty spot's
    # rim at (6, 0) (the penalty area line x = 6.75 is 1.75 m away); 0.1 m from the goal line; 0.1 m
    # outside the centre circle.
    check("distance to markings: spot, touch line, penalty spot, goal line, circle",
          np.allclose(d, [0.0, 0.0, 0.925, 0.1, 0.1], atol=1e-9), str(d))
    check.done()


def test_synthetic(tmp_path):
    check = Checks()
    tmp = str(tmp_path)
    rng = np.random.default_rng(7)
    pose = (-2.35, 1.6, 2.2)
    law = {"center_coloum": 236.4, "center_row": 243.1, "para_a": 1.62, "para_b": 0.0069, "correction_x": 4.0, "correction_y": -2.5}
    calib = os.path.join(tmp, "calib", "7")
    n_line, n_stray = write_synthetic_calib(calib, pose, law, rng)
    out = os.path.join(tmp, "rec7")
    r = subprocess.run([PY, os.path.join(str(ROOT), "scripts", "nubot_to_recording.py"), calib, "-o", out, "--robot", "7",
                        "--frames", "30"], capture_output=True, text=True)
    check("converter runs on a synthetic calib folder", r.returncode == 0, r.stderr.strip()[-300:])
    if r.returncode != 0:
        check.done()
        return
    head, frames = omniloc_recording.read(out)
    frames = list(frames)
    ref = head["reference"]["reference"]
    twin = head["reference"]["twin"]
    hit = near(ref, pose, 0.03, 0.5) or near(twin, pose, 0.03, 0.5)
    check("reference search finds the synthetic pose (or its twin) within 3 cm / 0.5 deg", hit,
          f"known {pose}, reference {ref}, residual {head['reference']['residual_m']}")
    check("twin is (-x, -y, theta + pi)", near(twin, (-ref[0], -ref[1], ref[2] + math.pi), 1e-4, 0.01))
    nb = head["reference"]["next_best"]
    check("next-best distinct pose is worse and distinct", nb is not None and nb["residual_m"] > head["reference"]["residual_m"] + 0.05
          and not near(nb["pose"], ref, 0.5, 20) and not near(nb["pose"], twin, 0.5, 20), str(nb))
    check("stray pixels and duplicates: inliers about 95 %", 0.9 <= head["reference"]["inliers"] <= 0.99, str(head["reference"]["inliers"]))
    check("duplicates removed", head["conversion"]["distinct_pixels"] < head["conversion"]["pixels_in_file"])
    r0 = frames[0]["robots"][0]
    check("recording: scenario null, msl2012, 30 frames, ground truth, no start, no compass, still",
          head["scenario"] is None and head["field"] == "msl2012" and head["frames"] == 30 and head["ground_truth"] is True
          and "start" not in head["robots"][0] and r0["heading"] is None and r0["odometry"] == [0.0, 0.0, 0.0]
          and r0["truth"] == ref and len(r0["line_points"]) == head["conversion"]["line_points"])
    check("source and licence in the header", head["source"]["licence"] == "Apache-2.0" and "nubot_ws" in head["source"]["repository"])
    check.done()


# ---------------------------------------------------------------------------------------------------
# (b) the shipped real frames


def last_estimate(run):
    with open(os.path.join(run, "frames.csv")) as fh:
        lines = fh.read().splitlines()
    cols = lines[0].split(",")
    row = dict(zip(cols, lines[-1].split(",")))
    return (float(row["est_x"]), float(row["est_y"]), float(row["est_theta"])), row["valid"] == "1", len(lines) - 1


@needs_omniloc
def test_real(tmp_path):
    check = Checks()
    binary, tmp = OMNILOC, str(tmp_path)
    robots = sorted(d for d in os.listdir(REAL) if os.path.isfile(os.path.join(REAL, d, "recording.json")))
    check("shipped real recordings: robot1, robot2, robot4, robot5", robots == ["robot1", "robot2", "robot4", "robot5"], str(robots))
    markings = P.field_markings("msl2012")
    for name in robots:
        folder = os.path.join(REAL, name)
        head, frames = omniloc_recording.read(folder)  # checks count and SHA-256
        first = next(frames)
        r0 = first["robots"][0]
        ref = head["reference"]["reference"]
        twin = head["reference"]["twin"]
        pts = np.array(r0["line_points"])
        check(f"{name}: header (format 1, scenario null, msl2012, 300 frames at 30 Hz, truth = reference, no start, no compass)",
              head["format"] == "omniloc-recording/1" and head["scenario"] is None and head["field"] == "msl2012"
              and head["frames"] == 300 and head["camera_rate_hz"] == 30.0 and head["ground_truth"] is True
              and "start" not in head["robots"][0] and r0["truth"] == ref and r0["heading"] is None
              and r0["odometry"] == [0.0, 0.0, 0.0] and head["source"]["commit"] == NF.SOURCE_COMMIT)
        res = math.sqrt(P.score_exact(markings, ref, pts, head["reference"]["method"]["c_m"]))
        check(f"{name}: residual of the reference recomputed ({res:.4f} m) as recorded, under 0.1 m",
              abs(res - head["reference"]["residual_m"]) < 2e-4 and res < 0.1)
        nb = head["reference"]["next_best"]
        check(f"{name}: next-best distinct pose at least 2.5 times the reference's residual",
              nb["residual_m"] > 2.5 * head["reference"]["residual_m"], f"{nb['residual_m']} vs {head['reference']['residual_m']}")
        for label, loc, asserted in (("grid_global", {"type": "grid_global"}, True), ("hybrid", {"type": "hybrid"}, True),
                                     ("mcl", {"type": "mcl"}, True), ("mcl as paper 002 without a compass", MCL_PAPER, False)):
            run = os.path.join(tmp, f"{name}_{label.replace(' ', '_')}")
            p = subprocess.run([binary, "replay", folder, "--localizer", json.dumps(loc), "-o", run, "--overwrite"],
                               capture_output=True, text=True, cwd=str(ROOT))
            if p.returncode != 0:
                check(f"{name}: replay {label}", False, p.stderr.strip()[-300:])
                continue
            summ = json.load(open(os.path.join(run, "summary.json")))["robots"][0]
            est, valid, n = last_estimate(run)
            on_ref, on_twin = near(est, ref, 0.25, 10), near(est, twin, 0.25, 10)
            where = "reference" if on_ref else "twin" if on_twin else "wrong"
            p50 = summ["position_m"]["p50"]
            detail = (f"last estimate {[round(v, 3) for v in est]} valid {valid}: {where}; summary p50 "
                      + ("no estimate" if p50 is None else f"{p50:.3f} m"))
            if asserted:
                ok = n == 300 and summ["frames_total"] == 300 and valid and (on_ref or on_twin)
                if label == "grid_global":
                    # Valid from the first frame on; summary.json scores against the reference, so its
                    # median error is small or, on the twin, twice the reference's distance from the centre.
                    p50, far = summ["position_m"]["p50"], 2 * math.hypot(ref[0], ref[1])
                    ok = ok and summ["valid_fraction"] == 1.0 and (p50 < 0.05 or abs(p50 - far) < 0.05)
                check(f"{name}: {label} ends on the reference or its twin (300 frames, last one valid)", ok, detail)
            else:
                print(f"info {name}: {label}: {detail}", flush=True)
    check.done()
