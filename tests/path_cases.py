#!/usr/bin/python3
"""Every path a user can hand omniloc, made hostile: each command's path options and positional
arguments, the paths inside scenario, sweep, experiment and gate rules files, and the files inside a
recording, each given a name over NAME_MAX, a path over PATH_MAX, a component that is a file, a
folder without permission, a symbolic-link loop, a FIFO, a device (a link to /dev/zero), a missing
file, the wrong kind (a folder for a file, a file for a folder) and relative forms. Every case
must end in exit 2 (exit 0 only where root ignores the permission), naming the option or JSON path
and the reason in words - never exit 1, a signal, a hang (a FIFO opened for reading blocks), a
"filesystem error", "terminate called" or a Python traceback.

Usage: path_cases.py OMNILOC [--jobs J] [--only SUBSTRING] [--list]
Exit 1 listing every case that misbehaved (its command line and what it printed).
"""
import argparse
import concurrent.futures
import json
import os
import pathlib
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import zlib

ROOT = pathlib.Path(__file__).resolve().parent.parent
ROOTED = os.geteuid() == 0
FORBIDDEN = ["filesystem error", "terminate called", "Traceback (most recent call last)", "what():"]

# The words each case's reason must hold (the operating system's for what the kernel refuses, ours
# for kinds it allows but omniloc cannot use). None: root ignores permissions, so any exit 0 / 2 is
# right as long as an exit 2 says something.
WORDS = {
    "name_max": "File name too long",
    "path_max": "File name too long",
    "relative_name_max": "File name too long",
    "file_component": "Not a directory",
    "relative_file_component": "Not a directory",
    "no_permission": None if ROOTED else "Permission denied",
    "symlink_loop": "Too many levels of symbolic links",
    "fifo": "FIFO",
    "device": "character device",
    "missing": "No such file or directory",
    "folder_for_file": "a folder, not a regular file",
    "file_for_folder": "a regular file, not a folder",
    "optional": None,  # an optional file that is not a readable one is skipped: exit 0 (or 2 with words)
}
# Cases for a file or folder that is read, and for one that is written (a missing output is fine,
# and the wrong kind of an existing output is what --overwrite decides).
READ_FILE = ["name_max", "path_max", "relative_name_max", "file_component", "relative_file_component", "no_permission",
             "symlink_loop", "fifo", "device", "missing", "folder_for_file"]
READ_FOLDER = ["name_max", "path_max", "relative_name_max", "file_component", "relative_file_component", "no_permission",
               "symlink_loop", "fifo", "device", "missing", "file_for_folder"]
# Root writes where it likes: there the permission case of an output would only do the work.
WRITE = ["name_max", "path_max", "relative_name_max", "file_component", "relative_file_component", "symlink_loop", "fifo",
         "device"] + ([] if ROOTED else ["no_permission"])


def hostile(w):
    """The path of each case (absolute under w, or relative to w, where every command runs)."""
    (w / "plain.txt").write_text("{}\n")
    (w / "adir").mkdir()
    os.mkfifo(w / "fifo")
    (w / "dev").symlink_to("/dev/zero")
    (w / "loop").symlink_to("loop")
    (w / "locked").mkdir()
    os.chmod(w / "locked", 0)
    return {
        "name_max": str(w / ("n" * 300)),
        "path_max": str(w / "/".join(["p" * 200] * 25)),
        "relative_name_max": "r" * 300,
        "file_component": str(w / "plain.txt" / "child"),
        "relative_file_component": "plain.txt/child",
        "no_permission": str(w / "locked" / "inside"),
        "symlink_loop": str(w / "loop"),
        "fifo": str(w / "fifo"),
        "device": str(w / "dev"),
        "missing": str(w / "absent"),
        "folder_for_file": str(w / "adir"),
        "file_for_folder": str(w / "plain.txt"),
    }


def scenario(base, **extra):
    s = json.loads((ROOT / "scenarios" / base).read_text())
    s.update(extra)
    return s


