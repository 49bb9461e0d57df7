#!/usr/bin/env bash
# Fuzzes the scenario, sweep and experiment readers (fuzz/scenario_fuzz.cpp, libFuzzer with ASan +
# UBSan) for SECONDS, starting from every JSON file under scenarios/ plus the corpus kept in
# build-asan/fuzz-corpus from earlier runs. Exit 1 on a finding; the input that caused it is saved
# as build-asan/fuzz-artifacts/crash-* (turn it into a test in tests/robust_input_test.cpp).
# Usage: scripts/fuzz.sh [SECONDS=60] [libFuzzer flags]
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
cd "$(dirname "$0")/.."
secs="${1:-60}"
shift || true
# OMNILOC_FUZZ_BUILT=1 (scripts/sanitize.sh --with-fuzz, which built it with the tests): no configure
# or build here, which would touch build-asan/ while its ctest reads it.
[ "${OMNILOC_FUZZ_BUILT:-0}" = 1 ] || scripts/asan_build.sh scenario_fuzz
corpus=build-asan/fuzz-corpus
mkdir -p "$corpus" build-asan/fuzz-artifacts
seeds=$(mktemp -d)
i=0
while IFS= read -r f; do cp "$f" "$seeds/$i.json"; i=$((i + 1)); done < <(find scenarios -name '*.json' | sort)
# olp/1 client streams (docs/protocol.md): inputs starting with "olp\n" go to the protocol reader.
for f in fuzz/olp_corpus/*; do cp "$f" "$seeds/olp_$(basename "$f")"; done
# Recordings (docs/recording.md): inputs starting with "rec\n" go to the recording reader.
for f in fuzz/recording_corpus/*; do cp "$f" "$seeds/rec_$(basename "$f")"; done
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/.ci/lsan-mesa.supp"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# -max_len: the shipped files are below 8 KiB; room for deep nesting and long arrays.
# -timeout: an input that takes 20 s to validate is a finding (100000 occlusion sectors once
# took 34 s: tests/robust_input_test.cpp LargeInputsValidateInLinearTime).
status=0
./build-asan/scenario_fuzz "$corpus" "$seeds" -max_total_time="$secs" -max_len=65536 -timeout=20 -rss_limit_mb=3072 \
  -artifact_prefix=build-asan/fuzz-artifacts/ -print_final_stats=1 "$@" 2>build-asan/fuzz.log || status=$?
tail -n 15 build-asan/fuzz.log
rm -rf "$seeds"
if [ $status -ne 0 ]; then
  echo "fuzz: FINDING (exit $status); see build-asan/fuzz.log and build-asan/fuzz-artifacts/" >&2
  exit 1
fi
echo "fuzz: no finding in $secs s"
