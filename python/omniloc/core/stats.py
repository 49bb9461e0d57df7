"""Statistics for few seeds, with no SciPy (Debian's python3 is the only dependency).

interval(): THE interval rule of omniloc, the same as batch/aggregate.cpp's mean_ci95 (docs/results.md
"Intervals", measured by scripts/interval_coverage.py): n >= 5, the 95 % Student t interval of the
mean, its lower bound clipped at 0 when no seed is negative ("t95"); 2 <= n <= 4, no reliable
interval exists, so the seeds' range min..max is given instead and says so ("range"); n = 1, none.
Each result names its kind. stats(): the mean, the median and every seed's value with that
interval. outliers() flags a seed whose error lies far above the others. welch(): Welch's t-test
for two result sets. wilson(): the Wilson score interval of a success rate.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence, TypeGuard, Union


# The interval rule (one for every tool; batch/aggregate.cpp applies the same in C++): the kind
# names printed beside every interval, and aggregate.csv's "interval" column.
T95 = "t95"      # 95 % Student t interval of the mean, clipped at 0 for a non-negative sample (n >= 5)


RANGE = "range"  # the seeds' min..max: NOT a confidence interval (2 <= n <= 4: none is reliable)


NO_INTERVAL = "none"  # one seed


MIN_T_SEEDS = 5  # below this no candidate covered the mean reliably (scripts/interval_coverage.py)


STUDENT_T = T95  # old name


@dataclass(frozen=True)
class Interval:
    """The interval of the mean of a few seeds' values (interval()): kind T95, RANGE or NO_INTERVAL;
    everything None over no value."""
    n: int
    mean: Optional[float]
    lo: Optional[float]
    hi: Optional[float]
    kind: Optional[str]


@dataclass
class SeedStats:
    """A statistic over seeds (stats()): the values used (None and NaN left out), their mean, median
    and standard deviation, and interval()'s lo / hi / kind as method (None where n < 2). Over runs
    (core.metrics.run_stats) also no_value (runs where the statistic is null: no estimate), of (runs
    that have the key) and why (the reason to print where no run has a value)."""
    n: int
    mean: Optional[float]
    median: Optional[float]
    sd: Optional[float]
    lo: Optional[float]
    hi: Optional[float]
    values: list[float]
    method: Optional[str]
    no_value: int = 0
    of: int = 0
    why: Optional[str] = None


@dataclass(frozen=True)
class Welch:
    """Welch's t-test of mean(b) - mean(a): diff, t, df, p (None where a side has fewer than two values)."""
    diff: Optional[float]
    t: Optional[float]
    df: Optional[float]
    p: Optional[float]


def percentile(sorted_vals: Sequence[float], q: float) -> float:
    """The q-quantile (0..1) of sorted values, linear interpolation between order statistics."""
    pos = q * (len(sorted_vals) - 1)
    k = int(math.floor(pos))
    if k + 1 >= len(sorted_vals):
        return sorted_vals[-1]
    return sorted_vals[k] + (pos - k) * (sorted_vals[k + 1] - sorted_vals[k])


def interval(values: Sequence[Optional[float]]) -> Interval:
    """The interval of the mean of a few seeds' values, by omniloc's one rule (docs/results.md
    "Intervals"): an Interval (n, mean, lo, hi, kind).
      n >= 5: kind T95, the 95 % Student t interval; a sample without negative values (an error, a
              count) never gets a negative bound: the lower one is clipped at 0.
      2..4:   kind RANGE, lo / hi the seeds' minimum and maximum: with so few seeds no interval is
              reliable (the bootstrap covers the mean 57-80 % of the time on skewed errors; t nears
              95 % only with a lower bound below 0 in up to 84 % of samples), so none is claimed.
      1:      kind NO_INTERVAL, lo = hi = the value.   0: everything None.
    None and NaN values are left out."""
    v = [float(x) for x in values if x is not None and not (isinstance(x, float) and math.isnan(x))]
    n = len(v)
    if n == 0:
        return Interval(n=0, mean=None, lo=None, hi=None, kind=None)
    m = sum(v) / n
    if n == 1:
        return Interval(n=1, mean=m, lo=m, hi=m, kind=NO_INTERVAL)
    if n < MIN_T_SEEDS:
        return Interval(n=n, mean=m, lo=min(v), hi=max(v), kind=RANGE)
    sd = math.sqrt(sum((x - m) ** 2 for x in v) / (n - 1))
    half = t_quantile_975(n - 1) * sd / math.sqrt(n)
    lo = m - half
    if min(v) >= 0:
        lo = max(lo, 0.0)
    return Interval(n=n, mean=m, lo=lo, hi=m + half, kind=T95)


