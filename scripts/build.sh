#!/usr/bin/env bash
# Configures and builds omniloc in build/ (Release, warnings as errors). Extra arguments go to cmake.
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOMNILOC_WERROR=ON "$@" >/dev/null
# OMNILOC_BUILD_TARGETS="omniloc": only those targets (scripts/run.sh needs no tests or benchmarks).
cmake --build build -j"$(nproc)" ${OMNILOC_BUILD_TARGETS:+--target $OMNILOC_BUILD_TARGETS}
