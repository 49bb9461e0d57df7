"""Reading omniloc result folders and pairing them with the papers' published rows BY KEY.

Used by report.py, paper_table.py and compare.py (one implementation of loading, pairing and
statistics). A published row in results/reference/papers.json names the runs that reproduce it:

    "reproduced_by": {"rows": {"12.5 %": {"scenario": "tracking", "localizer": "matching",
                                          "config": {"/occlusion/fraction": 0.125}}, ...},
                      "config_defaults": {"/occlusion/fraction": 0.0}, "command": "..."}

A run matches a key when its summary's scenario and localizer are the key's and every JSON pointer
of "config" has that value in the run's effective configuration (config.json); a pointer absent
from the configuration takes its value from "config_defaults" (absent and no default: no match).
A key may say "start_pose_given" (true / false); a run that recorded the other value never matches
it (paper_claims.row_key gives every "(global start)" row false).
"scenario" may be a list of names: the first name that has matching runs is taken (the same
condition may be run under two names, e.g. the 50 % row as occlusion_002 or as tracking with a
swept occlusion; taking one avoids counting a seed twice). Where a run comes from (which sweep, its
position in it) never matters.

Statistics for few seeds (stats()): the mean, the median and every seed's value, and interval():
THE interval rule of omniloc, the same as batch/aggregate.cpp's mean_ci95 (docs/results.md
"Intervals", measured by scripts/interval_coverage.py): n >= 5, the 95 % Student t interval of the
mean, its lower bound clipped at 0 when no seed is negative ("t95"); 2 <= n <= 4, no reliable
interval exists, so the seeds' range min..max is given instead and says so ("range"); n = 1, none.
Each result names its kind. outliers() flags a seed whose error lies far above the others.
Welch's t-test for two result sets. No SciPy: Debian's python3 and python3-matplotlib are the only
dependencies.

No estimate (docs/results.md "Coverage and recall"): an error statistic over zero answered frames is
null in summary.json, with "why_null" beside it; it is never 0. Run.lookup() tells a null (found,
None) from an absent key (not found: a run from before the key); run_stats() counts the runs with a
value ("n") and those without ("no_value"), and every tool says "no estimate in k of n runs"
(no_estimate_text) where a statistic has none, never a number. recall/<threshold> is the share of
ALL scored frames within a (position, heading) threshold, valid_fraction the share answered; the
headline threshold (summary.json scoring.headline, headline_key()) is the one tables lead with.
"""
import contextlib
import csv
import json
import math
import os
import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parent.parent
PAPERS = ROOT / "results" / "reference" / "papers.json"

# The papers' error-table layout: (summary field, statistic), in the published column order.
TABLE_KEYS = [("x_cm", "mean"), ("y_cm", "mean"), ("theta_rad", "mean"), ("x_cm", "std"), ("y_cm", "std"), ("theta_rad", "std"),
              ("x_cm", "max"), ("y_cm", "max"), ("theta_rad", "max")]
TABLE_COLS = ["mean x cm", "mean y cm", "mean th rad", "std x cm", "std y cm", "std th rad", "max x cm", "max y cm", "max th rad"]


def load_papers():
    """papers.json (the published figures and the rules that judge ours), with each claim's causes
    from causes.json beside it (our explanations of the verdicts that do not hold: kept apart, so the
    papers' record holds only what the papers say)."""
    papers = json.loads(PAPERS.read_text())
    causes_file = PAPERS.with_name("causes.json")
    if causes_file.exists():
        causes = json.loads(causes_file.read_text()).get("claims", {})
        ids = {c["id"] for c in papers.get("claims", [])}
        unknown = sorted(set(causes) - ids)
        if unknown:
            raise ValueError(f"{causes_file}: causes for unknown claim(s) {', '.join(unknown)} (claims: {', '.join(sorted(ids))})")
        for c in papers.get("claims", []):
            if c["id"] in causes:
                c["causes"] = causes[c["id"]]
    return papers


def _skip_dir(d):
    return d.name.startswith(".") or ".staging" in d.name or d.name.endswith(".tmp") or ".partial" in d.name


# Sweep folders used although their aggregate was not final (discover(..., accept_incomplete=True)),
# so a tool can say so in its output.
INCOMPLETE = []


