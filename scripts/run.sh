#!/usr/bin/env bash
# Installs what is missing, builds, runs the default job and prints its error table.
# Usage: scripts/run.sh [SCENARIO.json]   (default: scenarios/quickstart.json)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
scenario="${1:-scenarios/quickstart.json}"
./build/omniloc run "$scenario"
