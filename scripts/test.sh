#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test through ctest.
# Usage: scripts/test.sh [ctest arguments], e.g. scripts/test.sh -LE scenario (skip slow scenario tests).
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
cd build
# The tests' runs keep their worlds in a cache of their own, emptied first, so every test run draws
# what it replays (docs/recording.md section 9) and nothing reaches the user's results/cache.
export OMNILOC_CACHE="$PWD/test_world_cache"
rm -rf "$OMNILOC_CACHE"
ctest --output-on-failure -j"$(nproc)" --timeout 900 "$@"