def incomplete_reason(d, files):
    """Why sweep folder `d` is not final, or None: only the merge (or a local sweep that ran every
    run) writes aggregate.json, with "complete" (batch/aggregate.hpp); a folder with runs/ and
    specs/ but no aggregate.json is a sweep whose shards or merge have not finished."""
    if "aggregate.json" in files:
        try:
            agg = json.loads((d / "aggregate.json").read_text())
        except (OSError, ValueError):
            return "its aggregate.json cannot be read"
        if agg.get("complete") is False:
            return f"its aggregate covers {agg.get('done')} of {agg.get('expected')} runs"
        return None
    if (d / "runs").is_dir() and (d / "specs").is_dir():
        return "it has no final aggregate yet (shards still running, or the merge `omniloc sweep SPEC --aggregate-only` not run)"
    return None


def discover(paths, accept_incomplete=False):
    """(runs, sweeps, experiments) under the given folders: run folders (summary.json, including those
    inside sweeps), sweep folders (aggregate.json) and experiment folders (PNG / JSON pictures).
    A sweep folder whose aggregate is not final stops it (SystemExit naming the folder) unless
    `accept_incomplete`; then its finished runs are used and the folder is listed in INCOMPLETE."""
    runs, sweeps, experiments = [], [], []
    stale = set()
    for p in paths:
        p = pathlib.Path(p)
        if not p.is_dir():
            raise SystemExit(f"{p}: not a folder")
        for d, subdirs, files in os.walk(p):
            d = pathlib.Path(d)
            if _skip_dir(d):
                subdirs[:] = []
                continue
            subdirs.sort()
            why = incomplete_reason(d, files)
            if why:
                if not accept_incomplete:
                    raise SystemExit(f"{d}: an incomplete sweep: {why}; see `omniloc sweep SPEC --status`, "
                                     "or pass --accept-incomplete to use its finished runs anyway")
                if d not in INCOMPLETE:
                    INCOMPLETE.append(d)
            if "aggregate.json" in files:
                sweeps.append(d)
                # Only the runs this sweep lists: a folder reused with another spec keeps old runs.
                listed = {row["id"] for row in read_csv(d / "runs.csv")}
                if listed and (d / "runs").is_dir():
                    stale.update(str(x) for x in (d / "runs").iterdir() if x.name not in listed)
            if str(d) in stale:
                subdirs[:] = []
                continue
            if "summary.json" in files:
                runs.append(d)
                subdirs[:] = []
            elif "aggregate.json" not in files and d.name != "img" and (any(f.endswith(".png") for f in files) or d.name + ".json" in files):
                experiments.append(d)  # an experiment's folder: its pictures, or its JSON named after it
    uniq = lambda xs: sorted(set(xs))
    return [Run(r) for r in uniq(runs)], uniq(sweeps), uniq(experiments)


class Run:
    """One run folder: summary.json (+ config.json, frames.csv, timing.csv on demand)."""

    def __init__(self, folder):
        self.folder = pathlib.Path(folder)
        self.summary = json.loads((self.folder / "summary.json").read_text())
        self._config = None

    scenario = property(lambda self: self.summary.get("scenario"))
    localizer = property(lambda self: self.summary.get("localizer"))
    seed = property(lambda self: self.summary.get("seed"))
    version = property(lambda self: (self.summary.get("omniloc") or {}).get("version", "unrecorded"))

    @property
    def start_pose_given(self):
        """Whether the localizer was reset with the true start pose (summary.json start_pose_given):
        True, False, or None for a run made before omniloc recorded it."""
        v = self.summary.get("start_pose_given")
        return v if isinstance(v, bool) else None

    @property
    def config(self):
        if self._config is None:
            f = self.folder / "config.json"
            self._config = json.loads(f.read_text()) if f.exists() else {}
        return self._config

    def robot(self, index=0):
        robots = self.summary.get("robots") or []
        return robots[index] if index < len(robots) else None

    def metric(self, path, phase="tracking", robot=0):
        """A number of robot `robot`'s summary, e.g. "x_cm/mean" or "recovery/recovered". With
        phase "tracking" it is read from the tracking-phase block where the run has one (kidnaps,
        covers) and the block has the key; otherwise from the all-frames figures. None when absent
        AND when null (no estimate): lookup() tells the two apart. A null of the tracking phase is
        never replaced by the all-frames figure."""
        found, v = self.lookup(path, phase, robot)
        return _plain(v) if found else None

    def lookup(self, path, phase="tracking", robot=0):
        """(found, value): found False when the summary has no such key (a run made before it);
        (True, None) when the statistic is null: no frame with an estimate (see why_null())."""
        r = self.robot(robot)
        if r is None:
            return False, None
        if phase == "tracking" and isinstance(r.get("tracking_phase"), dict):
            found, v = find(r["tracking_phase"], path)
            if found:
                return True, v
        return find(r, path)

    def why_null(self, path, phase="tracking", robot=0):
        """The reason summary.json gives beside a null statistic ("no estimate in any of the 30
        scored frames", "no kidnap recovered"): the "why_null" of the innermost block on the path
        that has one; None when there is none."""
        r = self.robot(robot)
        if r is None:
            return None
        block = r
        if phase == "tracking" and isinstance(r.get("tracking_phase"), dict) and find(r["tracking_phase"], path)[0]:
            block = r["tracking_phase"]
        why = block.get("why_null")
        for part in path.strip("/").split("/")[:-1]:
            block = block.get(part) if isinstance(block, dict) else None
            if not isinstance(block, dict):
                break
            why = block.get("why_null", why)
        return why if isinstance(why, str) else None

    @property
    def headline(self):
        """The key of the headline recall threshold ("25cm_10deg", summary.json scoring.headline);
        None for a run made before recall was scored."""
        h = (self.summary.get("scoring") or {}).get("headline")
        return h if isinstance(h, str) else None

    def frames(self):
        return read_csv(self.folder / "frames.csv")

    def timing(self):
        return read_csv(self.folder / "timing.csv")


