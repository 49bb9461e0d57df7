#!/usr/bin/env python3
"""A numpy particle filter on omniloc's line points, over olp/1 (example).

Tracks from the true start pose (needs_start_pose, as the papers' tracking localizers do); it has
no global search (3000 particles spread over the field settled 8 m off on tracking.json: tried), so after a
kidnap it stays lost. Parameters (scenario "params", all optional):
  particles (300), max_points (40), sigma_hit (0.12 m), p_far (0.05), temper (0.5),
  heading_sigma (0.1 rad; compass, when the robot has one), use_heading (true).
Use:
  "localizer": {"type": "external", "command": ["python3", "clients/python/examples/particle_filter.py"],
                "params": {"particles": 300}}
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # clients/python, no install needed
sys.path.insert(0, str(Path(__file__).resolve().parent))      # field_pf next to this file
import numpy as np  # noqa: E402

import omniloc_client as olp  # noqa: E402
from field_pf import ParticleFilter, pick_points  # noqa: E402


class LinePointParticleFilter(olp.Localizer):
    name = "py_particle_filter"
    version = "1.0"
    needs_start_pose = True

    def ready(self, hello):
        p = hello.params
        self.max_points = int(p.get("max_points", 40))
        self.use_heading = bool(p.get("use_heading", True))
        self.options = {k: p[k] for k in ("particles", "sigma_hit", "p_far", "temper", "heading_sigma") if k in p}
        self.field = hello.field

    def reset(self, seed, start):
        self.pf = ParticleFilter(self.field, np.random.default_rng(seed), **self.options)
        self.pf.start_at(start)

    def update(self, frame):
        self.pf.predict(frame.odometry)
        pts = np.asarray(frame.line_points, dtype=float).reshape(-1, 2)
        pts = pick_points(pts, self.max_points)
        self.pf.correct(pts, frame.heading if self.use_heading else None)
        pose, cov = self.pf.estimate()
        resampled = self.pf.resample_if_needed()
        spread = float(np.sqrt(cov[0, 0] + cov[1, 1]))
        # 50 of the particles, for the run viewer (omniloc run --debug-view; otherwise dropped).
        step = max(1, self.pf.n // 50)
        w = np.exp(self.pf.logw - self.pf.logw.max())
        shown = [(float(x), float(y), float(th), float(wi)) for (x, y, th), wi in zip(self.pf.p[::step][:50], w[::step][:50])]
        return olp.Estimate(pose, valid=True, covariance=cov, mode="tracking",
                            extra={"points_used": len(pts), "spread_m": spread, "resampled": int(resampled)}, particles=shown)


if __name__ == "__main__":
    olp.serve(LinePointParticleFilter())
