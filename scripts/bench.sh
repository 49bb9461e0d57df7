#!/usr/bin/env bash
# Runs every Google Benchmark program (build/bench_*) on one core and writes Google Benchmark JSON,
# with the commit and machine in its context, to OUT_DIR (default results/bench/<commit>).
# Usage: scripts/bench.sh [OUT_DIR] [extra benchmark flags], e.g. --benchmark_min_time=0.05 (seconds; Debian 12 ships Google Benchmark 1.7.1, which takes a plain number)
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
cd "$(dirname "$0")/.."
[ -x build/omniloc ] || scripts/build.sh
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
dirty=$(git diff --quiet 2>/dev/null || echo "-dirty")
out="${1:-results/bench/$commit$dirty}"
shift || true
mkdir -p "$out"
cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//' | tr ',' ' ')
export LP_NUM_THREADS=1   # llvmpipe on one core: the targets are per core
for b in build/bench_*; do
  [ -x "$b" ] || continue
  name=$(basename "$b")
  echo "== $name"
  taskset -c 0 "$b" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
    --benchmark_context=commit="$commit$dirty" --benchmark_context=cpu="$cpu" \
    --benchmark_out="$out/$name.json.tmp" --benchmark_out_format=json "$@" \
    && mv "$out/$name.json.tmp" "$out/$name.json"
done
# History: the medians of this run with the commit, one line appended to results/history/bench.jsonl
# (the report's history page, python/omniloc/report/history.py, draws them over commits; compare
# only records measured in the same minutes).
/usr/bin/python3 - "$out" "$commit$dirty" <<'EOF'
import datetime, glob, json, os, sys
out, commit = sys.argv[1:]
medians = {}
for f in sorted(glob.glob(os.path.join(out, "bench_*.json"))):
    for b in json.load(open(f)).get("benchmarks", []):
        if b.get("aggregate_name") == "median":
            scale = {"ns": 1, "us": 1e3, "ms": 1e6, "s": 1e9}[b.get("time_unit", "ns")]
            medians[b["run_name"]] = b["real_time"] * scale
os.makedirs("results/history", exist_ok=True)
with open("results/history/bench.jsonl", "a") as h:
    h.write(json.dumps({"commit": commit, "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                        "real_time_ns": medians}, sort_keys=True) + "\n")
EOF
echo "benchmark JSON in $out"
