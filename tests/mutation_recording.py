#!/usr/bin/python3
"""Mutation test of `omniloc replay`: deterministic mutants of two recordings, a shipped one made by
`omniloc record` (data/recordings/ci_tracking/1, paper 002's tracking path, its first 2 s) and one written
by hand from docs/recording.md (tests/data/handwritten_recording, a log not made by omniloc), each
replayed with every built-in localizer. Each replay must exit 0 or 2: never a signal, never another
code, never hang.

Mutants change recording.json or one line of the frames: bytes (deleted, inserted, duplicated, cut),
JSON structure (keys set to other types, deleted, duplicated) and above all values (a number replaced
by an extreme one: 1e308, -1e308, 1e20, just past a documented limit, negative times...). Most mutants
get a frames_sha256 that matches the mutated frames, so the mutation reaches the value checks and
the localizers instead of stopping at the checksum; some keep the old one, and some mutate the gzip
stream itself.

A mutant that replays with one localizer is replayed with every other built-in one too (a value a
reader lets through reaches all of them); a mutant refused (exit 2) is refused whichever localizer
was named, and leaves no run folder (the frames are read as the replay consumes them:
docs/recording.md section 7).

Usage: mutation_recording.py OMNILOC [--count N] [--seed S] [--jobs J] [--keep DIR]
Exit 1 (listing the first bad inputs, kept under --keep) when any replay misbehaves.
"""
import argparse
import concurrent.futures
import gzip
import hashlib
import json
import os
import pathlib
import random
import shutil
import subprocess
import sys
import tempfile
import time

from mutation_validate import mutate

ROOT = pathlib.Path(__file__).resolve().parent.parent
SEEDS = [ROOT / "data" / "recordings" / "ci_tracking" / "1", ROOT / "tests" / "data" / "handwritten_recording"]
LOCALIZERS = ["matching", "grid_global", "mcl", "hybrid", "landmarks", "odometry_only", "ukf_mh"]

# Values at and past docs/recording.md's limits (50 m, 1000 rad, 3600 s, exposure 1e4 ms, gain 1e3),
# and ones that overflow a localizer's arithmetic.
EXTREME_NUMBERS = [1e308, -1e308, 1e20, -1e20, 50.0, -50.0, 50.000001, -50.000001, 1000.0, 1000.5, -1000.5, 3600.0, 3600.5,
                   1e4, 1e4 + 1, -1e-300, 5e-324, 0.0, -0.0, -1.0, 2 ** 53 + 1, 2 ** 63, 0.5, 7.49, 12.0]


def read_seed(folder, frames=60):
    """(header, frames lines) of a recording folder, frames uncompressed: its first `frames` frames
    (2 s at 30 Hz; a replay then costs about the program's start, so a thousand mutants take a minute)."""
    head = json.loads((folder / "recording.json").read_text())
    raw = (folder / head["frames_file"]).read_bytes()
    if head["frames_file"].endswith(".gz"):
        raw = gzip.decompress(raw)
    lines = raw.split(b"\n")[:-1][:frames]
    head["frames"] = len(lines)
    head["duration_s"] = min(head["duration_s"], len(lines) / head["camera_rate_hz"])
    head["frames_sha256"] = hashlib.sha256(b"".join(line + b"\n" for line in lines)).hexdigest()
    return head, lines


def numbers_at(j, path=()):
    """JSON paths of every number in j."""
    if isinstance(j, bool):
        return
    if isinstance(j, (int, float)):
        yield path
    elif isinstance(j, dict):
        for k, v in j.items():
            yield from numbers_at(v, path + (k,))
    elif isinstance(j, list):
        for i, v in enumerate(j):
            yield from numbers_at(v, path + (i,))


def set_number(rng, text):
    """One number of a JSON text set to an extreme value (a value mutation that keeps the structure)."""
    try:
        j = json.loads(text)
    except (ValueError, UnicodeDecodeError, RecursionError):
        return text
    paths = list(numbers_at(j))
    if not paths:
        return text
    path = rng.choice(paths)
    node = j
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = rng.choice(EXTREME_NUMBERS)
    return json.dumps(j, separators=(",", ":")).encode()


