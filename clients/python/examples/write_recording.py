#!/usr/bin/env python3
"""Writes a small omniloc recording from plain arrays, as a team would convert a robot's log: no
omniloc involved. The "log" here is made up: a robot drives a 2 m circle on the MSL 2012 field for
20 s at 30 Hz; its odometry is the true motion with 2 % scale noise, its compass the true heading
with 0.01 rad noise, and its line points are the field's lines within 5 m, seen from the true pose
with 2 cm noise (real line points come from the robot's vision: docs/protocol.md section 5).

    write_recording.py OUT_FOLDER [--no-truth] [--seed N]
    build/omniloc replay OUT_FOLDER --localizer '{"type": "matching"}' -o results/runs/my_log

With --no-truth the recording has no true poses: a replay writes the estimates and scores nothing.
"""
import argparse
import math
import os
import random
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import omniloc_recording  # noqa: E402  (clients/python)

# The MSL 2012 field's lines (data/fields/msl2012.json): outer lines, halfway line, centre circle.
SEGMENTS = [(-9, -6, 9, -6), (9, -6, 9, 6), (9, 6, -9, 6), (-9, 6, -9, -6), (0, -6, 0, 6)]
CIRCLE = (0.0, 0.0, 2.0)


def line_samples(step=0.05):
    pts = []
    for x1, y1, x2, y2 in SEGMENTS:
        n = int(math.hypot(x2 - x1, y2 - y1) / step)
        pts += [(x1 + (x2 - x1) * i / n, y1 + (y2 - y1) * i / n) for i in range(n + 1)]
    cx, cy, r = CIRCLE
    n = int(2 * math.pi * r / step)
    pts += [(cx + r * math.cos(2 * math.pi * i / n), cy + r * math.sin(2 * math.pi * i / n)) for i in range(n)]
    return pts


def truth_at(t):
    """A 2 m circle around (-4, 1), once every 20 s, facing along the path."""
    a = 2 * math.pi * t / 20.0
    return (-4.0 + 2.0 * math.sin(a), 1.0 - 2.0 * math.cos(a), a)


def relative(p, q):
    """q in the robot frame of p (odometry's convention)."""
    dx, dy = q[0] - p[0], q[1] - p[1]
    c, s = math.cos(p[2]), math.sin(p[2])
    return (c * dx + s * dy, -s * dx + c * dy, q[2] - p[2])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("--no-truth", action="store_true")
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    lines = line_samples()
    rate, seconds = 30.0, 20.0
    start = truth_at(0.0)
    with omniloc_recording.Writer(a.out, name="made_up_log", field="msl2012", camera_rate_hz=rate,
                                  robots=[{"id": 0, "start": start}], ground_truth=not a.no_truth,
                                  comment="clients/python/examples/write_recording.py: a made-up log") as w:
        prev = start
        for k in range(int(seconds * rate) + 1):
            t = k / rate
            pose = truth_at(t)
            dx, dy, dth = relative(prev, pose) if k else (0.0, 0.0, 0.0)
            scale = 1.0 + rng.gauss(0.0, 0.02)
            c, s = math.cos(pose[2]), math.sin(pose[2])
            seen = []
            for i, (x, y) in enumerate(lines):
                ex, ey = x - pose[0], y - pose[1]
                if i % 3 == k % 3 and math.hypot(ex, ey) < 5.0:
                    seen.append((c * ex + s * ey + rng.gauss(0, 0.02), -s * ex + c * ey + rng.gauss(0, 0.02)))
            w.frame(t, [{"robot": 0, "odometry": (dx * scale, dy * scale, dth * scale), "heading": pose[2] + rng.gauss(0, 0.01),
                         "line_points": seen, "truth": None if a.no_truth else pose}])
            prev = pose
    print(f"wrote {a.out}: {int(seconds * rate) + 1} frames{' without' if a.no_truth else ' with'} ground truth")


if __name__ == "__main__":
    main()
