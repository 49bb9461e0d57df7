#!/usr/bin/env python3
"""Own vision over olp/1 (example): asks for the raw RGB image, finds the white field lines itself
and localizes with the particle filter of particle_filter.py (field_pf.py).

Line detection: `rays` radial scan lines from the mirror centre, one sample per image pixel of
radius, from the calibrated minimum radius out to `max_distance_m` on the floor. Each sample is
classed by plain RGB rules: green (G well above R and B), white (R, G, B close together and at
least as bright as the field's green channel), black (obstacle, much darker than the field).
A line point is a white run with green at most 3 samples before and after it, no longer than 3x a
line's width at that radius (+2 px); its centre goes through the calibration from hello.camera to
a robot-frame floor point. A ray stops at its first black sample (robots). Everything per frame
is numpy on precomputed pixel indices.

Parameters (scenario "params", all optional): rays (120), max_distance_m (6.0), plus the particle
filter's (particles, max_points, sigma_hit, ...; see particle_filter.py).
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # clients/python, no install needed
sys.path.insert(0, str(Path(__file__).resolve().parent))      # field_pf next to this file
import numpy as np  # noqa: E402

import omniloc_client as olp  # noqa: E402
from field_pf import ParticleFilter, pick_points  # noqa: E402


class RadialLineScanner:
    """White line points (robot frame, metres) from an RGB panorama; see the module docstring."""

    def __init__(self, camera, line_width, rays=120, max_distance=6.0):
        cal = camera.calibration()
        self.width, self.height = camera.width, camera.height
        r0 = int(np.ceil(cal.min_radius)) + 1
        r1 = int(np.floor(cal.max_radius)) - 1
        radii = np.arange(r0, r1 + 1, dtype=float)
        bearings = 2 * np.pi * np.arange(rays) / rays
        n = len(radii)
        self.u = np.zeros((rays, n), dtype=np.intp)
        self.v = np.zeros((rays, n), dtype=np.intp)
        self.points = np.zeros((rays, n, 2))
        self.max_run = np.zeros((rays, n))
        self.inside = np.zeros((rays, n), dtype=bool)
        for i, b in enumerate(bearings):
            d = np.array([cal.distance(r, b) or np.nan for r in radii])
            d_next = np.array([cal.distance(min(r + 1.0, cal.max_radius), b) or np.nan for r in radii])
            uu = np.floor(cal.cu - radii * np.sin(b)).astype(np.intp)  # pixel centre at index + 0.5
            vv = np.floor(cal.cv - radii * np.cos(b)).astype(np.intp)
            ok = (np.isfinite(d) & (d <= max_distance) & (uu >= 0) & (uu < self.width) & (vv >= 0) & (vv < self.height))
            self.u[i] = np.where(ok, uu, 0)
            self.v[i] = np.where(ok, vv, 0)
            self.inside[i] = ok
            self.points[i, :, 0] = d * np.cos(b)
            self.points[i, :, 1] = d * np.sin(b)
            metres_per_px = np.maximum(d_next - d, 1e-4)
            self.max_run[i] = 3.0 * line_width / metres_per_px + 2.0
        self.points = np.nan_to_num(self.points)

    def detect(self, image):
        """(M, 2) robot-frame line points found in `image` ((H, W, 3) uint8)."""
        px = image[self.v, self.u].astype(np.int16)  # (rays, samples, 3)
        r, g, b = px[..., 0], px[..., 1], px[..., 2]
        hi = np.maximum(np.maximum(r, g), b)
        lo = np.minimum(np.minimum(r, g), b)
        green = (g * 10 > 14 * np.maximum(r, b)) & (g > 20) & self.inside
        if not green.any():
            return np.zeros((0, 2))
        g_field = float(np.median(g[green]))
        white = (lo * 10 > 7 * hi) & (g * 10 >= 9 * g_field) & self.inside
        black = (hi * 10 < 3 * g_field) & self.inside
        rays, n = white.shape
        # a ray ends at its first black sample (another robot, a covered sector)
        first_black = np.where(black.any(axis=1), black.argmax(axis=1), n)
        # white runs: +1 where one starts, -1 one past where it ends
        step = np.diff(np.pad(white.astype(np.int8), ((0, 0), (1, 1))), axis=1)
        rs, s = np.nonzero(step == 1)
        _, e = np.nonzero(step == -1)  # same rows, same order: runs pair up
        # green within 3 samples before the start and after the end (anti-aliased edges)
        cg = np.pad(np.cumsum(green, axis=1), ((0, 0), (1, 0)))
        before = cg[rs, s] - cg[rs, np.maximum(s - 3, 0)]
        after = cg[rs, np.minimum(e + 3, n)] - cg[rs, e]
        centre = (s + e - 1) // 2
        keep = (before > 0) & (after > 0) & (e - s <= self.max_run[rs, centre]) & (e + 3 <= first_black[rs])
        rs, s, e = rs[keep], s[keep], e[keep]
        return 0.5 * (self.points[rs, s] + self.points[rs, e - 1])


class OwnVisionLocalizer(olp.Localizer):
    name = "py_own_vision"
    version = "1.0"
    needs_start_pose = True
    wants_image = True

    def ready(self, hello):
        p = hello.params
        self.scanner = RadialLineScanner(hello.camera, hello.field.line_width or 0.125, int(p.get("rays", 120)),
                                         float(p.get("max_distance_m", 6.0)))
        self.max_points = int(p.get("max_points", 40))
        self.options = {k: p[k] for k in ("particles", "sigma_hit", "p_far", "temper", "heading_sigma") if k in p}
        self.field = hello.field

    def reset(self, seed, start):
        self.pf = ParticleFilter(self.field, np.random.default_rng(seed), **self.options)
        self.pf.start_at(start)

    def update(self, frame):
        self.pf.predict(frame.odometry)
        found = self.scanner.detect(frame.image) if frame.camera_ok and frame.image is not None else np.zeros((0, 2))
        pts = pick_points(found, self.max_points)
        self.pf.correct(pts, frame.heading)
        pose, cov = self.pf.estimate()
        self.pf.resample_if_needed()
        return olp.Estimate(pose, covariance=cov, mode="tracking",
                            extra={"own_points": len(found), "points_used": len(pts)})


if __name__ == "__main__":
    olp.serve(OwnVisionLocalizer())
