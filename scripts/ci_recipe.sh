#!/usr/bin/env bash
# Runs docs/ci.md's CI recipe (scripts/ci_recipe.py) with the omniloc on PATH; the clean-root stage
# (scripts/clean_root_check.sh) copies this file into a fresh Debian 12 root where only the package
# is installed, so it takes ci_recipe.py and ci.md from the package when no source tree is beside it.
# Usage: scripts/ci_recipe.sh [ci_recipe.py options]   (e.g. --system github --pr degraded)
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
here=$(cd "$(dirname "$0")" && pwd)
py=$here/ci_recipe.py
[ -f "$py" ] || py=/usr/share/omniloc/scripts/ci_recipe.py
exec /usr/bin/python3 "$py" "$@"
