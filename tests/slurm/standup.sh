#!/usr/bin/env bash
# Stand up a single-node Slurm (slurm-wlm 22.05 from Debian + munge) on this machine for
# `pytest -m slurm` (tests/slurm/test_slurm_profile.py). Root on Debian only.
#
#   bash tests/slurm/standup.sh     # install, configure, start; waits until the node is idle
#   bash tests/slurm/stop.sh        # stop what this script started (by PID), nothing else
#
# What it does:
#   * apt-get installs slurm-wlm and munge (noninteractive, no recommends);
#   * writes /etc/slurm/slurm.conf for one node: cons_tres with cores and memory as
#     consumable resources, CPUs/sockets/cores/RealMemory as `slurmd -C` reports them,
#     accounting storage disabled (no slurmdbd), process tracking by /proc (works without
#     cgroups, e.g. in containers), jobs exceeding their --mem killed (OverMemoryKill), so a
#     too-small mem_mb in profiles/slurm fails the test instead of passing silently;
#   * starts munged (unless one already answers), slurmctld and slurmd, waits for `sinfo` to
#     show the node idle and records the PIDs of the daemons it started in $STATE/daemons.pid.
# It refuses to overwrite a slurm.conf it did not write and to start daemons next to running
# ones it did not start. Running it again while its daemons are up is a no-op.
set -euo pipefail
# The daemons (slurmctld, slurmd, munged) install to /usr/sbin, which a minimal CI PATH may lack.
export PATH="$PATH:/usr/sbin:/sbin"

STATE=${INFSUP_SLURM_STATE:-/run/infsup-contact-slurm}
CONF=/etc/slurm/slurm.conf
MARK="# written by infsup-contact tests/slurm/standup.sh"
PIDS=$STATE/daemons.pid
LOGDIR=/var/log/slurm
TIMEOUT=${INFSUP_SLURM_TIMEOUT:-90}

die() { echo "standup.sh: $*" >&2; exit 1; }

[ "$(id -u)" = 0 ] || die "must run as root (it installs packages and starts daemons)"
command -v apt-get >/dev/null || die "needs Debian/Ubuntu (apt-get); install slurm-wlm and munge yourself"

alive() { [ -n "${1:-}" ] && kill -0 "$1" 2>/dev/null; }

node_state() { sinfo -h -N -o '%t' 2>/dev/null | head -n1; }

# Already up from an earlier run of this script: nothing to do.
if [ -f "$PIDS" ]; then
    all_alive=1
    while read -r _name pid; do alive "$pid" || all_alive=0; done < "$PIDS"
    if [ "$all_alive" = 1 ] && [ "$(node_state)" = idle ]; then
        echo "standup.sh: Slurm already up (PIDs in $PIDS)"; sinfo; exit 0
    fi
    die "$PIDS lists daemons that are not all running: run tests/slurm/stop.sh first"
fi

# --- packages ---------------------------------------------------------------------------
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v sinfo >/dev/null \
   || ! command -v munged >/dev/null; then
    echo "standup.sh: installing slurm-wlm and munge from apt"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
fi

# Daemons this script did not start must not be running (a real cluster node, or leftovers).
for d in slurmctld slurmd; do
    if pgrep -x "$d" >/dev/null; then
        die "a $d is already running (PID $(pgrep -x "$d" | tr '\n' ' ')) and was not started by this script; stop it first"
    fi
done

# --- slurm.conf ---------------------------------------------------------------------------
if [ -f "$CONF" ] && ! grep -qxF "$MARK" "$CONF"; then
    die "$CONF exists and was not written by this script; refusing to overwrite it"
fi
host=$(hostname -s)
# "NodeName=vm CPUs=2 Boards=1 SocketsPerBoard=1 CoresPerSocket=2 ThreadsPerCore=1 RealMemory=24105"
hw=$(slurmd -C | head -n1 | sed -E "s/^NodeName=[^ ]+ //")
echo "$hw" | grep -q 'CPUs=[0-9]' && echo "$hw" | grep -q 'RealMemory=[0-9]' \
    || die "could not read CPUs and RealMemory from 'slurmd -C' (got: $hw)"
