#!/usr/bin/env bash
# Installs what is missing, builds, runs the default job and prints its error table.
# Usage: scripts/run.sh [SCENARIO.json]
#   default: scenarios/paper/tracking.json, the papers' tracking experiment from rendered images
#   (about a minute on one core; the first run also calibrates the camera and learns the colour
#   table, cached in results/cache/).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
scenario="${1:-scenarios/paper/tracking.json}"
./build/omniloc run "$scenario"
