#!/usr/bin/python3
"""Mutation test of `omniloc validate` (robust input: every input class exits 0 or 2): deterministic
mutants of the shipped scenario, experiment and sweep files (sweeps since a sweep localizer's
"label" of the wrong type was found to exit 1), each run through `omniloc validate`, which must
exit 0 or 2 - never a signal, never another code, never hang. Besides the random mutants, every
shipped sweep is validated with its first scenario entry set to each hostile path of path_cases()
(tests/path_cases.py checks the words of every command's path errors).

Usage: mutation_validate.py OMNILOC [--count N] [--seed S] [--jobs J] [--keep DIR]
Exit 1 (listing the first bad inputs, saved under --keep) when any mutant misbehaves.
"""
import argparse
import concurrent.futures
import json
import os
import pathlib
import random
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent

# Values that once broke a reader: out-of-range and float-overflowing numbers, path tricks in
# names, deep nesting, NUL and invalid UTF-8, huge counts.
EXTREME_TEXT = ["1e400", "-1e400", "1e39", "-1e39", "1e308", "4e-400", "-0", "0", "-1", "18446744073709551616",
                "9007199254740993", "1.5", "true", "null", '""', '".."', '"../../x"', '"/"', '"."', '"\\u0000"',
                '"auto"', "[]", "{}", "[[[[[[[[[[]]]]]]]]]]", '"' + "x" * 5000 + '"']
EXTREME_JSON = [1e39, -1e39, 1e308, -1e308, 0, -1, 1, 2**63, 2**64, 0.5, 1e6, -1e6, True, None, "", "..", "../../x", "/", ".",
                "random", "auto", "\u0000", [], {}, [0, 0], [0, 0, 0], [1e39, 1e39], [[0, 0]] * 3, {"type": "still"},
                {"type": "constant", "velocity": [1e30, 0]}, {"type": "waypoints", "points": [[100, 0]]}, {"type": "matching"},
                {"width": 64, "height": 64}, {"centre_offset_px": [1e6, 0]}, {"calibration": "/nonexistent"},
                {"colour_table": "/"}, {"sectors": [[0, 10]] * 50}, list(range(200))]


def path_cases(work):
    """Hostile paths (the sweep's scenario entry of 5000 characters once ended in a raw "filesystem
    error: File name too long", exit 1): over NAME_MAX, over PATH_MAX, through a file, through a
    folder without permission, a link loop, a FIFO (whose reader would block), a device. Absolute,
    under `work` (see `prepare`), and relative to a mutant sweep (work/scenarios/sweeps/)."""
    return ["x" * 5000, "n" * 300, str(work / "/".join(["p" * 200] * 25)), str(work / "plain.txt" / "child.json"),
            "../../plain.txt/child.json", str(work / "locked" / "inside.json"), str(work / "loop"), str(work / "fifo"),
            str(work / "dev"), "/dev/zero", "../../fifo", ""]


def path_mutants(work, seeds):
    """Deterministic mutants: every shipped sweep with its first scenario entry (as a string and as
    {"file": ...}) and its first recording entry set to each hostile path."""
    out = []
    for name, text in seeds:
        if not is_sweep(name):
            continue
        for p in path_cases(work):
            for entry in (p, {"file": p}, {"recording": p}):
                m = json.loads(text)
                m["scenarios"][0] = entry
                out.append((name, json.dumps(m).encode()))
    return out


def corpus():
    """Every shipped input file: scenarios, experiments and sweeps. A sweep names its scenario files
    relative to itself and its external clients relative to the working directory, so its mutants are
    written into a copy of the scenarios/ tree (see `place`) and run where clients/ and build/ resolve."""
    files = sorted((ROOT / "scenarios").rglob("*.json"))
    return [(str(f.relative_to(ROOT / "scenarios")), f.read_bytes()) for f in files]


def is_sweep(name):
    return name.startswith("sweeps" + os.sep)


