#!/usr/bin/env bash
# Proves the Slurm scripts on a real single-node Slurm: installs Debian's slurm-wlm and munge
# if needed, starts munged, slurmctld and slurmd on this machine, submits a 4-task job array
# plus the dependent merge job, and compares the merged tables byte for byte with an unsplit
# run. Needs root. Usage: scripts/slurm/ci-test.sh path/to/smithwalk
set -euo pipefail
smithwalk=$(realpath "${1:?usage: $0 SMITHWALK_BINARY}")
here=$(dirname "$(realpath "$0")")
repo=$(realpath "$here/../..")
work=$(mktemp -d)
trap 'scancel --quiet --user=root >/dev/null 2>&1 || true; pkill -x slurmd || true; pkill -x slurmctld || true; rm -rf "$work"' EXIT

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi

# munge: a key and a running daemon.
if [ ! -s /etc/munge/munge.key ]; then
    dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
fi
chown munge:munge /etc/munge/munge.key && chmod 400 /etc/munge/munge.key
mkdir -p /run/munge && chown munge:munge /run/munge
pgrep -x munged >/dev/null || runuser -u munge -- munged
munge -n | unmunge >/dev/null

# A one-node cluster on this machine.
node=$(uname -n | cut -d. -f1)
cpus=$(nproc)
mem=$(($(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 512))
mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
cat > /etc/slurm/slurm.conf <<CONF
ClusterName=smithwalk-ci
SlurmctldHost=$node(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=ci Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
pkill -x slurmctld || true
pkill -x slurmd || true
slurmctld -c
slurmd
for _ in $(seq 60); do
    sinfo -h -o %t 2>/dev/null | grep -qx idle && break
    sleep 1
done
sinfo

# A small run: unsplit, then through Slurm in 4 shards.
cat > "$work/run.toml" <<CONF
paths = 300_000
seed = 9
[surface]
alpha = [0.5, [1.0, 0.1]]
[[material]]
kind = "conductor"
[[material]]
kind = "dielectric"
eta = 1.5
[incident]
theta_deg = [0, 60]
[detector]
cos_theta_bins = 16
phi_bins = 32
max_order = 4
CONF
"$smithwalk" run "$work/run.toml" --out "$work/unsplit" >/dev/null
merge_job=$(SMITHWALK="$smithwalk" "$repo/scripts/slurm/submit.sh" "$work/run.toml" "$work/slurm" 4)
echo "merge job $merge_job"
fail() {
    echo "slurm test failed: $*" >&2
    tail -n 20 "$work"/slurm/*.log /var/log/slurm/*.log >&2 || true
    exit 1
}
for _ in $(seq 600); do
    reason=$(squeue -h -j "$merge_job" -o %r 2>/dev/null || true)
    [ -n "$reason" ] || break
    case "$reason" in *DependencyNeverSatisfied*) fail "a shard task failed, the merge job can never run" ;; esac
    sleep 1
done
[ -z "$(squeue -h -j "$merge_job" 2>/dev/null || true)" ] || fail "timed out"
for f in lobes.csv summary.csv; do
    cmp "$work/unsplit/$f" "$work/slurm/merged/$f" || fail "$f differs from the unsplit run"
done
echo "slurm: 4-task array + merge job reproduce the unsplit run byte for byte"
