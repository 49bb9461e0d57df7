#!/usr/bin/env python3
"""Dead reckoning over olp/1: the start pose composed with every frame's odometry.

Its est.tum equals omniloc's built-in `odometry_only` on the same scenario and seed (to the last
bit: compose_odometry does omniloc's Pose2::compose operations in the same order). Use:
  "localizer": {"type": "external", "command": ["python3", "clients/python/examples/dead_reckoning.py"]}
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # clients/python, no install needed
import omniloc_client as olp  # noqa: E402


class DeadReckoning(olp.Localizer):
    name = "py_dead_reckoning"
    version = "1.0"
    needs_start_pose = True

    def ready(self, hello):
        # params {"wants_image": true}: take the image too (unused; bench/protocol_bench.cpp measures
        # what receiving it costs a Python client).
        self.wants_image = bool(hello.params.get("wants_image", False))

    def reset(self, seed, start):
        self.pose = start

    def update(self, frame):
        self.pose = olp.compose_odometry(self.pose, frame.odometry)
        return olp.Estimate(self.pose, valid=True, mode="dead_reckoning")


if __name__ == "__main__":
    olp.serve(DeadReckoning())