def prepare(work, omniloc):
    """The mutants' folder: scenarios/ copied (sweeps' relative paths), clients/ and tests/ linked, and
    build/ linked to the tested binary's folder (a sweep's C++ client is build/olp_cpp_example)."""
    shutil.copytree(ROOT / "scenarios", work / "scenarios")
    for name in ("clients", "tests", "data"):
        (work / name).symlink_to(ROOT / name)
    # What path_cases() points at.
    (work / "plain.txt").write_text("{}\n")
    os.mkfifo(work / "fifo")
    (work / "dev").symlink_to("/dev/zero")
    (work / "loop").symlink_to("loop")
    (work / "locked").mkdir(mode=0)
    (work / "build").symlink_to(pathlib.Path(omniloc).resolve().parent if os.sep in omniloc else ROOT / "build")


def place(work, k, name):
    """Where mutant k of `name` is written: sweeps beside the shipped sweeps, the rest in work/."""
    base = os.path.basename(name)
    if is_sweep(name):
        return work / "scenarios" / "sweeps" / f"m{k:06d}_{base}"
    return work / f"m{k:06d}_{base}"


def json_paths(j, prefix=()):
    yield prefix
    if isinstance(j, dict):
        for k, v in j.items():
            yield from json_paths(v, prefix + (k,))
    elif isinstance(j, list):
        for i, v in enumerate(j):
            yield from json_paths(v, prefix + (i,))


def set_at(j, path, value):
    if not path:
        return value
    node = j
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value
    return j