def fixtures(w, omniloc):
    """Small valid inputs beside the hostile paths: a 0.2 s scenario without a camera (its run and
    its recording take well under a second), a camera scenario to validate, a sweep, a run folder,
    gate rules and an error_budget description. Returns the recording's folder."""
    tiny = scenario("quickstart.json", duration=0.2, name="tiny")
    (w / "tiny.json").write_text(json.dumps(tiny))
    (w / "bad.json").write_text("{}\n")  # a scenario that fails validation: heavy commands stop at it
    (w / "sweep.json").write_text(json.dumps({"scenarios": ["tiny.json"]}))
    (w / "rules.json").write_text(json.dumps({"rules": [{"metric": "position_m/rmse", "max": 100}]}))
    env = dict(os.environ, OMNILOC_CACHE="off")
    for cmd in (["run", "tiny.json", "-o", "run1", "--no-cache", "--quiet"], ["record", "tiny.json", "-o", "rec", "--quiet"]):
        r = subprocess.run([omniloc] + cmd, cwd=w, capture_output=True, text=True, timeout=120, env=env)
        if r.returncode != 0:
            sys.exit(f"fixture {' '.join(cmd)} failed: {r.stderr}")
    return w / "rec"


def json_fields():
    """(name, file written, how the hostile path goes in, JSON path named, commands that read it, kind)."""
    cam = lambda **v: scenario("regression/tracking_short.json", **v)  # noqa: E731
    ext = lambda **v: scenario("quickstart.json", duration=0.2, localizer=dict({"type": "external", "command": ["true"]}, **v))  # noqa: E731
    eb = json.loads((ROOT / "scenarios" / "experiments" / "error_budget.json").read_text())
    return [
        ("scenario /vision/calibration", "f.json", lambda p: cam(vision={"calibration": p}), "/vision/calibration", READ_FILE),
        ("scenario /vision/colour_table", "f.json", lambda p: cam(vision={"colour_table": p}), "/vision/colour_table", READ_FILE),
        ("scenario /localizer/cwd", "f.json", lambda p: ext(cwd=p), "/localizer/cwd", READ_FOLDER),
        ("scenario /localizer/command/0", "f.json",
         lambda p: ext(command=[p if "/" in p else "./" + p]), "/localizer/command/0", READ_FILE),
        ("scenario /localizer/command/1", "f.json", lambda p: ext(command=["python3", p]), "/localizer/command/1", READ_FILE),
        ("scenario /localizer/hash/0", "f.json", lambda p: ext(hash=[p]), "/localizer/hash/0", READ_FILE),
        ("sweep /scenarios/0", "s.json", lambda p: {"scenarios": [p]}, "/scenarios/0", READ_FILE),
        ("sweep /scenarios/0/file", "s.json", lambda p: {"scenarios": [{"file": p}]}, "/scenarios/0/file", READ_FILE),
        ("sweep /scenarios/0/recording", "s.json", lambda p: {"scenarios": [{"recording": p}]}, "/scenarios/0/recording", READ_FOLDER),
        ("sweep /localizers/0/cwd", "s.json",
         lambda p: {"scenarios": ["tiny.json"], "localizers": [{"type": "external", "command": ["true"], "cwd": p}]},
         "/localizers/0", READ_FOLDER),
        ("experiment /scenario", "e.json", lambda p: dict(eb, scenario=p), "/scenario", READ_FILE),
    ]


