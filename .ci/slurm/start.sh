#!/bin/bash
# Start a single-node Slurm 22.05 cluster on this host for sedpack's Slurm tests
# (pipeline/tests/slurm.rs): munged + slurmctld + slurmd, loopback only, no
# systemd, no cgroups. With --accounting also a socket-only MariaDB + slurmdbd,
# so that plain `sacct` works as on production clusters. Must run as root; a
# hostname that does not resolve to a loopback address is added to /etc/hosts.
# Idempotent: re-running with the daemons up only re-checks the node.
# Undo with stop.sh (controller state in /var/spool is kept).
# Adapted from the project's shared local-slurm scripts; MaxArraySize is small
# so that a test campaign of 12 jobs spans two job arrays.
set -euo pipefail

MARK="# written by start-local-slurm.sh"  # the shared script's mark: either may rewrite the other's config
OWN=/run/local-slurm            # pid files of the daemons *this* script started
LOG=/var/log/slurm
WAIT=${LOCAL_SLURM_WAIT:-60}    # seconds to wait for the node to become usable
acct=; [ "${1:-}" = --accounting ] && acct=1
t0=$SECONDS

die() { echo ".ci/slurm/start.sh: $*" >&2; exit 1; }
[ "$(id -u)" = 0 ] || die "must run as root"

# 1. Packages (minimal set, no recommends).
pkgs="slurmctld slurmd slurm-client munge"; cmds="slurmctld slurmd sbatch munged"
[ -n "$acct" ] && pkgs="$pkgs slurmdbd mariadb-server" && cmds="$cmds slurmdbd mariadbd"
missing=; for c in $cmds; do command -v "$c" >/dev/null || missing=1; done
if [ -n "$missing" ]; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get install -y -q --no-install-recommends $pkgs >/dev/null 2>&1 ||
    { apt-get update -q >/dev/null && apt-get install -y -q --no-install-recommends $pkgs >/dev/null; } ||
    die "apt-get install $pkgs failed"
fi

# 2. Config: one node = this host as `slurmd -C` sees it, reached via 127.0.0.1.
#    NoInAddrAny makes the daemons bind to what `hostname` resolves to, which
#    therefore must be a loopback address.
node=$(hostname -s)
resolved() { getent ahostsv4 "$(hostname)" | awk 'NR == 1 { print $1 }' || true; }
addr=$(resolved)
case $addr in
  127.*) ;;
  *) echo "127.0.0.1 $(hostname)" >> /etc/hosts
     # An earlier line of /etc/hosts for the hostname still wins: then it is for the user to fix.
     case $(resolved) in 127.*) ;; *) die "hostname '$(hostname)' resolves to '${addr:-nothing}', not 127.x";; esac
     echo ".ci/slurm/start.sh: hostname '$(hostname)' resolved to '${addr:-nothing}'; added it to /etc/hosts as 127.0.0.1" >&2 ;;
