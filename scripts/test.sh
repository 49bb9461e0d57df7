#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test through ctest.
# Usage: scripts/test.sh [ctest arguments], e.g. scripts/test.sh -LE scenario (skip slow scenario tests).
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
cd build
# The tests keep every cache in a root of their own, emptied first, so every test run draws what it
# replays (docs/recording.md section 9) and nothing reaches the user's ~/.cache/omniloc
# (tests/CMakeLists.txt names the same root for a ctest started by hand).
export OMNILOC_CACHE="$PWD/test_world_cache"
rm -rf "$OMNILOC_CACHE"
# Their temporary folders in the build tree too: tests name folders under the temporary directory
# after themselves, so two clones testing at once on one machine would share them.
export TMPDIR="$PWD/test_tmp"
rm -rf "$TMPDIR" && mkdir -p "$TMPDIR"
ctest --output-on-failure -j"$(nproc)" --timeout 900 "$@"
