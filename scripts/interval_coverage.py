#!/usr/bin/python3
"""Coverage of candidate 95 % intervals for the MEAN of a few seeds' non-negative errors.

Why: the aggregate, the terminal's sweep table, compare and the report must use one interval method
for one quantity (docs/results.md "Intervals"), chosen by how often each candidate actually contains the true
mean with the seed counts a sweep has (n = 3, 4, 5; 10 for reference). The errors of a run are
non-negative and skewed (one seed on a wrong pose is far above the others), so the samples are drawn
from lognormal distributions (mu = 0, sigma 0.25, 0.5, 1.0; true mean exp(sigma^2 / 2)) and, for
reference, a normal one (mean 1, sd 0.25).

Candidates:
  t            Student t on the raw values: mean +- t(0.975, n-1) s / sqrt(n)
  t, clipped   the same with the lower bound raised to 0 (a non-negative quantity; the true mean is
               > 0, so clipping never changes coverage: it only removes impossible values)
  log-t        Student t on log values, back-transformed: an interval for the GEOMETRIC mean
               (the median of a lognormal), not for the mean; its coverage of the mean is shown
  bootstrap    percentile bootstrap of the mean (exact over all n^n ordered resamples for n <= 5,
               2000 resamples above), as the report used to print
  range        min..max of the seeds; its coverage of the mean is also exact:
               1 - F(mu)^n - (1 - F(mu))^n, printed beside the simulated value

Deterministic (fixed numpy seed): `scripts/interval_coverage.py [--reps N] [--markdown]`.
Needs numpy (Debian: python3-numpy); only this script does, the report does not.
"""
import argparse
import itertools
import math

import numpy as np

T975 = {2: 4.302653, 3: 3.182446, 4: 2.776445, 9: 2.262157}  # Student t 0.975 quantiles for df = n - 1


def normal_cdf(x):
    return 0.5 * (1 + math.erf(x / math.sqrt(2)))


def distributions():
    """(name, sampler(rng, shape), true mean, F(true mean))."""
    out = [("normal(1, 0.25)", lambda rng, shape: rng.normal(1.0, 0.25, shape), 1.0, 0.5)]
    for s in (0.25, 0.5, 1.0):
        # lognormal(0, s): mean exp(s^2/2); F(mean) = Phi(s / 2)
        out.append((f"lognormal sigma {s}", lambda rng, shape, s=s: rng.lognormal(0.0, s, shape), math.exp(s * s / 2), normal_cdf(s / 2)))
    return out


def bootstrap_bounds(x, rng):
    """Percentile bootstrap 2.5 / 97.5 % of the mean for every row of x (reps x n)."""
    reps, n = x.shape
    if n <= 5:
        idx = np.array(list(itertools.product(range(n), repeat=n)))  # n^n x n: every ordered resample
    else:
        idx = rng.integers(0, n, size=(2000, n))
    lo, hi = np.empty(reps), np.empty(reps)
    for a in range(0, reps, 1000):  # in chunks: 1000 x 3125 x 5 values at a time
        means = x[a:a + 1000][:, idx].mean(axis=2)
        lo[a:a + 1000], hi[a:a + 1000] = np.quantile(means, 0.025, axis=1), np.quantile(means, 0.975, axis=1)
    return lo, hi


def coverage(reps=20000, ns=(3, 4, 5, 10), seed=38):
    rng = np.random.default_rng(seed)
    rows = []
    for name, sampler, mu, f_mu in distributions():
        for n in ns:
            x = sampler(rng, (reps, n))
            m, s = x.mean(axis=1), x.std(axis=1, ddof=1)
            half = T975[n - 1] * s / math.sqrt(n)
            lo, hi = m - half, m + half
            cov = {}
            cov["t"] = np.mean((lo <= mu) & (mu <= hi))
            cov["t, clipped"] = np.mean((np.maximum(lo, 0) <= mu) & (mu <= hi))
            lx = np.log(np.maximum(x, 1e-300))
            lm, ls = lx.mean(axis=1), lx.std(axis=1, ddof=1)
            lh = T975[n - 1] * ls / math.sqrt(n)
            cov["log-t"] = np.mean((np.exp(lm - lh) <= mu) & (mu <= np.exp(lm + lh))) if name.startswith("lognormal") else float("nan")
            blo, bhi = bootstrap_bounds(x, rng)
            cov["bootstrap"] = np.mean((blo <= mu) & (mu <= bhi))
            cov["range"] = np.mean((x.min(axis=1) <= mu) & (mu <= x.max(axis=1)))
            cov["range, exact"] = 1 - f_mu ** n - (1 - f_mu) ** n
            cov["t below 0"] = np.mean(lo < 0)
            rows.append((name, n, cov))
    return rows


COLS = ["t", "t, clipped", "log-t", "bootstrap", "range", "range, exact", "t below 0"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reps", type=int, default=20000, help="samples per cell (default 20000: +-0.003 at 95 %%)")
    ap.add_argument("--markdown", action="store_true", help="print a markdown table")
    a = ap.parse_args()
    rows = coverage(a.reps)
    f = lambda v: "-" if isinstance(v, float) and math.isnan(v) else f"{v:.3f}"
    if a.markdown:
        print("| distribution | n | " + " | ".join(COLS) + " |")
        print("|---|---|" + "---|" * len(COLS))
        for name, n, cov in rows:
            print(f"| {name} | {n} | " + " | ".join(f(cov[c]) for c in COLS) + " |")
    else:
        print(f"{'distribution':<22} {'n':>3} " + " ".join(f"{c:>12}" for c in COLS))
        for name, n, cov in rows:
            print(f"{name:<22} {n:>3} " + " ".join(f"{f(cov[c]):>12}" for c in COLS))
    print(f"(coverage of the true mean by nominal 95 % intervals, {a.reps} samples per row, numpy seed 38; "
          "'t below 0': share of t intervals whose lower bound is negative; log-t covers the geometric mean, shown against the mean)")


if __name__ == "__main__":
    main()
