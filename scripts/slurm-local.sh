#!/usr/bin/env bash
# A real single-node Slurm cluster on this machine, for the cluster tests (ctest -L cluster) and for
# trying `omniloc sweep --slurm` without a cluster. No systemd: munged, slurmctld -D and slurmd -D run
# as plain background processes with every file (config, key, sockets, state, spool, logs, PIDs)
# under one scratch folder, addresses pinned to 127.0.0.1 and non-default ports so a site's own
# Slurm or munge on the machine is neither used nor disturbed.
#
# Usage: scripts/slurm-local.sh up     install missing Debian packages, start, wait until the node is idle
#        scripts/slurm-local.sh down   cancel every job, stop exactly the daemons `up` started
#        scripts/slurm-local.sh env    print the export line the Slurm clients need
# Environment: OMNILOC_SLURM_DIR (default /tmp/omniloc-slurm), OMNILOC_SLURM_PORT (default 16817;
# slurmd uses the next port). After `up`: export SLURM_CONF=$OMNILOC_SLURM_DIR/slurm.conf
#
# Pitfalls this script handles (Debian 12, Slurm 22.05, munge 0.5.15):
#  - munged refuses a socket folder that others can write and a key others can read: 0755 / 0600.
#  - slurmd's job helper (slurmstepd) ignores SIGTERM, so `down` cancels jobs before stopping daemons.
#  - proctrack/linuxproc and task/none: no cgroups needed (containers, CI machines).
#  - no slurmdbd: sacct does not work here; poll squeue / scontrol show job instead.
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
DIR="${OMNILOC_SLURM_DIR:-/tmp/omniloc-slurm}"
PORT="${OMNILOC_SLURM_PORT:-16817}"
CONF="$DIR/slurm.conf"
export SLURM_CONF="$CONF"
PKGS=(slurmctld slurmd slurm-client munge)

log() { echo "slurm-local: $*" >&2; }

alive() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }

install_packages() {
  local missing=()
  for p in "${PKGS[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  command -v apt-get >/dev/null || { log "cannot install ${missing[*]}: no apt-get on this machine"; return 1; }
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  log "installing ${missing[*]}"
  # The packages' maintainer scripts try to start the daemons through systemd/init; policy-rc.d 101
  # forbids that (we start our own copies below), and is removed again afterwards.
  local policy=/usr/sbin/policy-rc.d created_policy=0
  if [ ! -e "$policy" ]; then
    printf '#!/bin/sh\nexit 101\n' | $sudo tee "$policy" >/dev/null && $sudo chmod 755 "$policy" && created_policy=1
  fi
  export DEBIAN_FRONTEND=noninteractive
  local rc=0
  { $sudo apt-get update -qq && $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null; } || rc=$?
  [ $created_policy -eq 1 ] && $sudo rm -f "$policy"
  return $rc
}

write_config() {
  local host cpus mem user
  host="$(hostname -s)"
  cpus="$(nproc)"
  # Advertise 90 % of the memory so slurmd's own check against the real total never fails.
  mem="$(free -m | awk '/^Mem:/ {print int($2 * 0.9)}')"
  user="$(id -un)"
  mkdir -p "$DIR"/{state,spool,log,munge,run}
  cat >"$CONF" <<EOF
# Written by scripts/slurm-local.sh: a one-node test cluster, everything under $DIR.
ClusterName=omniloc-local
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$PORT
SlurmdPort=$((PORT + 1))
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
AuthInfo=socket=$DIR/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$DIR/run/slurmctld.pid
SlurmdPidFile=$DIR/run/slurmd.pid
SlurmctldLogFile=$DIR/log/slurmctld.log
SlurmdLogFile=$DIR/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
# Start batch jobs as soon as they are eligible (the default waits for the next scheduling pass).
SchedulerParameters=batch_sched_delay=0
# Finished jobs stay visible to scontrol / squeue for 10 minutes (there is no accounting database).
MinJobAge=600
KillWait=5
ReturnToService=2
SlurmctldTimeout=30
SlurmdTimeout=30
NodeName=$host NodeAddr=127.0.0.1 NodeHostname=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
}