def interval_text(iv: Union[Interval, SeedStats, None], digits: int = 3) -> str:
    """How every tool prints an interval (stats() or interval() output):
    'mean [lo, hi] (n=5, t95)', "mean (seeds' range lo to hi, n=3)", 'mean (n=1, no interval)', '-'."""
    if not iv or not iv.n:
        return "-"
    m = fnum(iv.mean, digits)
    kind = iv.kind if isinstance(iv, Interval) else iv.method
    if iv.n == 1 or kind == NO_INTERVAL:
        return f"{m} (n=1, no interval)"
    if kind == RANGE:
        return f"{m} (seeds' range {fnum(iv.lo, digits)} to {fnum(iv.hi, digits)}, n={iv.n})"
    return f"{m} [{fnum(iv.lo, digits)}, {fnum(iv.hi, digits)}] (n={iv.n}, {kind})"


INTERVAL_RULE_TEXT = ("intervals: n >= 5 seeds, the 95 % Student t interval of the mean, never below 0 for a non-negative quantity (t95); "
                      "2 to 4 seeds, no reliable interval exists, so the seeds' range (min to max) is shown instead, marked as such; "
                      "1 seed, none (docs/results.md \"Intervals\")")


def stats(values: Sequence[Optional[float]]) -> SeedStats:
    """The seeds' values (None and NaN left out) with their mean, median, standard deviation and
    interval()'s lo / hi / kind as method (the one rule; None where n < 2)."""
    v = [x for x in values if x is not None and not (isinstance(x, float) and math.isnan(x))]
    n = len(v)
    out = SeedStats(n=n, mean=None, median=None, sd=None, lo=None, hi=None, values=v, method=None)
    if n == 0:
        return out
    iv = interval(v)
    mean = iv.mean if iv.mean is not None else math.nan
    out.mean = iv.mean
    out.median = percentile(sorted(v), 0.5)
    if n < 2:
        return out
    out.sd = math.sqrt(sum((x - mean) ** 2 for x in v) / (n - 1))
    out.lo, out.hi, out.method = iv.lo, iv.hi, iv.kind
    return out


def is_number(v: object) -> TypeGuard[float]:
    """Whether v is a number (not a bool, not NaN)."""
    return isinstance(v, (int, float)) and not isinstance(v, bool) and not (isinstance(v, float) and math.isnan(v))


def outliers(values: Sequence[Optional[float]], factor: float = 3.0) -> list[int]:
    """Indices of the seeds whose (non-negative) error lies far above the others: above `factor`
    times the median of the other seeds AND further from it than `factor` times their range. Both
    conditions, so that three close small values (2.9, 3.0, 3.3 cm) flag nothing and one seed at
    806 cm beside two at 3 cm is flagged. Needs n >= 3 (with two seeds neither is "the odd one")."""
    out: list[int] = []
    vals = [v for v in values if v is not None]
    if len(values) < 3 or len(vals) < len(values):
        return out
    for i, x in enumerate(vals):
        others = sorted(vals[:i] + vals[i + 1:])
        med = percentile(others, 0.5)
        spread = others[-1] - others[0]
        if x > factor * med and x - med > factor * spread and x - med > 1e-9:
            out.append(i)
    return out