def mutate(rng, text):
    """One or more mutations of a byte string; structural ones go through Python's json."""
    ops = rng.randint(1, 3)
    for _ in range(ops):
        op = rng.randrange(11)
        n = len(text)
        if op == 0 and n:  # delete a range
            a = rng.randrange(n)
            text = text[:a] + text[a + rng.randint(1, 20):]
        elif op == 1:  # insert random bytes
            a = rng.randrange(n + 1)
            text = text[:a] + bytes(rng.randrange(256) for _ in range(rng.randint(1, 8))) + text[a:]
        elif op == 2 and n:  # duplicate a range
            a = rng.randrange(n)
            b = min(n, a + rng.randint(1, 200))
            text = text[:b] + text[a:b] + text[b:]
        elif op == 3 and n:  # truncate
            text = text[:rng.randrange(n)]
        elif op == 4:  # replace a number token with an extreme literal
            digits = [i for i, c in enumerate(text) if 48 <= c <= 57]
            if digits:
                a = rng.choice(digits)
                b = a
                while b < n and text[b:b + 1] in (b"0", b"1", b"2", b"3", b"4", b"5", b"6", b"7", b"8", b"9", b".", b"e", b"-"):
                    b += 1
                text = text[:a] + rng.choice(EXTREME_TEXT).encode() + text[b:]
        elif op == 5:  # deep nesting at a value position
            colons = [i for i, c in enumerate(text) if c == 58]
            if colons:
                a = rng.choice(colons) + 1
                k = rng.choice([10, 63, 64, 65, 1000, 100000])
                text = text[:a] + b"[" * k + b"]" * k + b"," + text[a:]
        elif op == 6 and n:  # a NUL or an invalid UTF-8 byte
            a = rng.randrange(n)
            text = text[:a] + rng.choice([b"\x00", b"\xff", b"\xc3", b"\xed\xa0\x80"]) + text[a:]
        else:  # structural: set / delete / duplicate a key through json
            try:
                j = json.loads(text)
            except (ValueError, UnicodeDecodeError, RecursionError):
                continue
            paths = list(json_paths(j))
            path = rng.choice(paths)
            if op == 7:
                j = set_at(j, path, rng.choice(EXTREME_JSON))
            elif op == 8 and path:
                node = j
                for p in path[:-1]:
                    node = node[p]
                del node[path[-1]]
            elif op == 9 and path and isinstance(path[-1], str):
                # duplicate key: render then repeat the member textually
                s = json.dumps(j)
                key = json.dumps(path[-1])
                i = s.find(key + ":")
                if i >= 0:
                    s = s[:i] + key + ": 1, " + s[i:]
                text = s.encode()
                continue
            else:
                j = set_at(j, path, rng.choice(EXTREME_JSON))
            try:
                text = json.dumps(j, allow_nan=True).encode()
            except (ValueError, RecursionError):
                pass
    return text


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("omniloc")
    ap.add_argument("--count", type=int, default=3000)
    ap.add_argument("--seed", type=int, default=19)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--keep", default=None, help="folder for the inputs that misbehaved")
    a = ap.parse_args()
    if os.sep in a.omniloc:  # the mutants run in their own folder: a relative path would not resolve there
        a.omniloc = str(pathlib.Path(a.omniloc).resolve())
    rng = random.Random(a.seed)
    seeds = corpus()
    work = pathlib.Path(tempfile.mkdtemp(prefix="omniloc_mutation_"))
    prepare(work, a.omniloc)
    # Inputs are generated up front from one seeded generator, so a run is reproducible whatever the
    # scheduling of the workers.
    # Hostile paths are also values a random mutation may put anywhere (a scenario's data files, a
    # client's cwd).
    EXTREME_JSON.extend(path_cases(work))
    inputs = []
    for k in range(a.count):
        name, text = seeds[rng.randrange(len(seeds))]
        inputs.append((k, name, mutate(rng, text)))
    fixed = [(a.count + i, name, text) for i, (name, text) in enumerate(path_mutants(work, seeds))]
    codes = {}
    bad = []
    t0 = time.monotonic()

    # Mutants go to `omniloc validate` in batches: with several files it validates each in its own
    # forked process and prints "[exit N] FILE" or "[signal S] FILE", so a crash is still a crash of
    # exactly that input, without paying the program's start-up (~0.2 s) per mutant.
    batch = 100

    def one(chunk, timeout=None):
        files = []
        for k, name, text in chunk:
            f = place(work, k, name)
            f.write_bytes(text)
            files.append((k, name, f))
        verdict = {}
        try:
            r = subprocess.run([a.omniloc, "validate"] + [str(f) for _, _, f in files], stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL, timeout=timeout or a.timeout * len(files), cwd=str(work))
            for line in r.stdout.decode(errors="replace").splitlines():
                if line.startswith("[exit ") or line.startswith("[signal "):
                    kind, _, rest = line[1:].partition("] ")
                    what, num = kind.split(" ")
                    verdict[rest] = int(num) if what == "exit" else -int(num)
        except subprocess.TimeoutExpired:
            pass  # the inputs without a verdict count as hangs
        out = []
        for k, name, f in files:
            rc = verdict.get(str(f), "no verdict (hang?)")
            if rc in (0, 2):
                f.unlink()
            out.append((k, name, rc, "", f))
        return out

    # The path mutants in small batches with one time limit each: a reader blocked on the FIFO
    # must not hold a whole batch for a.timeout per file.
    chunks = [(inputs[i:i + batch], None) for i in range(0, len(inputs), batch)]
    chunks += [(fixed[i:i + 20], a.timeout) for i in range(0, len(fixed), 20)]
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as ex:
        for results in ex.map(lambda c: one(*c), chunks):
            for k, name, rc, err, f in results:
                codes[rc] = codes.get(rc, 0) + 1
                if rc not in (0, 2):
                    bad.append((k, name, rc, err, f))
    secs = time.monotonic() - t0
    summary = ", ".join(f"exit {c}: {n}" if isinstance(c, int) and c >= 0 else f"{'signal ' + str(-c) if isinstance(c, int) else c}: {n}"
                        for c, n in sorted(codes.items(), key=lambda x: str(x[0])))
    sweeps = sum(1 for _, name, _ in inputs if is_sweep(name))
    print(f"mutation_validate: {a.count} mutants (seed {a.seed}; {sweeps} of them of the {sum(1 for n, _ in seeds if is_sweep(n))} "
          f"shipped sweeps, the rest of {sum(1 for n, _ in seeds if not is_sweep(n))} scenario and experiment files) "
          f"and {len(fixed)} sweeps with a hostile path in {secs:.1f} s with {a.jobs} jobs: {summary}")
    if bad:
        keep = pathlib.Path(a.keep) if a.keep else work
        keep.mkdir(parents=True, exist_ok=True)
        for k, name, rc, err, f in bad[:20]:
            dst = keep / f.name
            if f != dst:
                shutil.copy(f, dst)
            print(f"  BAD mutant {k} of {name}: {rc}; input kept as {dst}\n    {err.strip()}")
        print(f"mutation_validate: {len(bad)} mutants neither exited 0 nor 2")
        return 1
    os.chmod(work / "locked", 0o755)
    shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