start_munge() {
  alive "$DIR/run/munged.pid" && return 0
  chmod 0755 "$DIR/munge"
  if [ ! -s "$DIR/munge/munge.key" ]; then
    dd if=/dev/urandom of="$DIR/munge/munge.key" bs=1024 count=1 status=none
  fi
  chmod 0600 "$DIR/munge/munge.key"
  # --force: munged would refuse to start as root or when /tmp looks insecure to it; every path is ours.
  munged --force --socket="$DIR/munge/munge.socket" --key-file="$DIR/munge/munge.key" \
    --pid-file="$DIR/run/munged.pid" --log-file="$DIR/log/munged.log" --seed-file="$DIR/munge/munge.seed"
  for _ in $(seq 50); do [ -S "$DIR/munge/munge.socket" ] && alive "$DIR/run/munged.pid" && return 0; sleep 0.1; done
  log "munged did not start (see $DIR/log/munged.log)"; return 1
}

# Starts a foreground daemon in its own session and records its PID in $DIR/run/<name>.daemon.pid.
start_daemon() {
  local name="$1"; shift
  alive "$DIR/run/$name.daemon.pid" && return 0
  setsid "$@" </dev/null >>"$DIR/log/$name.out" 2>&1 &
  echo $! >"$DIR/run/$name.daemon.pid"
}

up() {
  if ! install_packages; then
    log "Slurm cannot be installed on this machine; the cluster tests will skip"; return 1
  fi
  write_config
  start_munge
  export MUNGE_SOCKET="$DIR/munge/munge.socket"
  start_daemon slurmctld slurmctld -D -f "$CONF"
  start_daemon slurmd slurmd -D -f "$CONF" -N "$(hostname -s)"
  local t0=$SECONDS
  until sinfo -h -o '%t' 2>/dev/null | grep -qx 'idle'; do
    for d in slurmctld slurmd; do
      alive "$DIR/run/$d.daemon.pid" || { log "$d exited (see $DIR/log/$d.log and $DIR/log/$d.out)"; return 1; }
    done
    if [ $((SECONDS - t0)) -gt 30 ]; then log "node not idle after 30 s: $(sinfo 2>&1 | tail -1)"; return 1; fi
    sleep 0.2
  done
  log "up in $((SECONDS - t0)) s: $(sinfo -h -o '%P %D %t %c CPUs')"
  echo "export SLURM_CONF=$CONF"
}

down() {
  if [ -f "$CONF" ] && alive "$DIR/run/slurmctld.daemon.pid"; then
    scancel --quiet --user="$(id -un)" 2>/dev/null || true
    # Wait for the jobs' helpers to finish before the daemons go (at most KillWait + a little).
    for _ in $(seq 75); do [ -z "$(squeue -h -t PD,R,CG,S -o %i 2>/dev/null)" ] && break; sleep 0.2; done
  fi
  local pids=()
  for f in slurmd.daemon slurmctld.daemon munged; do
    if alive "$DIR/run/$f.pid"; then pids+=("$(cat "$DIR/run/$f.pid")"); fi
  done
  [ ${#pids[@]} -gt 0 ] && kill "${pids[@]}" 2>/dev/null || true
  for _ in $(seq 50); do
    local left=0
    for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null && left=1; done
    [ $left -eq 0 ] && break
    sleep 0.1
  done
  for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null && kill -KILL "$p" 2>/dev/null; done
  rm -f "$DIR"/run/*.pid
  log "down (${#pids[@]} daemon(s) stopped)"
}

case "${1:-}" in
  up) up ;;
  down) down ;;
  env) echo "export SLURM_CONF=$CONF" ;;
  *) echo "usage: $0 up|down|env" >&2; exit 2 ;;
esac
