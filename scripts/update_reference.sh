#!/usr/bin/env bash
# Regenerates the committed regression numbers (results/reference/regression/*.summary.json) from
# scenarios/regression/*.json. Run it only when a change of numbers is deliberate; the diff of the
# reference files then shows exactly what moved, and belongs in the same commit as its cause.
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
cd "$(dirname "$0")/.."
[ -x build/omniloc ] || scripts/build.sh
for s in scenarios/regression/*.json; do
  name=$(basename "$s" .json)
  out=$(mktemp -d)
  ./build/omniloc run "$s" -o "$out/run" --quiet >/dev/null
  # Without the provenance block (which build made it): tests/regression_test.cpp compares the rest.
  /usr/bin/python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); j.pop("omniloc", None); open(sys.argv[2],"w").write(json.dumps(j, indent=2) + "\n")' \
    "$out/run/summary.json" "results/reference/regression/$name.summary.json"
  rm -rf "$out"
  echo "updated results/reference/regression/$name.summary.json"
done