def command_fields(rec):
    """(name, argv with {} for the hostile path, what stderr must name (None: the path itself), kind)."""
    out = "{out}"  # each case's own output, which must not exist after it (refused before any work)
    loc = '{"type": "odometry_only"}'
    return [
        ("validate FILE", ["validate", "{}"], None, READ_FILE),
        ("run FILE", ["run", "{}", "--no-cache", "--quiet", "-o", out], None, READ_FILE),
        ("run -o", ["run", "tiny.json", "--no-cache", "--quiet", "-o", "{}"], "-o", WRITE),
        ("run --frames", ["run", "tiny.json", "--no-cache", "--quiet", "-o", out, "--frames", "{}"], "--frames", WRITE),
        ("run --cache", ["run", "tiny.json", "--quiet", "-o", out, "--cache", "{}"], "--cache", WRITE),
        ("record FILE", ["record", "{}", "--quiet", "-o", out], None, READ_FILE),
        ("record -o", ["record", "tiny.json", "--quiet", "-o", "{}"], "-o", WRITE),
        ("replay RECORDING", ["replay", "{}", "--localizer", loc, "--quiet", "-o", out], None, READ_FOLDER),
        ("replay --localizer", ["replay", str(rec), "--localizer", "{}", "--quiet", "-o", out], "--localizer", READ_FILE),
        ("replay -o", ["replay", str(rec), "--localizer", loc, "--quiet", "-o", "{}"], "-o", WRITE),
        ("render FILE", ["render", "{}", "-o", out + ".png"], None, READ_FILE),
        ("render -o", ["render", "bad.json", "-o", "{}"], "-o", WRITE),
        ("calibrate FILE", ["calibrate", "{}", "-o", out + ".json"], None, READ_FILE),
        ("calibrate -o", ["calibrate", "bad.json", "-o", "{}"], "-o", WRITE),
        ("colour-calibrate FILE", ["colour-calibrate", "{}", "-o", out + ".lut"], None, READ_FILE),
        ("colour-calibrate -o", ["colour-calibrate", "bad.json", "-o", "{}"], "-o", WRITE),
        ("schema -o", ["schema", "-o", "{}"], "-o", WRITE),
        ("sweep SWEEP", ["sweep", "{}", "--no-cache", "-o", out], None, READ_FILE),
        ("sweep -o", ["sweep", "sweep.json", "--no-cache", "-o", "{}"], "-o", WRITE),
        ("sweep --resume -o", ["sweep", "sweep.json", "--no-cache", "--resume", "-o", "{}"], "-o", WRITE),
        ("sweep --aggregate-only -o", ["sweep", "sweep.json", "--no-cache", "--aggregate-only", "-o", "{}"], "-o", WRITE),
        ("sweep --status -o", ["sweep", "sweep.json", "--status", "-o", "{}"], "-o", WRITE),
        ("sweep --localizer", ["sweep", "sweep.json", "--no-cache", "--localizer", "{}", "-o", out], "--localizer", READ_FILE),
        ("sweep --cache", ["sweep", "sweep.json", "--cache", "{}", "-o", out], "--cache", WRITE),
        ("experiment --config", ["experiment", "error_budget", "--config", "{}", "-o", out], "--config", READ_FILE),
        ("experiment -o", ["experiment", "error_budget", "--config", "bad.json", "-o", "{}"], "-o", WRITE),
        ("cache --cache", ["cache", "list", "--cache", "{}"], "--cache", WRITE),
        # The results package (python/omniloc/commands), through the same binary.
        ("view RUN_DIR", ["view", "{}", "-o", out + ".html"], None, READ_FOLDER),
        ("view -o", ["view", "run1", "-o", "{}"], None, WRITE),
        ("view --recording", ["view", "run1", "--recording", "{}", "-o", out + ".html"], None, READ_FOLDER),
        ("view --frames", ["view", "run1", "--frames", "{}", "-o", out + ".html"], "--frames", READ_FOLDER),
        ("report RESULTS", ["report", "{}", "-o", out], "RESULTS", READ_FOLDER),
        ("report --baseline", ["report", "run1", "--baseline", "{}", "-o", out], "--baseline", READ_FOLDER),
        ("report --history", ["report", "run1", "--history", "{}", "-o", out], "--history", READ_FOLDER),
        ("report -o", ["report", "run1", "-o", "{}"], "-o", WRITE),
        ("gate RESULTS", ["gate", "{}", "--rules", "rules.json"], None, READ_FOLDER),
        ("gate --rules", ["gate", "run1", "--rules", "{}"], None, READ_FILE),
        ("gate --baseline", ["gate", "run1", "--rules", "rules.json", "--baseline", "{}"], "baseline", READ_FOLDER),
        ("gate --junit", ["gate", "run1", "--rules", "rules.json", "--junit", "{}"], "--junit", WRITE),
        ("gate --benchmark-json", ["gate", "run1", "--rules", "rules.json", "--benchmark-json", "{}"], "--benchmark-json", WRITE),
        ("compare A", ["compare", "{}", "run1"], None, READ_FOLDER),
        ("compare B", ["compare", "run1", "{}"], None, READ_FOLDER),
        ("paper-table RESULTS", ["paper-table", "{}", "--paper", "000_tracking"], None, READ_FOLDER),
        ("global-start FOLDER", ["global-start", "{}"], None, READ_FOLDER),
        ("global-start --json", ["global-start", "run1", "--json", "{}"], "--json", WRITE),
    ]


