#!/usr/bin/env bash
# Configures and builds omniloc in build/ (Release, warnings as errors). Extra arguments go to cmake.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOMNILOC_WERROR=ON "$@" >/dev/null
cmake --build build -j"$(nproc)"
