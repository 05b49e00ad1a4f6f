#!/usr/bin/env bash
# A one-node Slurm cluster for the `slurm` tests (the recipe of docs/guide/slurm.md, "Testing"),
# kept inside DIR: its slurm.conf, state, spool, logs and pid files, so that nothing under /etc is
# written and a test run leaves no daemon behind (stop). MUNGE is the system's: started if it is
# not running, its key created if missing.
#   slurm_cluster.sh start DIR   -> DIR/slurm.conf (export SLURM_CONF=DIR/slurm.conf); or DIR/skip
#                                   holding why no cluster can run here (Slurm not installed, not
#                                   root: the tests then skip); or exit 1 with the daemons' logs when
#                                   one was installed but did not come up (the tests then fail)
#   slurm_cluster.sh stop DIR    -> the daemons started by `start` stopped, their jobs with them
set -uo pipefail

# The daemons started below must not inherit a descriptor of our caller's: munged keeps every one
# it is given, so a caller reading our output through a pipe would wait for its end forever.
for fd_path in /proc/$$/fd/*; do
  fd=${fd_path##*/}
  case $fd in 0 | 1 | 2 | 255) ;; *) eval "exec $fd>&-" 2>/dev/null ;; esac
done
action=${1:?start or stop}
dir=${2:?the cluster folder}
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)

sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo -n)

skip() {
  echo "$*" > "$dir/skip"
  echo "slurm_cluster: no cluster: $*" >&2
  exit 0
}

# A daemon that is installed but did not come up: a failure, with what its log says.
fail() {
  echo "slurm_cluster: $1" >&2
  for log in "${@:2}"; do
    [ -f "$log" ] && { echo "--- the end of $log:" >&2; tail -n 20 "$log" >&2; }
  done
  exit 1
}

stop_pid_file() {
  [ -f "$1" ] || return 0
  local pid
  pid=$(cat "$1")
  "${sudo_cmd[@]}" kill "$pid" 2>/dev/null
  for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  "${sudo_cmd[@]}" kill -9 "$pid" 2>/dev/null
  rm -f "$1"
}

if [ "$action" = stop ]; then
  export SLURM_CONF="$dir/slurm.conf"
  [ -f "$SLURM_CONF" ] && "${sudo_cmd[@]}" env SLURM_CONF="$SLURM_CONF" scancel --user="$(id -un)" 2>/dev/null
  stop_pid_file "$dir/slurmd.pid"
  stop_pid_file "$dir/slurmctld.pid"
  exit 0
fi

rm -f "$dir/skip"
for program in slurmctld slurmd sbatch squeue scancel munged munge; do
  command -v "$program" >/dev/null 2>&1 || [ -x "/usr/sbin/$program" ] ||
    skip "$program is not installed (Debian: apt-get install slurm-wlm munge)"
done
if [ "$(id -u)" -ne 0 ] && ! sudo -n true 2>/dev/null; then
  skip "starting slurmctld and slurmd needs root (or sudo without a password)"
fi

# MUNGE: every Slurm message is signed with its key.
# Running if it answers (a pgrep would also see a munged that has died but is not yet reaped).
if ! munge -n </dev/null >/dev/null 2>&1; then
  "${sudo_cmd[@]}" mkdir -p /etc/munge /var/lib/munge /var/log/munge /run/munge
  if [ ! -s /etc/munge/munge.key ]; then
    "${sudo_cmd[@]}" sh -c 'dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key 2>/dev/null'
  fi
  "${sudo_cmd[@]}" chown -R munge:munge /etc/munge /var/lib/munge /var/log/munge /run/munge
  "${sudo_cmd[@]}" chmod 400 /etc/munge/munge.key
  "${sudo_cmd[@]}" su -s /bin/sh munge -c /usr/sbin/munged </dev/null ||
    fail "munged did not start" /var/log/munge/munged.log
fi

host=$(hostname -s)
cpus=$(nproc)
memory=$(( $(free -m | awk '/^Mem:/ {print $2}') * 9 / 10 ))
mkdir -p "$dir/state" "$dir/spool" "$dir/log"
cat > "$dir/slurm.conf" <<CONF
ClusterName=seeptest
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
ReturnToService=2
SlurmctldPort=$(( 16817 + RANDOM % 1000 ))
SlurmdPort=$(( 17818 + RANDOM % 1000 ))
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
MinJobAge=300
KillWait=10
NodeName=$host CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$dir/slurm.conf"
# -i: ignore state a previous run may have left in this folder.
"${sudo_cmd[@]}" env SLURM_CONF="$SLURM_CONF" /usr/sbin/slurmctld -i </dev/null ||
  fail "slurmctld did not start" "$dir/log/slurmctld.log"
sleep 1
"${sudo_cmd[@]}" env SLURM_CONF="$SLURM_CONF" /usr/sbin/slurmd </dev/null ||
  fail "slurmd did not start" "$dir/log/slurmd.log"
for _ in $(seq 60); do
  if timeout 5 sinfo --noheader --format=%t 2>/dev/null | grep -qxE '(idle|mix|alloc)'; then
    echo "slurm_cluster: one node ($host, $cpus CPUs) up; SLURM_CONF=$SLURM_CONF"
    exit 0
  fi
  sleep 0.5
done
fail "the node did not come up within 30 s: $(timeout 10 sinfo 2>&1 | tail -n 1)" \
  "$dir/log/slurmctld.log" "$dir/log/slurmd.log"
