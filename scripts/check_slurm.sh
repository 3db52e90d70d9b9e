#!/usr/bin/env bash
# Runs a frame range on a real batch scheduler and checks it: Debian's Slurm (slurm-wlm, with
# munge) started here as a one-node cluster in a temporary folder, the `developing` preset's
# frames 0..7 rendered by a job array in chunks of 2 (docs/farm.md's recipe), and every frame
# compared byte for byte with one local run of the whole range. The daemons are stopped and the
# folder removed at the end, whatever happens. Installs slurm-wlm when it is missing (root).
#
#   bash scripts/check_slurm.sh [path/to/cloudsketch]   (default: target/debug/cloudsketch)
set -euo pipefail
# The daemons run as root (SlurmUser=root), as on the CI machine; elsewhere through sudo.
if [ "$(id -u)" != 0 ]; then exec sudo -E bash "$0" "$@"; fi
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$(realpath "${1:-$ROOT/target/debug/cloudsketch}")"
log() { printf '\033[1;34m[slurm]\033[0m %s\n' "$*" >&2; }
SUDO=""

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  log "apt-get install slurm-wlm (brings munge)"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
fi

work="$(mktemp -d /tmp/cloudsketch-slurm.XXXXXX)"
chmod 755 "$work"
munge_pid=""
stop() {
  # Jobs first (an interrupted run leaves none running), then the daemons, waited for.
  if [ -n "${SLURM_CONF:-}" ]; then scancel --quiet --full --partition=main 2>/dev/null || true; fi
  local pids=()
  for pidfile in "$work/slurmd.pid" "$work/slurmctld.pid"; do
    [ -f "$pidfile" ] && pids+=("$(cat "$pidfile")")
  done
  [ -n "$munge_pid" ] && pids+=("$munge_pid")
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for _ in $(seq 50); do
    alive=0
    for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
    [ "$alive" = 0 ] && break
    sleep 0.2
  done
  rm -rf "$work"
}
trap stop EXIT

# munge: a key if there is none, and the daemon (this script's own; stopped at the end).
if ! $SUDO test -f /etc/munge/munge.key; then
  log "a munge key"
  $SUDO dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
  $SUDO chown munge:munge /etc/munge/munge.key
  $SUDO chmod 400 /etc/munge/munge.key
fi
$SUDO mkdir -p /run/munge /var/log/munge /var/lib/munge
$SUDO chown munge:munge /run/munge /var/log/munge /var/lib/munge
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
  $SUDO munged --force
  munge_pid="$(cat /run/munge/munged.pid 2>/dev/null || true)"
fi

host="$(hostname -s)"
cpus="$(nproc)"
# Ports of their own per run (two runs side by side do not meet).
port=$(( 20000 + ($$ % 5000) * 2 ))
mkdir -p "$work/state" "$work/spool" "$work/farm" "$work/local"
cat >"$work/slurm.conf" <<EOF
ClusterName=cloudsketch
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
SlurmctldPort=$port
SlurmdPort=$((port + 1))
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=main Nodes=$host Default=YES State=UP
EOF
export SLURM_CONF="$work/slurm.conf"
log "slurmctld and slurmd (one node: $host, $cpus CPUs)"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 60); do
  if sinfo -h -o '%t' 2>/dev/null | grep -q idle; then break; fi
  sleep 1
done
if ! sinfo -h -o '%t' | grep -q idle; then
  tail -n 30 "$work/slurmctld.log" "$work/slurmd.log" >&2 || true
  log "the node did not come up"
  exit 1
fi

# The job: the developing preset's frames, small and fast; each task renders its chunk.
"$BIN" new --preset developing -o "$work/developing.json"
args=(render "$work/developing.json" --size 160x90 --set /render/slices=32 --fps 2)
cat >"$work/chunk.sh" <<EOF
#!/usr/bin/env bash
# One task of the array: frames \$SLURM_ARRAY_TASK_ID and the next.
set -euo pipefail
first=\$SLURM_ARRAY_TASK_ID
exec "$BIN" ${args[*]} --frames "\$first..\$((first + 1))" --progress json -o "$work/farm/frame_####.png"
EOF
chmod +x "$work/chunk.sh"
log "sbatch --array=0-6:2 (frames 0..7 in chunks of 2)"
start=$(date +%s)
if ! timeout 900 sbatch --wait --array=0-6:2 --output="$work/task-%a.log" "$work/chunk.sh" >/dev/null; then
  cat "$work"/task-*.log >&2 || true
  log "the array job failed"
  exit 1
fi
log "array job done in $(( $(date +%s) - start )) s; $(grep -h '"frame"' "$work"/task-*.log | wc -l) frames reported"

"$BIN" "${args[@]}" --frames 0..7 -o "$work/local/frame_####.png" 2>/dev/null
for n in 0 1 2 3 4 5 6 7; do
  name="$(printf 'frame_%04d.png' "$n")"
  if ! cmp -s "$work/farm/$name" "$work/local/$name"; then
    log "frame $n from the array job differs from the local run's"
    exit 1
  fi
done
if cmp -s "$work/local/frame_0000.png" "$work/local/frame_0007.png"; then
  log "frames 0 and 7 are the same image: the cloud did not develop"
  exit 1
fi
log "8 frames from 4 Slurm tasks equal one local run's, byte for byte"
