#!/usr/bin/env bash
# A throwaway single-node Slurm on this machine, for tests (CI, a developer's box, a container).
#
#   deploy/slurm/single-node.sh start STATE_DIR   # then: export SLURM_CONF=STATE_DIR/slurm.conf
#   deploy/slurm/single-node.sh stop  STATE_DIR
#
# Needs root and Debian's packages:  apt-get install -y --no-install-recommends slurm-wlm munge
# Everything (config, munge key and socket, state, spool, logs, pid files) lives under STATE_DIR, and
# the daemons are started directly (no systemd). A private munged on its own socket means a system
# munged, running or not, is never touched. `start` stops whatever an earlier start left, then starts
# clean (slurmctld -c), so it can be re-run. Ports: SLURMCTLD_PORT / SLURMD_PORT (default 6817/6818).
set -euo pipefail

cmd=${1:-}; state=${2:-}
[[ ( $cmd == start || $cmd == stop ) && -n $state ]] || { echo "usage: $0 start|stop STATE_DIR" >&2; exit 2; }
mkdir -p "$state"; state=$(cd "$state" && pwd)
ctld_port=${SLURMCTLD_PORT:-6817}; slurmd_port=${SLURMD_PORT:-6818}

stop() {  # TERM all at once (each takes ~2 s to exit), then wait: a restart needs the ports free
    local f pid pids=()
    for f in slurmd slurmctld munged; do
        pid=$(cat "$state/run/$f.pid" 2>/dev/null || true)
        rm -f "$state/run/$f.pid"
        # only if that pid is still our daemon: a stale pid file may name a reused pid
        [[ -n $pid && $(cat "/proc/$pid/comm" 2>/dev/null) == "$f" ]] || continue
        kill "$pid" && pids+=("$pid")
    done
    for pid in "${pids[@]}"; do
        for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        kill -9 "$pid" 2>/dev/null || true   # still there after 10 s
    done
}

logs() { for f in "$state"/log/*.log; do echo "==> $f <=="; tail -n 30 "$f"; done >&2; }

if [[ $cmd == stop ]]; then stop; exit 0; fi

stop
mkdir -p "$state"/{run,log,spool,ctld,munge}
chmod 755 "$state/munge"   # munged: key and socket dir writable by their owner only

# Munge: own key (made once), own socket; Slurm is pointed at the socket via AuthInfo below.
# --force: munged wants every directory above its socket searchable by all, which a mktemp -d or /root
# is not; that only matters to non-root clients, and everything here runs as root.
key=$state/munge/munge.key
[[ -s $key ]] || { mungekey --create --keyfile="$key" 2>/dev/null || dd if=/dev/urandom of="$key" bs=1k count=1 status=none; }
chmod 400 "$key"
sock=$state/munge/munge.socket
munged --force --socket="$sock" --key-file="$key" --pid-file="$state/run/munged.pid" \
       --log-file="$state/log/munged.log" --seed-file="$state/munge/munged.seed"

# The node line is what slurmd itself detects (CPUs, cores, RealMemory), so the node never drains for
# "low resources"; only its name is replaced by localhost (slurmd is started with -N localhost).
node=$(slurmd -C | head -n 1 | sed 's/^NodeName=[^ ]*/NodeName=localhost NodeAddr=127.0.0.1/')

# No cgroups (containers rarely give slurmd a usable hierarchy): linuxproc tracks processes through
# /proc, task/none binds nothing, no accounting. cons_tres with CR_CPU hands out single CPUs, so array
# tasks run side by side up to the CPU count and memory is not a consumable.
cat > "$state/slurm.conf" <<CONF
ClusterName=meshslim-test
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$sock
StateSaveLocation=$state/ctld
SlurmdSpoolDir=$state/spool
SlurmctldPidFile=$state/run/slurmctld.pid
SlurmdPidFile=$state/run/slurmd.pid
SlurmctldLogFile=$state/log/slurmctld.log
SlurmdLogFile=$state/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
MailProg=/bin/true
SchedulerParameters=sched_interval=1
$node State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF

export SLURM_CONF=$state/slurm.conf
slurmctld -c     # -c: ignore job state a previous run saved
slurmd -c -N localhost

# Ready once the node reports idle; sinfo fails until slurmctld answers, hence || true.
for _ in $(seq 60); do
    [[ $(sinfo -h -n localhost -o %t 2>/dev/null || true) == idle ]] && { echo "export SLURM_CONF=$SLURM_CONF"; exit 0; }
    sleep 0.5
done
echo "single-node.sh: node not idle after 30 s; sinfo says: $(sinfo -h -N -o '%N %t %E' 2>&1 || true)" >&2
logs; stop; exit 1   # leave nothing running behind a failed start