def png_1x1():
    """A one-pixel grey PNG, written by hand (no imaging library needed)."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 1, 1, 8, 0, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(b"\x00\x80")) + chunk(b"IEND", b""))


def recording_files(w, rec):
    """Recordings whose own files are hostile: recording.json and the frames file each replaced by a
    FIFO, a link to /dev/zero, a link loop, a folder or nothing (and, without root, made unreadable).
    Read by replay and by a sweep's {"recording": ...} entry. Yields (name, recording folder, file)."""
    head = json.loads((rec / "recording.json").read_text())
    # A recording with images (its header says so; the 0.2 s scenario draws none): frame 0's image.
    img = w / "rec_images"
    shutil.copytree(rec, img)
    (img / "recording.json").write_text(json.dumps(dict(head, images=True)))
    (img / "images").mkdir()
    for r in head["robots"]:
        for k in range(head["frames"]):
            (img / "images" / f"r{r['id']}_{k:06d}.png").write_bytes(png_1x1())
    for file in ("recording.json", head.get("frames_file", "frames.jsonl"), "images/r0_000000.png"):
        for case in ("fifo", "device", "symlink_loop", "folder_for_file", "missing", "no_permission"):
            d = w / f"rec_{file.split('.')[0].replace('/', '_')}_{case}"
            src = img if file.startswith("images/") else rec
            shutil.copytree(src, d)
            f = d / file
            f.unlink()
            if case == "fifo":
                os.mkfifo(f)
            elif case == "device":
                f.symlink_to("/dev/zero")
            elif case == "symlink_loop":
                f.symlink_to(f.name)
            elif case == "folder_for_file":
                f.mkdir()
            elif case == "no_permission":
                shutil.copy(src / file, f)
                os.chmod(f, 0)
            yield f"recording {file} {case}", d, file, case
    # timing.csv is optional: anything but a readable file there is as if it were absent (a replay
    # that opened a FIFO would block for ever), so the replay of this one succeeds.
    d = w / "rec_timing_fifo"
    shutil.copytree(rec, d)
    (d / "timing.csv").unlink()
    os.mkfifo(d / "timing.csv")
    yield "recording timing.csv fifo", d, "timing.csv", "optional"


def judge(job, rc, text, took):
    """None when one case behaved (exit `rc`, printed `text`), else what was wrong."""
    words = WORDS[job["case"]]
    bad = [f for f in FORBIDDEN if f in text]
    if rc is None:
        return "hung (no exit within the time limit)"
    if rc < 0:
        return f"killed by signal {-rc}"
    if bad:
        return f"exit {rc} with {bad[0]!r}"
    if rc not in (0, 2):
        return f"exit {rc}"
    if rc == 0:
        return None if words is None else "exit 0: the path was not refused"
    if not text.strip():
        return "exit 2 without a message"
    if words and words not in text:
        return f"exit 2 without the words {words!r}"
    if job["label"] not in text:
        return f"exit 2 without naming {job['label']!r}"
    left = sorted(str(x) for x in job["out"].parent.glob(job["out"].name + "*")) if job["out"] else []
    if left:
        return f"exit 2 but wrote {left[0]}: refused only after work"
    if took is not None and took > 20:
        return f"took {took:.0f} s: refused only after work"
    return None


def run_one(job, w, omniloc, timeout):
    t0 = time.monotonic()
    try:
        r = subprocess.run([omniloc] + job["argv"], cwd=w, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                           errors="replace", timeout=timeout, env=dict(os.environ, OMNILOC_CACHE=str(w / "cache")))
    except subprocess.TimeoutExpired:
        return [judge(job, None, "", None)]
    return [judge(job, r.returncode, r.stdout, time.monotonic() - t0)]


