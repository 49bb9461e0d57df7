#!/usr/bin/env bash
# Runs every Google Benchmark program (build/bench_*) on one core and writes Google Benchmark JSON,
# with the commit and machine in its context, to OUT_DIR (default results/bench/<commit>).
# Usage: scripts/bench.sh [OUT_DIR] [extra benchmark flags], e.g. --benchmark_min_time=0.05 (seconds; Debian 12 ships Google Benchmark 1.7.1, which takes a plain number)
set -euo pipefail
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
echo "benchmark JSON in $out"