esac
hw=$(slurmd -C | awk 'NR == 1')  # NodeName=.. CPUs=.. Boards=.. ... RealMemory=N
mem=$(sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' <<<"$hw")
cpus=$(sed -n 's/.*CPUs=\([0-9]*\).*/\1/p' <<<"$hw")
[ -n "$mem" ] && [ -n "$cpus" ] || die "cannot parse 'slurmd -C': $hw"
if [ -n "$acct" ]; then
  storage="accounting_storage/slurmdbd
AccountingStorageHost=127.0.0.1"
else
  storage=accounting_storage/none
fi
slurm_conf="$MARK
ClusterName=local
SlurmctldHost=$node(127.0.0.1)
SlurmUser=root
AuthType=auth/munge
CommunicationParameters=NoCtldInAddrAny,NoInAddrAny
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=$LOG/slurmctld.log
SlurmdLogFile=$LOG/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=$storage
JobCompType=jobcomp/filetxt
JobCompLoc=$LOG/jobcomp.log
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MinJobAge=300
MaxArraySize=8
MpiDefault=none
MailProg=/bin/true
PreemptType=preempt/partition_prio
PreemptMode=REQUEUE
${hw% RealMemory=*} RealMemory=$((mem * 9 / 10)) NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=debug Nodes=$node Default=YES MaxTime=INFINITE State=UP PriorityTier=1
PartitionName=urgent Nodes=$node MaxTime=INFINITE State=UP PriorityTier=2"
dbd_conf="$MARK
AuthType=auth/munge
DbdHost=$node
DbdAddr=127.0.0.1
CommunicationParameters=NoInAddrAny
SlurmUser=root
PidFile=/run/slurmdbd.pid
LogFile=$LOG/slurmdbd.log
StorageType=accounting_storage/mysql
StorageHost=localhost
StorageUser=root
StorageLoc=slurm_acct_db"

alive() { # alive PIDFILE NAME: the pid in PIDFILE is a running NAME
  local pid; pid=$(cat "$1" 2>/dev/null) || return 1
  [ -n "$pid" ] && [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = "$2" ]
}
running() { alive /run/slurmctld.pid slurmctld || alive /run/slurmd.pid slurmd || alive /run/slurmdbd.pid slurmdbd; }
put() { # put FILE CONTENT: (re)write a config file of ours, never someone else's
  [ -f "$1" ] && ! grep -qxF "$MARK" "$1" && die "$1 was not written by this script; not overwriting it"
  [ "$(cat "$1" 2>/dev/null)" = "$2" ] && return 0
  running && die "$1 would change while Slurm is running; run .ci/slurm/stop.sh first"
  printf '%s\n' "$2" > "$1"
}
put /etc/slurm/slurm.conf "$slurm_conf"
if [ -n "$acct" ]; then put /etc/slurm/slurmdbd.conf "$dbd_conf"; chmod 600 /etc/slurm/slurmdbd.conf; fi
mkdir -p /var/spool/slurmctld /var/spool/slurmd "$LOG" "$OWN"

# 3. Daemons. Each is started only if not already running; the ones started
#    here get their pid recorded in $OWN so that the stop script kills only them.
end=$((SECONDS + WAIT))         # one wall-clock deadline for all the waiting below
fail() { tail -n 5 "$LOG"/slurm*.log >&2 || true; die "$* (clean up with .ci/slurm/stop.sh)"; }
retry() { # retry COMMAND...: until it succeeds (5 s per try) or the deadline passes
  until timeout 5 "$@" >/dev/null 2>&1; do [ $SECONDS -lt $end ] || return 1; sleep 0.2; done
}
start() { # start NAME PIDFILE COMMAND...
  local name=$1 pidfile=$2; shift 2
  alive "$pidfile" "$name" && return 0
  rm -f "$pidfile"
  # stdio to a file: a daemon must not hold the caller's stdout/stderr pipe open
  "$@" </dev/null >>"$LOG/daemons.out" 2>&1 || fail "$name failed to start"
  for _ in $(seq 50); do alive "$pidfile" "$name" && break; sleep 0.2; done
  alive "$pidfile" "$name" || fail "$name did not come up (see also $LOG/daemons.out)"
  cp "$pidfile" "$OWN/$name.pid"
}

if [ ! -s /etc/munge/munge.key ]; then
  mungekey --create --keyfile=/etc/munge/munge.key
  chown munge:munge /etc/munge/munge.key && chmod 0400 /etc/munge/munge.key
fi
install -d -o munge -g munge -m 0755 /run/munge
start munged /run/munge/munged.pid runuser -u munge -- /usr/sbin/munged
if [ -n "$acct" ]; then
  install -d -o mysql -g root -m 0755 /run/mysqld
  [ -d /var/lib/mysql/mysql ] || mariadb-install-db --user=mysql >/dev/null
  # --skip-networking: unix socket only; slurmdbd connects as root via unix_socket auth.
  start mariadbd /run/mysqld/mysqld.pid setsid -f /usr/sbin/mariadbd --user=mysql \
    --skip-networking --pid-file=/run/mysqld/mysqld.pid
  retry mariadb -e 'select 1' || fail "mariadbd does not answer"
  start slurmdbd /run/slurmdbd.pid /usr/sbin/slurmdbd
  # slurmctld without state files dies ("no TRES") if slurmdbd is not listening yet
  retry bash -c ': </dev/tcp/127.0.0.1/6819' || fail "slurmdbd does not listen on 127.0.0.1:6819"
fi
start slurmctld /run/slurmctld.pid /usr/sbin/slurmctld
start slurmd /run/slurmd.pid /usr/sbin/slurmd

# 4. Wait until the node is usable (idle, or busy with jobs from an earlier run)
#    and, with --accounting, until sacct answers.
while :; do
  for d in slurmctld slurmd; do alive /run/$d.pid $d || fail "$d exited"; done
  state=$(timeout 5 sinfo -h -n "$node" -o %T 2>/dev/null || true)
  case $state in
    idle|mixed|allocated|completing) [ -z "$acct" ] || retry sacct -n -X -j 1 && break ;;
    drained|draining) timeout 5 scontrol update NodeName="$node" State=RESUME >/dev/null 2>&1 || true ;;
  esac
  [ $SECONDS -lt $end ] || fail "node $node not usable after ${WAIT}s (state: '${state:-no answer}')"
  sleep 0.5
done
echo "local slurm up: node=$node cpus=$cpus state=$state partitions=debug,urgent" \
     "accounting=$([ -n "$acct" ] && echo slurmdbd || echo none) ctld=127.0.0.1:6817" \
     "owned=[$(cd "$OWN" && ls 2>/dev/null | sed 's/\.pid$//' | paste -sd' ')] in $((SECONDS - t0))s"
