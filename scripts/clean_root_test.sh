#!/usr/bin/env bash
# The README's test command on a fresh machine: a clean Debian 12 root (mmdebstrap --variant=apt:
# apt and its essentials, the bookworm, bookworm-updates and bookworm-security suites) with a user
# who is not root and may use sudo, a fresh clone of this clone's HEAD in that user's home, and there,
# as that user from a login shell (no variable of this machine's environment, no locale):
# scripts/test.sh, which installs with sudo apt what install-deps.sh lists, builds and runs ctest.
# A test that passes here (.ci/run's tests stage) but fails there depends on something the scripts do
# not install: a package, a pip module, a tool on PATH, a warm cache, root, a locale. .ci/run's
# fresh_root stage (docs/performance.md "A fresh machine").
# Usage: scripts/clean_root_test.sh [ctest arguments]   (passed to scripts/test.sh; default: every test)
# The clone is of the commit HEAD names, never the working tree, so untracked or uncommitted files
# cannot leak in. Two caches make a repeated run cheaper without changing what it tests: the root's
# downloaded .debs (OMNILOC_CLEAN_ROOT_CACHE, shared with scripts/clean_root_check.sh; apt takes a
# cached .deb only when its version and checksum are the ones the mirror lists) and this machine's
# ccache ($CCACHE_DIR, else /var/cache/omniloc/ccache; OMNILOC_FRESH_ROOT_CCACHE="" starts cold): the
# user's ~/.cache/ccache starts as hard links to its entries, in folders of the user's own, so the
# user can neither write to nor remove this machine's entries. A miss costs time only.
# Whole log: build/fresh_root.log; its check lines and last lines are printed. Exit 0: every test
# passed in the root; 1: something failed in it; 3: no root could be made here (not root, no
# mmdebstrap, no mirror): the reason is printed, and .ci/run fails unless OMNILOC_CI_FRESH_ROOT=0.
# OMNILOC_FRESH_ROOT_LIMIT: seconds scripts/test.sh may take in the root (default 1080, under .ci/run's
# 1200 for the stage); at the limit every process in the root is ended and the check fails.
# OMNILOC_FRESH_ROOT_TMPFS=0: the root on disk even where a tmpfs could hold it.
# OMNILOC_CLEAN_ROOT_MIRROR: another Debian mirror (default http://deb.debian.org/debian);
# OMNILOC_CLEAN_ROOT_SECURITY: another security mirror (default http://deb.debian.org/debian-security).
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
cd "$(dirname "$0")/.."
src=$PWD
log=$src/build/fresh_root.log
mkdir -p "$(dirname "$log")"
: >"$log"
work=$(mktemp -d /tmp/omniloc-fresh-root.XXXXXX)
trap 'rm -rf "$work"' EXIT
t0=$SECONDS start=$(date +%s)
say() { echo "fresh-root: $*" | tee -a "$log"; }
finish() {
  local rc=$1
  echo "--- the check's own lines in $log:"
  grep -E '^(fresh-root:|install-deps:|[0-9]+% tests passed|The following tests|[[:space:]]+[0-9]+ - )' "$log" || true
  echo "--- last 30 lines of $log:"
  tail -n 30 "$log"
  exit "$rc"
}
no_root() {
  say "NO ROOT: $*"
  say "the README's test command was not run on a fresh machine; OMNILOC_CI_FRESH_ROOT=0 runs CI without this check"
  finish 3
}

user=tester  # uid 1000, like a first user
sha=$(git rev-parse HEAD)
# A clone through git's transport (--no-local: no hard links into this repository's objects); HEAD is
# fetched by name too, so a detached CI checkout is found.
git clone --quiet --no-local "$src" "$work/omniloc" >>"$log" 2>&1
git -C "$work/omniloc" fetch --quiet "$src" HEAD >>"$log" 2>&1
git -C "$work/omniloc" checkout --quiet --detach "$sha" >>"$log" 2>&1
say "fresh clone of $(git log -1 --format='%h %s' "$sha" | cut -c1-80)"
[ -z "$(git status --porcelain --untracked-files=no)" ] || say "note: this clone's uncommitted changes are not tested (the root has HEAD only)"