def read_csv(path):
    path = pathlib.Path(path)
    if not path.exists():
        return []
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


def dig(obj, path):
    """obj["a"]["b"] for path "a/b" (numbers only); None when absent or null."""
    found, v = find(obj, path)
    return _plain(v) if found else None


def find(obj, path):
    """(found, value) of obj["a"]["b"] for path "a/b": (True, None) for a null (a statistic over no
    frame), (False, None) for an absent key."""
    for part in path.strip("/").split("/"):
        if isinstance(obj, dict) and part in obj:
            obj = obj[part]
        elif isinstance(obj, list) and part.isdigit() and int(part) < len(obj):
            obj = obj[int(part)]
        else:
            return False, None
    return True, obj


def _plain(v):
    return v if isinstance(v, (int, float)) and not isinstance(v, bool) else (v if isinstance(v, (dict, list, str, bool)) else None)


def pointer(obj, ptr):
    """(found, value) of a JSON pointer (RFC 6901) in obj."""
    if ptr in ("", "/"):
        return True, obj
    for raw in ptr[1:].split("/"):
        part = raw.replace("~1", "/").replace("~0", "~")
        if isinstance(obj, dict) and part in obj:
            obj = obj[part]
        elif isinstance(obj, list) and part.isdigit() and int(part) < len(obj):
            obj = obj[int(part)]
        else:
            return False, None
    return True, obj


def same_value(a, b):
    if isinstance(a, bool) or isinstance(b, bool):
        return a is b or a == b and type(a) is type(b)
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_value(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same_value(x, y) for x, y in zip(a, b))
    return a == b


SCENARIO_DEFAULT_PROFILE = "robot"  # what a scenario without "noise_profile" runs under
DEFAULT_PROFILE = "robot"  # the profile published rows pair by default (pairing_profile changes it)


@contextlib.contextmanager
def pairing_profile(name):
    """Within the block, keys without a /noise_profile pair runs of profile `name`."""
    global DEFAULT_PROFILE
    old, DEFAULT_PROFILE = DEFAULT_PROFILE, name
    try:
        yield
    finally:
        DEFAULT_PROFILE = old


def key_matches(run, key, defaults=None, scenario=None):
    """A published row's key matches runs of its scenario, localizer and configuration values; a key
    that names no /noise_profile means the default profile ("robot"), so runs under another profile
    (field_robot, ideal) never mix into the row."""
    defaults = defaults or {}
    if run.scenario != (scenario or key.get("scenario")):
        return False
    if "/noise_profile" not in (key.get("config") or {}):
        found, prof = pointer(run.config, "/noise_profile")
        if (prof if found else SCENARIO_DEFAULT_PROFILE) != DEFAULT_PROFILE:
            return False
    if "localizer" in key and run.localizer != key["localizer"]:
        return False
    if not start_pose_compatible(key.get("start_pose_given"), run.start_pose_given):
        return False
    for ptr, want in (key.get("config") or {}).items():
        found, have = pointer(run.config, ptr)
        if not found:
            if ptr not in defaults:
                return False
            have = defaults[ptr]
        if not same_value(have, want):
            return False
    return True