def make_mutant(rng, head, lines, folder):
    """Writes one mutant recording into `folder`."""
    head = json.loads(json.dumps(head))
    lines = list(lines)
    target = rng.random()
    if target < 0.15:  # the header
        text = json.dumps(head, indent=1).encode()
        text = set_number(rng, text) if rng.random() < 0.5 else mutate(rng, text)
        head_text = text
    else:
        head_text = None
        op = rng.random()
        if op < 0.55:  # a value in a frame
            k = rng.randrange(len(lines))
            for _ in range(rng.randint(1, 3)):
                lines[k] = set_number(rng, lines[k])
        elif op < 0.85:  # bytes or structure of a frame
            k = rng.randrange(len(lines))
            lines[k] = mutate(rng, lines[k])
        else:  # whole lines: deleted, duplicated, swapped
            k = rng.randrange(len(lines))
            kind = rng.randrange(3)
            if kind == 0:
                del lines[k]
            elif kind == 1:
                lines.insert(k, lines[k])
            elif len(lines) > 1:
                j = rng.randrange(len(lines))
                lines[k], lines[j] = lines[j], lines[k]
    frames = b"".join(line + b"\n" for line in lines)
    if rng.random() < 0.9:  # the checksum follows the change, so the values are what is tested
        head["frames_sha256"] = hashlib.sha256(frames).hexdigest()
    gz = head.get("frames_file") == "frames.jsonl.gz"
    data = gzip.compress(frames, mtime=0) if gz else frames
    if gz and rng.random() < 0.05:  # the gzip stream itself
        data = mutate(rng, data)
    folder.mkdir(parents=True)
    (folder / ("frames.jsonl.gz" if gz else "frames.jsonl")).write_bytes(data)
    (folder / "recording.json").write_bytes(head_text if head_text is not None else json.dumps(head, indent=1).encode())


def replay(omniloc, folder, localizer, out, timeout):
    """Exit code of one replay (negative: the signal it died of; None: it hung)."""
    try:
        r = subprocess.run([omniloc, "replay", str(folder), "--localizer", json.dumps({"type": localizer}), "-o", str(out), "--quiet"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=timeout)
        # A refused recording writes nothing: no run folder, no staging folder beside it.
        left = out.exists() or any(p.name.startswith("." + out.name) for p in out.parent.iterdir())
    except subprocess.TimeoutExpired:
        return None, "timeout"
    finally:
        shutil.rmtree(out, ignore_errors=True)
    if r.returncode == 2 and left:
        return 99, "exit 2 but a run folder was left: " + r.stderr.decode(errors="replace")[-300:]
    return r.returncode, r.stderr.decode(errors="replace")[-400:]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("omniloc")
    ap.add_argument("--count", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=46)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--keep", default=None, help="folder for the mutants that misbehaved")
    a = ap.parse_args()
    omniloc = str(pathlib.Path(a.omniloc).resolve())
    rng = random.Random(a.seed)
    seeds = [(s.relative_to(ROOT), *read_seed(s)) for s in SEEDS]
    work = pathlib.Path(tempfile.mkdtemp(prefix="omniloc_mutation_recording_"))
    # Every mutant is made up front from one seeded generator: a run is reproducible whatever the
    # scheduling of the workers.
    mutants = []
    for k in range(a.count):
        name, head, lines = seeds[k % len(seeds)]
        folder = work / f"m{k:05d}"
        make_mutant(rng, head, lines, folder)
        mutants.append((k, name, folder))

    def one(m):
        k, name, folder = m
        first = LOCALIZERS[k % len(LOCALIZERS)]
        results = [(first, *replay(omniloc, folder, first, work / f"out{k}", a.timeout))]
        if results[0][1] == 0:
            results += [(loc, *replay(omniloc, folder, loc, work / f"out{k}", a.timeout)) for loc in LOCALIZERS if loc != first]
        return k, name, folder, results

    codes, bad, replays = {}, [], 0
    t0 = time.monotonic()
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as ex:
        for k, name, folder, results in ex.map(one, mutants):
            ok = True
            for loc, rc, err in results:
                replays += 1
                codes[rc] = codes.get(rc, 0) + 1
                if rc not in (0, 2):
                    ok = False
                    bad.append((k, name, loc, rc, err, folder))
            if ok:
                shutil.rmtree(folder, ignore_errors=True)
    secs = time.monotonic() - t0

    def label(c):
        return "hang" if c is None else f"signal {-c}" if c < 0 else f"exit {c}"

    summary = ", ".join(f"{label(c)}: {n}" for c, n in sorted(codes.items(), key=lambda x: (x[0] is None, x[0] or 0)))
    print(f"mutation_recording: {a.count} mutants (seed {a.seed}) of {', '.join(str(s[0]) for s in seeds)}, {replays} replays "
          f"with {', '.join(LOCALIZERS)} in {secs:.1f} s with {a.jobs} jobs: {summary}")
    if bad:
        keep = pathlib.Path(a.keep) if a.keep else work / "kept"
        keep.mkdir(parents=True, exist_ok=True)
        for k, name, loc, rc, err, folder in bad[:20]:
            dst = keep / folder.name
            if not dst.exists():
                shutil.copytree(folder, dst)
            print(f"  BAD mutant {k} of {name} with {loc}: {label(rc)}; kept as {dst}\n    {err.strip()}")
        print(f"mutation_recording: {len(bad)} replays neither exited 0 nor 2")
        return 1
    shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