def run_validate_batch(jobs, w, omniloc, timeout):
    """Many `omniloc validate FILE` cases in one call: it checks each file in a forked child, whose
    message comes before the "[exit N] FILE" line the parent prints after it."""
    files = [j["argv"][1] for j in jobs]
    try:
        r = subprocess.run([omniloc, "validate"] + files, cwd=w, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                           errors="replace", timeout=timeout, env=dict(os.environ, OMNILOC_CACHE=str(w / "cache")))
    except subprocess.TimeoutExpired:
        return [judge(j, None, "", None) for j in jobs]
    got, text = {}, []
    for line in r.stdout.splitlines():
        for marker, sign in (("[exit ", 1), ("[signal ", -1)):
            if line.startswith(marker) and "] " in line:
                code, _, f = line[len(marker):].partition("] ")
                got[f] = (sign * int(code), "\n".join(text))
                text = []
                break
        else:
            text.append(line)
    return [judge(j, *got.get(j["argv"][1], (None, "")), None) for j in jobs]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("omniloc")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--only", default="", help="only the fields whose name holds this")
    ap.add_argument("--list", action="store_true", help="list the commands x cases and exit")
    a = ap.parse_args()
    omniloc = str(pathlib.Path(a.omniloc).resolve())
    w = pathlib.Path(tempfile.mkdtemp(prefix="omniloc_paths_"))
    try:
        paths = hostile(w)
        rec = fixtures(w, omniloc)
        (w / "out").mkdir()
        jobs = []

        def add(name, case, argv, label, batch=False):
            out = w / "out" / f"{len(jobs):04d}"
            argv = [x.replace("{out}", str(out)) for x in argv]
            jobs.append({"name": name, "case": case, "argv": argv, "label": label, "out": out, "batch": batch})

        for name, argv, label, cases in command_fields(rec):
            for case in cases:
                p = paths[case]
                # A positional path is named by itself: its first characters (a long one is cut).
                add(name, case, [p if x == "{}" else x for x in argv], label or p[:60])
        for name, file, make, where, cases in json_fields():
            for case in cases:
                f = w / f"{len(jobs):04d}_{file}"
                f.write_text(json.dumps(make(paths[case])))
                add(name + " (validate)", case, ["validate", str(f)], where, batch=True)
                # run and sweep read these fields through the same readers as validate: one case of
                # each kind of reason shows they are reached before any work.
                if case not in ("name_max", "relative_file_component", "fifo", "device"):
                    continue
                if file == "f.json":
                    add(name + " (run)", case, ["run", str(f), "--no-cache", "--quiet", "-o", "{out}"], where)
                elif file == "s.json":
                    add(name + " (sweep)", case, ["sweep", str(f), "--no-cache", "-o", "{out}"], where)
        loc = '{"type": "odometry_only"}'
        for name, d, file, case in recording_files(w, rec):
            add(name + " (replay)", case, ["replay", str(d), "--localizer", loc, "--quiet", "-o", "{out}"], file)
            if file.startswith("images/") or case == "optional":
                continue  # a sweep's validation reads the header and checks the frames file, not each image
            s = w / f"{len(jobs):04d}_rs.json"
            s.write_text(json.dumps({"scenarios": [{"recording": str(d), "localizers": [{"type": "odometry_only"}]}]}))
            add(name + " (sweep)", case, ["validate", str(s)], file, batch=True)
        jobs = [j for j in jobs if a.only in j["name"]]
        if a.list:
            for j in jobs:
                print(f"{j['name']:48s} {j['case']}")
            return 0
        t0 = time.monotonic()
        single = [j for j in jobs if not j["batch"]]
        batched = [j for j in jobs if j["batch"]]
        groups = [[j] for j in single] + [batched[i:i + 40] for i in range(0, len(batched), 40)]
        work = lambda g: run_one(g[0], w, omniloc, a.timeout) if not g[0]["batch"] else run_validate_batch(g, w, omniloc, a.timeout)  # noqa: E731
        with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
            verdicts = [v for vs in pool.map(work, groups) for v in vs]
        ordered = [j for g in groups for j in g]
        failed = [(j, v) for j, v in zip(ordered, verdicts) if v]
        fields = sorted({j["name"] for j in jobs})
        print(f"{len(jobs)} cases over {len(fields)} command x path fields in {time.monotonic() - t0:.1f} s "
              f"({'as root: permission cases accept exit 0' if ROOTED else 'not root'}); {len(failed)} misbehaved")
        for j, why in failed:
            shown = " ".join(x if len(x) < 80 else x[:40] + "..." for x in j["argv"])
            print(f"FAIL {j['name']} [{j['case']}]: {why}\n     omniloc {shown}")
        return 1 if failed else 0
    finally:
        os.chmod(w / "locked", 0o755)
        for p in w.rglob("*"):
            if p.is_file() and not p.is_symlink():
                os.chmod(p, 0o644)
        shutil.rmtree(w, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