def start_pose_compatible(a, b):
    """Whether two start_pose_given values may share a row or be compared: equal, or either unknown
    (None: a key that does not say, a run made before omniloc recorded it). A run that tracked from
    the true start pose never pairs with one that had to find itself."""
    return a is None or b is None or a == b


def start_pose_text(given):
    """How a row says which task it ran: "given the start pose", "global start", or "" unknown."""
    return {True: "given the start pose", False: "global start"}.get(given, "")


def select(runs, key, defaults=None):
    """The runs that reproduce one published row (see the module's docstring), sorted by seed."""
    names = key["scenario"] if isinstance(key["scenario"], list) else [key["scenario"]]
    for name in names:
        hit = [r for r in runs if key_matches(r, key, defaults, scenario=name)]
        if hit:
            # One run per seed: the same run reported from two folders (a sweep and a copy) counts once.
            by_seed = {}
            for r in sorted(hit, key=lambda r: str(r.folder)):
                by_seed.setdefault(r.seed, r)
            return [by_seed[s] for s in sorted(by_seed)]
    return []


def describe_key(key):
    names = key["scenario"] if isinstance(key["scenario"], list) else [key["scenario"]]
    parts = [" or ".join(names)]
    if "localizer" in key:
        parts.append(key["localizer"])
    parts += [f"{p}={json.dumps(v)}" for p, v in (key.get("config") or {}).items()]
    return " / ".join(parts)


# ---- statistics -----------------------------------------------------------------------------

# The interval rule (one for every tool; batch/aggregate.cpp applies the same in C++): the kind
# names printed beside every interval, and aggregate.csv's "interval" column.
T95 = "t95"      # 95 % Student t interval of the mean, clipped at 0 for a non-negative sample (n >= 5)
RANGE = "range"  # the seeds' min..max: NOT a confidence interval (2 <= n <= 4: none is reliable)
NO_INTERVAL = "none"  # one seed
MIN_T_SEEDS = 5  # below this no candidate covered the mean reliably (scripts/interval_coverage.py)
STUDENT_T = T95  # old name


def percentile(sorted_vals, q):
    """The q-quantile (0..1) of sorted values, linear interpolation between order statistics."""
    pos = q * (len(sorted_vals) - 1)
    k = int(math.floor(pos))
    if k + 1 >= len(sorted_vals):
        return sorted_vals[-1]
    return sorted_vals[k] + (pos - k) * (sorted_vals[k + 1] - sorted_vals[k])


def interval(values):
    """The interval of the mean of a few seeds' values, by omniloc's one rule (docs/results.md
    "Intervals"): {"n", "mean", "lo", "hi", "kind"}.
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
        return {"n": 0, "mean": None, "lo": None, "hi": None, "kind": None}
    m = sum(v) / n
    if n == 1:
        return {"n": 1, "mean": m, "lo": m, "hi": m, "kind": NO_INTERVAL}
    if n < MIN_T_SEEDS:
        return {"n": n, "mean": m, "lo": min(v), "hi": max(v), "kind": RANGE}
    sd = math.sqrt(sum((x - m) ** 2 for x in v) / (n - 1))
    half = t_quantile_975(n - 1) * sd / math.sqrt(n)
    lo = m - half
    if min(v) >= 0:
        lo = max(lo, 0.0)
    return {"n": n, "mean": m, "lo": lo, "hi": m + half, "kind": T95}


def interval_text(iv, digits=3):
    """How every tool prints an interval (stats() or interval() output):
    'mean [lo, hi] (n=5, t95)', "mean (seeds' range lo to hi, n=3)", 'mean (n=1, no interval)', '-'."""
    if not iv or not iv["n"]:
        return "-"
    m = fnum(iv["mean"], digits)
    kind = iv.get("kind", iv.get("method"))
    if iv["n"] == 1 or kind == NO_INTERVAL:
        return f"{m} (n=1, no interval)"
    if kind == RANGE:
        return f"{m} (seeds' range {fnum(iv['lo'], digits)} to {fnum(iv['hi'], digits)}, n={iv['n']})"
    return f"{m} [{fnum(iv['lo'], digits)}, {fnum(iv['hi'], digits)}] (n={iv['n']}, {kind})"


INTERVAL_RULE_TEXT = ("intervals: n >= 5 seeds, the 95 % Student t interval of the mean, never below 0 for a non-negative quantity (t95); "
                      "2 to 4 seeds, no reliable interval exists, so the seeds' range (min to max) is shown instead, marked as such; "
                      "1 seed, none (docs/results.md \"Intervals\")")


def aggregate_interval(metric):
    """(lo, hi, kind) of one metric of an aggregate.json group ({"n", "mean", "ci95", "interval"}).
    Aggregates written before the rule have no "interval" and hold an unclipped Student t interval
    for every n >= 2: the kind returned is then "t95 (old aggregate)" for n >= 2, so a reader never
    takes it for the current rule's."""
    ci = metric.get("ci95") or [None, None]
    kind = metric.get("interval")
    if kind is None:
        kind = NO_INTERVAL if metric.get("n", 0) < 2 else "t95 (old aggregate)"
    return ci[0], ci[1], kind


