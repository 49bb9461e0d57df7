#!/usr/bin/env python3
"""Are runs rendered by two back-ends (OSMesa and EGL on a GPU, say) statistically the same?

OSMesa's llvmpipe and a GPU's rasterizer do not draw identical pixels (sampling positions, the
shader's derivatives and precision, the order of blending), so byte equality is not the question:
each run's figures move, and what must hold is that they move within the seed-to-seed spread.

Usage: render_equivalence.py A_DIR B_DIR [--alpha-t T]
  A_DIR, B_DIR: folders of run folders <anything>/<scenario>/<seed>/summary.json (as `omniloc run -o`
  writes them), the same scenarios and seeds on both sides (pairs by scenario and seed).
Per scenario and metric: mean and standard deviation over the seeds on each side, the paired mean
difference, and Welch's t of the two samples; a metric fails when |t| exceeds the two-sided 95 %
quantile of Student's t at Welch's degrees of freedom. Exit 1 when any metric fails.
Also prints the share of the renderer in the difference: the mean |paired difference| against the
seed-to-seed standard deviation.
"""
import json
import math
import os
import statistics
import sys

# Two-sided 95 % quantiles of Student's t by degrees of freedom (rounded down); 1.96 beyond 120.
T975 = {1: 12.71, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306, 9: 2.262, 10: 2.228, 11: 2.201,
        12: 2.179, 13: 2.160, 14: 2.145, 15: 2.131, 16: 2.120, 17: 2.110, 18: 2.101, 19: 2.093, 20: 2.086, 25: 2.060,
        30: 2.042, 40: 2.021, 60: 2.000, 120: 1.980}


def t_quantile(df):
    if df >= 120:
        return 1.96
    keys = sorted(k for k in T975 if k <= max(1, int(df)))
    return T975[keys[-1]]


def metrics(summary):
    r = summary["robots"][0]
    m = {"line points per frame": r["line_points"]["mean"], "position rmse cm": 100 * r["position_m"]["rmse"],
         "position p95 cm": 100 * r["position_m"]["p95"], "theta rmse rad": r["theta_rmse_rad"], "wrong frames": r["wrong_frames"]}
    if "tracking_phase" in r:
        m["tracking-phase rmse cm"] = 100 * r["tracking_phase"]["position_m"]["rmse"]
    rec = r.get("recovery", {})
    if rec.get("episodes", 0) > 0:
        m["kidnaps recovered"] = rec["recovered"]
        times = [k["recovery_time_s"] for k in rec.get("per_kidnap", []) if k.get("recovered")]
        if times:
            m["mean recovery time s"] = statistics.mean(times)
    return m


def load(top):
    runs = {}
    for d, _, files in os.walk(top):
        if "summary.json" in files:
            s = json.load(open(os.path.join(d, "summary.json")))
            runs[(s["scenario"], s["seed"])] = (metrics(s), s.get("omniloc", {}).get("render", {}))
    return runs


def main():
    if sys.argv[1:2] in (["-h"], ["--help"]):
        print(__doc__)
        return 0
    if len(sys.argv) < 3:
        print(__doc__)
        return 2
    a, b = load(sys.argv[1]), load(sys.argv[2])
    keys = sorted(set(a) & set(b))
    if not keys:
        print("no scenario and seed on both sides")
        return 2
    for side, runs in (("A", a), ("B", b)):
        dev = next(iter(runs.values()))[1]
        print(f"{side}: {sys.argv[1 if side == 'A' else 2]}: {dev.get('backend', '?')} on {dev.get('renderer', '?')} ({dev.get('vendor', '?')})")
    failed = 0
    for scen in sorted({k[0] for k in keys}):
        seeds = [k for k in keys if k[0] == scen]
        print(f"\n{scen}: {len(seeds)} seeds ({', '.join(str(k[1]) for k in seeds)})")
        print(f"  {'metric':26s} {'A mean':>10s} {'A sd':>9s} {'B mean':>10s} {'B sd':>9s} {'paired d':>10s} {'|d|/sd':>7s} {'t':>7s} {'t95':>6s}  verdict")
        names = [n for n in a[seeds[0]][0] if all(n in a[k][0] and n in b[k][0] for k in seeds)]
        for n in names:
            xa = [a[k][0][n] for k in seeds]
            xb = [b[k][0][n] for k in seeds]
            ma, mb = statistics.mean(xa), statistics.mean(xb)
            sa = statistics.stdev(xa) if len(xa) > 1 else 0.0
            sb = statistics.stdev(xb) if len(xb) > 1 else 0.0
            d = [y - x for x, y in zip(xa, xb)]
            md = statistics.mean(d)
            mad = statistics.mean(abs(v) for v in d)
            se2 = sa * sa / len(xa) + sb * sb / len(xb)
            if se2 == 0:
                t, df = (0.0 if ma == mb else math.inf), 1e9
            else:
                t = (mb - ma) / math.sqrt(se2)
                den = (sa ** 4 / (len(xa) ** 2 * (len(xa) - 1)) if sa else 0) + (sb ** 4 / (len(xb) ** 2 * (len(xb) - 1)) if sb else 0)
                df = se2 * se2 / den if den > 0 else 1e9
            q = t_quantile(df)
            ok = abs(t) <= q
            failed += not ok
            rel = mad / sa if sa > 0 else (0.0 if mad == 0 else math.inf)
            print(f"  {n:26s} {ma:10.4f} {sa:9.4f} {mb:10.4f} {sb:9.4f} {md:10.4f} {rel:7.2f} {t:7.2f} {q:6.2f}  {'same' if ok else 'DIFFERENT'}")
    print(f"\n{failed} metric(s) differ beyond the seed-to-seed spread" if failed else "\nall metrics within the seed-to-seed spread (Welch t, 95 %)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
