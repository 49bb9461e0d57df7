#!/usr/bin/env python3
"""Compares instruction counts with the committed baseline (the logic of scripts/icount.sh).

usage: icount_compare.py COUNTS --baseline FILE [--threshold PCT] [--commit C] [--out FILE] [--update]

COUNTS holds lines "workload instructions milliseconds". Exit 1 when a workload needs more than
PCT % more instructions than the baseline or is missing from it; with --update the counts become the
baseline (merged over it) and are appended to icount_history.jsonl beside it. Every call appends its
record to results/history/icount.jsonl.
"""
import argparse
import datetime
import json
import os
import subprocess
import sys
import tempfile


def compare(counts, base, threshold):
    """Rows (workload, baseline or None, now, percent or None, verdict) and the failures."""
    rows, failed = [], []
    for w in sorted(counts):
        b = base.get(w)
        if b is None:
            rows.append((w, None, counts[w], None, "no baseline"))
            failed.append(f"{w}: not in the baseline (scripts/icount.sh --update adds it)")
            continue
        pct = 100.0 * (counts[w] - b) / b
        verdict = ""
        if pct > threshold:
            verdict = f"SLOWER than +{threshold:g}%"
            failed.append(f"{w}: {pct:+.2f}% instructions ({b} -> {counts[w]})")
        elif pct < -threshold:
            verdict = "faster: update the baseline (scripts/icount.sh --update)"
        rows.append((w, b, counts[w], pct, verdict))
    return rows, failed


def cpu_signature():
    """The CPU model and the instruction-set extensions that libm, OpenCV and llvmpipe choose code
    paths by: counts are comparable only between machines that agree on these."""
    model, flags = "unknown", set()
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name") and model == "unknown":
                model = line.split(":", 1)[1].strip()
            elif line.startswith("flags") and not flags:
                flags = set(line.split(":", 1)[1].split())
    except OSError:
        pass
    isa = [f for f in ("sse4_2", "avx", "avx2", "fma", "avx512f") if f in flags]
    return {"model": model, "isa": isa}


def append_jsonl(path, record):
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    with open(path, "a") as f:
        f.write(json.dumps(record, sort_keys=True) + "\n")


def write_atomic(path, text):
    folder = os.path.dirname(path) or "."
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".tmp")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("counts")
    ap.add_argument("--baseline", required=True)
    ap.add_argument("--threshold", type=float, default=3.0)
    ap.add_argument("--commit", default="unknown")
    ap.add_argument("--out")
    ap.add_argument("--update", action="store_true")
    ap.add_argument("--history", default="results/history/icount.jsonl")
    a = ap.parse_args()
    counts, ms = {}, {}
    for line in open(a.counts):
        w, ir, t = line.split()
        counts[w], ms[w] = int(ir), int(t)
    try:
        valgrind = subprocess.run(["valgrind", "--version"], capture_output=True, text=True).stdout.strip()
    except OSError:
        valgrind = "valgrind (unknown version)"
    record = {"commit": a.commit, "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
              "tool": valgrind + " callgrind", "cpu": cpu_signature(), "instructions": dict(sorted(counts.items())),
              "valgrind_seconds": {w: ms[w] / 1000.0 for w in sorted(ms)}}
    if a.history:
        append_jsonl(a.history, record)
    if a.out:
        write_atomic(a.out, json.dumps(record, indent=2, sort_keys=True) + "\n")
    base_record = json.load(open(a.baseline)) if os.path.exists(a.baseline) else {}
    base = base_record.get("instructions", {})
    if "cpu" in base_record and base_record["cpu"].get("isa") != record["cpu"]["isa"]:
        print(f"note: the baseline was counted on a CPU with {base_record['cpu']} and this one has {record['cpu']}; "
              "libm, OpenCV and llvmpipe pick other code paths by instruction set, so counts may differ for that reason")
    rows, failed = compare(counts, base, a.threshold)
    print(f"{'workload':28s} {'baseline':>15s} {'now':>15s} {'change':>8s} {'valgrind s':>10s}")
    for w, b, now, pct, verdict in rows:
        print(f"{w:28s} {b if b is not None else '-':>15} {now:>15d} {'' if pct is None else f'{pct:+.2f}%':>8s} "
              f"{ms[w] / 1000.0:10.1f}  {verdict}")
    if a.update:
        merged = dict(base)
        merged.update(counts)
        # Valgrind's wall time is this machine's, not part of the committed records.
        stored = {k: v for k, v in record.items() if k != "valgrind_seconds"}
        write_atomic(a.baseline, json.dumps(dict(stored, instructions=dict(sorted(merged.items())), threshold_percent=a.threshold),
                                            indent=2, sort_keys=True) + "\n")
        # The committed history: one record per baseline change, drawn by the report's history page (omniloc.report.history).
        append_jsonl(os.path.join(os.path.dirname(a.baseline) or ".", "icount_history.jsonl"), stored)
        print(f"baseline written: {a.baseline} (commit {a.commit}); commit it with a message that says why")
        return 0
    if failed:
        print("icount gate FAILED:\n  " + "\n  ".join(failed), file=sys.stderr)
        return 1
    print(f"icount gate passed: every workload within +{a.threshold:g}% of {a.baseline}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