def stats(values, method=None):
    """{"n", "mean", "median", "sd", "lo", "hi", "values", "method"} over the seeds' values: lo / hi /
    method are interval()'s lo / hi / kind (the one rule; None where n < 2). `method` is accepted for
    old callers and ignored: every tool uses the same rule."""
    v = [x for x in values if x is not None and not (isinstance(x, float) and math.isnan(x))]
    n = len(v)
    out = {"n": n, "mean": None, "median": None, "sd": None, "lo": None, "hi": None, "values": v, "method": None}
    if n == 0:
        return out
    iv = interval(v)
    out["mean"] = iv["mean"]
    out["median"] = percentile(sorted(v), 0.5)
    if n < 2:
        return out
    out["sd"] = math.sqrt(sum((x - iv["mean"]) ** 2 for x in v) / (n - 1))
    out["lo"], out["hi"], out["method"] = iv["lo"], iv["hi"], iv["kind"]
    return out


def is_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and not (isinstance(v, float) and math.isnan(v))


def no_estimate_text(k, n):
    """'no estimate in 1 of 3 runs': how every tool names runs whose statistic is null."""
    return f"no estimate in {k} of {n} runs"


def run_values(runs, path, phase="tracking"):
    """(values, no_value, of) of one statistic over runs: the numbers of the runs that have one, how
    many runs have it null (no estimate), and how many have the key at all (a run made before the
    key counts in neither)."""
    values, no_value, of = [], 0, 0
    for r in runs:
        found, v = r.lookup(path, phase)
        if not found:
            continue
        of += 1
        if is_number(v):
            values.append(v)
        elif v is None:
            no_value += 1
    return values, no_value, of


def run_stats(runs, path, phase="tracking"):
    """stats() over the runs that have a value, with "no_value" (runs where the statistic is null:
    no estimate), "of" (runs that have the key) and "why" (the reason to print where no run has a
    value: the runs' why_null where they agree on one that is not about estimates, e.g. "no kidnap
    recovered"; else "no estimate")."""
    values, no_value, of = run_values(runs, path, phase)
    st = stats(values)
    st.update(no_value=no_value, of=of, why=None)
    if no_value:
        whys = {r.why_null(path, phase) for r in runs if r.lookup(path, phase) == (True, None)}
        one = whys.pop() if len(whys) == 1 else None
        st["why"] = one if one and not one.startswith("no estimate") else NO_ESTIMATE
    return st


NO_ESTIMATE = "no estimate"


def stat_cell(st, digits=3, scale=1.0):
    """A table cell for run_stats() output: the mean; "no estimate" (or the runs' shared reason)
    where no run has a value; "-" where no run has the key. Runs without a value beside runs with one
    are not noted here: the caller names them once per row (no_value_note)."""
    if st.get("n"):
        return fnum(st["mean"] * scale, digits)
    if st.get("no_value"):
        return st.get("why") or NO_ESTIMATE
    return "-"


def no_value_note(sts):
    """'no estimate in 1 of 3 runs' for the worst of several run_stats() results of one row ('' when
    every run has every value)."""
    worst = max(sts, key=lambda s: (s.get("no_value", 0), s.get("of", 0)), default=None)
    if not worst or not worst.get("no_value"):
        return ""
    return no_estimate_text(worst["no_value"], worst["of"])


DEFAULT_HEADLINE = "25cm_10deg"


def headline_key(runs):
    """The headline recall threshold of a set of runs (the one most of them name in
    summary.json scoring.headline); None when none of them records one (runs made before recall)."""
    counts = {}
    for r in runs:
        h = r.headline
        if h:
            counts[h] = counts.get(h, 0) + 1
    return max(sorted(counts), key=lambda h: counts[h]) if counts else None


