#!/usr/bin/env python3
"""Runs two omniloc binaries through the same command lines and reports every difference.

usage: cli_compare.py OLD_BINARY NEW_BINARY [--keep DIR] [--list]

For a change that must not change what a user sees (a refactoring of apps/ or of how input is read):
each case (`omniloc --help`, every command's --help, bad options, bad localizer JSON in a scenario, a
sweep file and on the command line of run / replay / sweep, missing files, and a few cheap good runs)
runs once per binary in the same fresh folder (the same paths, an empty cache of its own), and its
stdout, stderr and exit code are compared byte for byte. `--version` is left out: it names the
commit, and a sweep's run times are blanked. Prints one line per differing case with a diff; exit 0 when all are identical, 1 otherwise.
--list prints the cases and runs nothing. Takes 1.5 to 2.5 minutes on the 2-core VM (238 cases, two binaries).
"""
import argparse
import difflib
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
REC = ROOT / "data" / "recordings" / "ci_tracking" / "1"
HAND = ROOT / "tests" / "data" / "handwritten_recording"
QUICK = ROOT / "scenarios" / "quickstart.json"


def scenario(**changes):
    s = json.loads(QUICK.read_text())
    s.update(changes)
    return s


# Files every case may name, written into its folder.
FIXTURES = {
    "short.json": scenario(duration=0.5),
    "loc_unknown.json": scenario(localizer={"type": "nope"}),
    "loc_type_number.json": scenario(localizer={"type": 3}),
    "loc_no_type.json": scenario(localizer={"particles": 3}),
    "loc_not_object.json": scenario(localizer=["mcl"]),
    "loc_bad_param.json": scenario(localizer={"type": "mcl", "particles": "many"}),
    "loc_unknown_key.json": scenario(localizer={"type": "matching", "bogus": 1}),
    "loc_external_missing.json": scenario(localizer={"type": "external", "command": ["./no_such_client"]}),
    "loc_external_label.json": scenario(localizer={"type": "external", "command": ["true"], "label": "mcl"}),
    "two_errors.json": scenario(localizer={"type": "nope"}, bogus_key=1),
    "l_good.json": {"type": "odometry_only"},
    "l_bad.json": {"type": "mcl", "particles": -5},
    "l_array.json": [{"type": "odometry_only"}, {"type": "nope"}],
    "l_number.json": 7,
    "l_broken.json": "{\"type\": ",
    "sweep_good.json": {"name": "cmp", "scenarios": ["short.json"], "localizers": [{"type": "odometry_only"}]},
    "sweep_bad_loc.json": {"name": "cmp", "scenarios": ["short.json"], "localizers": [{"type": "odometry_only"}, {"type": "mcl", "bogus": 1}]},
    "sweep_bad_type.json": {"name": "cmp", "scenarios": ["short.json"], "localizers": [{"type": "nope"}]},
    "sweep_entry_loc.json": {"name": "cmp", "scenarios": [{"file": "short.json", "localizers": [{"type": "matching", "rprop_iterations": "x"}]}]},
    "sweep_own_loc.json": {"name": "cmp", "scenarios": ["loc_bad_param.json"]},
    "sweep_param_loc.json": {"name": "cmp", "scenarios": [{"file": "short.json", "parameters": {"/localizer/bogus": [1]}}]},
    "sweep_rec.json": {"name": "cmp", "scenarios": [{"recording": str(REC)}], "localizers": [{"type": "odometry_only"}]},
    "sweep_rec_bad.json": {"name": "cmp", "scenarios": [{"recording": str(REC)}], "localizers": [{"type": "mcl", "bogus": 1}]},
    "sweep_rec_own.json": {"name": "cmp", "scenarios": [{"recording": str(REC)}]},
    "sweep_hand.json": {"name": "cmp", "scenarios": [{"recording": str(HAND)}], "localizers": [{"type": "matching", "bogus": 2}]},
    "sweep_hand_own.json": {"name": "cmp", "scenarios": [{"recording": str(HAND)}]},
    "notjson.json": "this is not json",
    "sweep_rec_own_bad.json": {"name": "cmp", "scenarios": [{"recording": "rec_badloc"}]},
    "sweep_rec_own_label.json": {"name": "cmp", "scenarios": [{"recording": "rec_badlabel"}]},
}


def recording_with_localizer(dest, localizer):
    """A copy of REC whose recorded scenario holds `localizer`: a recording made with a bad one."""
    shutil.copytree(REC, dest)
    h = json.loads((dest / "recording.json").read_text())
    h["scenario"]["localizer"] = localizer
    (dest / "recording.json").write_text(json.dumps(h, indent=1))

