#!/bin/bash
# Stop the daemons that .ci/slurm/start.sh started, and only those, using the
# pid files it recorded in /run/local-slurm. Controller state (/var/spool/slurmctld)
# is kept, so a later start continues job ids and pending/running jobs.
# Running jobs survive a plain stop (their slurmstepd keeps going); pass
# --cancel-jobs to scancel every job first and wait (<= 30 s) for them to end.
set -u
OWN=/run/local-slurm
if [ "${1:-}" = --cancel-jobs ] && [ -f "$OWN/slurmctld.pid" ]; then
  ids=$(squeue -h -o %A 2>/dev/null | sort -u)
  if [ -n "$ids" ]; then
    scancel $ids
    for _ in $(seq 30); do [ -z "$(squeue -h -o %A 2>/dev/null)" ] && break; sleep 1; done
  fi
fi
# slurmctld first: once it is down nothing new is scheduled, so no launch can be
# lost between the two (a job allocated while slurmd is down stays a ghost RUNNING).
for name in slurmctld slurmd slurmdbd mariadbd munged; do
  f=$OWN/$name.pid
  [ -f "$f" ] || continue
  pid=$(cat "$f")
  if [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = "$name" ]; then
    kill -TERM "$pid"
    for _ in $(seq 100); do [ -d "/proc/$pid" ] || break; sleep 0.1; done
    if [ -d "/proc/$pid" ]; then
      echo ".ci/slurm/stop.sh: $name ($pid) ignored SIGTERM for 10 s, sending SIGKILL" >&2
      kill -KILL "$pid"
    fi
    echo "stopped $name ($pid)"
  fi
  rm -f "$f"
done
