#!/bin/bash
# cargo xtask cluster-test: a real Slurm run of docs/cluster's recipes on this machine.
#
# Usage: cluster-test.sh SPECTRACE_BINARY [SCENE]
#
# Starts a single-node Slurm (slurmctld and slurmd on localhost, with munge; Debian's
# slurm-wlm and munge packages) under a temporary folder, submits docs/cluster/submit.sh with
# SCENE (default scenes/office.json at a reduced size), waits for the 8-task render array and the
# dependent merge job, renders the same scene in one process, and compares the outputs byte for
# byte. Needs root (the daemons run as root) and no other Slurm on the machine. Stops its
# daemons on exit. Never run by CI.
set -euo pipefail

binary=$(realpath "$1")
root=$(cd "$(dirname "$0")/../.." && pwd)
scene=${2:-$root/scenes/office.json}
for tool in slurmctld slurmd sbatch squeue sinfo munged; do
    command -v "$tool" > /dev/null || { echo "cluster-test: $tool not found (apt-get install slurm-wlm munge)"; exit 2; }
done
[ "$(id -u)" = 0 ] || { echo "cluster-test: run as root (the Slurm daemons run as root here)"; exit 2; }

work=$(mktemp -d /tmp/spectrace-cluster-test-XXXXXX)
host=$(hostname -s)
cpus=$(nproc)
mkdir -p "$work"/{state,spool,run,job}
cat > "$work/slurm.conf" <<CONF
ClusterName=spectrace-test
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/run/slurmctld.pid
SlurmdPidFile=$work/run/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$work/slurm.conf

pids=()
cleanup() {
    scancel --user=root > /dev/null 2>&1 || true
    for pid in "${pids[@]}"; do kill "$pid" 2> /dev/null || true; done
    wait 2> /dev/null || true
}
trap cleanup EXIT

if ! pgrep -x munged > /dev/null; then
    if [ ! -s /etc/munge/munge.key ]; then
        (mungekey --create --force 2> /dev/null || /usr/sbin/create-munge-key -f) > /dev/null
    fi
    mkdir -p /run/munge && chown munge:munge /run/munge 2> /dev/null || true
    runuser -u munge -- munged 2> /dev/null || munged --force
fi
slurmctld -D -f "$SLURM_CONF" > "$work/slurmctld.out" 2>&1 & pids+=($!)
sleep 2
slurmd -D -f "$SLURM_CONF" > "$work/slurmd.out" 2>&1 & pids+=($!)
for _ in $(seq 60); do
    sinfo -h -o %t 2> /dev/null | grep -q idle && break
    sleep 1
done
sinfo -h -o %t | grep -q idle || { echo "cluster-test: the node did not come up"; tail "$work"/slurm*.log; exit 1; }
echo "== sinfo"
sinfo

# The job folder: the recipes as written, the scene, spectrace on the PATH.
cp "$root"/docs/cluster/{render.sbatch,merge.sbatch,submit.sh} "$work/job/"
sed 's/"width": 480, "height": 300/"width": 160, "height": 100/' "$scene" > "$work/job/scene.json"
# The scene's luminaire files, relative to it.
[ -d "$(dirname "$scene")/luminaires" ] && cp -r "$(dirname "$scene")/luminaires" "$work/job/"
mkdir -p "$work/bin" && ln -s "$binary" "$work/bin/spectrace"
export PATH=$work/bin:$PATH
cd "$work/job"
echo "== ./submit.sh scene.json"
started=$(date +%s.%N)
./submit.sh scene.json
for _ in $(seq 1800); do
    [ -z "$(squeue -h)" ] && break
    sleep 1
done
finished=$(date +%s.%N)
echo "== the merge job's log (its last lines) and the parts"
tail -n 3 spectrace-merge-*.log
ls parts
echo "== one process"
spectrace render scene.json --quiet --out whole
status=0
for f in scene.exr scene.png workplane.csv workplane.exr; do
    if cmp -s "out/$f" "whole/$f"; then
        echo "identical: $f"
    else
        echo "DIFFERENT: $f"; status=1
    fi
done
echo "array of 8 shards plus merge: $(echo "$finished - $started" | bc) s wall"
exit $status