if [ "$(id -u)" -ne 0 ]; then
  no_root "not root (mmdebstrap's root mode and chroot need it)"
fi
if ! command -v mmdebstrap >/dev/null; then
  apt-get install -y -qq --no-install-recommends mmdebstrap >>"$log" 2>&1 || true
  command -v mmdebstrap >/dev/null || no_root "mmdebstrap is not installed and apt could not install it"
fi

mirror=${OMNILOC_CLEAN_ROOT_MIRROR:-http://deb.debian.org/debian}
security=${OMNILOC_CLEAN_ROOT_SECURITY:-http://deb.debian.org/debian-security}
sources=("deb $mirror bookworm main" "deb $mirror bookworm-updates main" "deb $security bookworm-security main")

cache=${OMNILOC_CLEAN_ROOT_CACHE-/var/cache/omniloc/clean-root-debs}
cache_in=() cache_out=()
if [ -n "$cache" ] && mkdir -p "$cache" 2>/dev/null; then
  [ "$(du -sm "$cache" | cut -f1)" -le 2048 ] || rm -f "$cache"/*.deb
  say "download cache: $cache ($(find "$cache" -name '*.deb' | wc -l) .debs, $(du -sh "$cache" | cut -f1))"
  cache_in=(--skip=essential/unlink --setup-hook='mkdir -p "$1"/var/cache/apt/archives/'
            --setup-hook="sync-in '$cache' /var/cache/apt/archives/")
  # Only the .debs the cache lacks are copied back (sync-out copied all 400-odd every time), each by
  # copy and rename: the package stage's root may read the cache at the same time (.ci/run).
  printf '%s\n' 'for f in "$1"/var/cache/apt/archives/*.deb; do' \
    '  [ ! -f "$f" ] || [ -e "$2/${f##*/}" ] || { cp "$f" "$2/.${f##*/}.$$" && mv "$2/.${f##*/}.$$" "$2/${f##*/}"; }' \
    'done; true  # a cache that cannot be written costs a download, not the check' >"$work/cache_out.sh"
  cache_out=(--customize-hook="bash '$work/cache_out.sh' \"\$1\" '$cache'")
fi
limit=${OMNILOC_FRESH_ROOT_LIMIT:-1080}
ccache_src=${OMNILOC_FRESH_ROOT_CCACHE-${CCACHE_DIR:-/var/cache/omniloc/ccache}}
[ -d "$ccache_src" ] || ccache_src=""

# Ends, by its id, every process whose root is the given one (its /proc/PID/root): runuser starts the
# user's command in a session of its own, which no signal to a process group reaches, and mmdebstrap
# can unmount and delete the root only once nothing runs in it.
cat >"$work/end_root.sh" <<'FUNC'
end_root_processes() {
  local p pids=()
  [ -n "$1" ] || return 0
  for p in /proc/[0-9]*; do
    [ "$(readlink "$p/root" 2>/dev/null)" = "$1" ] && pids+=("${p#/proc/}")
  done
  [ ${#pids[@]} -eq 0 ] || kill -KILL "${pids[@]}" 2>/dev/null || true
}
FUNC

# Hooks run on this machine with the root as $1 (mmdebstrap mounts /proc, /dev and /sys for them).
# The user: what a Debian 12 install with a sudo-enabled first user has; nothing of the project.
cat >"$work/user_hook.sh" <<HOOK
set -euo pipefail
root=\$1
echo "\$root" >"$work/root-ready"
# The network names a Debian install writes (mmdebstrap writes none): without them "localhost" does
# not resolve, and sudo complains about the host's name at every call.
printf '127.0.0.1\tlocalhost\n127.0.1.1\t%s\n::1\tlocalhost ip6-localhost ip6-loopback\n' "\$(hostname)" >"\$root/etc/hosts"
# dpkg without fsync (what mmdebstrap itself does while it installs): the root is thrown away, and
# install-deps.sh's 400-odd packages install a minute or two sooner.
echo force-unsafe-io >"\$root/etc/dpkg/dpkg.cfg.d/fresh-root-unsafe-io"
DEBIAN_FRONTEND=noninteractive chroot "\$root" apt-get install -y -qq --no-install-recommends sudo
chroot "\$root" useradd --create-home --uid 1000 --shell /bin/bash $user
echo "$user ALL=(ALL) NOPASSWD:ALL" >"\$root/etc/sudoers.d/$user"
chmod 0440 "\$root/etc/sudoers.d/$user"
cp -a "$work/omniloc" "\$root/home/$user/omniloc"
chroot "\$root" chown -R $user:$user /home/$user/omniloc
if [ -n "$ccache_src" ]; then
  t=\$(date +%s)
  mkdir -p "\$root/home/$user/.cache"
  # Hard links where the root is on this cache's file system, else a copy; either way the folders are
  # the user's (a new entry lands there) and a linked entry stays root's, read-only to the user.
  cp -al "$ccache_src" "\$root/home/$user/.cache/ccache" 2>/dev/null || { rm -rf "\$root/home/$user/.cache/ccache"; cp -a "$ccache_src" "\$root/home/$user/.cache/ccache"; chroot "\$root" chown -R $user:$user /home/$user/.cache; }
  chown 1000:1000 "\$root/home/$user/.cache"
  find "\$root/home/$user/.cache/ccache" -type d -exec chown 1000:1000 {} +
  rm -f "\$root/home/$user/.cache/ccache/ccache.conf"
  echo "fresh-root: ~/.cache/ccache seeded from $ccache_src (\$(find "\$root/home/$user/.cache/ccache" -type f | wc -l) files, \$((\$(date +%s) - t)) s)"
else
  echo "fresh-root: no compile cache given: the build starts cold"
fi
echo "fresh-root: user $user (uid 1000, sudo), clone at /home/$user/omniloc; root ready \$((\$(date +%s) - $start)) s after the start"
HOOK

# The README's command as the user types it, from a login shell: runuser -l clears this machine's
# environment and sets the login one (HOME, PATH, no LANG). Its exit status is kept so that the .deb
# cache is saved also after a failure; the last hook hands it on.
test_args=""
[ $# -eq 0 ] || printf -v test_args ' %q' "$@"
printf 'cd ~/omniloc && scripts/test.sh%s\n' "$test_args" >"$work/user_command.sh"
cat >"$work/test_hook.sh" <<'HOOK'
root=$1 work=$2 user=$3 limit=$4
t=$(date +%s)
mark() { echo "fresh-root: $(($(date +%s) - t)) s into scripts/test.sh: $*"; }
. "$work/end_root.sh"
[ ! -f "$work/stopped" ] || exit 0
echo "fresh-root: + $(cut -d' ' -f4- "$work/user_command.sh")   (as $user, in ~/omniloc; time limit $limit s)"
install -m 0644 "$work/user_command.sh" "$root/tmp/fresh_root_command.sh"
# Each line is passed on as it is; where one phase ends (packages, build, ctest) a line with the time
# is added, so the log shows where the stage's time went.
{ chroot "$root" runuser -l "$user" -c 'bash /tmp/fresh_root_command.sh'; echo $? >"$work/test-rc"; } 2>&1 | {
  built=""
  while IFS= read -r line; do
    case $line in "["*) [ -n "$built" ] || { built=1; mark "the build starts"; } ;; esac
    printf '%s\n' "$line"
    case $line in
      "install-deps: done" | "install-deps: all "*) mark "packages installed" ;;
      "Test project "*) mark "the build is done, ctest starts" ;;
    esac
  done
} &
job=$!
while kill -0 "$job" 2>/dev/null; do
  if [ ! -f "$work/timed-out" ] && [ $(($(date +%s) - t)) -ge "$limit" ]; then
    touch "$work/timed-out"
    end_root_processes "$root"
  fi
  [ ! -f "$work/stopped" ] || end_root_processes "$root"
  sleep 5
done
wait "$job"
rc=$(cat "$work/test-rc" 2>/dev/null || echo none)
[ ! -f "$work/timed-out" ] || echo "fresh-root: TIME LIMIT: scripts/test.sh ended after $limit s (OMNILOC_FRESH_ROOT_LIMIT)"
echo "fresh-root: scripts/test.sh exit $rc after $(($(date +%s) - t)) s"
HOOK

# The root in memory where the machine has room: a tmpfs makes dpkg's unpacking and the build's writes
# cheaper, and deleting the root (86 s of a 796 s stage on disk) a matter of seconds. Its size is a
# ceiling, not a reservation: about 3 GB is used (packages 1.6 GB, the build and the tests' caches).
# Where no tmpfs can be mounted, or less than 8 GiB are free, the root stays on disk as before.
mem_root=""
avail_kb=$(awk '/^MemAvailable:/ {print $2}' /proc/meminfo 2>/dev/null || echo 0)
if [ "${OMNILOC_FRESH_ROOT_TMPFS:-1}" != 0 ] && [ "${avail_kb:-0}" -ge $((8 * 1024 * 1024)) ] && mkdir -p "$work/mem" &&
   mount -t tmpfs -o "size=$((avail_kb / 2))k,mode=0755" omniloc-fresh-root "$work/mem" 2>>"$log"; then
  mem_root=$work/mem
  trap 'umount -l "$work/mem" 2>/dev/null; rm -rf "$work"' EXIT
  say "the root is made in memory (tmpfs, at most $((avail_kb / 2 / 1024 / 1024)) GiB)"
fi
say "making a clean Debian 12 root with mmdebstrap --variant=apt (${sources[*]})"
# mmdebstrap runs in a session of its own: a signal to this script's process group (.ci/run's
# timeout, ^C) reaches this script alone, which ends what runs in the root and then waits while
# mmdebstrap unmounts and deletes it as after any failure (signalled itself, it left the root's
# mounts behind).
. "$work/end_root.sh"
stopped=""
on_signal() {
  stopped=1
  touch "$work/stopped"  # the test hook checks it too: the signal may come before the root exists
  say "stopped by a signal: ending what runs in the root; mmdebstrap then deletes it"
  end_root_processes "$(cat "$work/root-ready" 2>/dev/null)"
}
trap on_signal TERM INT HUP
TMPDIR=${mem_root:-${TMPDIR:-/tmp}} setsid mmdebstrap --variant=apt --mode=root --format=null "${cache_in[@]}" \
  --customize-hook="bash '$work/user_hook.sh' \"\$1\"" \
  --customize-hook="bash '$work/test_hook.sh' \"\$1\" '$work' $user $limit" \
  "${cache_out[@]}" \
  bookworm /dev/null "${sources[@]}" >>"$log" 2>&1 </dev/null &
mm=$!
rc=0
wait $mm || rc=$?
while kill -0 $mm 2>/dev/null; do  # a signal ended the wait, not mmdebstrap
  rc=0
  wait $mm || rc=$?
done
trap - TERM INT HUP
if [ -n "$stopped" ]; then
  say "FAILED: stopped by a signal after $((SECONDS - t0)) s (mmdebstrap exit $rc)"
  finish 1
fi
if [ ! -f "$work/root-ready" ]; then
  no_root "mmdebstrap could not make a root (exit $rc): $(grep -E '^E: ' "$log" | head -n 3 | tr '\n' ' ')"
fi
test_rc=$(cat "$work/test-rc" 2>/dev/null || echo "none (the user or clone could not be set up; mmdebstrap exit $rc)")
if [ "$test_rc" = 0 ] && [ $rc -eq 0 ]; then
  say "passed: the README's test command on a fresh Debian 12 root ($((SECONDS - t0)) s in all)"
  finish 0
fi
say "FAILED on a fresh Debian 12 root: scripts/test.sh exit $test_rc, mmdebstrap exit $rc ($((SECONDS - t0)) s in all)"
finish 1
