#!/usr/bin/env bash
# Installs every Debian package omniloc needs, only when something is missing.
# Usage: scripts/install-deps.sh [--report-check] [--mcap-check]
# OpenCV: we take the split -dev packages (core, imgproc, imgcodecs); they are ~10x smaller than
# libopencv-dev but ship no CMake config, so CMakeLists.txt finds headers and libraries itself.
# The program links core and imgproc; imgcodecs only the test that compares our PNG/JPEG files with it.
set -euo pipefail
report_check="" mcap_check=""
for arg in "$@"; do
  case "$arg" in
    -h|--help)
      cat <<'USAGE'
usage: scripts/install-deps.sh [--report-check] [--mcap-check]
Installs, with apt (sudo when not root), the Debian 12 packages omniloc needs to build, test and run,
and only those that are missing; does nothing when all are present.
  --report-check  also Debian's chromium, for the headless check of report.html (scripts/check_report_html.py)
  --mcap-check    also Debian's nodejs and npm, for the check of omniloc export's MCAP files by the
                  MCAP project's own reader (ctest mcap_export_py; skipped, saying why, without them)
USAGE
      exit 0 ;;
    --report-check) report_check=1 ;;
    --mcap-check) mcap_check=1 ;;
    *) echo "install-deps: unknown option $arg (try --help)" >&2; exit 2 ;;
  esac
done
PKGS=(
  build-essential cmake pkg-config git
  libbox2d-dev libeigen3-dev nlohmann-json3-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev  # imgcodecs: tests only (harness/image_file.hpp)
  libpng-dev libjpeg-dev  # PNG and JPEG files (harness/image_file.cpp)
  libosmesa6-dev libegl-dev libegl-mesa0 libgles-dev mesa-common-dev
  libbenchmark-dev libgtest-dev libgmock-dev
  libssl-dev zlib1g-dev libsimdjson-dev  # simdjson: the recording reader's fast path (harness/recording/frames_reader.cpp)
  python3 python3-matplotlib python3-jsonschema python3-numpy perl
  valgrind
  ccache  # a compile cache (CMakeLists.txt OMNILOC_CCACHE): a fresh clone builds from earlier objects
  dpkg-dev file  # scripts/package.sh: dpkg-shlibdeps computes the .deb's Depends; cpack tests ELF files with file
  libxml2-utils python3-yaml  # tests: xmllint validates omniloc gate's JUnit XML; the CI recipe test reads docs/ci.md's YAML
  python3-pytest mypy  # the results package's tests (python/tests, ctest results_pytest) and type check (results_mypy)
  # omniloc export's MCAP chunk compression (LZ4 frames). Already there with python3-matplotlib (its
  # python3-fonttools depends on it), named because the export imports it: not a new download, and
  # chunks stay readable by every MCAP reader (lz4 is one of the two compressions the format names).
  python3-lz4
)
# --report-check: also Debian's chromium, for the headless check of report.html
# (scripts/check_report_html.py; .ci/run). Not needed to build, test or run the suite.
[ -z "$report_check" ] || PKGS+=(chromium)
# --mcap-check: ctest mcap_export_py reads the exported MCAP files with the MCAP project's reader
# (@mcap/core, `npm ci` from tests/mcap_reader/package-lock.json). Not in the default list: Debian's
# npm brings about 420 packages, which a user who never checks MCAP files should not download; .ci/run
# asks for them. A nodejs that carries npm itself (NodeSource's, which provides and conflicts with
# Debian's npm) counts as having npm.
[ -z "$mcap_check" ] || PKGS+=(nodejs npm)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" && continue
  [ "$p" = npm ] && command -v npm >/dev/null && continue
  missing+=("$p")
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
