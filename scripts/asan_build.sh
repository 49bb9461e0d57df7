#!/usr/bin/env bash
# Builds TARGETS in build-asan/: clang-14 with AddressSanitizer + UndefinedBehaviorSanitizer and
# libFuzzer coverage, shared by scripts/sanitize.sh (unit tests) and scripts/fuzz.sh (fuzz target),
# so the libraries are compiled once for both. Installs clang-14, its runtimes (libFuzzer is in
# libclang-rt-14-dev), its linker lld-14 and Ninja from Debian when missing.
# Usage: scripts/asan_build.sh TARGET... | --deps-only (install, build nothing)
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
cd "$(dirname "$0")/.."
scripts/install-deps.sh >/dev/null
missing=()
for p in clang-14 libclang-rt-14-dev lld-14 ninja-build; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
[ "${1:-}" != --deps-only ] || exit 0  # .ci/run installs first, then builds beside other stages
# -O2 keeps the sanitized tests fast enough for CI. -gline-tables-only gives a report's stack its
# files and lines, which is all a sanitizer prints, without the full debug information of -g: objects
# a quarter the size and 10-20 % less compile time (measured on four of the heaviest files).
# lld links the 45 programs in about 0.6 s each where GNU ld took 1.4 s (a unit-test program, 130 MB).
# Benchmarks are not built: they are timing programs, not correctness checks.
# Ninja, not Make: CMake's top-level Makefile is .NOTPARALLEL, so `--target A B C ...` built the 45
# programs one after another, each test's one file on one core; Ninja builds them all at once.
# (CMakeLists.txt's OPTIMIZE_DEPENDENCIES lets the libraries compile side by side, not in a chain.)
# A unity build (eight files of a library compiled as one) parses the heavy headers (Eigen, OpenCV,
# nlohmann-json, under the sanitizers' instrumentation) once per eight files. It is used only here:
# the Release tree (scripts/build.sh) compiles file by file, so a file that does not include what
# it uses still fails there. Figures: docs/performance.md "CI's time".
# A build folder made by another generator (Make, before) is reconfigured: its cache and CMake's
# files go, the fuzz corpus and the programs' outputs stay.
if [ -f build-asan/CMakeCache.txt ] && ! grep -q '^CMAKE_GENERATOR:INTERNAL=Ninja$' build-asan/CMakeCache.txt; then
  rm -rf build-asan/CMakeCache.txt build-asan/CMakeFiles build-asan/Makefile
fi
cmake -G Ninja -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
  "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG" "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG" \
  -DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld -DCMAKE_SHARED_LINKER_FLAGS=-fuse-ld=lld \
  -DCMAKE_UNITY_BUILD=ON \
  -DOMNILOC_SANITIZE=ON -DOMNILOC_FUZZ=ON -DOMNILOC_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j"$(nproc)" --target "$@"