def recall_keys(runs):
    """Every recall threshold key the runs have (robot 0), tightest first."""
    keys = set()
    for r in runs:
        rob = r.robot() or {}
        keys |= {k for k in (rob.get("recall") or {})}
    return sorted(keys, key=recall_order)


def recall_order(key):
    m = _RECALL_KEY.fullmatch(str(key))
    return (float(m.group(1)), float(m.group(2)), key) if m else (math.inf, math.inf, str(key))


_RECALL_KEY = re.compile(r"(\d+(?:\.\d+)?(?:e[-+]?\d+)?)cm_(\d+(?:\.\d+)?(?:e[-+]?\d+)?)deg")


def recall_label(key):
    """'25 cm / 10 deg' for the key "25cm_10deg" (a reader's words, no underscore)."""
    m = _RECALL_KEY.fullmatch(str(key or ""))
    return f"{m.group(1)} cm / {m.group(2)} deg" if m else str(key).replace("_", " ")


def percent(v, digits=1):
    """'93.3 %' for 0.933; '-' for None."""
    return "-" if not is_number(v) else f"{100.0 * v:.{digits}f} %"


def outliers(values, factor=3.0):
    """Indices of the seeds whose (non-negative) error lies far above the others: above `factor`
    times the median of the other seeds AND further from it than `factor` times their range. Both
    conditions, so that three close small values (2.9, 3.0, 3.3 cm) flag nothing and one seed at
    806 cm beside two at 3 cm is flagged. Needs n >= 3 (with two seeds neither is "the odd one")."""
    out = []
    if len(values) < 3 or any(v is None for v in values):
        return out
    for i, x in enumerate(values):
        others = sorted(values[:i] + values[i + 1:])
        med = percentile(others, 0.5)
        spread = others[-1] - others[0]
        if x > factor * med and x - med > factor * spread and x - med > 1e-9:
            out.append(i)
    return out


def _betacf(a, b, x):
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


def betainc(a, b, x):
    """Regularised incomplete beta I_x(a, b)."""
    if x <= 0:
        return 0.0
    if x >= 1:
        return 1.0
    lbt = math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b) + a * math.log(x) + b * math.log(1 - x)
    if x < (a + 1) / (a + b + 2):
        return math.exp(lbt) * _betacf(a, b, x) / a
    return 1.0 - math.exp(lbt) * _betacf(b, a, 1 - x) / b


def t_two_sided_p(t, df):
    """P(|T| >= |t|) for Student's t with df degrees of freedom (df may be fractional: Welch)."""
    if df <= 0 or math.isnan(t):
        return float("nan")
    return betainc(df / 2.0, 0.5, df / (df + t * t))


def t_quantile_975(df):
    """The 0.975 quantile of Student's t by bisection on t_two_sided_p (exact enough for intervals)."""
    lo, hi = 0.0, 1000.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if t_two_sided_p(mid, df) > 0.05:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def welch(a, b):
    """Welch's unequal-variance t-test of mean(b) - mean(a): {"diff", "t", "df", "p"}; t, df and p are
    None when either side has fewer than two values (no seed-to-seed spread to compare with)."""
    sa, sb = stats(a), stats(b)
    out = {"diff": None if sa["mean"] is None or sb["mean"] is None else sb["mean"] - sa["mean"], "t": None, "df": None, "p": None}
    if sa["n"] < 2 or sb["n"] < 2:
        return out
    va, vb = sa["sd"] ** 2 / sa["n"], sb["sd"] ** 2 / sb["n"]
    if va + vb == 0:
        # No spread on either side (deterministic metric): any difference is exact.
        out.update(t=math.inf if out["diff"] else 0.0, df=float(sa["n"] + sb["n"] - 2), p=0.0 if out["diff"] else 1.0)
        return out
    t = out["diff"] / math.sqrt(va + vb)
    df = (va + vb) ** 2 / (va ** 2 / (sa["n"] - 1) + vb ** 2 / (sb["n"] - 1))
    out.update(t=t, df=df, p=t_two_sided_p(t, df))
    return out


def fnum(v, digits=3):
    if v is None or (isinstance(v, float) and (math.isnan(v) or math.isinf(v))):
        return "-"
    return f"{v:.{digits}f}"


def fstat(s, digits=3):
    """interval_text of a stats() result: 'mean [lo, hi] (n=5, t95)', "mean (seeds' range lo to hi,
    n=3)", 'mean (n=1, no interval)'."""
    return interval_text(s, digits)
