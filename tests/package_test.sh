#!/usr/bin/env bash
# The installed layout runs without the source tree (docs/package.md): `cmake --install`
# of the build folder into a temporary prefix (what the .deb holds, without building it), then the
# installed binary from an empty working directory must take its data, scenarios and the results
# package from <prefix>/share/omniloc, which `omniloc list` reports, and run the shipped quickstart
# scenario; the installed package finds papers.json beside itself.
# Usage: tests/package_test.sh BUILD_DIR   (ctest: package_install)
set -euo pipefail
case "${1:-}" in -h | --help | "") sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; [ -n "${1:-}" ] && exit 0; exit 2 ;; esac
build=$(realpath "$1")
tmp=$(mktemp -d /tmp/omniloc-package-test.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$tmp/usr" >"$tmp/install.log"
share=$tmp/usr/share/omniloc
[ "$(ls "$tmp/usr/bin")" = omniloc ] || fail "bin/ should hold omniloc only, holds: $(ls "$tmp/usr/bin")"
for f in data/fields data/noise_profiles.json scenarios/quickstart.json results/reference/papers.json \
         python/omniloc/__init__.py python/omniloc/core/paths.py python/omniloc/commands/report.py \
         python/omniloc/commands/gate.py python/omniloc/commands/compare.py python/omniloc/commands/paper_table.py \
         python/omniloc/report/assemble.py python/omniloc/tools/plot.py python/omniloc/data/nubot.py scripts/ci_recipe.py \
         clients/python/omniloc_client.py \
         clients/cpp/omniloc_client.hpp; do
  [ -e "$share/$f" ] || fail "not installed: share/omniloc/$f"
done
[ -f "$tmp/usr/share/doc/omniloc/README.md" ] || fail "README.md not in share/doc/omniloc"
[ -z "$(find "$tmp/usr" -name __pycache__ -o -name '*.pyc')" ] || fail "bytecode installed"
[ ! -e "$share/python/tests" ] && [ ! -e "$share/scripts/report.py" ] || fail "the package's tests or an old report script installed"

mkdir "$tmp/cwd" && cd "$tmp/cwd"
omniloc=(env -u OMNILOC_SHARE_DIR -u OMNILOC_DATA_DIR "$tmp/usr/bin/omniloc")
"${omniloc[@]}" list >list.txt
grep -qxF "shared files: $share" list.txt || fail "share_dir() is not the installed one: $(grep 'shared files' list.txt)"
grep -qxF "data: $share/data" list.txt || fail "data_dir() is not the installed one: $(grep '^data:' list.txt)"
# The same presets and noise profiles as the build tree's binary finds in the source tree.
for key in "field presets:" "noise profiles:"; do
  [ "$(grep "^$key" list.txt)" = "$(cd "$build" && ./omniloc list | grep "^$key")" ] || fail "$key differ from the build tree's"
done

"${omniloc[@]}" validate scenarios/quickstart.json >/dev/null 2>err.txt || fail "validate: $(cat err.txt)"
grep -qxF "omniloc: using $share/scenarios/quickstart.json" err.txt || fail "no note naming the shipped file: $(cat err.txt)"
"${omniloc[@]}" validate scenarios/sweeps/odometry_drift.json >/dev/null 2>err.txt || fail "sweep validate: $(cat err.txt)"
"${omniloc[@]}" run scenarios/quickstart.json -o "$tmp/q" --quiet >/dev/null 2>err.txt || fail "run: $(cat err.txt)"
[ -s "$tmp/q/summary.json" ] || fail "no summary.json"
# `omniloc compare` forwards to the installed package (python3 -m omniloc.commands.compare).
"${omniloc[@]}" compare --help >help.txt 2>&1 || fail "compare --help: $(cat help.txt)"
grep -q "omniloc compare" help.txt || fail "compare --help does not name the command: $(head -3 help.txt)"
# The installed package reads the installed results/reference (omniloc/core/paths.py): two folders up.
PYTHONPATH="$share/python" PYTHONDONTWRITEBYTECODE=1 /usr/bin/python3 -m omniloc.commands.paper_table . --paper list >tables.txt 2>&1 \
  || fail "paper_table from the installed package: $(cat tables.txt)"
grep -qx 002_table1_occlusion tables.txt || fail "the installed package did not read papers.json: $(head -3 tables.txt)"
[ -z "$(ls -A "$tmp/cwd" | grep -v -e list.txt -e err.txt -e help.txt -e tables.txt)" ] || fail "wrote into the working directory: $(ls "$tmp/cwd")"
echo "package layout: ok ($share)"
