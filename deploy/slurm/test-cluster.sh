#!/bin/bash
# A real Slurm cluster of one node (loopback only) renders the built-in scene as a job array
# of 4 shards plus a dependent merge job; the merged film must equal a one-process render of
# the same seed to the bit. Installs Debian's slurm-wlm and munge when they are missing
# (as root), runs every daemon from a scratch folder with its own key, ports and sockets,
# and stops all it started. Run by .ci/run after the tests (which build target/release).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
pathlab=${PATHLAB:-$root/target/release/pathlab}
if [ ! -x "$pathlab" ]; then
    echo "error: $pathlab is not built (cargo build --release)" >&2
    exit 1
fi
export PATHLAB=$pathlab

if ! command -v slurmctld >/dev/null 2>&1 || ! command -v munged >/dev/null 2>&1; then
    if [ "$(id -u)" -ne 0 ]; then
        echo "error: slurm-wlm and munge are missing, and installing them needs root" >&2
        exit 1
    fi
    echo "installing slurm-wlm and munge"
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y -q slurm-wlm munge >/dev/null 2>&1 ||
        { apt-get update -q >/dev/null && apt-get install -y -q slurm-wlm munge >/dev/null; }
fi

work=$(mktemp -d /tmp/pathlab-slurm.XXXXXX)
conf=$work/slurm.conf
cleanup() {
    set +e
    if [ -f "$conf" ]; then
        SLURM_CONF=$conf scancel --quiet --user="$(id -un)" 2>/dev/null
    fi
    local pids=()
    for pidfile in "$work/slurmd.pid" "$work/slurmctld.pid" "$work/munge/pid"; do
        [ -f "$pidfile" ] && pids+=("$(cat "$pidfile")")
    done
    for pid in "${pids[@]}"; do
        kill "$pid" 2>/dev/null
    done
    # Each daemon gets 10 seconds to go, then is killed.
    for pid in "${pids[@]}"; do
        for _ in $(seq 1 50); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.2
        done
        kill -9 "$pid" 2>/dev/null
    done
    for pid in "${pids[@]}"; do
        if kill -0 "$pid" 2>/dev/null; then
            echo "error: daemon $pid of this test is still running" >&2
        fi
    done
    rm -rf "$work"
}
trap cleanup EXIT

# munge with its own key and socket.
mkdir -p "$work/munge" "$work/state" "$work/spool" "$work/parts"
head -c 1024 /dev/urandom >"$work/munge/munge.key"
chmod 400 "$work/munge/munge.key"
munged --force --key-file="$work/munge/munge.key" --socket="$work/munge/socket" \
    --pid-file="$work/munge/pid" --log-file="$work/munge/log" --seed-file="$work/munge/seed" \
    2>/dev/null

node=$(hostname -s)
cat >"$conf" <<CONF
ClusterName=pathlab-test
SlurmctldHost=$node(127.0.0.1)
SlurmUser=$(id -un)
SlurmdUser=$(id -un)
AuthType=auth/munge
AuthInfo=socket=$work/munge/socket
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
NodeName=$node NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$conf
slurmctld -f "$conf"
slurmd -f "$conf"

fail() {
    echo "error: $*" >&2
    for log in "$work"/slurmctld.log "$work"/slurmd.log "$work"/*.log; do
        [ -f "$log" ] && { echo "--- $log" >&2; tail -n 20 "$log" >&2; }
    done
    exit 1
}
for _ in $(seq 1 150); do
    state=$(sinfo -h -o %T 2>/dev/null | head -n 1 || true)
    [ "$state" = idle ] && break
    sleep 0.2
done
[ "$state" = idle ] || fail "the node did not come up (state '$state')"

cd "$work"
flags=(-s 64 -r 64 48 --seed 3)
ids=$("$root/deploy/slurm/submit.sh" 4 cornell-box "$work/parts" "$work/merged.plf" "${flags[@]}")
echo "$ids"
merge=${ids##*job }
for _ in $(seq 1 600); do
    state=$(scontrol show job "$merge" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')
    case "$state" in
        COMPLETED) break ;;
        FAILED | CANCELLED | TIMEOUT | NODE_FAIL | OUT_OF_MEMORY) fail "the merge job ended $state" ;;
    esac
    sleep 0.5
done
[ "$state" = COMPLETED ] || fail "the merge job did not finish in 5 minutes (state '$state')"
ls "$work"/parts/part-{0,1,2,3}.plf >/dev/null || fail "a shard's part is missing"

"$pathlab" render cornell-box "${flags[@]}" -o "$work/single.plf" -q
cmp -s "$work/merged.plf" "$work/single.plf" || fail "the merged image differs from one render's"
echo "slurm: 4 shards and their merge equal one render to the bit"
