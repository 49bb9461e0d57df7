#!/usr/bin/env python3
"""Reference pose of one frame of robot-frame line points on an MSL field, by exhaustive search
(omniloc.data.nubot.search, whose docstring describes the method): prints the reference, its twin,
the residual and the next-best distinct pose as JSON.

    scripts/nubot_reference_pose.py POINTS.json [--field msl2012]   # POINTS.json: [[x, y], ...]
"""
import json
import os
import sys

# A developer's tool, run from a checkout: the results package beside it.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
from omniloc.data.nubot import search  # noqa: E402


def main():
    import argparse
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("points", help="JSON file: [[x, y], ...] robot frame, metres")
    ap.add_argument("--field", default="msl2012")
    ap.add_argument("--c", type=float, default=0.30)
    ap.add_argument("--xy-step", type=float, default=0.05)
    ap.add_argument("--theta-step", type=float, default=1.0)
    a = ap.parse_args()
    with open(a.points, encoding="utf-8") as fh:
        pts = json.load(fh)
    print(json.dumps(search(pts, a.field, c=a.c, xy_step=a.xy_step, theta_step_deg=a.theta_step, verbose=True), indent=2))


if __name__ == "__main__":
    main()
