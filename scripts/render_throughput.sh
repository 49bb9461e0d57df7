#!/usr/bin/env bash
# Frames per second of the renderer alone and of whole runs, per GL back-end and device, with
# 1 and several processes sharing the machine (and its GPU): docs/performance.md "GPUs".
#
# Usage: scripts/render_throughput.sh [-b BIN_DIR] [-o OUT_DIR] [-p "1 4 8"] [-B "osmesa egl"] [-s SECONDS] [-e SCENARIO]
#   -b  folder with omniloc and bench_render (default build)
#   -o  where the benchmark JSON, run folders and throughput.txt go (default results/throughput/<commit>)
#   -p  process counts (default "1 <cores>")
#   -B  back-ends (default "osmesa egl"; OMNILOC_EGL_DEVICE picks egl's device as in a run)
#   -s  seconds each render benchmark process runs (default 3)
#   -e  scenario for the end-to-end figure (default scenarios/paper/tracking.json, 1801 frames)
# "Render" is one PanoramicCamera::render of 640 x 640 (bench_render's <backend>_default: the CPU's
# vertex projection and photometry included, as a run pays them). "End to end" is P concurrent
# `omniloc run`s (seeds 1..P) after one run that fills the calibration and colour-table caches:
# frames of all runs / wall time. Nothing here is a pass/fail gate: the targets are in the docs.
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
root="$(cd "$(dirname "$0")/.." && pwd)"
bin="$root/build" out="" procs="" backends="osmesa egl" secs=3 scenario="$root/scenarios/paper/tracking.json"
while getopts "b:o:p:B:s:e:" opt; do
  case $opt in
    b) bin="$(cd "$OPTARG" && pwd)" ;; o) out="$OPTARG" ;; p) procs="$OPTARG" ;; B) backends="$OPTARG" ;;
    s) secs="$OPTARG" ;; e) scenario="$(cd "$(dirname "$OPTARG")" && pwd)/$(basename "$OPTARG")" ;;
    *) sed -n 2,10p "$0"; exit 2 ;;
  esac
done
cores=$(nproc)
[ -n "$procs" ] || procs="1 $cores"
commit=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)
[ -n "$out" ] || out="$root/results/throughput/$commit"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
report="$out/throughput.txt"
say() { echo "$*" | tee -a "$report"; }
: >"$report"
say "$("$bin/omniloc" --version 2>/dev/null | head -1); $(hostname); $cores cores: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'); $(date -u +%FT%TZ)"
if command -v nvidia-smi >/dev/null; then say "$(nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>&1)"; fi
"$bin/omniloc" gl-devices 2>&1 | tee -a "$report" || true

# Sum of frames_per_s over the P processes' benchmark JSON (they run side by side for $secs s).
sum_fps() {
  python3 - "$@" <<'EOF'
import json, sys
tot, each = 0.0, []
for f in sys.argv[1:]:
    for b in json.load(open(f)).get("benchmarks", []):
        if "error_message" in b:
            print("error:", b["error_message"]); sys.exit(1)
        each.append(b["frames_per_s"]); tot += b["frames_per_s"]
print(f"{tot:.0f} frames/s in all ({len(each)} processes: {', '.join(f'{x:.0f}' for x in each)})")
EOF
}

for be in $backends; do
  for p in $procs; do
    # llvmpipe's threads share the cores among the processes, as sweep -j does.
    lp=$(( cores / p > 0 ? cores / p : 1 ))
    pids=()
    for i in $(seq 1 "$p"); do
      LP_NUM_THREADS=$lp "$bin/bench_render" --benchmark_filter="BM_RenderFrame/${be}_default" --benchmark_min_time="$secs" \
        --benchmark_format=json --benchmark_out="$out/render_${be}_p${p}_$i.json" --benchmark_out_format=json >/dev/null 2>"$out/render_${be}_p${p}_$i.err" &
      pids+=($!)
    done
    ok=1
    for pid in "${pids[@]}"; do wait "$pid" || ok=0; done
    if [ $ok = 1 ]; then say "render $be 640x640, $p process(es): $(sum_fps "$out"/render_"${be}"_p"${p}"_*.json), ended $(date +%s)"
    else say "render $be, $p process(es): failed ($(head -c 300 "$out/render_${be}_p${p}_1.err"))"; fi
  done
done

# End to end: whole runs, P at a time.
frames_of() { python3 -c "import json,sys; print(sum(r['frames_total'] for r in json.load(open(sys.argv[1]))['robots']))" "$1"; }
for be in $backends; do
  work="$out/e2e_$be"
  rm -rf "$work"
  mkdir -p "$work"
  (
    cd "$work"
    export OMNILOC_GL_BACKEND=$be
    if ! "$bin/omniloc" run "$scenario" --seed 1000 -o cold --quiet >cold.log 2>&1; then
      echo "end to end $be: failed ($(tail -c 300 cold.log))"; exit 0
    fi
    echo "end to end $be: cold run (fills the caches) $(frames_of cold/summary.json) frames; rendering on $(python3 -c "import json; r=json.load(open('cold/summary.json'))['omniloc'].get('render',{}); print(r.get('renderer','?'))")"
    for p in $procs; do
      lp=$(( cores / p > 0 ? cores / p : 1 ))
      t0=$(date +%s.%N)
      pids=()
      for i in $(seq 1 "$p"); do
        LP_NUM_THREADS=$lp "$bin/omniloc" run "$scenario" --seed "$i" -o "p${p}_$i" --quiet >"p${p}_$i.log" 2>&1 &
        pids+=($!)
      done
      ok=1
      for pid in "${pids[@]}"; do wait "$pid" || ok=0; done
      t1=$(date +%s.%N)
      [ $ok = 1 ] || { echo "end to end $be, $p process(es): a run failed"; continue; }
      n=0
      for i in $(seq 1 "$p"); do n=$(( n + $(frames_of "p${p}_$i/summary.json") )); done
      python3 - "$be" "$p" "$n" "$t0" "$t1" "p${p}_1/timing.csv" <<'EOF'
import csv, statistics, sys
be, p, n, t0, t1, timing = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5]), sys.argv[6]
rows = list(csv.DictReader(open(timing)))
med = {k: statistics.median(float(r[k]) for r in rows) for k in rows[0] if k.endswith("_ms")}
print(f"end to end {be}, {p} process(es): {n / (t1 - t0):.0f} frames/s in all ({n} frames in {t1 - t0:.1f} s, ended {t1:.0f}); "
      f"per frame (medians of run 1): " + ", ".join(f"{k} {v:.2f}" for k, v in med.items()))
EOF
    done
  ) 2>&1 | tee -a "$report"
done
echo "figures in $report"
