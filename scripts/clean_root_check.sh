#!/usr/bin/env bash
# Installs a built omniloc .deb into a clean Debian 12 root and runs it there, with no source tree
# (docs/package.md). Called by .ci/run's package stage after scripts/package.sh.
# Usage: scripts/clean_root_check.sh DEB [LOG]   (LOG default: build/clean_root.log)
# The root: `mmdebstrap --variant=apt bookworm` (apt and its essentials only, from deb.debian.org;
# root, network), then `apt-get install /tmp/omniloc_*.deb` inside it, so the .deb's Depends alone
# must bring everything. In it, from /: omniloc --version, omniloc list, a run of the shipped
# quickstart scenario and, when the source tree has scripts/ci_recipe.sh, that recipe (docs/ci.md).
# Where no root can be made here (no mmdebstrap, not root, no mirror) the log says exactly why and
# the check falls back to the package unpacked with dpkg -x and run on this machine's libraries,
# which tests the layout but not the Depends line. The whole log goes to LOG; its tail is printed.
# OMNILOC_CLEAN_ROOT_MIRROR: another Debian mirror (default http://deb.debian.org/debian).
# OMNILOC_CLEAN_ROOT_CACHE: a folder that keeps the root's downloaded .debs between runs (default
# /var/cache/omniloc/clean-root-debs; empty: no cache). apt still reads the mirror's package lists
# and takes a cached .deb only when its version and checksum are the ones listed, so the root is
# what a fresh download would give; the cache only saves the ~270 MB download. Over 2 GiB (old
# versions piling up) it is emptied first.
set -euo pipefail
case "${1:-}" in -h | --help | "") sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; [ -n "${1:-}" ] && exit 0; exit 2 ;; esac  # the header above; nothing runs
cd "$(dirname "$0")/.."
deb=$(realpath "$1")
log=$(realpath -m "${2:-build/clean_root.log}")
recipe=$PWD/scripts/ci_recipe.sh
mkdir -p "$(dirname "$log")"
: >"$log"
work=$(mktemp -d /tmp/omniloc-clean-root.XXXXXX)
trap 'rm -rf "$work"' EXIT

say() { echo "clean-root: $*" | tee -a "$log"; }
finish() {
  local rc=$1
  echo "--- the check's own lines in $log:"
  grep -E '^(clean-root:|\+ |inside:|omniloc: using|shared files:|data:|omniloc [0-9a-f])' "$log" || true
  echo "--- last 25 lines of $log:"
  tail -n 25 "$log"
  exit "$rc"
}

# The commands run inside the root (or against the unpacked package), from / so nothing relative to
# a source tree can be found: the shipped scenario is found through share_dir().
# $T: the scratch folder (/tmp in the root; the fallback's own folder on this machine).
cat >"$work/inside.sh" <<'INSIDE'
set -euo pipefail
T=${T:-/tmp}
cd /
echo "+ omniloc --version"; omniloc --version
echo "+ omniloc list | tail -n 2"; omniloc list | tail -n 2
echo "+ omniloc validate scenarios/quickstart.json"; omniloc validate scenarios/quickstart.json
echo "+ omniloc run scenarios/quickstart.json -o $T/q --quiet"; omniloc run scenarios/quickstart.json -o "$T/q" --quiet
ls "$T/q"
test -s "$T/q/summary.json"
echo "inside: omniloc checks passed"
INSIDE
# Before the recipe: the .deb's Recommends (matplotlib for the report; `apt-get install ./x.deb` in
# docs/ci.md installs them too), what the recipe's workflow installs itself (git, numpy) and the
# runner's YAML reader (scripts/ci_recipe.py). OMNILOC_CLEAN_ROOT_RECIPE_TOOLS overrides the list.
# They are installed after the checks above, so those see only what the .deb's Depends brought.
recipe_tools=${OMNILOC_CLEAN_ROOT_RECIPE_TOOLS-$(dpkg-deb -f "$deb" Recommends | tr -d ,) git ca-certificates python3-numpy python3-yaml}
[ -f "$recipe" ] && cp "$recipe" "$work/ci_recipe.sh"
cat >"$work/recipe_hook.sh" <<HOOK
set -euo pipefail
root=\$1
if [ ! -f "$work/ci_recipe.sh" ]; then echo "clean-root: no scripts/ci_recipe.sh in the source tree: recipe not run"; exit 0; fi
cp "$work/ci_recipe.sh" "\$root/tmp/"
echo "clean-root: installing for the recipe: $recipe_tools"
[ -z "$recipe_tools" ] || DEBIAN_FRONTEND=noninteractive chroot "\$root" apt-get install -y --no-install-recommends $recipe_tools
echo "+ bash /tmp/ci_recipe.sh"
chroot "\$root" bash -c 'cd /tmp && bash /tmp/ci_recipe.sh --system github --pr degraded && bash /tmp/ci_recipe.sh --system gitlab --pr same'
HOOK

