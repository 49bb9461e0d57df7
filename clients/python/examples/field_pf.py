"""A small numpy particle filter on field-line points, shared by particle_filter.py and
own_vision.py (examples of omniloc's olp/1 clients; not part of the omniloc_client library).

- Distance map: the distance from every 5 cm cell centre of the floor (walls included) to the
  nearest line centre, computed exactly from hello.field's segments and arcs; looked up
  bilinearly, clamped at the map's border.
- Motion: every particle is moved by the frame's odometry plus Gaussian noise that grows with the
  distance and the turn.
- Measurement: each line point (robot frame) is placed in the world by each particle; its distance
  d to the nearest line scores exp(-d^2 / (2 sigma^2)) mixed with a floor (outliers), a product
  over the points (in logs, tempered); with a compass heading, a Gaussian on the heading error.
- Resampling: systematic, when the effective sample size drops below half the particles.
All randomness comes from one numpy Generator seeded from reset.seed, so runs are reproducible.
"""
import math

import numpy as np


class DistanceMap:
    """Distance (metres) from a world point to the nearest line centre of `field` (an
    omniloc_client.Field), tabulated on a `cell`-metre grid over the floor inside the walls."""

    def __init__(self, field, cell=0.05):
        x0, x1, y0, y1 = field.bounds()
        self.cell = cell
        self.x0, self.y0 = x0, y0
        self.nx = int(math.ceil((x1 - x0) / cell)) + 1
        self.ny = int(math.ceil((y1 - y0) / cell)) + 1
        xs = x0 + cell * np.arange(self.nx)
        ys = y0 + cell * np.arange(self.ny)
        X, Y = np.meshgrid(xs, ys, indexing="xy")  # (ny, nx)
        d = np.full(X.shape, np.inf)
        for x1_, y1_, x2_, y2_ in field.segments:
            ex, ey = x2_ - x1_, y2_ - y1_
            ll = ex * ex + ey * ey
            t = np.zeros_like(X) if ll == 0 else np.clip(((X - x1_) * ex + (Y - y1_) * ey) / ll, 0.0, 1.0)
            np.minimum(d, np.hypot(X - (x1_ + t * ex), Y - (y1_ + t * ey)), out=d)
        for cx, cy, r, start, sweep in field.arcs:
            ang = np.arctan2(Y - cy, X - cx)
            rel = np.mod(ang - start, 2 * np.pi) if sweep >= 0 else np.mod(start - ang, 2 * np.pi)
            on_arc = np.abs(np.hypot(X - cx, Y - cy) - r)
            ends = np.minimum(np.hypot(X - (cx + r * math.cos(start)), Y - (cy + r * math.sin(start))),
                              np.hypot(X - (cx + r * math.cos(start + sweep)), Y - (cy + r * math.sin(start + sweep))))
            np.minimum(d, np.where(rel <= abs(sweep), on_arc, ends), out=d)
        self.table = d

    def __call__(self, x, y):
        """Bilinear distance at world points (arrays of any equal shape)."""
        fx = np.clip((x - self.x0) / self.cell, 0.0, self.nx - 1.000001)
        fy = np.clip((y - self.y0) / self.cell, 0.0, self.ny - 1.000001)
        ix = fx.astype(np.intp)
        iy = fy.astype(np.intp)
        wx = fx - ix
        wy = fy - iy
        t = self.table
        top = t[iy, ix] * (1 - wx) + t[iy, ix + 1] * wx
        bottom = t[iy + 1, ix] * (1 - wx) + t[iy + 1, ix + 1] * wx
        return top * (1 - wy) + bottom * wy


def pick_points(points, at_most):
    """At most `at_most` of `points` (an (M, 2) array), evenly spread over the list (the vision
    emits them ray by ray, so this keeps them spread around the robot). Deterministic."""
    m = len(points)
    if m <= at_most:
        return points
    return points[np.linspace(0, m - 1, at_most).round().astype(np.intp)]