mkdir -p "$(dirname "$CONF")" "$STATE" "$LOGDIR" /var/lib/slurm/slurmctld /var/lib/slurm/slurmd
chown slurm: /var/lib/slurm/slurmctld "$LOGDIR"
tmp=$(mktemp "$CONF.XXXXXX")
cat > "$tmp" <<EOF
$MARK
# Single-node test cluster; see the header of tests/slurm/standup.sh.
ClusterName=infsup-test
SlurmctldHost=$host(127.0.0.1)
SlurmUser=slurm
AuthType=auth/munge
StateSaveLocation=/var/lib/slurm/slurmctld
SlurmdSpoolDir=/var/lib/slurm/slurmd
SlurmctldPidFile=$STATE/slurmctld.pid
SlurmdPidFile=$STATE/slurmd.pid
SlurmctldLogFile=$LOGDIR/slurmctld.log
SlurmdLogFile=$LOGDIR/slurmd.log
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
# no cgroups needed (containers): processes tracked through /proc, no task binding
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
# memory use sampled every 2 s; a job above its --mem is killed (what cgroups would enforce)
JobAcctGatherType=jobacct_gather/linux
JobAcctGatherFrequency=task=2
JobAcctGatherParams=OverMemoryKill
# no slurmdbd: sacct has nothing to say, job status comes from squeue
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
# finished jobs stay visible to squeue this long (the Snakemake plugin's squeue status
# needs at least 3 × its first status-check delay)
MinJobAge=600
ReturnToService=2
MpiDefault=none
NodeName=$host NodeAddr=127.0.0.1 $hw State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
chmod 644 "$tmp"
mv "$tmp" "$CONF"

# --- daemons ------------------------------------------------------------------------------
: > "$PIDS"   # appended as each daemon starts: stop.sh finds them even if a later step fails
wait_pidfile() {  # wait_pidfile FILE NAME: the PID in FILE once the daemon runs
    local f=$1 name=$2 i pid
    for i in $(seq 1 100); do
        pid=$(cat "$f" 2>/dev/null || true)
        if alive "$pid"; then echo "$pid"; return 0; fi
        sleep 0.1
    done
    die "$name did not start (see $LOGDIR/$name.log)"
}

if munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
    echo "standup.sh: munged already running; using it (not recorded, not stopped)"
else
    [ -s /etc/munge/munge.key ] || { mungekey --create --keyfile=/etc/munge/munge.key;
                                     chown munge: /etc/munge/munge.key; chmod 400 /etc/munge/munge.key; }
    install -d -o munge -g munge -m 0755 /run/munge
    rm -f /run/munge/munged.pid
    runuser -u munge -- /usr/sbin/munged
    pid=$(wait_pidfile /run/munge/munged.pid munged)
    echo "munged $pid" >> "$PIDS"
    munge -n | unmunge >/dev/null || die "munged does not answer"
fi

rm -f "$STATE/slurmctld.pid" "$STATE/slurmd.pid"
slurmctld -c   # -c: start clean, without jobs or state of an earlier test cluster
pid=$(wait_pidfile "$STATE/slurmctld.pid" slurmctld)
echo "slurmctld $pid" >> "$PIDS"
slurmd
pid=$(wait_pidfile "$STATE/slurmd.pid" slurmd)
echo "slurmd $pid" >> "$PIDS"

for i in $(seq 1 "$TIMEOUT"); do
    state=$(node_state)
    if [ "$state" = idle ]; then
        echo "standup.sh: node $host idle; daemons: $(tr '\n' ' ' < "$PIDS")(stop: bash tests/slurm/stop.sh)"
        sinfo
        exit 0
    fi
    sleep 1
done
die "node $host not idle after ${TIMEOUT}s (state: ${state:-none}); logs in $LOGDIR; stop with tests/slurm/stop.sh"
