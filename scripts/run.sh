#!/usr/bin/env bash
# The main job: installs what is missing (apt), builds, runs the paper suite as one sweep
# (scenarios/sweeps/paper_suite.json: every scenarios/paper/*.json and the variants the published
# tables need, three seeds each, both workers), the global localizers on the real robots' frames of
# data/real/nubot (scenarios/sweeps/real_robots.json, seconds), the paper suite under the field_robot
# profile, the paper figures' experiments, and writes the comparison report (results/report/report.html
# and report.md) with the reproduction scorecard and the real robots' section. Phases:
#   1/8 dependencies and build          5/8 paper suite, the other seeds (report)
#   2/8 paper suite, first seed         6/8 paper suite under the field_robot profile (report)
#   3/8 first scorecard and report      7/8 experiments (the papers' figures)
#   4/8 real robots' frames             8/8 final scorecard and report
#
# Usage: scripts/run.sh            default size (see README for the measured time)
#        scripts/run.sh --full     five seeds per scenario, the field_robot rows at three seeds, the
#                                  200-kidnap sweep of each global localizer, the global-start sweep
#                                  (20 seeds x 4 localizers), the lighting table with auto-adjust on
#                                  and off and the full-resolution experiments (a few hours on 2 cores)
#        scripts/run.sh FILE.json  one scenario, its error table printed
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
cd "$(dirname "$0")/.."
# A header per phase, so a reader of the terminal knows where the run is and how long each took.
t_start=$SECONDS
phase() { echo; echo "=== $1 (at $(( (SECONDS - t_start) / 60 )) min)"; }
phase "1/8 dependencies and build"
scripts/install-deps.sh
# Only the program it runs: the test and benchmark programs took 157 s of a fresh 9-minute build.
OMNILOC_BUILD_TARGETS=omniloc scripts/build.sh
PY=/usr/bin/python3; [ -x "$PY" ] || PY=python3
jobs="$(nproc)"

if [ $# -ge 1 ] && [ "$1" != "--full" ]; then
  exec ./build/omniloc run "$1"
fi
full=0; [ "${1:-}" = "--full" ] && full=1

# How many runs a sweep file makes (scenarios x localizers x parameter sets x seeds), from omniloc itself.
runs_of() { ./build/omniloc validate "$1" 2>/dev/null | sed -n 's/.*, \([0-9]*\) run(s)).*/\1/p' | head -1; }

# A copy of sweep SPEC with COUNT seeds, written to OUT (scenario paths made relative to results/suites/).
with_seeds() {
  mkdir -p results/suites
  "$PY" -c 'import json,sys; j=json.load(open(sys.argv[1])); j["seeds"]={"first":1,"count":int(sys.argv[3])}
base="../../scenarios/sweeps/"
j["scenarios"]=[({**s,"file":base+s["file"]} if isinstance(s,dict) else base+s) for s in j["scenarios"]]
open(sys.argv[2],"w").write(json.dumps(j,indent=1))' "$1" "$3" "$2"
}

# The report of what has landed so far, rewritten after each part (the scorecard's totals and the
# report's path are what the report command, python/omniloc/commands/report.py, prints last). $1: what
# is still to come ("" at the end).
report() {
  PYTHONPATH="python${PYTHONPATH:+:$PYTHONPATH}" "$PY" -m omniloc.commands.report "${results[@]}" -o results/report \
    --title "omniloc paper suite" >results/logs/report.log 2>&1 ||
    { cat results/logs/report.log; exit 1; }
  # The whole report is in report.html / report.md (and results/logs/report.log); the terminal gets its
  # totals and where it is.
  grep -E '^(scorecard|report): ' results/logs/report.log
  if [ -n "$1" ]; then
    echo "still running: $1; the report is rewritten when each part lands (total so far $(( (SECONDS - t_start) / 60 )) min)"
  else
    echo "open: $(pwd)/results/report/report.html (total $(( (SECONDS - t_start) / 60 )) min)"
  fi
}
mkdir -p results/report results/logs

# The paper suite: scenarios/sweeps/paper_suite.json holds every paper scenario and the variants the
# published tables need (three seeds per row); --full runs it with five seeds. Its first seed runs
# alone first (a third of the work), so the first scorecard comes early; the other seeds then join
# the same sweep folder (--resume skips the runs already there) and the report is rewritten.
spec=scenarios/sweeps/paper_suite.json
with_seeds "$spec" 1 results/suites/paper_suite_first_seed.json
if [ $full -eq 1 ]; then
  with_seeds "$spec" 5 results/suites/paper_suite.json
  spec=results/suites/paper_suite.json
fi
results=(results/sweeps/paper_suite)
phase "2/8 paper suite, first seed ($(runs_of results/suites/paper_suite_first_seed.json) runs, robot profile)"
./build/omniloc sweep results/suites/paper_suite_first_seed.json -j "$jobs"
# The first answer: the robot profile's scorecard from one seed (its verdicts say they rest on one).
phase "3/8 first scorecard and report (robot profile, one seed)"
report "the real robots' frames, the other seeds of the paper suite, the field_robot suite, then the experiments"

# The only real data: NuBot's four calibration frames (data/real/nubot) replayed with the global
# localizers, a few seconds; the report's "Real robots" section classifies each run against the
# reference pose and its 180-degree twin. In every report from here on.
phase "4/8 real robots' frames ($(runs_of scenarios/sweeps/real_robots.json) runs)"
./build/omniloc sweep scenarios/sweeps/real_robots.json -j "$jobs"
results+=(results/sweeps/real_robots)

phase "5/8 paper suite, the other seeds ($(runs_of "$spec") runs in all)"
./build/omniloc sweep "$spec" -j "$jobs" --resume
report "the field_robot suite, then the experiments"

# The same published rows under the field_robot profile, shown beside them in the report; one seed by
# default, three with --full (a contradiction between the profiles needs seed-to-seed spread).
fr_spec=scenarios/sweeps/paper_suite_field_robot.json
if [ $full -eq 1 ]; then
  with_seeds "$fr_spec" 3 results/suites/paper_suite_field_robot.json
  fr_spec=results/suites/paper_suite_field_robot.json
fi
phase "6/8 paper suite under the field_robot profile ($(runs_of "$fr_spec") runs)"
./build/omniloc sweep "$fr_spec" -j "$jobs"
results+=(results/sweeps/paper_suite_field_robot)
if [ $full -eq 1 ]; then
  # global_tracking: global start judged per run over 20 seeds (the report's "Global start" section).
  for s in kidnap_random global_tracking; do
    ./build/omniloc sweep "scenarios/sweeps/$s.json" -j "$jobs" --resume
    results+=("results/sweeps/$s")
  done
fi
report "the experiments"

# The figures' experiments (quick versions by default). Their tables go to the report, not the
# terminal: each one's own output is kept in results/experiments/<name>.log.
phase "7/8 experiments (the papers' figures)"
quick=--quick; [ $full -eq 1 ] && quick=
mkdir -p results/experiments
for e in $(./build/omniloc list | sed -n '/^experiments:/,/^$/p' | awk 'NR>1 && NF {print $1}'); do
  t0=$SECONDS
  ./build/omniloc experiment "$e" $quick >"results/experiments/$e.log" 2>&1 || { cat "results/experiments/$e.log"; exit 1; }
  echo "experiment $e: done in $(( SECONDS - t0 )) s (output: results/experiments/$e.log)"
  results+=("results/experiments/$e")
done

phase "8/8 final scorecard and report"
report ""