def _betacf(a: float, b: float, x: float) -> float:
    # Continued fraction of the incomplete beta function (modified Lentz), as in Numerical Recipes' derivation.
    tiny, qab, qap, qam = 1e-300, a + b, a + 1.0, a - 1.0
    c, d = 1.0, 1.0 - qab * x / qap
    d = 1.0 / (d if abs(d) > tiny else tiny)
    h = d
    for m in range(1, 300):
        m2 = 2 * m
        aa = m * (b - m) * x / ((qam + m2) * (a + m2))
        d = 1.0 + aa * d
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = 1.0 + aa / c
        c = c if abs(c) > tiny else tiny
        h *= d * c
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))
        d = 1.0 + aa * d
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = 1.0 + aa / c
        c = c if abs(c) > tiny else tiny
        de = d * c
        h *= de
        if abs(de - 1.0) < 1e-14:
            break
    return h


def betainc(a: float, b: float, x: float) -> float:
    """Regularised incomplete beta I_x(a, b)."""
    if x <= 0:
        return 0.0
    if x >= 1:
        return 1.0
    lbt = math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b) + a * math.log(x) + b * math.log(1 - x)
    if x < (a + 1) / (a + b + 2):
        return math.exp(lbt) * _betacf(a, b, x) / a
    return 1.0 - math.exp(lbt) * _betacf(b, a, 1 - x) / b


def t_two_sided_p(t: float, df: float) -> float:
    """P(|T| >= |t|) for Student's t with df degrees of freedom (df may be fractional: Welch)."""
    if df <= 0 or math.isnan(t):
        return float("nan")
    return betainc(df / 2.0, 0.5, df / (df + t * t))


def t_quantile_975(df: float) -> float:
    """The 0.975 quantile of Student's t by bisection on t_two_sided_p (exact enough for intervals)."""
    lo, hi = 0.0, 1000.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if t_two_sided_p(mid, df) > 0.05:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def welch(a: Sequence[Optional[float]], b: Sequence[Optional[float]]) -> Welch:
    """Welch's unequal-variance t-test of mean(b) - mean(a): diff, t, df, p; t, df and p are None
    when either side has fewer than two values (no seed-to-seed spread to compare with)."""
    sa, sb = stats(a), stats(b)
    diff = None if sa.mean is None or sb.mean is None else sb.mean - sa.mean
    if sa.n < 2 or sb.n < 2 or diff is None or sa.sd is None or sb.sd is None:
        return Welch(diff=diff, t=None, df=None, p=None)
    va, vb = sa.sd ** 2 / sa.n, sb.sd ** 2 / sb.n
    if va + vb == 0:
        # No spread on either side (deterministic metric): any difference is exact.
        return Welch(diff=diff, t=math.inf if diff else 0.0, df=float(sa.n + sb.n - 2), p=0.0 if diff else 1.0)
    t = diff / math.sqrt(va + vb)
    df = (va + vb) ** 2 / (va ** 2 / (sa.n - 1) + vb ** 2 / (sb.n - 1))
    return Welch(diff=diff, t=t, df=df, p=t_two_sided_p(t, df))


def fnum(v: Optional[float], digits: int = 3) -> str:
    if v is None or (isinstance(v, float) and (math.isnan(v) or math.isinf(v))):
        return "-"
    return f"{v:.{digits}f}"


def fstat(s: SeedStats, digits: int = 3) -> str:
    """interval_text of a stats() result: 'mean [lo, hi] (n=5, t95)', "mean (seeds' range lo to hi,
    n=3)", 'mean (n=1, no interval)'."""
    return interval_text(s, digits)


def wilson(k: int, n: int, z: float = 1.959963984540054) -> tuple[float, float]:
    """Wilson score interval (lo, hi) for k successes out of n; (0, 1) for n = 0."""
    if n == 0:
        return 0.0, 1.0
    p = k / n
    den = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return max(0.0, centre - half), min(1.0, centre + half)
