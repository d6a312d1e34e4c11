#!/usr/bin/env bash
# Stop the daemons tests/slurm/standup.sh started, by the PIDs it recorded (slurmd, then
# slurmctld, then munged if it started one). Nothing else is touched. No-op without a PID file.
set -euo pipefail

STATE=${INFSUP_SLURM_STATE:-/run/infsup-contact-slurm}
PIDS=$STATE/daemons.pid

if [ ! -f "$PIDS" ]; then
    echo "stop.sh: no $PIDS: nothing started by standup.sh is recorded"
    exit 0
fi

# reverse order of start; a PID is signalled only while it still names the recorded daemon
tac "$PIDS" | while read -r name pid; do
    comm=$(cat "/proc/$pid/comm" 2>/dev/null || true)
    if [ "$comm" != "$name" ]; then
        echo "stop.sh: $name ($pid) already gone"
        continue
    fi
    kill -TERM "$pid"
    for _ in $(seq 1 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    if kill -0 "$pid" 2>/dev/null; then
        echo "stop.sh: $name ($pid) ignored SIGTERM for 10 s; SIGKILL"
        kill -KILL "$pid"
    fi
    echo "stop.sh: stopped $name ($pid)"
done
rm -f "$PIDS"
echo "stop.sh: note: while slurm-wlm stays installed without a controller, every snakemake start waits" \
     "10 s (its Slurm plugin asks 'scontrol show config'); remove the packages if Slurm is no longer needed"