class ParticleFilter:
    """Pose particles (x, y, theta) with weights; see the module docstring."""

    def __init__(self, field, rng, particles=300, sigma_hit=0.12, p_far=0.05, temper=0.5,
                 heading_sigma=0.1, trans_noise=0.1, rot_noise=0.1, drift_noise=0.05, cell=0.05):
        self.map = DistanceMap(field, cell)
        self.field = field
        self.rng = rng
        self.n = int(particles)
        self.sigma_hit = sigma_hit
        self.p_far = p_far
        self.temper = temper
        self.heading_sigma = heading_sigma
        self.trans_noise, self.rot_noise, self.drift_noise = trans_noise, rot_noise, drift_noise
        self.p = np.zeros((self.n, 3))
        self.logw = np.zeros(self.n)

    def start_at(self, pose, spread=(0.05, 0.05, 0.03)):
        self.p = np.asarray(pose, dtype=float) + self.rng.normal(0.0, 1.0, (self.n, 3)) * np.asarray(spread)
        self.logw = np.zeros(self.n)

    def predict(self, odometry):
        dx, dy, dth = odometry
        dist = math.hypot(dx, dy)
        noise = self.rng.normal(0.0, 1.0, (self.n, 3))
        sxy = self.trans_noise * dist + 0.002
        sth = self.rot_noise * abs(dth) + self.drift_noise * dist + 0.002
        ndx = dx + sxy * noise[:, 0]
        ndy = dy + sxy * noise[:, 1]
        c, s = np.cos(self.p[:, 2]), np.sin(self.p[:, 2])
        self.p[:, 0] += c * ndx - s * ndy
        self.p[:, 1] += s * ndx + c * ndy
        self.p[:, 2] = np.mod(self.p[:, 2] + dth + sth * noise[:, 2] + np.pi, 2 * np.pi) - np.pi

    def correct(self, points, heading=None):
        """points: (M, 2) robot-frame line points; heading: compass (world, radians) or None."""
        if len(points):
            px, py = points[:, 0], points[:, 1]
            c, s = np.cos(self.p[:, 2:3]), np.sin(self.p[:, 2:3])  # (N, 1)
            wx = self.p[:, 0:1] + c * px - s * py                  # (N, M)
            wy = self.p[:, 1:2] + s * px + c * py
            d = self.map(wx, wy)
            lik = np.log((1.0 - self.p_far) * np.exp(-0.5 * (d / self.sigma_hit) ** 2) + self.p_far)
            self.logw += self.temper * lik.sum(axis=1)
        if heading is not None:
            e = np.angle(np.exp(1j * (self.p[:, 2] - heading)))
            self.logw += -0.5 * (e / self.heading_sigma) ** 2
        self.logw -= self.logw.max()

    def weights(self):
        w = np.exp(self.logw)
        return w / w.sum()

    def n_eff(self):
        w = self.weights()
        return 1.0 / float(np.sum(w * w))

    def resample_if_needed(self):
        if self.n_eff() >= 0.5 * self.n:
            return False
        w = self.weights()
        positions = (self.rng.random() + np.arange(self.n)) / self.n
        idx = np.searchsorted(np.cumsum(w), positions)
        self.p = self.p[np.minimum(idx, self.n - 1)]
        self.logw = np.zeros(self.n)
        return True

    def estimate(self):
        """(pose, covariance 3x3): the weighted mean (circular for theta) and spread."""
        w = self.weights()
        x = float(w @ self.p[:, 0])
        y = float(w @ self.p[:, 1])
        th = math.atan2(float(w @ np.sin(self.p[:, 2])), float(w @ np.cos(self.p[:, 2])))
        dev = np.column_stack([self.p[:, 0] - x, self.p[:, 1] - y, np.angle(np.exp(1j * (self.p[:, 2] - th)))])
        cov = (dev * w[:, None]).T @ dev
        return (x, y, th), cov
