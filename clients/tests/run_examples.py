#!/usr/bin/env python3
"""End-to-end checks of the olp/1 client examples through a real `omniloc run` (ctest runs these
from the source root; see clients/CMakeLists.txt).

  run_examples.py OMNILOC CHECK [--seconds S] [--seed N] [--max-mean-cm X] [--cpp-example PATH]

CHECK is one of
  dead_reckoning     python dead_reckoning.py: est.tum equal to the built-in odometry_only's within 1e-9 m
  cpp_dead_reckoning the C++ example (--cpp-example): the same
  particle_filter    particle_filter.py: summary.json's mean position error below --max-mean-cm
  own_vision         own_vision.py: the same
  rerun              particle_filter.py twice with one seed: est.tum and frames.csv byte-identical
The scenario is scenarios/paper/tracking.json cut to --seconds (a temporary copy); the examples
run under this interpreter (sys.executable), which needs numpy for the last three.
"""
import argparse
import csv
import json
import math
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "clients" / "python" / "examples"


def scenario(tmp, name, seconds, localizer):
    sc = json.loads((ROOT / "scenarios" / "paper" / "tracking.json").read_text())
    sc["duration"] = seconds
    sc["localizer"] = localizer
    sc["description"] = f"scenarios/paper/tracking.json cut to {seconds} s, for clients/tests/run_examples.py"
    path = Path(tmp) / f"{name}.json"
    path.write_text(json.dumps(sc, indent=2))
    return path


def run(omniloc, path, seed, out):
    t0 = time.monotonic()
    p = subprocess.run([omniloc, "run", str(path), "--seed", str(seed), "-o", str(out), "--overwrite", "--quiet"],
                       cwd=ROOT, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"omniloc run {path.name} failed ({p.returncode}):\n{p.stdout}\n{p.stderr}")
    summary = json.loads((Path(out) / "summary.json").read_text())
    print(f"{path.name}: {time.monotonic() - t0:.1f} s, localizer {summary.get('localizer')}, "
          f"robots[0] = {json.dumps(summary['robots'][0])[:400]}")
    return summary


def position_error_cm(run_dir):
    """Mean and rms of frames.csv's err_pos over the valid frames (summary.json gives the rmse and
    percentiles, not the mean), in cm, and the number of valid frames."""
    with open(Path(run_dir) / "frames.csv", newline="") as f:
        errs = [float(r["err_pos"]) for r in csv.DictReader(f) if r["valid"] == "1"]
    if not errs:
        sys.exit("no valid frame")
    return 100.0 * sum(errs) / len(errs), 100.0 * math.sqrt(sum(e * e for e in errs) / len(errs)), len(errs)


def tum(path):
    rows = []
    for line in Path(path).read_text().splitlines():
        rows.append([float(v) for v in line.split()])
    return rows


def check_equal_to_odometry_only(omniloc, tmp, args, command):
    ours = run(omniloc, scenario(tmp, "ext", args.seconds, {"type": "external", "command": command}), args.seed, Path(tmp) / "ext")
    builtin = run(omniloc, scenario(tmp, "builtin", args.seconds, {"type": "odometry_only"}), args.seed, Path(tmp) / "builtin")
    a, b = tum(Path(tmp) / "ext" / "est.tum"), tum(Path(tmp) / "builtin" / "est.tum")
    expected = round(args.seconds * 30) + 1
    if len(a) != len(b) or len(a) < expected:
        sys.exit(f"est.tum has {len(a)} rows, odometry_only's {len(b)} (expected {expected})")
    worst = max(max(abs(x - y) for x, y in zip(ra, rb)) for ra, rb in zip(a, b))
    print(f"{len(a)} poses, largest difference {worst:.3g}")
    if worst > 1e-9:
        sys.exit(f"est.tum differs from odometry_only's by {worst} (> 1e-9)")
    if ours["localizer"] == builtin["localizer"]:
        sys.exit("summary.json should name the client's localizer, not odometry_only")


def check_error(omniloc, tmp, args, script):
    s = run(omniloc, scenario(tmp, script, args.seconds, {"type": "external", "command": [sys.executable, str(EXAMPLES / f"{script}.py")]}),
            args.seed, Path(tmp) / "out")
    mean_cm, rmse_cm, valid = position_error_cm(Path(tmp) / "out")
    print(f"mean position error {mean_cm:.2f} cm (rmse {rmse_cm:.2f} cm, summary.json {100 * s['robots'][0]['position_m']['rmse']:.2f} cm), "
          f"{valid} valid frames; bound {args.max_mean_cm} cm")
    if valid != round(args.seconds * 30) + 1:
        sys.exit(f"{script}: {valid} valid frames; a tracking client from the true start pose should stand behind every frame")
    if not mean_cm < args.max_mean_cm:
        sys.exit(f"{script}: mean position error {mean_cm:.1f} cm is not below {args.max_mean_cm} cm")


def check_rerun(omniloc, tmp, args):
    path = scenario(tmp, "pf", args.seconds, {"type": "external", "command": [sys.executable, str(EXAMPLES / "particle_filter.py")]})
    run(omniloc, path, args.seed, Path(tmp) / "a")
    run(omniloc, path, args.seed, Path(tmp) / "b")
    for name in ("est.tum", "frames.csv"):
        if (Path(tmp) / "a" / name).read_bytes() != (Path(tmp) / "b" / name).read_bytes():
            sys.exit(f"{name} differs between two runs with seed {args.seed}")
    print("est.tum and frames.csv byte-identical")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("omniloc")
    ap.add_argument("check", choices=["dead_reckoning", "cpp_dead_reckoning", "particle_filter", "own_vision", "rerun"])
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--max-mean-cm", type=float, default=20.0)
    ap.add_argument("--cpp-example")
    args = ap.parse_args()
    omniloc = str(Path(args.omniloc).resolve())
    tmp = tempfile.mkdtemp(prefix=f"olp_{args.check}_")
    try:
        if args.check == "dead_reckoning":
            check_equal_to_odometry_only(omniloc, tmp, args, [sys.executable, str(EXAMPLES / "dead_reckoning.py")])
        elif args.check == "cpp_dead_reckoning":
            check_equal_to_odometry_only(omniloc, tmp, args, [str(Path(args.cpp_example).resolve())])
        elif args.check == "rerun":
            check_rerun(omniloc, tmp, args)
        else:
            check_error(omniloc, tmp, args, args.check)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