CPP = ["run", "record", "replay", "render", "calibrate", "colour-calibrate", "validate", "gl-devices", "list", "schema", "sweep",
       "experiment", "cache"]
PY = ["compare", "gate", "report", "paper-table", "global-start", "view"]


def cases():
    out = [[], ["--help"], ["-h"], ["nope"], ["help"]]
    out += [[c, "--help"] for c in CPP + PY] + [[c, "-h"] for c in CPP]
    out += [["run"], ["run", "a.json", "b.json"], ["run", "short.json", "--bogus"], ["run", "short.json", "--seed", "-1"],
            ["run", "short.json", "--seed", "x"], ["run", "short.json", "--frames-every", "0"], ["run", "short.json", "--seed"],
            ["run", "short.json", "--draw-each", "--no-cache"], ["run", "short.json", "--cache", "c", "--no-cache"],
            ["run", "missing.json"], ["run", "notjson.json"], ["run", "short.json", "-o", "nonempty"],
            ["run", "short.json", "--quiet=1"], ["run", "short.json", "--quiet", "-o", "out"], ["run", "scenarios/quickstart.json", "--help"],
            ["run", "short.json", "--quiet", "-o", "out", "--seed", "7", "--no-cache"]]
    for f in sorted(k for k in FIXTURES if k.startswith("loc_") or k == "two_errors.json"):
        out += [["run", f, "--quiet", "-o", "out"], ["validate", f]]
    out += [["validate", "short.json", "loc_unknown.json", "missing.json", "notjson.json"], ["validate", "sweep_good.json"],
            ["validate", "scenarios/quickstart.json"], ["validate"]]
    out += [["record"], ["record", "missing.json"], ["record", "short.json", "--images=yes"], ["record", "loc_unknown.json", "-o", "nonempty"]]
    locs = ["", " ", "{", "{bad", "[1]", "[{\"type\": \"odometry_only\"}]", "7", "{}", "{\"type\": 3}", "{\"type\": \"nope\"}",
            "{\"type\": \"mcl\", \"particles\": \"many\"}", "{\"type\": \"matching\", \"bogus\": 1}", "{\"type\": \"matching\", \"comment\": \"c\"}",
            "{\"type\": \"external\", \"command\": [\"./no_such_client\"]}", "{\"type\": \"external\", \"command\": [\"true\"], \"label\": \"mcl\"}",
            "{\"type\": \"external\", \"command\": [\"true\"], \"cwd\": \"no_dir\"}",
            "l_good.json", "l_bad.json", "l_array.json", "l_number.json", "l_broken.json", "missing_localizer.json", "nonempty"]
    for rec in (str(REC), str(HAND)):
        out += [["replay", rec, "--localizer", v, "--quiet", "-o", "out"] for v in locs]
        out += [["replay", rec, "--localizer", "{\"type\": \"odometry_only\"}", "--quiet", "-o", "out", "--seed", "3"],
                ["replay", rec, "--localizer", "{\"type\": \"mcl\"}", "--quiet", "-o", "nonempty"]]
    out += [["replay", str(REC)], ["replay", "missing_rec", "--localizer", "l_good.json"], ["replay", "nonempty", "--localizer", "l_good.json"],
            ["replay", str(REC), "--localizer", "l_good.json", "--seed", "-3"]]
    sweep_locs = ["{\"type\": \"nope\"}", "[{\"type\": \"odometry_only\"}, {\"type\": \"mcl\", \"bogus\": 1}]", "[]", "[7]", "7", "{", "",
                  "l_bad.json", "l_array.json", "{\"type\": \"odometry_only\", \"label\": \"a b\"}", "{\"type\": \"odometry_only\", \"label\": 5}"]
    for s in ("sweep_good.json", "sweep_rec.json", "sweep_hand_own.json"):
        out += [["sweep", s, "--localizer", v, "-o", "sw", "--stop-after", "1"] for v in sweep_locs]
        out += [["sweep", s, "--localizer", "l_good.json", "--localizer", "{\"type\": \"nope\"}", "-o", "sw"]]
    for f in sorted(k for k in FIXTURES if k.startswith("sweep_")):
        out += [["sweep", f, "-o", "sw", "--stop-after", "1", "--no-cache"], ["validate", f]]
    out += [["sweep"], ["sweep", "missing.json"], ["sweep", "sweep_good.json", "--slurm", "--localizer", "l_good.json"],
            ["sweep", "sweep_good.json", "--tasks", "2"], ["sweep", "sweep_good.json", "--shard", "3/2"], ["sweep", "sweep_good.json", "--shard", "x"],
            ["sweep", "sweep_good.json", "--status", "--slurm"], ["sweep", "sweep_good.json", "-j", "0"],
            ["sweep", "sweep_good.json", "--draw-each", "--cache", "c"], ["sweep", "sweep_good.json", "--aggregate-only", "-o", "sw"],
            ["sweep", "sweep_good.json", "--status", "-o", "sw", "--tasks", "1"],
            ["sweep", "sweep_good.json", "--slurm", "--dry-run", "--tasks", "2", "-o", "sw", "--no-cache"]]
    out += [["render"], ["render", "short.json"], ["render", "short.json", "-o", "f.png", "--t", "nan"],
            ["render", "short.json", "-o", "f.png", "--robot", "5"], ["render", "missing.json", "-o", "f.png"]]
    out += [["calibrate", "missing.json"], ["calibrate", "short.json", "--seed", "x"], ["calibrate", "short.json", "-o", "nonempty"],
            ["colour-calibrate", "missing.json"], ["colour-calibrate", "short.json", "--seed", "-1"]]
    out += [["list"], ["list", "x"], ["schema"], ["schema", "--sweep"], ["schema", "--markdown"], ["schema", "--markdown", "--sweep"],
            ["schema", "-o", "no_dir/x.json"], ["schema", "-o", "schema.json"], ["gl-devices", "x"]]
    out += [["experiment"], ["experiment", "nope"], ["experiment", "nope", "--bogus"], ["experiment", "nope", "--config", "missing.json"]]
    out += [["cache"], ["cache", "bogus", "--cache", "c"], ["cache", "size", "--cache", "c"], ["cache", "list", "--cache", "c"],
            ["cache", "prune", "--max-size", "x", "--cache", "c"]]
    out += [["compare"], ["gate", "x"], ["view", "missing_run"]]
    return out


