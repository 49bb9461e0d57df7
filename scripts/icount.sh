#!/usr/bin/env bash
# Instruction counts of fixed-work workloads (bench/icount.cpp) under valgrind's callgrind, compared
# with the committed baseline results/reference/icount.json. CI's speed gate: instruction counts do
# not move with the load on a shared VM (wall-clock medians there drift by 1.5x within an hour), so a
# few per cent is a real change in the code.
#
# Usage: scripts/icount.sh [--update] [--threshold PCT] [--only W1,W2] [--jobs N] [--out FILE]
#   (no option)  count every workload, print the table, exit 1 if any needs more than PCT % (default 3)
#                more instructions than the baseline, or if the baseline lacks a workload
#   --update     write the counts as the new baseline and append them to
#                results/reference/icount_history.jsonl (commit both with a message that says why)
#   --only       a comma-separated subset (see build/icount --list)
# Every run appends its counts, with the commit, to results/history/icount.jsonl (omniloc report
# --history draws them over commits).
set -euo pipefail
cd "$(dirname "$0")/.."
PY=/usr/bin/python3
baseline=results/reference/icount.json
threshold=3
update=0
only=""
jobs=$(nproc)
out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --update) update=1 ;;
    --threshold) threshold="$2"; shift ;;
    --only) only="$2"; shift ;;
    --jobs) jobs="$2"; shift ;;
    --out) out="$2"; shift ;;
    -h|--help) sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "icount.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
  shift
done
command -v valgrind >/dev/null || scripts/install-deps.sh
[ -f build/CMakeCache.txt ] || scripts/build.sh  # one place for the configure flags
cmake --build build -j"$(nproc)" --target icount >/dev/null

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [ -n "$only" ]; then
  tr ',' '\n' <<<"$only" >"$work/names"
else
  build/icount --list | awk '{print $1}' >"$work/names"
fi
# Calibration maps, colour tables and distance maps are cached on disk first, natively, so that no
# workload's count (or time) depends on whether a cache was warm. In a cache root of the build's own
# (docs/recording.md section 9), never the user's.
export OMNILOC_CACHE="$PWD/build/icount_cache"
build/icount --prepare
# Mesa's on-disk shader cache (~/.cache/mesa_shader_cache): llvmpipe compiles a shader it has not
# cached with LLVM, inside the counted region, so a cold or partly warm cache put 10-16 % on
# end_to_end's count with no change to our code (measured on a clean clone at ab04330: +16.3 % with
# the cache removed, +9.97 % in CI after the tests had warmed part of it). A native run does not warm
# it: under valgrind the CPU reports other features, so llvmpipe compiles other variants. One run of
# the rendering workload under valgrind's no-op tool (a few times faster than callgrind) stores them,
# so the count is the same on a fresh machine as on one that counted before.
LP_NUM_THREADS=0 valgrind --tool=none build/icount end_to_end >/dev/null 2>&1

# One workload: its instructions between CALLGRIND_START/STOP (the "totals:" line of the profile).
# llvmpipe draws in the calling thread (LP_NUM_THREADS=0) so that thread scheduling cannot move the
# count.
count_one() {
  local w=$1 dir=$2
  local t0 t1
  t0=$(date +%s%N)
  if ! LP_NUM_THREADS=0 valgrind --tool=callgrind --instr-atstart=no --callgrind-out-file="$dir/$w.cg" \
      build/icount "$w" >"$dir/$w.stdout" 2>"$dir/$w.log"; then
    echo "icount.sh: workload $w failed (log follows)" >&2
    tail -20 "$dir/$w.log" >&2
    return 1
  fi
  t1=$(date +%s%N)
  local ir
  ir=$(awk '/^totals:/ {print $2}' "$dir/$w.cg")
  printf '%s %s %s\n' "$w" "$ir" "$(( (t1 - t0) / 1000000 ))" >"$dir/$w.count"
}
export -f count_one
# Longest first, so the 30-frame end-to-end run does not start last on a free core.
{ grep -x end_to_end "$work/names" || true; grep -vx end_to_end "$work/names" || true; } \
  | xargs -P "$jobs" -I{} bash -c 'count_one "$@"' _ {} "$work"
cat "$work"/*.count >"$work/counts"

commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
dirty=$(git diff --quiet HEAD 2>/dev/null || echo "-dirty")
"$PY" scripts/icount_compare.py "$work/counts" --baseline "$baseline" --threshold "$threshold" \
  --commit "$commit$dirty" ${out:+--out "$out"} $([ "$update" = 1 ] && echo --update)
