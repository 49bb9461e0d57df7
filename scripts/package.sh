#!/usr/bin/env bash
# Builds the Debian package omniloc_<version>_<arch>.deb (docs/package.md) with CPack.
# Usage: scripts/package.sh [BUILD_DIR]   (default build; configured, Release, when it does not exist)
# Builds only the omniloc target there, runs `cpack -G DEB` and prints the .deb's path, its size and
# its Depends line (dpkg-shlibdeps computes it from the linked libraries; needs dpkg-dev and file,
# which scripts/install-deps.sh installs). The last line printed is the .deb's path.
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
cd "$(dirname "$0")/.."
build=${1:-build}
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DOMNILOC_WERROR=ON >/dev/null
fi
cmake --build "$build" --target omniloc -j"$(nproc)"
# Our own CPack configuration only (the build folder may hold others' CPackConfig.cmake files).
(cd "$build" && rm -f omniloc_*.deb && cpack -G DEB --config CPackConfig.cmake >cpack.log 2>&1) \
  || { tail -n 30 "$build/cpack.log" >&2; echo "package: cpack failed (whole log: $build/cpack.log)" >&2; exit 1; }
deb=$(ls "$build"/omniloc_*.deb)
deb=$(cd "$(dirname "$deb")" && pwd)/$(basename "$deb")
echo "package: $(du -h "$deb" | cut -f1) ($(stat -c %s "$deb") bytes)"
echo "Depends: $(dpkg-deb -f "$deb" Depends)"
echo "$deb"