def run_case(binary, args, work):
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    for name, content in FIXTURES.items():
        (work / name).write_text(content if isinstance(content, str) else json.dumps(content, indent=1))
    recording_with_localizer(work / "rec_badloc", {"type": "mcl", "bogus": 1})
    recording_with_localizer(work / "rec_badlabel", {"type": "mcl", "label": "a b"})
    (work / "nonempty").mkdir()
    (work / "nonempty" / "x").write_text("x")
    env = {k: v for k, v in os.environ.items() if not k.startswith("OMNILOC_")}
    env.update({"OMNILOC_CACHE": str(work / "cache"), "PYTHONDONTWRITEBYTECODE": "1"})
    try:
        r = subprocess.run([binary] + args, cwd=work, env=env, capture_output=True, timeout=300)
        # A sweep's progress line says how long each run took.
        return r.returncode, r.stdout, re.sub(rb": ok [0-9.e+-]+ s,", b": ok <seconds> s,", r.stderr)
    except subprocess.TimeoutExpired:
        return "timeout", b"", b""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("old", nargs="?")
    ap.add_argument("new", nargs="?")
    ap.add_argument("--keep", help="the folder the cases run in (default: a temporary one, removed afterwards)")
    ap.add_argument("--list", action="store_true", help="print the cases, run nothing")
    a = ap.parse_args()
    all_cases = cases()
    if not a.list and not (a.old and a.new):
        ap.error("give OLD_BINARY and NEW_BINARY")
    if a.list:
        for c in all_cases:
            print(" ".join(c))
        return 0
    base = pathlib.Path(a.keep) if a.keep else pathlib.Path(tempfile.mkdtemp(prefix="cli_compare_"))
    work = base / "work"
    different = 0
    by_code = {}
    for args in all_cases:
        old = run_case(os.path.abspath(a.old), args, work)
        new = run_case(os.path.abspath(a.new), args, work)
        by_code[old[0]] = by_code.get(old[0], 0) + 1
        if old == new:
            continue
        different += 1
        print(f"DIFFERENT: omniloc {' '.join(args)}")
        if old[0] != new[0]:
            print(f"  exit {old[0]} -> {new[0]}")
        for name, o, n in (("stdout", old[1], new[1]), ("stderr", old[2], new[2])):
            if o != n:
                diff = difflib.unified_diff(o.decode(errors="replace").splitlines(), n.decode(errors="replace").splitlines(),
                                            f"old {name}", f"new {name}", lineterm="", n=1)
                print("\n".join("  " + line for line in diff))
    if not a.keep:
        shutil.rmtree(base, ignore_errors=True)
    codes = ", ".join(f"{n} exit {c}" for c, n in sorted(by_code.items(), key=lambda x: str(x[0])))
    print(f"{len(all_cases)} cases ({codes}): {len(all_cases) - different} identical, {different} different")
    return 1 if different else 0


if __name__ == "__main__":
    sys.exit(main())