mirror=${OMNILOC_CLEAN_ROOT_MIRROR:-http://deb.debian.org/debian}  # e.g. a local mirror or apt-cacher
t0=$SECONDS
why=""
if [ "$(id -u)" -ne 0 ]; then
  why="not root (mmdebstrap's root mode and chroot need it)"
elif ! command -v mmdebstrap >/dev/null; then
  apt-get install -y -qq --no-install-recommends mmdebstrap >>"$log" 2>&1 || true
  command -v mmdebstrap >/dev/null || why="mmdebstrap is not installed and apt could not install it"
fi
if [ -z "$why" ]; then
  say "making a clean Debian 12 root with mmdebstrap --variant=apt and installing $(basename "$deb") into it"
  # Hooks run on this machine with the root as $1; mmdebstrap mounts /proc, /dev and /sys for them
  # (share_dir() reads /proc/self/exe). The first hook marks that the root itself could be made, so a
  # failure after it is the package's, not this machine's. Format null: the root is deleted at the end.
  cache=${OMNILOC_CLEAN_ROOT_CACHE-/var/cache/omniloc/clean-root-debs}
  cache_opts=()
  if [ -n "$cache" ] && mkdir -p "$cache" 2>/dev/null; then
    [ "$(du -sm "$cache" | cut -f1)" -le 2048 ] || rm -f "$cache"/*.deb
    say "download cache: $cache ($(find "$cache" -name '*.deb' | wc -l) .debs, $(du -sh "$cache" | cut -f1))"
    # essential/unlink kept: the essential packages' .debs stay in the root's archive for sync-out.
    cache_opts=(--skip=essential/unlink
                --setup-hook='mkdir -p "$1"/var/cache/apt/archives/'
                --setup-hook="sync-in '$cache' /var/cache/apt/archives/")
  fi
  rc=0
  mmdebstrap --variant=apt --mode=root --format=null "${cache_opts[@]}" \
    --customize-hook="touch '$work/root-ready'" \
    --customize-hook="copy-in '$deb' /tmp" \
    --customize-hook="copy-in '$work/inside.sh' /tmp" \
    --customize-hook='t=$(date +%s); DEBIAN_FRONTEND=noninteractive chroot "$1" apt-get install -y --no-install-recommends /tmp/'"$(basename "$deb")"' && echo "clean-root: apt-get install of the .deb took $(($(date +%s) - t)) s"' \
    --customize-hook='chroot "$1" dpkg -L omniloc | grep -c . | sed "s/^/clean-root: files installed: /"' \
    --customize-hook='test ! -e "$1'"$PWD"'" && echo "clean-root: no source tree in the root ('"$PWD"' absent)"' \
    --customize-hook='chroot "$1" bash /tmp/inside.sh' \
    --customize-hook="bash '$work/recipe_hook.sh' \"\$1\"" \
    ${cache_opts[@]:+--customize-hook="sync-out /var/cache/apt/archives '$cache'"} \
    bookworm /dev/null "$mirror" >>"$log" 2>&1 || rc=$?
  # The package under test is never part of the cache.
  [ ${#cache_opts[@]} -eq 0 ] || rm -f "$cache"/omniloc_*.deb
  if [ $rc -eq 0 ]; then
    say "passed in a clean Debian 12 root ($((SECONDS - t0)) s in all)"
    finish 0
  fi
  if [ -f "$work/root-ready" ]; then
    say "FAILED inside the clean root (mmdebstrap exit $rc; see above)"
    finish 1
  fi
  why="mmdebstrap could not make a root (exit $rc): $(grep -E '^E: ' "$log" | head -n 3 | tr '\n' ' ')"
fi

# Fallback: what can be tested without a clean root.
say "no clean root: $why"
say "FALLBACK: unpacking with dpkg -x and running on this machine's libraries (tests the layout and share_dir(), not the Depends line)"
dpkg -x "$deb" "$work/unpacked"
rc=0
unset OMNILOC_SHARE_DIR OMNILOC_DATA_DIR
export T=$work PATH="$work/unpacked/usr/bin:$PATH"
bash "$work/inside.sh" >>"$log" 2>&1 || rc=$?
# The recipe from the source tree (its runner and docs/ci.md beside it), with the unpacked omniloc
# first on PATH; this machine's python3-yaml, git and matplotlib.
if [ $rc -eq 0 ] && [ -f "$recipe" ]; then
  echo "+ bash $recipe (source tree's runner, unpacked omniloc)" >>"$log"
  (cd "$work" && bash "$recipe") >>"$log" 2>&1 || rc=$?
fi
if [ $rc -eq 0 ]; then say "passed (fallback: unpacked package, not a clean root)"; else say "FAILED (fallback: unpacked package)"; fi
finish $rc
