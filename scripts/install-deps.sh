#!/usr/bin/env bash
# Installs every Debian package omniloc needs, only when something is missing.
# Usage: scripts/install-deps.sh [--report-check]
# OpenCV: we take the split -dev packages (core, imgproc, imgcodecs); they are ~10x smaller than
# libopencv-dev but ship no CMake config, so CMakeLists.txt finds headers and libraries itself.
set -euo pipefail
case "${1:-}" in
  -h|--help)
    cat <<'USAGE'
usage: scripts/install-deps.sh [--report-check]
Installs, with apt (sudo when not root), the Debian 12 packages omniloc needs to build, test and run,
and only those that are missing; does nothing when all are present.
  --report-check  also Debian's chromium, for the headless check of report.html (scripts/check_report_html.py)
USAGE
    exit 0 ;;
  ""|--report-check) ;;
  *) echo "install-deps: unknown option $1 (try --help)" >&2; exit 2 ;;
esac
PKGS=(
  build-essential cmake pkg-config git
  libbox2d-dev libeigen3-dev nlohmann-json3-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev
  libosmesa6-dev libegl-dev libegl-mesa0 libgles-dev mesa-common-dev
  libbenchmark-dev libgtest-dev libgmock-dev
  libssl-dev zlib1g-dev libsimdjson-dev  # simdjson: the recording reader's fast path (harness/recording/frames_reader.cpp)
  python3 python3-matplotlib python3-jsonschema python3-numpy perl
  valgrind
  ccache  # a compile cache (CMakeLists.txt OMNILOC_CCACHE): a fresh clone builds from earlier objects
  dpkg-dev file  # scripts/package.sh: dpkg-shlibdeps computes the .deb's Depends; cpack tests ELF files with file
  libxml2-utils python3-yaml  # tests: xmllint validates omniloc gate's JUnit XML; the CI recipe test reads docs/ci.md's YAML
  python3-pytest mypy  # the results package's tests (python/tests, ctest results_pytest) and type check (results_mypy)
)
# --report-check: also Debian's chromium, for the headless check of report.html
# (scripts/check_report_html.py; .ci/run). Not needed to build, test or run the suite.
if [ "${1:-}" = "--report-check" ]; then
  PKGS+=(chromium)
fi
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PKGS[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
